"""Each entry point of a corpus as two robots of one cell, against its run alone (issue 89: a robot
of a cell that nothing couples runs as it runs alone; "as fast per robot as one robot alone").

For every entry point (interp/realprograms.py ``find_backups``, ``entries_of``) a cell file of two
robots running it (R2 facing R1 ``--spacing`` mm away on X, ``inputs: auto``, the backup as the
workspace, MuJoCo on) is run untraced (interp/robotcell.py ``cell_runs``, ``run_cell``), and the
program once alone with the cell's own options for its robot (``_options``: what ``krl run`` of
the program with ``--inputs auto`` gives). Nothing couples the two robots (no wire, PLC or zone;
a collision is reported, never acted on), so each robot's I/O log (robot/io.py ``IOImage.log``:
time, signal, value, source) and end (reason, simulated time, line) must be its run alone's.

``--speed T1,T2``: for the entry points whose cell ran to its limit, the CPU time
(``time.process_time``) of the run phase at T1 and at T2 s simulated, for the cell and for its
two robots alone one after the other, each the least of ``--repeat`` runs after one untimed run
of each (a program's first run in a process fills caches its later runs share); the steady cost
is T2's less T1's (start-up and the cell's scene build cancel), and the ratio alone / cell is
per robot / alone (1: a robot in the cell costs what it costs alone; an entry point whose steady
cost is not positive, cell or alone, gives no ratio and is left out of the pooled one). CPU
times on a shared host spread by 10-25 % a run: a single entry point's ratio is a rough figure,
the pooled one over many is the measure.

Usage::

    python tools/cell_pairs.py [--corpus DIR] [--spacing 2000] [--sim-time 20] [--interp vm|tree]
                               [--only SUBSTRING] [--speed T1,T2 [--repeat 3]] [--json OUT]

Exit status 1 when some robot's run differs from its run alone (or a cell failed to run), else 0.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

from interp.realprograms import entries_of, find_backups
from interp.robotcell import _options, cell_runs, load_robot_cell, run_cell
from interp.run import RunSinks, make_runtime, run_setup
from krl.terminal import printable

#: the corpus read by default (the project's shared test data, read in place)
DEFAULT_CORPUS = Path(__file__).resolve().parents[2] / "shared" / "krl-corpus"


def cell_text(program: Path, workspace: Path, spacing: float) -> str:
    """The cell file of two robots running `program` (its backup `workspace`), R2 facing R1
    `spacing` mm away on X, both ``inputs: auto``."""
    return "robots:\n" + "".join(
        f"  R{k}: {{program: {json.dumps(str(program))}, workspace: {json.dumps(str(workspace))}, inputs: auto, "
        f"base: [{spacing * (k - 1)}, 0, 0, {180 * (k - 1)}, 0, 0]}}\n" for k in (1, 2))


def _io(ctl) -> list:
    return [[round(t, 6), s, round(v, 9) if isinstance(v, float) else v, src] for t, s, v, src, *_ in ctl.io.log]


def _end(res) -> list:
    return [res.reason, round(res.sim_time, 6), res.line]


def compare(cell_file: Path, interp: str, sim: float) -> dict:
    """The cell `cell_file` run untraced for `sim` s, each robot against its robot's program alone
    (module docstring): ``{"same": [bool per robot], "cell": reason, "alone": end, "io": events
    alone, "first": [alone's, the cell's] first differing I/O event of the first robot that
    differs (or None)}``."""
    cell = load_robot_cell(cell_file)
    with cell_runs(cell, interp, sim) as runs:
        res = run_cell(cell, runs)
        got = [(_io(r.runtime.controller), _end(r.runtime.result)) for r in runs]
    with run_setup(_options(cell.robots[0], interp, sim, None)) as setup:
        rt, _ = make_runtime(setup.spec, RunSinks())
        end = _end(rt.run())
        alone = (_io(rt.controller), end)
    row = {"same": [g == alone for g in got], "cell": res.reason, "alone": alone[1], "io": len(alone[0]),
           "first": None}
    for g in got:
        if g != alone:
            a, b = alone[0], g[0]
            i = next((i for i, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b)))
            row["first"] = [a[i] if i < len(a) else alone[1], b[i] if i < len(b) else g[1]]
            break
    return row


def _cpu_cell(cell_file: Path, interp: str, sim: float) -> float:
    cell = load_robot_cell(cell_file)
    with cell_runs(cell, interp, sim) as runs:
        t0 = time.process_time()
        run_cell(cell, runs)
        return time.process_time() - t0


def _cpu_alone(cell_file: Path, interp: str, sim: float) -> float:
    cell = load_robot_cell(cell_file)
    cpu = 0.0
    for robot in cell.robots:
        with run_setup(_options(robot, interp, sim, None)) as setup:
            rt, _ = make_runtime(setup.spec, RunSinks())
            t0 = time.process_time()
            rt.run()
            cpu += time.process_time() - t0
    return cpu


def steady(cell_file: Path, interp: str, t1: float, t2: float, repeat: int) -> dict:
    """The steady CPU cost (s) of `t2` - `t1` simulated seconds of the cell and of its robots
    alone (module docstring): ``{"cell": s, "alone": s, "ratio": alone / cell}``."""
    _cpu_cell(cell_file, interp, t1)
    _cpu_alone(cell_file, interp, t1)
    out = {}
    for name, fn in (("cell", _cpu_cell), ("alone", _cpu_alone)):
        out[name] = min(fn(cell_file, interp, t2) for _ in range(repeat)) - \
            min(fn(cell_file, interp, t1) for _ in range(repeat))
    out["ratio"] = out["alone"] / out["cell"] if out["cell"] > 0 < out["alone"] else None
    return out


def pooled(rows: dict) -> tuple[float, float, int, int]:
    """The steady CPU costs of `rows` (entry point -> its row, ``speed`` as :func:`steady` gives
    it) summed: (cell s, alone s, entry points summed, entry points left out): only those whose
    steady cost is positive both ways (one that is not, a run whose cost did not grow from T1 to
    T2 within the CPU clock's spread, gives no ratio)."""
    timed = [r["speed"] for r in rows.values() if r.get("speed")]
    kept = [s for s in timed if s["cell"] > 0 < s["alone"]]
    return sum(s["cell"] for s in kept), sum(s["alone"] for s in kept), len(kept), len(timed) - len(kept)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--corpus", type=Path, default=DEFAULT_CORPUS)
    ap.add_argument("--spacing", type=float, default=2000.0, help="mm between the two robots' bases")
    ap.add_argument("--sim-time", type=float, default=20.0, help="simulated s of each run compared")
    ap.add_argument("--interp", choices=("vm", "tree"), default="vm")
    ap.add_argument("--only", help="the entry points whose path holds this")
    ap.add_argument("--speed", metavar="T1,T2", help="also the steady CPU cost of the entry points that ran to the limit")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    times = tuple(float(x) for x in args.speed.split(",")) if args.speed else None
    rows: dict[str, dict] = {}
    with tempfile.TemporaryDirectory() as tmp:
        cell_file = Path(tmp) / "cell.yaml"
        for root in find_backups(args.corpus):
            for program in entries_of(root):
                key = str(program.relative_to(args.corpus))
                if args.only and args.only not in key:
                    continue
                cell_file.write_text(cell_text(program, root, args.spacing), encoding="utf-8")
                try:
                    row = compare(cell_file, args.interp, args.sim_time)
                    if times and all(row["same"]) and row["cell"] == "max_sim_time":
                        row["speed"] = steady(cell_file, args.interp, times[0], times[1], args.repeat)
                except Exception as exc:        # one entry point's failure is its row's, the sweep goes on
                    row = {"error": f"{type(exc).__name__}: {exc}"}
                rows[key] = row
                speed = row.get("speed")
                print(printable(key), row.get("error") or ("same" if all(row["same"]) else f"DIFFERS {row['first']}"),
                      "" if "error" in row else f"{row['alone'][0]} at {row['alone'][1]} s, {row['io']} I/O",
                      f"per robot / alone {speed['ratio']:.3f}" if speed and speed["ratio"] else "", flush=True)
    bad = [k for k, r in rows.items() if "error" in r or not all(r["same"])]
    print(f"{len(rows) - len(bad)} of {len(rows)} entry points: each robot of the two-robot cell as its run alone")
    cell_s, alone_s, n, left = pooled(rows)
    if n:
        print(f"steady CPU {times[1] - times[0]:g} s simulated, {n} entry points: cell {cell_s:.2f} s, "
              f"alone {alone_s:.2f} s, per robot / alone {alone_s / cell_s:.3f} (pooled)"
              + (f"; {left} left out, a steady cost not positive" if left else ""))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1), encoding="utf-8")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
