"""KRL frames as 4x4 homogeneous transforms (reference §4.3-§4.4, robot-model.md §6-§7).

Units: X, Y, Z in mm; A, B, C in degrees. KUKA's orientation convention is
``R = Rz(A) · Ry(B) · Rx(C)`` (intrinsic Z, Y', X''), i.e. scipy's Euler sequence
``'ZYX'`` (upper case = intrinsic). All rotation maths goes through
``scipy.spatial.transform.Rotation``.

Gimbal lock (B = ±90°, reference §4.4, robot-model.md §6/§13.2): only A - C
(B = +90°) or A + C (B = -90°) is defined. This module puts the whole rotation
into **A and sets C = 0** (scipy's choice for the third angle). KUKA's own
split is not documented; compare orientations as matrices, never as raw ABC.

Normalised ranges returned by :func:`matrix_to_frame`: A, C in (-180, 180],
B in [-90, 90].
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

#: 4x4 identity, i.e. ``$NULLFRAME``.
I4: np.ndarray = np.eye(4)
I4.setflags(write=False)
NULLFRAME: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

#: |B| within this many degrees of 90 is treated as gimbal lock.
GIMBAL_TOL_DEG = 1e-6

_EULER = "ZYX"  # intrinsic Z, Y', X'': R = Rz(A) Ry(B) Rx(C)


def frame_to_matrix(x: Any = 0.0, y: float = 0.0, z: float = 0.0,
                    a: float = 0.0, b: float = 0.0, c: float = 0.0) -> np.ndarray:
    """KRL FRAME {X, Y, Z, A, B, C} (mm, deg) -> 4x4 homogeneous transform.

    ``T = Trans(X, Y, Z) · Rz(A) · Ry(B) · Rx(C)`` (reference §4.4, robot-model.md §6).
    ``x`` may instead be a 6-sequence (X, Y, Z, A, B, C) or a mapping with
    keys X..C (case-insensitive, missing = 0); then the other arguments are ignored.
    """
    if isinstance(x, Mapping) or (not np.isscalar(x) and np.ndim(x) == 1):
        x, y, z, a, b, c = _six(x)
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler(_EULER, [a, b, c], degrees=True).as_matrix()
    T[:3, 3] = (x, y, z)
    return T


def _six(f: Any) -> tuple[float, ...]:
    if isinstance(f, Mapping):
        low = {str(k).lower(): v for k, v in f.items()}
        return tuple(float(low.get(k, 0.0)) for k in "xyzabc")
    vals = [float(v) for v in f]
    if len(vals) != 6:
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
        R, p = T, np.zeros(3)
    else:
        R, p = T[:3, :3], T[:3, 3]
    rot = Rotation.from_matrix(R)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # scipy's gimbal-lock warning
        a, b, c = rot.as_euler(_EULER, degrees=True)
    if abs(abs(b) - 90.0) < GIMBAL_TOL_DEG:
        # Only A - C (B = +90) or A + C (B = -90) is defined: put it all into A.
        b = 90.0 if b > 0 else -90.0
        Rm = rot.as_matrix()
        # With C = 0: R = Rz(A) Ry(±90), so column y of R is (-sin A, cos A, 0).
        a = float(np.degrees(np.arctan2(-Rm[0, 1], Rm[1, 1])))
        c = 0.0
    return (float(p[0]), float(p[1]), float(p[2]), _wrap180(a), float(b), _wrap180(c))


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
    if arr.shape == (6,):
        return frame_to_matrix(arr)
    raise ValueError(f"not a frame: shape {arr.shape}")


def rotation_angle_deg(R1: np.ndarray, R2: np.ndarray) -> float:
    """Angle (deg) of the relative rotation between two orientations (3x3 or 4x4)."""
    R1 = np.asarray(R1, dtype=float)[:3, :3]
    R2 = np.asarray(R2, dtype=float)[:3, :3]
    return float(np.degrees(Rotation.from_matrix(R1.T @ R2).magnitude()))
