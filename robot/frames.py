"""KRL frames as 4x4 homogeneous transforms (reference §4.3-§4.4, robot-model.md §6-§7).

Units: X, Y, Z in mm; A, B, C in degrees. KUKA's orientation convention is
``R = Rz(A) · Ry(B) · Rx(C)`` (intrinsic Z, Y', X''), i.e. scipy's Euler sequence
``'ZYX'`` (upper case = intrinsic).

**Rotation maths: scipy, and four closed forms.** ``scipy.spatial.transform.Rotation`` is the
reference of every rotation conversion of the project. Four conversions the planner and the
KRL geometric operator make at every motion are written here in closed form instead:
:func:`frame_to_matrix` (the product Rz · Ry · Rx), :func:`matrix_to_frame` (B from atan2 of
-R[2,0] and the first column's length, A and C from atan2), :func:`rotation_angle_deg` and
:func:`rotvec_of` (the angle from atan2 of the skew part's length and (trace - 1) / 2, accurate
at every angle; the axis of a rotation near 180 deg from the symmetric part). Why: scipy 1.17
orthogonalises every matrix it is given (``from_matrix``: an SVD) and wraps each call in its
array-API dispatch, 0.15-0.4 ms a conversion; a CAM program that moves every 20 ms spent a
third of its planning there (issue 62). They agree with scipy to 1e-12 deg (a rotation and an
angle) on every rotation tests/robot/test_frames_closed_form.py draws, gimbal lock and 180 deg
included, and they leave the traces of every corpus and history entry point identical to the
byte (``tools/trace_identity.py``, written to 6 decimals: 2026-11-26). Everything else (the
trace's batches of poses, URDF origins, machine data) stays scipy's.

Gimbal lock (B = ±90°, reference §4.4, robot-model.md §6/§13.2): only A - C
(B = +90°) or A + C (B = -90°) is defined. This module puts the whole rotation
into **A and sets C = 0** (scipy's choice for the third angle). KUKA's own
split is not documented; compare orientations as matrices, never as raw ABC.

Normalised ranges returned by :func:`matrix_to_frame`: A, C in (-180, 180],
B in [-90, 90].
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from .axismap import CART_KEYS as CART

#: 4x4 identity, i.e. ``$NULLFRAME``.
I4: np.ndarray = np.eye(4)
I4.setflags(write=False)
NULLFRAME: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

#: |B| within this many degrees of 90 is treated as gimbal lock.
GIMBAL_TOL_DEG = 1e-6

def frame_to_matrix(x: Any = 0.0, y: float = 0.0, z: float = 0.0,
                    a: float = 0.0, b: float = 0.0, c: float = 0.0) -> np.ndarray:
    """KRL FRAME {X, Y, Z, A, B, C} (mm, deg) -> 4x4 homogeneous transform.

    ``T = Trans(X, Y, Z) · Rz(A) · Ry(B) · Rx(C)`` (reference §4.4, robot-model.md §6).
    ``x`` may instead be a 6-sequence (X, Y, Z, A, B, C) or a mapping with
    keys X..C (case-insensitive, missing = 0); then the other arguments are ignored.
    """
    if isinstance(x, Mapping) or (not np.isscalar(x) and np.ndim(x) == 1):
        x, y, z, a, b, c = _six(x)
    ra, rb, rc = math.radians(float(a)), math.radians(float(b)), math.radians(float(c))
    ca, sa, cb, sb, cc, sc = math.cos(ra), math.sin(ra), math.cos(rb), math.sin(rb), math.cos(rc), math.sin(rc)
    return np.array([[ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc, float(x)],
                     [sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc, float(y)],
                     [-sb, cb * sc, cb * cc, float(z)],
                     [0.0, 0.0, 0.0, 1.0]])


def _six(f: Any) -> tuple[float, ...]:
    if isinstance(f, Mapping):
        low = {str(k).lower(): v for k, v in f.items()}
        return tuple(float(low.get(k, 0.0)) for k in "xyzabc")
    vals = [float(v) for v in f]
    if len(vals) != len(CART):
        raise ValueError(f"a frame needs 6 components (X, Y, Z, A, B, C), got {len(vals)}")
    return tuple(vals)


def _wrap180(v: float) -> float:
    """Wrap an angle to (-180, 180]; tiny values become +0.0."""
    w = -((-v + 180.0) % 360.0) + 180.0  # (-180, 180]
    if abs(w) < 1e-12:
        w = 0.0
    return float(w)


def matrix_to_frame(T: np.ndarray) -> tuple[float, float, float, float, float, float]:
    """4x4 transform (or 3x3 rotation) -> (X, Y, Z, A, B, C) in mm and degrees.

    Principal branch B in [-90, 90]; A, C in (-180, 180]. At gimbal lock
    (|B| within :data:`GIMBAL_TOL_DEG` of 90) C is set to 0 and A carries the
    rotation about the common axis (reference §4.4; KUKA's own split is
    [uncertain], robot-model.md §13.2).
    """
    T = np.asarray(T, dtype=float)
    if T.shape == (3, 3):
        (r00, r01, _r02), (r10, r11, _r12), (r20, r21, r22) = T.tolist()
        x = y = z = 0.0
    else:
        (r00, r01, _r02, x), (r10, r11, _r12, y), (r20, r21, r22, z) = T[:3].tolist()
    b = math.degrees(math.atan2(-r20, math.hypot(r00, r10)))
    if abs(abs(b) - 90.0) < GIMBAL_TOL_DEG:
        # Only A - C (B = +90) or A + C (B = -90) is defined: put it all into A.
        b = 90.0 if b > 0 else -90.0
        # With C = 0: R = Rz(A) Ry(±90), so column y of R is (-sin A, cos A, 0).
        a = math.degrees(math.atan2(-r01, r11))
        c = 0.0
    else:
        a = math.degrees(math.atan2(r10, r00))
        c = math.degrees(math.atan2(r21, r22))
    return (float(x), float(y), float(z), _wrap180(a), float(b), _wrap180(c))


def compose(T1: np.ndarray, T2: np.ndarray, *more: np.ndarray) -> np.ndarray:
    """KRL geometric operator ``T1 : T2 [: T3 ...]`` = ``T1 @ T2 @ ...`` (reference §4.3).

    T2 is given relative to T1; the result is T2 expressed in T1's reference
    frame. Associative, not commutative. Arguments are 4x4 arrays.
    """
    out = np.asarray(T1, dtype=float) @ np.asarray(T2, dtype=float)
    for T in more:
        out = out @ np.asarray(T, dtype=float)
    return out


def inv_pos(T: np.ndarray) -> np.ndarray:
    """KRL ``INV_POS(F)``: inverse of a rigid transform, so ``inv_pos(F) : F = $NULLFRAME``
    (reference §4.3, §4.5). Input and output 4x4, mm."""
    T = np.asarray(T, dtype=float)
    R = T[:3, :3]
    out = np.eye(4)
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ T[:3, 3]
    return out


def as_matrix(F: Any) -> np.ndarray:
    """Coerce a frame to a 4x4 array: None -> identity ($NULLFRAME), a 4x4 array
    as is, a 6-sequence or X..C mapping via :func:`frame_to_matrix`."""
    if F is None:
        return np.eye(4)
    if isinstance(F, Mapping):
        return frame_to_matrix(F)
    arr = np.asarray(F, dtype=float)
    if arr.shape == (4, 4):
        return arr
    if arr.shape == (len(CART),):
        return frame_to_matrix(arr)
    raise ValueError(f"not a frame: shape {arr.shape}")


def rotation_angle_deg(R1: np.ndarray, R2: np.ndarray) -> float:
    """Angle (deg, 0..180) of the relative rotation between two orientations (3x3 or 4x4)."""
    R1 = np.asarray(R1, dtype=float)[:3, :3]
    R2 = np.asarray(R2, dtype=float)[:3, :3]
    return math.degrees(_angle(R1.T @ R2)[0])


def _angle(R: np.ndarray) -> tuple[float, tuple[float, float, float], float]:
    """(angle in rad, the skew part (R21 - R12, R02 - R20, R10 - R01), its length) of a rotation:
    the angle from atan2(|skew| / 2, (trace - 1) / 2), accurate at every angle."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R.tolist()
    w = (r21 - r12, r02 - r20, r10 - r01)
    s = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    return math.atan2(0.5 * s, 0.5 * (r00 + r11 + r22 - 1.0)), w, s


def rotvec_of(R: np.ndarray) -> np.ndarray:
    """The rotation vector (rad, (3,)) of a 3x3 rotation: the log map (scipy's
    ``Rotation.from_matrix(R).as_rotvec()``). Near 180 deg, where the skew part vanishes, the
    axis comes from the symmetric part (R + R^T)/2 = cos θ I + (1 - cos θ) n n^T, its sign from
    the skew part."""
    R = np.asarray(R, dtype=float)
    th, w, s = _angle(R)
    if th < 1e-6:
        k = 0.5 * (1.0 + th * th / 6.0)      # θ / (2 sin θ), its series near 0
        return np.array([w[0] * k, w[1] * k, w[2] * k])
    if th < math.pi - 1e-3:
        k = th / s
        return np.array([w[0] * k, w[1] * k, w[2] * k])
    c = math.cos(th)
    d = [math.sqrt(max(0.0, (float(R[i, i]) - c) / (1.0 - c))) for i in range(3)]
    i = max(range(3), key=lambda j: d[j])
    n = [0.0, 0.0, 0.0]
    n[i] = d[i]
    for j in range(3):
        if j != i:
            n[j] = (float(R[i, j]) + float(R[j, i])) / (2.0 * (1.0 - c) * d[i])
    sign = 1.0 if sum(n[j] * w[j] for j in range(3)) >= 0.0 else -1.0
    norm = math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
    return np.array([sign * th * n[0] / norm, sign * th * n[1] / norm, sign * th * n[2] / norm])
