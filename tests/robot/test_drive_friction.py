"""The friction an axis' drive shows, taken where its PTPs cannot show it (issue 88;
robot/kukatrace/identify.py ``drive_friction``, ``fit_axes``).

A drive that lags by the torque it needs over its gain, ``e = (J q'' + F tanh(q'/v0) + b q') / K``,
has the following error ``m q'' + c tanh(q'/v0) + k q'`` with ``m = J/K``, ``c = F/K``, ``k = b/K``:
``k/m = b/J`` is the planner's friction (1/s). The figures below are worked by hand; the runs are
planned here by a robot whose friction the fit is not told.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from robot.kukatrace.identify import drive_friction, fit_axes
from robot.mada import load_robot
from robot.motion import MotionParams
from robot.planner import ptp_profile


def test_the_drive_friction_is_k_over_m_where_the_drive_shows_friction():
    following = {"inertia_s2": [2.0e-5, 4.0e-5, 5.0e-5, 5.0e-5, 0.0, 6.0e-5],
                 "coulomb_deg": [0.0, 0.0, 0.005, 0.006, 0.006, 0.007],
                 "viscous_s": [3.0e-4, 2.0e-4, 2.5e-4, -1.0e-4, 2.0e-4, 2.4e-4],
                 "coulomb_speed_deg_s": 2.0}
    got = drive_friction(following)
    # A1, A2: no Coulomb term (their k is a lag's, not a friction); A4: k < 0; A5: m 0
    assert got.tolist() == pytest.approx([0.0, 0.0, 2.5e-4 / 5.0e-5, 0.0, 0.0, 2.4e-4 / 6.0e-5])
    assert got[2] == pytest.approx(5.0) and got[5] == pytest.approx(4.0)


def _robot(friction_a5: float):
    """The KR 3 R540 without its dynamic model or ramp law, A5 at 16 000 deg/s² with the friction given."""
    m = load_robot("kr3_r540")
    joints = tuple(replace(j, max_acc_deg_s2=16000.0) if i == 4 else j for i, j in enumerate(m.joints))
    return replace(m, joints=joints, dynamics=None, ptp_ramp_deg=(), ptp_short_ramp_s2=0.0, ptp_short_ramp_below_s=0.0,
                   ptp_friction=(0.0, 0.0, 0.0, 0.0, friction_a5, 0.0))


def _a5_runs(truth, accs) -> list[dict]:
    """Single-axis PTPs of A5 by 60, 110 and 170 deg at 100 % $VEL_AXIS and each $ACC_AXIS of `accs`,
    planned by `truth`, as the identification reads them."""
    mots = []
    for acc in accs:
        for d in (60.0, 110.0, 170.0):
            dq = np.zeros(6)
            dq[4] = d
            p = replace(MotionParams.initmov(truth), vel_axis=(100.0,) * 6, acc_axis=(acc,) * 6, ov_pro=100.0)
            mots.append({"dq": dq, "q0": np.zeros(6), "vel": [100.0] * 6, "acc": [acc] * 6, "load": None,
                         "plan": ptp_profile(dq, p, truth).t_total})
    return mots


def test_runs_at_full_acceleration_take_the_drives_friction_and_fit_the_acceleration_beside_it():
    truth = _robot(4.0)
    runs = _a5_runs(truth, (100.0,))
    base = _robot(0.0)
    acc, _ramp, fric = fit_axes(base, runs, friction=np.array([0.0, 0.0, 0.0, 0.0, 4.0, 0.0]))
    assert fric[4] == 4.0
    assert acc[4] == pytest.approx(16000.0, rel=2e-3)
    # without it the runs at 100 % show no friction: none is fitted, and A5 trades for it
    acc0, _ramp, fric0 = fit_axes(base, runs)
    assert fric0[4] == 0.0
    # the plan at 10 % $ACC_AXIS: with the drive's friction as the truth's, without it shorter
    slow = _a5_runs(truth, (10.0,))
    with_f = replace(base, joints=tuple(replace(j, max_acc_deg_s2=float(a)) for j, a in zip(base.joints, acc)),
                     ptp_friction=tuple(float(c) for c in fric))
    without = replace(base, joints=tuple(replace(j, max_acc_deg_s2=float(a)) for j, a in zip(base.joints, acc0)),
                      ptp_friction=tuple(float(c) for c in fric0))
    for m in slow:
        p = replace(MotionParams.initmov(base), vel_axis=(100.0,) * 6, acc_axis=(10.0,) * 6, ov_pro=100.0)
        assert ptp_profile(m["dq"], p, with_f).t_total == pytest.approx(m["plan"], rel=2e-3)
        assert ptp_profile(m["dq"], p, without).t_total < 0.97 * m["plan"]


def test_a_run_at_a_reduced_acceleration_shows_the_friction_itself():
    truth = _robot(4.0)
    runs = _a5_runs(truth, (100.0, 10.0))
    _acc, _ramp, fric = fit_axes(_robot(0.0), runs, friction=np.array([0.0, 0.0, 0.0, 0.0, 9.0, 0.0]))
    assert fric[4] == pytest.approx(4.0, abs=0.1)
