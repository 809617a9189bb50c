"""Motion planning: a :class:`~robot.motion.MotionRequest` becomes a :class:`Segment` that
the main run samples every IPO cycle (reference §6.3-§6.7, robot-model.md §7-§8).

A segment is a geometric path plus one normalised time law (:mod:`robot.profiles`: a
trapezoid, or a piecewise profile for a SPLINE block; CP paths are slowed so the axes keep
machine data, issue 15):

* :class:`JointSegment` (PTP, SPTP): ``q(u) = q0 + u·(q1 - q0)``, synchronised axes.

External axes E1..En (robot/external.py) are the axis vector's entries after A1..An: a PTP
moves them synchronised with the robot axes; on a CP path they move linearly in the path
parameter, ``E(u) = E0 + u·(E1 - E0)``, start and stop with the robot, and the path is slowed
for their speed and acceleration like for the robot's axes. A track (#ERSYS) moves
``$ROBROOT`` with E, so the arm's axes on a CP path follow it; a ``$BASE`` linked to a BASE
kinematic (``MotionParams.base_kin``, KSS ``EK``) turns with it.
* :class:`CartSegment` (LIN, CIRC, SLIN, SCIRC, SPLINE): the TCP moves in ``$BASE`` along
  a chain of path pieces (line, circular arc, Catmull-Rom curve for SPL points); the
  orientation follows ``$ORI_TYPE``/``$CIRC_TYPE``; axis values come from the inverse
  kinematics each cycle, keeping the start status S and the turn nearest to the last
  setpoint (reference §6.5: CP motions ignore the target's S and T). Where each solution
  is the next one's reference (the planning walk of a path, the main run's coming cycles at
  full path speed: :meth:`CartSegment.axes_run`) the chain is solved at once in numpy
  (:meth:`RobotModel.ik_chain`), with the same results bit for bit; a kept row is used only
  for the same time law, time and reference, so a BRAKE, a blend, an interrupt's motion or an
  advance-run event between cycles gets the per-cycle setpoint.

Planning happens in the advance run (:func:`plan`), so an unreachable target or a soft-limit
violation of a target raises :class:`~robot.errors.RobotError` at the motion statement.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from itertools import accumulate
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import RobotError, SoftLimitError, WorkspaceError
from .frames import frame_to_matrix, inv_pos, matrix_to_frame, rotation_angle_deg, rotvec_of
from . import kinematics
from .axismap import AxisMap
from .blas import numpy_cblas
from .external import ExternalAxes
from .dynamics import ArmDynamics
from .external_tcp import external_tcp
from .kinematics import Kinematics
from .kinematics.compiled import COMPILED_AXES
from .motion import AXIS_KEYS, CART_KEYS, MotionParams, MotionRequest, Trigger
from .limits import (DEFAULT_MODE, T1_SPEED_MM_S, cp_path_speed, motion_limits, ptp_axis_accelerations,
                     ptp_axis_speeds, ptp_ramp_accelerations)
from .profiles import FrictionProfile, PiecewiseProfile, Trapezoid


#: An axis jump (deg) between neighbouring planning samples of a CP path that means the
#: path crosses a singularity (the IK had to flip the wrist to keep the status).
SINGULAR_JUMP_DEG = 90.0
#: Tries of a spline piece's end tangents: halved up to 4 times, then zero (a straight piece).
CUSP_ATTEMPTS = 6
#: Factor on the axis maximum speed above which an interpolated CP setpoint is rejected.
CP_SPEED_LIMIT_FACTOR = 1.5
#: Largest axis step (deg) between the planning samples of a CP path (axis speed and
#: acceleration are estimated from them).
CP_SAMPLE_STEP_DEG = 1.0
#: Most planning samples of one piece of a CP path (near a wrist singularity A4/A6 turn fast
#: on a short piece; 256 left steps of several degrees there, and the sampled speed 3 % under
#: the peak between samples: tests/robot/test_limits_property.py, KR 120 R2700 extra HA).
CP_MAX_SAMPLES = 1024
#: Safety factor on the sampled TCP/flange speed of a path in T1 (sampling between points).
T1_MARGIN = 1.02
#: Passes of the batched IK chain (:meth:`RobotModel.ik_chain`) before it gives up and the
#: chain is solved pose by pose (each pass fixes at least one more row).
IK_CHAIN_PASSES = 6
#: IPO cycles of a CP segment the main run solves at once (:meth:`CartSegment.axes_run`).
AHEAD_CYCLES = 128
#: Shortest chain solved at once: below it numpy's fixed cost per pass (two passes at least)
#: is more than the per-pose solves (measured 2026-11-24: even at 40 poses, about 1.1x slower).
MIN_CHAIN = 64


class RobotModel:
    """Adapter between the planner and the kinematics module (mm, deg, 4x4 frames).

    ``tcp(q, tool_T, base_T)`` -> TCP 4x4 in ``$BASE``; ``ik(T, tool_T, base_T, status, turn,
    ref)`` -> axes (n,) raising WorkspaceError/SoftLimitError; ``status_turn(q)``.

    Axis vectors are A1..An, E1..En: n = :attr:`n` the robot's axis count (``machine.n_axes``),
    then the external axes. :meth:`from_krl` and :meth:`to_krl` convert from and to KRL's
    E6AXIS order (A1..A6, E1..E6: a robot with fewer axes has no A(n+1)..A6).
    """

    def __init__(self, machine: Any, kin: Kinematics | None = None, mode: str = DEFAULT_MODE) -> None:
        self.machine = machine
        self.mode = mode
        self.kin = kin if kin is not None else Kinematics(machine)
        #: the robot's axis count (A1..An); the external axes follow it in axis vectors
        self.n = self.kin.n_axes
        self.robroot_T = frame_to_matrix(*machine.robroot_frame)
        self._robroot_is_null = bool(np.allclose(self.robroot_T, np.eye(4)))
        self._robroot_inv_T = inv_pos(self.robroot_T)
        #: external axes (robot/external.py), None without; axis vectors are A1..An, E1..En
        self.n_ext = len(getattr(machine, "external_axes", ()))
        #: where each axis sits in KRL's E6AXIS (robot/axismap.py): the one mapping
        self.axes = AxisMap.of(machine)
        self.ext = None
        self._ersys = False
        if self.n_ext:
            self.ext = ExternalAxes(machine)
            self._ersys = self.ext.robroot_kin is not None
            self.v_max = np.array(machine.all_max_speed, dtype=float)
            self.a_max = np.array(machine.all_max_acc, dtype=float)
            ext_apo = [90.0] * self.n_ext
            self.apo_dis_ptp = np.array(list(machine.apo_dis_ptp_deg)[:self.n] + ext_apo, dtype=float)
            self._e_lo = np.array([e.limit[0] for e in machine.external_axes], dtype=float)
            self._e_hi = np.array([e.limit[1] for e in machine.external_axes], dtype=float)
        else:
            self.v_max = np.array(machine.max_speed_deg_s, dtype=float)
            self.a_max = np.array(machine.max_acc_deg_s2, dtype=float)
            self.apo_dis_ptp = np.array(machine.apo_dis_ptp_deg[:self.n], dtype=float)

    def from_krl(self, values: Any) -> np.ndarray:
        """An axis vector of this model from KRL's order (robot/axismap.py ``from_krl``)."""
        return self.axes.from_krl(values)

    def to_krl(self, q: np.ndarray) -> np.ndarray:
        """The axis vector `q` in KRL's order (robot/axismap.py ``to_krl``)."""
        return self.axes.to_krl(q)

    def linked(self, system: str, root: Any = None) -> "RobotModel":
        """This model with ``$BASE`` on the BASE kinematic `system` (robot/external.py):
        ``$BASE_C(E) = root : ETn(E) : $BASE`` in :meth:`tcp` and :meth:`ik` (`root`: X..C of
        the kinematic's root, ``EK``'s; None: the machine data's)."""
        if self.ext is None or system not in self.ext.base_kins:
            raise RobotError(f"$BASE linked to {system}: no such external kinematic in $EX_KIN")
        return _LinkedBase(self, system, root)

    def check_limits(self, q: np.ndarray) -> None:
        """``$SOFTN_END``/``$SOFTP_END`` of A1..An and E1..En (SoftLimitError, reference §8.2)."""
        self.kin.check_soft_limits(q)
        if self.n_ext:
            e = np.asarray(q, dtype=float)[self.n:self.n + self.n_ext]
            for i in range(self.n_ext):
                if e[i] < self._e_lo[i] - 1e-9 or e[i] > self._e_hi[i] + 1e-9:
                    pos = bool(e[i] > self._e_hi[i])
                    raise SoftLimitError(6 + i + 1, float(e[i]), positive=pos,
                                         message=f"software limit switch {'+' if pos else '-'}E{i + 1}")

    def tcp(self, q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """TCP in $BASE: INV_POS($BASE) : $ROBROOT : FLANGE(q) : $TOOL (``base_inv_T`` is
        INV_POS($BASE), precomputed; ``$ROBROOT_C(E)`` on a track)."""
        F = self.kin.forward(q)
        if self._ersys:
            F = self.ext.robroot(q[self.n:]) @ F          # type: ignore[union-attr]
        elif not self._robroot_is_null:
            F = self.robroot_T @ F
        return base_inv_T @ F @ tool_T

    def ik(self, T_base: np.ndarray, tool_inv_T: np.ndarray | None, base_T: np.ndarray | None,
           status: int | None, turn: int | None, ref: np.ndarray) -> np.ndarray:
        """Axes for a TCP pose in $BASE (``tool_inv_T`` = INV_POS($TOOL); None for a
        ``$TOOL``/``$BASE`` that is the null frame: the product with the identity is skipped)."""
        F = T_base if base_T is None else base_T @ T_base
        if tool_inv_T is not None:
            F = F @ tool_inv_T
        if self.n_ext:
            # the external axes are given (ref's E part): the arm solves in $ROBROOT_C(E)
            e = np.asarray(ref, dtype=float)[self.n:self.n + self.n_ext]
            if self._ersys:
                F = inv_pos(self.ext.robroot(e)) @ F      # type: ignore[union-attr]
            elif not self._robroot_is_null:
                F = self._robroot_inv_T @ F
            q = self.kin.inverse(F, status=status, turn=turn, reference_deg=ref[:self.n])
            return np.concatenate([q, e])
        if not self._robroot_is_null:
            F = self._robroot_inv_T @ F
        return self.kin.inverse(F, status=status, turn=turn, reference_deg=ref)

    def status_turn(self, q: np.ndarray) -> tuple[int, int]:
        return self.kin.status_turn(q)

    @property
    def batch_ik(self) -> bool:
        """True when :meth:`ik_chain` solves in numpy (a family that solves chains, the OPW
        family: ``solves_chains``; no external axes and no linked $BASE, and no compiled inverse:
        robot/simcore.pyx solves one pose faster than numpy's passes over a chain, measured);
        otherwise it returns None and callers solve cycle by cycle."""
        return (type(self) is RobotModel and not self.n_ext and self.kin.impl.solves_chains
                and not self.kin.compiled_inverse)

    def ik_chain(self, poses: list[tuple[np.ndarray, np.ndarray]], tool_inv_T: np.ndarray | None,
                 base_T: np.ndarray | None, status: int | None, ref: np.ndarray) -> np.ndarray | None:
        """:meth:`ik` along a chain of TCP poses ``(p (3,), R (3, 3))`` in $BASE where each
        solution is the next one's reference (the first one's is `ref`): the (N, n) axes,
        bit for bit those of n calls of :meth:`ik` in turn, or None when the chain must be
        solved call by call (not :attr:`batch_ik`, an error on some pose, no fixed point).

        The rows are solved at once by :meth:`Kinematics.inverse_chain` (passes of
        :meth:`Kinematics.inverse_many` until a fixed point). Issue 39, "Simulator"."""
        N = len(poses)
        if N < MIN_CHAIN or not self.batch_ik:
            return None
        F = np.empty((N, 4, 4))
        for i, (p, R) in enumerate(poses):
            T = np.empty((4, 4))
            T[:3, :3] = R
            T[:3, 3] = p
            T[3] = _BOTTOM_ROW
            if base_T is not None:
                T = base_T @ T
            if tool_inv_T is not None:
                T = T @ tool_inv_T
            if not self._robroot_is_null:
                T = self._robroot_inv_T @ T
            F[i] = T
        return self.kin.inverse_chain(F, status, ref, IK_CHAIN_PASSES)

    def tcp_pos_many(self, Q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """TCP positions (N, 3) in $BASE for axis rows Q (N, n + external axes)."""
        F = self.kin.forward_many(Q)
        if self._ersys:
            F = np.array([self.ext.robroot(q[self.n:]) for q in Q]) @ F      # type: ignore[union-attr]
        elif not self._robroot_is_null:
            F = self.robroot_T @ F
        T = base_inv_T @ F @ tool_T
        return T[:, :3, 3]

    def solve_position(self, p: np.ndarray, wrist: np.ndarray, ref: np.ndarray,
                       tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """Axes whose TCP is at ``p`` (mm, in $BASE) with the wrist axes A4..A6 fixed to
        ``wrist`` (deg): Newton iteration on A1..A3 from ``ref`` (``$ORI_TYPE #JOINT``).
        Raises WorkspaceError when it does not converge, SoftLimitError outside the limits."""
        q = np.array(ref, dtype=float)
        q[3:self.n] = wrist
        h = 1e-5
        for _ in range(20):
            Q = np.repeat(q[None, :], 4, axis=0)
            Q[1, 0] += h
            Q[2, 1] += h
            Q[3, 2] += h
            P = self.tcp_pos_many(Q, tool_T, base_inv_T)
            r = P[0] - p
            if float(np.linalg.norm(r)) < 1e-7:
                self.check_limits(q)
                return q
            J = (P[1:] - P[0]).T / h
            try:
                dx = np.linalg.solve(J, -r)
            except np.linalg.LinAlgError:
                break
            q[:3] += np.clip(dx, -20.0, 20.0)
        raise WorkspaceError("workspace error: target not reachable ($ORI_TYPE #JOINT)")


class _LinkedBase(RobotModel):
    """A :class:`RobotModel` whose ``$BASE`` turns with a BASE kinematic (a turntable)."""

    def __init__(self, model: RobotModel, system: str, root: Any = None) -> None:   # noqa: D107 - a view of `model`
        self.__dict__.update(model.__dict__)
        self._kin_et = model.ext.base_kins[system]               # type: ignore[union-attr]
        self._root = root

    def _et(self, e: np.ndarray) -> np.ndarray:
        return self.ext.chain(self._kin_et, e, self._root)       # type: ignore[union-attr]

    def tcp(self, q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        return RobotModel.tcp(self, q, tool_T, base_inv_T @ inv_pos(self._et(q[self.n:])))

    def ik(self, T_base, tool_inv_T, base_T, status, turn, ref):
        E = self._et(np.asarray(ref, dtype=float)[self.n:])
        return RobotModel.ik(self, T_base, tool_inv_T, E if base_T is None else E @ base_T, status, turn, ref)

    def tcp_pos_many(self, Q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        return np.array([self.tcp(q, tool_T, base_inv_T)[:3, 3] for q in Q])


def rotvec_matrix(v: np.ndarray) -> np.ndarray:
    """Rotation matrix of a rotation vector (rad), Rodrigues' formula (the same matrix as
    scipy's ``Rotation.from_rotvec(v).as_matrix()`` to rounding, without its overhead)."""
    x, y, z = float(v[0]), float(v[1]), float(v[2])
    th = math.sqrt(x * x + y * y + z * z)
    if th < 1e-12:
        return np.eye(3)
    s, c = math.sin(th), math.cos(th)
    x, y, z = x / th, y / th, z / th
    C = 1.0 - c
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


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
        self.length = norm3(d)
        self.dir = d / self.length if self.length > 0 else np.zeros(3)

    def pos(self, s: float) -> np.ndarray:
        return self.p0 + self.dir * s

    def tangent(self, s: float) -> np.ndarray:
        """Unit tangent at arc length s."""
        return self.dir

    min_radius = math.inf


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

    def tangent(self, s: float) -> np.ndarray:
        ph = self.phi(s)
        sg = 1.0 if self.angle >= 0 else -1.0
        return sg * (-math.sin(ph) * self.e1 + math.cos(ph) * self.e2)

    @property
    def min_radius(self) -> float:
        return self.r


#: 5-point Gauss-Legendre nodes on [0, 1] and their weights (exact for polynomials of
#: degree 9; the arc length integrand |P'(t)| of a cubic is smooth between table points).
_GL_X = tuple(0.5 * (1.0 + x) for x in np.polynomial.legendre.leggauss(5)[0])
_GL_W = tuple(0.5 * w for w in np.polynomial.legendre.leggauss(5)[1])
_GL = tuple(zip(_GL_X, _GL_W))


class CatmullRomPiece(_Piece):
    """Uniform Catmull-Rom curve from P1 to P2 (neighbours P0, P3), re-parametrised by arc
    length (SPL points of a SPLINE block, reference §6.2 [U]).

    The arc length is exact to rounding: a 256-interval table of ``s(t)`` integrated with
    Gauss-Legendre, and :meth:`t_of_s` solves ``s(t) = s`` by a safeguarded Newton step on the
    same integral. (A linear interpolation of ``t`` in that table ran up to 14 % fast or slow
    where ``|P'(t)|`` changes fast — near a zero end tangent — and a SPLINE block on the KR 210
    R2700-2 reached 103.5 % of ``$VEL.CP``: issue 22.)"""

    N = 256

    def __init__(self, P0: np.ndarray, P1: np.ndarray, P2: np.ndarray, P3: np.ndarray,
                 m1: np.ndarray | None = None, m2: np.ndarray | None = None) -> None:
        """Hermite form: end tangents ``m1 = (P2-P0)/2``, ``m2 = (P3-P1)/2`` (Catmull-Rom)
        unless given (a SPL point next to an SLIN/SCIRC takes that piece's direction, so
        the junction has no kink)."""
        P0, P1, P2, P3 = (np.asarray(v, dtype=float) for v in (P0, P1, P2, P3))
        m1 = 0.5 * (P2 - P0) if m1 is None else np.asarray(m1, dtype=float)
        m2 = 0.5 * (P3 - P1) if m2 is None else np.asarray(m2, dtype=float)
        chord = P2 - P1
        if float(np.linalg.norm(chord)) <= 1e-9:
            m1 = m2 = np.zeros(3)
        ts = np.linspace(0.0, 1.0, self.N + 1)
        # no cusp or loop: the curve must keep moving towards P2 (tangent · chord > 0); else
        # the end tangents are shortened (halved up to 4 times, then zero: a straight piece
        # whose junctions are corners)
        for attempt in range(CUSP_ATTEMPTS):
            c1 = m1
            c2 = 3.0 * chord - 2.0 * m1 - m2
            c3 = -2.0 * chord + m1 + m2
            d = c1 + ts[1:-1, None] * (2.0 * c2 + 3.0 * ts[1:-1, None] * c3)
            if float(np.linalg.norm(chord)) <= 1e-9 or float(np.min(d @ chord)) > 0.0:
                break
            if attempt >= 4:
                m1 = m2 = np.zeros(3)
            else:
                m1, m2 = 0.5 * m1, 0.5 * m2
        self.c0 = P1
        self.c1 = m1
        self.c2 = 3.0 * chord - 2.0 * m1 - m2
        self.c3 = -2.0 * chord + m1 + m2
        # exact arc length per table interval (Gauss-Legendre on |P'(t)|)
        h = 1.0 / self.N
        tq = ts[:-1, None] + h * np.array(_GL_X)[None, :]
        dq = self.c1 + tq[..., None] * (2.0 * self.c2 + 3.0 * tq[..., None] * self.c3)
        seg = h * (np.linalg.norm(dq, axis=2) @ np.array(_GL_W))
        self._s = np.concatenate([[0.0], np.cumsum(seg)])
        self._t = ts
        self.length = float(self._s[-1])
        self._sl = self._s.tolist()
        self._cf = tuple(float(x) for x in (*self.c1, *self.c2, *self.c3))
        d1 = self.c1 + ts[:, None] * (2.0 * self.c2 + 3.0 * ts[:, None] * self.c3)
        d2 = 2.0 * self.c2 + 6.0 * ts[:, None] * self.c3
        n1 = np.linalg.norm(d1, axis=1)
        cr = np.linalg.norm(np.cross(d1, d2), axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            kappa = np.where(n1 > 1e-9, cr / np.maximum(n1, 1e-12) ** 3, 0.0)
        km = float(np.max(kappa)) if len(kappa) else 0.0
        self.min_radius = 1.0 / km if km > 1e-12 else math.inf

    def _speed(self, t: float) -> float:
        """|P'(t)| (mm per unit t)."""
        a1, a2, a3, b1, b2, b3, c1, c2, c3 = self._cf
        x = a1 + t * (2.0 * b1 + 3.0 * t * c1)
        y = a2 + t * (2.0 * b2 + 3.0 * t * c2)
        z = a3 + t * (2.0 * b3 + 3.0 * t * c3)
        return math.sqrt(x * x + y * y + z * z)

    def _arc(self, t0: float, t1: float) -> float:
        """Arc length (mm) from t0 to t1 (Gauss-Legendre, the table's rule)."""
        a1, a2, a3, b1, b2, b3, c1, c2, c3 = self._cf
        h = t1 - t0
        acc = 0.0
        for x, w in _GL:
            t = t0 + h * x
            dx = a1 + t * (2.0 * b1 + 3.0 * t * c1)
            dy = a2 + t * (2.0 * b2 + 3.0 * t * c2)
            dz = a3 + t * (2.0 * b3 + 3.0 * t * c3)
            acc += w * math.sqrt(dx * dx + dy * dy + dz * dz)
        return h * acc

    def t_of_s(self, s: float) -> float:
        """Curve parameter t in [0, 1] at arc length ``s`` (mm): the table interval, then a
        Newton step on the exact integral, kept inside the interval (bisection fallback)."""
        L = self.length
        if L <= 0.0 or s <= 0.0:
            return 0.0
        if s >= L:
            return 1.0
        sl = self._sl
        k = min(bisect_right(sl, s) - 1, self.N - 1)
        h = 1.0 / self.N
        tk = k * h
        lo, hi = tk, tk + h
        s0 = sl[k]
        ds = sl[k + 1] - s0
        t = lo + h * (s - s0) / ds if ds > 0 else lo
        tol = 1e-12 * max(1.0, L)
        for _ in range(30):
            f = s0 + self._arc(tk, t) - s
            if abs(f) <= tol:
                break
            if f > 0.0:
                hi = t
            else:
                lo = t
            d = self._speed(t)
            tn = t - f / d if d > 0.0 else -1.0
            t = tn if lo < tn < hi else 0.5 * (lo + hi)
        return t

    def tangent(self, s: float) -> np.ndarray:
        t = self.t_of_s(s)
        d = self.c1 + t * (2.0 * self.c2 + 3.0 * t * self.c3)
        n = float(np.linalg.norm(d))
        if n > 1e-9:
            return d / n
        c = 3.0 * (self.c0 + self.c1 + self.c2 + self.c3 - self.c0)  # zero end tangent: the
        nc = float(np.linalg.norm(c))                                  # curve leaves along the chord
        return c / nc if nc > 1e-12 else np.zeros(3)

    def _at(self, t: float) -> np.ndarray:
        return self.c0 + t * (self.c1 + t * (self.c2 + t * self.c3))

    def pos(self, s: float) -> np.ndarray:
        if self.length <= 0:
            return self.c0.copy()
        return self._at(self.t_of_s(s))


# ------------------------------------------------------------------------- segments
_BOTTOM_ROW = np.array([0.0, 0.0, 0.0, 1.0])


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
        self._c_ik: Any = None      # CartSegment.ik's compiled inverse (robot/simcore.pyx), False: none
        self._c_path: Any = None    # CartSegment's compiled poses (robot/simcore.pyx CartPath), False: none
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
        return norm3(self.pose_u(u)[0] - p_end)


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
                pr = cp.pose_u(u)      # the same pose, compiled (robot/simcore.pyx CartPath)
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
            # compiled inverse solves it as it stands (robot/simcore.pyx; the same axes as
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
                # $BASE and $TOOL multiplied as below, numpy's BLAS in C (robot/simcore.pyx
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
        """robot/simcore.pyx's ``CartPath`` of this segment's lines and arcs (kept; with the
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
        in one call of the compiled inverse (robot/simcore.pyx ``inverse_chain_rp``, the rows of
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
            # the same distance in C (robot/simcore.pyx CartPath.dist_to: numpy's dot product)
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


def _cart_path(sc: Any, seg: "CartSegment") -> Any:
    """robot/simcore.pyx's ``CartPath`` of `seg`'s pieces (see ``CartSegment._compiled_path``):
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
    return cp


#: [address] of numpy's cblas_dgemm once CartPath.use_frames was seen to multiply as numpy does
#: (robot/blas.py), [0] when not: :func:`_frames_gemm`
_FRAMES_GEMM: list[int] = []


def _frames_gemm(sc: Any) -> int:
    """The ``cblas_dgemm`` address for robot/simcore.pyx ``CartPath.use_frames`` (0: none, or its
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


def plan(req: MotionRequest, q_start: np.ndarray, model: RobotModel, *,
         first: bool = False) -> Segment:
    """Plan one motion from the axes ``q_start`` (the previous programmed end point).

    Raises:
        RobotError: incomplete first motion (BCO), PATH trigger on PTP, a ``$IPO_MODE``
            other than #BASE and #TCP (robot/external_tcp.py); WorkspaceError / SoftLimitError (subclasses) when the
            target (or a SPLINE/CIRC point) is unreachable or outside the soft limits.
    """
    p: MotionParams = req.params
    if first:
        _check_complete(req, model.axes.robot_keys)
    if p.ipo_mode == "TCP":
        model = external_tcp(model)      # the fixed tool in the workpiece frame
    elif p.ipo_mode != "BASE":
        raise RobotError(f"$IPO_MODE=#{p.ipo_mode} is not supported by the simulator")
    q0 = np.asarray(q_start, dtype=float).copy()
    if getattr(p, "base_kin", None) and model.n_ext:
        model = model.linked(p.base_kin, getattr(p, "base_root", None))   # $BASE on a BASE kinematic (robot/external.py)
    tool_T = _matrix_of(p.tool)
    base_T = _matrix_of(p.base)
    base_inv = _inverse_of(base_T)[0]
    start_T = model.tcp(q0, tool_T, base_inv)
    if req.kind in ("PTP", "SPTP"):
        seg = _plan_joint(req, q0, start_T, tool_T, base_T, model)
    else:
        seg = (_planned_line(req, q0, start_T, tool_T, base_T, model) if req.kind == "LIN" else None) \
            or _plan_cart(req, q0, start_T, tool_T, base_T, model)
    _plan_triggers(seg)
    seg.limits = motion_limits(req, model.machine, model.mode)
    return seg


def _plan_joint(req: MotionRequest, q0: np.ndarray, start_T: np.ndarray, tool_T: np.ndarray,
                base_T: np.ndarray, model: RobotModel) -> JointSegment:
    p = req.params
    t = req.target
    n = model.n
    if req.is_axis_target:
        # the robot's axes A1..An (an A(n+1)..A6 of the target has no axis: ignored), then E
        keys = model.axes.model_keys[:len(q0)]
        if req.relative:
            q1 = q0 + np.array([float(t.get(k, 0.0)) for k in keys])
        else:
            q1 = np.array([float(t[k]) if k in t else q0[i] for i, k in enumerate(keys)])
        model.check_limits(q1)
    else:
        T1 = _cart_target(t, start_T, req.relative, req.rel_frame)
        s = int(t["S"]) if "S" in t and not req.relative else None
        tt = int(t["T"]) if "T" in t and not req.relative else None
        q1 = model.ik(T1, inv_pos(tool_T), base_T, s, tt, _ext_target(q0, t, req.relative, model.axes))
        if len(q1) > n:
            model.check_limits(q1)
    dq = np.abs(q1 - q0)
    moving = dq > 1e-9
    if not moving.any():
        prof = Trapezoid.plan(math.inf, math.inf)
        v_prog = math.inf
        V = 0.0
    else:
        V, alpha, fric, beta = _ptp_axis_limits(q1 - q0, p, model.machine, model.mode, q0)
        if model.mode == "T1":
            # TCP and flange <= 250 mm/s (reference §6.7 [C]): the largest |dp/du| on the path
            us = np.linspace(0.0, 1.0, 33)
            Q = q0[None, :] + us[:, None] * (q1 - q0)[None, :]
            F = model.kin.forward_many(Q)
            if not model._robroot_is_null:
                F = model.robroot_T @ F
            tcp = (inv_pos(base_T) @ F @ tool_T)[:, :3, 3]
            dp = max(float(np.max(np.linalg.norm(np.diff(tcp, axis=0), axis=1))),
                     float(np.max(np.linalg.norm(np.diff(F[:, :3, 3], axis=0), axis=1))))
            dp *= (len(us) - 1) * T1_MARGIN
            if dp > 0:
                V = min(V, T1_SPEED_MM_S / dp)
        prof = _ptp_profile(V, alpha, fric, p, beta)
        v_prog = V
    seg = JointSegment(req, q0, q1, prof, v_prog, tool_T, base_T, model)
    seg.vel_peak = dq * prof.v
    seg.acc_peak = dq * getattr(prof, "a_peak", prof.a)
    return seg


def ptp_limits(dq: np.ndarray, p: MotionParams, machine: Any, mode: str = DEFAULT_MODE,
               q0: np.ndarray | None = None) -> tuple[float, float]:
    """(V 1/s, A 1/s²) of a synchronised PTP moving the axes by `dq` (deg; A1..An, E1..En) from
    `q0`: the normalised speed and acceleration of the leading axis, ``min_i v_i/|dq_i|`` and
    ``min_i a_i/|dq_i|`` over the moving axes, with :func:`robot.limits.ptp_axis_speeds` and
    :func:`robot.limits.ptp_axis_accelerations` (reference §6.6; issue 60); for a robot with an
    identified dynamic model (``machine.dynamics``) and `q0` given, ``A`` is what the drives' torques
    allow at `q0` with the load of `p` (robot/dynamics.py, the axes moving together; issue 73). :func:`ptp_profile` is the
    motion's time law. Raises RobotError for a non-positive limit."""
    V, alpha, _, _ = _ptp_axis_limits(dq, p, machine, mode, q0)
    return V, float(np.min(alpha))


def _ptp_axis_limits(dq: np.ndarray, p: MotionParams, machine: Any, mode: str,
                     q0: np.ndarray | None) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """(V, alpha, c, beta) of :func:`ptp_limits` per axis: ``alpha`` (1/s², (n,)) the normalised
    acceleration each axis allows starting from rest (inf for an axis that neither moves nor, by
    the arm's dynamics, needs torque), ``c`` (1/s, (n,)) what it loses per unit of normalised speed
    by its friction at 100 % override (machine data ``ptp_friction``; :func:`ptp_profile`),
    ``beta`` (1/s², (n,)) the braking's to rest (``alpha`` itself for a robot without a dynamic
    model; robot/dynamics.py ``ArmDynamics.ptp_bounds``)."""
    dq = np.asarray(dq, dtype=float)
    ad = np.abs(dq)
    moving = ad > 1e-9
    v_axis = ptp_axis_speeds(p, machine, mode)       # $RED_T1 in T1 (issue 15)
    a_axis = ptp_axis_accelerations(p, machine)      # as KSS 8.5 (issue 60)
    if np.any(v_axis[moving] <= 0) or np.any(a_axis[moving] <= 0):
        raise RobotError("PTP: $VEL_AXIS, $ACC_AXIS and $OV_PRO must be positive")
    V = float(np.min(v_axis[moving] / ad[moving]))
    safe = np.where(moving, ad, 1.0)
    alpha = np.where(moving, a_axis / safe, np.inf)
    fr = np.zeros(len(dq))
    got = tuple(getattr(machine, "ptp_friction", ()) or ())[:len(dq)]
    fr[:len(got)] = got
    c = np.where(moving, fr, 0.0)
    dyn = arm_dynamics(machine)
    if dyn is None or q0 is None or len(dq) != dyn.n:
        return V, alpha, c, alpha
    # the robot's dynamic model decides (robot/dynamics.py: the drives' torques at the start and
    # at the end, with the load the program set); the ramp bound at a reduced $VEL_AXIS stays, and
    # an axis whose torque limit was measured keeps its identified acceleration as a cap. An axis'
    # friction per unit of normalised speed scales as the dynamics scale its acceleration
    factor = np.asarray(list(p.acc_axis)[:dyn.n], dtype=float) / 100.0 * (p.ov_pro / 100.0) ** 2
    ramp = np.where(moving, ptp_ramp_accelerations(p, machine) / safe, np.inf)
    dyn.set_load(getattr(p, "load", None), getattr(p, "load_a3", None))
    a_acc, a_dec = dyn.ptp_bounds(q0, q0 + dq, factor)
    a_max = np.asarray(getattr(machine, "all_max_acc", machine.max_acc_deg_s2), dtype=float)[:dyn.n]
    static = a_max * factor / safe
    capped = moving & dyn.capped
    a_acc = np.where(capped, np.minimum(a_acc, static), a_acc)
    a_dec = np.where(capped, np.minimum(a_dec, static), a_dec)
    with np.errstate(invalid="ignore"):
        c = np.where(moving & np.isfinite(a_acc), c * a_acc / static, 0.0)
    return V, np.minimum(a_acc, ramp), c, np.minimum(a_dec, ramp)


def ptp_profile(dq: np.ndarray, p: MotionParams, machine: Any, mode: str = DEFAULT_MODE,
                q0: np.ndarray | None = None, V: float | None = None) -> Any:
    """The time law of a synchronised PTP moving the axes by `dq` from `q0` (:func:`ptp_limits`;
    at the normalised speed `V` when given, less than its): :class:`~robot.profiles.Trapezoid`
    with ``V`` and ``A`` of :func:`ptp_limits`; for a robot whose axes lose acceleration with
    their speed (machine data ``ptp_friction``, 1/s, identified: robot/identified.py) a
    :class:`~robot.profiles.FrictionProfile`: axis ``i`` allows the normalised acceleration
    ``alpha_i - c_i·u'`` accelerating and ``alpha_i + c_i·u'`` braking; the motion takes the
    line through the least of them at rest and at ``V`` (below the least of the lines, so
    within every axis' own). The override scales the motion's time: ``c_i · $OV_PRO%``."""
    v_lim, alpha, c, beta = _ptp_axis_limits(dq, p, machine, mode, q0)
    return _ptp_profile(v_lim if V is None else V, alpha, c, p, beta)


def _ptp_profile(V: float, alpha: np.ndarray, c: np.ndarray, p: MotionParams, beta: np.ndarray) -> Any:
    """:func:`ptp_profile` from the axes' limits (:func:`_ptp_axis_limits`): starting at the least
    of `alpha`, braking at the least of `beta` (robot/profiles.py ``FrictionProfile``'s
    ``a_brake`` when they differ)."""
    A = float(np.min(alpha))
    D = A if beta is alpha else float(np.min(beta))
    if not np.any(c > 0) or not (0 < V < math.inf):
        if D == A or not (0 < V < math.inf):
            return Trapezoid.plan(V, A)
        return FrictionProfile(V, A, 0.0, 0.0, a_brake=D)
    c = c * p.ov_pro / 100.0
    a_end = float(np.min(alpha - c * V))
    d_end = float(np.min(beta + c * V))
    return FrictionProfile(V, A, max(0.0, (A - a_end) / V), max(0.0, (d_end - D) / V), a_brake=D)


#: robot/dynamics.py ArmDynamics of a machine's ``dynamics`` (by the mapping's id: machines made
#: from one another with ``replace`` share it), kept: a program plans many PTPs on one robot
_DYNAMICS: dict[int, Any] = {}


def arm_dynamics(machine: Any) -> Any:
    """The robot/dynamics.py ArmDynamics the planner uses for `machine` (None for a robot without
    a dynamic model): one per ``dynamics`` mapping, kept (the identification adjusts its torques
    and rotor inertias in place, robot/kukatrace/identify.py)."""
    dyn = getattr(machine, "dynamics", None)
    if dyn is None or dyn.get("plan") is False:      # shown, not planned with (robot/described_dynamics.py)
        return None
    got = _DYNAMICS.get(id(dyn))
    if got is None or got[0] is not dyn:
        if len(_DYNAMICS) >= 16:
            _DYNAMICS.clear()
        got = _DYNAMICS[id(dyn)] = (dyn, ArmDynamics(machine, dyn))
    return got[1]


def _orientation_modes(p: MotionParams, kind: str) -> str:
    if p.ori_type == "CONSTANT":
        return "CONSTANT"
    if kind in ("CIRC", "SCIRC") and p.circ_type == "PATH":
        return "PATH"
    return "VAR"  # #JOINT: pose_u interpolates like #VAR; axes() moves the wrist axes linearly


def _cp_speeds(prm: MotionParams, mode: str) -> tuple[float, float, float, float]:
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

    pts = [T[:3, 3].copy() for T in pts_T]
    n = len(geo)
    built: list[_Piece | None] = [None] * n
    # lines and arcs first (CA moves an end point), then the SPL curves, whose end
    # tangents follow a neighbouring SLIN/SCIRC (no kink at such a junction)
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
        if g != "SPL":
            continue
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
        built[k] = CatmullRomPiece(P0, a, b, P3, m1, m2)
    pieces: list[_Piece] = [pc for pc in built if pc is not None]

    rots: list[np.ndarray] = [start_T[:3, :3].copy()]
    ori: list[str] = []
    thetas: list[float] = []
    speeds: list[tuple[float, float, float, float]] = []
    for k, (g, data) in enumerate(geo):
        prm = items[k][4]
        piece = pieces[k]
        mode = _orientation_modes(prm, "SCIRC" if g == "ARC" else "SLIN")
        if mode == "CONSTANT":
            R1 = rots[k]
        elif mode == "PATH":
            assert isinstance(piece, ArcPiece)
            R1 = rotvec_matrix(piece.n * piece.angle) @ rots[k]
        else:
            R1 = pts_T[k + 1][:3, :3].copy()
        rots.append(R1)
        ori.append(mode)
        thetas.append(rotation_angle_deg(rots[k], R1))
        speeds.append(_cp_speeds(prm, model.mode))

    # parameter u: proportional to max(L_k, θ_k·c) with one scale c (mm/deg) for the block,
    # so the path speed is continuous where pieces meet (= the old time weights when all
    # pieces share $VEL/$ACC)
    v_cp0, v_ori0, _, _ = _cp_speeds(p, model.mode)
    c = v_cp0 / v_ori0
    weights = [max(pc.length, th * c) for pc, th in zip(pieces, thetas)]
    W = float(sum(weights))
    n = model.n
    q_end = _ext_target(q0, req.target if req.kind != "SPLINE" else
                        (req.segments[-1].target if req.segments else {}), req.relative, model.axes)
    if len(q0) > n:
        model.check_limits(np.concatenate([q0[:n], q_end[n:]]))
    seg = CartSegment(req, q0, q_end, Trapezoid.plan(math.inf, math.inf), math.inf,
                      tool_T, base_T, model, pieces, rots, weights, ori)
    seg.vel_peak = np.zeros(len(q0))
    seg.acc_peak = np.zeros(len(q0))
    if len(q0) > n and W <= 1e-6 and float(np.max(np.abs(q_end[n:] - q0[n:]))) > 1e-9:
        raise RobotError(f"{req.kind}: a CP motion that moves only the external axes is not simulated "
                         f"(the TCP stands still); move them with PTP")
    if W <= 1e-6:  # nothing to move (a zero-length LIN): zero duration, never approximated
        seg.q1 = q0.copy()
        return seg

    m = len(pieces)
    dt = model.machine.ipo_cycle_s
    vmax: list[float] = []
    amax: list[float] = []
    vprog: list[float] = []
    for k in range(m):
        L, th, w = pieces[k].length, thetas[k], weights[k]
        v_cp, v_ori, a_cp, a_ori = speeds[k]
        lk = L * W / w if w > 0 else 0.0       # mm per unit u
        ok = th * W / w if w > 0 else 0.0      # deg per unit u
        # curvature: the centripetal acceleration v²/r stays within $ACC.CP on a spline; a CIRC's
        # path speed is not limited by it (the real KR C4 plans a 360° CIRC of r 150 mm at
        # $ACC.CP 2.3 m/s² as the plain triangle 2·sqrt(L/a): 1.280 s, issue 60)
        curved = L > 0 and req.kind != "CIRC"
        v_curve = math.sqrt(a_cp * pieces[k].min_radius) if curved else math.inf
        v = min(v_cp / lk if lk > 0 else math.inf, v_ori / ok if ok > 0 else math.inf)
        vprog.append(v)
        v = min(v, v_curve / lk if lk > 0 else math.inf)
        a = min(a_cp / lk if lk > 0 else math.inf, a_ori / ok if ok > 0 else math.inf)
        vmax.append(v if v < math.inf else 1e12)
        amax.append(a if a < math.inf else 1e12)
    # corners between pieces: the velocity turns within one IPO cycle, so the corner speed
    # keeps |Δv|/Δt within $ACC.CP (reference §6.2: the spline is slowed at corners)
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

    # walk the path per piece: IK (start status S, continuous turn), singularities, and the
    # axis speeds/accelerations the path needs (the path is slowed so that the axes stay
    # within machine data: |q'|·du/dt <= v_max, |q''|·(du/dt)² + |q'|·d²u/dt² <= a_max)
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
        seg.q1 = model.ik(pts_T[-1], inv_pos(tool_T), base_T, s_t, t_t, q0)
    ref = q0.copy()
    ub = seg.u_bounds
    v_ax = model.v_max
    a_ax = model.a_max
    junction_q: list[np.ndarray] = []
    sec_d: list[tuple[np.ndarray, np.ndarray, float]] = []
    # the pieces whose axes the compiled path solves in a chain (below) are walked in C, the
    # same numbers (robot/simcore.pyx ``CartPath.walk``); None there: the code below
    walker = _compiled_walker(seg) if model.mode != "T1" else None
    chain_from = MIN_CHAIN if model.batch_ik else CP_MAX_SAMPLES + 1
    for k in range(m):
        L, th = pieces[k].length, thetas[k]
        nk = max(4, min(48, int(L / 50.0) + int(th / 10.0) + 4))
        # next to a corner the axis velocity turns within one IPO cycle (up to half of a_max,
        # junction rule below) while the path brakes: the piece keeps the other half
        budget = 0.5 if (kink[k] or kink[k + 1]) else 1.0
        walked = None if walker is None else walker(
            float(ub[k]), float(ub[k + 1]), nk, status, ref, chain_from, budget, plain, v_ax, a_ax,
            vmax[k], SINGULAR_JUMP_DEG, CP_SAMPLE_STEP_DEG, CP_MAX_SAMPLES)
        if walked is not None:
            junction_q.append(ref.copy())
            ref, d1_first, d1_last, qd, qdd, vmax[k], Aax = walked
            if k == 0:
                seg.qd_start = d1_first
            if k == m - 1:
                seg.qd_end = d1_last
            if not plain:
                amax[k] = min(amax[k], max(Aax, 1e-9))
            sec_d.append((qd, qdd, budget))
            continue
        start = ref
        while True:
            us = _samples(float(ub[k]), float(ub[k + 1]), nk + 1)
            Q = np.empty((nk + 1, len(q0)))
            Q[0] = start
            ref = start
            chain = None
            if seg.joint_ori:
                pass                        # solved sample by sample below (the wrist is given)
            elif len(q0) == model.n and nk >= MIN_CHAIN and model.batch_ik:
                chain = seg.ik_chain([seg.pose_u(float(us[j])) for j in range(1, nk + 1)], ref)
            elif len(q0) == model.n and seg.compiled_solver():
                # the poses and the compiled inverse along the samples in one call (the same
                # rows); else the poses here and the inverse in one call
                cp = seg._compiled_path()
                chain = cp.chain_u(us[1:], seg.status, ref) if cp else None
                if chain is None:
                    chain = seg.ik_chain_compiled([seg.pose_u(float(us[j])) for j in range(1, nk + 1)], ref)
            jumps = None
            if chain is not None:
                # the same rows as the loop below; its singularity check, in its order
                Q[1:] = chain
                jumps = np.abs(np.diff(Q, axis=0))
                for j in np.flatnonzero(jumps.max(axis=1) > SINGULAR_JUMP_DEG)[:1].tolist():
                    i = int(np.argmax(jumps[j]))
                    raise RobotError(f"CP path through a singularity: A{i + 1} would turn "
                                     f"{jumps[j][i]:.0f} deg at once (keep the status on CP paths)")
                ref = Q[nk].copy()
            for j in range(1, nk + 1 if chain is None else 1):
                if seg.joint_ori:
                    q = seg.joint_axes_u(float(us[j]), ref)
                else:
                    pu, Ru = seg.pose_u(float(us[j]))
                    q = seg.ik(pu, Ru, ref, float(us[j])) if len(q0) > model.n else seg.ik(pu, Ru, ref)
                jump = np.abs(q - ref)
                if float(jump.max()) > SINGULAR_JUMP_DEG:
                    i = int(np.argmax(jump))
                    raise RobotError(f"CP path through a singularity: A{i + 1} would turn "
                                     f"{jump[i]:.0f} deg at once (keep the status on CP paths)")
                Q[j] = q
                ref = q
            # resolution: at most ~1° of any axis between samples (near a wrist singularity
            # A4/A6 turn fast on a short piece of path), up to CP_MAX_SAMPLES per piece
            if nk <= 0:
                step = 0.0
            else:
                step = float((jumps if jumps is not None else np.abs(np.diff(Q, axis=0))).max())
            if step <= CP_SAMPLE_STEP_DEG or nk >= CP_MAX_SAMPLES:
                break
            nk = min(CP_MAX_SAMPLES, int(nk * step / CP_SAMPLE_STEP_DEG) + 1)
        h = float(us[1] - us[0])
        if h <= 0:
            junction_q.append(Q[0].copy())
            sec_d.append((np.zeros(len(q0)), np.zeros(len(q0)), 1.0))
            continue
        d1 = gradient_rows(Q, h)
        d2 = gradient_rows(d1, h)
        qd = np.max(np.abs(d1), axis=0)
        qdd = np.max(np.abs(d2), axis=0)
        junction_q.append(Q[0].copy())
        if k == 0:
            seg.qd_start = d1[0].copy()
        if k == m - 1:
            seg.qd_end = d1[-1].copy()
        # v/x where x > 1e-9, else inf (x: 1.0 where not taken, so that nothing divides by 0)
        moves, turns = qd > 1e-9, qdd > 1e-9
        qd_safe, qdd_safe = np.where(moves, qd, 1.0), np.where(turns, qdd, 1.0)
        V = float(np.where(moves, v_ax / qd_safe, np.inf).min())
        if not plain:
            V = min(V, float(np.where(turns, np.sqrt(0.5 * budget * a_ax / qdd_safe), np.inf).min()))
        if model.mode == "T1":
            F = model.kin.forward_many(Q)
            dpf = float(np.max(np.linalg.norm(np.diff(F[:, :3, 3], axis=0), axis=1))) / h
            lk = L * W / weights[k] if weights[k] > 0 else 0.0
            if dpf > lk * (1.0 + 1e-6):  # the flange moves faster than the TCP (tool, rotation)
                V = min(V, T1_SPEED_MM_S / (dpf * T1_MARGIN))
        vmax[k] = min(vmax[k], V)
        if not plain:
            Aax = float(np.where(moves, (budget * a_ax - qdd * vmax[k] ** 2) / qd_safe, np.inf).min())
            amax[k] = min(amax[k], max(Aax, 1e-9))
        sec_d.append((qd, qdd, budget))

    def rebudget(k: int) -> None:
        """Half the axis acceleration for piece k (a junction turns the axis velocities)."""
        qd, qdd, b = sec_d[k]
        if b <= 0.5:
            return
        sec_d[k] = (qd, qdd, 0.5)
        with np.errstate(divide="ignore", invalid="ignore"):
            vmax[k] = min(vmax[k], float(np.min(np.where(qdd > 1e-9, np.sqrt(0.25 * a_ax / qdd), np.inf))))
            Aax = float(np.min(np.where(qd > 1e-9, (0.5 * a_ax - qdd * vmax[k] ** 2) / qd, np.inf)))
        amax[k] = min(amax[k], max(Aax, 1e-9))

    for k in range(1, m):  # axis-velocity jumps where pieces meet (one-sided derivatives)
        if vnode[k] <= 0.0:
            continue
        uk, du_ = float(ub[k]), 1e-5
        e_u = (lambda v: v) if len(q0) > model.n else (lambda v: None)
        qj = seg.ik(*seg.pose_u(uk), junction_q[k], e_u(uk))
        qL = seg.ik(*seg.pose_u(uk - du_), qj, e_u(uk - du_))
        qR = seg.ik(*seg.pose_u(uk + du_), qj, e_u(uk + du_))
        jump = np.abs((qR - qj) - (qj - qL)) / du_
        # a jump that matters at full speed (> 5 % of a_max within one cycle; e.g. the
        # orientation rate changing between pieces) is a corner for the axes
        v_full = min(vmax[k - 1], vmax[k])
        if np.any(jump * v_full > 0.05 * a_ax * dt):
            rebudget(k - 1)
            rebudget(k)
            with np.errstate(divide="ignore"):
                vj = float(np.min(np.where(jump > 1e-9, 0.5 * a_ax * dt / jump, np.inf)))
            vnode[k] = min(vnode[k], vj)
    for k in range(m):
        qd, qdd, _ = sec_d[k]
        seg.vel_peak = np.maximum(seg.vel_peak, qd * vmax[k])
        seg.acc_peak = np.maximum(seg.acc_peak, qdd * vmax[k] ** 2 + qd * amax[k])
    if m == 1:
        prof: Any = Trapezoid.plan(vmax[0], amax[0])
    else:
        prof = PiecewiseProfile([float(x) for x in ub], vmax, amax, vnode)
    seg.profile = prof
    seg.v_prog = vprog[-1]
    if not seg.joint_ori:
        seg.q1 = ref
    seg.status = status
    return seg


def _planned_line(req: MotionRequest, q0: np.ndarray, start_T: np.ndarray, tool_T: np.ndarray,
                  base_T: np.ndarray, model: RobotModel) -> CartSegment | None:
    """:func:`_plan_cart` of a single LIN to a complete Cartesian target, ``$ORI_TYPE #VAR``,
    outside T1, on a six-axis arm without external axes and ``$ROBROOT`` whose inverse is compiled:
    the numbers in C (robot/simcore.pyx ``plan_line``: the same operations in the same order,
    numpy's products and dot products through its BLAS, checked once a process by
    :func:`_line_blas`), the segment made here with the attributes ``CartSegment.__init__`` and
    :func:`_plan_cart` give it, the same values bit for bit (tests/robot/test_simcore.py compares
    the two attribute by attribute). None where ``plan_line`` leaves the plan to the Python code
    (an orientation that turns along the line, a zero length, a walk it does not mirror) or
    anything above does not hold: :func:`_plan_cart` plans it (and raises its errors)."""
    p = req.params
    t = req.target
    if (req.relative or p.ori_type != "VAR" or model.mode == "T1" or type(model) is not RobotModel
            or model.n_ext or not model._robroot_is_null or len(q0) != COMPILED_AXES
            or model.n != COMPILED_AXES or not t.keys() >= _CART_SET or not t.keys().isdisjoint(AXIS_KEYS)):
        return None
    sc = kinematics.compiled_module()
    opw = model.kin.compiled_core() if sc is not None else None
    blas = _line_blas(sc) if opw else None
    if blas is None:
        return None
    tool_inv, _, tool_null = _inverse_of(tool_T)
    base_inv, base_null, _ = _inverse_of(base_T)
    tool_inv_T, base_inv_T = tool_inv.copy(), base_inv.copy()
    ik_tool = None if tool_null else tool_inv_T
    ik_base = None if base_null else base_T
    framed = ik_tool is not None or ik_base is not None
    if framed and not _frames_gemm(sc):
        return None
    try:
        v_cp, v_ori, a_cp, a_ori = _cp_speeds(p, model.mode)
    except RobotError:
        return None
    status = model.status_turn(q0)[0]
    got = sc.plan_line(opw, blas[0], blas[1], start_T, *[float(t[k]) for k in CART_KEYS], v_cp, v_ori, a_cp,
                       a_ori, status, q0, MIN_CHAIN if model.batch_ik else CP_MAX_SAMPLES + 1,
                       bool(getattr(model.machine, "ptp_ramp_deg", ())), model.v_max, model.a_max,
                       SINGULAR_JUMP_DEG, CP_SAMPLE_STEP_DEG, CP_MAX_SAMPLES, ik_base, ik_tool)
    if got is None:
        return None
    (p0, p1, direction, L, R0, R1, _theta, rv, still, w, u1, cp, q1, qd_start, qd_end, vel_peak, acc_peak,
     v_prog, vmax, amax) = got
    line = LinePiece.__new__(LinePiece)
    line.__dict__.update(p0=p0, p1=p1, length=L, dir=direction)
    rots = [R0, R1]
    seg = CartSegment.__new__(CartSegment)
    seg.__dict__.update(
        req=req, id=req.id, q0=q0, q1=q1, profile=Trapezoid.plan(vmax, amax), v_prog=v_prog, tool_T=tool_T,
        base_T=base_T, tool_inv_T=tool_inv_T, base_inv_T=base_inv_T, _ik_tool=ik_tool, _ik_base=ik_base,
        _c_ik=False if framed else opw, _c_path=cp, _c_framed=framed, model=model, status=status, triggers=[],
        limits=None, vel_peak=vel_peak, acc_peak=acc_peak, qd_start=qd_start, qd_end=qd_end, _last_q=q0.copy(),
        _end_frame=None, _ahead=None, e1=q0[model.n:].copy(), pieces=[line], rots=rots, ori=["VAR"],
        W=float(sum([w])), joint_ori=False, u_bounds=np.array([0.0, u1]), _ub=[0.0, u1], _lens=[L],
        lengths=np.array([L]), _sb=[0.0, L], s_bounds=np.array([0.0, L]), _R=rots, _rv=[rv], _R_still=[still],
        _path_end=None)
    return seg


_CART_SET = frozenset(CART_KEYS)
#: [(cblas_dgemm, cblas_ddot) addresses] once robot/simcore.pyx ``line_products`` was seen to
#: compute numpy's products and dot products bit for bit, [None] when not: :func:`_line_blas`
_LINE_BLAS: list[tuple[int, int] | None] = []


def _line_blas(sc: Any) -> tuple[int, int] | None:
    """The ``cblas_dgemm`` and ``cblas_ddot`` addresses for robot/simcore.pyx ``plan_line``, or None
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


def _compiled_walker(seg: CartSegment) -> Callable[..., Any] | None:
    """The compiled walk of the planning walk's pieces (robot/simcore.pyx ``CartPath.walk``)
    where the walk solves each piece's samples with ``CartPath.chain_u``, else None."""
    if seg.joint_ori or len(seg.q0) != seg.model.n or not seg.compiled_solver():
        return None
    cp = seg._compiled_path()
    return cp.walk if cp else None


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
    if isinstance(tr, Trigger) and tr.distance is not None:
        if tr.distance == 0:
            return TriggerPlan(tr, index, None if piece in (None, 0) else u0, "start")
        return TriggerPlan(tr, index, None if last else u1, "end")
    if seg.req.kind == "PTP":
        what = "TRIGGER WHEN PATH" if isinstance(tr, Trigger) else "STOP WHEN PATH"
        raise RobotError(f"{what} is not allowed for a PTP motion (use SPTP or a CP motion)")
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
        tgt = {k: float(v) for k, v in zip(seg.model.axes.robot_keys, seg.q1)}
        kind = "PTP"
    else:
        T = seg.model.tcp(seg.q1, seg.tool_T, seg.base_inv_T)
        tgt = dict(zip(CART_KEYS, matrix_to_frame(T)))
        kind = "LIN"
    return MotionRequest(kind=kind, target=tgt, params=req.params, approx=req.approx,
                         approx2=req.approx2, triggers=req.triggers, file=req.file,
                         line=req.line, id=req.id)


__all__ = ["RobotModel", "Segment", "JointSegment", "CartSegment", "TriggerPlan", "plan", "ptp_limits", "ptp_profile",
           "resolved_target", "LinePiece", "ArcPiece", "CatmullRomPiece"]
