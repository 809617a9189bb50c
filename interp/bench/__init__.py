"""The compute benchmark of `krl bench` (docs/architecture.md, "Bytecode VM", "Benchmark").

:func:`compute` runs bench.src on the tree interpreter and on the VM, and the same work
hand-written in Python (bench.py), in this process, interleaved, ``repeat`` times each,
and reports the best time of each. Statements per second count the runtime's steps
(statements and loop iterations, the same number on both interpreters); the Python
figure is that count divided by the Python time.
"""

from __future__ import annotations

import re
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
PROGRAM = HERE / "bench.src"


def rounds(program: Path = PROGRAM) -> int:
    """The benchmark's ``ROUNDS`` (its data list, bench.dat), for the Python version."""
    m = re.search(r"DECL\s+INT\s+ROUNDS\s*=\s*(\d+)", program.with_suffix(".dat").read_text(), re.I)
    if m is None:
        raise RuntimeError(f"no DECL INT ROUNDS = n in {program.with_suffix('.dat')}")
    return int(m.group(1))


def run_krl(interp: str, program: Path = PROGRAM):
    """One run: (seconds, steps, (CHECK_I, CHECK_R))."""
    from interp.run import make_runtime  # noqa: PLC0415

    rt, _ = make_runtime(program, mujoco=False, max_steps=10 ** 9, interp=interp)
    t0 = time.perf_counter()
    res = rt.run()
    dt = time.perf_counter() - t0
    if res.reason != "completed":
        raise RuntimeError(f"benchmark did not complete on {interp}: {res.reason} {res.text} line {res.line}")
    m = rt.program.module(program.stem)
    return dt, rt.steps, (m.data["CHECK_I"].get(), m.data["CHECK_R"].get())


def run_python(loops: int = 20):
    """The Python version, ``loops`` times (it is too fast to time once): (seconds per
    run, result)."""
    from . import bench as py  # noqa: PLC0415

    n = rounds()
    t0 = time.perf_counter()
    for _ in range(loops):
        got = py.bench(n)
    return (time.perf_counter() - t0) / loops, got


def compute(repeat: int = 3) -> dict:
    """Best-of-``repeat`` times of tree, VM and Python; ratios and statement rates."""
    best = {"tree": None, "vm": None, "python": None}
    steps = None
    checks = {}
    for _ in range(repeat):
        for kind in ("tree", "vm"):
            dt, n, check = run_krl(kind)
            steps = n
            checks[kind] = check
            best[kind] = dt if best[kind] is None else min(best[kind], dt)
        dt, check = run_python()
        checks["python"] = check
        best["python"] = dt if best["python"] is None else min(best["python"], dt)
    if not (checks["tree"] == checks["vm"] == checks["python"]):
        raise RuntimeError(f"benchmark results differ: {checks}")
    return {
        "steps": steps,
        "tree_s": best["tree"], "vm_s": best["vm"], "python_s": best["python"],
        "vm_vs_tree": best["tree"] / best["vm"],
        "tree_stmts_per_s": steps / best["tree"],
        "vm_stmts_per_s": steps / best["vm"],
        "python_stmts_per_s": steps / best["python"],
        "python_vs_vm": best["vm"] / best["python"],
    }
