"""The SCARA (KUKA's KR SCARA family, e.g. KR 6 R500 Z200, on a KR C4): four axes, all vertical —
A1 and A2 turn the two arms, A3 moves the quill up and down (a linear axis, mm), A4 turns the
flange about the quill.

Machine data (``$MAIN_AXIS=#CC``, "CC = SCARA" in KUKA's own comment on the variable in every
corpus ``$machine.dat``; KR C2 machine-data handbook "Maschinendaten 12.0400 en" §2.1.145: "In
the case of a SCARA robot (#CC) ... ``$AXIS_SEQ[1]=3`` defines axis 3 as the linear axis",
§2.1.4: ``$AXIS_TYPE`` 1 linear, 3 rotary)::

    FLANGE(A) = $TIRORO · Rz(d1·A1) · Tx($LENGTH_A) · Rz(d2·A2) · Tx($LENGTH_B) · Tz(d3·A3)
              · Rz(d4·A4) · $TFLWP

with ``d_i = $AXIS_DIR[i]``, ``$NUM_AX=4``, ``$AXIS_TYPE[3]=1`` and ``$AXIS_SEQ[1]=3`` (A3 is the
linear axis). No public KR SCARA ``$machine.dat`` exists: this reading of ``$TIRORO``,
``$LENGTH_A``, ``$LENGTH_B`` and ``$TFLWP`` for the SCARA's two arm lengths, the arm's height and
the flange below the quill is the project's decision (docs/robot.md "The SCARA").

Inverse (closed form; mm, deg): the flange keeps only its rotation about the vertical (the tilt
of a target, its B and C against the vertical, is dropped, as on the 4-axis palletizer: the
SCARA has no axis for it); the rotation about the vertical gives A1 + A2 + A4, the height A3, and
the planar two-link arm to the quill gives A1 and A2, two solutions (the elbow on either side).

Status and turn follow KUKA's definitions for the articulated arm (robot-model.md §8; ISG's
"Status & Turn" page, which uses KUKA's definition:
https://www.isg-stuttgart.de/fileadmin/kernel/kernel-html/en-GB/814171275.html), read for the
SCARA's axes (decision: KUKA publishes no SCARA-specific table we could find):

* S bit 0: the wrist point (the quill's axis) behind the A1 axis, x < 0 in the A1 frame ("if the
  wrist is behind axis A1, 1 is added");
* S bit 1: the elbow joint at or past its stretched position, A2 >= phi (phi = 0 when the two
  arms are in line at A2 = 0), as KUKA's bit 1 is A3 >= phi for the arm (SINUMERIK's copy of
  KUKA's definition: "0 = A3 < 0°, 1 = A3 >= 0°"): the two solutions of a target differ in it;
* S bit 2 (A5 < 0): there is no A5; it selects nothing;
* T bit i = 1 when A(i+1) < 0 (i = 0..3; A3 in mm).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..chain import Chain
from ..madavalues import MachineDataError, axis_dirs, frame, get, krl_value, num, tr
from . import scararows
from .compiled import pure_module
from .constants import BOUNDARY_EPS, OVERHEAD_SINGULAR_MM
from .family import Geometry, KinematicFamily, check_closed_form, inverse_rows_many, select_solutions

#: The provenance of the derived values.
RULES = {
    "reach_wrist_point_mm": "derived: $LENGTH_A + $LENGTH_B (the SCARA's two arms)",
}


class Scara(KinematicFamily):
    """The SCARA family (module docstring)."""

    name = "scara"
    title = "analytic (SCARA: two arms, a linear A3 and the flange axis A4)"
    s_free = 4
    reduced_orientation = True

    def __init__(self, kin: Any, found: Any = None) -> None:
        super().__init__(kin, found)
        j = kin.joints
        #: the direction (+1: counterclockwise seen from above) of each axis, and A3's (mm up)
        self.s = [float(j.axes[i][2] * j.kuka_sign[i]) for i in range(4)]
        o = j.origins
        self.o0 = o[0]                       # the A1 axis point in $ROBROOT
        self.a = o[1]                        # A1 axis -> A2 axis, in the frame turning with A1
        self.b = o[2] + o[3]                 # A2 axis -> the quill (A3/A4 axis), turning with A1 + A2
        self.f = j.p_flange                  # the quill point -> the flange, turning with A4
        self.R_F = j.R_flange                # the flange's rotation at A4 = 0
        self.l1, self.alpha = math.hypot(self.a[0], self.a[1]), math.atan2(self.a[1], self.a[0])
        self.l2, self.beta = math.hypot(self.b[0], self.b[1]), math.atan2(self.b[1], self.b[0])
        #: A2 (deg) where the two arms are in line: S bit 1 switches there
        self.phi_deg = math.degrees(self.alpha - self.beta) * self.s[1] + 0.0
        self._rows: Any = None      # robot/kinematics/scararows.py's rows of this robot (made on first use)

    # ------------------------------------------------------------------ machine data
    @classmethod
    def geometry(cls, values: dict[str, Any], source: str, prov: dict[str, str], a4fix: bool,
                 a5link: bool) -> Geometry | None:
        """The chain of the module docstring from ``$TIRORO``, ``$LENGTH_A``, ``$LENGTH_B``,
        ``$TFLWP`` and ``$AXIS_DIR[1..4]``; None unless ``$MAIN_AXIS=#CC``."""
        main = values.get("$MAIN_AXIS")
        if main is None or main.value != "#CC":
            return None
        nax = values.get("$NUM_AX")
        if nax is not None and nax.value != 4:
            raise MachineDataError(f"{nax.where()}: $NUM_AX={krl_value(nax.value)}: a SCARA ($MAIN_AXIS=#CC) "
                                   f"has 4 axes")
        if nax is not None:
            prov["$NUM_AX"] = nax.where()
        seq = values.get("$AXIS_SEQ")
        lin = seq.value.get(1) if seq is not None and isinstance(seq.value, dict) else None
        if lin != 3:
            where = seq.where(1) if seq is not None else main.where()
            raise MachineDataError(f"{where}: $AXIS_SEQ[1]={krl_value(lin) if lin is not None else 'not set'}: "
                                   f"the SCARA's linear axis is A3 ($AXIS_SEQ[1]=3, KR C2 machine-data "
                                   f"handbook §2.1.145); another axis order is not simulated")
        prov["$AXIS_SEQ"] = seq.where(1)
        types = values.get("$AXIS_TYPE")
        for i, want in ((1, 3), (2, 3), (3, 1), (4, 3)):
            t = types.value.get(i) if types is not None and isinstance(types.value, dict) else None
            if t != want and not (want == 3 and t == 5):
                where = types.where(i) if types is not None else main.where()
                raise MachineDataError(f"{where}: $AXIS_TYPE[{i}]={krl_value(t) if t is not None else 'not set'}: "
                                       f"a SCARA's A{i} is {'linear (1)' if want == 1 else 'rotary (3)'}")
        prov["$AXIS_TYPE"] = types.where(1)
        tiroro, dv = frame(values, "$TIRORO", source)
        prov["$TIRORO"] = dv.where()
        la, lb = get(values, "$LENGTH_A", source), get(values, "$LENGTH_B", source)
        l1, l2 = num(la.value, la.where(), "$LENGTH_A"), num(lb.value, lb.where(), "$LENGTH_B")
        prov["$LENGTH_A"], prov["$LENGTH_B"] = la.where(), lb.where()
        tflwp, dv = frame(values, "$TFLWP", source)
        prov["$TFLWP"] = dv.where()
        d, dirs = axis_dirs(values, source, 4)
        prov["$AXIS_DIR"] = dirs.where(1)
        fixed = [tiroro, tr(x=l1), tr(x=l2), np.eye(4), tflwp]
        local = [np.array([0.0, 0.0, di]) for di in d]
        prov["reach_wrist_point_mm"] = RULES["reach_wrist_point_mm"]
        return Geometry(chain=Chain.of(fixed, local, ("rotary", "rotary", "linear", "rotary")), opw=None,
                        status_phi_deg=0.0, reach_mm=l1 + l2)

    @classmethod
    def detect(cls, kin: Any) -> Any:
        m = kin.machine
        kinds = tuple(j.kind for j in m.joints)
        if m.main_axis != "#CC" or kinds != ("rotary", "rotary", "linear", "rotary"):
            return None
        return True

    def check(self, where: str) -> None:
        """The closed form must give back random configurations of the machine data's chain
        (1e-6 mm); robot.madavalues.MachineDataError otherwise (axes not vertical: a tilted
        ``$TIRORO``, a turned ``$TFLWP``)."""
        vertical = all(abs(abs(float(v[2])) - 1.0) < 1e-12 for v in self.kin.joints.axes)
        if not vertical:
            raise MachineDataError(f"{where}: $TIRORO: the SCARA's four axes must stand vertical in $ROBROOT")
        check_closed_form(self.kin, self.solutions, where,
                          "$TFLWP: this SCARA's flange is not one the closed form covers", sample=_sample)

    # ------------------------------------------------------------------ FK, S/T
    joints_forward = True

    def forward(self, a: np.ndarray) -> np.ndarray:
        return self.kin.joints.forward(a)

    def forward_many(self, A: np.ndarray) -> np.ndarray:
        return self.kin.joints.forward_many(A)

    def wrist_point_x(self, q) -> float:
        """x (mm) of the quill's axis in the A1 frame: the arm's direction at A1 (S bit 0)."""
        th2 = math.radians(self.s[1] * float(q[1]))
        return self.l1 + self.l2 * math.cos(th2 + self.beta - self.alpha)

    def status_turn(self, q: np.ndarray) -> tuple[int, int]:
        s = int(self.wrist_point_x(q) < -BOUNDARY_EPS) | (int(q[1] >= self.phi_deg - BOUNDARY_EPS) << 1)
        t = 0
        for i in range(4):
            if q[i] < -BOUNDARY_EPS:
                t |= 1 << i
        return s, t

    def status_row(self, q: list[float]) -> tuple[int, int]:
        x = self.wrist_point_x(q)
        s = int(x < -BOUNDARY_EPS) | (int(q[1] >= self.phi_deg - BOUNDARY_EPS) << 1)
        amb = int(abs(x) < OVERHEAD_SINGULAR_MM) | (int(abs(q[1] - self.phi_deg) < 1e-7) << 1) | self.s_free
        return s, amb

    # ------------------------------------------------------------------ IK
    def solutions(self, flange_T: np.ndarray, ref: np.ndarray | None) -> list[list[float]]:
        """The (up to two) rows of a flange pose: A1..A4 (deg; A3 mm), A1, A2, A4 wrapped to
        (-180, 180]; none out of reach (robot/kinematics/scararows.py, compiled where built: the
        same rows)."""
        rows = self._rows
        if rows is None:
            rows = self._rows = pure_module(scararows).ScaraRows(
                self.o0, self.a, self.b, self.f, self.R_F.reshape(9), self.s, self.l1, self.l2,
                self.alpha, self.beta)
        return rows.rows(np.asarray(flange_T, dtype=float), ref)

    inverse = select_solutions
    inverse_many = inverse_rows_many

    def describe(self) -> list[str]:
        return [f"kinematics SCARA arms {self.l1:g} + {self.l2:g} mm; A3 linear (quill), A4 the flange "
                f"axis; S bit 1 switches at A2 = {self.phi_deg:g} deg"]


def _sample(kin: Any, rng: np.random.Generator) -> np.ndarray:
    """A random configuration within the soft limits (for check_closed_form)."""
    return rng.uniform(np.maximum(kin._lo, -170.0), np.minimum(kin._hi, 170.0))


__all__ = ["RULES", "Scara"]
