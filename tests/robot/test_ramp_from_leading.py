"""A ramp distance from a synchronised PTP that the axis leads (issue 88: a second program at a
reduced $VEL_AXIS).

With PTP_vel_test left out, no single-axis PTP at a reduced ``$VEL_AXIS`` shows a ramp (PTP_away's are
the 3 kg dynamics', tests/robot/test_ramp_shown.py), so A3 got none and PTP_vel_test's A3 runs at 10 %
were planned 4-9 % too short. PTP_away's HOME -> XP3 at 10 % (../shared/real-traces PROG.TXT: A1 +40,
A2 +65, A3 -120 deg from HOME, 3 kg, ENDTIME - START 2.291 s; at 100 % 0.331 s) is led by A3 and
takes longer than its full-speed partner explains. robot/kukatrace/identify.py ``ramp_from_leading``
identifies A3's ramp distance from it. The expected values are worked by hand in the comments.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from robot.kukatrace.identify import bare, ramp_from_leading
from robot.machine import ROBOT_LIBRARY
from robot.mada import load_mada

HOME = (0.0, -110.0, 110.0, 0.0, 0.0, 0.0)
DQ = (40.0, 65.0, -120.0, 0.0, 0.0, 0.0)        # HOME -> XP3 of PTP_away.dat


def _ptp(vel: float, plan: float, dq=DQ, kg: float = 3.0) -> dict:
    return {"q0": np.array(HOME), "dq": np.array(dq, dtype=float), "vel": [vel] * 6, "acc": [100.0] * 6,
            "plan": plan, "load": {"m": kg}}


def _machine():
    return bare(load_mada(ROBOT_LIBRARY / "kr3_r540.dat"))


def test_a3_ramp_from_home_to_xp3_at_10_percent():
    # At 10 % the axes' own times are A1 40/53.0 = 0.755 s, A2 65/52.9 = 1.229 s, A3 120/53.8 =
    # 2.230 s: A3 leads. A ramp over R deg at 53.8 deg/s is an acceleration 53.8²/(2R), so the
    # trapezoid lasts d/v + 2R/v: R = (2.291 - 2.2305)·53.8/2 = 1.628 deg (the bare machine's
    # accelerations, 8 000-50 000 deg/s², are far from binding at 10 %).
    # Its 100 % partner, 0.331 s: 0.331 - 120/538 = 0.108 s of ramp, A3 at 538/0.108 = 4 967
    # deg/s² (a trapezoid: 538²/4967 = 58 deg <= 120); with it the 10 % run would last
    # 2.2305 + 53.8/4967 = 2.241 s, and 2.291 s is 2.2 % longer: the run shows the ramp.
    got = ramp_from_leading(_machine(), [_ptp(100.0, 0.331), _ptp(10.0, 2.291)])
    assert list(got) == [2]
    assert abs(got[2][0] - (2.291 - 120.0 / 53.8) * 53.8 / 2.0) < 0.02


def test_no_ramp_without_a_partner_or_when_the_dynamics_explain_it():
    m = _machine()
    # no full-speed run of the same motion: nothing shown
    assert ramp_from_leading(m, [_ptp(10.0, 2.291)]) == {}
    # a partner of another load, or another motion, is no partner
    assert ramp_from_leading(m, [_ptp(100.0, 0.331, kg=0.661), _ptp(10.0, 2.291)]) == {}
    assert ramp_from_leading(m, [_ptp(100.0, 0.331, dq=(0.0, 65.0, -120.0, 0, 0, 0)), _ptp(10.0, 2.291)]) == {}
    # 2.245 s is within 2 % of the 2.241 s the partner's acceleration explains: the dynamics'
    assert ramp_from_leading(m, [_ptp(100.0, 0.331), _ptp(10.0, 2.245)]) == {}


def test_an_axis_that_does_not_lead_alone_gives_nothing():
    # A1 and A3 with the same time at 10 % (53.0 and 53.8 deg/s: 40 and 40.6 deg): two leading axes
    dq = (40.0, 0.0, 40.0 * 53.8 / 53.0, 0.0, 0.0, 0.0)
    assert ramp_from_leading(_machine(), [_ptp(100.0, 0.2, dq=dq), _ptp(10.0, 0.9, dq=dq)]) == {}


def test_the_machine_keeps_the_other_axes_ramps():
    # A1 with a ramp of 1.54 deg (it does not lead here: 0.755 s against A3's 2.230 s) changes nothing
    m = _machine()
    with_a1 = replace(m, ptp_ramp_deg=(1.54, 0.0, 0.0, 0.0, 0.0, 0.0))
    a = ramp_from_leading(m, [_ptp(100.0, 0.331), _ptp(10.0, 2.291)])[2][0]
    b = ramp_from_leading(with_a1, [_ptp(100.0, 0.331), _ptp(10.0, 2.291)])[2][0]
    assert abs(a - b) < 1e-3
