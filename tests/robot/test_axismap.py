"""robot/axismap.py, the one mapping of a model's axes to KRL's E6AXIS/E6POS (issues 64, 62): the
KRL vectors and components of a six-axis arm with a track, a SCARA with a turntable and a seven-axis
arm with two external axes, written out by hand from the rule (A1..An then E1..Em; a seven-axis
arm's J3 as E1, its external axes from E2)."""

from __future__ import annotations

import numpy as np
import pytest

from robot.axismap import AxisMap


def test_a_six_axis_arm_with_a_track_is_krl_order_itself():
    m = AxisMap(6, 1, (False,) * 6 + (True,), (0.0, -90.0, 90.0, 0.0, 0.0, 0.0, 10.0))
    q = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 700.0])
    assert m.slots == ("A1", "A2", "A3", "A4", "A5", "A6", "E1")
    assert m.to_krl(q) is q and m.krl_size == 7 and m.krl_index == (0, 1, 2, 3, 4, 5, 6)
    assert m.from_krl(q[:6]).tolist() == [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 10.0]     # E1 from HOME
    assert m.unit("E1") == "mm" and m.unit("A1") == "deg"


def test_a_scara_with_a_turntable_has_zero_a5_a6():
    m = AxisMap(4, 1, (False, False, True, False, False), (0.0, 0.0, 0.0, 0.0, 0.0))
    q = [10.0, 20.0, -100.0, 30.0, 45.0]
    assert m.to_krl(q).tolist() == [10.0, 20.0, -100.0, 30.0, 0.0, 0.0, 45.0]
    assert m.from_krl([10.0, 20.0, -100.0, 30.0, 99.0, 99.0, 45.0]).tolist() == q
    assert m.components(q)["E1"] == 45.0 and m.components(q)["A5"] == 0.0


def test_a_seven_axis_arm_carries_its_redundancy_as_e1():
    m = AxisMap(7, 2, (False,) * 9, (0.0,) * 7 + (5.0, 6.0))
    q = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 80.0, 90.0]       # J1..J7, then two external axes
    assert m.slots == ("A1", "A2", "E1", "A3", "A4", "A5", "A6", "E2", "E3")
    assert m.robot_keys == ("A1", "A2", "E1", "A3", "A4", "A5", "A6") and m.ext_keys == ("E2", "E3")
    # KRL: A1 A2 A3 A4 A5 A6 E1 E2 E3 = J1 J2 J4 J5 J6 J7 J3 ext1 ext2
    assert m.to_krl(q).tolist() == [1.0, 2.0, 4.0, 5.0, 6.0, 7.0, 3.0, 80.0, 90.0]
    assert m.from_krl(m.to_krl(q)).tolist() == q
    assert m.from_krl([1.0, 2.0, 4.0, 5.0, 6.0, 7.0, 3.0]).tolist() == q[:7] + [5.0, 6.0]
    assert m.e_components(q) == {"E1": 3.0, "E2": 80.0, "E3": 90.0}
    assert m.external(q) == {"E2": 80.0, "E3": 90.0}
    assert m.from_components({"A3": 40.0, "E1": 30.0}).tolist() == [0.0, 0.0, 30.0, 40.0, 0.0, 0.0, 0.0, 5.0, 6.0]


def test_more_axes_than_e6axis_holds_are_refused():
    with pytest.raises(ValueError, match="E6AXIS"):
        AxisMap(8, 0, (False,) * 8, (0.0,) * 8)
    with pytest.raises(ValueError, match="5 more E components"):
        AxisMap(7, 6, (False,) * 13, (0.0,) * 13)
