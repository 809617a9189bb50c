"""The 4-axis palletizer (KUKA's KR ... PA: ``$DEF_A4FIX`` and ``$DEF_A5LINK``, or
``$DEF_A4FIX`` with ``$NUM_AX=4``; docs/robot.md "The palletizers").

A4 stays at 0 and the parallelogram leads A5 so that the flange keeps looking down (A2 + A3 +
A5 keeps its HOME value): a flange pose has four degrees of freedom, X, Y, Z and the rotation
about the vertical. The pose's tilt (its B and C against the vertical) is not followed: KUKA's
4-axis transformation has no axis for it, and the flange keeps the nearest vertical pose (the
rotation about the vertical closest in the least-squares sense). The arm plane's direction is
that of the flange seen from the A1 axis; the A5 point lies the fixed offset back from the
flange in that plane; OPW solves the arm for that point (``c4 = 0``). Only rows that put the
flange where asked (1e-6 mm) are kept.

The model keeps KUKA's six axis numbers (A4 fixed at 0, A5 led), so the robot has six joints.
Status: the OPW arm's; S bit 2 and T bits 3, 4 (A4, A5) select nothing (a palletizer cannot
choose the sign of its led A5: the backup's points carry S 6 / T 18 where the model's A5 is +4°).

The rows are robot/kinematics/pal4rows.py's (compiled where built: the same rows).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from . import pal4rows
from .compiled import pure_python, rows_on
from .family import check_closed_form
from .opwsolver import OPWSolver
from .palcore import RowsFamily


class Palletizer4(RowsFamily):
    """The 4-axis palletizer (module docstring)."""

    name = "palletizer4"
    title = "analytic (4-axis palletizer: $DEF_A4FIX, A5 led by the parallelogram)"
    s_free = 4
    reduced_orientation = True
    t_free = 0b11000

    def __init__(self, kin: Any, found: Any = None) -> None:
        super().__init__(kin, found)
        m = kin.machine
        q = np.array(m.home_deg, dtype=float)
        q[0] = q[3] = q[5] = 0.0
        T = kin.joints.forward(q)
        #: the flange's offset from the A5 axis point in the arm's vertical plane at A1 = 0 (mm),
        #: and the flange rotation at HOME with A1 = A6 = 0
        self.pa = (T[:3, 3] - kin.joints.joint_point(q, 4), T[:3, :3].copy())
        self.solver = OPWSolver(replace(m.opw, c4=0.0), float(m.status_phi_deg), kin, self.s_free, self.t_free)

    @classmethod
    def detect(cls, kin: Any) -> Any:
        return True if kin.machine.a5link else None

    def check(self, where: str) -> None:
        """The 4-axis closed form must give back random linked configurations of the chain
        (A4 = 0, A2 + A3 + A5 as at HOME); robot.mada.MachineDataError otherwise."""
        home = self.kin._home

        def link(q):
            q[4] = home[4] + home[1] + home[2] - q[1] - q[2]

        led = "$NUM_AX=4" if "a5_led" in self.kin.machine.provenance else "$DEF_A5LINK=TRUE"
        check_closed_form(
            self.kin, self.solutions, where,
            f"$DEF_A4FIX=TRUE, A5 led ({led}): this palletizer's arm ($TIRORO, $TX3P3, $DH_4, $DH_5, "
            f"$TFLWP) is not one the 4-axis closed form covers", link=link)


    def solutions(self, flange_T: np.ndarray, ref_deg: np.ndarray | None) -> list[list[float]]:
        """The rows of a flange pose (module docstring); A4 is 0: pal4rows.py ``pose_rows``, the rows
        of :meth:`_vertical`'s rotation and position (the same bytes, compiled where built)."""
        return self.rows_object().pose_rows(np.asarray(flange_T, dtype=float), ref_deg)

    def _vertical(self, flange_T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(R_v, p): the vertical flange rotation nearest the pose's (3x3) and its position (3,, mm)
        in numpy (:meth:`numpy_rows`; :meth:`solutions` computes it in pal4rows.py ``pose_rows``)."""
        offset, R_ref = self.pa
        T = np.asarray(flange_T, dtype=float)
        R_rel = T[:3, :3] @ R_ref.T
        psi = math.atan2(R_rel[1, 0] - R_rel[0, 1], R_rel[0, 0] + R_rel[1, 1])
        c, s = math.cos(psi), math.sin(psi)
        Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        return Rz @ R_ref, T[:3, 3]

    def numpy_rows(self, flange_T: np.ndarray, ref_deg: np.ndarray | None) -> list[list[float]]:
        """:meth:`solutions` with the flange test through :meth:`Kinematics.forward` (numpy and
        scipy) in place of pal4rows.py's own forward kinematics: the reference the rows are
        checked against (tests/robot/test_simcore.py, tools/palletizer_rows_check.py)."""
        offset = self.pa[0]
        R_v, p = self._vertical(flange_T)
        rows: list[list[float]] = []
        phi = math.atan2(p[1], p[0])
        for arm in (phi, phi + math.pi):
            ca, sa = math.cos(arm), math.sin(arm)
            Tw = np.eye(4)
            Tw[:3, :3] = R_v
            Tw[:3, 3] = p - np.array([ca * offset[0] - sa * offset[1], sa * offset[0] + ca * offset[1], offset[2]])
            for row in self.solver.core(Tw, ref_deg):
                if abs(row[3]) < 1e-6:
                    row[3] = 0.0
                elif abs(abs(row[3]) - 180.0) < 1e-6:
                    continue                    # the flipped wrist: A4 cannot turn
                if float(np.abs(self.kin.forward(row)[:3, 3] - p).max()) < 1e-6:
                    rows.append(row)
        return rows

    def make_rows(self, python: bool = False) -> tuple[Any, bool]:
        """robot/kinematics/pal4rows.py's ``Palletizer4Rows`` of this robot: compiled on the
        compiled OPW core where both are built and current, else (or with `python`) the Python
        file on fastpath.py's OPW core as Python (the same rows); and whether compiled."""
        if python:
            mod, core = pure_python(pal4rows), self.solver.python_core()
        else:
            mod, core = rows_on(pal4rows, self.solver)
        j = self.kin.joints
        rows = mod.Palletizer4Rows(core, j.origins.tolist(), j.axes.tolist(), j.kuka_sign.tolist(),
                                   j.R_origin.tolist(), j.origin_rot, j.R_flange.tolist(),
                                   j.p_flange.tolist(), self.pa[0].tolist(), self.pa[1].tolist())
        return rows, mod is not pure_python(pal4rows)


__all__ = ["Palletizer4"]
