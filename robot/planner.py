"""Motion planning: a :class:`~robot.motion.MotionRequest` becomes a :class:`Segment` that
the main run samples every IPO cycle (reference §6.3-§6.7, robot-model.md §7-§8).

A segment is a geometric path plus one normalised trapezoidal time law
(:mod:`robot.profiles`):

* :class:`JointSegment` (PTP, SPTP): ``q(u) = q0 + u·(q1 - q0)``, synchronised axes.
* :class:`CartSegment` (LIN, CIRC, SLIN, SCIRC, SPLINE): the TCP moves in ``$BASE`` along
  a chain of path pieces (line, circular arc, Catmull-Rom curve for SPL points); the
  orientation follows ``$ORI_TYPE``/``$CIRC_TYPE``; axis values come from the inverse
  kinematics each cycle, keeping the start status S and the turn nearest to the last
  setpoint (reference §6.5: CP motions ignore the target's S and T).

Planning happens in the advance run (:func:`plan`), so an unreachable target or a soft-limit
violation of a target raises :class:`~robot.errors.RobotError` at the motion statement.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from .errors import RobotError, WorkspaceError
from .frames import frame_to_matrix, inv_pos, matrix_to_frame
from .kinematics import Kinematics
from .motion import AXIS_KEYS, CART_KEYS, MotionParams, MotionRequest, Trigger
from .profiles import Trapezoid


#: An axis jump (deg) between neighbouring planning samples of a CP path that means the
#: path crosses a singularity (the IK had to flip the wrist to keep the status).
SINGULAR_JUMP_DEG = 90.0
#: Factor on the axis maximum speed above which an interpolated CP setpoint is rejected.
CP_SPEED_LIMIT_FACTOR = 1.5


class RobotModel:
    """Adapter between the planner and the kinematics module (mm, deg, 4x4 frames).

    ``tcp(q, tool_T, base_T)`` -> TCP 4x4 in ``$BASE``; ``ik(T, tool_T, base_T, status, turn,
    ref)`` -> axes (6,) raising WorkspaceError/SoftLimitError; ``status_turn(q)``.
    """

    def __init__(self, machine: Any, kin: Kinematics | None = None) -> None:
        self.machine = machine
        self.kin = kin if kin is not None else Kinematics(machine)
        self.robroot_T = frame_to_matrix(*machine.robroot_frame)
        self._robroot_is_null = bool(np.allclose(self.robroot_T, np.eye(4)))
        self.v_max = np.array(machine.max_speed_deg_s, dtype=float)
        self.a_max = np.array(machine.max_acc_deg_s2, dtype=float)
        self.apo_dis_ptp = np.array(machine.apo_dis_ptp_deg, dtype=float)

    def tcp(self, q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """TCP in $BASE: INV_POS($BASE) : $ROBROOT : FLANGE(q) : $TOOL (``base_inv_T`` is
        INV_POS($BASE), precomputed)."""
        F = self.kin.forward(q)
        if not self._robroot_is_null:
            F = self.robroot_T @ F
        return base_inv_T @ F @ tool_T

    def ik(self, T_base: np.ndarray, tool_inv_T: np.ndarray, base_T: np.ndarray,
           status: int | None, turn: int | None, ref: np.ndarray) -> np.ndarray:
        """Axes for a TCP pose in $BASE (``tool_inv_T`` = INV_POS($TOOL))."""
        F = base_T @ T_base @ tool_inv_T
        if not self._robroot_is_null:
            F = inv_pos(self.robroot_T) @ F
        return self.kin.inverse(F, status=status, turn=turn, reference_deg=ref)

    def status_turn(self, q: np.ndarray) -> tuple[int, int]:
        return self.kin.status_turn(q)

    def tcp_pos_many(self, Q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """TCP positions (n, 3) in $BASE for axis rows Q (n, 6)."""
        F = self.kin.forward_many(Q)
        if not self._robroot_is_null:
            F = self.robroot_T @ F
        T = base_inv_T @ F @ tool_T
        return T[:, :3, 3]

    def solve_position(self, p: np.ndarray, wrist: np.ndarray, ref: np.ndarray,
                       tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """Axes whose TCP is at ``p`` (mm, in $BASE) with the wrist axes A4..A6 fixed to
        ``wrist`` (deg): Newton iteration on A1..A3 from ``ref`` (``$ORI_TYPE #JOINT``).
        Raises WorkspaceError when it does not converge, SoftLimitError outside the limits."""
        q = np.array(ref, dtype=float)
        q[3:6] = wrist
        h = 1e-5
        for _ in range(20):
            Q = np.repeat(q[None, :], 4, axis=0)
            Q[1, 0] += h
            Q[2, 1] += h
            Q[3, 2] += h
            P = self.tcp_pos_many(Q, tool_T, base_inv_T)
            r = P[0] - p
            if float(np.linalg.norm(r)) < 1e-7:
                self.kin.check_soft_limits(q)
                return q
            J = (P[1:] - P[0]).T / h
            try:
                dx = np.linalg.solve(J, -r)
            except np.linalg.LinAlgError:
                break
            q[:3] += np.clip(dx, -20.0, 20.0)
        raise WorkspaceError("workspace error: target not reachable ($ORI_TYPE #JOINT)")


# ------------------------------------------------------------------------- path pieces
class _Piece:
    """A geometric piece of a Cartesian path: position by arc length s in [0, L] (mm)."""

    length: float

    def pos(self, s: float) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError


class LinePiece(_Piece):
    def __init__(self, p0: np.ndarray, p1: np.ndarray) -> None:
        self.p0 = np.asarray(p0, dtype=float)
        self.p1 = np.asarray(p1, dtype=float)
        d = self.p1 - self.p0
        self.length = float(np.linalg.norm(d))
        self.dir = d / self.length if self.length > 0 else np.zeros(3)

    def pos(self, s: float) -> np.ndarray:
        return self.p0 + self.dir * s


class ArcPiece(_Piece):
    """Circular arc: centre c, radius r, in-plane unit vectors e1 (to the start) and e2,
    swept angle ``angle`` (rad, signed: positive = towards e2)."""

    def __init__(self, p0: np.ndarray, pa: np.ndarray, p1: np.ndarray, ca_deg: float | None) -> None:
        p0, pa, p1 = (np.asarray(v, dtype=float) for v in (p0, pa, p1))
        a, b = pa - p0, p1 - p0
        n = np.cross(a, b)
        nn = float(np.linalg.norm(n))
        if nn < 1e-6 * max(1.0, float(np.linalg.norm(a) * np.linalg.norm(b))):
            raise RobotError("CIRC: start, auxiliary and end point do not define a circle")
        n = n / nn
        # circumcentre of the triangle p0, pa, p1
        aa, bb = float(a @ a), float(b @ b)
        # c - p0 = (|a|^2 b - |b|^2 a) x (a x b) / (2 |a x b|^2)
        c = p0 + (aa * np.cross(b, np.cross(a, b)) + bb * np.cross(np.cross(a, b), a)) / (2.0 * nn * nn)
        self.c = c
        self.r = float(np.linalg.norm(p0 - c))
        self.n = n
        self.e1 = (p0 - c) / self.r
        self.e2 = np.cross(n, self.e1)
        v1 = p1 - c
        phi1 = math.atan2(float(v1 @ self.e2), float(v1 @ self.e1)) % (2 * math.pi)
        if ca_deg is not None:
            self.angle = math.radians(float(ca_deg))
        else:
            self.angle = phi1
        self.length = abs(self.angle) * self.r

    def phi(self, s: float) -> float:
        return math.copysign(s / self.r, self.angle) if self.r > 0 else 0.0

    def pos(self, s: float) -> np.ndarray:
        ph = self.phi(s)
        return self.c + self.r * (math.cos(ph) * self.e1 + math.sin(ph) * self.e2)


class CatmullRomPiece(_Piece):
    """Uniform Catmull-Rom curve from P1 to P2 (neighbours P0, P3), re-parametrised by arc
    length through a 48-point table (SPL points of a SPLINE block, reference §6.2 [U])."""

    N = 48

    def __init__(self, P0: np.ndarray, P1: np.ndarray, P2: np.ndarray, P3: np.ndarray) -> None:
        P0, P1, P2, P3 = (np.asarray(v, dtype=float) for v in (P0, P1, P2, P3))
        self.c0 = P1
        self.c1 = 0.5 * (P2 - P0)
        self.c2 = 0.5 * (2 * P0 - 5 * P1 + 4 * P2 - P3)
        self.c3 = 0.5 * (-P0 + 3 * P1 - 3 * P2 + P3)
        ts = np.linspace(0.0, 1.0, self.N + 1)
        pts = np.array([self._at(t) for t in ts])
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        self._s = np.concatenate([[0.0], np.cumsum(seg)])
        self._t = ts
        self.length = float(self._s[-1])

    def _at(self, t: float) -> np.ndarray:
        return self.c0 + t * (self.c1 + t * (self.c2 + t * self.c3))

    def pos(self, s: float) -> np.ndarray:
        if self.length <= 0:
            return self.c0.copy()
        t = float(np.interp(s, self._s, self._t))
        return self._at(t)


# ------------------------------------------------------------------------- segments
@dataclass
class TriggerPlan:
    """A trigger resolved to its segment: reference parameter ``u_ref`` on the path
    (None for DISTANCE=0/1, resolved by the controller because blends move them)."""

    trigger: Trigger
    index: int
    u_ref: float | None = None
    kind: str = "end"  # "start" | "end" | "path"


class Segment:
    """A planned motion. Sampling is by local time ``tau`` (s) from the segment start.

    Attributes:
        req: the request; id: its id.
        q0, q1: start and end axes (deg), shape (6,).
        profile: :class:`~robot.profiles.Trapezoid`; T: duration (s).
        v_prog: the requested normalised speed (1/s) (for C_VEL).
        tool_T, base_T: the motion's $TOOL and $BASE (4x4); status: start S.
        triggers: :class:`TriggerPlan` list.
    """

    cart: bool = False

    def __init__(self, req: MotionRequest, q0: np.ndarray, q1: np.ndarray, profile: Trapezoid,
                 v_prog: float, tool_T: np.ndarray, base_T: np.ndarray, model: RobotModel) -> None:
        self.req = req
        self.id = req.id
        self.q0 = q0
        self.q1 = q1
        self.profile = profile
        self.T = profile.t_total
        self.v_prog = v_prog
        self.tool_T = tool_T
        self.base_T = base_T
        self.tool_inv_T = inv_pos(tool_T)
        self.base_inv_T = inv_pos(base_T)
        self.model = model
        self.status = model.status_turn(q0)[0]
        self.triggers: list[TriggerPlan] = []
        self._last_q = q0.copy()
        self._end_frame: list[float] | None = None

    def u(self, tau: float) -> float:
        return self.profile.u(tau)

    # overridden
    def axes(self, tau: float) -> np.ndarray:
        raise NotImplementedError

    def pose(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """TCP position (mm, (3,)) and rotation matrix (3, 3) in $BASE at local time tau."""
        raise NotImplementedError

    @property
    def end_frame(self) -> list[float]:
        """Programmed end point as (X, Y, Z, A, B, C) of the TCP in $BASE (mm, deg)."""
        if self._end_frame is None:
            self._end_frame = list(matrix_to_frame(self.model.tcp(self.q1, self.tool_T,
                                                                  self.base_inv_T)))
        return self._end_frame

    def end_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Programmed end point: TCP position (mm) and 3x3 rotation in $BASE."""
        T = self.model.tcp(self.q1, self.tool_T, self.base_inv_T)
        return T[:3, 3].copy(), T[:3, :3].copy()

    def start_pose(self) -> tuple[np.ndarray, np.ndarray]:
        T = self.model.tcp(self.q0, self.tool_T, self.base_inv_T)
        return T[:3, 3].copy(), T[:3, :3].copy()

    def tcp_dist_to_end(self, u: float) -> float:
        """Euclidean TCP distance (mm) from the point at parameter u to the end point."""
        raise NotImplementedError

    def u_of_path(self, s: float) -> float:
        """Parameter u where the TCP path length from the start is ``s`` (mm), clamped."""
        raise NotImplementedError

    @property
    def path_length(self) -> float:
        raise NotImplementedError


class JointSegment(Segment):
    """PTP / SPTP: linear in axis space, synchronised time law (reference §6.6)."""

    cart = False

    def __init__(self, *a: Any, **kw: Any) -> None:
        super().__init__(*a, **kw)
        self.dq = self.q1 - self.q0
        self._len_table: tuple[np.ndarray, np.ndarray] | None = None

    def axes_u(self, u: float) -> np.ndarray:
        return self.q0 + u * self.dq

    def axes(self, tau: float) -> np.ndarray:
        return self.axes_u(self.profile.u(tau))

    def pose_u(self, u: float) -> tuple[np.ndarray, np.ndarray]:
        T = self.model.tcp(self.axes_u(u), self.tool_T, self.base_inv_T)
        return T[:3, 3].copy(), T[:3, :3].copy()

    def pose(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        return self.pose_u(self.profile.u(tau))

    def _table(self) -> tuple[np.ndarray, np.ndarray]:
        if self._len_table is None:
            us = np.linspace(0.0, 1.0, 65)
            pts = np.array([self.pose_u(float(u))[0] for u in us])
            s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
            self._len_table = (us, s)
        return self._len_table

    @property
    def path_length(self) -> float:
        return float(self._table()[1][-1])

    def u_of_path(self, s: float) -> float:
        us, ss = self._table()
        if ss[-1] <= 0:
            return 0.0
        return float(np.interp(s, ss, us))

    def tcp_dist_to_end(self, u: float) -> float:
        p_end = self.end_pose()[0]
        return float(np.linalg.norm(self.pose_u(u)[0] - p_end))


class CartSegment(Segment):
    """LIN / CIRC / SLIN / SCIRC / SPLINE: TCP path in $BASE (reference §6.7).

    ``pieces``: path pieces; ``rots``: orientation at each piece boundary (len = pieces+1);
    ``w``: time weight of each piece (``max(L/v_cp, θ/v_ori)``); ``ori``: per-piece
    orientation mode (``VAR``, ``CONSTANT``, ``PATH``).
    """

    cart = True

    def __init__(self, req: MotionRequest, q0: np.ndarray, q1: np.ndarray, profile: Trapezoid,
                 v_prog: float, tool_T: np.ndarray, base_T: np.ndarray, model: RobotModel,
                 pieces: list[_Piece], rots: list[Rotation], weights: list[float],
                 ori: list[str]) -> None:
        super().__init__(req, q0, q1, profile, v_prog, tool_T, base_T, model)
        self.pieces = pieces
        self.rots = rots
        self.ori = ori
        W = float(sum(weights))
        self.W = W
        self.joint_ori = req.params.ori_type == "JOINT" and req.kind != "SPLINE"
        cw = np.concatenate([[0.0], np.cumsum(weights)])
        self.u_bounds = cw / W if W > 0 else np.linspace(0.0, 1.0, len(pieces) + 1)
        self.lengths = np.array([p.length for p in pieces])
        self.s_bounds = np.concatenate([[0.0], np.cumsum(self.lengths)])
        # orientation of piece k at fraction f: R_k · exp(f · r_k) (= slerp, reference §6.7)
        self._R = [r.as_matrix() for r in rots]
        self._rv = [(rots[k].inv() * rots[k + 1]).as_rotvec() for k in range(len(pieces))]

    @property
    def path_length(self) -> float:
        return float(self.s_bounds[-1])

    def _locate(self, u: float) -> tuple[int, float]:
        ub = self.u_bounds
        n = len(self.pieces)
        if u <= 0.0:
            return 0, 0.0
        if u >= 1.0:
            return n - 1, 1.0
        k = int(np.searchsorted(ub, u, side="right")) - 1
        k = min(max(k, 0), n - 1)
        du = ub[k + 1] - ub[k]
        return k, (u - ub[k]) / du if du > 0 else 1.0

    def pose_u(self, u: float) -> tuple[np.ndarray, np.ndarray]:
        """TCP position (mm, (3,)) and rotation matrix (3, 3) in $BASE at parameter u."""
        k, f = self._locate(u)
        piece = self.pieces[k]
        p = piece.pos(f * piece.length)
        mode = self.ori[k]
        if mode == "VAR":
            if f <= 0.0:
                R = self._R[k]
            elif f >= 1.0:
                R = self._R[k + 1]
            else:
                R = self._R[k] @ Rotation.from_rotvec(f * self._rv[k]).as_matrix()
        elif mode == "PATH":
            assert isinstance(piece, ArcPiece)
            R = Rotation.from_rotvec(piece.n * piece.phi(f * piece.length)).as_matrix() @ self._R[k]
        else:  # CONSTANT
            R = self._R[k]
        return p, R

    def pose(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        return self.pose_u(self.profile.u(tau))

    def ik(self, p: np.ndarray, R: np.ndarray, ref: np.ndarray) -> np.ndarray:
        """Axes for a TCP pose (position mm, 3x3 rotation) in this segment's $BASE/$TOOL,
        start status S, turn nearest to ``ref``. Raises WorkspaceError/SoftLimitError."""
        T = np.eye(4)
        T[:3, :3] = R
        T[:3, 3] = p
        return self.model.ik(T, self.tool_inv_T, self.base_T, self.status, None, ref)

    def axes(self, tau: float) -> np.ndarray:
        if tau >= self.T:
            self._last_q = self.q1.copy()
            return self.q1.copy()
        if self.joint_ori:
            # $ORI_TYPE #JOINT: wrist axes linear in u, TCP on the path (reference §6.7)
            u = self.profile.u(tau)
            p = self.pose_u(u)[0]
            wrist = self.q0[3:6] + u * (self.q1[3:6] - self.q0[3:6])
            q = self.model.solve_position(p, wrist, self._last_q, self.tool_T, self.base_inv_T)
            self._last_q = q
            return q
        p, R = self.pose(tau)
        q = self.ik(p, R, self._last_q)
        self._last_q = q
        return q

    def u_of_path(self, s: float) -> float:
        sb = self.s_bounds
        if sb[-1] <= 0:
            return 0.0
        s = min(max(s, 0.0), sb[-1])
        k = int(np.searchsorted(sb, s, side="right")) - 1
        k = min(max(k, 0), len(self.pieces) - 1)
        L = self.lengths[k]
        f = (s - sb[k]) / L if L > 0 else 1.0
        return float(self.u_bounds[k] + f * (self.u_bounds[k + 1] - self.u_bounds[k]))

    def s_of_u(self, u: float) -> float:
        k, f = self._locate(u)
        return float(self.s_bounds[k] + f * self.lengths[k])

    def tcp_dist_to_end(self, u: float) -> float:
        return float(np.linalg.norm(self.pose_u(u)[0] - self.pieces[-1].pos(self.pieces[-1].length)))

    def ori_angle_to_end(self, u: float) -> float:
        """Remaining orientation change (deg) from parameter u to the end."""
        R = self.pose_u(u)[1]
        return float(np.degrees(Rotation.from_matrix(R.T @ self.pose_u(1.0)[1]).magnitude()))

    @property
    def ori_angle(self) -> float:
        return self.ori_angle_to_end(0.0)


# ------------------------------------------------------------------------- planning
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
    start6 = matrix_to_frame(start_T)
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


def _check_complete(req: MotionRequest) -> None:
    t = req.target
    if req.relative or req.kind in ("CIRC", "SCIRC", "SPLINE"):
        raise RobotError("BCO run: the first motion must be a PTP or LIN to a complete target")
    if req.is_axis_target:
        ok = all(k in t for k in AXIS_KEYS)
    else:
        ok = all(k in t for k in CART_KEYS)
    if not ok:
        raise RobotError("BCO run: the first motion needs a complete target (no partial aggregate)")


def _time_weight(L: float, theta: float, v_cp: float, v_ori: float) -> float:
    return max(L / v_cp if L > 0 else 0.0, theta / v_ori if theta > 0 else 0.0)


def plan(req: MotionRequest, q_start: np.ndarray, model: RobotModel, *,
         first: bool = False) -> Segment:
    """Plan one motion from the axes ``q_start`` (the previous programmed end point).

    Raises:
        RobotError: incomplete first motion (BCO), PATH trigger on PTP, unsupported
            ``$IPO_MODE``; WorkspaceError / SoftLimitError (subclasses) when the
            target (or a SPLINE/CIRC point) is unreachable or outside the soft limits.
    """
    p: MotionParams = req.params
    if first:
        _check_complete(req)
    if p.ipo_mode != "BASE":
        raise RobotError(f"$IPO_MODE=#{p.ipo_mode} is not supported by the simulator")
    q0 = np.asarray(q_start, dtype=float).copy()
    tool_T = frame_to_matrix(*p.tool)
    base_T = frame_to_matrix(*p.base)
    base_inv = inv_pos(base_T)
    start_T = model.tcp(q0, tool_T, base_inv)
    if req.kind in ("PTP", "SPTP"):
        seg = _plan_joint(req, q0, start_T, tool_T, base_T, model)
    else:
        seg = _plan_cart(req, q0, start_T, tool_T, base_T, model)
    _plan_triggers(seg)
    return seg


def _plan_joint(req: MotionRequest, q0: np.ndarray, start_T: np.ndarray, tool_T: np.ndarray,
                base_T: np.ndarray, model: RobotModel) -> JointSegment:
    p = req.params
    t = req.target
    if req.is_axis_target:
        if req.relative:
            q1 = q0 + np.array([float(t.get(k, 0.0)) for k in AXIS_KEYS])
        else:
            q1 = np.array([float(t[k]) if k in t else q0[i] for i, k in enumerate(AXIS_KEYS)])
        model.kin.check_soft_limits(q1)
    else:
        T1 = _cart_target(t, start_T, req.relative, req.rel_frame)
        s = int(t["S"]) if "S" in t and not req.relative else None
        tt = int(t["T"]) if "T" in t and not req.relative else None
        q1 = model.ik(T1, inv_pos(tool_T), base_T, s, tt, q0)
    dq = np.abs(q1 - q0)
    moving = dq > 1e-9
    if not moving.any():
        prof = Trapezoid.plan(math.inf, math.inf)
        v_prog = math.inf
    else:
        v_axis = model.v_max * np.array(p.vel_axis) / 100.0 * p.ov_pro / 100.0
        a_axis = model.a_max * np.array(p.acc_axis) / 100.0
        if np.any(v_axis[moving] <= 0) or np.any(a_axis[moving] <= 0):
            raise RobotError("PTP: $VEL_AXIS, $ACC_AXIS and $OV_PRO must be positive")
        V = float(np.min(v_axis[moving] / dq[moving]))
        A = float(np.min(a_axis[moving] / dq[moving]))
        prof = Trapezoid.plan(V, A)
        v_prog = V
    return JointSegment(req, q0, q1, prof, v_prog, tool_T, base_T, model)


def _orientation_modes(p: MotionParams, kind: str) -> str:
    if p.ori_type == "CONSTANT":
        return "CONSTANT"
    if kind in ("CIRC", "SCIRC") and p.circ_type == "PATH":
        return "PATH"
    return "VAR"  # #JOINT: pose_u interpolates like #VAR; axes() moves the wrist axes linearly


def _plan_cart(req: MotionRequest, q0: np.ndarray, start_T: np.ndarray, tool_T: np.ndarray,
               base_T: np.ndarray, model: RobotModel) -> CartSegment:
    p = req.params
    # build the list of (kind, target, aux, ca, params) items
    if req.kind == "SPLINE":
        if not req.segments:
            raise RobotError("SPLINE block without segments")
        items = [(s.kind.upper(), s.target, s.aux, s.ca, s.params or p, s) for s in req.segments]
    else:
        kind = {"LIN": "SLIN", "SLIN": "SLIN", "CIRC": "SCIRC", "SCIRC": "SCIRC"}[req.kind]
        items = [(kind, req.target, req.aux, req.ca, p, None)]

    cur_T = start_T
    pts_T: list[np.ndarray] = [start_T]
    geo: list[tuple[str, Any]] = []
    for kind, tgt, aux, ca, prm, _ in items:
        if any(k in tgt for k in AXIS_KEYS):
            # an axis target for a CP motion: its TCP pose
            qa = np.array([float(tgt[k]) if k in tgt else 0.0 for k in AXIS_KEYS])
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

    pts = [T[:3, 3].copy() for T in pts_T]
    pieces: list[_Piece] = []
    rots: list[Rotation] = [Rotation.from_matrix(start_T[:3, :3])]
    ori: list[str] = []
    weights: list[float] = []
    v_lims: list[tuple[float, float, float, float]] = []
    for k, (g, data) in enumerate(geo):
        prm = items[k][4]
        a, b = pts[k], pts[k + 1]
        if g == "ARC":
            piece: _Piece = ArcPiece(a, data[0], b, data[1])
            if data[1] is not None:  # CA moves the end point onto the circle
                b = piece.pos(piece.length)
                pts[k + 1] = b
                pts_T[k + 1] = pts_T[k + 1].copy()
                pts_T[k + 1][:3, 3] = b
        elif g == "SPL":
            P0 = pts[k - 1] if k >= 1 else 2 * a - b
            P3 = pts[k + 2] if k + 2 < len(pts) else 2 * b - a
            piece = CatmullRomPiece(P0, a, b, P3)
        else:
            piece = LinePiece(a, b)
        pieces.append(piece)
        mode = _orientation_modes(prm, "SCIRC" if g == "ARC" else "SLIN")
        if mode == "CONSTANT":
            R1 = rots[k]
        elif mode == "PATH":
            assert isinstance(piece, ArcPiece)
            R1 = Rotation.from_rotvec(piece.n * piece.angle) * rots[k]
        else:
            R1 = Rotation.from_matrix(pts_T[k + 1][:3, :3])
        rots.append(R1)
        ori.append(mode)
        theta = float(np.degrees((rots[k].inv() * R1).magnitude()))
        v_cp = prm.vel_cp * 1000.0 * prm.ov_pro / 100.0
        v_ori = min(prm.vel_ori1, prm.vel_ori2) * prm.ov_pro / 100.0
        a_cp = prm.acc_cp * 1000.0
        a_ori = min(prm.acc_ori1, prm.acc_ori2)
        if min(v_cp, v_ori, a_cp, a_ori) <= 0:
            raise RobotError("CP motion: $VEL, $ACC and $OV_PRO must be positive")
        weights.append(_time_weight(piece.length, theta, v_cp, v_ori))
        v_lims.append((piece.length, theta, a_cp, a_ori))

    W = float(sum(weights))
    if W <= 0:
        prof = Trapezoid.plan(math.inf, math.inf)
        v_prog = math.inf
    else:
        # per piece: speed L_k·W/w_k·du/dt <= v_cp (holds by construction of w) and
        # acceleration L_k·W/w_k·A <= a_cp, θ_k·W/w_k·A <= a_ori
        A = math.inf
        for (L, th, a_cp, a_ori), w in zip(v_lims, weights):
            if w <= 0:
                continue
            if L > 0:
                A = min(A, a_cp * w / (L * W))
            if th > 0:
                A = min(A, a_ori * w / (th * W))
        prof = Trapezoid.plan(1.0 / W, A)
        v_prog = 1.0 / W
    # end axes: IK of the final pose with the start status (CP keeps S, reference §6.5)
    T_end = np.eye(4)
    T_end[:3, :3] = rots[-1].as_matrix()
    T_end[:3, 3] = pts[-1]
    status = model.status_turn(q0)[0]
    # walk the path coarsely so the end turn follows continuously from the start
    seg = CartSegment(req, q0, q0.copy(), prof, v_prog, tool_T, base_T, model,
                      pieces, rots, weights, ori)
    ref = q0.copy()
    n_chk = max(2, min(64, int(seg.path_length / 50.0) + 2 + int(seg.ori_angle / 10.0)))
    for u in np.linspace(0.0, 1.0, n_chk)[1:]:
        pu, Ru = seg.pose_u(float(u))
        q = seg.ik(pu, Ru, ref)
        jump = np.abs(q - ref)
        if float(jump.max()) > SINGULAR_JUMP_DEG:
            i = int(np.argmax(jump))
            raise RobotError(f"CP path through a singularity: A{i + 1} would turn "
                             f"{jump[i]:.0f} deg at once (keep the status on CP paths)")
        ref = q
    seg.q1 = ref
    seg.status = status
    return seg


def _plan_triggers(seg: Segment) -> None:
    req = seg.req
    plans: list[TriggerPlan] = []
    if req.kind == "SPLINE":
        # triggers of the block segments refer to that segment's start / end
        for k, s in enumerate(req.segments):
            for tr in s.triggers:
                plans.append(_trigger_plan(seg, tr, len(plans), k))
    for tr in req.triggers:
        plans.append(_trigger_plan(seg, tr, len(plans), None))
    seg.triggers = plans


def _trigger_plan(seg: Segment, tr: Trigger, index: int, piece: int | None) -> TriggerPlan:
    if piece is not None and isinstance(seg, CartSegment):
        u0, u1 = float(seg.u_bounds[piece]), float(seg.u_bounds[piece + 1])
        s0, s1 = float(seg.s_bounds[piece]), float(seg.s_bounds[piece + 1])
        last = piece == len(seg.pieces) - 1
    else:
        u0, u1, s0, s1, last = 0.0, 1.0, 0.0, None, True
    if tr.distance is not None:
        if tr.distance == 0:
            return TriggerPlan(tr, index, None if piece in (None, 0) else u0, "start")
        return TriggerPlan(tr, index, None if last else u1, "end")
    if seg.req.kind == "PTP":
        raise RobotError("TRIGGER WHEN PATH is not allowed for a PTP motion (use SPTP or a CP motion)")
    L = seg.path_length
    if s1 is None:
        s1 = L
    ref = s0 if tr.onstart else s1
    s = min(max(ref + float(tr.path_mm), 0.0), L)  # out-of-range shifts clamp silently
    return TriggerPlan(tr, index, seg.u_of_path(s), "path")


def resolved_target(seg: Segment) -> MotionRequest:
    """A request that drives to ``seg``'s end point from anywhere: PTP segments as an
    axis-target PTP, CP segments as a LIN to the end pose (used to re-plan motions
    suspended by BRAKE when the interrupt routine moved the robot)."""
    req = seg.req
    if not seg.cart:
        tgt = {k: float(v) for k, v in zip(AXIS_KEYS, seg.q1)}
        kind = "PTP"
    else:
        T = seg.model.tcp(seg.q1, seg.tool_T, seg.base_inv_T)
        tgt = dict(zip(CART_KEYS, matrix_to_frame(T)))
        kind = "LIN"
    return MotionRequest(kind=kind, target=tgt, params=req.params, approx=req.approx,
                         approx2=req.approx2, triggers=req.triggers, file=req.file,
                         line=req.line, id=req.id)


__all__ = ["RobotModel", "Segment", "JointSegment", "CartSegment", "TriggerPlan", "plan",
           "resolved_target", "LinePiece", "ArcPiece", "CatmullRomPiece"]
