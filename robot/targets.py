"""Motion targets (issue 76: out of robot/planner.py): a motion statement's Cartesian target as
a 4x4 frame in ``$BASE`` (partial aggregates take the start's components; ``_REL`` in
``$BASE`` or ``$TOOL``), its external axes, and the check of the first motion's BCO target."""

from __future__ import annotations

import numpy as np

from .errors import RobotError
from .axismap import AxisMap
from .frames import frame_to_matrix
from .motion import CART_KEYS, MotionRequest
from .planmemo import _frame_of


def _apply_partial(start6: tuple[float, ...], tgt: dict[str, float]) -> list[float]:
    return [float(tgt[k]) if k in tgt else float(start6[i]) for i, k in enumerate(CART_KEYS)]


def _cart_target(req_target: dict[str, float], start_T: np.ndarray, relative: bool,
                 rel_frame: str) -> np.ndarray:
    """Resolve a (partial or relative) Cartesian target to a 4x4 TCP pose in $BASE."""
    if relative:
        off = [float(req_target.get(k, 0.0)) for k in CART_KEYS]
        D = frame_to_matrix(*off)
        if rel_frame == "TOOL":
            return start_T @ D
        out = np.eye(4)
        out[:3, :3] = D[:3, :3] @ start_T[:3, :3]
        out[:3, 3] = start_T[:3, 3] + D[:3, 3]
        return out
    if all(k in req_target for k in CART_KEYS):     # complete: nothing from the start pose
        return frame_to_matrix(*[float(req_target[k]) for k in CART_KEYS])
    start6 = _frame_of(start_T)
    if all(k in req_target for k in ("A", "B", "C")):
        return frame_to_matrix(*_apply_partial(start6, req_target))
    # partial orientation: keep the start rotation exactly when none of A, B, C is given
    if not any(k in req_target for k in ("A", "B", "C")):
        out = start_T.copy()
        for i, k in enumerate(("X", "Y", "Z")):
            if k in req_target:
                out[i, 3] = float(req_target[k])
        return out
    return frame_to_matrix(*_apply_partial(start6, req_target))


def _ext_target(q0: np.ndarray, target: dict[str, float], relative: bool, amap: AxisMap) -> np.ndarray:
    """``q0`` (A1..An, E1..En) with its external axes set from the target's E components
    (relative: added), the rest kept; ``q0`` itself without external axes (`amap`: the model's
    robot/axismap.py map)."""
    n = amap.n_robot
    if len(q0) <= n:
        return q0
    out = q0.copy()
    for i, key in enumerate(amap.ext_keys[:len(q0) - n]):
        if key in target:
            out[n + i] = (q0[n + i] if relative else 0.0) + float(target[key])
    return out


def _check_complete(req: MotionRequest, robot_keys: tuple[str, ...]) -> None:
    t = req.target
    if req.relative or req.kind in ("CIRC", "SCIRC", "SPLINE"):
        raise RobotError("BCO run: the first motion must be a PTP or LIN to a complete target")
    if req.is_axis_target:
        ok = all(k in t for k in robot_keys)
    else:
        ok = all(k in t for k in CART_KEYS)
    if not ok:
        raise RobotError("BCO run: the first motion needs a complete target (no partial aggregate)")
