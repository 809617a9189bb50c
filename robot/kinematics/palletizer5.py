"""The 5-axis palletizer: ``$DEF_A4FIX`` TRUE, ``$DEF_A5LINK`` FALSE (and ``$NUM_AX`` 5 or 6),
and its closed form.

A4 stays at 0 and A5 is a driven axis, so the flange has five degrees of freedom: its
position, the direction of the A6 axis within the arm's vertical plane (A2 + A3 + A5), and
the rotation about the A6 axis (A6). KUKA's transformation has no axis that tilts the A6
axis out of the arm plane; a target's component out of it is dropped (docs/robot.md "The
palletizers"; the same decision as for the 4-axis palletizer, whose flange keeps only the
rotation about the vertical). The flange may sit off the A5 axis (``$DH_5`` a/d and
``$TFLWP``, as on KUKA's palletizers): the solution is geometric, from the joints of the model
at A4 = 0:

1. the arm plane from the target's position (A1 towards it, or the overhead solution
   behind the A1 axis);
2. the target's A6 axis projected into that plane gives the pitch; the fixed offset from the
   A5 point to the flange, turned by that pitch, gives the A5 point;
3. A1..A3 from the OPW arm solution for the A5 point (c4 = 0), A5 from the pitch, A6 from
   the rotation left about the A6 axis.

Status: the OPW arm's; S bit 2 and T bits 3 and 4 (the signs of A4 and A5) select nothing. A4
is fixed, and A5 is not chosen: for a given arm (A1..A3, chosen by S bits 0 and 1) and the
target's A6 axis in the arm plane, A5 has one value (within its range, no ±360° variant); in
palletizing mode KUKA's controller computes it from A2 and A3 so that the flange stays parallel
to the floor ("$PAL_MODE", 5-axis palletizers KR300PA_2 S C4 FLR and the like: "A5 drives to its
calculated position"; industrialmonitordirect.com knowledge base, "KUKA 5-Axis Palletizer A5
Gripper Parallelism Fix"). A taught point's T bit 4 records the sign of A5 on the robot that
taught it; on a model whose A5 comes out with the other sign it selected the -360° variant
and refused the point ("software limit switch -A5", issue 72: a KR 470 PA-2's first pick,
T 26), as T bit 4 is also free on the 4-axis palletizer.

Units: mm and deg. Raises nothing itself; :meth:`Palletizer5.check` raises
robot.mada.MachineDataError when the machine data's wrist does not have this form.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from . import pal5rows
from .compiled import pure_python, rows_on
from .family import check_closed_form
from .opwsolver import OPWSolver
from .palcore import RowsFamily


def _rot_about(axis: np.ndarray, angle: float) -> np.ndarray:
    return _rotvecs(np.asarray(axis, dtype=float)[None, :] * angle)[0]


def _rotvecs(v: np.ndarray) -> np.ndarray:
    """Rotation matrices (N x 3 x 3) of rotation vectors `v` (N x 3, rad): Rodrigues' formula,
    the matrices of scipy's ``Rotation.from_rotvec`` without its per-call overhead."""
    th = np.linalg.norm(v, axis=1)
    u = np.divide(v, th[:, None], out=np.zeros_like(v), where=th[:, None] > 0.0)
    K = np.zeros((len(v), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -u[:, 2], u[:, 1], -u[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = u[:, 2], -u[:, 1], u[:, 0]
    s, c = np.sin(th)[:, None, None], np.cos(th)[:, None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


class Palletizer5(RowsFamily):
    """The 5-axis palletizer (module docstring), for :class:`robot.kinematics.Kinematics` `kin`."""

    name = "palletizer5"
    title = "analytic (5-axis palletizer: $DEF_A4FIX)"
    s_free = 4
    reduced_orientation = True
    #: A4's and A5's turn bits select nothing (module docstring, "Status")
    t_free = 0b11000

    def __init__(self, kin: Any, found: Any = None) -> None:
        super().__init__(kin, found)
        m = kin.machine
        #: the arm's status (and the OPW solver of the arm for the A5 point: c4 = 0)
        self.solver = OPWSolver(m.opw, float(m.status_phi_deg), kin, self.s_free, self.t_free)
        self.arm = OPWSolver(replace(m.opw, c4=0.0), float(m.status_phi_deg), kin, self.s_free, self.t_free)
        q0 = np.zeros(6)
        pts, dirs, T0 = self.joints(q0)
        R0 = T0[:3, :3]
        #: the A6 axis in the flange frame (constant: the flange turns with A6 about it)
        self.a6_in_flange = R0.T @ dirs[5]
        self._a1_sign: float | None = None

    @classmethod
    def detect(cls, kin: Any) -> Any:
        m = kin.machine
        return True if m.a4fix and not m.a5link else None


    def joints(self, q: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray], np.ndarray]:
        """Points and unit directions of the six joint axes, and the flange (4x4), at axes `q`
        (deg), in ``$ROBROOT``."""
        k = self.kin.joints
        qr = k.kuka_sign * np.radians(np.asarray(q, dtype=float)[:6])
        Rj = _rotvecs(k.axes * qr[:, None])
        R = np.eye(3)
        p = np.zeros(3)
        pts, dirs = [], []
        for i in range(6):
            p = p + R @ k.origins[i]
            if k.origin_rot:
                R = R @ k.R_origin[i]
            pts.append(p.copy())
            dirs.append(R @ k.axes[i])
            R = R @ Rj[i]
        T = np.eye(4)
        T[:3, :3] = R @ k.R_flange
        T[:3, 3] = p + R @ k.p_flange
        return pts, dirs, T

    def solutions(self, flange_T: np.ndarray, ref_deg: np.ndarray | None) -> list[list[float]]:
        """The solutions (lists of A1..A6, deg, wrapped to (-180, 180]) whose flange is at the
        target's position (1e-6 mm) with the A6 axis the target's, projected into the arm plane:
        robot/kinematics/pal5rows.py's rows (compiled where built: the same rows)."""
        return self.rows_object().rows(np.asarray(flange_T, dtype=float), ref_deg)

    def make_rows(self, python: bool = False) -> tuple[Any, bool]:
        """robot/kinematics/pal5rows.py's ``Palletizer5Rows`` of this robot: compiled on the
        compiled OPW core of the arm where both are built and current, else (or with `python`) the
        Python file on fastpath.py's OPW core as Python (the same rows); and whether compiled."""
        if self._a1_sign is None:
            self._a1_of(0.0)
        if python:
            mod, core = pure_python(pal5rows), self.arm.python_core()
        else:
            mod, core = rows_on(pal5rows, self.arm)
        j = self.kin.joints
        rows = mod.Palletizer5Rows(core, j.origins.tolist(), j.axes.tolist(), j.kuka_sign.tolist(),
                                   j.R_origin.tolist(), j.origin_rot, j.R_flange.tolist(),
                                   j.p_flange.tolist(), self.a6_in_flange.tolist(), self._a1_sign)
        return rows, mod is not pure_python(pal5rows)

    def numpy_rows(self, flange_T: np.ndarray, ref_deg: np.ndarray | None) -> list[list[float]]:
        """:meth:`solutions` in numpy (Rodrigues' formula through :meth:`joints`, the flange test
        through :meth:`Kinematics.forward`): the reference pal5rows.py's rows are checked against
        (tests/robot/test_kinematics_compiled.py), the same rows within 1e-9 deg."""
        T = np.asarray(flange_T, dtype=float)
        p, R = T[:3, 3], T[:3, :3]
        a_des = R @ self.a6_in_flange
        out: list[list[float]] = []
        phi = math.atan2(p[1], p[0])
        for arm in (phi, phi + math.pi):
            # the joints with A1 turning the arm plane towards `arm` (A1 = 0 looks along +X)
            a1 = self._a1_of(arm)
            pts, dirs, F = self.joints([a1, 0.0, 0.0, 0.0, 0.0, 0.0])
            n = dirs[4] / np.linalg.norm(dirs[4])              # the A5 axis: the plane's normal
            a_p = a_des - float(a_des @ n) * n
            if np.linalg.norm(a_p) < 1e-9:
                continue                                        # the A6 axis along the normal
            a_p = a_p / np.linalg.norm(a_p)
            a_ref = dirs[5]
            psi = math.atan2(float(n @ np.cross(a_ref, a_p)), float(a_ref @ a_p))
            v = _rot_about(n, psi) @ (F[:3, 3] - pts[4])
            w = p - v                                           # the A5 point
            Tw = np.eye(4)
            Tw[:3, 3] = w
            arms = self.arm.core(Tw, ref_deg)
            seen: set[tuple[float, ...]] = set()
            for row in arms:
                key = tuple(round(v_, 9) for v_ in row[:3])
                if key in seen:
                    continue
                seen.add(key)
                sol = self._wrist(row[:3], R, a_des, p)
                if sol is not None:
                    out.append(sol)
        return out

    def _a1_of(self, azimuth: float) -> float:
        """A1 (deg) that turns the arm plane (the A1 = 0 plane contains +X) to `azimuth` (rad)."""
        if self._a1_sign is None:
            d1 = self.joints(np.zeros(6))[1][0]
            self._a1_sign = 1.0 if d1[2] > 0 else -1.0
        return math.degrees(azimuth) * self._a1_sign

    def _wrist(self, a123, R: np.ndarray, a_des: np.ndarray, p: np.ndarray) -> list[float] | None:
        q = [float(a123[0]), float(a123[1]), float(a123[2]), 0.0, 0.0, 0.0]
        pts, dirs, F = self.joints(q)
        n = dirs[4] / np.linalg.norm(dirs[4])
        a_p = a_des - float(a_des @ n) * n
        if np.linalg.norm(a_p) < 1e-9:
            return None
        a_p = a_p / np.linalg.norm(a_p)
        a0 = dirs[5]
        q[4] = math.degrees(math.atan2(float(n @ np.cross(a0, a_p)), float(a0 @ a_p)))
        pts, dirs, F = self.joints(q)
        # the target turned (least) so that its A6 axis lies in the plane
        c = np.cross(a_des, a_p)
        s = np.linalg.norm(c)
        Rc = R if s < 1e-15 else _rot_about(c / s, math.atan2(s, float(a_des @ a_p))) @ R
        d6 = dirs[5] / np.linalg.norm(dirs[5])
        rel = Rc @ F[:3, :3].T                                  # = Rot(d6, A6)
        # the angle of the rotation `rel` about d6: sin from its skew part, cos from its trace
        sin_t = 0.5 * float(d6 @ (rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]))
        q[5] = math.degrees(math.atan2(sin_t, 0.5 * (float(np.trace(rel)) - 1.0)))
        q = [-((-v + 180.0) % 360.0) + 180.0 for v in q]
        if float(np.abs(self.kin.forward(q)[:3, 3] - p).max()) > 1e-6:
            return None
        return q

    def check(self, where: str) -> None:
        """Raise robot.mada.MachineDataError (at `where`) unless the closed form gives back
        random configurations of the machine-data chain (A4 = 0;
        robot.kinematics.Kinematics.check_closed_form)."""
        check_closed_form(
            self.kin, self.solutions, where,
            "$DEF_A4FIX=TRUE, $DEF_A5LINK=FALSE: the wrist of this 5-axis palletizer "
            "($DH_4, $DH_5, $TFLWP) does not keep the A6 axis in the arm's plane")


__all__ = ["Palletizer5"]
