"""Run small KRL programs for the interpreter tests."""

from __future__ import annotations

import textwrap
from pathlib import Path

from interp.run import make_runtime, run_spec, RunSinks
from net.hub import Network
from robot.controller import Controller
from robot.trace import TraceWriter


class Run:
    def __init__(self, rt, result, trace):
        self.rt = rt
        self.result = result
        self.trace = trace
        self.events = trace.events if trace is not None else []

    def var(self, module: str, name: str):
        return self.rt.program.module(module).data[name.upper()].get()

    def kinds(self, kind: str) -> list:
        return [e for e in self.events if e["kind"] == kind]

    def io(self, signal: str) -> list:
        return [(e["t"], e["value"]) for e in self.events if e["kind"] == "io" and e["signal"] == signal]


def refuse_runs(monkeypatch) -> None:
    """From now on a controller or a network hub built fails the test: a tool that only reads a
    program's data lists reads its own copy of the program's model (interp/runtime/model.py)."""
    def refuse(*a, **k):
        raise AssertionError("a controller or a network hub was built")
    monkeypatch.setattr(Controller, "__init__", refuse)
    monkeypatch.setattr(Network, "__init__", refuse)


def write(tmp: Path, name: str, text: str) -> Path:
    """Write `text` (dedented) to ``tmp/name``, making its folders."""
    p = tmp / name
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(textwrap.dedent(text).lstrip("\n"), encoding="utf-8")
    return p


def _write_new(tmp: Path, name: str, text: str) -> Path:
    """:func:`write`, unless ``tmp/name`` holds that text already: then left as it is, its
    modification time too, so that a test's runs of one program load its files once (the
    process's cache of checked workspaces knows a file by its path, size and modification time:
    interp/runtime/program.py ``checked_workspace``; rewritten at each run, tests/interp/test_spin.py's
    programs were loaded and checked again by 44 of its runs, about 45 ms of CPU each; :func:`write`
    itself writes always: a test that patches what a run memoises on the checked files, as
    tests/interp/test_timer_wait.py does, needs its second run to load them again)."""
    p = tmp / name
    try:
        if p.read_text(encoding="utf-8") == textwrap.dedent(text).lstrip("\n"):
            return p
    except (OSError, ValueError):        # none yet, or not text
        pass
    return write(tmp, name, text)


def run_krl(tmp: Path, src: str, dat: str | None = None, name: str = "prog", *, files: dict | None = None,
            stimuli: str | None = None, max_sim_time: float = 60.0, max_steps: int = 2_000_000,
            submit: list | None = None, before=None, trace: bool = True, interp: str = "tree",
            spins: str = "park") -> Run:
    """Write ``name``.src (and .dat) into ``tmp``, run it on the tree interpreter (or
    ``interp="vm"``)."""
    prog = _write_new(tmp, f"{name}.src", src)
    if dat is not None:
        _write_new(tmp, f"{name}.dat", dat)
    for fname, text in (files or {}).items():
        _write_new(tmp, fname, text)
    inputs = None
    if stimuli is not None:
        inputs = _write_new(tmp, "stimuli.yaml", stimuli)
    tw = TraceWriter(keep=True) if trace else None
    rt, _ = make_runtime(run_spec(prog, inputs=inputs, max_sim_time=max_sim_time, max_steps=max_steps,
                         mujoco=False, submit=[tmp / s for s in (submit or [])],
                         check=False, interp=interp, spins=spins),
                         RunSinks(trace=tw))   # run-time semantics, errors included (krl run --no-check)
    if before is not None:
        before(rt)
    res = rt.run()
    return Run(rt, res, tw)


def run_beside(tmp: Path, prog: str, sub: str, dat: str, *, interp: str, enabled: bool = True,
               shadow: bool = False, stimuli: str | None = None, max_sim_time: float = 30.0,
               max_steps: int = 10_000_000):
    """Run ``prog`` (with the data list `dat`) beside the submit program `sub`, untraced, with the
    spin watch on or not (`enabled`) or shadowing (`shadow`). Returns ``(runtime, result)``."""
    p = _write_new(tmp, "prog.src", prog)
    _write_new(tmp, "prog.dat", dat)
    s = _write_new(tmp, "sps.sub", sub)
    inputs = _write_new(tmp, "stimuli.yaml", stimuli) if stimuli else None
    rt, _ = make_runtime(run_spec(p, inputs=inputs, max_sim_time=max_sim_time, max_steps=max_steps,
                                  mujoco=False, submit=[s], check=False, interp=interp,
                                  spins=spins_of(enabled, shadow)))
    return rt, rt.run()


def spins_of(enabled: bool, shadow: bool = False) -> str:
    """RunSpec.spins of the spin watch on or not (`enabled`), shadowing (`shadow`)."""
    return "shadow" if shadow else ("park" if enabled else "off")


def same_run(tmp: Path, prog: str, sub: str, dat: str, interp: str, **kw):
    """:func:`run_beside` with and without the spin watch: the I/O log, the end and the steps must
    agree and no catch-up diverge; returns the parked run ``(runtime, result)``."""
    return same_runs(tmp, prog, sub, dat, interp, **kw)[1]


def same_runs(tmp: Path, prog: str, sub: str, dat: str, interp: str, **kw):
    """:func:`same_run`'s two runs, ``((runtime, result) without the watch, (runtime, result)
    parked)``, for a test that reads the unparked run too (no third run for it)."""
    off, r_off = run_beside(tmp, prog, sub, dat, interp=interp, enabled=False, **kw)
    on, r_on = run_beside(tmp, prog, sub, dat, interp=interp, **kw)
    assert on.controller.io.log == off.controller.io.log
    assert (r_on.reason, r_on.file, r_on.line, r_on.sim_time, r_on.steps) == \
        (r_off.reason, r_off.file, r_off.line, r_off.sim_time, r_off.steps)
    sw = on.ff.spin
    assert (sw.diverged, sw.missed) == (0, 0), sw.why
    return (off, r_off), (on, r_on)
