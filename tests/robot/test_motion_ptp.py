"""PTP timing from first principles (reference §6.6; robot-model.md §5).

Expected durations are computed here by hand from the trapezoidal profile documented in
robot/profiles.py, with the machine data of robot-model.md §5:
v_max(A1) = 360 deg/s, a_max(A1) = 21.666156 rad/s² = 1241.38 deg/s²,
v_max(A2) = 300 deg/s, a_max(A2) = 6.889457 rad/s² = 394.74 deg/s².
"""

from __future__ import annotations

import math

import pytest

from robot.bench import run_motions
from robot.controller import Controller
from robot.errors import RobotError, SoftLimitError
from robot.frames import matrix_to_frame
from robot.motion import MotionParams, MotionRequest
from robot.trace import TraceWriter

DT = 0.012
A1_V = 360.0
A1_A = math.degrees(21.666156)
A2_V = 300.0
A2_A = math.degrees(6.889457)
HOME = {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 0, "A6": 0}


def single_axis_time(d: float, v: float, a: float) -> float:
    """Textbook trapezoid: d >= v²/a -> d/v + v/a, else triangle 2·sqrt(d/a)."""
    if d >= v * v / a:
        return d / v + v / a
    return 2.0 * math.sqrt(d / a)


def _run(reqs, **kw):
    tw = TraceWriter(keep=True)
    ctl = Controller(trace=tw, mujoco=False, **kw)
    run_motions(ctl, reqs)
    return ctl, tw.events


def _phase_times(events, mid):
    """The motion's phase times, and ``reached``: when its interpolation ended (the END signal
    of an exact stop comes 24-36 ms later, robot/exactstop.py)."""
    ph = {e["phase"]: e["t"] for e in events if e["kind"] == "motion" and e["id"] == mid}
    ph["reached"] = next(e["reached"] for e in events
                         if e["kind"] == "motion" and e["id"] == mid and e["phase"] == "end")
    return ph


@pytest.mark.parametrize("d,vel_pct", [(90.0, 100.0), (150.0, 100.0), (90.0, 50.0), (5.0, 100.0)])
def test_ptp_single_axis_duration(d, vel_pct):
    P = MotionParams().with_(vel_axis=(vel_pct,) * 6)
    target = dict(HOME, A1=d)
    _, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("PTP", target, P)])
    ph = _phase_times(ev, 2)
    expected = single_axis_time(d, A1_V * vel_pct / 100.0, A1_A)
    measured = ph["reached"] - ph["start"]
    assert measured == pytest.approx(expected, abs=1e-6)  # the trace keeps µs


def test_ptp_synchronised_axes_leading_axis():
    """A1 90° and A2 30°: every axis needs its own time; the slowest (leading) axis sets
    the duration and all axes start and stop together."""
    P = MotionParams()
    target = dict(HOME, A1=90.0, A2=-60.0)
    _, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("PTP", target, P)])
    t_a1 = single_axis_time(90.0, A1_V, A1_A)
    t_a2 = single_axis_time(30.0, A2_V, A2_A)
    expected = max(t_a1, t_a2)  # here A2 leads (0.551 s vs 0.539 s)
    assert t_a2 > t_a1
    ph = _phase_times(ev, 2)
    measured = ph["reached"] - ph["start"]
    assert measured == pytest.approx(expected, abs=1e-6)  # the trace keeps µs
    # synchronous: at every sample both axes have covered the same fraction
    t0 = ph["start"]
    for e in ev:
        if e["kind"] == "pose" and t0 <= e["t"] <= ph["end"]:
            f1 = (e["axes"][0] - 0.0) / 90.0
            f2 = (e["axes"][1] + 90.0) / 30.0
            assert f1 == pytest.approx(f2, abs=1e-6)


def test_ptp_profile_samples_match_hand_formula():
    """Each IPO sample of a trapezoidal PTP lies on the hand-computed profile."""
    P = MotionParams()
    d = 150.0
    _, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("PTP", dict(HOME, A1=d), P)])
    ph = _phase_times(ev, 2)
    t0 = ph["start"]
    v, a = A1_V, A1_A
    ta = v / a
    T = d / v + v / a

    def s(t):
        if t < ta:
            return 0.5 * a * t * t
        if t < T - ta:
            return 0.5 * a * ta * ta + v * (t - ta)
        if t < T:
            return d - 0.5 * a * (T - t) ** 2
        return d

    n = 0
    for e in ev:
        if e["kind"] == "pose" and t0 <= e["t"] <= ph["end"]:
            assert e["axes"][0] == pytest.approx(s(e["t"] - t0), abs=1e-5)
            n += 1
    assert n == round((ph["end"] - t0) / DT) + 1


def test_ptp_vel_axis_and_override_scale_speed():
    """The program override scales the motion's time, as KSS does (speeds by ov, accelerations
    by ov²: the END signals of every _po85 recording fit T/0.85, docs/robot.md)."""
    P = MotionParams().with_(ov_pro=50.0)
    _, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("PTP", dict(HOME, A1=90.0), P)])
    ph = _phase_times(ev, 2)
    expected = single_axis_time(90.0, A1_V, A1_A) / 0.5
    assert ph["reached"] - ph["start"] == pytest.approx(expected, abs=1e-6)  # the trace keeps µs
    P = MotionParams().with_(vel_axis=(50.0,) * 6)
    _, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("PTP", dict(HOME, A1=90.0), P)])
    ph = _phase_times(ev, 2)
    expected = single_axis_time(90.0, A1_V * 0.5, A1_A)
    assert ph["reached"] - ph["start"] == pytest.approx(expected, abs=1e-6)  # the trace keeps µs


def test_ptp_partial_and_relative_targets():
    P = MotionParams()
    ctl, ev = _run([MotionRequest("PTP", HOME, P), MotionRequest("PTP", {"A1": 20}, P),
                    MotionRequest("PTP_REL", {"A3": -10, "A1": 5}, P)])
    q = ctl.actual.axis_act()
    assert list(q) == pytest.approx([25, -90, 80, 0, 0, 0], abs=1e-9)


def test_ptp_cartesian_target_reaches_pose():
    P = MotionParams()
    tool_down = dict(HOME, A5=90)
    ctl, _ = _run([MotionRequest("PTP", tool_down, P),
                   MotionRequest("PTP", {"X": 500, "Y": 100, "Z": 600}, P)])
    pos = ctl.actual.pos_act()
    assert (pos["X"], pos["Y"], pos["Z"]) == pytest.approx((500, 100, 600), abs=1e-6)
    assert pos["S"] == 2


def test_ptp_soft_limit_error_at_planning():
    ctl = Controller(mujoco=False)
    ctl.queue.enqueue(MotionRequest("PTP", HOME, MotionParams()))
    with pytest.raises(SoftLimitError) as ei:
        ctl.queue.enqueue(MotionRequest("PTP", {"A1": 175}, MotionParams()))
    assert ei.value.message == "software limit switch +A1"
    assert len(ctl.queue) == 1  # nothing queued for the failing statement


def test_first_motion_must_be_complete():
    ctl = Controller(mujoco=False)
    with pytest.raises(RobotError):
        ctl.queue.enqueue(MotionRequest("PTP", {"A1": 10}, MotionParams()))


def test_motion_params_from_sysvars():
    p = MotionParams.from_sysvars({
        "$VEL": {"CP": 0.3, "ORI1": 150}, "$acc_axis": [50] * 6,
        "$APO": {"CDIS": 12.5, "CPTP": 20}, "$TOOL": {"X": 0, "Y": 0, "Z": 225, "A": 0, "B": 0, "C": 0},
        "$ORI_TYPE": "#CONSTANT", "$OV_PRO": 75})
    assert (p.vel_cp, p.vel_ori1, p.vel_ori2) == (0.3, 150.0, 200.0)
    assert p.acc_axis == (50.0,) * 6 and p.vel_axis == (100.0,) * 6
    assert (p.apo_cdis, p.apo_cptp, p.apo_cvel) == (12.5, 20.0, 100.0)
    assert p.tool == (0.0, 0.0, 225.0, 0.0, 0.0, 0.0)
    assert p.ori_type == "CONSTANT" and p.ov_pro == 75.0


def test_ptp_status_and_turn_select_the_configuration():
    """PTP to an E6POS with S/T: the configuration the bits name (reference §6.5)."""
    ctl = Controller(mujoco=False)
    goal = [20.0, -80.0, 100.0, 40.0, -30.0, -120.0]  # A5 < 0: S bit 2; A6 < 0: T bit 5
    x, y, z, a, b, c = matrix_to_frame(ctl.model.kin.forward(goal))
    s, t = ctl.model.kin.status_turn(goal)
    assert s & 4 and t & 32
    run_motions(ctl, [MotionRequest("PTP", dict(HOME, A5=30), MotionParams()),
                      MotionRequest("PTP", {"X": x, "Y": y, "Z": z, "A": a, "B": b, "C": c,
                                            "S": s, "T": t}, MotionParams())])
    assert list(ctl.actual.axis_act()) == pytest.approx(goal, abs=1e-6)
