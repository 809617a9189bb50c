"""The 4-axis palletizer of the robot library (robot/data/kr180_r3200_pa.dat; issue 22,
docs/robot.md "The palletizer"): A4 fixed at 0, A5 led by the parallelogram so that the flange
stays vertical, and an inverse that keeps X, Y, Z and the rotation about the vertical.

Expected poses are computed by hand from the data's lengths (mm): A2 axis 675 above the foot
and 350 ahead of A1; link arm 1350; arm 1220 from A3 to A5; flange 280 ahead of A5 and 250
below it. With KUKA's directions the link arm's elevation is -A2 and the arm's -(A2 + A3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.errors import SoftLimitError, WorkspaceError
from robot.frames import frame_to_matrix, matrix_to_frame
from robot.kinematics import Kinematics
from robot.mada import MachineDataError, load_mada
from robot.machine import ROBOT_LIBRARY, library_robots

PA = ROBOT_LIBRARY / "kr180_r3200_pa.dat"


@pytest.fixture(scope="module")
def pa():
    return load_mada(PA)


def hand_flange(a1, a2, a3):
    """Flange position (mm) of the palletizer, by hand (module docstring)."""
    up, fore = math.radians(-a2), math.radians(-(a2 + a3))
    r = 350 + 1350 * math.cos(up) + 1220 * math.cos(fore) + 280
    z = 675 + 1350 * math.sin(up) + 1220 * math.sin(fore) - 250
    w = math.radians(-a1)                       # $AXIS_DIR[1] = -1: A1 > 0 turns clockwise
    return np.array([r * math.cos(w), r * math.sin(w), z])


def test_the_library_lists_the_palletizer_and_the_model_says_what_it_is(pa):
    assert library_robots()["kr180_r3200_pa"] == PA
    assert pa.a4fix and pa.a5link
    assert pa.trafoname == "#KR180R3200 PA C4 FLR"
    assert pa.joints[3].limit_deg == (0.0, 0.0)
    assert [round(v, 3) for v in pa.max_speed_deg_s] == [105.0, 107.0, 114.0, 100.0, 300.0, 292.0]
    # the A5 point at full stretch: 350 + 1350 + 1220
    assert pa.reach_wrist_point_mm == pytest.approx(2920.0)
    assert pa.provenance["$DEF_A5LINK"].endswith("kr180_r3200_pa.dat:21")


@pytest.mark.parametrize("q", [(0, -90, 90), (30, -45, 90), (-120, -100, 140), (75, -20, 40)])
def test_forward_kinematics_matches_the_hand_computed_pose(pa, q):
    a1, a2, a3 = q
    axes = [a1, a2, a3, 0.0, 90.0 - a2 - a3, 17.0]
    T = Kinematics(pa).forward(axes)
    assert np.allclose(T[:3, 3], hand_flange(a1, a2, a3), atol=1e-6)
    assert T[2, 2] == pytest.approx(-1.0, abs=1e-12)     # the flange looks straight down


def test_home_is_the_pose_of_the_data(pa):
    assert pa.home_flange_pose[:3] == pytest.approx((1850.0, 0.0, 1775.0), abs=1e-6)


def test_inverse_returns_the_linked_configuration(pa):
    k = Kinematics(pa)
    rng = np.random.default_rng(7)
    for _ in range(40):
        a1, a2, a3, a6 = rng.uniform(-150, 150), rng.uniform(-130, -15), rng.uniform(10, 150), rng.uniform(-300, 300)
        axes = [a1, a2, a3, 0.0, 90.0 - a2 - a3, a6]
        if not k.within_limits(axes):
            continue
        got = k.inverse(k.forward(axes), reference_deg=axes)
        assert np.allclose(got, axes, atol=1e-7), (axes, got)
        assert got[3] == 0.0


def test_a_tilted_target_keeps_its_position_and_the_flange_stays_vertical(pa):
    k = Kinematics(pa)
    # a taught pose of the palletizer backup: B and C a few tenths of a degree off the vertical
    T = frame_to_matrix(1435.0, -405.0, 300.0, 178.66, 0.665, -179.63)
    q = k.inverse(T, reference_deg=pa.home_deg)
    F = k.forward(q)
    assert np.allclose(F[:3, 3], T[:3, 3], atol=1e-6)
    assert F[2, 2] == pytest.approx(-1.0, abs=1e-12)
    assert q[3] == 0.0 and q[4] == pytest.approx(90.0 - q[1] - q[2])
    # the rotation about the vertical is the target's A
    assert matrix_to_frame(F)[3] == pytest.approx(178.66, abs=0.05)


def test_status_bit_2_and_the_turn_of_a4_a5_select_nothing(pa):
    """The backup's points carry S 6 / T 18 (A5 < 0) for poses whose linked A5 is positive on
    this model: a palletizer cannot choose A5, so those bits are free."""
    k = Kinematics(pa)
    axes = [15.0, -54.0, 140.0, 0.0, 4.0, 14.0]
    T = k.forward(axes)
    for status, turn in ((2, 2), (6, 18), (6, 2)):
        assert np.allclose(k.inverse(T, status, turn, pa.home_deg), axes, atol=1e-7)
    with pytest.raises(SoftLimitError, match="A2"):
        k.inverse(T, 0, 2, pa.home_deg)              # bit 1 still selects: the other elbow, past A2's range


def test_out_of_reach_is_a_workspace_error(pa):
    with pytest.raises(WorkspaceError):
        Kinematics(pa).inverse(frame_to_matrix(3500.0, 0.0, 500.0, 0.0, 0.0, 180.0))


def test_a_palletizer_whose_home_does_not_look_down_is_refused(tmp_path):
    text = PA.read_text(encoding="utf-8").replace("A5 90.0000,A6", "A5 45.0000,A6")
    bad = tmp_path / "$machine.dat"
    bad.write_text(text, encoding="utf-8")
    with pytest.raises(MachineDataError, match=r"\$DEF_A5LINK.*straight down"):
        load_mada(bad)
