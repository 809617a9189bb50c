"""Run small KRL programs for the interpreter tests."""

from __future__ import annotations

import textwrap
from pathlib import Path

from interp.run import make_runtime, run_spec
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


def write(tmp: Path, name: str, text: str) -> Path:
    """Write `text` (dedented) to ``tmp/name``, making its folders."""
    p = tmp / name
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(textwrap.dedent(text).lstrip("\n"), encoding="utf-8")
    return p


def run_krl(tmp: Path, src: str, dat: str | None = None, name: str = "prog", *, files: dict | None = None,
            stimuli: str | None = None, max_sim_time: float = 60.0, max_steps: int = 2_000_000,
            submit: list | None = None, before=None, trace: bool = True, interp: str = "tree") -> Run:
    """Write ``name``.src (and .dat) into ``tmp``, run it on the tree interpreter (or
    ``interp="vm"``)."""
    prog = write(tmp, f"{name}.src", src)
    if dat is not None:
        write(tmp, f"{name}.dat", dat)
    for fname, text in (files or {}).items():
        write(tmp, fname, text)
    inputs = None
    if stimuli is not None:
        inputs = write(tmp, "stimuli.yaml", stimuli)
    tw = TraceWriter(keep=True) if trace else None
    rt, _ = make_runtime(run_spec(prog, inputs=inputs, trace=tw, max_sim_time=max_sim_time, max_steps=max_steps,
                         mujoco=False, submit=[tmp / s for s in (submit or [])],
                         check=False, interp=interp))   # run-time semantics, errors included (krl run --no-check)
    if before is not None:
        before(rt)
    res = rt.run()
    return Run(rt, res, tw)
