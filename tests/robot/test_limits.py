"""The limits checker (robot/limits.py) on hand-built traces: every expected value is
computed here from the trace we build and the machine data, not from the planner."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.kinematics import Kinematics
from robot.limits import (T1_SPEED_MM_S, MotionLimits, check_trace, motion_limits,
                          normalise_mode, red_t1_pct)
from robot.machine import load_machine
from robot.motion import MotionParams, MotionRequest

DT = 0.012
M = load_machine()
V_MAX = np.array(M.max_speed_deg_s)
A_MAX = np.array(M.max_acc_deg_s2)
HOME = np.array([0.0, -90.0, 90.0, 0.0, 90.0, 0.0])


def _motion(mid, t, phase, limits=None):
    ev = {"t": t, "kind": "motion", "id": mid, "type": "PTP", "target": {}, "approximation": None,
          "phase": phase}
    if limits is not None:
        ev["limits"] = limits.as_trace()
    return ev


def _pose(t, q):
    return {"t": round(t, 6), "kind": "pose", "axes": [float(v) for v in q], "tcp": [0.0] * 6}


def _a1_trapezoid(v, a, dist):
    """Poses of A1 moving ``dist`` deg with a trapezoid (v deg/s, a deg/s²), every 12 ms."""
    ta = v / a
    T = dist / v + ta
    out = []
    k = 1
    while True:
        t = k * DT
        tt = min(t, T)
        if tt < ta:
            s = 0.5 * a * tt * tt
        elif tt <= T - ta:
            s = 0.5 * a * ta * ta + v * (tt - ta)
        else:
            s = dist - 0.5 * a * (T - tt) ** 2
        q = HOME.copy()
        q[0] += s
        out.append(_pose(t, q))
        if t >= T + 2 * DT:
            return out, T
        k += 1


def _ptp_limits(a1_deg_s):
    axes = tuple(V_MAX)
    return MotionLimits(None, (a1_deg_s,) + axes[1:])


def test_axis_trapezoid_within_its_limits_passes():
    poses, T = _a1_trapezoid(100.0, 500.0, 40.0)
    ev = [_motion(1, DT, "start", _ptp_limits(120.0))] + poses + [_motion(1, T + 2 * DT, "end")]
    rep = check_trace(ev, M)
    assert rep.ok, [str(v) for v in rep.violations]
    assert rep.axis_speed_ratio == pytest.approx(100.0 / 120.0, rel=1e-6)
    # accelerations: a second difference of a piecewise quadratic never exceeds |q''| = 500
    assert rep.axis_acc_ratio <= 500.0 / A_MAX[0] + 1e-9
    assert rep.axis_acc_ratio > 0.5 * 500.0 / A_MAX[0]


def test_axis_speed_above_the_programmed_limit_is_a_violation():
    poses, T = _a1_trapezoid(100.0, 500.0, 40.0)
    ev = [_motion(1, DT, "start", _ptp_limits(90.0))] + poses + [_motion(1, T + 2 * DT, "end")]
    rep = check_trace(ev, M)
    assert not rep.ok
    v = rep.violations[0]
    assert (v.what, v.axis, v.motion) == ("axis_speed", 1, 1)
    assert rep.axis_speed_ratio == pytest.approx(100.0 / 90.0, rel=1e-6)
    # 3 % tolerance: 100 against 98 is allowed
    ev[0] = _motion(1, DT, "start", _ptp_limits(98.0))
    assert check_trace(ev, M).ok


def test_a_velocity_step_is_an_acceleration_violation_unless_it_is_a_fault_stop():
    # A1 jumps from rest to 50 deg/s (0.6° per cycle): 50/0.012 = 4167 deg/s² > a_max 1241
    poses = [_pose(k * DT, HOME + [0.6 * max(0, k - 3), 0, 0, 0, 0, 0]) for k in range(1, 12)]
    ev = [_motion(1, DT, "start", _ptp_limits(360.0))] + poses
    rep = check_trace(ev, M)
    acc = [v for v in rep.violations if v.what == "axis_acc"]
    assert acc and acc[0].axis == 1
    assert acc[0].value == pytest.approx(50.0 / DT, rel=1e-6)
    # the same jump as a stop right after an error is a fault stop, not planned motion
    poses = [_pose(k * DT, HOME + [0.6 * min(k, 5), 0, 0, 0, 0, 0]) for k in range(1, 12)]
    ev = ([_motion(1, DT, "start", _ptp_limits(360.0))] + poses[:5]
          + [{"t": 5 * DT, "kind": "error", "text": "x"}] + poses[5:])
    rep = check_trace(ev, M)
    assert not [v for v in rep.violations if v.what == "axis_acc"]


def _line_poses(kin, p0, direction, speed, n, t0=DT):
    """Axes of a straight TCP line ($TOOL = $BASE = NULLFRAME) at ``speed`` mm/s."""
    ref = HOME.copy()
    T0 = kin.forward(np.array([0.0, -90.0, 90.0, 0.0, 45.0, 0.0]))
    out = []
    for k in range(n):
        T = T0.copy()
        T[:3, 3] = np.asarray(p0) + np.asarray(direction) * speed * k * DT
        ref = kin.inverse(T, reference_deg=ref)
        out.append(_pose(t0 + k * DT, ref))
    return out


def test_tcp_path_speed_is_measured_through_the_kinematics():
    kin = Kinematics(M)
    lim = MotionLimits(500.0, tuple(V_MAX))
    # 480 mm/s on a straight line: within 500 (ratio 0.96)
    poses = _line_poses(kin, (500.0, -50.0, 600.0), (0.0, 1.0, 0.0), 480.0, 20)
    rep = check_trace([_motion(1, DT, "start", lim)] + poses, M)
    assert rep.ok and rep.path_ratio == pytest.approx(0.96, abs=1e-6)
    # 560 mm/s: 112 % of $VEL.CP
    poses = _line_poses(kin, (500.0, -50.0, 600.0), (0.0, 1.0, 0.0), 560.0, 20)
    rep = check_trace([_motion(1, DT, "start", lim)] + poses, M)
    assert [v.what for v in rep.violations][:1] == ["path"]
    assert rep.path_ratio == pytest.approx(1.12, abs=1e-6)


def test_in_an_approximation_window_the_larger_limit_applies():
    kin = Kinematics(M)
    poses = _line_poses(kin, (500.0, -50.0, 600.0), (0.0, 1.0, 0.0), 560.0, 20)
    slow, fast = MotionLimits(500.0, tuple(V_MAX)), MotionLimits(600.0, tuple(V_MAX))
    t_end = poses[-1]["t"]
    ev = [_motion(1, DT, "start", slow), _motion(2, DT, "start", fast)] + poses + \
        [_motion(1, t_end, "end")]
    assert check_trace(ev, M).ok
    # after the first motion ended only the second one's limit counts; before the second
    # started, only the first one's
    ev = [_motion(1, DT, "start", slow)] + poses[:10] + [_motion(1, poses[9]["t"], "end"),
                                                          _motion(2, poses[9]["t"], "start", fast)] + poses[10:]
    rep = check_trace(ev, M)
    assert rep.violations and all(v.t <= poses[9]["t"] + 1e-9 for v in rep.violations)


def test_motion_limits_from_the_request():
    P = MotionParams().with_(vel_cp=0.8, ov_pro=50.0, vel_axis=(20.0,) * 6)
    lin = motion_limits(MotionRequest("LIN", {"X": 1}, P), M, "AUT")
    assert lin.path == pytest.approx(400.0) and lin.axes == pytest.approx(tuple(V_MAX))
    ptp = motion_limits(MotionRequest("PTP", {"A1": 1}, P), M, "AUT")
    assert ptp.path is None and ptp.axes == pytest.approx(tuple(V_MAX * 0.2 * 0.5))
    # T1: TCP and flange 250 mm/s, PTP axes reduced by $RED_T1 (7 %, robot-model.md §10)
    assert red_t1_pct(M) == 7.0
    ptp1 = motion_limits(MotionRequest("PTP", {"A1": 1}, P), M, "T1")
    assert ptp1.path == T1_SPEED_MM_S and ptp1.flange == T1_SPEED_MM_S
    assert ptp1.axes == pytest.approx(tuple(V_MAX * 0.2 * 0.5 * 0.07))
    lin1 = motion_limits(MotionRequest("LIN", {"X": 1}, P.with_(ov_pro=100.0)), M, "T1")
    assert lin1.path == T1_SPEED_MM_S


def test_mode_names():
    assert normalise_mode("EXT") == "EX" and normalise_mode("#t1") == "T1"
    assert normalise_mode(None) == "AUT"
    with pytest.raises(ValueError):
        normalise_mode("T3")


def test_flange_speed_is_checked_in_t1():
    kin = Kinematics(M)
    poses = _line_poses(kin, (500.0, -50.0, 600.0), (0.0, 1.0, 0.0), 300.0, 10)
    lim = MotionLimits(None, tuple(V_MAX), T1_SPEED_MM_S)
    rep = check_trace([_motion(1, DT, "start", lim)] + poses, M)
    assert [v.what for v in rep.violations][:1] == ["flange"]
    assert rep.flange_ratio == pytest.approx(300.0 / 250.0, abs=1e-6)
    assert math.isclose(rep.path_ratio, 0.0)
