"""Planned motions (issue 76: out of robot/planner.py): a :class:`Segment` is a geometric path
plus one normalised time law that the main run samples every IPO cycle: :class:`JointSegment`
(PTP, SPTP) and :class:`CartSegment` (LIN, CIRC, SLIN, SCIRC, SPLINE), with the
:class:`TriggerPlan`s resolved on it and the compiled path (robot/cartpath.py ``CartPath``) of a
Cartesian segment's lines and arcs. robot/planner.py plans them (its docstring tells the model)."""

from __future__ import annotations

from bisect import bisect_right
from itertools import accumulate
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import SoftLimitError, WorkspaceError
from .frames import frame_to_matrix, inv_pos, rotation_angle_deg, rotvec_of
from . import kinematics
from .blas import numpy_cblas
from .motion import MotionRequest, Trigger
from .profiles import Trapezoid
from .pathpieces import ArcPiece, LinePiece, _Piece, rotvec_matrix
from .kinematics.compiled import COMPILED_AXES
from .planmemo import _BOTTOM_ROW, _EYE3, _Z3, _Z33, _Z333, _frame_of, _inverse_of, norm3
from .robotmodel import MIN_CHAIN, RobotModel


#: IPO cycles of a CP segment the main run solves at once (:meth:`CartSegment.axes_run`).
AHEAD_CYCLES = 128


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
        q0, q1: start and end axes (deg), shape (n,) (then the external axes).
        profile: :class:`~robot.profiles.Trapezoid`; T: its duration (s), ``profile.t_total``.
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
        self.v_prog = v_prog
        self.tool_T = tool_T
        self.base_T = base_T
        tool_inv, _, tool_null = _inverse_of(tool_T)
        base_inv, base_null, _ = _inverse_of(base_T)
        self.tool_inv_T = tool_inv.copy()
        self.base_inv_T = base_inv.copy()
        # the frames the IK multiplies with, None for a null frame (RobotModel.ik skips them)
        self._ik_tool = None if tool_null else self.tool_inv_T
        self._ik_base = None if base_null else base_T
        self._c_ik: Any = None      # CartSegment.ik's compiled inverse (robot/cartpath.py), False: none
        self._c_path: Any = None    # CartSegment's compiled poses (robot/cartpath.py CartPath), False: none
        self._c_framed = False      # the compiled path solves through $BASE and $TOOL (CartPath.use_frames)
        self.model = model
        self.status = model.status_turn(q0)[0]
        self.triggers: list[TriggerPlan] = []
        self.limits: Any = None            # robot.limits.MotionLimits, set by plan()
        self.vel_peak = np.zeros(len(q0))  # highest planned axis speeds (deg/s)
        self.acc_peak = np.zeros(len(q0))  # highest planned axis accelerations (deg/s²)
        self.qd_start = q1 - q0            # dq/du at the start and at the end (deg)
        self.qd_end = q1 - q0
        self._last_q = q0.copy()
        self._end_frame: list[float] | None = None
        #: the main run's solved cycles ahead (CartSegment.axes_run)
        self._ahead: tuple | None = None

    @property
    def T(self) -> float:  # noqa: N802 - the duration's symbol in the planner's formulas
        """Duration (s): the profile's (one fact; a blend that replaces the profile changes it)."""
        return self.profile.t_total

    def u(self, tau: float) -> float:
        return self.profile.u(tau)

    # overridden
    def axes(self, tau: float) -> np.ndarray:
        raise NotImplementedError

    def axes_run(self, pt: float, t0: float, dt: float, end: float) -> np.ndarray:
        """:meth:`axes` at ``pt - t0`` from the main run (see :meth:`CartSegment.axes_run`)."""
        return self.axes(pt - t0)

    def pose(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """TCP position (mm, (3,)) and rotation matrix (3, 3) in $BASE at local time tau."""
        raise NotImplementedError

    @property
    def end_frame(self) -> list[float]:
        """Programmed end point as (X, Y, Z, A, B, C) of the TCP in $BASE (mm, deg)."""
        if self._end_frame is None:
            self._end_frame = list(_frame_of(self.model.tcp(self.q1, self.tool_T,
                                                                  self.base_inv_T)))
        return self._end_frame

    def end_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Programmed end point: TCP position (mm) and 3x3 rotation in $BASE."""
        T = self.model.tcp(self.q1, self.tool_T, self.base_inv_T)
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
            # the 65 TCP positions in one call (robot/ipocycle.py Forward.tcp_points, compiled where
            # built: pose_u's numbers), else point by point
            pts = self.model.tcp_points(self.q0, self.dq, us, self.tool_T, self.base_inv_T)
            if pts is None:
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

    def tcp_dist_to_end(self, u: float, p_end: np.ndarray | None = None) -> float:
        """:meth:`Segment.tcp_dist_to_end`; `p_end`: the end point's position when the caller
        has it already (``end_pose()[0]``)."""
        if p_end is None:
            p_end = self.end_pose()[0]
        pts = self.model.tcp_points(self.q0, self.dq, np.array((u,)), self.tool_T, self.base_inv_T)
        return norm3((self.pose_u(u)[0] if pts is None else pts[0]) - p_end)


class CartSegment(Segment):
    """LIN / CIRC / SLIN / SCIRC / SPLINE: TCP path in $BASE (reference §6.7).

    ``pieces``: path pieces; ``rots``: orientation at each piece boundary (len = pieces+1);
    ``w``: time weight of each piece (``max(L/v_cp, θ/v_ori)``); ``ori``: per-piece
    orientation mode (``VAR``, ``CONSTANT``, ``PATH``).
    """

    cart = True

    def __init__(self, req: MotionRequest, q0: np.ndarray, q1: np.ndarray, profile: Trapezoid,
                 v_prog: float, tool_T: np.ndarray, base_T: np.ndarray, model: RobotModel,
                 pieces: list[_Piece], rots: list[np.ndarray], weights: list[float],
                 ori: list[str]) -> None:
        super().__init__(req, q0, q1, profile, v_prog, tool_T, base_T, model)
        #: E1..En at the end of the path (they move linearly in u from q0's)
        self.e1 = np.asarray(q1, dtype=float)[model.n:].copy()
        self.pieces = pieces
        self.rots = rots
        self.ori = ori
        W = float(sum(weights))
        self.W = W
        self.joint_ori = req.params.ori_type == "JOINT" and req.kind != "SPLINE"
        cw = np.array([0.0, *accumulate(weights)])     # np.cumsum's sums, in its order
        self.u_bounds = cw / W if W > 0 else np.linspace(0.0, 1.0, len(pieces) + 1)
        self._ub = self.u_bounds.tolist()
        self._lens = [float(p.length) for p in pieces]
        self.lengths = np.array(self._lens)
        self._sb = [0.0, *accumulate(self._lens)]     # s_bounds as floats, for u_of_path
        self.s_bounds = np.array(self._sb)
        # orientation of piece k at fraction f: R_k · exp(f · r_k) (= slerp, reference §6.7)
        self._R = rots
        self._rv = [rotvec_of(rots[k].T @ rots[k + 1]) for k in range(len(pieces))]
        # a piece without orientation change (a LIN that keeps the start orientation): its
        # R_k · exp(f · 0) once, instead of a product with the identity every cycle
        self._R_still = [self._R[k] @ _EYE3 if norm3(rv) < 1e-12     # rotvec_matrix(0)
                         else None for k, rv in enumerate(self._rv)]
        self._path_end: np.ndarray | None = None      # tcp_dist_to_end's end point, once

    @property
    def path_length(self) -> float:
        return float(self.s_bounds[-1])

    def _locate(self, u: float) -> tuple[int, float]:
        ub = self._ub
        n = len(self.pieces)
        if u <= 0.0:
            return 0, 0.0
        if u >= 1.0:
            return n - 1, 1.0
        k = bisect_right(ub, u) - 1
        k = min(max(k, 0), n - 1)
        du = ub[k + 1] - ub[k]
        return k, (u - ub[k]) / du if du > 0 else 1.0

    def pose_u(self, u: float) -> tuple[np.ndarray, np.ndarray]:
        """TCP position (mm, (3,)) and rotation matrix (3, 3) in $BASE at parameter u."""
        cp = self._c_path
        if cp is None:
            cp = self._compiled_path()
        if cp:
            try:
                pr = cp.pose_u(u)      # the same pose, compiled (robot/cartpath.py CartPath)
            except (TypeError, ValueError):
                pr = None
            if pr is not None:
                return pr
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
                R = self._R_still[k]
                if R is None:
                    R = self._R[k] @ rotvec_matrix(f * self._rv[k])
        elif mode == "PATH":
            assert isinstance(piece, ArcPiece)
            R = rotvec_matrix(piece.n * piece.phi(f * piece.length)) @ self._R[k]
        else:  # CONSTANT
            R = self._R[k]
        return p, R

    def pose(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        return self.pose_u(self.profile.u(tau))

    def ik(self, p: np.ndarray, R: np.ndarray, ref: np.ndarray, u: float | None = None) -> np.ndarray:
        """Axes for a TCP pose (position mm, 3x3 rotation) in this segment's $BASE/$TOOL,
        start status S, turn nearest to ``ref``. With external axes they take their value
        at the path parameter `u` (``E0 + u·(E1 - E0)``), or ``ref``'s without `u`.
        Raises WorkspaceError/SoftLimitError."""
        c = self._c_ik
        if c is None:
            c = self._c_ik = self._compiled_ik()
        if c:
            # no $TOOL, $BASE, $ROBROOT or external axes between this pose and the arm's: the
            # compiled inverse solves it as it stands (robot/kinematics/fastpath.py; the same axes as
            # below); None: the Python code decides (and raises)
            try:
                q = c.inverse_rp(R, p, self.status, None, ref)
            except (TypeError, ValueError):     # not float64 arrays: the Python code takes them
                q = None
            if q is not None:
                return q
        else:
            cp = self._c_path
            if cp is None:
                cp = self._compiled_path()
            if cp and self._c_framed:
                # $BASE and $TOOL multiplied as below, numpy's BLAS in C (robot/cartpath.py
                # CartPath.use_frames), then the compiled inverse; None: the code below decides
                try:
                    q = cp.solve_rp(R, p, self.status, ref)
                except (TypeError, ValueError):
                    q = None
                if q is not None:
                    return q
        T = np.empty((4, 4))
        T[:3, :3] = R
        T[:3, 3] = p
        T[3] = _BOTTOM_ROW
        n = self.model.n
        if u is not None and len(ref) > n:
            ref = np.concatenate([ref[:n], self.q0[n:] + u * (self.e1 - self.q0[n:])])
        return self.model.ik(T, self._ik_tool, self._ik_base, self.status, None, ref)

    def _compiled_path(self) -> Any:
        """robot/cartpath.py's ``CartPath`` of this segment's lines and arcs (kept; with the
        compiled inverse when :meth:`ik` runs it), or False (no compiled module, external
        axes, ``$ORI_TYPE #JOINT``)."""
        if self._c_path is None:
            self._c_path = False
            sc = kinematics.compiled_module()
            if sc is not None and len(self.q0) == self.model.n == COMPILED_AXES and not self.joint_ori:
                self._c_path = _cart_path(sc, self) or False
        return self._c_path

    def compiled_solver(self) -> bool:
        """Does :meth:`ik` run compiled code: the compiled inverse on the poses as they stand, or
        the compiled path's through $BASE and $TOOL (:func:`_cart_path`)?"""
        return bool(self.compiled_inverse()) or (bool(self._compiled_path()) and self._c_framed)

    def compiled_inverse(self) -> Any:
        """The compiled inverse :meth:`ik` runs on its poses as they stand (kept), or False."""
        c = self._c_ik
        if c is None:
            c = self._c_ik = self._compiled_ik()
        return c

    def _compiled_ik(self) -> Any:
        """The compiled inverse for :meth:`ik`'s poses as they stand, or False."""
        m = self.model
        if (type(m) is not RobotModel or m.n_ext or not m._robroot_is_null or self._ik_tool is not None
                or self._ik_base is not None):
            return False
        return m.kin.compiled_core()

    def ik_chain(self, poses: list[tuple[np.ndarray, np.ndarray]], ref: np.ndarray) -> np.ndarray | None:
        """:meth:`ik` of each pose with the previous solution as reference (the first: `ref`),
        solved at once (:meth:`RobotModel.ik_chain`): (N, n) axes, or None (solve one by one)."""
        return self.model.ik_chain(poses, self._ik_tool, self._ik_base, self.status, ref)

    def ik_chain_compiled(self, poses: list[tuple[np.ndarray, np.ndarray]], ref: np.ndarray) -> np.ndarray | None:
        """:meth:`ik` of each pose with the previous solution as reference (the first: `ref`)
        in one call of the compiled inverse (robot/kinematics/fastpath.py ``inverse_chain_rp``, the rows of
        the calls :meth:`ik` makes, bit for bit): (N, 6) axes, or None where :meth:`ik` does
        not run the compiled inverse as it stands or some pose needs the Python code (the
        caller solves pose by pose, which raises the error)."""
        c = self.compiled_inverse()
        if not c or not poses or len(ref) != COMPILED_AXES:
            return None
        R = np.array([pr[1] for pr in poses], dtype=float)
        p = np.array([pr[0] for pr in poses], dtype=float)
        if R.shape != (len(poses), 3, 3) or p.shape != (len(poses), 3):
            return None
        return c.inverse_chain_rp(R, p, self.status, None, np.asarray(ref, dtype=float))

    def axes_run(self, pt: float, t0: float, dt: float, end: float) -> np.ndarray:
        """:meth:`axes` at ``tau = pt - t0`` for the main run, which advances ``pt`` by `dt`
        each IPO cycle: the coming cycles up to local time `end` (exclusive; the segment's end
        or its blend start) are solved at once (:meth:`ik_chain`, up to
        :data:`AHEAD_CYCLES`) and kept. A kept row is returned only for the same profile, the
        same ``tau`` and the same reference (the last setpoint, byte for byte); anything
        else (a BRAKE, a new blend profile, a setpoint set from outside) solves again, so
        the result is always the one :meth:`axes` gives."""
        tau = pt - t0
        if self._c_ik:                # the compiled inverse: cycle by cycle (no numpy chains)
            return self.axes(tau)
        ahead = self._ahead
        if ahead is not None:
            prof, taus, refs, Q, i = ahead
            if (i < len(taus) and prof is self.profile and taus[i] == tau
                    and refs[i] == self._last_q.tobytes()):
                q = Q[i].copy()
                self._ahead = (prof, taus, refs, Q, i + 1)
                self._last_q = q
                return q
            self._ahead = None
        if self.joint_ori or len(self.q0) > self.model.n or tau >= self.T or not self.model.batch_ik:
            return self.axes(tau)
        if end - tau < (MIN_CHAIN - 2) * dt:     # the segment's tail: cycle by cycle
            return self.axes(tau)
        taus = [tau]
        t = pt
        while len(taus) < AHEAD_CYCLES:
            t = t + dt
            if t - t0 >= end:
                break
            taus.append(t - t0)
        if len(taus) < MIN_CHAIN:
            return self.axes(tau)
        ref = self._last_q
        Q = self.ik_chain([self.pose(x) for x in taus], ref)
        if Q is None:
            return self.axes(tau)
        refs = [ref.tobytes()] + [row.tobytes() for row in Q[:-1]]
        self._ahead = (self.profile, taus, refs, Q, 0)
        return self.axes_run(pt, t0, dt, end)

    def axes(self, tau: float) -> np.ndarray:
        if tau >= self.T:
            self._last_q = self.q1.copy()
            return self.q1.copy()
        if self.joint_ori:
            q = self.joint_axes_u(self.profile.u(tau), self._last_q)
            self._last_q = q
            return q
        if len(self.q0) > self.model.n:
            u = self.profile.u(tau)
            q = self.ik(*self.pose_u(u), self._last_q, u)
        else:
            cp = self._c_path
            if cp is None:
                cp = self._compiled_path()
            if cp:
                # pose_u and ik in one compiled call (the same axes); None: the code below
                try:
                    q = cp.axes_u(self.profile.u(tau), self.status, self._last_q)
                except (TypeError, ValueError):
                    q = None
                if q is not None:
                    self._last_q = q
                    return q
            p, R = self.pose(tau)
            q = self.ik(p, R, self._last_q)
        self._last_q = q
        return q

    def joint_axes_u(self, u: float, ref: np.ndarray) -> np.ndarray:
        """``$ORI_TYPE #JOINT`` (reference §6.7): the axes at parameter `u`: the wrist axes
        linear from the start's to the end's (:attr:`q1`: the target's S and T), A1..A3 putting
        the TCP on the path (Newton from `ref`)."""
        p = self.pose_u(u)[0]
        n = self.model.n
        wrist = self.q0[3:n] + u * (self.q1[3:n] - self.q0[3:n])
        if len(ref) > n:
            ref = np.concatenate([ref[:n], self.q0[n:] + u * (self.e1 - self.q0[n:])])
        return self.model.solve_position(p, wrist, ref, self.tool_T, self.base_inv_T)

    def u_of_path(self, s: float) -> float:
        sb, ub = self._sb, self._ub         # s_bounds and u_bounds as floats (the same numbers)
        if sb[-1] <= 0:
            return 0.0
        s = min(max(s, 0.0), sb[-1])
        k = bisect_right(sb, s) - 1         # np.searchsorted(s_bounds, s, side="right") - 1
        k = min(max(k, 0), len(self.pieces) - 1)
        L = self._lens[k]
        f = (s - sb[k]) / L if L > 0 else 1.0
        return float(ub[k] + f * (ub[k + 1] - ub[k]))

    def s_of_u(self, u: float) -> float:
        k, f = self._locate(u)
        return float(self.s_bounds[k] + f * self.lengths[k])

    def tcp_dist_to_end(self, u: float) -> float:
        end = self._path_end
        if end is None:             # the last piece's end point (its pieces do not change)
            end = self._path_end = self.pieces[-1].pos(self.pieces[-1].length)
        cp = self._c_path
        if cp is None:
            cp = self._compiled_path()
        if cp:
            # the same distance in C (robot/cartpath.py CartPath.dist_to: numpy's dot product)
            sc = kinematics.compiled_module()
            blas = _line_blas(sc) if sc is not None else None
            d = cp.dist_to(u, end, blas[1]) if blas is not None else None
            if d is not None:
                return d
        return norm3(self.pose_u(u)[0] - end)

    def ori_angle_to_end(self, u: float) -> float:
        """Remaining orientation change (deg) from parameter u to the end."""
        R = self.pose_u(u)[1]
        return rotation_angle_deg(R, self.pose_u(1.0)[1])

    @property
    def ori_angle(self) -> float:
        return self.ori_angle_to_end(0.0)


def _cart_path(sc: Any, seg: "CartSegment") -> Any:
    """robot/cartpath.py's ``CartPath`` of `seg`'s pieces (see ``CartSegment._compiled_path``):
    lines and arcs with the rotations ``CartSegment.pose_u`` holds, other pieces (splines, a
    ``#PATH`` orientation) marked for the Python code; None when no piece is mirrored."""
    n = len(seg.pieces)
    # the tables as lists first, each made an array once (a line: a = p0, b = dir; an arc: a = centre,
    # b = e1, c = e2, r, angle; rots: the rotations at f <= 0, within, at f >= 1)
    kinds, mid_ok = [-1] * n, [0] * n
    length, r, angle = [0.0] * n, [1.0] * n, [0.0] * n
    a, b, c = [_Z3] * n, [_Z3] * n, [_Z3] * n
    rots: list[Any] = [_Z333] * n
    for k, pc in enumerate(seg.pieces):
        mode = seg.ori[k]
        if type(pc) is LinePiece:
            kind, pa, pb, pcc, pr, pang = 0, pc.p0, pc.dir, _Z3, 1.0, 0.0
        elif type(pc) is ArcPiece:
            kind, pa, pb, pcc, pr, pang = 1, pc.c, pc.e1, pc.e2, pc.r, pc.angle
        else:
            continue
        if mode == "VAR":
            still = seg._R_still[k]
            rots[k] = (seg._R[k], _Z33 if still is None else still, seg._R[k + 1])
            mid_ok[k] = 0 if still is None else 1
        elif mode == "CONSTANT":
            rots[k] = (seg._R[k],) * 3
            mid_ok[k] = 1
        else:
            continue
        kinds[k], a[k], b[k], c[k], r[k], angle[k], length[k] = kind, pa, pb, pcc, pr, pang, pc.length
    if max(kinds) < 0:
        return None
    kinds_a, mid_a = np.array(kinds, dtype=np.intc), np.array(mid_ok, dtype=np.intc)
    length_a, r_a, angle_a = np.array(length, dtype=float), np.array(r, dtype=float), np.array(angle, dtype=float)
    a_a, b_a, c_a = np.array(a, dtype=float), np.array(b, dtype=float), np.array(c, dtype=float)
    rots_a = np.array(rots, dtype=float)
    opw = seg.compiled_inverse() or None
    gemm = 0
    if opw is None:
        m = seg.model
        if type(m) is RobotModel and not m.n_ext and m._robroot_is_null:
            opw = m.kin.compiled_core() or None
            gemm = _frames_gemm(sc) if opw is not None else 0
            if not gemm:
                opw = None
    cp = sc.CartPath(opw, np.asarray(seg._ub, dtype=float), kinds_a, mid_a, length_a, r_a, angle_a, a_a, b_a, c_a,
                     rots_a)
    if gemm:
        cp.use_frames(gemm, seg._ik_base, seg._ik_tool)
        seg._c_framed = True
    _use_turns(sc, seg, cp, kinds, mid_ok)
    return cp


def _use_turns(sc: Any, seg: "CartSegment", cp: Any, kinds: list[int], mid_ok: list[int]) -> None:
    """The slerps within `seg`'s ``#VAR`` pieces whose orientation turns, computed by `cp` (robot/
    cartpath.py ``CartPath.use_turns``; ``CartSegment.pose_u``'s ``R_k @ rotvec_matrix(f * rv_k)``)
    where the piece's R_k and rv_k are C-contiguous float64 arrays (numpy's product of such is the one
    call the compiled path makes) and :func:`_turn_gemm` found the products numpy's."""
    ok = [0] * len(kinds)
    for k, kind in enumerate(kinds):
        if kind >= 0 and not mid_ok[k] and seg.ori[k] == "VAR":
            R, rv = seg._R[k], seg._rv[k]
            if (type(R) is np.ndarray and R.dtype == np.float64 and R.shape == (3, 3) and R.flags.c_contiguous
                    and type(rv) is np.ndarray and rv.dtype == np.float64 and rv.shape == (3,)):
                ok[k] = 1
    if not any(ok):
        return
    gemm = _turn_gemm(sc)
    if gemm:
        rvs = np.array([rv if ok[k] else _Z3 for k, rv in enumerate(seg._rv)], dtype=float)
        cp.use_turns(gemm, rvs, np.array(ok, dtype=np.intc))


#: [address] of numpy's cblas_dgemm once robot/cartpath.py ``turn_products`` was seen to compute
#: ``R0 @ rotvec_matrix(f * rv)`` as numpy and robot/pathpieces.py do, [0] when not: :func:`_turn_gemm`
_TURN_GEMM: list[int] = []


def _turn_gemm(sc: Any) -> int:
    """The ``cblas_dgemm`` address for robot/cartpath.py ``CartPath.use_turns`` (0: none, or its slerps
    are not robot/pathpieces.py's with numpy's product bit for bit on a probe of drawn rotations,
    rotation vectors and fractions, tiny turns among them), checked once a process."""
    if not _TURN_GEMM:
        gemm = numpy_cblas("dgemm")
        rng = np.random.default_rng(8606)
        for i in range(64 if gemm else 0):
            R0 = frame_to_matrix(*rng.uniform(-500.0, 500.0, 6))[:3, :3].copy()
            rv = rng.normal(0.0, 1.0, 3) * (1e-13 if i % 8 == 0 else 1.0)
            f = float(rng.uniform(0.0, 1.0))
            if sc.turn_products(gemm, R0, rv, f).tobytes() != (R0 @ rotvec_matrix(f * rv)).tobytes():
                gemm = 0
        _TURN_GEMM.append(gemm)
    return _TURN_GEMM[0]


#: [address] of numpy's cblas_dgemm once CartPath.use_frames was seen to multiply as numpy does
#: (robot/blas.py), [0] when not: :func:`_frames_gemm`
_FRAMES_GEMM: list[int] = []


def _frames_gemm(sc: Any) -> int:
    """The ``cblas_dgemm`` address for robot/cartpath.py ``CartPath.use_frames`` (0: none, or its
    products are not numpy's ``@`` bit for bit on a probe of drawn frames and poses: the
    compiled path then solves only poses without $BASE and $TOOL), checked once a process."""
    if not _FRAMES_GEMM:
        gemm = numpy_cblas("dgemm")
        if gemm:
            rng = np.random.default_rng(62)
            z1, z3 = np.zeros(1), np.zeros((1, 3))
            probe = sc.CartPath(None, np.array([0.0, 1.0]), np.zeros(1, dtype=np.intc),
                                np.ones(1, dtype=np.intc), z1, np.ones(1), z1, z3, z3, z3, np.zeros((1, 3, 3, 3)))
            for i in range(32):
                base = frame_to_matrix(*rng.uniform(-500.0, 500.0, 6))
                tool = inv_pos(frame_to_matrix(*rng.uniform(-200.0, 200.0, 6)))
                T = frame_to_matrix(*rng.uniform(-900.0, 900.0, 6))
                pre, post = (base, tool) if i % 3 == 0 else (None, tool) if i % 3 == 1 else (base, None)
                probe.use_frames(gemm, pre, post)
                want = T if pre is None else pre @ T
                want = want if post is None else want @ post
                if probe.flange_rp(T[:3, :3], T[:3, 3])[:3].tobytes() != want[:3].tobytes():
                    gemm = 0
                    break
        _FRAMES_GEMM.append(gemm)
    return _FRAMES_GEMM[0]


#: [(cblas_dgemm, cblas_ddot) addresses] once robot/cartpath.py ``line_products`` was seen to
#: compute numpy's products and dot products bit for bit, [None] when not: :func:`_line_blas`
_LINE_BLAS: list[tuple[int, int] | None] = []


def _line_blas(sc: Any) -> tuple[int, int] | None:
    """The ``cblas_dgemm`` and ``cblas_ddot`` addresses for robot/cartpath.py ``plan_line``, or None
    (none at hand, or its ``A.T @ B``, ``A @ eye(3)`` and ``v.dot(v)`` are not numpy's bit for bit on
    a probe of drawn rotations, the same and nearly the same, and vectors), checked once a process."""
    if not _LINE_BLAS:
        gemm, ddot = numpy_cblas("dgemm"), numpy_cblas("ddot")
        ok = bool(gemm and ddot)
        rng = np.random.default_rng(6205)
        for i in range(48 if ok else 0):
            A = frame_to_matrix(*rng.uniform(-500.0, 500.0, 6))[:3, :3].copy()
            B = frame_to_matrix(*rng.uniform(-500.0, 500.0, 6))[:3, :3].copy() if i % 2 else \
                A + rng.normal(0.0, 1e-15, (3, 3)) * (i % 4 == 0)
            v = rng.normal(0.0, 1.0, 3) * 10.0 ** rng.uniform(-20.0, 6.0)
            P, Q, dot = sc.line_products(gemm, ddot, A, B, v)
            if (P.tobytes() != (A.T @ B).tobytes() or Q.tobytes() != (A @ _EYE3).tobytes()
                    or dot.hex() != float(v.dot(v)).hex()):
                ok = False
        _LINE_BLAS.append((gemm, ddot) if ok else None)
    return _LINE_BLAS[0]


__all__ = ["Segment", "JointSegment", "CartSegment", "TriggerPlan", "_line_blas"]
