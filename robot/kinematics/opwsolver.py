"""The OPW closed form of an ortho-parallel arm with a spherical wrist (Brandstötter, Angerer,
Hofbaur 2014; robot-model.md §4.2) and the arm's status S (robot-model.md §8): the solver the
six-axis family uses for its inverse, the palletizers for their arm (``c4 = 0``: the A5 point)
and the numeric family for its seeds and its status. One pose at a time it is
robot/kinematics/fastpath.py (compiled when built); :meth:`OPWSolver.core_many` and
:meth:`OPWSolver.status_many` are the same formulas over N poses in numpy (the OPW family's
inverse of many, bit for bit the scalar rows: tests/robot/test_inverse_many.py).

Units: mm and degrees; poses are 4x4 flange frames (mm). The solutions are the KUKA axes
``q = wrap180(degrees((th + offset) * sign))`` of OPW's joint angles ``th``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .compiled import _fastpath, _python_fastpath, fastpath_compiled, fastpath_module
from .constants import ACOS_TOL, BOUNDARY_EPS, OVERHEAD_SINGULAR_MM, WRIST_SINGULAR_DEG


class OPWSolver:
    """The OPW solution of one arm: :class:`~robot.machine.OPWParams` `o`, the status switching
    angle `phi_deg` (A3 where the wrist point is on the line A2-A3), for the robot of `kin` (its
    soft limits) with the S and T bits `s_free`, `t_free` that select nothing on it. The scalar
    work is robot/kinematics/fastpath.py's ``OPWCore`` (:attr:`c`, compiled when it is built)."""

    def __init__(self, o: Any, phi_deg: float, kin: Any, s_free: int = 0, t_free: int = 0) -> None:
        self.phi_deg = float(phi_deg)
        self.o = o
        self.sign = np.array(o.sign_corrections, dtype=float)
        self.off = np.radians(np.array(o.offsets_deg, dtype=float))
        # per-robot constants of the vectorised solution and status (core_many, status_many)
        self.kappa_2 = o.a2 * o.a2 + o.c3 * o.c3
        self.c2_2 = o.c2 * o.c2
        self.k = math.sqrt(self.kappa_2)
        self.at23 = math.atan2(o.a2, o.c3)
        self.sgn = [float(v) for v in self.sign]
        self.offs = [float(v) for v in self.off]
        #: the scalar solver: robot/kinematics/fastpath.py's OPWCore (compiled when built)
        self._core_args = (o, self.phi_deg, self.sgn, self.offs, kin._lo_l, kin._hi_l, kin._ks_l, s_free, t_free)
        self.c = fastpath_module().OPWCore(*self._core_args)

    def python_core(self) -> Any:
        """:attr:`c` as robot/kinematics/fastpath.py runs it as Python (itself where fastpath is not
        compiled): the core a pure-Python module reaches into (its registers are lists there)."""
        if not self.compiled:
            return self.c
        return _python_fastpath().OPWCore(*self._core_args)

    @property
    def compiled(self) -> bool:
        """True when :attr:`c` is the compiled fastpath's."""
        return fastpath_compiled() and isinstance(self.c, _fastpath.OPWCore)

    # ------------------------------------------------------------------ S
    def wrist_point_x(self, axes_deg: Sequence[float]) -> float:
        """x of the wrist point in the A1 frame, mm (robot-model.md §4.4; S bit 0)."""
        q = np.asarray(axes_deg, dtype=float)
        o = self.o
        t2 = math.radians(self.sign[1] * q[1]) - self.off[1]
        t3 = math.radians(self.sign[2] * q[2]) - self.off[2]
        return float(o.a1 + o.c2 * math.sin(t2) + o.c3 * math.sin(t2 + t3)
                     + o.a2 * math.cos(t2 + t3))

    def status(self, q: np.ndarray) -> int:
        """S of the axes `q` (robot-model.md §8): bit 0 the wrist point behind the A1 axis, bit 1
        A3 >= phi, bit 2 A5 < 0 (values within 1e-9 of a switching point on its non-negative side)."""
        s = 0
        if self.wrist_point_x(q) < -BOUNDARY_EPS:
            s |= 1
        if q[2] >= self.phi_deg - BOUNDARY_EPS:
            s |= 2
        if q[4] < -BOUNDARY_EPS:
            s |= 4
        return s

    def status_row(self, q: list[float]) -> tuple[int, int]:
        """S of one axis configuration (6 floats, deg) and the mask of its S bits that sit on
        their switching point (wrist point on the A1 axis, A3 = phi, A5 = 0), or that select
        nothing on this robot (fastpath ``OPWCore.status``)."""
        c = self.c
        c.status(q[0], q[1], q[2], q[3], q[4], q[5])
        return c.s_out, c.amb_out

    def status_many(self, Q: np.ndarray, s_free: int) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`status_row` over the last axis of Q (..., 6) in numpy: (S, ambiguous bits) arrays."""
        o = self.o
        t2 = np.radians(self.sgn[1] * Q[..., 1]) - self.offs[1]
        t23 = t2 + np.radians(self.sgn[2] * Q[..., 2]) - self.offs[2]
        xw = o.a1 + o.c2 * np.sin(t2) + o.c3 * np.sin(t23) + o.a2 * np.cos(t23)
        phi = self.phi_deg
        s = ((xw < -BOUNDARY_EPS).astype(int) | ((Q[..., 2] >= phi - BOUNDARY_EPS).astype(int) << 1)
             | ((Q[..., 4] < -BOUNDARY_EPS).astype(int) << 2))
        amb = ((np.abs(xw) < OVERHEAD_SINGULAR_MM).astype(int) | ((np.abs(Q[..., 2] - phi) < 1e-7).astype(int) << 1)
               | ((np.abs(Q[..., 4]) < WRIST_SINGULAR_DEG).astype(int) << 2) | s_free)
        return s, amb

    # ------------------------------------------------------------------ IK
    def core(self, flange_T: np.ndarray, ref_deg: np.ndarray | None) -> list[list[float]]:
        """OPW closed form: up to 8 lists of KUKA axis values (deg, wrapped to (-180, 180]) of the
        flange pose (4x4, mm; fastpath ``OPWCore.core``). With ``ref_deg`` the free angle at a
        singularity is taken from it: A1 when the wrist point is on the A1 axis, A4 when A5 = 0."""
        return self.c.rows_of(np.asarray(flange_T, dtype=float),
                              None if ref_deg is None else np.asarray(ref_deg, dtype=float))

    def core_many(self, Ts: np.ndarray, refs: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
        """:meth:`core` over N targets: (N, 8, 6) axes (deg, wrapped; NaN where a branch does not
        exist), the (N, 8) mask of existing solutions, in the scalar order, and whether the
        result is free of `refs` (no target at a singularity)."""
        o = self.o
        acos = np.frompyfunc(math.acos, 1, 1)
        atan2_ = np.frompyfunc(math.atan2, 2, 1)

        def atan2(y, x):
            return atan2_(y, x).astype(float)
        r00, r01, r02, px = Ts[:, 0, 0], Ts[:, 0, 1], Ts[:, 0, 2], Ts[:, 0, 3]
        r10, r11, r12, py = Ts[:, 1, 0], Ts[:, 1, 1], Ts[:, 1, 2], Ts[:, 1, 3]
        r20, r21, r22, pz = Ts[:, 2, 0], Ts[:, 2, 1], Ts[:, 2, 2], Ts[:, 2, 3]
        cx, cy, cz = px - o.c4 * r02, py - o.c4 * r12, pz - o.c4 * r22
        rho2 = cx * cx + cy * cy - o.b * o.b
        reach = rho2 >= 0.0
        nx1 = np.sqrt(np.where(reach, rho2, 0.0)) - o.a1
        over = np.sqrt(cx * cx + cy * cy) < OVERHEAD_SINGULAR_MM
        ref_free = not bool(over.any())
        tmp1 = np.where(over, np.radians(self.sgn[0] * refs[:, 0]) - self.offs[0], atan2(cy, cx))
        tmp2 = atan2(o.b, nx1 + o.a1)
        th1s = (tmp1 - tmp2, tmp1 + tmp2 - math.pi)
        tmp3 = cz - o.c1
        s1_2 = nx1 * nx1 + tmp3 * tmp3
        tmp4 = nx1 + 2.0 * o.a1
        s2_2 = tmp4 * tmp4 + tmp3 * tmp3
        s_ = (np.sqrt(s1_2), np.sqrt(s2_2))
        s_2 = (s1_2, s2_2)
        base2 = (atan2(nx1, tmp3), -atan2(tmp4, tmp3))
        n = Ts.shape[0]
        Q = np.full((n, 8, 6), np.nan)
        valid = np.zeros((n, 8), dtype=bool)
        col = 0
        for b in range(2):
            with np.errstate(divide="ignore", invalid="ignore"):
                arg2 = (s_2[b] + self.c2_2 - self.kappa_2) / (2.0 * s_[b] * o.c2)
                arg3 = (s_2[b] - self.c2_2 - self.kappa_2) / (2.0 * o.c2 * self.k)
            exists = reach & (s_[b] >= 1e-12) & (np.abs(arg2) <= 1.0 + ACOS_TOL) & (np.abs(arg3) <= 1.0 + ACOS_TOL)
            a2c = acos(np.clip(np.where(exists, arg2, 0.0), -1.0, 1.0)).astype(float)
            a3c = acos(np.clip(np.where(exists, arg3, 0.0), -1.0, 1.0)).astype(float)
            for th1, th2, th3 in ((th1s[b], -a2c + base2[b], a3c - self.at23),
                                  (th1s[b], a2c + base2[b], -a3c - self.at23)):
                sn1, cs1 = np.sin(th1), np.cos(th1)
                s23, c23 = np.sin(th2 + th3), np.cos(th2 + th3)
                mm = r02 * s23 * cs1 + r12 * s23 * sn1 + r22 * c23
                th5 = atan2(np.sqrt(np.maximum(0.0, 1.0 - mm * mm)), mm)
                th4 = atan2(r12 * cs1 - r02 * sn1, r02 * c23 * cs1 + r12 * c23 * sn1 - r22 * s23)
                th6 = atan2(r01 * s23 * cs1 + r11 * s23 * sn1 + r21 * c23,
                            -r00 * s23 * cs1 - r10 * s23 * sn1 - r20 * c23)
                sing = np.abs(np.degrees(th5)) < WRIST_SINGULAR_DEG
                ref_free = ref_free and not bool((sing & exists).any())
                total = th4 + th6
                th4 = np.where(sing, np.radians(self.sgn[3] * refs[:, 3]) - self.offs[3], th4)
                th6 = np.where(sing, total - th4, th6)
                for sol in ((th1, th2, th3, th4, th5, th6), (th1, th2, th3, th4 + math.pi, -th5, th6 - math.pi)):
                    for i, th in enumerate(sol):
                        Q[:, col, i] = -((-np.degrees((th + self.offs[i]) * self.sgn[i]) + 180.0) % 360.0) + 180.0
                    valid[:, col] = exists
                    col += 1
        Q[~valid] = np.nan
        return Q, valid, ref_free

__all__ = ["OPWSolver"]
