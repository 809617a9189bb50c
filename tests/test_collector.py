"""The process's one policy on Python's cyclic collector (krl/collector.py).

* Declared once: no module of the project but krl/collector.py pauses, freezes or unfreezes the
  collector, sets its thresholds or asks for the size of its permanent generation (tests may, to
  measure).
* The thresholds are set in every process of the tools: in the `krl` command's, in a worker
  process of krl.pool and in the simulator's benchmark alone, the young threshold is
  krl.collector.YOUNG_THRESHOLD.
* A KRL run neither freezes nor unfreezes: its objects stay in the collector's generations, so
  a process running one run after the other collects the finished ones (a per-run freeze once
  kept a Dask worker of the variants sweep from ever collecting: 9.9 GB, 2026-11-27); in a
  process that keeps frozen objects (the language server, a debug session) they stay frozen.
  Nor does it ask ``gc.get_freeze_count()``, whose cost grows with the permanent generation
  (a walk of it: 0.1 s per call at 6 million objects).
* A forked worker of krl.pool finds what it inherited frozen and keeps it so: in the suite, two
  workers forked by a test worker that held 2.1 million objects of garbage each spent 6-7 s
  of CPU collecting the parent's garbage before this (2026-11-25).
"""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
from pathlib import Path

from tests.test_imports_inside_functions import _files

REPO = Path(__file__).resolve().parents[1]
ONLY_HERE = {"disable", "freeze", "unfreeze", "get_freeze_count", "set_threshold"}
PROGRAM = REPO / "tests" / "vm" / "programs" / "fast" / "fp_errors.src"
#: the name ``gc`` anywhere in a file's text (identifiers are whole words)
_NAMES_GC = re.compile(r"\bgc\b")


def _gc_calls(path: Path) -> list[str]:
    text = path.read_text(encoding="utf-8")
    # a file that never names ``gc`` holds no ``gc.X`` (an attribute of the name gc): not parsed
    # (a cheap first pass: the test 2.0-2.4 -> 0.44-0.48 s of CPU, 2026-11-29)
    if not _NAMES_GC.search(text):
        return []
    tree = ast.parse(text)
    return [f"{path.relative_to(REPO)}:{n.lineno}: gc.{n.attr}" for n in ast.walk(tree)
            if isinstance(n, ast.Attribute) and n.attr in ONLY_HERE
            and isinstance(n.value, ast.Name) and n.value.id == "gc"]


def test_only_the_collector_module_pauses_or_freezes_the_collector():
    files = [p for p in _files() if p.relative_to(REPO).parts[0] != "tests"]
    assert REPO / "krl" / "collector.py" in files
    found = [c for p in files if p != REPO / "krl" / "collector.py" for c in _gc_calls(p)]
    assert not found, "\n".join(found)
    # the scan sees such a call where there is one
    assert _gc_calls(REPO / "krl" / "collector.py")


_CHILD = r"""
import gc, json, sys
from krl import collector
from interp.run import make_runtime, run_spec

def counted():
    gc.collect()
    return gc.get_freeze_count()

if sys.argv[2] == "keep":
    keep_me = [[i] for i in range(1000)]
    collector.keep()
before = counted()
real = gc.get_freeze_count
def refuse():
    raise AssertionError("gc.get_freeze_count() called during the run")
gc.get_freeze_count = refuse
seen = []
rt, _ = make_runtime(run_spec(sys.argv[1], mujoco=False, check=False, max_steps=1000, max_sim_time=1.0))
sched_cycles = rt.scheduler.cycles      # the run's IPO cycles (Runtime.run is their loop)
def probe():
    seen.append(real())
    return sched_cycles()
rt.scheduler.cycles = probe
res = rt.run()
gc.get_freeze_count = real
# an object is frozen when it is tracked and in none of the collector's three generations
in_generations = {id(o) for o in gc.get_objects()}
kept_frozen = sys.argv[2] == "keep" and gc.is_tracked(keep_me[0]) and id(keep_me[0]) not in in_generations
print(json.dumps({"before": before, "during": seen[0], "after": counted(), "reason": res.reason,
                  "enabled": gc.isenabled(), "kept_frozen": kept_frozen}))
"""


def _child(mode: str) -> dict:
    out = subprocess.run([sys.executable, "-c", _CHILD, str(PROGRAM), mode], cwd=REPO, capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_run_freezes_nothing():
    got = _child("plain")
    assert got["before"] == 0
    assert got["during"] == 0            # the front end's and the runtime's objects stay collectable
    assert got["after"] == 0
    assert got["enabled"] is True
    assert got["reason"] in ("completed", "error")


def test_a_run_in_a_process_that_keeps_frozen_objects_leaves_them_frozen():
    got = _child("keep")
    assert got["before"] >= 1000         # the 1000 lists kept, and what was loaded before
    # the run froze nothing more (a frozen object whose last reference goes is freed, so the
    # count may fall) and unfroze nothing: the kept objects are still out of the generations
    assert got["during"] <= got["before"]
    assert got["after"] <= got["before"]
    assert got["kept_frozen"] is True
    assert got["enabled"] is True


_THRESHOLDS = r"""
import gc, json, sys
from app import main
from krl import collector
from krl.pool import run_tasks
try:
    main(["check", sys.argv[1]])
except SystemExit as e:
    assert e.code == 0, e.code
command = gc.get_threshold()
# a worker of a fork server (a fresh interpreter importing its preload) sets it itself
worker = [o.value for o in run_tasks(gc.get_threshold, [(0, ())], jobs=1, preload=("krl.workspace",))]
print(json.dumps({"command": command, "worker": worker, "policy": collector.YOUNG_THRESHOLD}))
"""
# the simulator's benchmark on its own (python -m robot.bench): the robot package sets it itself,
# before anything loads KRL (robot.bench's planner reads machine data, which loads krl.workspace
# since the imports went to the top, issue 62), and the benchmark keeps it
_SIMULATOR = ("import gc, sys, robot; first = (gc.get_threshold()[0], 'krl.workspace' in sys.modules); "
              "import robot.bench; print(*first, gc.get_threshold()[0])")


def test_the_tools_processes_collect_at_the_policys_threshold(tmp_path):
    (tmp_path / "demo.src").write_text("DEF demo()\nEND\n")
    out = subprocess.run([sys.executable, "-c", _THRESHOLDS, str(tmp_path / "demo.src")], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["policy"] == 100_000
    assert got["command"][0] == got["policy"] and got["worker"][0][0] == got["policy"]
    # the older generations keep Python's own thresholds
    assert got["command"][1:] == got["worker"][0][1:] == [10, 10]
    out = subprocess.run([sys.executable, "-c", _SIMULATOR], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == [str(got["policy"]), "False", str(got["policy"])]


_FORKED = r"""
import gc, json
from krl import collector
from krl.pool import run_tasks

inherited = [[i] for i in range(50_000)]       # the parent's objects, tracked by the collector

def child_view(_):
    mine = [[i] for i in range(10)]
    in_generations = {id(o) for o in gc.get_objects()}
    return {"inherited_in_generations": sum(id(o) in in_generations for o in inherited),
            "mine_in_generations": sum(id(o) in in_generations for o in mine),
            "enabled": gc.isenabled()}

in_generations = {id(o) for o in gc.get_objects()}
parent = sum(id(o) in in_generations for o in inherited)
out = [o.value if o.status == "done" else o.detail for o in run_tasks(child_view, [(k, (k,)) for k in range(2)], jobs=2)]
print(json.dumps({"parent": parent, "children": out}))
"""


def test_a_forked_worker_leaves_what_it_inherited_out_of_its_collections():
    """A pool worker (forked) finds its parent's objects frozen and keeps them so: its
    collections walk only what it makes. The parent's own objects stay in its generations."""
    out = subprocess.run([sys.executable, "-c", _FORKED], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["parent"] == 50_000
    assert got["children"] == [{"inherited_in_generations": 0, "mine_in_generations": 10,
                                "enabled": True}] * 2


_MANY = r"""
import gc, json, sys, weakref
from interp.run import make_runtime, run_spec

# after the imports (krl.collector raises a lower threshold to its own): a young collection
# every few runs here
gc.set_threshold(10_000, *gc.get_threshold()[1:])
refs = []
for _ in range(int(sys.argv[2])):
    rt, _interp = make_runtime(run_spec(sys.argv[1], mujoco=False, check=False, max_steps=1000, max_sim_time=1.0))
    rt.run()
    refs.append(weakref.ref(rt.scheduler))      # the runtime has slots; its scheduler refers back to it
    del rt, _interp
print(json.dumps({"alive": sum(r() is not None for r in refs), "runs": len(refs)}))
"""


def test_runs_one_after_the_other_leave_no_garbage_behind():
    """Many runs in one process that keeps nothing frozen (a Dask worker of the variants sweep, a
    test worker, `krl report --jobs 1`): a finished run's objects (reference cycles: a runtime's
    parts refer to it) are collected without anyone calling gc.collect(). When each run froze
    its set-up, the freeze reset the young generation's count, so no collection ever ran
    between runs: a Dask worker of the whole variants sweep grew by about 100 MB a variant to
    9.9 GB, paused at 80 % of its memory limit, and the sweep stopped (2026-11-27). Here the
    young threshold is 10,000 objects; a run of this program leaves about 2,400."""
    out = subprocess.run([sys.executable, "-c", _MANY, str(PROGRAM), "40"], cwd=REPO, capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["runs"] == 40
    # left: the runs since the last young collection, and those a young collection found alive
    # (moved to the middle generation, collected with it every ten young ones); before: all 40
    assert got["alive"] <= 20, got

