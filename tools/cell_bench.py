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
* **moving, wired** (``--wired``): the moving robots in a chain, R1 -> R2 -> R3 -> R4: each copies
  its ``$IN[20]`` to ``$OUT[21]`` in every loop and toggles its ``$OUT[20]``, its successor's
  ``$IN[20]`` (docs/cells.md "Wires in turns": before 2026-11-29 a wired cell ran cycle by cycle);
  against each program alone (no partner: its input stays FALSE, its motions are the same).

"Alone" is a single run as ``krl run`` makes it (interp/run.py ``run_setup``, ``make_runtime``,
``Runtime.run``), not a cell of one robot (before issue 89's last session the moving cell was
set against R1's program alone in a one-robot cell, which carries the cell's per-cycle watches,
and R2..R4 move farther than R1).

The robots stand ``--spacing`` mm apart on X (``base``, default 2,000): every cycle in which a
robot moved the cell checks its robots' bodies against each other in its one MuJoCo scene
(interp/cellcontacts.py), unless no two robots are within reach of each other
(robot/cellscene.py ``pairs_in_reach``: for two KR 6 R900, farther apart than 2.99 m), when
the check is skipped and no scene is built.

Each run's CPU time (``time.process_time``: the cell's build, each robot's program read and
MuJoCo model made, and the run; the build's share printed) gives simulated seconds per CPU second
(per robot for the moving cell: robots x simulated s / CPU s). ``--repeat`` repetitions, the
cell and its single runs one after the other in each, their order alternating: each repetition
gives a paired ratio (per robot / alone, the two measured side by side under the same load), and
the figure is the median of those ratios with its spread (the quartiles, and the standard error of
the median, 1.25 x their standard deviation / sqrt(repeat)): a difference is shown when it exceeds
that spread. On a shared machine the ratio of the best runs (printed too) mixes two moments'
loads.

The CPU times include each run's build; the line after each moving figure gives the paired
ratio of the run phases alone (each run's CPU less its build's).

**Instructions** (``--instructions T1,T2``): the paired CPU ratios of a moving run spread by
0.1-0.4 on this shared host (0.74-1.16 for the same code, 2026-11-29), far more than the few %
the cell must show against alone. Counted instructions do not depend on the load: each moving
cell and its four programs alone (one after the other in one process, as the CPU figure runs
them) run under valgrind's callgrind (``--toggle-collect=builtin_eval*``: the run phase alone,
called inside ``eval``; ``PYTHONHASHSEED=0``), each at T1 and T2 s simulated, in a process of
its own; the difference of the two counts over ``T2 - T1`` is the cost of a simulated second,
the start-up, imports, builds and the first plans cancelling. The counted cells are written to
one folder run after run (:data:`COUNT_FOLDER`, under the checkout's reports/): the path's hash
orders the run's dicts and sets, and a random temporary folder moved the count of the same code
by up to 0.2 M instructions a simulated second (the checkout's own path still does: compare
variants in one checkout). The ratio printed is the four
alone over the cell (per robot / alone, in instructions): 1 when a robot in the cell costs what
it costs alone. Four callgrind processes, ``--jobs`` at once, each some 70 s of CPU (its
start-up under valgrind; 4-20 minutes of wall time on the loaded host); ``--callgrind-out``
keeps their files for ``callgrind_annotate``. ``--repeat 0`` leaves the CPU runs out.

Usage::

    python tools/cell_bench.py [--sim-time 600] [--moving-time 60] [--repeat 9] [--interp vm|tree]
                               [--spacing 2000[,3200...]] [--instructions 5,15 [--jobs 2]
                               [--callgrind-out DIR]] [--no-idle]
"""

from __future__ import annotations

import argparse
import contextlib
import fcntl
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Iterator

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
#: :data:`MOVE` reading its predecessor's output and writing its successor's input
MOVE_WIRED = MOVE.replace("    LIN", "    $OUT[21] = $IN[20]\n    LIN").replace(
    "    PTP {{A1 -", "    $OUT[20] = NOT $OUT[20]\n    PTP {{A1 -")


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


def _paired(cell: Path, alone: list[Path], interp: str, sim: float, repeat: int) -> list[tuple]:
    """`repeat` repetitions of the cell and its programs alone, side by side, their order
    alternating: per repetition (cell's measure, alone's measure) (:func:`_measure`, :func:`_alone`)."""
    out = []
    for k in range(repeat):
        if k % 2:
            a = _alone(alone, interp, sim)
            c = _measure(cell, interp, sim)
        else:
            c = _measure(cell, interp, sim)
            a = _alone(alone, interp, sim)
        out.append((c, a))
    return out


def _run_phase(kind: str, paths: list[Path], interp: str, sim_time: float) -> tuple[float, float, str]:
    """The child of :func:`_count`: the cell `paths[0]` (`kind` ``cell``) or each program of
    `paths` alone (``alone``, as :func:`_alone`) built, then run for `sim_time` inside ``eval``,
    whose C function callgrind's ``--toggle-collect=builtin_eval*`` counts alone: the run phase
    only. (CPU s of the run phases, simulated s, end)."""
    cpu = 0.0
    if kind == "cell":
        cell = load_robot_cell(paths[0])
        with cell_runs(cell, interp, sim_time) as runs:
            t0 = time.process_time()
            res = eval("run_cell(cell, runs)", {"run_cell": run_cell, "cell": cell, "runs": runs})
            cpu = time.process_time() - t0
        return cpu, res.time, res.reason
    for program in paths:
        with run_setup({"program": program, "interp_kind": interp, "max_sim_time": sim_time,
                        "no_submit": True}) as setup:
            rt, _ = make_runtime(setup.spec, RunSinks())
            t0 = time.process_time()
            res = eval("rt.run()", {"rt": rt})
            cpu += time.process_time() - t0
    return cpu, res.sim_time, res.reason


#: callgrind's total of the events it counted (``--cache-sim=no``: instructions executed)
_TOTALS = re.compile(r"^(?:totals|summary):\s*(\d+)", re.MULTILINE)


def _count(kind: str, paths: list[Path], interp: str, sim_time: float, out: Path) -> int:
    """Instructions executed by the run phase (:func:`_run_phase`) of the cell or programs
    `paths`, counted by valgrind's callgrind in a process of its own (its output file `out`).
    Raises RuntimeError when callgrind fails or counts nothing."""
    cmd = ["valgrind", "--tool=callgrind", "--toggle-collect=builtin_eval*", f"--callgrind-out-file={out}",
           sys.executable, str(Path(__file__).resolve()), "--_child", kind, "--interp", interp,
           "--moving-time", str(sim_time), *map(str, paths)]
    # one hash seed: the same sets in the same order, the same count run after run (the child is
    # this Python: its checkout's code, the bench file run from anywhere)
    env = dict(os.environ, PYTHONHASHSEED="0")
    done = subprocess.run(cmd, capture_output=True, text=True, env=env)
    m = _TOTALS.search(out.read_text()) if done.returncode == 0 and out.exists() else None
    if m is None or int(m[1]) == 0:
        raise RuntimeError(f"callgrind of {kind} {sim_time} s failed ({done.returncode}): {done.stderr[-2000:]}")
    return int(m[1])


def _instructions(move4: Path, interp: str, times: tuple[float, float], folder: Path, jobs: int) -> list[str]:
    """The lines of ``--instructions``: the moving cell `move4`'s run phase and its four programs'
    run alone one after the other in one process (as :func:`_alone`; :func:`_count`, `jobs`
    callgrind processes at once, their outputs kept in `folder`), in instructions a simulated
    second: the counts of the two simulated durations `times`, their difference over the extra
    seconds (each run's fixed cost, its first plans and the contact watch's build, cancels); and
    per robot / alone, the four alone over the cell."""
    kinds = [("cell", [move4]), ("alone", [move4.parent / f"r{k}.src" for k in (1, 2, 3, 4)])]
    with ThreadPoolExecutor(jobs) as pool:
        counts = [[pool.submit(_count, kind, paths, interp, t, folder / f"callgrind.{kind}.{t:g}") for t in times]
                  for kind, paths in kinds]
        n = [[c.result() for c in pair] for pair in counts]
    cell, alone = [(b - a) / (times[1] - times[0]) for a, b in n]
    return [f"    the cell: {cell / 1e6:.3f} M instructions a simulated second ({cell / 4e6:.3f} M a robot; "
            f"{n[0][0] / 1e6:.1f} M and {n[0][1] / 1e6:.1f} M in all); the four alone {alone / 1e6:.3f} M "
            f"({n[1][0] / 1e6:.1f} M and {n[1][1] / 1e6:.1f} M): per robot / alone {alone / cell:.4f} "
            f"(callgrind, {times[0]:g} and {times[1]:g} s simulated)"]


#: where ``--instructions`` writes the cells it counts: one path run after run (a random temporary
#: folder's name moved the count of the same code by up to 0.2 M a simulated second, 2026-11-29: the
#: path's hash orders the run's dicts and sets); under the checkout's reports/ (not tracked)
COUNT_FOLDER = Path(__file__).resolve().parents[1] / "reports" / "cell-bench-count"


@contextlib.contextmanager
def _count_folder() -> Iterator[Path]:
    """:data:`COUNT_FOLDER`, emptied, held by this bench alone while it counts (an exclusive lock
    on a file beside it: a second bench in the same checkout waits)."""
    COUNT_FOLDER.parent.mkdir(parents=True, exist_ok=True)
    with open(COUNT_FOLDER.parent / "cell-bench-count.lock", "w", encoding="utf-8") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        shutil.rmtree(COUNT_FOLDER, ignore_errors=True)
        COUNT_FOLDER.mkdir()
        try:
            yield COUNT_FOLDER
        finally:
            shutil.rmtree(COUNT_FOLDER, ignore_errors=True)


def _spread(ratios: list[float]) -> str:
    """The median of `ratios`, their quartiles and the median's standard error (module docstring)."""
    q = statistics.quantiles(ratios, n=4) if len(ratios) > 1 else [ratios[0]] * 3
    sem = 1.25 * statistics.stdev(ratios) / len(ratios) ** 0.5 if len(ratios) > 1 else float("nan")
    return f"median {statistics.median(ratios):.3f} +- {sem:.3f} (quartiles {q[0]:.3f}-{q[2]:.3f}, n {len(ratios)})"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sim-time", type=float, default=600.0, help="the idle cells' simulated time (s)")
    ap.add_argument("--moving-time", type=float, default=60.0, help="the moving cells' simulated time (s)")
    ap.add_argument("--repeat", type=int, default=9)
    ap.add_argument("--interp", choices=("vm", "tree"), default="vm")
    ap.add_argument("--spacing", default="2000", help="mm between the robots' bases on X (a comma-separated list: "
                    "a moving cell each; 3200 and more: never checked for collisions)")
    ap.add_argument("--wired", action="store_true", help="also the moving cell wired in a chain (the first spacing)")
    ap.add_argument("--instructions", metavar="T1,T2", help="also count each moving cell's run phase and its programs' "
                    "alone in instructions (valgrind's callgrind) at T1 and T2 s simulated: the difference a second")
    ap.add_argument("--jobs", type=int, default=2, help="callgrind processes at once (--instructions)")
    ap.add_argument("--callgrind-out", type=Path, help="a folder to keep callgrind's outputs in (--instructions; "
                    "callgrind_annotate reads them)")
    ap.add_argument("--no-idle", action="store_true", help="leave the idle cell out")
    ap.add_argument("--_child", choices=("cell", "alone"), help=argparse.SUPPRESS)
    ap.add_argument("paths", nargs="*", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args._child:
        cpu, sim, reason = _run_phase(args._child, args.paths, args.interp, args.moving_time)
        print(f"{cpu:.6f} s CPU the run phase, {sim:.3f} s simulated, {reason}")
        return 0
    counted = tuple(float(x) for x in args.instructions.split(",")) if args.instructions else None
    if counted is not None and (len(counted) != 2 or not 0 < counted[0] < counted[1]):
        ap.error("--instructions is T1,T2 with 0 < T1 < T2")
    spacings = [float(x) for x in args.spacing.split(",")]
    with tempfile.TemporaryDirectory(prefix="krl-cell-bench-") as tmp:
        folder = Path(tmp)
        idle4 = _write(folder, "idle4", {"R1": TOGGLE, **{f"R{k}": FOLLOW.format(k=k) for k in (2, 3, 4)}},
                       [f"R1 $OUT[5] -> R{k} $IN[5]" for k in (2, 3, 4)])
        print(f"cells of four robots ({args.interp}), {args.repeat} repetitions side by side with one robot alone, "
              "x real time per CPU second:")
        if args.repeat and not args.no_idle:
            runs = _paired(idle4, [idle4.parent / "r1.src"], args.interp, args.sim_time, args.repeat)
            c = min((c for c, _ in runs), key=lambda m: m[0])
            print(f"  idle    four robots as a cell: {_spread([c[1] / c[0] for c, _ in runs])} "
                  f"(best {c[0]:.2f} s CPU for {c[1]:.0f} s, {c[3]:.2f} of it the build, {c[2]})")
        for spacing in spacings:
            move4 = _write(folder, f"move4_{spacing:.0f}", {f"R{k}": MOVE.format(k=k, a=20 + 5 * k)
                                                            for k in (1, 2, 3, 4)}, [], spacing)
            if args.repeat:
                runs = _paired(move4, [move4.parent / f"r{k}.src" for k in (1, 2, 3, 4)], args.interp,
                               args.moving_time, args.repeat)
                ratios = [a[0] / c[0] for c, a in runs]          # per robot / alone: the same simulated work
                c = min((c for c, _ in runs), key=lambda m: m[0])
                a = min((a for _, a in runs), key=lambda m: m[0])
                print(f"  moving  four robots {spacing:.0f} mm apart, per robot / alone (paired): {_spread(ratios)}; "
                      f"best runs: {4 * c[1] / c[0]:.1f}x per robot ({c[0]:.2f} s CPU for {c[1]:.0f} s, {c[3]:.2f} the "
                      f"build), alone {4 * a[1] / a[0]:.1f}x ({a[0]:.2f} s CPU, {a[3]:.2f} the builds), {c[2]}")
                # the run phases alone (each run's CPU less its build's): the builds' share left out
                print(f"          the run phases alone, per robot / alone (paired): "
                      f"{_spread([(a[0] - a[3]) / (c[0] - c[3]) for c, a in runs])}")
            if counted is not None:
                print(f"  moving  four robots {spacing:.0f} mm apart, instructions of the run phase:")
                out = args.callgrind_out or folder
                out.mkdir(parents=True, exist_ok=True)
                with _count_folder() as fixed:
                    move4 = _write(fixed, f"move4_{spacing:.0f}", {f"R{k}": MOVE.format(k=k, a=20 + 5 * k)
                                                                   for k in (1, 2, 3, 4)}, [], spacing)
                    print("\n".join(_instructions(move4, args.interp, counted, out, args.jobs)), flush=True)
        if args.wired and args.repeat:
            spacing = spacings[0]
            wired4 = _write(folder, "wired4", {f"R{k}": MOVE_WIRED.format(k=k, a=20 + 5 * k) for k in (1, 2, 3, 4)},
                            [f"R{k} $OUT[20] -> R{k + 1} $IN[20]" for k in (1, 2, 3)], spacing)
            runs = _paired(wired4, [wired4.parent / f"r{k}.src" for k in (1, 2, 3, 4)], args.interp,
                           args.moving_time, args.repeat)
            print(f"  moving  four robots {spacing:.0f} mm apart wired in a chain, per robot / alone (paired): "
                  f"{_spread([a[0] / c[0] for c, a in runs])}, {min(runs)[0][2]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
