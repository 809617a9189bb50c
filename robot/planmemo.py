"""The planner's bounded memos and numerical helpers (issue 76: out of robot/planner.py): the
planning walk's sample parameters, the conversions between frames and matrices and a frame's
inverse kept by their bytes (each table cleared when full), ``norm3`` and ``gradient_rows``
(numpy's norm and gradient, the same numbers without their argument handling)."""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable
from typing import Any

import numpy as np

from .frames import frame_to_matrix, inv_pos, matrix_to_frame
from .motion import CART_KEYS


_BOTTOM_ROW = np.array([0.0, 0.0, 0.0, 1.0])
_SAMPLES: dict[tuple[float, float, int], np.ndarray] = {}


def _samples(a: float, b: float, n: int) -> np.ndarray:
    """``np.linspace(a, b, n)``, kept (read-only) by its arguments: the planning walk samples
    most pieces on the same parameters (a single LIN: 0 to 1)."""
    return _kept(_SAMPLES, (a, b, n), lambda: _readonly(np.linspace(a, b, n)))


def _readonly(A: np.ndarray) -> np.ndarray:
    A.setflags(write=False)
    return A


def norm3(v: np.ndarray) -> float:
    """``float(np.linalg.norm(v))`` of a float64 vector, the same number (numpy's norm is
    ``sqrt(v.dot(v))``: the same dot product, and both square roots correctly rounded) without
    its argument handling (a planned CP motion and a blend's distances take several)."""
    return math.sqrt(v.dot(v))


def gradient_rows(f: np.ndarray, h: float) -> np.ndarray:
    """``np.gradient(f, h, axis=0, edge_order=2)`` of the rows of `f` (at least 3, spacing `h`, a
    Python float), the same operations in the same order as numpy 2's (central differences
    inside, the second-order one-sided ones at the ends): the same numbers, without its
    argument handling (a planned CP motion takes two)."""
    out = np.empty_like(f)
    out[1:-1] = (f[2:] - f[:-2]) / (2. * h)
    out[0] = (-1.5 / h) * f[0] + (2. / h) * f[1] + (-0.5 / h) * f[2]
    out[-1] = (0.5 / h) * f[-3] + (-2. / h) * f[-2] + (1.5 / h) * f[-1]
    return out


#: Conversions kept by :func:`_frame_of` and :func:`_matrix_of` (each table cleared when full).
FRAME_MEMO = 512
_FRAME_OF: dict[bytes, tuple[float, ...]] = {}
_MATRIX_OF: dict[bytes, np.ndarray] = {}


def _kept(table: dict, key: Hashable, make: Callable[[], Any]) -> Any:
    """``table[key]``, made by `make()` the first time (the table is cleared when it holds
    :data:`FRAME_MEMO` entries): the one bounded memo of the planner's conversions."""
    got = table.get(key)
    if got is None:
        if len(table) >= FRAME_MEMO:
            table.clear()
        got = table[key] = make()
    return got


_INVERSE_OF: dict[bytes, tuple[np.ndarray, bool, bool]] = {}
_EYE4 = np.eye(4)
_EYE3 = np.eye(3)
_Z3, _Z33, _Z333 = np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3, 3))   # _cart_path's empty entries


def _inverse_of(T: np.ndarray) -> tuple[np.ndarray, bool, bool]:
    """(:func:`robot.frames.inv_pos` of the 4x4 T, is T the identity, is its inverse), kept by
    T's float64 bytes: the motions of a program share their $TOOL and $BASE. The inverse is the
    kept array (read-only): copy it to keep it."""
    A = np.asarray(T, dtype=float)

    def make() -> tuple[np.ndarray, bool, bool]:
        inv = inv_pos(A)
        inv.setflags(write=False)
        return inv, bool(np.array_equal(A, _EYE4)), bool(np.array_equal(inv, _EYE4))

    return _kept(_INVERSE_OF, A.tobytes() + str(A.shape).encode(), make)


def _frame_of(T: np.ndarray) -> tuple[float, ...]:
    """:func:`robot.frames.matrix_to_frame` of T, kept by T's bytes: a program's cycle plans
    the same points again. The same tuple as the call."""
    A = np.asarray(T, dtype=float)
    return _kept(_FRAME_OF, A.tobytes() + str(A.shape).encode(), lambda: tuple(matrix_to_frame(A)))


def _matrix_of(frame: Any) -> np.ndarray:
    """:func:`robot.frames.frame_to_matrix` of six numbers (X, Y, Z, A, B, C), kept by their
    float64 bytes (so -0.0 is not 0.0): the motions of a program share their $TOOL and $BASE.
    A new array each call, as the function gives. A frame that is the very tuple of the last call
    (a MotionParams' $TOOL or $BASE: interp/runtime/motion.py hands the same snapshot again while
    nothing changed) takes the matrix it got then: the same numbers, without the bytes."""
    last = _LAST_MATRIX.get(id(frame))
    if last is not None and last[0] is frame:
        return last[1].copy()
    try:
        v = np.array(frame, dtype=float)
    except (TypeError, ValueError):
        return frame_to_matrix(*frame)
    if v.shape != (len(CART_KEYS),):
        return frame_to_matrix(*frame)
    kept = _kept(_MATRIX_OF, v.tobytes(), lambda: frame_to_matrix(*frame))
    if type(frame) is tuple and all(type(x) is float for x in frame):     # immutable all through
        if len(_LAST_MATRIX) >= 8:
            _LAST_MATRIX.clear()
        _LAST_MATRIX[id(frame)] = (frame, kept)
    return kept.copy()


#: _matrix_of's last frames by identity (a tuple of floats, kept alive here) and their matrices
_LAST_MATRIX: dict[int, tuple[tuple, np.ndarray]] = {}
