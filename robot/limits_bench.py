"""``python -m robot.limits_bench``: the example motion programs of issue 15, run through the
controller and measured with :func:`robot.limits.check_trace` (max path speed, axis speed
and axis acceleration as a ratio of the limit; 1.00 = at the limit).

The limits are computed from the requests (:func:`robot.limits.motion_limits`), so the
script measures any version of the planner the same way.
"""

from __future__ import annotations

import json
import sys
from typing import Any

from .bench import run_motions
from .controller import Controller
from .limits import check_trace, motion_limits, normalise_mode
from .motion import MotionParams, MotionRequest, SplineSegment
from .trace import TraceWriter

HOME = {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 90, "A6": 0}


def _xyz(x: float, y: float, z: float) -> dict[str, float]:
    return {"X": x, "Y": y, "Z": z}


def examples() -> dict[str, tuple[str, list[MotionRequest]]]:
    """name -> (mode, requests)."""
    P = MotionParams.initmov()
    out: dict[str, tuple[str, list[MotionRequest]]] = {}
    # LIN -> LIN C_DIS 30 mm on a straight line, zone longer than the braking distance
    s = P.with_(vel_cp=0.2, apo_cdis=30.0)
    out["lin_cdis_collinear"] = ("AUT", [
        MotionRequest("PTP", HOME, P),
        MotionRequest("LIN", _xyz(450, -150, 600), s),
        MotionRequest("LIN", _xyz(450, 0, 600), s, approx="C_DIS"),
        MotionRequest("LIN", _xyz(450, 150, 600), s)])
    # pick and place with C_DIS corners and C_PTP
    f = P.with_(vel_cp=1.0, apo_cdis=50.0)
    pp = P.with_(apo_cptp=80.0)
    seq = [MotionRequest("PTP", HOME, P)]
    for y in (-200, 200):
        seq += [MotionRequest("PTP", _xyz(500, y, 700), pp, approx="C_PTP", approx2="C_DIS"),
                MotionRequest("LIN", _xyz(500, y, 500), f, approx="C_DIS"),
                MotionRequest("LIN", _xyz(500, y, 450), f.with_(vel_cp=0.2)),
                MotionRequest("LIN", _xyz(500, y, 700), f, approx="C_DIS"),
                MotionRequest("LIN", _xyz(650, y / 2, 700), f, approx="C_DIS")]
    seq.append(MotionRequest("PTP", HOME, P))
    out["pick_and_place"] = ("AUT", seq)
    # palletizing: a 3x2 grid, PTP C_PTP over each place, LIN down/up with C_DIS
    pal = [MotionRequest("PTP", HOME, P)]
    for i in range(3):
        for j in range(2):
            x, y = 450 + 80 * i, -120 + 240 * j
            pal += [MotionRequest("PTP", _xyz(x, y, 650), pp, approx="C_PTP", approx2="C_DIS"),
                    MotionRequest("LIN", _xyz(x, y, 520), f, approx="C_DIS"),
                    MotionRequest("LIN", _xyz(x, y, 650), f, approx="C_DIS")]
    pal.append(MotionRequest("PTP", HOME, P))
    out["palletizing"] = ("AUT", pal)
    # PTP C_PTP -> LIN
    out["ptp_cptp_lin"] = ("AUT", [
        MotionRequest("PTP", HOME, P),
        MotionRequest("PTP", {"A1": 60, "A2": -80, "A3": 100, "A4": 0, "A5": 60, "A6": 0}, pp,
                      approx="C_PTP"),
        MotionRequest("LIN", _xyz(500, 0, 600), P)])
    # a SPLINE block: SPL points, an SPL -> SLIN junction, a 45° SLIN -> SCIRC corner
    segs = (SplineSegment("SPL", _xyz(480, -100, 650)),
            SplineSegment("SPL", _xyz(520, -50, 600)),
            SplineSegment("SLIN", _xyz(520, 50, 600)),
            SplineSegment("SCIRC", _xyz(620, 150, 600), aux=_xyz(591, 79, 600)),
            SplineSegment("SPL", _xyz(560, 200, 650)))
    out["spline_block"] = ("AUT", [
        MotionRequest("PTP", HOME, P),
        MotionRequest("LIN", _xyz(450, -150, 700), P),
        MotionRequest("SPLINE", {}, P.with_(vel_cp=1.0), segments=segs)])
    # T1: a LIN at $VEL.CP 2 m/s and a PTP at 100 %
    out["t1_lin_ptp"] = ("T1", [
        MotionRequest("PTP", HOME, P),
        MotionRequest("LIN", _xyz(450, -200, 600), P),
        MotionRequest("LIN", _xyz(450, 200, 600), P),
        MotionRequest("PTP", {"A1": 40, "A2": -80, "A3": 100, "A4": 0, "A5": 60, "A6": 0}, P)])
    return out


def measure(name: str, mode: str, reqs: list[MotionRequest]) -> dict[str, Any]:
    """Run one example; the ratios of :class:`robot.limits.LimitReport`."""
    tw = TraceWriter(keep=True)
    try:
        ctl = Controller(trace=tw, mujoco=False, mode_op=mode)
    except TypeError:  # a controller without operating modes
        ctl = Controller(trace=tw, mujoco=False)
    run_motions(ctl, reqs)
    lims = {i + 1: motion_limits(r, ctl.machine, normalise_mode(mode)) for i, r in enumerate(reqs)}
    rep = check_trace(tw.events, ctl.machine, limits=lims)
    return {"example": name, "mode": mode, "path": round(rep.path_ratio, 3),
            "axis_speed": round(rep.axis_speed_ratio, 3), "axis_acc": round(rep.axis_acc_ratio, 3),
            "flange": round(rep.flange_ratio, 3), "violations": len(rep.violations),
            "sim_s": round(ctl.time, 3)}


def main(argv: list[str] | None = None) -> int:  # pragma: no cover - manual entry point
    rows = [measure(n, m, r) for n, (m, r) in examples().items()]
    for row in rows:
        print(json.dumps(row))
    return 0 if all(r["violations"] == 0 for r in rows) else 1


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main(sys.argv[1:]))
