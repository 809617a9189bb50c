"""The geometry of KUKA's articulated arm from its machine data (``$MAIN_AXIS=#NR``, or unset):
the six-axis chain every arm family shares (opw.py, palletizer4.py, palletizer5.py, numeric.py
answer ``geometry`` with :func:`arm_geometry`).

The chain (robot-model.md §4.3, ``d_i = $AXIS_DIR[i]``, mm/deg; robot/chain.py)::

    $TIRORO · Rz(d1·A1) · Tx($LENGTH_A) · Ry(d2·A2) · Tx($LENGTH_B) · Ry(d3·A3) · $TX3P3 ·
    Rz(d4·A4) · DH($DH_4) · Rz(d5·A5) · DH($DH_5) · Rz(d6·A6) · $TFLWP

and what follows from it: the OPW parameters of the standard arm (``a1=$LENGTH_A, a2=-$TX3P3.Z,
b=$TX3P3.Y, c1=$TIRORO.Z, c2=$LENGTH_B, c3=$TX3P3.X, c4=$TFLWP.Z``, robot-model.md §4.2; the
axis signs from the chain's own form), the switching angle of S bit 1 ``phi =
atan2($TX3P3.Z, $TX3P3.X)`` and the reach ``$LENGTH_A + $LENGTH_B + |($TX3P3.X, $TX3P3.Z)|``
to the wrist point. ``$NUM_AX`` is 6, or 4..6 on a palletizer (``$DEF_A4FIX``; with 4 the
parallelogram leads A5, docs/robot.md "The palletizers").
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..chain import Chain, opw_form
from ..machine import OPWParams
from ..madavalues import MachineDataError, axis_dirs, dh, frame, get, krl_value, num, tr
from .constants import BOUNDARY_EPS
from .family import Geometry, KinematicFamily, inverse_rows_many, select_solutions

#: The provenance entries of the derived values (robot/mada.py RULES holds the rest).
RULES = {
    "status_phi_deg": "derived: atan2($TX3P3.Z, $TX3P3.X), A3 where the arm is stretched (robot-model.md §8)",
    "reach_wrist_point_mm": "derived: $LENGTH_A + $LENGTH_B + |($TX3P3.X, $TX3P3.Z)|",
    "opw": "derived: a1=$LENGTH_A, a2=-$TX3P3.Z, b=$TX3P3.Y, c1=$TIRORO.Z, c2=$LENGTH_B, "
           "c3=$TX3P3.X, c4=$TFLWP.Z (robot-model.md §4.2-4.3); signs from the chain's axes",
}


def arm_geometry(machine: dict[str, Any], source: str, prov: dict[str, str], a4fix: bool,
                 a5link: bool) -> Geometry | None:
    """The arm's :class:`~robot.kinematics.family.Geometry` from the machine data values (None
    when ``$MAIN_AXIS`` names other main axes). Raises MachineDataError naming the variable,
    its value and file:line."""
    main = machine.get("$MAIN_AXIS")
    if main is not None and main.value not in (None, "#NR"):
        return None
    nax = machine.get("$NUM_AX")
    if nax is not None and nax.value is not None:
        n = nax.value
        least = 4 if a4fix else 6
        if isinstance(n, bool) or not isinstance(n, int) or not least <= n <= 6:
            raise MachineDataError(f"{nax.where()}: $NUM_AX={krl_value(n)}: a robot with "
                                   f"{'$DEF_A4FIX' if a4fix else 'six axes'} has {least}..6 axes")
        prov["$NUM_AX"] = nax.where()
        if a4fix and not a5link and n == 4:
            # A1, A2, A3 and the flange axis A6 are driven: A5 has no drive, so the parallelogram
            # leads it, whatever $DEF_A5LINK says (KUKA's palletizers keep $DEF_A5LINK FALSE).
            a5link = True
            dv5 = machine.get("$DEF_A5LINK")
            prov["a5_led"] = (f"derived: A5 led by the parallelogram, the flange kept vertical "
                              f"($NUM_AX=4 with $DEF_A4FIX=TRUE leaves A5 no drive; $DEF_A5LINK=FALSE "
                              f"at {dv5.where() if dv5 is not None and dv5.value is not None else 'default'})")

    tiroro, dv = frame(machine, "$TIRORO", source)
    prov["$TIRORO"] = dv.where()
    la = get(machine, "$LENGTH_A", source)
    lb = get(machine, "$LENGTH_B", source)
    length_a = num(la.value, la.where(), "$LENGTH_A")
    length_b = num(lb.value, lb.where(), "$LENGTH_B")
    prov["$LENGTH_A"], prov["$LENGTH_B"] = la.where(), lb.where()
    tx3p3, dv = frame(machine, "$TX3P3", source)
    prov["$TX3P3"] = dv.where()
    tflwp, dv = frame(machine, "$TFLWP", source)
    prov["$TFLWP"] = dv.where()
    dh4 = get(machine, "$DH_4", source)
    dh5 = get(machine, "$DH_5", source)
    prov["$DH_4"], prov["$DH_5"] = dh4.where(), dh5.where()
    axis_dir, dirs = axis_dirs(machine, source, 6)
    prov["$AXIS_DIR"] = dirs.where(1)

    F4, _ = dh(dh4)
    F5, _ = dh(dh5)
    fixed = [tiroro, tr(x=length_a), tr(x=length_b), tx3p3, F4, F5, tflwp]
    local = [np.array([0.0, 0.0, axis_dir[0]]), np.array([0.0, axis_dir[1], 0.0]),
             np.array([0.0, axis_dir[2], 0.0]), np.array([0.0, 0.0, axis_dir[3]]),
             np.array([0.0, 0.0, axis_dir[4]]), np.array([0.0, 0.0, axis_dir[5]])]
    chain = Chain.of(fixed, local)

    # OPW parameters of the standard arm (robot-model.md §4.2); the OPW family checks them
    # against the chain and finds the form of any other arm from the chain itself (robot/chain.py)
    tx = {k: num(machine["$TX3P3"].value.get(k, 0.0), prov["$TX3P3"]) for k in "XYZABC"}
    ti = {k: num(machine["$TIRORO"].value.get(k, 0.0), prov["$TIRORO"]) for k in "XYZABC"}
    fl = {k: num(machine["$TFLWP"].value.get(k, 0.0), prov["$TFLWP"]) for k in "XYZABC"}
    form = opw_form(chain)
    signs = form.params.sign_corrections if form is not None else (-1, 1, 1, -1, 1, -1)
    opw = OPWParams(a1=length_a, a2=-tx["Z"], b=tx["Y"], c1=ti["Z"], c2=length_b, c3=tx["X"],
                    c4=fl["Z"], offsets_deg=(0.0, -90.0, 0.0, 0.0, 0.0, 0.0), sign_corrections=signs)
    for key in ("opw", "status_phi_deg", "reach_wrist_point_mm"):
        prov[key] = RULES[key]
    return Geometry(chain=chain, opw=opw, status_phi_deg=math.degrees(math.atan2(tx["Z"], tx["X"])),
                    reach_mm=length_a + length_b + math.hypot(tx["X"], tx["Z"]), a5link=a5link)


class ArmFamily(KinematicFamily):
    """What the arm families (opw.py, palletizer4.py, palletizer5.py, numeric.py) share, declared
    once: the arm's chain from machine data (:func:`arm_geometry`), the joints' forward
    kinematics, the OPW arm's status and turn (robot-model.md §8; the family's ``solver``, a
    robot/kinematics/opwsolver.py ``OPWSolver``), the choice among the family's ``solutions``
    (robot/kinematics/family.py ``select``), N poses row by row, ``krl robot show``'s line of the
    machine data's OPW parameters. Each family adds ``detect`` and ``solutions`` (and whatever it
    does otherwise)."""

    @classmethod
    def geometry(cls, values: dict[str, Any], source: str, prov: dict[str, str], a4fix: bool,
                 a5link: bool) -> Geometry | None:
        return arm_geometry(values, source, prov, a4fix, a5link)

    joints_forward = True

    def forward(self, a: np.ndarray) -> np.ndarray:
        return self.kin.joints.forward(a)

    def forward_many(self, A: np.ndarray) -> np.ndarray:
        return self.kin.joints.forward_many(A)

    def status_turn(self, q: np.ndarray) -> tuple[int, int]:
        s = self.solver.status(q)
        t = 0
        for i in range(6):
            if q[i] < -BOUNDARY_EPS:
                t |= 1 << i
        return s, t

    def status_row(self, q: list[float]) -> tuple[int, int]:
        return self.solver.status_row(q)

    def wrist_point_x(self, q) -> float:
        return self.solver.wrist_point_x(q)

    inverse = select_solutions
    inverse_many = inverse_rows_many

    def describe(self) -> list[str]:
        return [opw_line(self.kin.machine.opw)]


def opw_line(o: Any) -> str:
    """``krl robot show``'s line of the OPW parameters `o` (mm)."""
    return (f"kinematics OPW a1={o.a1 + 0.0:g} a2={o.a2 + 0.0:g} b={o.b + 0.0:g} c1={o.c1 + 0.0:g} "
            f"c2={o.c2 + 0.0:g} c3={o.c3 + 0.0:g} c4={o.c4 + 0.0:g} mm")


__all__ = ["RULES", "ArmFamily", "arm_geometry", "opw_line"]
