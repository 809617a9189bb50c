"""The controller's IPO cycle as ``krl run`` runs it (issue 86): the CPU of
robot/controller.py ``Controller.step`` per IPO cycle, the cycles where the robot moves apart,
and the whole run's simulated seconds per CPU second, side by side with a baseline checkout.

Each run is ``krl run PROGRAM --inputs CELL --interp vm --max-sim-time S`` in a fresh process
of its checkout (``PYTHONPATH=CHECKOUT`` on this interpreter, as tools/whole_run_bench.py's
workers: the checkouts share this venv's dependencies, each with its own compiled parts), the
command's own entry (app ``main``) in-process, its output discarded; unlike
tools/whole_run_bench.py the MuJoCo arm reads the robot back, as a user's run does. The worker
wraps ``Controller.step`` (``time.process_time`` before and after each call: a moving cycle is
one after whose step ``Controller.is_moving()`` holds) and ``Runtime.run`` (the run's CPU,
the start excluded). The two checkouts alternate run by run (the first to run alternates too),
``--repeat`` times; the figures printed are each side's median and the ratios of the medians.

Usage::

    python tools/ipo_cycle_bench.py --baseline CHECKOUT [--checkout CHECKOUT] [--sim-time 300]
                                    [--repeat 3] [--cell PROGRAM CELL ...] [--json OUT]

Default cells: examples/palletizer5 ``R1/cell.src`` with its ``cell.yaml``, and the corpus
palletizer ingeniado__KRC4-Robot-Palletizer ``main.src`` with ``--inputs auto``. Exit status 0,
2 on bad usage or when a worker fails.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent
CORPUS = HERE.parent / "shared" / "krl-corpus"
#: (program, cell file or "auto") of the default runs
CELLS = ((HERE / "examples" / "palletizer5" / "R1" / "cell.src", str(HERE / "examples" / "palletizer5" / "cell.yaml")),
         (CORPUS / "ingeniado__KRC4-Robot-Palletizer" / "main.src", "auto"))


def worker(checkout: Path, program: str, cell: str, sim_time: float) -> int:
    """One measured ``krl run`` of `program` in this process (the checkout first on sys.path);
    prints one JSON row: ``steps``, ``moving`` (cycles), ``step_s``, ``moving_step_s`` (CPU s in
    Controller.step), ``run_s`` (CPU s of Runtime.run), ``sim_s``."""
    sys.path.insert(0, str(checkout))
    # the checkout's modules, by name once sys.path names it (this file imports none of them)
    main = importlib.import_module("app").main
    Runtime = importlib.import_module("interp.runtime.core").Runtime
    Controller = importlib.import_module("robot.controller").Controller

    got = {"steps": 0, "moving": 0, "step_s": 0.0, "moving_step_s": 0.0, "run_s": 0.0, "sim_s": 0.0}
    step, run, clock = Controller.step, Runtime.run, time.process_time

    def timed_step(ctl):
        c0 = clock()
        out = step(ctl)
        c = clock() - c0
        got["steps"] += 1
        got["step_s"] += c
        if ctl.is_moving():
            got["moving"] += 1
            got["moving_step_s"] += c
        return out

    def timed_run(rt, *a, **kw):
        c0 = clock()
        try:
            return run(rt, *a, **kw)
        finally:
            got["run_s"] += clock() - c0
            got["sim_s"] = rt.controller.time

    Controller.step, Runtime.run = timed_step, timed_run
    args = ["run", program, "--interp", "vm", "--max-sim-time", f"{sim_time:g}"] + ["--inputs", cell]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        try:
            main(args)
        except SystemExit:
            pass
    print(json.dumps(got))
    return 0


def _run(checkout: Path, program: Path, cell: str, sim_time: float) -> dict:
    env = dict(os.environ, PYTHONPATH=str(checkout))
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "worker", str(checkout), str(program), cell,
                          str(sim_time)], cwd=checkout, env=env, capture_output=True, text=True, check=False)
    if out.returncode != 0 or not out.stdout.strip():
        raise SystemExit(f"error: the worker of {checkout} failed: {out.stderr.strip()[-400:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def _figures(rows: list[dict]) -> dict:
    """The medians of the runs' per-cycle costs (us) and rates (simulated s per CPU s)."""
    def med(f):
        return round(statistics.median(f(r) for r in rows), 2)
    return {"step_us": med(lambda r: 1e6 * r["step_s"] / max(r["steps"], 1)),
            "moving_step_us": med(lambda r: 1e6 * r["moving_step_s"] / max(r["moving"], 1)),
            "run_us_per_cycle": med(lambda r: 1e6 * r["run_s"] / max(r["steps"], 1)),
            "sim_per_cpu": med(lambda r: r["sim_s"] / r["run_s"] if r["run_s"] > 0 else 0.0),
            "steps": rows[0]["steps"], "moving": rows[0]["moving"], "sim_s": rows[0]["sim_s"]}


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["worker"]:
        return worker(Path(argv[1]), argv[2], argv[3], float(argv[4]))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", type=Path, required=True, help="the checkout measured side by side (today's main)")
    ap.add_argument("--checkout", type=Path, default=HERE, help="the checkout measured (default: this one)")
    ap.add_argument("--sim-time", type=float, default=300.0, help="simulated seconds of each run (default 300)")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each side per cell (default 3)")
    ap.add_argument("--cell", nargs=2, action="append", metavar=("PROGRAM", "CELL"),
                    help="a run: its program and cell file (or auto); default the two palletizers")
    ap.add_argument("--json", type=Path, help="write the figures here")
    a = ap.parse_args(argv)
    cells = [(Path(p), c) for p, c in a.cell] if a.cell else [(p, c) for p, c in CELLS if p.is_file()]
    sides = {"base": a.baseline.resolve(), "new": a.checkout.resolve()}
    report = []
    print(f"{'cell':28s} {'side':5s} {'step us':>8s} {'moving us':>9s} {'run us/cyc':>10s} {'sim/cpu':>8s}"
          f" {'cycles':>7s} {'moving':>7s}")
    for program, cell in cells:
        rows: dict[str, list[dict]] = {"base": [], "new": []}
        for i in range(a.repeat):
            for side in (("base", "new") if i % 2 == 0 else ("new", "base")):
                rows[side].append(_run(sides[side], program, cell, a.sim_time))
        fig = {side: _figures(rows[side]) for side in rows}
        name = f"{program.parent.name}/{program.name}"[-28:]
        for side in ("base", "new"):
            f = fig[side]
            print(f"{name:28s} {side:5s} {f['step_us']:8.2f} {f['moving_step_us']:9.2f} {f['run_us_per_cycle']:10.2f}"
                  f" {f['sim_per_cpu']:8.1f} {f['steps']:7d} {f['moving']:7d}")
        ratio = {k: round(fig["base"][k] / fig["new"][k], 2) if fig["new"][k] else None
                 for k in ("step_us", "moving_step_us", "run_us_per_cycle")}
        print(f"{name:28s} base/new step {ratio['step_us']}x, moving step {ratio['moving_step_us']}x, "
              f"run {ratio['run_us_per_cycle']}x")
        report.append({"program": str(program), "cell": cell, "figures": fig, "ratio": ratio, "rows": rows})
    if a.json:
        a.json.write_text(json.dumps(report, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
