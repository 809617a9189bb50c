"""The closed forms of robot/frames.py against scipy's rotations, the project's reference
(issue 62: Euler ZYX to a matrix and back, the angle and the rotation vector of a rotation),
on drawn rotations and on the special ones: gimbal lock (B = +-90), 180 deg about each axis
and about a drawn axis, the identity, angles within 1e-9 of 0 and of 180 deg."""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from robot.frames import GIMBAL_TOL_DEG, frame_to_matrix, matrix_to_frame, rotation_angle_deg, rotvec_of

RNG = np.random.default_rng(62)


def _wrap(d: float) -> float:
    return (d + 180.0) % 360.0 - 180.0


def _drawn(n: int) -> list[np.ndarray]:
    return [Rotation.from_quat(q).as_matrix() for q in RNG.normal(size=(n, 4))]


def _special() -> list[np.ndarray]:
    out = [np.eye(3)]
    axes = [np.eye(3)[i] for i in range(3)] + [v / np.linalg.norm(v) for v in RNG.normal(size=(4, 3))]
    for ax in axes:
        for th in (math.pi, math.pi - 1e-9, math.pi - 1e-4, 1e-9, 1e-13, 2.0):
            out.append(Rotation.from_rotvec(ax * th).as_matrix())
    for b in (90.0, -90.0):
        for a, c in ((30.0, 0.0), (0.0, 45.0), (-170.0, 120.0)):
            out.append(Rotation.from_euler("ZYX", [a, b, c], degrees=True).as_matrix())
    return out


def test_frame_to_matrix_is_scipys_euler_zyx():
    cases = [tuple(RNG.uniform(-180.0, 180.0, 3) * (1.0, 0.5, 1.0)) for _ in range(2000)] \
        + [(0.0, 90.0, 0.0), (10.0, -90.0, 20.0), (180.0, 0.0, -180.0), (-90.0, 45.0, 90.0)]
    for a, b, c in cases:
        M = frame_to_matrix(1.0, -2.0, 3.0, a, b, c)
        assert np.abs(M[:3, :3] - Rotation.from_euler("ZYX", [a, b, c], degrees=True).as_matrix()).max() < 1e-14
        assert M[:3, 3].tolist() == [1.0, -2.0, 3.0] and M[3].tolist() == [0.0, 0.0, 0.0, 1.0]


def test_matrix_to_frame_is_scipys_euler_zyx_away_from_gimbal_lock():
    worst = 0.0
    for R in _drawn(2000):
        _x, _y, _z, a, b, c = matrix_to_frame(R)
        e = Rotation.from_matrix(R).as_euler("ZYX", degrees=True)
        worst = max(worst, abs(_wrap(a - e[0])), abs(b - e[1]), abs(_wrap(c - e[2])))
    assert worst < 1e-9


def test_matrix_to_frame_at_gimbal_lock_puts_the_rotation_into_a():
    """B = +-90: only A - C (A + C) is defined; the module's rule C = 0 (docstring), and the
    frame made of the result is the rotation given."""
    for R in _special():
        x, y, z, a, b, c = matrix_to_frame(R)
        if abs(abs(b) - 90.0) < GIMBAL_TOL_DEG:
            assert c == 0.0
        assert np.abs(frame_to_matrix(x, y, z, a, b, c)[:3, :3] - R).max() < 1e-9
        assert -180.0 < a <= 180.0 and -180.0 < c <= 180.0 and -90.0 <= b <= 90.0


def test_the_angle_and_the_rotation_vector_are_scipys():
    for R in _drawn(2000) + _special():
        ref = Rotation.from_matrix(R)
        assert abs(rotation_angle_deg(np.eye(3), R) - math.degrees(ref.magnitude())) < 1e-9
        rv, want = rotvec_of(R), ref.as_rotvec()
        if abs(np.linalg.norm(want) - math.pi) < 1e-6:
            # 180 deg: +n and -n are the same rotation; scipy picks one
            assert min(np.abs(rv - want).max(), np.abs(rv + want).max()) < 1e-6
            assert np.abs(Rotation.from_rotvec(rv).as_matrix() - R).max() < 1e-6
        else:
            assert np.abs(rv - want).max() < 1e-9
