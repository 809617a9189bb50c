"""The compute benchmark of `krl bench` (docs/architecture.md, "Bytecode VM", "Benchmark").

:func:`compute` runs bench.src on the tree interpreter and on the VM, and the same work
hand-written in Python (bench.py), in this process, interleaved, ``repeat`` times each,
and reports the best time of each. Statements per second count the runtime's steps
(statements and loop iterations, the same number on both interpreters); the Python
figure is that count divided by the Python time.
"""

from __future__ import annotations

import json
import os
import re
import sys
import time
from pathlib import Path

from krl.cbuild import OTHER_CHECKOUT_PRELUDE

from . import bench as py
from interp.run import make_runtime, run_spec
from interp.vm.vm import COMPILED
import shutil
import subprocess
import tempfile

HERE = Path(__file__).resolve().parent
PROGRAM = HERE / "bench.src"


def rounds(program: Path = PROGRAM) -> int:
    """The benchmark's ``ROUNDS`` (its data list, bench.dat), for the Python version."""
    m = re.search(r"DECL\s+INT\s+ROUNDS\s*=\s*(\d+)", program.with_suffix(".dat").read_text(), re.I)
    if m is None:
        raise RuntimeError(f"no DECL INT ROUNDS = n in {program.with_suffix('.dat')}")
    return int(m.group(1))


def run_krl(interp: str, program: Path = PROGRAM, clock=None):
    """One run: (seconds, steps, (CHECK_I, CHECK_R)); seconds of `clock` (default
    time.perf_counter, wall time; time.process_time: this process's CPU time)."""
    clock = clock or time.perf_counter

    rt, _ = make_runtime(run_spec(program, mujoco=False, max_steps=10 ** 9, interp=interp))
    t0 = clock()
    res = rt.run()
    dt = clock() - t0
    if res.reason != "completed":
        raise RuntimeError(f"benchmark did not complete on {interp}: {res.reason} {res.text} line {res.line}")
    m = rt.program.module(program.stem)
    return dt, rt.clock.steps, (m.data["CHECK_I"].get(), m.data["CHECK_R"].get())


def run_python(loops: int = 20, clock=None):
    """The Python version, ``loops`` times (it is too fast to time once): (seconds per
    run, result); seconds of `clock` as in :func:`run_krl`."""
    clock = clock or time.perf_counter
    n = rounds()
    t0 = clock()
    for _ in range(loops):
        got = py.bench(n)
    return (clock() - t0) / loops, got


# the starting commit of issue 23: the tree interpreter must stay at least as fast as there
BASELINE_REV = "89ac166"

# CPU mode: every revision's run_krl times with time.perf_counter, so this fresh process,
# which runs only the benchmark, reads the CPU clock there
_BASELINE_SNIPPET = OTHER_CHECKOUT_PRELUDE + """
import json, sys, time
if sys.argv[1] == "cpu":
    time.perf_counter = time.process_time
try:
    from interp.bench import run_krl            # the layout since issue 23
except ImportError:
    from interp.vm.bench import run_krl         # before it
out = {}
for kind in ("tree", "vm"):
    dt, steps, check = run_krl(kind)
    out[kind] = [dt, steps, [check[0], check[1]]]
try:
    from interp.vm.vm import COMPILED
except ImportError:                             # a revision before the compiled loop
    COMPILED = False
out["vm_loop"] = "compiled" if COMPILED else "python"
print(json.dumps(out))
"""

# compiles the revision's own VM loop (interp/vm/build.py, since issue 23) and simulator hot path
# (robot/build.py, since issue 39) where it has them
_BASELINE_BUILD = OTHER_CHECKOUT_PRELUDE + """
out = []
for name in ("interp.vm.build", "robot.build"):
    try:
        module = __import__(name, fromlist=["build"])
    except ImportError:
        continue
    out.append(module.build())
print("; ".join(out) or "no build")
"""


class BaselineError(RuntimeError):
    """The baseline revision cannot be checked out (not a revision of this repository)."""


class Baseline:
    """The tree interpreter and the VM of another revision of this repository (``rev``), run
    side by side with this one: a temporary ``git worktree`` of ``rev`` (with this checkout's
    generated parser: the grammar is the same; its own VM loop compiled there by its own
    interp/vm/build.py where it has one), each run a fresh process whose Python path is that
    worktree; the time is measured inside it, as :func:`run_krl` measures. Use as a context
    manager; the worktree is removed afterwards. Raises :class:`BaselineError` when ``rev`` is not
    a revision of this repository."""

    def __init__(self, rev: str = BASELINE_REV) -> None:
        self.rev = rev
        self.dir = None

    def __enter__(self) -> "Baseline":

        repo = HERE.parents[1]
        self.dir = Path(tempfile.mkdtemp(prefix="krl-baseline-")) / "tree"
        made = subprocess.run(["git", "-C", str(repo), "worktree", "add", "--detach", str(self.dir), self.rev],
                              capture_output=True, text=True)
        if made.returncode != 0:
            shutil.rmtree(self.dir.parent, ignore_errors=True)
            why = (made.stderr.strip().splitlines() or ["git worktree add failed"])[-1]
            raise BaselineError(f"--baseline {self.rev!r} is not a revision of this repository "
                                f"(a commit, tag or branch, not a folder): {why}")
        gen = repo / "krl" / "syntax" / "generated"
        shutil.copytree(gen, self.dir / "krl" / "syntax" / "generated", dirs_exist_ok=True,
                        ignore=shutil.ignore_patterns("__pycache__"))
        self._python(_BASELINE_BUILD)
        return self

    def __exit__(self, *exc) -> None:

        repo = HERE.parents[1]
        subprocess.run(["git", "-C", str(repo), "worktree", "remove", "--force", str(self.dir)],
                       capture_output=True, text=True)
        shutil.rmtree(self.dir.parent, ignore_errors=True)

    def _python(self, code: str, *args: str) -> str:
        """Run `code` (with `args` in sys.argv[1:]) in a fresh process on that revision; its
        output's last line. Raises RuntimeError when it fails."""
        env = dict(os.environ, PYTHONPATH=str(self.dir))
        p = subprocess.run([sys.executable, "-c", code, *args], cwd=self.dir, env=env,
                           capture_output=True, text=True, timeout=3600)
        if p.returncode != 0:
            raise RuntimeError(f"baseline {self.rev} failed: {p.stderr[-2000:]}")
        return p.stdout.strip().splitlines()[-1]

    def run(self, cpu: bool = False) -> dict:
        """One run of the benchmark on that revision's tree interpreter and VM: ``{"tree":
        (seconds, steps, (CHECK_I, CHECK_R)), "vm": (...), "vm_loop": "compiled" | "python"}``;
        `cpu`: seconds of the process's CPU time instead of wall time."""
        got = json.loads(self._python(_BASELINE_SNIPPET, "cpu" if cpu else "wall"))
        out = {kind: (got[kind][0], got[kind][1], tuple(got[kind][2])) for kind in ("tree", "vm")}
        out["vm_loop"] = got["vm_loop"]
        return out


#: at most this many timed VM runs per round of :func:`compute`
VM_RUNS_PER_ROUND = 8


def compute(repeat: int = 3, baseline: Baseline | None = None, cpu: bool = False) -> dict:
    """Best-of-``repeat`` times of tree, VM and Python (the VM's best over up to
    ``VM_RUNS_PER_ROUND`` runs per round, as many as fit in the tree's time of the round; and,
    with `baseline`, the tree interpreter and the VM of another revision), interleaved in this run; `cpu`: each time is
    the CPU time of the process that runs it (time.process_time), which a shared machine's
    load disturbs far less than wall time (``clock`` in the result says which); ratios and statement rates,
    and ``vm_loop``: which dispatch loop the VM ran ("compiled": the Cython build of
    interp/vm/loop.py; "python": loop.py itself, when no current build exists)."""
    best = {"tree": None, "vm": None, "python": None, "baseline": None, "baseline_vm": None}
    baseline_loop = None
    clock = time.process_time if cpu else time.perf_counter
    steps = None
    checks = {}
    for _ in range(repeat):
        # the VM's run is short (tens of ms), so one round times it as often as its time fits
        # in the tree interpreter's run of that round (at most VM_RUNS_PER_ROUND times): both
        # best times are then taken over about the same measured time, as timeit does
        tree_dt, steps, checks["tree"] = run_krl("tree", clock=clock)
        best["tree"] = tree_dt if best["tree"] is None else min(best["tree"], tree_dt)
        runs = 1 if best["vm"] is None else max(1, min(VM_RUNS_PER_ROUND, int(tree_dt / max(best["vm"], 1e-9))))
        for _ in range(runs):
            dt, steps, checks["vm"] = run_krl("vm", clock=clock)
            best["vm"] = dt if best["vm"] is None else min(best["vm"], dt)
        dt, check = run_python(clock=clock)
        checks["python"] = check
        best["python"] = dt if best["python"] is None else min(best["python"], dt)
        if baseline is not None:
            got = baseline.run(cpu)
            baseline_loop = got["vm_loop"]
            for kind, key in (("tree", "baseline"), ("vm", "baseline_vm")):
                dt, n, check = got[kind]
                if n != steps:
                    raise RuntimeError(f"baseline {baseline.rev} counts {n} steps on its {kind}, this tree {steps}")
                checks[key] = check
                best[key] = dt if best[key] is None else min(best[key], dt)
    if len({checks[k] for k in checks}) != 1:
        raise RuntimeError(f"benchmark results differ: {checks}")

    out = {
        "steps": steps, "clock": "cpu" if cpu else "wall",
        "vm_loop": "compiled" if COMPILED else "python",
        "tree_s": best["tree"], "vm_s": best["vm"], "python_s": best["python"],
        "vm_vs_tree": best["tree"] / best["vm"],
        "tree_stmts_per_s": steps / best["tree"],
        "vm_stmts_per_s": steps / best["vm"],
        "python_stmts_per_s": steps / best["python"],
        "python_vs_vm": best["vm"] / best["python"],
    }
    if baseline is not None:
        out.update({"baseline_rev": baseline.rev, "baseline_tree_s": best["baseline"],
                    "tree_vs_baseline": best["baseline"] / best["tree"],
                    "baseline_vm_s": best["baseline_vm"], "baseline_vm_loop": baseline_loop,
                    "vm_vs_baseline": best["baseline_vm"] / best["vm"]})
    return out
