"""The speed of a cell of several robots (issue 89: "a cell of four robots runs at least 100x real
time per CPU second when idle and as fast per robot as one robot alone when moving"), side by
side with one robot alone, in one process.

Cells written here (interp/robotcell.py's cell file, the KR 6 R900 of a program without a
backup, MuJoCo on as ``krl run`` has it):

* **idle**: R1 toggles ``$OUT[5]`` every 30 s; R2..R4, wired to it, follow it in ``WAIT FOR``
  and answer on ``$OUT[6]``; against R1's program alone;
* **moving**: four robots each cycling two PTPs and a LIN (each its own A1 amplitude); against
  each robot's own program alone, one after the other (their CPU times added: the work the cell's
  four robots do, done by four single runs).

"Alone" is a single run as ``krl run`` makes it (interp/run.py ``run_setup``, ``make_runtime``,
``Runtime.run``), not a cell of one robot (before issue 89's last session the moving cell was
set against R1's program alone in a one-robot cell, which carries the cell's per-cycle watches,
and R2..R4 move farther than R1).

The robots stand ``--spacing`` mm apart on X (``base``, default 2,000): every cycle in which a
robot moved the cell checks its robots' bodies against each other in its one MuJoCo scene
(interp/cellcontacts.py), unless no two robots are within reach of each other
(robot/cellscene.py ``_pairs_in_reach``: for two KR 6 R900, farther apart than 2.99 m), when
the check is skipped.

Each run's CPU time (``time.process_time``: the cell's build, each robot's program read and
MuJoCo model made, and the run; the build's share printed) gives simulated seconds per CPU second (per robot for the moving cell: robots x simulated s / CPU s). Best of
``--repeat``, the cell and the single robot alternating.

Usage::

    python tools/cell_bench.py [--sim-time 600] [--moving-time 120] [--repeat 3] [--interp vm|tree]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from interp.robotcell import cell_runs, load_robot_cell, run_cell
from interp.run import RunSinks, make_runtime, run_setup

TOGGLE = """DEF r1()
  LOOP
    WAIT SEC 30
    $OUT[5] = NOT $OUT[5]
  ENDLOOP
END
"""
FOLLOW = """DEF r{k}()
  LOOP
    WAIT FOR $IN[5]
    $OUT[6] = TRUE
    WAIT FOR NOT $IN[5]
    $OUT[6] = FALSE
  ENDLOOP
END
"""
MOVE = """DEF r{k}()
  PTP {{A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}}
  LOOP
    PTP {{A1 {a}, A2 -80, A3 100, A4 0, A5 45, A6 0}}
    LIN {{X 500, Y 100, Z 700, A 0, B 90, C 0}}
    PTP {{A1 -{a}, A2 -95, A3 85, A4 10, A5 30, A6 0}}
  ENDLOOP
END
"""


def _write(folder: Path, name: str, programs: dict[str, str], wires: list[str], spacing: float = 2000.0) -> Path:
    """The cell `name` in a folder of its own below `folder`: its programs and cell file."""
    folder = folder / name
    folder.mkdir()
    for robot, text in programs.items():
        (folder / f"{robot.lower()}.src").write_text(text, encoding="utf-8")
    # the robots `spacing` mm apart on X (a cell's robots stand apart: interp/cellcontacts.py checks
    # that their bodies do not meet; in one place every pair would touch in every cycle)
    lines = ["robots:"] + [f"  {r}: {{program: {r.lower()}.src, no_submit: true, base: [{spacing * k}, 0, 0, 0, 0, 0]}}"
                           for k, r in enumerate(programs)]
    if wires:
        lines += ["wires:"] + [f"  - {w}" for w in wires]
    path = folder / f"{name}.yaml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _measure(path: Path, interp: str, sim_time: float) -> tuple[float, float, str, float]:
    """(CPU s, simulated s, end, CPU s of the build alone) of the cell `path` run for `sim_time`."""
    t0 = time.process_time()
    cell = load_robot_cell(path)
    with cell_runs(cell, interp, sim_time) as runs:
        built = time.process_time() - t0
        res = run_cell(cell, runs)
    return time.process_time() - t0, res.time, res.reason, built


def _alone(programs: list[Path], interp: str, sim_time: float) -> tuple[float, float, str, float]:
    """(CPU s, simulated s, end, CPU s of the builds alone) of each program run alone for
    `sim_time` as ``krl run`` runs it (MuJoCo on, no submit interpreter), one after the other:
    the CPU times added, the simulated time each's."""
    cpu = built = 0.0
    for program in programs:
        t0 = time.process_time()
        with run_setup({"program": program, "interp_kind": interp, "max_sim_time": sim_time,
                        "no_submit": True}) as setup:
            rt, _ = make_runtime(setup.spec, RunSinks())
            built += time.process_time() - t0
            res = rt.run()
        cpu += time.process_time() - t0
    return cpu, res.sim_time, res.reason, built


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sim-time", type=float, default=600.0, help="the idle cells' simulated time (s)")
    ap.add_argument("--moving-time", type=float, default=120.0, help="the moving cells' simulated time (s)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--interp", choices=("vm", "tree"), default="vm")
    ap.add_argument("--spacing", type=float, default=2000.0, help="mm between the robots' bases on X")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="krl-cell-bench-") as tmp:
        folder = Path(tmp)
        idle4 = _write(folder, "idle4", {"R1": TOGGLE, **{f"R{k}": FOLLOW.format(k=k) for k in (2, 3, 4)}},
                       [f"R1 $OUT[5] -> R{k} $IN[5]" for k in (2, 3, 4)])
        move4 = _write(folder, "move4", {f"R{k}": MOVE.format(k=k, a=20 + 5 * k) for k in (1, 2, 3, 4)}, [],
                       args.spacing)
        rows = []
        for what, cell, alone, sim, robots in (("idle", idle4, [idle4.parent / "r1.src"], args.sim_time, 4),
                                               ("moving", move4, [move4.parent / f"r{k}.src" for k in (1, 2, 3, 4)],
                                                args.moving_time, 4)):
            best_cell = best_alone = None
            for _ in range(args.repeat):
                c = _measure(cell, args.interp, sim)
                a = _alone(alone, args.interp, sim)
                best_cell = c if best_cell is None or c[0] < best_cell[0] else best_cell
                best_alone = a if best_alone is None or a[0] < best_alone[0] else best_alone
            per_robot = robots * best_cell[1] / best_cell[0]
            single = len(alone) * best_alone[1] / best_alone[0]
            rows.append((what, best_cell, best_alone, best_cell[1] / best_cell[0], per_robot, single))
        print(f"cells of four robots ({args.interp}, {args.spacing:.0f} mm apart), best of {args.repeat}, "
              "x real time per CPU second:")
        for what, c, a, whole, per_robot, single in rows:
            print(f"  {what:<7} four robots {whole:8.1f}x as a cell, {per_robot:8.1f}x per robot "
                  f"({c[0]:.2f} s CPU for {c[1]:.0f} s, {c[3]:.2f} of it the build, {c[2]}); each robot's program "
                  f"alone {single:8.1f}x ({a[0]:.2f} s CPU, {a[3]:.2f} the builds, {a[2]}); per robot / alone "
                  f"{per_robot / single:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
