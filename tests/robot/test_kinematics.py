"""Forward/inverse kinematics, status/turn, soft limits and the $BASE/$TOOL chain.

Expected values are taken from robot-model.md (§4.1 DH table, §5 limits and
speeds, §7 worked $POS_ACT example, §9 test vectors), or computed here from
those tables with an independent implementation; never from the code under test.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from robot.errors import RobotError, SoftLimitError, WorkspaceError
from robot.frames import frame_to_matrix
from robot.kinematics import Kinematics
from robot.machine import load_machine

LIMITS = np.array([[-170, 170], [-190, 45], [-120, 156], [-185, 185], [-120, 120], [-350, 350]], dtype=float)


@pytest.fixture(scope="module")
def kin() -> Kinematics:
    return Kinematics(load_machine())


# --------------------------------------------------------------------------- helpers
def abc_matrix(a: float, b: float, c: float) -> np.ndarray:
    """R = Rz(A)·Ry(B)·Rx(C) written out (robot-model.md §6)."""
    cA, sA = math.cos(math.radians(a)), math.sin(math.radians(a))
    cB, sB = math.cos(math.radians(b)), math.sin(math.radians(b))
    cC, sC = math.cos(math.radians(c)), math.sin(math.radians(c))
    return np.array([
        [cA * cB, cA * sB * sC - sA * cC, cA * sB * cC + sA * sC],
        [sA * cB, sA * sB * sC + cA * cC, sA * sB * cC - cA * sC],
        [-sB, cB * sC, cB * cC],
    ])


# robot-model.md §4.1: standard DH with KUKA angles, T_i = Rz(theta) Tz(d) Tx(a) Rx(alpha), mm
DH = [  # a, alpha, d, theta sign, theta offset
    (25.0, -90.0, 400.0, -1, 0.0),
    (455.0, 0.0, 0.0, 1, 0.0),
    (35.0, -90.0, 0.0, 1, -90.0),
    (0.0, 90.0, 420.0, -1, 0.0),
    (0.0, -90.0, 0.0, 1, 0.0),
    (0.0, 0.0, 80.0, -1, 180.0),
]


def dh_forward(q_deg) -> np.ndarray:
    T = np.eye(4)
    for (a, alpha, d, sgn, off), q in zip(DH, q_deg):
        th = math.radians(sgn * q + off)
        al = math.radians(alpha)
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
        T = T @ np.array([
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ])
    return T


def rot_angle_deg(R1, R2) -> float:
    c = (np.trace(np.asarray(R1)[:3, :3].T @ np.asarray(R2)[:3, :3]) - 1.0) / 2.0
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def random_axes(rng, n):
    return rng.uniform(LIMITS[:, 0], LIMITS[:, 1], size=(n, 6))


# --------------------------------------------------------------------------- machine data
def test_machine_data_from_yaml():
    m = load_machine()
    assert m.name == "KR 6 R900 sixx"
    assert [j.axis for j in m.joints] == [1, 2, 3, 4, 5, 6]
    assert [j.limit_deg for j in m.joints] == [tuple(r) for r in LIMITS]
    # robot-model.md §5: $VEL_AXIS_MA / |$RAT_MOT_AX| * 6
    np.testing.assert_allclose([j.max_speed_deg_s for j in m.joints],
                               [360.0, 300.0, 360.0, 381.18, 388.34, 615.09], atol=0.01)
    np.testing.assert_allclose(m.joints[0].max_acc_deg_s2, math.degrees(21.666156), rtol=1e-9)
    assert m.home_deg == (0.0, -90.0, 90.0, 0.0, 0.0, 0.0)
    assert m.status_phi_deg == pytest.approx(math.degrees(math.atan2(35, 420)), abs=1e-9)
    assert m.ipo_cycle_s == 0.012
    assert (m.vel_ma.cp, m.vel_ma.ori1, m.vel_ma.ori2) == (3.0, 400.0, 400.0)
    assert m.vel_ma["cp"] == 3.0 and m.acc_ma.cp == 10.0
    assert m.apo_dis_ptp_deg == (90.0,) * 6
    assert m.default_tool_frame == (0.0, 0.0, 225.0, 0.0, 0.0, 0.0)
    assert m.robroot_frame == (0.0,) * 6
    np.testing.assert_allclose(m.flange_quat_wxyz, [math.sqrt(0.5), 0, math.sqrt(0.5), 0], atol=1e-12)
    o = m.opw
    assert (o.a1, o.a2, o.b, o.c1, o.c2, o.c3, o.c4) == pytest.approx((25, -35, 0, 400, 455, 420, 80))


# --------------------------------------------------------------------------- FK
# robot-model.md §9
VECTORS = [
    ((0, -90, 90, 0, 0, 0), (525, 0, 890), (0, 90, 0), 2, 2),
    ((0, -90, 90, 0, 90, 0), (445, 0, 810), (180, 0, 180), 2, 2),
    ((30, -60, 100, 40, -50, 120), (596.733, -299.038, 553.791), (-94.0147, -59.4559, -85.8975), 6, 18),
    ((-45, -100, 110, -170, 35, -300), (304.128, 315.397, 842.747), (149.4735, -17.3932, 64.2863), 2, 43),
    ((0, -150, 20, 0, 10, 0), (-705.824, 0, 996.023), (0, -30, 0), 3, 2),
]


@pytest.mark.parametrize("axes,xyz,abc,s,t", VECTORS)
def test_section9_vectors(kin, axes, xyz, abc, s, t):
    F = kin.forward(axes)
    assert F.shape == (4, 4)
    np.testing.assert_allclose(F[:3, 3], xyz, atol=1e-3)
    assert rot_angle_deg(F[:3, :3], abc_matrix(*abc)) < 1e-3
    assert kin.status_turn(axes) == (s, t)
    # and back: the given S/T select exactly these axes
    np.testing.assert_allclose(kin.inverse(F, s, t), axes, atol=1e-6)


def test_fk_equals_dh_table(kin):
    rng = np.random.default_rng(21)
    for q in random_axes(rng, 300):
        np.testing.assert_allclose(kin.forward(q), dh_forward(q), atol=1e-9)


def test_wrist_point_formula(kin):
    # robot-model.md §4.4: wrist point x in the A1 frame
    rng = np.random.default_rng(22)
    for q in random_axes(rng, 50):
        a2, a23 = math.radians(q[1]), math.radians(q[1] + q[2])
        x = 25 + 455 * math.cos(a2) + 420 * math.cos(a23) + 35 * math.sin(a23)
        assert kin.wrist_point_x(q) == pytest.approx(x, abs=1e-9)


# --------------------------------------------------------------------------- frame chain (§7)
def test_pos_act_worked_example(kin):
    axes = (0, -90, 90, 0, 90, 0)
    tool = frame_to_matrix(0, 0, 225, 0, 0, 0)
    base = frame_to_matrix(500, 0, 0, 90, 0, 0)
    P = kin.tcp_pose(axes, tool=tool, base=base)
    np.testing.assert_allclose(P[:3, 3], [0, 55, 585], atol=1e-9)
    assert rot_angle_deg(P, abc_matrix(90, 0, 180)) < 1e-9
    # frames may also be given as (X, Y, Z, A, B, C)
    P2 = kin.tcp_pose(axes, tool=(0, 0, 225, 0, 0, 0), base=(500, 0, 0, 90, 0, 0))
    np.testing.assert_allclose(P2, P, atol=1e-12)
    # inverse chain: flange target of that TCP is the flange of the axes
    np.testing.assert_allclose(kin.flange_target(P, tool=tool, base=base), kin.forward(axes), atol=1e-9)
    q = kin.inverse(kin.flange_target(P, tool=tool, base=base), 2, 2)
    np.testing.assert_allclose(q, axes, atol=1e-6)


def test_robroot_in_chain(kin):
    # $POS_ACT = INV_POS($BASE) : $ROBROOT : FLANGE : $TOOL with a shifted robot root
    axes = (10, -80, 95, 5, 30, -20)
    robroot = frame_to_matrix(1000, 200, 0, 180, 0, 0)
    tool = frame_to_matrix(0, 0, 225, 0, 0, 0)
    P = kin.tcp_pose(axes, tool=tool, robroot=robroot)
    F = kin.forward(axes)
    np.testing.assert_allclose(P[:3, 3], robroot[:3, :3] @ (F[:3, 3] + F[:3, :3] @ [0, 0, 225]) + [1000, 200, 0],
                               atol=1e-9)
    np.testing.assert_allclose(kin.flange_target(P, tool=tool, robroot=robroot), F, atol=1e-9)


# --------------------------------------------------------------------------- IK
def test_ik_round_trip_random(kin):
    rng = np.random.default_rng(23)
    seen_s = set()
    for q in random_axes(rng, 1500):
        s, t = kin.status_turn(q)
        seen_s.add(s)
        q2 = kin.inverse(kin.forward(q), s, t)
        np.testing.assert_allclose(q2, q, atol=1e-6)
    assert seen_s == set(range(8))


@pytest.mark.parametrize("a4,a6", [(182.0, 300.0), (-183.5, -250.0), (184.9, -349.0), (-181.0, 345.0),
                                   (179.0, 181.0), (-179.0, -181.0)])
def test_ik_round_trip_wrist_beyond_180(kin, a4, a6):
    for a1, a2, a3, a5 in [(20, -70, 100, 40), (-60, -120, 60, -25), (150, -160, 30, 80)]:
        q = np.array([a1, a2, a3, a4, a5, a6], dtype=float)
        s, t = kin.status_turn(q)
        np.testing.assert_allclose(kin.inverse(kin.forward(q), s, t), q, atol=1e-6)


def test_every_reachable_status_turn_combination(kin):
    """For a few poses: every (S, T) an in-limit configuration can have is reproduced."""
    rng = np.random.default_rng(24)
    n_combos = 0
    for q0 in random_axes(rng, 6):
        F = kin.forward(q0)
        configs = {}
        for sol in kin.solutions(F):
            np.testing.assert_allclose(kin.forward(sol), F, atol=1e-6)
            variants = [[v + k for k in (-720, -360, 0, 360, 720) if lo - 1e-9 <= v + k <= hi + 1e-9]
                        for v, (lo, hi) in zip(sol, LIMITS)]
            for q in itertools.product(*variants):
                configs[kin.status_turn(q)] = np.array(q)
        assert kin.status_turn(q0) in configs
        for (s, t), q in configs.items():
            np.testing.assert_allclose(kin.inverse(F, s, t), q, atol=1e-6)
            n_combos += 1
    assert n_combos > 30


def test_solutions_are_eight_distinct_status(kin):
    F = kin.forward((30, -60, 100, 40, -50, 120))
    sols = kin.solutions(F)
    assert len(sols) == 8
    assert sorted(kin.status_turn(s)[0] for s in sols) == list(range(8))
    for s in sols:
        assert s.shape == (6,)
        np.testing.assert_allclose(kin.forward(s), F, atol=1e-6)


def test_status_none_keeps_reference_branch_turn_none_nearest(kin):
    q = np.array([20, -70, 100, 30, 40, 185], dtype=float)
    F = kin.forward(q)
    # reference near q: same branch, A6 = 185 is nearer to 170 than -175
    ref = np.array([20, -70, 100, 30, 40, 170], dtype=float)
    np.testing.assert_allclose(kin.inverse(F, reference_deg=ref), q, atol=1e-6)
    ref2 = np.array([20, -70, 100, 30, 40, -170], dtype=float)
    np.testing.assert_allclose(kin.inverse(F, reference_deg=ref2), q - [0, 0, 0, 0, 0, 360], atol=1e-6)
    # status None but turn given: T 34 = A2 and A6 negative
    np.testing.assert_allclose(kin.inverse(F, turn=34, reference_deg=ref), q - [0, 0, 0, 0, 0, 360], atol=1e-6)
    # T 32 would need A2 = +290
    with pytest.raises(SoftLimitError, match=r"\+A2"):
        kin.inverse(F, turn=32, reference_deg=ref)
    # reference in the flipped wrist branch (A5 < 0, S = 6): the flipped solution
    flip_ref = np.array([20, -70, 100, -150, -40, 0], dtype=float)
    q_flip = kin.inverse(F, reference_deg=flip_ref)
    assert kin.status_turn(q_flip)[0] == 6
    assert q_flip[4] == pytest.approx(-40, abs=1e-6)
    np.testing.assert_allclose(kin.forward(q_flip), F, atol=1e-6)


def test_status_bits_above_2_are_ignored(kin):
    q = (30, -60, 100, 40, -50, 120)
    F = kin.forward(q)
    np.testing.assert_allclose(kin.inverse(F, 6 | 16, 18), q, atol=1e-6)  # S 22, bit 4 set (reference §6.5)


def test_wrist_singularity_keeps_reference_a4(kin):
    home = (0, -90, 90, 0, 0, 0)
    F = kin.forward(home)
    np.testing.assert_allclose(kin.inverse(F, 2, 2), home, atol=1e-6)
    ref = (0, -90, 90, 30, 0, -10)
    q = kin.inverse(F, reference_deg=ref)
    assert q[3] == pytest.approx(30, abs=1e-6) and q[5] == pytest.approx(-30, abs=1e-6)
    np.testing.assert_allclose(kin.forward(q), F, atol=1e-9)
    # A5 = 0 is on the S bit 2 boundary: both S 2 and S 6 are accepted there
    q6 = kin.inverse(F, 6, 2)
    np.testing.assert_allclose(kin.forward(q6), F, atol=1e-9)


# --------------------------------------------------------------------------- errors
def test_soft_limit_check(kin):
    kin.check_soft_limits((0, -90, 90, 0, 0, 0))
    kin.check_soft_limits((170, -190, 156, -185, 120, 350))  # on the limits is allowed
    with pytest.raises(SoftLimitError) as e:
        kin.check_soft_limits((0, -195, 90, 0, 0, 0))
    assert e.value.message == "software limit switch -A2"
    assert e.value.axis == 2 and e.value.value_deg == -195
    assert str(e.value) == "software limit switch -A2"
    with pytest.raises(SoftLimitError, match=r"software limit switch \+A1"):
        kin.check_soft_limits((171, -90, 90, 0, 0, 0))
    with pytest.raises(SoftLimitError, match=r"software limit switch \+A6"):
        kin.check_soft_limits((0, -90, 90, 0, 0, 351))


def test_inverse_soft_limit_errors(kin):
    # A5 = 125 is the only solution of this pose with S 2 (the flip S 6 has A5 = -125)
    F = kin.forward((0, -90, 90, 0, 125, 0))
    with pytest.raises(SoftLimitError) as e:
        kin.inverse(F, 2, 2)
    assert e.value.message == "software limit switch +A5" and e.value.axis == 5
    assert e.value.value_deg == pytest.approx(125, abs=1e-6)
    assert isinstance(e.value, RobotError)
    with pytest.raises(SoftLimitError, match=r"software limit switch -A5"):
        kin.inverse(F, 6, 2 | 16)
    # an in-limit neighbour of the same pose family is fine
    F_ok = kin.forward((0, -90, 90, 0, 115, 0))
    np.testing.assert_allclose(kin.inverse(F_ok, 2, 2), (0, -90, 90, 0, 115, 0), atol=1e-6)
    # T asks for A1 < 0 where A1 = 30: -330 is outside $SOFTN_END[1]
    F2 = kin.forward((30, -60, 100, 40, -50, 120))
    with pytest.raises(SoftLimitError, match=r"software limit switch -A1") as e2:
        kin.inverse(F2, 6, 18 | 1)
    assert e2.value.value_deg == pytest.approx(-330, abs=1e-6)


def test_unreachable_target_raises_workspace_error(kin):
    F = frame_to_matrix(2000, 0, 400, 0, 90, 0)
    with pytest.raises(WorkspaceError) as e:
        kin.inverse(F, 2, 2)
    assert "workspace" in e.value.message
    assert kin.solutions(F) == []
    with pytest.raises(WorkspaceError):
        kin.inverse(frame_to_matrix(0, 0, 2500, 0, 0, 0))


def test_unreachable_status_raises_workspace_error(kin):
    # near the reach limit in front: the overhead branches (S bit 0) would need > 901 mm
    F = kin.forward((0, -30, 10, 0, 20, 0))
    assert len(kin.solutions(F)) == 4
    with pytest.raises(WorkspaceError):
        kin.inverse(F, 3, 2)


def test_status_none_from_singular_reference_is_free(kin):
    # the reference sits on A5 = 0 (S bit 2 undetermined): the nearby flipped wrist is taken,
    # not the A4 + 180 solution that S = 2 would force
    F = kin.forward((0, -90, 90, 0, -5, 0))
    np.testing.assert_allclose(kin.inverse(F, reference_deg=(0, -90, 90, 0, 0, 0)), (0, -90, 90, 0, -5, 0),
                               atol=1e-6)
    q = kin.inverse(F, 2, reference_deg=(0, -90, 90, 0, 0, 0))
    assert q[4] == pytest.approx(5, abs=1e-6) and abs(q[3]) == pytest.approx(180, abs=1e-6)


def test_forward_many_and_pos_act(kin):
    rng = np.random.default_rng(25)
    Q = random_axes(rng, 50)
    T = kin.forward_many(Q)
    assert T.shape == (50, 4, 4)
    for q, t in zip(Q, T):
        np.testing.assert_allclose(t, dh_forward(q), atol=1e-9)
    # robot-model.md §7 worked example as an E6POS tuple
    x, y, z, a, b, c, s, t = kin.pos_act((0, -90, 90, 0, 90, 0), tool=(0, 0, 225, 0, 0, 0),
                                         base=(500, 0, 0, 90, 0, 0))
    assert (x, y, z) == pytest.approx((0, 55, 585), abs=1e-9)
    assert rot_angle_deg(abc_matrix(a, b, c), abc_matrix(90, 0, 180)) < 1e-9
    assert (s, t) == (2, 2)


def test_yaml_copy_matches_shared_file():
    """robot/data/kr6_r900.yaml is the shared machine data plus the two [added] keys."""
    shared = Path(__file__).resolve().parents[3] / "shared" / "robots" / "kr6_r900.yaml"
    if not shared.exists():
        pytest.skip("../shared/robots/kr6_r900.yaml is not present")
    ours = yaml.safe_load((Path(__file__).resolve().parents[2] / "robot" / "data" / "kr6_r900.yaml").read_text())
    theirs = yaml.safe_load(shared.read_text())
    assert set(ours) - set(theirs) == {"robroot_mm_deg", "ipo_cycle_s"}
    assert {k: ours[k] for k in theirs} == theirs


from hypothesis import assume, given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_KIN = Kinematics(load_machine())  # hypothesis tests cannot use function-scoped fixtures


@given(st.tuples(*[st.floats(lo, hi, allow_nan=False) for lo, hi in LIMITS]))
def test_ik_round_trip_property(q):
    kin = _KIN
    q = np.array(q)
    # stay away from the switching points (there S is ambiguous by definition)
    assume(abs(q[4]) > 1e-3 and abs(q[2] - 4.763641690726179) > 1e-3 and abs(kin.wrist_point_x(q)) > 1e-3)
    s, t = kin.status_turn(q)
    np.testing.assert_allclose(kin.inverse(kin.forward(q), s, t), q, atol=1e-6)
