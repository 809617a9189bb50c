"""Speed benchmark of the simulated controller (issue 5, "Speed").

:func:`run_bench` drives a :class:`~robot.controller.Controller` directly (no interpreter)
through a fixed program with at least ``min_motion_s`` seconds of motion — PTP, LIN and CIRC
with C_PTP/C_DIS approximation, triggers and I/O, and the full per-IPO-cycle JSON Lines
trace — and reports ``sim_realtime_factor`` = simulated seconds / wall-clock seconds and
``sim_cpu_factor`` = simulated seconds / CPU seconds of the process (the figure to compare on a
loaded machine). The target is >= 20 (60 s of motion in under 3 s); issue 39 asks for 300.
``krl bench --json`` reports the same figures (:func:`measure`: warm, the same run). ``python -m robot.bench --against DIR``
measures another checkout side by side (see :func:`main`).

Also holds :func:`run_motions`, a small driver used by the tests and the benchmark.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable, Iterable
from typing import Any

from krl.cbuild import OTHER_CHECKOUT_PRELUDE

from .controller import Controller, Event
from .motion import MotionParams, MotionRequest, Trigger
from .trace import TraceWriter
from .mada import load_robot

TARGET_FACTOR = 20.0


def run_motions(ctl: Controller, requests: Iterable[MotionRequest], *,
                wait_between: bool = False) -> list[Event]:
    """Enqueue ``requests`` like an advance run would (blocking while the queue holds
    ``$ADVANCE`` motions), then step until idle. With ``wait_between`` every motion is
    followed by an advance-run stop (like ``WAIT SEC 0``). Returns all events."""
    out: list[Event] = []
    for req in requests:
        while not ctl.can_enqueue():
            out.extend(ctl.step())
        ctl.queue.enqueue(req)
        if wait_between:
            out.extend(wait_idle(ctl))
    out.extend(wait_idle(ctl))
    return out


def step_until(ctl: Controller, predicate: Callable[[], bool], max_cycles: int = 10_000_000) -> list[Event]:
    """Step `ctl` until ``predicate()`` is true (checked before each cycle), at most
    `max_cycles` cycles; returns all events. Interpreters that evaluate interrupts step
    themselves."""
    out: list[Event] = []
    n = 0
    while not predicate() and n < max_cycles:
        out.extend(ctl.step())
        n += 1
    return out


def wait_idle(ctl: Controller) -> list[Event]:
    """Step `ctl` until it is idle (``Controller.is_idle``); returns all events."""
    return step_until(ctl, ctl.is_idle)


def wait_sec(ctl: Controller, seconds: float) -> list[Event]:
    """Step `ctl` for ``WAIT SEC seconds`` (``Controller.cycles_for``); returns all events."""
    out: list[Event] = []
    for _ in range(ctl.cycles_for(seconds)):
        out.extend(ctl.step())
    return out


#: Reach (mm, wrist point) of the KR 6 R900 for which the benchmark's points are written.
_KR6_REACH_MM = 901.456


def bench_program(machine: Any = None) -> list[MotionRequest]:
    """One loop (about 8 s of motion on the KR 6 R900) of the benchmark program. On another
    robot the Cartesian points and the path speed scale with its reach (issue 22), so the
    same program runs on a KR 210 from machine data."""
    P = MotionParams.initmov(machine)
    k = (machine.reach_wrist_point_mm / _KR6_REACH_MM) if machine is not None else 1.0
    slow = P.with_(vel_cp=0.25 * k, apo_cdis=20.0 * k)
    ptp = P.with_(vel_axis=(30.0,) * 6, apo_cptp=50.0)

    def xyz(x: float, y: float, z: float) -> dict[str, float]:
        return {"X": x * k, "Y": y * k, "Z": z * k}

    return [
        MotionRequest("PTP", {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 90, "A6": 0}, ptp),
        MotionRequest("LIN", xyz(445, 150, 600), slow, approx="C_DIS",
                      triggers=(Trigger(distance=1, delay_ms=-50, line=1),)),
        MotionRequest("LIN", xyz(600, 150, 600), slow, approx="C_DIS"),
        MotionRequest("CIRC", xyz(600, -150, 600), slow, approx="C_DIS", aux=xyz(700, 0, 600)),
        MotionRequest("LIN", xyz(445, -150, 700), slow,
                      triggers=(Trigger(distance=0, delay_ms=20, line=2),)),
        MotionRequest("PTP", {"A1": 40, "A2": -80, "A3": 100, "A5": 60}, ptp, approx="C_PTP"),
        MotionRequest("PTP", {"A1": -40, "A2": -100, "A3": 80, "A5": 80}, ptp, approx="C_PTP"),
    ]


def run_bench(min_motion_s: float = 60.0, trace_path: str | None = None, machine: Any = None) -> dict[str, Any]:
    """Simulate the benchmark program until at least ``min_motion_s`` of simulated time has
    passed; the trace goes to ``trace_path`` (default: the null device, so serialisation is
    still paid). ``machine``: the robot (default the KR 6 R900). Returns {robot, sim_s,
    wall_s, sim_realtime_factor, cycles, motions, target}."""
    sink = trace_path or os.devnull
    with TraceWriter(sink) as tw:
        t0 = time.perf_counter()
        c0 = time.process_time()
        ctl = Controller(machine, trace=tw)
        n = 0
        while ctl.time < min_motion_s:
            reqs = bench_program(ctl.machine)
            for i, req in enumerate(reqs):
                while not ctl.can_enqueue():
                    for ev in ctl.step():
                        if ev.kind == "trigger":
                            ctl.io.set_out(1, not ctl.io.get_out(1), "trigger")
                ctl.queue.enqueue(req)
                n += 1
        wait_idle(ctl)
        ctl.log.finish("program_end")
        wall = time.perf_counter() - t0
        cpu = time.process_time() - c0
    sim = ctl.time
    return {"robot": ctl.machine.name, "sim_s": round(sim, 3), "wall_s": round(wall, 3),
            "sim_realtime_factor": round(sim / wall, 2) if wall > 0 else float("inf"),
            "cpu_s": round(cpu, 3), "sim_cpu_factor": round(sim / cpu, 2) if cpu > 0 else float("inf"),
            "cycles": ctl.cycle, "motions": n, "target": TARGET_FACTOR}


def measure(min_motion_s: float = 60.0, robot: str | None = None, warm_up: bool = True) -> dict[str, Any]:
    """The simulator's figure, as ``python -m robot.bench`` and ``krl bench --json`` both give it
    (issue 48, "one figure per measure"): :func:`run_bench` on the robot of path `robot` (None:
    the KR 6 R900), after a short untimed run when `warm_up` (the process's one-time costs:
    importing MuJoCo, the first model compile, numpy's and scipy's first calls, which a cold
    figure would add once: 221-256x against 404x on 2026-11-24); adds ``warmup_s`` (its wall
    time)."""
    machine = None
    if robot:

        machine = load_robot(robot)
    t0 = time.perf_counter()
    if warm_up:
        run_bench(1.0, machine=machine)
    warm = time.perf_counter() - t0
    r = run_bench(min_motion_s, machine=machine)
    r["warmup_s"] = round(warm, 3)
    return r


def _child_measure(root: str, min_motion_s: float, robot: str | None, warm_up: bool) -> dict[str, Any]:
    """:func:`run_bench` of the checkout in `root` (its own ``robot`` package, a child process
    of this interpreter), warmed up like :func:`measure`."""
    code = (OTHER_CHECKOUT_PRELUDE +
            "import json, sys, time; sys.path.insert(0, sys.argv[1]); from robot.bench import run_bench\n"
            "m = None\n"
            "if sys.argv[3]:\n from robot.mada import load_robot; m = load_robot(sys.argv[3])\n"
            "t0 = time.perf_counter()\n"
            "if sys.argv[4] == '1': run_bench(1.0, machine=m)\n"
            "w = time.perf_counter() - t0\n"
            "c0 = time.process_time(); r = run_bench(float(sys.argv[2]), machine=m)\n"
            "r.setdefault('cpu_s', round(time.process_time() - c0, 3)); r['warmup_s'] = round(w, 3)\n"
            "print(json.dumps(r))")
    res = subprocess.run([sys.executable, "-c", code, str(root), str(min_motion_s), robot or "",
                          "1" if warm_up else "0"], capture_output=True, text=True, cwd=root, check=False)
    if res.returncode != 0:
        raise SystemExit(f"the benchmark in {root} failed:\n{res.stderr[-2000:]}")
    r = json.loads(res.stdout.strip().splitlines()[-1])
    r["sim_cpu_factor"] = round(r["sim_s"] / r["cpu_s"], 2) if r["cpu_s"] > 0 else float("inf")
    return r


def main(argv: list[str] | None = None) -> int:  # pragma: no cover - manual entry point
    """``python -m robot.bench [--robot PATH] [--against DIR] [--rounds N] [--no-warm-up]``:
    run the benchmark on the KR 6 R900 or on the robot of PATH (a backup folder or .zip, a
    $machine.dat or a robot YAML: robot/mada.py ``load_robot``) and print JSON with the
    real-time ratio (simulated s per wall s) and the simulated s per CPU s; exit 1 below
    target. The timed run follows a short untimed one (``warmup_s``: the process's one-time
    costs, such as importing MuJoCo), unless ``--no-warm-up``. ``--against DIR`` runs the same
    benchmark of the checkout in DIR (e.g. a worktree of the baseline) in a child process, in
    alternation with this one for ``--rounds`` rounds, and prints both and their ratio (best
    round of each: the least disturbed by the machine's load)."""
    ap = argparse.ArgumentParser(prog="python -m robot.bench")
    ap.add_argument("--robot", default=None, help="robot: backup folder/.zip, $machine.dat or robot YAML")
    ap.add_argument("--min-motion-s", type=float, default=60.0, help="simulated seconds of motion")
    ap.add_argument("--against", metavar="DIR", help="also run the benchmark of the checkout in DIR")
    ap.add_argument("--rounds", type=int, default=3, help="rounds with --against (default 3)")
    ap.add_argument("--no-warm-up", action="store_true", help="time the first run of the process")
    args = ap.parse_args(argv)
    warm = not args.no_warm_up
    robot = os.path.abspath(args.robot) if args.robot else None
    if not args.against:
        r = measure(args.min_motion_s, robot, warm)
        print(json.dumps(r))
        return 0 if r["sim_realtime_factor"] >= TARGET_FACTOR else 1
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    mine: list[dict[str, Any]] = []
    other: list[dict[str, Any]] = []
    for _ in range(max(1, args.rounds)):
        mine.append(_child_measure(here, args.min_motion_s, robot, warm))
        other.append(_child_measure(os.path.abspath(args.against), args.min_motion_s, robot, warm))
    best = {key: (max(mine, key=lambda r: r[key])[key], max(other, key=lambda r: r[key])[key])
            for key in ("sim_realtime_factor", "sim_cpu_factor")}
    print(json.dumps({"robot": mine[0]["robot"], "rounds": len(mine),
                      "this": {"sim_realtime_factor": best["sim_realtime_factor"][0],
                               "sim_cpu_factor": best["sim_cpu_factor"][0]},
                      "against": {"dir": args.against, "sim_realtime_factor": best["sim_realtime_factor"][1],
                                  "sim_cpu_factor": best["sim_cpu_factor"][1]},
                      "cpu_ratio": round(best["sim_cpu_factor"][0] / best["sim_cpu_factor"][1], 2),
                      "wall_ratio": round(best["sim_realtime_factor"][0] / best["sim_realtime_factor"][1], 2),
                      "per_round": [{"this": [a["sim_realtime_factor"], a["sim_cpu_factor"]],
                                     "against": [b["sim_realtime_factor"], b["sim_cpu_factor"]]}
                                    for a, b in zip(mine, other)]}))
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
