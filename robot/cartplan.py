"""The Cartesian planner (LIN, CIRC, SLIN, SCIRC, SPLINE; issue 76: cut out of robot/planner.py's
``_plan_cart``), in the order it plans: the motion's targets as frames in ``$BASE``
(robot/targets.py), the path through them (robot/pathpieces.py: lines, arcs with ``CA``,
Catmull-Rom curves for SPL points whose end tangents follow a neighbouring SLIN/SCIRC), the
orientation of each piece (``$ORI_TYPE``, ``$CIRC_TYPE``), the path parameter u, then the time
law (robot/cartlaw.py) and, in robot/planner.py ``plan``, the triggers (robot/pathtriggers.py).
Reference §6.5-§6.7 (CP motions keep the start status S; the orientation follows
``$ORI_TYPE``/``$CIRC_TYPE``)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .cartlaw import cart_time_law, cp_speeds
from .errors import RobotError
from .frames import inv_pos, rotation_angle_deg
from .motion import AXIS_KEYS, MotionParams, MotionRequest
from .pathpieces import ArcPiece, CatmullRomPiece, LinePiece, _Piece, rotvec_matrix
from .profiles import Trapezoid
from .robotmodel import RobotModel
from .segments import CartSegment
from .targets import _cart_target, _ext_target

#: a CP motion's kind as a SPLINE block's segment kind
_BLOCK_KIND = {"LIN": "SLIN", "SLIN": "SLIN", "CIRC": "SCIRC", "SCIRC": "SCIRC"}


def _orientation_modes(p: MotionParams, kind: str) -> str:
    if p.ori_type == "CONSTANT":
        return "CONSTANT"
    if kind in ("CIRC", "SCIRC") and p.circ_type == "PATH":
        return "PATH"
    return "VAR"  # #JOINT: pose_u interpolates like #VAR; axes() moves the wrist axes linearly


def _cart_items(req: MotionRequest) -> list[tuple]:
    """The (kind, target, aux, ca, params, block segment) items of the motion: a SPLINE block's
    segments, or the one motion as its block kind. Raises RobotError for an empty block."""
    p = req.params
    if req.kind == "SPLINE":
        if not req.segments:
            raise RobotError("SPLINE block without segments")
        return [(s.kind.upper(), s.target, s.aux, s.ca, s.params or p, s) for s in req.segments]
    return [(_BLOCK_KIND[req.kind], req.target, req.aux, req.ca, p, None)]


def _cart_targets(req: MotionRequest, items: list[tuple], start_T: np.ndarray, tool_T: np.ndarray,
                  base_T: np.ndarray, model: RobotModel) -> tuple[list[np.ndarray], list[tuple[str, Any]]]:
    """The frames (4x4 in $BASE) from the start through each item's target, and each item's path
    kind ("ARC" with its auxiliary point and CA, "SLIN", "SPL"). Raises RobotError."""
    cur_T = start_T
    pts_T: list[np.ndarray] = [start_T]
    geo: list[tuple[str, Any]] = []
    for kind, tgt, aux, ca, _prm, _ in items:
        if any(k in tgt for k in AXIS_KEYS):
            # an axis target for a CP motion: its TCP pose
            qa = np.array([float(tgt[k]) if k in tgt else 0.0 for k in model.axes.robot_keys])
            if req.relative:
                raise RobotError("CP _REL motion with an axis target")
            T1 = model.tcp(qa, tool_T, inv_pos(base_T))
        else:
            T1 = _cart_target(tgt, cur_T, req.relative, req.rel_frame)
        if kind == "SCIRC":
            if aux is None:
                raise RobotError("CIRC without auxiliary point")
            Ta = _cart_target(aux, cur_T, req.relative, req.rel_frame)
            geo.append(("ARC", (Ta[:3, 3].copy(), ca)))
        elif kind in ("SLIN", "SPL"):
            geo.append((kind, None))
        else:
            raise RobotError(f"{kind} is not allowed in a SPLINE block")
        pts_T.append(T1)
        cur_T = T1
    return pts_T, geo


def _path_pieces(geo: list[tuple[str, Any]], pts_T: list[np.ndarray]) -> list[_Piece]:
    """The path's pieces through the frames' positions: lines and arcs first (CA moves an end
    point: its frame in `pts_T` is replaced), then the SPL curves, whose end tangents follow a
    neighbouring SLIN/SCIRC (no kink at such a junction)."""
    pts = [T[:3, 3].copy() for T in pts_T]
    n = len(geo)
    built: list[_Piece | None] = [None] * n
    for k, (g, data) in enumerate(geo):
        a, b = pts[k], pts[k + 1]
        if g == "ARC":
            arc = ArcPiece(a, data[0], b, data[1])
            if data[1] is not None:  # CA moves the end point onto the circle
                b = arc.pos(arc.length)
                pts[k + 1] = b
                pts_T[k + 1] = pts_T[k + 1].copy()
                pts_T[k + 1][:3, 3] = b
            built[k] = arc
        elif g == "SLIN":
            built[k] = LinePiece(a, b)
    for k, (g, _) in enumerate(geo):
        if g == "SPL":
            built[k] = _spline_piece(k, geo, pts, built)
    return [pc for pc in built if pc is not None]


def _spline_piece(k: int, geo: list[tuple[str, Any]], pts: list[np.ndarray],
                  built: list[_Piece | None]) -> CatmullRomPiece:
    """The Catmull-Rom curve of SPL segment k between pts[k] and pts[k + 1]."""
    n = len(geo)
    a, b = pts[k], pts[k + 1]
    chord = float(np.linalg.norm(b - a))
    P0 = pts[k - 1] if k >= 1 else 2 * a - b
    P3 = pts[k + 2] if k + 2 < len(pts) else 2 * b - a
    m1 = m2 = None
    prev_p = built[k - 1] if k >= 1 and geo[k - 1][0] != "SPL" else None
    next_p = built[k + 1] if k + 1 < n and geo[k + 1][0] != "SPL" else None
    if prev_p is not None and prev_p.length > 0:
        m1 = prev_p.tangent(prev_p.length) * chord
    if next_p is not None and next_p.length > 0:
        m2 = next_p.tangent(0.0) * chord
    return CatmullRomPiece(P0, a, b, P3, m1, m2)


def _orientations(geo: list[tuple[str, Any]], items: list[tuple], pieces: list[_Piece], start_T: np.ndarray,
                  pts_T: list[np.ndarray], mode: str) -> tuple[list, list[str], list[float], list[tuple]]:
    """(rotations at the pieces' ends (n + 1), orientation mode per piece, its turn (deg), its
    speeds (:func:`robot.cartlaw.cp_speeds`)). Raises RobotError (speeds not positive)."""
    rots: list[np.ndarray] = [start_T[:3, :3].copy()]
    ori: list[str] = []
    thetas: list[float] = []
    speeds: list[tuple[float, float, float, float]] = []
    for k, (g, _data) in enumerate(geo):
        prm = items[k][4]
        piece = pieces[k]
        o_mode = _orientation_modes(prm, "SCIRC" if g == "ARC" else "SLIN")
        if o_mode == "CONSTANT":
            R1 = rots[k]
        elif o_mode == "PATH":
            assert isinstance(piece, ArcPiece)
            R1 = rotvec_matrix(piece.n * piece.angle) @ rots[k]
        else:
            R1 = pts_T[k + 1][:3, :3].copy()
        rots.append(R1)
        ori.append(o_mode)
        thetas.append(rotation_angle_deg(rots[k], R1))
        speeds.append(cp_speeds(prm, mode))
    return rots, ori, thetas, speeds


def _cart_segment(req: MotionRequest, q0: np.ndarray, tool_T: np.ndarray, base_T: np.ndarray,
                  model: RobotModel, pieces: list[_Piece], rots: list, weights: list[float],
                  ori: list[str]) -> CartSegment:
    """The segment of the path, its time law still open (an infinite trapezoid), the external
    axes' end from the last target. Raises SoftLimitError (the external axes' end)."""
    n = model.n
    q_end = _ext_target(q0, req.target if req.kind != "SPLINE" else
                        (req.segments[-1].target if req.segments else {}), req.relative, model.axes)
    if len(q0) > n:
        model.check_limits(np.concatenate([q0[:n], q_end[n:]]))
    seg = CartSegment(req, q0, q_end, Trapezoid.plan(math.inf, math.inf), math.inf,
                      tool_T, base_T, model, pieces, rots, weights, ori)
    seg.vel_peak = np.zeros(len(q0))
    seg.acc_peak = np.zeros(len(q0))
    return seg


def plan_cart(req: MotionRequest, q0: np.ndarray, start_T: np.ndarray, tool_T: np.ndarray,
              base_T: np.ndarray, model: RobotModel) -> CartSegment:
    """The :class:`~robot.segments.CartSegment` of a CP motion or SPLINE block from the axes q0
    (its TCP `start_T` in $BASE; $TOOL `tool_T`, $BASE `base_T`): targets, path, orientation,
    path parameter, time law. Raises RobotError (and its WorkspaceError, SoftLimitError)."""
    items = _cart_items(req)
    pts_T, geo = _cart_targets(req, items, start_T, tool_T, base_T, model)
    pieces = _path_pieces(geo, pts_T)
    rots, ori, thetas, speeds = _orientations(geo, items, pieces, start_T, pts_T, model.mode)
    # parameter u: proportional to max(L_k, θ_k·c) with one scale c (mm/deg) for the block,
    # so the path speed is continuous where pieces meet (= the old time weights when all
    # pieces share $VEL/$ACC)
    v_cp0, v_ori0, _, _ = cp_speeds(req.params, model.mode)
    c = v_cp0 / v_ori0
    weights = [max(pc.length, th * c) for pc, th in zip(pieces, thetas)]
    W = float(sum(weights))
    n = model.n
    seg = _cart_segment(req, q0, tool_T, base_T, model, pieces, rots, weights, ori)
    if len(q0) > n and W <= 1e-6 and float(np.max(np.abs(seg.q1[n:] - q0[n:]))) > 1e-9:
        raise RobotError(f"{req.kind}: a CP motion that moves only the external axes is not simulated "
                         f"(the TCP stands still); move them with PTP")
    if W <= 1e-6:  # nothing to move (a zero-length LIN): zero duration, never approximated
        seg.q1 = q0.copy()
        return seg
    cart_time_law(seg, thetas, weights, speeds, pts_T[-1])
    return seg


__all__ = ["plan_cart"]
