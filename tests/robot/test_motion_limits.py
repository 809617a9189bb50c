"""The planner keeps its limits (issue 15): approximation zones, spline corners, T1, and the
smaller points (RESUME abort event, zero-length LIN never approximated). Expected numbers
are derived by hand in each docstring; the limit check itself is robot/limits.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.bench import run_motions, wait_idle
from robot.controller import Controller
from robot.frames import matrix_to_frame
from robot.limits import check_trace
from robot.mada import load_robot
from robot.motion import MotionParams, MotionRequest, SplineSegment
from robot.pathpieces import CatmullRomPiece
from robot.planner import plan
from robot.trace import TraceWriter

DT = 0.012
HOME = {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 90, "A6": 0}


def _run(reqs, **kw):
    tw = TraceWriter(keep=True)
    ctl = Controller(trace=tw, mujoco=False, **kw)
    run_motions(ctl, reqs)
    return ctl, tw.events


def _xyz(x, y, z):
    return {"X": x, "Y": y, "Z": z}


def _phases(ev, mid):
    return {e["phase"]: e["t"] for e in ev if e["kind"] == "motion" and e["id"] == mid}


def _speeds(ev, t0, t1):
    P = [(e["t"], np.array(e["tcp"][:3])) for e in ev if e["kind"] == "pose" and t0 <= e["t"] <= t1]
    return [float(np.linalg.norm(b - a)) / (tb - ta) for (ta, a), (tb, b) in zip(P, P[1:])]


def test_collinear_lin_c_dis_zone_longer_than_braking_keeps_vel_cp():
    """0.2 m/s, $ACC.CP 2.3 m/s²: braking distance 0.04/4.6 m = 8.7 mm < C_DIS 30 mm. The
    blend starts 30 mm before the point (zone rule), the TCP never runs faster than
    200 mm/s (3 %), and, the lines being collinear, it does not slow down either."""
    P = MotionParams().with_(vel_cp=0.2, apo_cdis=30.0)
    ctl, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("LIN", _xyz(450, -150, 600), P),
                    MotionRequest("LIN", _xyz(450, 0, 600), P, approx="C_DIS"),
                    MotionRequest("LIN", _xyz(450, 150, 600), P)])
    ph = _phases(ev, 3)
    sp = _speeds(ev, ph["blend_start"] - 0.2, ph["blend_end"] + 0.2)
    assert max(sp) <= 200.0 * 1.03
    assert min(sp) >= 200.0 * 0.97
    bs = [e for e in ev if e["kind"] == "pose" and e["t"] == ph["blend_start"]][0]
    assert 30.0 - 200.0 * DT <= -bs["tcp"][1] <= 30.0 + 1e-6
    rep = check_trace(ev, ctl.machine)
    assert rep.ok, [str(v) for v in rep.violations]


def test_spline_corner_is_slowed_for_acc_cp():
    """A 45° SLIN -> SCIRC corner: the velocity turns by 45° within one IPO cycle, so the
    corner speed is at most $ACC.CP·Δt/(2·sin(22.5°)) = 2300·0.012/0.7654 = 36.1 mm/s; the
    SPL -> SLIN junction has no kink (the SPL end tangent follows the line)."""
    P = MotionParams().with_(vel_cp=1.0)
    segs = (SplineSegment("SPL", _xyz(480, -100, 650)), SplineSegment("SPL", _xyz(520, -50, 600)),
            SplineSegment("SLIN", _xyz(520, 50, 600)),
            SplineSegment("SCIRC", _xyz(620, 150, 600), aux=_xyz(591, 79, 600)))
    ctl, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("LIN", _xyz(450, -150, 700), P),
                    MotionRequest("SPLINE", {}, P, segments=segs)])
    ph = _phases(ev, 3)
    poses = [e for e in ev if e["kind"] == "pose" and ph["start"] <= e["t"] <= ph["end"]]
    pts = np.array([e["tcp"][:3] for e in poses])
    # speed near the corner (520, 50, 600)
    k = int(np.argmin(np.linalg.norm(pts - [520, 50, 600], axis=1)))
    near = np.linalg.norm(np.diff(pts[k - 1:k + 2], axis=0), axis=1) / DT
    assert near.min() <= 36.1 * 1.03 + 2300 * DT  # within one cycle of the corner
    # SPL -> SLIN junction at (520, -50, 600): the curve ends in the line's direction
    seg = ctl_seg(segs)
    t_end = seg.pieces[1].tangent(seg.pieces[1].length)
    assert math.degrees(math.acos(min(1.0, float(t_end @ seg.pieces[2].dir)))) < 0.01
    rep = check_trace(ev, ctl.machine)
    assert rep.ok, [str(v) for v in rep.violations]
    assert rep.path_ratio <= 1.03


def ctl_seg(segs):
    """The planned SPLINE segment of the corner test (start: the LIN's end point)."""
    ctl = Controller(mujoco=False)
    P = MotionParams().with_(vel_cp=1.0)
    ctl.queue.enqueue(MotionRequest("PTP", HOME, P))
    ctl.queue.enqueue(MotionRequest("LIN", _xyz(450, -150, 700), P))
    return plan(MotionRequest("SPLINE", {}, P, segments=segs), ctl.queue.planned_axes(), ctl.model)


def test_t1_limits_tcp_to_250_and_ptp_to_red_t1():
    """T1: a LIN at $VEL.CP 2 m/s runs at 250 mm/s; a PTP of A1 by 40° at 100 % runs A1 at
    $RED_T1 7 % of 360 deg/s = 25.2 deg/s (or slower for the 250 mm/s TCP limit)."""
    P = MotionParams()
    ctl, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("LIN", _xyz(450, -200, 600), P),
                    MotionRequest("LIN", _xyz(450, 200, 600), P),
                    MotionRequest("PTP", dict(HOME, A1=40), P)], mode_op="T1")
    ph = _phases(ev, 3)
    sp = _speeds(ev, ph["start"], ph["end"])
    assert max(sp) == pytest.approx(250.0, rel=0.01)
    ph4 = _phases(ev, 4)
    a1 = [e["axes"][0] for e in ev if e["kind"] == "pose" and ph4["start"] <= e["t"] <= ph4["end"]]
    assert max(abs(b - a) / DT for a, b in zip(a1, a1[1:])) <= 25.2 * 1.001
    rep = check_trace(ev, ctl.machine)
    assert rep.ok, [str(v) for v in rep.violations]
    # the same program in AUT is not held to 250 mm/s (triangle peak sqrt(2300·400) = 959 mm/s
    # at most)
    ctl, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("LIN", _xyz(450, -200, 600), P),
                    MotionRequest("LIN", _xyz(450, 200, 600), P)])
    ph = _phases(ev, 3)
    assert 500.0 < max(_speeds(ev, ph["start"], ph["end"])) <= 959.2 * 1.03


def test_ov_pro_scales_the_path_speed():
    """$OV_PRO 50 %: a LIN at 0.4 m/s runs at 200 mm/s (reference §6.7)."""
    P = MotionParams().with_(vel_cp=0.4, ov_pro=50.0)
    ctl, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("LIN", _xyz(450, -200, 600), P),
                    MotionRequest("LIN", _xyz(450, 200, 600), P)])
    ph = _phases(ev, 3)
    assert max(_speeds(ev, ph["start"], ph["end"])) == pytest.approx(200.0, rel=0.01)


def test_zero_length_lin_with_c_dis_is_never_approximated():
    """A LIN to where the robot already is, with C_DIS: no blend events for it, nor for the
    motion before it (docs/robot.md: a zero-length motion is never approximated)."""
    P = MotionParams().with_(vel_cp=0.5, apo_cdis=20.0)
    ctl, ev = _run([MotionRequest("PTP", HOME, P),
                    MotionRequest("LIN", _xyz(450, 0, 600), P, approx="C_DIS"),
                    MotionRequest("LIN", _xyz(450, 0, 600), P, approx="C_DIS"),
                    MotionRequest("LIN", _xyz(450, 100, 600), P)])
    for mid in (2, 3):
        assert not {"blend_start", "blend_end"} & set(_phases(ev, mid)), mid
    assert not [e for e in ev if e["kind"] == "message"]


def test_resume_logs_an_abort_end_for_the_abandoned_motion():
    tw = TraceWriter(keep=True)
    ctl = Controller(trace=tw, mujoco=False)
    P = MotionParams().with_(vel_cp=0.2)
    run_motions(ctl, [MotionRequest("PTP", HOME, P)])
    ctl.queue.enqueue(MotionRequest("LIN", _xyz(450, -200, 600), P))
    for _ in range(20):
        ctl.step()
    ctl.brake()
    while ctl.is_braking():
        ctl.step()
    ctl.cancel_pending()  # RESUME
    wait_idle(ctl)
    ends = [e for e in tw.events if e["kind"] == "motion" and e["id"] == 2 and e["phase"] == "end"]
    assert len(ends) == 1 and ends[0]["reason"] == "abort"
    rep = check_trace(tw.events, ctl.machine)
    assert rep.ok, [str(v) for v in rep.violations]


# --- issue 22: a SPLINE block on the KR 210 R2700-2 (corpus machine data) ran 3.5 % fast
#: axes of the hypothesis example (tests/robot/test_limits_property.py) that found it
_Q_PTP = (0.1119580201929864, -56.96738358343825, 93.00162128323555, 49.222207072650406,
          40.18797832928211, -38.851313995089335)
_Q_SLIN = (48.46763857996379, -84.68297076522397, 98.28514676886586, -55.85690038183901,
           44.41919788344541, 53.532764559774506)
_Q_SPL = (-18.602663600207677, -62.036078556012775, 110.42944724739775, 28.58585569981011,
          31.917407178259865, 29.47640487191653)


def test_spl_after_a_reversing_slin_keeps_vel_cp_on_the_kr210(shared_corpus):
    """The breach of issue 22, reduced to its last two spline segments: on the KR 210 R2700-2
    (HugoDanielson__ChinaMilling's R1/Mada/$machine.dat) a PTP C_DIS, then a SPLINE block with
    an SLIN and an SPL point that turns back (> 90° from the line's direction, so the curve
    has zero end tangents: a straight piece whose speed |P'(t)| is 0 at both ends). The block
    runs at $VEL.CP 0.14834713588757553 m/s · $OV_PRO 30 % = 44.504 mm/s (program values);
    the TCP speed measured cycle by cycle after the PTP has ended must stay there (the trace
    rounds positions to 1e-6 mm: ±1.7e-4 mm/s). The arc-length table interpolated linearly ran
    up to 46.18 mm/s (103.8 %) on the SPL piece."""
    robot = load_robot(shared_corpus / "HugoDanielson__ChinaMilling")
    assert robot.name.startswith("KR210R2700_2")
    tw = TraceWriter(keep=True)
    ctl = Controller(robot, trace=tw, mujoco=False)

    def cart(q):
        return dict(zip("XYZABC", matrix_to_frame(ctl.model.kin.forward(np.asarray(q)))))

    axes = ("A1", "A2", "A3", "A4", "A5", "A6")
    P_ptp = MotionParams().with_(vel_axis=(18.447362809681138,) * 6, ov_pro=30.0, apo_cdis=4.37334970611875)
    P = MotionParams().with_(vel_cp=0.14834713588757553, ov_pro=30.0)
    run_motions(ctl, [
        MotionRequest("PTP", {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 60, "A6": 0}, MotionParams()),
        MotionRequest("PTP", dict(zip(axes, _Q_PTP)), P_ptp, approx="C_DIS", approx2="C_DIS"),
        MotionRequest("SPLINE", {}, P, segments=(SplineSegment("SLIN", cart(_Q_SLIN)),
                                                 SplineSegment("SPL", cart(_Q_SPL))))])
    ev = tw.events
    limit = 148.34713588757553 * 0.30
    sp = _speeds(ev, _phases(ev, 2)["end"], _phases(ev, 3)["end"])
    assert len(sp) > 5000  # about 80 s of spline at 44.5 mm/s
    assert max(sp) <= limit + 2e-4, max(sp)
    assert max(sp) >= limit - 1e-3  # and it does run at the programmed speed
    rep = check_trace(ev, robot)
    assert rep.ok, [str(v) for v in rep.violations]


def test_catmull_rom_piece_is_parametrised_by_exact_arc_length():
    """A SPL point that turns back from the SLIN before it (tangent · chord < 0): the curve
    becomes the straight chord with zero end tangents, P(t) = P1 + (3t² - 2t³)·(P2 - P1). On a
    straight piece the arc length is the distance from P1, so pos(s) must lie s mm from P1
    along the chord, including next to the ends where |P'(t)| vanishes."""
    P1, P2 = np.array([100.0, 0.0, 0.0]), np.array([-1900.0, 300.0, 200.0])
    m1 = np.array([1.0, 0.0, 0.0]) * float(np.linalg.norm(P2 - P1))  # the SLIN's direction
    pc = CatmullRomPiece(2 * P1 - P2, P1, P2, 2 * P2 - P1, m1, None)
    L = float(np.linalg.norm(P2 - P1))
    assert not pc.c1.any()  # the fallback: zero end tangents
    assert pc.length == pytest.approx(L, rel=1e-12)
    u = (P2 - P1) / L
    for s in [0.01, 0.3, 0.53, 1.0, 5.0, 37.0, 0.5 * L, L - 5.0, L - 0.53, L - 0.01]:
        assert np.linalg.norm(pc.pos(s) - (P1 + s * u)) < 1e-8, s
