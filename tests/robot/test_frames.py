"""KRL frames: ABC convention, geometric operator ':' and INV_POS.

Expected values come from robot-model.md §6 (worked ABC matrices) and from the
closed-form matrix R = Rz(A)·Ry(B)·Rx(C) written out below (robot-model.md §6,
reference §4.4), not from the code under test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.frames import as_matrix, compose, frame_to_matrix, inv_pos, matrix_to_frame


def abc_matrix(a: float, b: float, c: float) -> np.ndarray:
    """The explicit KUKA matrix of robot-model.md §6 (c = cos, s = sin)."""
    cA, sA = math.cos(math.radians(a)), math.sin(math.radians(a))
    cB, sB = math.cos(math.radians(b)), math.sin(math.radians(b))
    cC, sC = math.cos(math.radians(c)), math.sin(math.radians(c))
    return np.array([
        [cA * cB, cA * sB * sC - sA * cC, cA * sB * cC + sA * sC],
        [sA * cB, sA * sB * sC + cA * cC, sA * sB * cC - cA * sC],
        [-sB, cB * sC, cB * cC],
    ])


# robot-model.md §6 worked examples (rows), 4 decimals in the source.
WORKED = [
    ((90, 0, 0), [[0, -1, 0], [1, 0, 0], [0, 0, 1]]),
    ((0, 90, 0), [[0, 0, 1], [0, 1, 0], [-1, 0, 0]]),
    ((0, 0, 90), [[1, 0, 0], [0, 0, -1], [0, 1, 0]]),
    ((30, 45, 60), [[0.6124, 0.2803, 0.7392], [0.3536, 0.7392, -0.5732], [-0.7071, 0.6124, 0.3536]]),
    ((180, 0, 180), [[-1, 0, 0], [0, 1, 0], [0, 0, -1]]),
]


@pytest.mark.parametrize("abc,rows", WORKED)
def test_worked_abc_examples(abc, rows):
    T = frame_to_matrix(0, 0, 0, *abc)
    assert T.shape == (4, 4)
    np.testing.assert_allclose(T[:3, :3], np.array(rows, dtype=float), atol=1e-4)
    np.testing.assert_allclose(T[3], [0, 0, 0, 1])


def test_frame_matches_closed_form_and_translation():
    rng = np.random.default_rng(11)
    for _ in range(200):
        x, y, z = rng.uniform(-2000, 2000, 3)
        a, c = rng.uniform(-180, 180, 2)
        b = rng.uniform(-90, 90)
        T = frame_to_matrix(x, y, z, a, b, c)
        np.testing.assert_allclose(T[:3, :3], abc_matrix(a, b, c), atol=1e-12)
        np.testing.assert_allclose(T[:3, 3], [x, y, z], atol=1e-12)


def test_frame_accepts_sequence_and_mapping():
    ref = frame_to_matrix(1, 2, 3, 10, 20, 30)
    np.testing.assert_allclose(frame_to_matrix([1, 2, 3, 10, 20, 30]), ref)
    np.testing.assert_allclose(frame_to_matrix({"X": 1, "Y": 2, "Z": 3, "A": 10, "B": 20, "C": 30}), ref)
    np.testing.assert_allclose(as_matrix({"z": 5}), frame_to_matrix(0, 0, 5, 0, 0, 0))
    np.testing.assert_allclose(as_matrix(None), np.eye(4))


def test_matrix_to_frame_round_trip_principal_branch():
    rng = np.random.default_rng(12)
    for _ in range(300):
        f = (*rng.uniform(-1000, 1000, 3), rng.uniform(-179.9, 179.9), rng.uniform(-89.9, 89.9),
             rng.uniform(-179.9, 179.9))
        g = matrix_to_frame(frame_to_matrix(*f))
        np.testing.assert_allclose(g, f, atol=1e-9)
        assert -90.0 <= g[4] <= 90.0


def test_matrix_to_frame_ranges_and_180():
    # A, C in (-180, 180]: a half turn is reported as +180, never -180
    x, y, z, a, b, c = matrix_to_frame(abc_matrix(180, 0, 180))
    assert (a, b, c) == pytest.approx((180.0, 0.0, 180.0), abs=1e-9)
    assert a > 0 and c > 0
    # B outside [-90, 90] is folded into the principal branch; same matrix
    R = abc_matrix(10, 120, 20)
    f = matrix_to_frame(R)
    assert -90 <= f[4] <= 90
    np.testing.assert_allclose(abc_matrix(*f[3:]), R, atol=1e-12)


@pytest.mark.parametrize("b", [90.0, -90.0])
def test_gimbal_lock_split_c_zero(b):
    # Only A - C (B = +90) or A + C (B = -90) is defined: the module puts all into A, C = 0.
    for a, c in [(0, 0), (30, 0), (10, 40), (-170, 25), (179, -179)]:
        R = abc_matrix(a, b, c)
        xa, xb, xc = matrix_to_frame(R)[3:]
        assert xb == b
        assert xc == 0.0
        np.testing.assert_allclose(abc_matrix(xa, xb, xc), R, atol=1e-12)
        expected_a = a - c if b > 0 else a + c
        assert math.isclose(math.remainder(xa - expected_a, 360.0), 0.0, abs_tol=1e-9)


def test_home_flange_orientation_is_0_90_0():
    # robot-model.md §9: HOME flange orientation Ry(90) -> A 0, B 90, C 0 (gimbal lock)
    R = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], dtype=float)
    assert matrix_to_frame(R)[3:] == pytest.approx((0.0, 90.0, 0.0), abs=1e-12)


def test_inv_pos_identity_both_sides():
    rng = np.random.default_rng(13)
    for _ in range(100):
        F = frame_to_matrix(*rng.uniform(-1000, 1000, 3), *rng.uniform(-180, 180, 3))
        np.testing.assert_allclose(compose(inv_pos(F), F), np.eye(4), atol=1e-9)
        np.testing.assert_allclose(compose(F, inv_pos(F)), np.eye(4), atol=1e-9)
        assert matrix_to_frame(compose(inv_pos(F), F)) == pytest.approx((0, 0, 0, 0, 0, 0), abs=1e-9)


def test_inv_pos_hand_example():
    # F = {X 100, A 90}: the inverse maps the point back: {X 0, Y 100, A -90}
    F = frame_to_matrix(100, 0, 0, 90, 0, 0)
    assert matrix_to_frame(inv_pos(F)) == pytest.approx((0, 100, 0, -90, 0, 0), abs=1e-9)


def test_geometric_operator_associative_not_commutative():
    F1 = frame_to_matrix(100, 0, 0, 90, 0, 0)
    F2 = frame_to_matrix(0, 50, 0, 0, 30, 0)
    F3 = frame_to_matrix(10, 20, 30, 5, -10, 15)
    np.testing.assert_allclose(compose(compose(F1, F2), F3), compose(F1, compose(F2, F3)), atol=1e-9)
    np.testing.assert_allclose(compose(F1, F2, F3), compose(compose(F1, F2), F3), atol=1e-9)
    assert not np.allclose(compose(F1, F2), compose(F2, F1))


def test_geometric_operator_hand_example():
    # reference §4.3: position pA + RA·pB, orientation RA·RB.
    # {X 100, A 90} : {X 0, Y 50} -> the point Y 50 of the rotated frame is X 100 - 50 = 50
    F1 = frame_to_matrix(100, 0, 0, 90, 0, 0)
    F2 = frame_to_matrix(0, 50, 0, 0, 0, 0)
    assert matrix_to_frame(compose(F1, F2)) == pytest.approx((50, 0, 0, 90, 0, 0), abs=1e-9)
    # the other way round: {X 0, Y 50} : {X 100, A 90} -> X 100, Y 50, A 90
    assert matrix_to_frame(compose(F2, F1)) == pytest.approx((100, 50, 0, 90, 0, 0), abs=1e-9)
