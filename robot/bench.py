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


def bench_program(machine: Any = None) -> list[MotionRequest]:
    """One loop (about 8 s of motion) of the benchmark program."""
    P = MotionParams.initmov(machine)
    slow = P.with_(vel_cp=0.25, apo_cdis=20.0)
    ptp = P.with_(vel_axis=(30.0,) * 6, apo_cptp=50.0)
    return [
        MotionRequest("PTP", {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 90, "A6": 0}, ptp),
        MotionRequest("LIN", {"X": 445, "Y": 150, "Z": 600}, slow, approx="C_DIS",
                      triggers=(Trigger(distance=1, delay_ms=-50, line=1),)),
        MotionRequest("LIN", {"X": 600, "Y": 150, "Z": 600}, slow, approx="C_DIS"),
        MotionRequest("CIRC", {"X": 600, "Y": -150, "Z": 600}, slow, approx="C_DIS",
                      aux={"X": 700, "Y": 0, "Z": 600}),
        MotionRequest("LIN", {"X": 445, "Y": -150, "Z": 700}, slow,
                      triggers=(Trigger(distance=0, delay_ms=20, line=2),)),
        MotionRequest("PTP", {"A1": 40, "A2": -80, "A3": 100, "A5": 60}, ptp, approx="C_PTP"),
        MotionRequest("PTP", {"A1": -40, "A2": -100, "A3": 80, "A5": 80}, ptp, approx="C_PTP"),
    ]


def run_bench(min_motion_s: float = 60.0, trace_path: str | None = None) -> dict[str, Any]:
    """Simulate the benchmark program until at least ``min_motion_s`` of simulated time has
    passed; the trace goes to ``trace_path`` (default: the null device, so serialisation is
    still paid). Returns {sim_s, wall_s, sim_realtime_factor, cycles, motions, target}."""
    sink = trace_path or os.devnull
    with TraceWriter(sink) as tw:
        t0 = time.perf_counter()
        ctl = Controller(trace=tw)
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
    return {"sim_s": round(sim, 3), "wall_s": round(wall, 3),
            "sim_realtime_factor": round(sim / wall, 2) if wall > 0 else float("inf"),
            "cycles": ctl.cycle, "motions": n, "target": TARGET_FACTOR}


def main() -> int:  # pragma: no cover - manual entry point
    """``python -m robot.bench``: run the benchmark, print JSON, exit 1 below target."""
    import json

    r = run_bench()
    print(json.dumps(r))
    return 0 if r["sim_realtime_factor"] >= TARGET_FACTOR else 1


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
