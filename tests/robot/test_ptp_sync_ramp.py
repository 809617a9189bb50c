"""The ramp at a reduced $VEL_AXIS in a synchronised PTP (issue 88).

A KR C4 PTP is synchronous: every axis starts and stops together, the leading axis (the slowest
at its programmed speed) sets the duration and the others are slowed to it (the KRL reference
§6.6). The ramp bound at a reduced ``$VEL_AXIS`` (robot/limits.py ``ptp_ramp_accelerations``:
at most ``v_i² / 2R_i`` with ``v_i`` the axis' programmed speed) binds the leading axes alone
(robot/planner.py ``leading_axes``): a slowed axis never reaches its programmed speed. The times
below are worked by hand from ``T = d/v + v/a`` of the leading axis' trapezoid; the recorded case
is PTP_away's HOME -> XP1 at 10 % (../shared/real-traces: PROG.TXT's ENDTIME - START), a motion
none of the identified parameters was fitted on (robot/kukatrace/identify.py ``ptp_sets``: its
multi-axis PTPs are a check).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from interp.tracebench import real_recordings
from robot.kukatrace.identify import planned, ptp_motions
from robot.mada import load_robot
from robot.motion import MotionParams
from robot.planner import leading_axes, ptp_profile


@pytest.fixture(scope="module")
def arm():
    """The KR 3 R540 without its dynamic model (accelerations from its joints alone), without its
    short-ramp law (robot/planner.py ``short_ramp_scale``) and with a ramp distance of 10 deg on A6 only."""
    m = load_robot("kr3_r540")
    return replace(m, dynamics=None, ptp_friction=(), ptp_ramp_deg=(0.0, 0.0, 0.0, 0.0, 0.0, 10.0),
                   ptp_short_ramp_s2=0.0, ptp_short_ramp_below_s=0.0)


def _plan(machine, dq, vel):
    p = replace(MotionParams.initmov(machine), vel_axis=(vel,) * 6, acc_axis=(100.0,) * 6, ov_pro=100.0)
    return ptp_profile(np.asarray(dq, dtype=float), p, machine).t_total


def test_a_slowed_axis_ramp_bound_does_not_bind(arm):
    # 10 %: A1 60 deg at 53 deg/s (1.132 s) leads, A6 40 deg at 80 deg/s (0.5 s) is slowed.
    # A1 alone: T = 60/53 + 53/a1 (a1 its joint's acceleration, A1 has no ramp distance).
    a1 = arm.joints[0].max_acc_deg_s2
    v1 = 0.1 * arm.joints[0].max_speed_deg_s
    assert _plan(arm, [60, 0, 0, 0, 0, 40], 10.0) == pytest.approx(60 / v1 + v1 / a1, rel=1e-9)
    # with A6's bound (80²/20 = 320 deg/s², normalised 320/40 = 8 /s²) it would take 60/53 + (53/60)/8
    assert _plan(arm, [60, 0, 0, 0, 0, 40], 10.0) < 60 / v1 + (v1 / 60) / 8.0 - 0.09


def test_the_leading_axis_ramp_bound_binds(arm):
    # 10 %: A6 170 deg at 80 deg/s (2.125 s) leads; its bound 80²/(2·10) = 320 deg/s²:
    # T = 170/80 + 80/320 = 2.375 s whether A1 moves 10 deg with it or not
    assert _plan(arm, [10, 0, 0, 0, 0, 170], 10.0) == pytest.approx(170 / 80 + 80 / 320, rel=1e-9)
    assert _plan(arm, [0, 0, 0, 0, 0, 170], 10.0) == pytest.approx(170 / 80 + 80 / 320, rel=1e-9)


def test_leading_axes():
    v = np.array([53.0, 52.9, 53.8, 60.0, 60.0, 80.0])
    assert list(leading_axes(np.array([60, 75, -40, -80, 40, 80.0]), v)) == [False, True] + [False] * 4
    # two axes at the same time both lead; an axis that does not move never does
    assert list(leading_axes(np.array([53.0, 0, 0, 0, 0, 80.0]), v)) == [True, False, False, False, False, True]
    assert not leading_axes(np.zeros(6), v).any()


def test_ptp_away_home_to_xp1_at_10_percent(real_traces):
    # PTP_away's first motion of A1_away_10: HOME -> XP1, every axis moving (A1 60, A2 75, A3 -40,
    # A4 -80, A5 40, A6 80 deg), 3 kg, 10 % $VEL_AXIS; A2 leads (75/52.9 = 1.418 s). PROG.TXT:
    # ENDTIME - START = 1.452 s. With every moving axis' ramp bound A6's (80 deg/s) made it
    # 1.60 s (+10 %); with the leading axis' 1.449 s (-0.2 %); under the short-ramp law that replaced
    # the ramp distances (robot/planner.py short_ramp_scale, issue 88) 1.432 s (-1.4 %)
    (mot,) = [m for m in ptp_motions(real_recordings(real_traces, {"PTP_away"}))
              if m["name"] == "A1_away_10" and m["k"] == 0]
    assert mot["plan"] == pytest.approx(1.452, abs=0.001)
    assert planned(load_robot("kr3_r540"), mot) == pytest.approx(mot["plan"], rel=0.02)
