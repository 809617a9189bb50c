"""The ramp distance of an axis that no recording of the fold shows (issue 88, helper plan4).

With PTP_vel_test left out of ../shared/real-traces, only A1 and A3 get a ramp distance at a reduced
``$VEL_AXIS`` (from PTP_away's synchronised PTPs at 10 %: A1 0.755 deg, A3 1.624 deg;
robot/kukatrace/identify.py ``ramp_from_leading``); A2 and the wrist got none and PTP_vel_test's
10 % runs of A6 were planned 11.6 % too short. ``ramp_fallback`` gives such an axis the shortest
ramp time shown, ``min_j 2 R_j / v_j``, at its own speed. The values are worked by hand below.
"""

from __future__ import annotations

import pytest

from robot.kukatrace.identify import ramp_fallback

V = (530.0, 529.0, 538.0, 600.0, 600.0, 800.0)     # the KR 3 R540's axis speeds, deg/s


def test_the_axes_without_a_ramp_take_the_shortest_ramp_time_shown():
    # A1: 2 x 0.755 / 530 = 2.849 ms, A3: 2 x 1.624 / 538 = 6.037 ms: the shortest 2.849 ms.
    # A2 at 529 deg/s: 529 x 2.849e-3 / 2 = 0.7536 deg; A4, A5 at 600: 0.8547; A6 at 800: 1.1396
    got = ramp_fallback((0.755, 0.0, 1.624, 0.0, 0.0, 0.0), V, {0, 1, 2, 3, 4, 5})
    assert got[0] == 0.755 and got[2] == 1.624
    assert got[1] == pytest.approx(0.7536, abs=1e-4)
    assert got[3] == pytest.approx(0.8547, abs=1e-4) and got[4] == pytest.approx(0.8547, abs=1e-4)
    assert got[5] == pytest.approx(1.1396, abs=1e-4)


def test_nothing_to_take_from_or_nothing_missing():
    # no axis shows a ramp: none is made up
    assert ramp_fallback((0.0,) * 6, V, {0, 1, 2, 3, 4, 5}) == (0.0,) * 6
    # every axis has one: unchanged (the fit on all programs, robot/data/identified/kr3_r540.yaml)
    every = (1.435, 0.792, 1.574, 5.149, 3.246, 9.214)
    assert ramp_fallback(every, V, {0, 1, 2, 3, 4, 5}) == every


def test_an_axis_without_a_ptp_neither_gives_nor_takes():
    # A6 has no PTP in the fold (its 2 deg is fit_axes' default, not a recording's): it is not a
    # source, so A1's 2 x 2.0 / 530 = 7.547 ms is the shortest shown, not A6's 2 x 2 / 800 = 5 ms
    # (A2 would get 529 x 5e-3 / 2 = 1.3225 deg), and it keeps its value.
    # A2 at 529 deg/s: 529 x 7.547e-3 / 2 = 1.9962 deg
    got = ramp_fallback((2.0, 0.0, 0.0, 0.0, 0.0, 2.0), V, {0, 1, 2, 3, 4})
    assert got[5] == 2.0
    assert got[1] == pytest.approx(1.9962, abs=1e-4)
