"""Run a program on both interpreters and compare the traces event for event."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from interp.realprograms import DEFAULT_CORPUS, find_backups, programs_of
from interp.run import make_runtime, run_spec, RunSinks
from robot.trace import TraceWriter

REPO = Path(__file__).resolve().parents[2]
PAPER = REPO.parent / "shared" / "examples" / "paper_fig1.src"
CORPUS = sorted((REPO / "corpus" / "programs").glob("*.src"))
CASES = sorted((REPO / "conformance" / "cases").glob("*/program.src"))

#: the tests of make test that load the corpus's first backup (HugoDanielson__ChinaMilling/KRC)
#: run on one worker (--dist loadgroup), which checks it once (interp/runtime/program.py
#: ``checked_workspace``): tests/vm/test_assembler.py's round trip of its routines and
#: tests/vm/test_differential.py's shard 4 of the real programs (3 of them). In one process the
#: shard took 9.4 instead of 12.4 s of CPU after the round trip (2026-11-29)
FIRST_BACKUP = pytest.mark.xdist_group("corpus-first-backup")


def run_trace(program: Path, interp: str, *, inputs=None, submit=(), before=None, max_sim_time=30.0,
              max_steps=2_000_000):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(program, inputs=inputs, max_sim_time=max_sim_time, max_steps=max_steps,
                         mujoco=False, submit=list(submit), interp=interp, check=False), RunSinks(trace=tw))
    if before is not None:
        before(rt)
    res = rt.run()
    tw.close()
    return res, tw.events


def real_programs() -> list:
    """The main programs of the KRC backups in ../shared/krl-corpus ([] when it is absent)."""
    if not DEFAULT_CORPUS.is_dir():
        return []
    out = []
    for b in find_backups(DEFAULT_CORPUS):
        out += programs_of(b)
    return out


def case_options(program: Path) -> dict:
    d = program.parent
    kw: dict = {}
    exp = d / "expect.yaml"
    if exp.exists():
        e = yaml.load(exp.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader)) or {}   # at collection
        if e.get("submit"):
            kw["submit"] = [d / e["submit"]]
        if e.get("max_sim_time"):
            kw["max_sim_time"] = float(e["max_sim_time"])
        else:
            kw["max_sim_time"] = 10.0
    if (d / "stimuli.yaml").exists():
        kw["inputs"] = d / "stimuli.yaml"
    return kw


def first_difference(a: list, b: list):
    """None if the event lists are equal, else (index, event a, event b)."""
    for i, (x, y) in enumerate(zip(a, b)):
        if x != y:
            return i, x, y
    if len(a) != len(b):
        i = min(len(a), len(b))
        return i, a[i] if i < len(a) else None, b[i] if i < len(b) else None
    return None


def compare(program: Path, **kw):
    rt_res, tree_ev = run_trace(program, "tree", **kw)
    vm_res, vm_ev = run_trace(program, "vm", **kw)
    return (rt_res, vm_res), first_difference(tree_ev, vm_ev), len(tree_ev)
