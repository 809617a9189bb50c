"""The time law of a Cartesian path (issue 76: cut out of robot/planner.py's ``_plan_cart``;
reference §6.2, §6.7, issue 15): the path speed and acceleration each piece allows (``$VEL.CP``,
``$VEL.ORI``, ``$ACC``, ``$OV_PRO``; a spline's curvature), the corner speeds where pieces meet,
the planning walk of each piece (the inverse kinematics along samples of the path keeping the
start status S and the nearest turn, singularities, the axis speeds and accelerations the path
needs, so that it is slowed until the axes keep machine data: ``|q'|·du/dt <= v_max``,
``|q''|·(du/dt)² + |q'|·d²u/dt² <= a_max``), the junctions' axis-velocity jumps, and the
segment's profile (robot/profiles.py: a trapezoid for one piece, else a piecewise profile).
The pieces the compiled path solves are walked in C (robot/cartpath.py ``CartPath.walk``), the
same numbers."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import RobotError
from .frames import inv_pos
from .limits import T1_MARGIN, T1_SPEED_MM_S, cp_path_speed
from .motion import MotionParams
from .planmemo import _samples, gradient_rows
from .profiles import PiecewiseProfile, Trapezoid
from .robotmodel import MIN_CHAIN
from .segments import CartSegment

#: An axis jump (deg) between neighbouring planning samples of a CP path that means the
#: path crosses a singularity (the IK had to flip the wrist to keep the status).
SINGULAR_JUMP_DEG = 90.0
#: Largest axis step (deg) between the planning samples of a CP path (axis speed and
#: acceleration are estimated from them).
CP_SAMPLE_STEP_DEG = 1.0
#: Most planning samples of one piece of a CP path (near a wrist singularity A4/A6 turn fast
#: on a short piece; 256 left steps of several degrees there, and the sampled speed 3 % under
#: the peak between samples: tests/robot/test_limits_property.py, KR 120 R2700 extra HA).
CP_MAX_SAMPLES = 1024


def cp_speeds(prm: MotionParams, mode: str) -> tuple[float, float, float, float]:
    """(v_cp mm/s, v_ori deg/s, a_cp mm/s², a_ori deg/s²) of a CP piece: ``$VEL.CP``
    · ``$OV_PRO``% (T1: at most 250 mm/s), the smaller ORI value (reference §6.7); the
    accelerations · ``($OV_PRO%)²``: the override scales the motion's time, as it does a PTP's
    (robot/limits.py ``ptp_axis_accelerations``; issue 60)."""
    v_cp = cp_path_speed(prm, mode)
    v_ori = min(prm.vel_ori1, prm.vel_ori2) * prm.ov_pro / 100.0
    ov2 = (prm.ov_pro / 100.0) ** 2
    a_cp = prm.acc_cp * 1000.0 * ov2
    a_ori = min(prm.acc_ori1, prm.acc_ori2) * ov2
    if min(v_cp, v_ori, a_cp, a_ori) <= 0:
        raise RobotError("CP motion: $VEL, $ACC and $OV_PRO must be positive")
    return v_cp, v_ori, a_cp, a_ori


def _compiled_walker(seg: CartSegment) -> Callable[..., Any] | None:
    """The compiled walk of the planning walk's pieces (robot/cartpath.py ``CartPath.walk``)
    where the walk solves each piece's samples with ``CartPath.chain_u``, else None."""
    if seg.joint_ori or len(seg.q0) != seg.model.n or not seg.compiled_solver():
        return None
    cp = seg._compiled_path()
    return cp.walk if cp else None


def _piece_limits(seg: CartSegment, thetas: list[float], weights: list[float],
                  speeds: list[tuple]) -> tuple[list[float], list[float], list[float]]:
    """(v_max, a_max, v_prog) in u per piece from the path's and the orientation's speeds and
    accelerations; a spline's curvature keeps the centripetal acceleration v²/r within
    ``$ACC.CP``; a CIRC's path speed is not limited by it (the real KR C4 plans a 360° CIRC of
    r 150 mm at $ACC.CP 2.3 m/s² as the plain triangle 2·sqrt(L/a): 1.280 s, issue 60)."""
    W = seg.W
    vmax: list[float] = []
    amax: list[float] = []
    vprog: list[float] = []
    for k, piece in enumerate(seg.pieces):
        L, th, w = piece.length, thetas[k], weights[k]
        v_cp, v_ori, a_cp, a_ori = speeds[k]
        lk = L * W / w if w > 0 else 0.0       # mm per unit u
        ok = th * W / w if w > 0 else 0.0      # deg per unit u
        curved = L > 0 and seg.req.kind != "CIRC"
        v_curve = math.sqrt(a_cp * piece.min_radius) if curved else math.inf
        v = min(v_cp / lk if lk > 0 else math.inf, v_ori / ok if ok > 0 else math.inf)
        vprog.append(v)
        v = min(v, v_curve / lk if lk > 0 else math.inf)
        a = min(a_cp / lk if lk > 0 else math.inf, a_ori / ok if ok > 0 else math.inf)
        vmax.append(v if v < math.inf else 1e12)
        amax.append(a if a < math.inf else 1e12)
    return vmax, amax, vprog


def _corner_speeds(seg: CartSegment, weights: list[float], speeds: list[tuple],
                   dt: float) -> tuple[list[float], list[bool]]:
    """(speed in u at each piece boundary, is it a kink): the velocity turns within one IPO
    cycle at a corner, so the corner speed keeps |Δv|/Δt within $ACC.CP (reference §6.2: the
    spline is slowed at corners)."""
    pieces, W = seg.pieces, seg.W
    m = len(pieces)
    vnode = [0.0] * (m + 1)
    kink = [False] * (m + 1)
    for k in range(1, m):
        vnode[k] = math.inf
        A_, B_ = pieces[k - 1], pieces[k]
        if A_.length <= 0 or B_.length <= 0:
            vnode[k] = 0.0
            continue
        cosang = float(np.clip(A_.tangent(A_.length) @ B_.tangent(0.0), -1.0, 1.0))
        ang = math.acos(cosang)
        if ang > 1e-3:
            kink[k] = True
            a_c = min(speeds[k - 1][2], speeds[k][2])
            v_c = a_c * dt / (2.0 * math.sin(ang / 2.0))
            lk0 = A_.length * W / weights[k - 1]
            lk1 = B_.length * W / weights[k]
            vnode[k] = min(v_c / lk0, v_c / lk1)
    return vnode, kink


def _singular(jump: np.ndarray) -> RobotError:
    """The error of an axis step `jump` (deg, per axis) through a singularity."""
    i = int(np.argmax(jump))
    return RobotError(f"CP path through a singularity: A{i + 1} would turn "
                      f"{jump[i]:.0f} deg at once (keep the status on CP paths)")


@dataclass
class _Walk:
    """The planning walk of a CP segment's pieces: the limits it lowers (``vmax``, ``amax``, per
    piece, in u), the reference axes it carries from sample to sample, and per piece the axes
    at its start and (max |q'|, max |q''|, acceleration budget)."""

    seg: CartSegment
    thetas: list[float]
    weights: list[float]
    vmax: list[float]
    amax: list[float]
    kink: list[bool]
    plain: bool
    ref: np.ndarray
    junction_q: list[np.ndarray] = field(default_factory=list)
    sec_d: list[tuple[np.ndarray, np.ndarray, float]] = field(default_factory=list)

    def run(self) -> None:
        """Walk every piece: in C where the compiled path solves it, else here."""
        seg, model = self.seg, self.seg.model
        walker = _compiled_walker(seg) if model.mode != "T1" else None
        chain_from = MIN_CHAIN if model.batch_ik else CP_MAX_SAMPLES + 1
        ub = seg.u_bounds
        for k, piece in enumerate(seg.pieces):
            nk = max(4, min(48, int(piece.length / 50.0) + int(self.thetas[k] / 10.0) + 4))
            # next to a corner the axis velocity turns within one IPO cycle (up to half of a_max,
            # junction rule below) while the path brakes: the piece keeps the other half
            budget = 0.5 if (self.kink[k] or self.kink[k + 1]) else 1.0
            walked = None if walker is None else walker(
                float(ub[k]), float(ub[k + 1]), nk, seg.status, self.ref, chain_from, budget, self.plain,
                model.v_max, model.a_max, self.vmax[k], SINGULAR_JUMP_DEG, CP_SAMPLE_STEP_DEG, CP_MAX_SAMPLES)
            if walked is not None:
                self._take_walked(k, walked, budget)
            else:
                self._walk_piece(k, nk, budget)

    def _take_walked(self, k: int, walked: tuple, budget: float) -> None:
        """Piece k as the compiled walk planned it."""
        seg = self.seg
        self.junction_q.append(self.ref.copy())
        self.ref, d1_first, d1_last, qd, qdd, self.vmax[k], Aax = walked
        if k == 0:
            seg.qd_start = d1_first
        if k == len(seg.pieces) - 1:
            seg.qd_end = d1_last
        if not self.plain:
            self.amax[k] = min(self.amax[k], max(Aax, 1e-9))
        self.sec_d.append((qd, qdd, budget))

    def _samples_of(self, k: int, nk: int) -> tuple[np.ndarray, np.ndarray]:
        """(u samples, axes at them) of piece k: nk + 1 samples at first, more until no axis
        moves more than CP_SAMPLE_STEP_DEG between two (near a wrist singularity A4/A6 turn fast
        on a short piece of path), up to CP_MAX_SAMPLES. Raises RobotError (a singularity)."""
        seg, model = self.seg, self.seg.model
        ub, n_ax = seg.u_bounds, len(seg.q0)
        start = self.ref
        while True:
            us = _samples(float(ub[k]), float(ub[k + 1]), nk + 1)
            Q = np.empty((nk + 1, n_ax))
            Q[0] = start
            self.ref = start
            jumps = self._chain(us, nk, Q)
            for j in range(1, nk + 1 if jumps is None else 1):
                if seg.joint_ori:
                    q = seg.joint_axes_u(float(us[j]), self.ref)
                else:
                    pu, Ru = seg.pose_u(float(us[j]))
                    q = seg.ik(pu, Ru, self.ref, float(us[j])) if n_ax > model.n else seg.ik(pu, Ru, self.ref)
                jump = np.abs(q - self.ref)
                if float(jump.max()) > SINGULAR_JUMP_DEG:
                    raise _singular(jump)
                Q[j] = q
                self.ref = q
            if nk <= 0:
                step = 0.0
            else:
                step = float((jumps if jumps is not None else np.abs(np.diff(Q, axis=0))).max())
            if step <= CP_SAMPLE_STEP_DEG or nk >= CP_MAX_SAMPLES:
                return us, Q
            nk = min(CP_MAX_SAMPLES, int(nk * step / CP_SAMPLE_STEP_DEG) + 1)

    def _chain(self, us: np.ndarray, nk: int, Q: np.ndarray) -> np.ndarray | None:
        """The axes at samples 1..nk solved at once into Q (their steps, checked for a
        singularity in the per-sample order), or None: solved sample by sample."""
        seg, model = self.seg, self.seg.model
        chain = None
        if seg.joint_ori:
            pass                        # solved sample by sample (the wrist is given)
        elif len(seg.q0) == model.n and nk >= MIN_CHAIN and model.batch_ik:
            chain = seg.ik_chain([seg.pose_u(float(us[j])) for j in range(1, nk + 1)], self.ref)
        elif len(seg.q0) == model.n and seg.compiled_solver():
            # the poses and the compiled inverse along the samples in one call (the same
            # rows); else the poses here and the inverse in one call
            cp = seg._compiled_path()
            chain = cp.chain_u(us[1:], seg.status, self.ref) if cp else None
            if chain is None:
                chain = seg.ik_chain_compiled([seg.pose_u(float(us[j])) for j in range(1, nk + 1)], self.ref)
        if chain is None:
            return None
        Q[1:] = chain
        jumps = np.abs(np.diff(Q, axis=0))
        for j in np.flatnonzero(jumps.max(axis=1) > SINGULAR_JUMP_DEG)[:1].tolist():
            raise _singular(jumps[j])
        self.ref = Q[nk].copy()
        return jumps

    def _walk_piece(self, k: int, nk: int, budget: float) -> None:
        """Piece k walked here: its samples, their derivatives in u, and the limits they set."""
        seg = self.seg
        us, Q = self._samples_of(k, nk)
        h = float(us[1] - us[0])
        if h <= 0:
            self.junction_q.append(Q[0].copy())
            self.sec_d.append((np.zeros(len(seg.q0)), np.zeros(len(seg.q0)), 1.0))
            return
        d1 = gradient_rows(Q, h)
        d2 = gradient_rows(d1, h)
        qd = np.max(np.abs(d1), axis=0)
        qdd = np.max(np.abs(d2), axis=0)
        self.junction_q.append(Q[0].copy())
        if k == 0:
            seg.qd_start = d1[0].copy()
        if k == len(seg.pieces) - 1:
            seg.qd_end = d1[-1].copy()
        self._axis_limits(k, Q, h, qd, qdd, budget)
        self.sec_d.append((qd, qdd, budget))

    def _axis_limits(self, k: int, Q: np.ndarray, h: float, qd: np.ndarray, qdd: np.ndarray,
                     budget: float) -> None:
        """Lower piece k's speed and acceleration (in u) so that the axes keep their maxima
        (and, in T1, the flange 250 mm/s)."""
        model = self.seg.model
        v_ax, a_ax = model.v_max, model.a_max
        # v/x where x > 1e-9, else inf (x: 1.0 where not taken, so that nothing divides by 0)
        moves, turns = qd > 1e-9, qdd > 1e-9
        qd_safe, qdd_safe = np.where(moves, qd, 1.0), np.where(turns, qdd, 1.0)
        V = float(np.where(moves, v_ax / qd_safe, np.inf).min())
        if not self.plain:
            V = min(V, float(np.where(turns, np.sqrt(0.5 * budget * a_ax / qdd_safe), np.inf).min()))
        if model.mode == "T1":
            F = model.kin.forward_many(Q)
            dpf = float(np.max(np.linalg.norm(np.diff(F[:, :3, 3], axis=0), axis=1))) / h
            L = self.seg.pieces[k].length
            lk = L * self.seg.W / self.weights[k] if self.weights[k] > 0 else 0.0
            if dpf > lk * (1.0 + 1e-6):  # the flange moves faster than the TCP (tool, rotation)
                V = min(V, T1_SPEED_MM_S / (dpf * T1_MARGIN))
        self.vmax[k] = min(self.vmax[k], V)
        if not self.plain:
            Aax = float(np.where(moves, (budget * a_ax - qdd * self.vmax[k] ** 2) / qd_safe, np.inf).min())
            self.amax[k] = min(self.amax[k], max(Aax, 1e-9))

    def rebudget(self, k: int) -> None:
        """Half the axis acceleration for piece k (a junction turns the axis velocities)."""
        a_ax = self.seg.model.a_max
        qd, qdd, b = self.sec_d[k]
        if b <= 0.5:
            return
        self.sec_d[k] = (qd, qdd, 0.5)
        with np.errstate(divide="ignore", invalid="ignore"):
            self.vmax[k] = min(self.vmax[k], float(np.min(np.where(qdd > 1e-9, np.sqrt(0.25 * a_ax / qdd), np.inf))))
            Aax = float(np.min(np.where(qd > 1e-9, (0.5 * a_ax - qdd * self.vmax[k] ** 2) / qd, np.inf)))
        self.amax[k] = min(self.amax[k], max(Aax, 1e-9))

    def junctions(self, vnode: list[float], dt: float) -> None:
        """Axis-velocity jumps where pieces meet (one-sided derivatives): a jump that matters at
        full speed (> 5 % of a_max within one cycle; e.g. the orientation rate changing between
        pieces) is a corner for the axes."""
        seg = self.seg
        model = seg.model
        a_ax = model.a_max
        ub = seg.u_bounds
        for k in range(1, len(seg.pieces)):
            if vnode[k] <= 0.0:
                continue
            uk, du_ = float(ub[k]), 1e-5
            e_u = (lambda v: v) if len(seg.q0) > model.n else (lambda v: None)
            qj = seg.ik(*seg.pose_u(uk), self.junction_q[k], e_u(uk))
            qL = seg.ik(*seg.pose_u(uk - du_), qj, e_u(uk - du_))
            qR = seg.ik(*seg.pose_u(uk + du_), qj, e_u(uk + du_))
            jump = np.abs((qR - qj) - (qj - qL)) / du_
            v_full = min(self.vmax[k - 1], self.vmax[k])
            if np.any(jump * v_full > 0.05 * a_ax * dt):
                self.rebudget(k - 1)
                self.rebudget(k)
                with np.errstate(divide="ignore"):
                    vj = float(np.min(np.where(jump > 1e-9, 0.5 * a_ax * dt / jump, np.inf)))
                vnode[k] = min(vnode[k], vj)


def cart_time_law(seg: CartSegment, thetas: list[float], weights: list[float], speeds: list[tuple],
                  end_T: np.ndarray) -> None:
    """Plan `seg`'s time law (its ``profile``, ``v_prog``, the axes' peaks, ``q1`` and ``status``)
    from its pieces' turns (deg), u weights and speeds (:func:`cp_speeds`); `end_T` the last
    target (4x4 in $BASE, for #JOINT's end axes). Raises RobotError (a singularity)."""
    model = seg.model
    req, q0 = seg.req, seg.q0
    dt = model.machine.ipo_cycle_s
    vmax, amax, vprog = _piece_limits(seg, thetas, weights, speeds)
    vnode, kink = _corner_speeds(seg, weights, speeds, dt)
    status = seg.status             # model.status_turn(q0)[0], made by the segment
    # on a robot whose axis accelerations are those its PTPs were identified with (robot/
    # identified.py), not limits of its axes, a LIN or CIRC keeps $ACC.CP whatever accelerations
    # its axes need (the real KR 3 R540 plans the CIRCs of its recordings at 2.3 m/s², although A2
    # then needs 1.06 x the acceleration it has in a PTP; issue 60); its axis speeds still slow it.
    # Elsewhere, and for a spline, the path is slowed for both
    plain = req.kind in ("LIN", "CIRC") and bool(getattr(model.machine, "ptp_ramp_deg", ()))
    if seg.joint_ori:
        # $ORI_TYPE #JOINT: the wrist axes move linearly from the start's to the target's, the
        # target's as its S and T give them (the real KR C4 goes from S 6 to S 2 on such a LIN, A5
        # through 0: Linear_updated line 38, issue 60); the TCP stays on the path
        t = req.target
        s_t = int(t["S"]) if "S" in t and not req.relative else status
        t_t = int(t["T"]) if "T" in t and not req.relative else None
        seg.q1 = model.ik(end_T, inv_pos(seg.tool_T), seg.base_T, s_t, t_t, q0)
    walk = _Walk(seg, thetas, weights, vmax, amax, kink, plain, q0.copy())
    walk.run()
    walk.junctions(vnode, dt)
    for k in range(len(seg.pieces)):
        qd, qdd, _ = walk.sec_d[k]
        seg.vel_peak = np.maximum(seg.vel_peak, qd * vmax[k])
        seg.acc_peak = np.maximum(seg.acc_peak, qdd * vmax[k] ** 2 + qd * amax[k])
    if len(seg.pieces) == 1:
        prof: Any = Trapezoid.plan(vmax[0], amax[0])
    else:
        prof = PiecewiseProfile([float(x) for x in seg.u_bounds], vmax, amax, vnode)
    seg.profile = prof
    seg.v_prog = vprog[-1]
    if not seg.joint_ori:
        seg.q1 = walk.ref
    seg.status = status


__all__ = ["cart_time_law", "cp_speeds", "SINGULAR_JUMP_DEG", "CP_SAMPLE_STEP_DEG", "CP_MAX_SAMPLES"]
