"""Speed benchmark of the simulated controller (issue 5, "Speed").

:func:`run_bench` drives a :class:`~robot.controller.Controller` directly (no interpreter)
through a fixed program with at least ``min_motion_s`` seconds of motion — PTP, LIN and CIRC
with C_PTP/C_DIS approximation, triggers and I/O, and the full per-IPO-cycle JSON Lines
trace — and reports ``sim_realtime_factor`` = simulated seconds / wall-clock seconds.
The target is >= 20 (60 s of motion in under 3 s). ``krl bench --json`` reports this value.

Also holds :func:`run_motions`, a small driver used by the tests and the benchmark.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterable
from typing import Any

from .controller import Controller, Event
from .motion import MotionParams, MotionRequest, Trigger
from .trace import TraceWriter

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
        ctl.enqueue(req)
        if wait_between:
            out.extend(ctl.wait_idle())
    out.extend(ctl.wait_idle())
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
        ctl = Controller(machine, trace=tw)
        n = 0
        while ctl.time < min_motion_s:
            reqs = bench_program(ctl.machine)
            for i, req in enumerate(reqs):
                while not ctl.can_enqueue():
                    for ev in ctl.step():
                        if ev.kind == "trigger":
                            ctl.set_out(1, not ctl.io.get_out(1), "trigger")
                ctl.enqueue(req)
                n += 1
        ctl.wait_idle()
        ctl.finish("program_end")
        wall = time.perf_counter() - t0
    sim = ctl.time
    return {"robot": ctl.machine.name, "sim_s": round(sim, 3), "wall_s": round(wall, 3),
            "sim_realtime_factor": round(sim / wall, 2) if wall > 0 else float("inf"),
            "cycles": ctl.cycle, "motions": n, "target": TARGET_FACTOR}


def main(argv: list[str] | None = None) -> int:  # pragma: no cover - manual entry point
    """``python -m robot.bench [--robot PATH]``: run the benchmark on the KR 6 R900 or on the
    robot of PATH (a backup folder or .zip, a $machine.dat or a robot YAML:
    robot/mada.py ``load_robot``), print JSON with the real-time ratio, exit 1 below target."""
    import argparse
    import json

    ap = argparse.ArgumentParser(prog="python -m robot.bench")
    ap.add_argument("--robot", default=None, help="robot: backup folder/.zip, $machine.dat or robot YAML")
    ap.add_argument("--min-motion-s", type=float, default=60.0, help="simulated seconds of motion")
    args = ap.parse_args(argv)
    machine = None
    if args.robot:
        from .mada import load_robot

        machine = load_robot(args.robot)
    r = run_bench(args.min_motion_s, machine=machine)
    print(json.dumps(r))
    return 0 if r["sim_realtime_factor"] >= TARGET_FACTOR else 1


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
