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
from scipy.spatial.transform import Rotation

from robot.errors import SoftLimitError, WorkspaceError
from robot.frames import frame_to_matrix, matrix_to_frame
from robot.kinematics import Kinematics
from robot.mada import MachineDataError, load_mada
from robot.machine import ROBOT_LIBRARY, library_robots
from robot.show import show_lines

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


# ---------------------------------------------------------------- the 5-axis palletizer
# robot/data/kr180_r3200_pa5.dat: the same arm with $DEF_A4FIX TRUE and $DEF_A5LINK FALSE (issue 34):
# A5 is driven, so the flange tilts in the arm's vertical plane by d = A2 + A3 + A5 - 90 deg from
# pointing straight down (A5 decreasing turns it towards the front, as A5 > 0 turns a six-axis
# KUKA flange down). By hand, in the arm plane (r ahead, z up): the flange axis points along
# (-sin d, -cos d), the direction 'ahead' of it along (cos d, -sin d), and the flange sits 280 mm
# ahead of and 250 mm along the axis from the A5 point.

PA5 = ROBOT_LIBRARY / "kr180_r3200_pa5.dat"


@pytest.fixture(scope="module")
def pa5():
    return load_mada(PA5)


def hand_flange5(a1, a2, a3, a5):
    up, fore = math.radians(-a2), math.radians(-(a2 + a3))
    d = math.radians(a2 + a3 + a5 - 90.0)
    r = 350 + 1350 * math.cos(up) + 1220 * math.cos(fore) + 280 * math.cos(d) - 250 * math.sin(d)
    z = 675 + 1350 * math.sin(up) + 1220 * math.sin(fore) - 280 * math.sin(d) - 250 * math.cos(d)
    w = math.radians(-a1)
    axis = np.array([-math.sin(d) * math.cos(w), -math.sin(d) * math.sin(w), -math.cos(d)])
    return np.array([r * math.cos(w), r * math.sin(w), z]), axis


def test_the_5_axis_palletizer_is_its_own_family(pa5):
    assert pa5.a4fix and not pa5.a5link
    assert Kinematics(pa5).family == "palletizer5"
    assert pa5.joints[3].limit_deg == (0.0, 0.0)


@pytest.mark.parametrize("q", [(0, -90, 90, 90), (30, -45, 90, 10), (-120, -100, 140, -30), (75, -20, 40, 100)])
def test_5_axis_forward_kinematics_by_hand(pa5, q):
    a1, a2, a3, a5 = q
    T = Kinematics(pa5).forward([a1, a2, a3, 0.0, a5, 23.0])
    pos, axis = hand_flange5(a1, a2, a3, a5)
    assert np.allclose(T[:3, 3], pos, atol=1e-6)
    assert np.allclose(T[:3, 2], axis, atol=1e-12)         # the flange's Z is the A6 axis


def test_5_axis_inverse_round_trip(pa5):
    k = Kinematics(pa5)
    rng = np.random.default_rng(9)
    n = 0
    for _ in range(60):
        axes = [rng.uniform(-170, 170), rng.uniform(-130, -15), rng.uniform(10, 150), 0.0,
                rng.uniform(-115, 115), rng.uniform(-300, 300)]
        if not k.within_limits(axes) or abs(axes[4]) < 1.0:
            continue
        s, t = k.status_turn(axes)
        got = k.inverse(k.forward(axes), s, t, reference_deg=axes)
        assert np.allclose(got, axes, atol=1e-7), (axes, got)
        if s & 1 == 0:                   # from HOME (in front of A1): the position is reached
            got = k.inverse(k.forward(axes), reference_deg=pa5.home_deg)
            assert np.allclose(k.forward(got)[:3, 3], k.forward(axes)[:3, 3], atol=1e-6)
        n += 1
    assert n > 30


def test_5_axis_target_out_of_the_arm_plane_keeps_its_position_and_pitch(pa5):
    k = Kinematics(pa5)
    axes = [20.0, -60.0, 110.0, 0.0, 30.0, 45.0]
    T = k.forward(axes)
    # tilt the target 5 deg about its own direction 'ahead' x the axis: out of the arm plane
    n = np.array([-math.sin(math.radians(-20.0)), math.cos(math.radians(-20.0)), 0.0])   # plane normal
    ahead = np.cross(n, T[:3, 2])
    R = Rotation.from_rotvec(ahead / np.linalg.norm(ahead) * math.radians(5.0)).as_matrix()
    T2 = T.copy()
    T2[:3, :3] = R @ T[:3, :3]
    q = k.inverse(T2, reference_deg=axes)
    F = k.forward(q)
    assert np.allclose(F[:3, 3], T[:3, 3], atol=1e-6)         # the position is kept
    assert abs(float(F[:3, 2] @ n)) < 1e-9                    # the A6 axis stays in the plane
    assert np.allclose(q, axes, atol=1e-6)                    # the out-of-plane tilt is dropped


def test_5_axis_status_bit_2_and_turn_of_a4_select_nothing(pa5):
    k = Kinematics(pa5)
    axes = [15.0, -54.0, 140.0, 0.0, 14.0, 14.0]
    T = k.forward(axes)
    for status, turn in ((2, 2), (6, 10), (6, 2)):
        assert np.allclose(k.inverse(T, status, turn, pa5.home_deg), axes, atol=1e-7)


# ---------------------------------------------------------------- KUKA's flags on a 4-axis palletizer
# KUKA's palletizers keep $DEF_A4FIX TRUE and $DEF_A5LINK FALSE on the 4-axis form too; $NUM_AX = 4
# (A1, A2, A3 and the flange axis A6 driven) leaves A5 without a drive, so the parallelogram leads it.


@pytest.fixture(scope="module")
def pa4_kuka_flags(tmp_path_factory):
    text = PA5.read_text(encoding="utf-8").replace("INT $NUM_AX=5 ;", "INT $NUM_AX=4 ;")
    assert "INT $NUM_AX=4 ;" in text and "BOOL $DEF_A5LINK=FALSE" in text
    f = tmp_path_factory.mktemp("pa4") / "$machine.dat"
    f.write_text(text, encoding="utf-8")
    return load_mada(f)


def test_num_ax_4_with_a5link_false_is_the_4_axis_palletizer(pa4_kuka_flags):
    m = pa4_kuka_flags
    assert m.a4fix and m.a5link and Kinematics(m).family == "palletizer4"
    assert "$NUM_AX=4" in m.provenance["a5_led"] and m.provenance["a5_led"].startswith("derived")
    text = "\n".join(show_lines(m))
    assert "$DEF_A4FIX=TRUE $DEF_A5LINK=FALSE (A5 led: $NUM_AX=4)" in text
    assert "4-axis palletizer" in text


@pytest.mark.parametrize("q", [(0, -90, 90), (30, -45, 90), (-120, -100, 140)])
def test_num_ax_4_forward_and_inverse_are_those_of_the_linked_arm(pa4_kuka_flags, q):
    a1, a2, a3 = q
    axes = [a1, a2, a3, 0.0, 90.0 - a2 - a3, -40.0]
    k = Kinematics(pa4_kuka_flags)
    T = k.forward(axes)
    assert np.allclose(T[:3, 3], hand_flange(a1, a2, a3), atol=1e-6)
    assert T[2, 2] == pytest.approx(-1.0, abs=1e-12)
    assert np.allclose(k.inverse(T, reference_deg=axes), axes, atol=1e-7)


def test_num_ax_below_4_is_refused_naming_it(tmp_path):
    bad = tmp_path / "$machine.dat"
    bad.write_text(PA5.read_text(encoding="utf-8").replace("INT $NUM_AX=5 ;", "INT $NUM_AX=3 ;"),
                   encoding="utf-8")
    with pytest.raises(MachineDataError, match=r"\$machine.dat:21: \$NUM_AX=3: a robot with \$DEF_A4FIX has 4..6"):
        load_mada(bad)


def test_5_axis_first_pick_of_the_issue_is_not_refused_for_the_sign_of_a5(pa5):
    """Issue 72 item 2, rebuilt from its numbers on the library's 5-axis palletizer (the KR 470
    PA-2 of the issue is neither in the catalogue nor in ../shared/robots): from XHOME {A1 2.57,
    A2 -60.81, A3 139.58, A4 0, A5 11.23, A6 92.35} (A2 + A3 + A5 = 90: the flange straight down),
    XPre_Pick_Point {X 1612.745, Y -69.344, Z -185.774, A 0, B 0, C 0, S 6, T 26} with TOOL_DATA[1]
    {Z 1025, A -90, B 0, C 180}, BASE 0, was refused at once, "software limit switch -A5": T 26
    asks A5 < 0 (bit 4) and A4 < 0 (bit 3), and this arm's A5 there is positive. In palletizing
    mode KUKA computes A5 from A2 and A3 (the flange kept parallel to the floor), so A5's sign,
    like A4's, selects nothing. Expected by hand: the TCP's Z axis is the world's, the tool's
    turns the flange's Z down, so the flange is 1025 mm above the TCP, pointing down: A1 =
    atan2(69.344, 1612.745) (A1 > 0 turns clockwise: $AXIS_DIR[1] = -1), A4 = 0 and A2 + A3 + A5
    = 90; the flange at (1612.745, -69.344, -185.774 + 1025)."""
    k = Kinematics(pa5)
    home = [2.57, -60.81, 139.58, 0.0, 11.23, 92.35]
    tcp = frame_to_matrix(1612.745, -69.344, -185.774, 0.0, 0.0, 0.0)
    tool = frame_to_matrix(0.0, 0.0, 1025.0, -90.0, 0.0, 180.0)
    flange = tcp @ np.linalg.inv(tool)
    q = k.inverse(flange, 6, 26, home)
    assert q[0] == pytest.approx(math.degrees(math.atan2(69.344, 1612.745)), abs=1e-9)
    assert q[3] == 0.0
    assert q[1] + q[2] + q[4] == pytest.approx(90.0, abs=1e-9)
    assert np.allclose(k.forward(q)[:3, 3], [1612.745, -69.344, -185.774 + 1025.0], atol=1e-6)
    assert np.allclose(k.inverse(flange, 2, 2, home), q, atol=1e-9)      # the same with S 2, T 2


def test_5_axis_a_turn_that_asks_the_other_sign_of_a1_names_a1_and_its_side(pa5):
    """Issue 85 item 2: when a program's Status/Turn search rejects every configuration (its A4
    check read limits of 0) the PTP goes out with a turn that does not fit the target. A target
    at A1 = -40 (by hand: A2 -80, A3 100, A5 30, A6 10) asked with T bit 0 clear (A1 >= 0): the
    only A1 of that sign is -40 + 360 = 320, beyond $SOFTP_END[1] = 185, so the controller's
    message is "software limit switch +A1" with the value 320 -- the axis and the side the turn
    violates, not the A4 that the search got wrong."""
    q = [-40.0, -80.0, 100.0, 0.0, 30.0, 10.0]
    kin = Kinematics(pa5)
    T = kin.forward(q)
    s, t = kin.status_turn(q)
    assert t & 1                                  # A1 < 0: bit 0 set (reference §8.1)
    np.testing.assert_allclose(kin.inverse(T, s, t, np.array(pa5.home_deg)), q, atol=1e-6)
    with pytest.raises(SoftLimitError) as exc:
        kin.inverse(T, s, t & ~1, np.array(pa5.home_deg))
    assert (str(exc.value), exc.value.axis, exc.value.value_deg) == ("software limit switch +A1", 1, pytest.approx(320.0))
