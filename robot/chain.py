"""The kinematic chain of a KUKA arm as its machine data define it, and the closed forms it has.

The chain (mm, deg; ``d_i = $AXIS_DIR[i]``; robot-model.md §4.3, KR C2 machine-data
handbook "Maschinendaten 12.0400" §2.1)::

    FLANGE(A) = $TIRORO · Rz(d1·A1) · Tx($LENGTH_A) · Ry(d2·A2) · Tx($LENGTH_B) · Ry(d3·A3)
              · $TX3P3 · Rz(d4·A4) · DH($DH_4) · Rz(d5·A5) · DH($DH_5) · Rz(d6·A6) · $TFLWP

with ``DH({a, d, alpha}) = Tz(d) · Tx(a) · Rx(alpha)``: seven fixed frames ``F0..F6`` and six
joint axes in the frame after the fixed frame before each (:class:`Chain`).

:func:`opw_form` finds, from the geometry of the chain at A = 0 (not from the robot's name),
whether the arm has the ortho-parallel form with a spherical wrist that the OPW closed form
solves (Brandstötter, Angerer, Hofbaur: "An analytical solution of the inverse kinematics
problem of industrial serial manipulators with an ortho-parallel basis and a spherical wrist",
2014), and gives its parameters, axis signs and the fixed frames before and after it. The
caller verifies the form against :func:`chain_forward` before using it (robot/kinematics/opw.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .machine import OPWParams

#: The standard arm's axis count (robot-model.md §3: A1..A6, the OPW form with a spherical wrist):
#: the chains of the arm families; a SCARA's or palletizer's chain has fewer
ARM_AXES = 6

#: OPW's joint offsets for KUKA's zero pose (arm stretched forward; robot-model.md §4.2).
OPW_OFFSETS_DEG = (0.0, -90.0, 0.0, 0.0, 0.0, 0.0)
#: Geometry closer than this (mm, or a unit vector's component) counts as exact.
_GEOM_EPS = 1e-9


@dataclass(frozen=True)
class Chain:
    """A serial chain ``F0 · J1(q1) · F1 · ... · Jn(qn) · Fn`` (n = 6 for the arms above, 4 for
    a SCARA), each joint ``Ji`` a rotation about its unit axis ``ui`` by ``qi`` deg or, for a
    linear axis, a translation along it by ``qi`` mm.

    Attributes:
        fixed: n + 1 4x4 fixed transforms F0..Fn (mm) as nested tuples.
        axes: n unit joint axes u1..un (the frame after F(i-1)), KUKA's ``$AXIS_DIR`` in them.
        kinds: ``"rotary"`` or ``"linear"`` per axis (empty: all rotary).
    """

    fixed: tuple
    axes: tuple
    kinds: tuple = ()

    def frames(self) -> list[np.ndarray]:
        """F0..F6 as 4x4 arrays (mm)."""
        return [np.array(f, dtype=float) for f in self.fixed]

    def local_axes(self) -> list[np.ndarray]:
        """u1..u6 as arrays."""
        return [np.array(a, dtype=float) for a in self.axes]

    def linear(self, i: int) -> bool:
        """True when axis i (0 = A1) is linear."""
        return bool(self.kinds) and self.kinds[i] == "linear"

    @staticmethod
    def of(fixed: list[np.ndarray], axes: list[np.ndarray], kinds: tuple = ()) -> "Chain":
        return Chain(tuple(tuple(map(tuple, np.asarray(f, dtype=float).tolist())) for f in fixed),
                     tuple(tuple(float(v) for v in a) for a in axes), tuple(kinds))


def chain_forward(chain: Chain, axes_deg) -> np.ndarray:
    """The flange frame of the chain itself (4x4, mm) for axes A1..An in deg (a linear axis in mm)."""
    fixed, local = chain.frames(), chain.local_axes()
    T = fixed[0].copy()
    for i in range(len(local)):
        J = np.eye(4)
        if chain.linear(i):
            J[:3, 3] = local[i] * float(axes_deg[i])
        else:
            J[:3, :3] = Rotation.from_rotvec(local[i] * math.radians(float(axes_deg[i]))).as_matrix()
        T = T @ J @ fixed[i + 1]
    return T


def chain_to_joints(fixed: list[np.ndarray], axes_local: list[np.ndarray]
                    ) -> tuple[list[np.ndarray], list[np.ndarray], np.ndarray]:
    """URDF-style joints of a serial chain ``F0 · J1(q1) · F1 · ... · Jn(qn) · Fn`` (:class:`Chain`).

    Args:
        fixed: n + 1 4x4 fixed transforms F0..Fn (mm).
        axes_local: n unit joint axes u1..un in the frame after F(i-1).
    Returns:
        (origins, axes, flange): joint origins (translations in the parent joint's frame,
        no rotation), joint axes in that frame, and the 4x4 last link -> flange transform.
        Each fixed rotation is moved past the joints that follow it
        (``R · Rot(u, q) = Rot(R u, q) · R``, and ``R · Trans(u, q) = Trans(R u, q) · R``); on a
        six-axis arm a translation along a wrist axis (A4, A6) is moved to the joint origin
        where ROS-Industrial URDFs put it (it commutes with the rotation about that axis).
    """
    n = len(axes_local)
    R = np.eye(3)
    origins: list[np.ndarray] = []
    axes: list[np.ndarray] = []
    for i in range(n):
        origins.append(R @ fixed[i][:3, 3])
        R = R @ fixed[i][:3, :3]
        axes.append(R @ axes_local[i])
    flange = np.eye(4)
    flange[:3, :3] = R @ fixed[n][:3, :3]
    flange[:3, 3] = R @ fixed[n][:3, 3]
    if n != ARM_AXES:
        clean = [np.round(v, 9) + 0.0 for v in origins]
        clean_axes = [np.where(np.abs(v) < 1e-12, 0.0, np.round(v, 12)) + 0.0 for v in axes]
        flange[np.abs(flange) < 1e-12] = 0.0
        return clean, clean_axes, flange
    # A4: the part of its origin along its own axis goes to A5's origin
    a = axes[3]
    along = float(origins[3] @ a) * a
    origins[3] = origins[3] - along
    origins[4] = origins[4] + along
    # A6: the part of the flange offset along its axis goes to A6's origin
    a = axes[5]
    along = float(flange[:3, 3] @ a) * a
    origins[5] = origins[5] + along
    flange[:3, 3] = flange[:3, 3] - along
    clean = [np.round(v, 9) + 0.0 for v in origins]
    clean_axes = [np.where(np.abs(v) < 1e-12, 0.0, np.round(v, 12)) + 0.0 for v in axes]
    flange[np.abs(flange) < 1e-12] = 0.0
    return clean, clean_axes, flange


@dataclass(frozen=True)
class OpwForm:
    """An arm in the OPW form: ``FLANGE = base · OPW(q) · end`` (None = identity).

    ``params`` has the lengths (mm), ``OPW_OFFSETS_DEG`` and the axis signs found from the
    geometry; ``phi_deg`` is A3 where the wrist point lies on the line A2-A3 (S bit 1,
    robot-model.md §8)."""

    params: OPWParams
    base: np.ndarray | None
    end: np.ndarray | None
    phi_deg: float


def _unit_sign(v: np.ndarray, axis: int) -> int | None:
    """+1/-1 when `v` is the unit vector along coordinate `axis` (or its opposite), else None."""
    others = [abs(float(v[k])) for k in range(3) if k != axis]
    if max(others) > _GEOM_EPS or abs(abs(float(v[axis])) - 1.0) > _GEOM_EPS:
        return None
    return 1 if v[axis] > 0 else -1


def opw_form(chain: Chain) -> OpwForm | None:
    """The OPW form of `chain` (module docstring), or None when its geometry at A = 0 is not
    ortho-parallel with a spherical wrist: A1 vertical; A2 and A3 parallel to each other and
    perpendicular to A1 with the link between them perpendicular to both; A4 and A6 along the
    forearm, A5 perpendicular to them, all three through one point."""
    F = chain.frames()
    u = chain.local_axes()
    if _unit_sign(u[0], 2) is None:
        return None
    base: np.ndarray | None = F[0]
    c1_add = 0.0
    if np.abs(F[0][:3, :3] - np.eye(3)).max() < 1e-15 and abs(F[0][0, 3]) + abs(F[0][1, 3]) == 0.0:
        base, c1_add = None, float(F[0][2, 3])
    R = np.eye(3)
    p = np.zeros(3)
    pts, dirs = [], []
    for i in range(ARM_AXES):
        if i > 0:
            p = p + R @ F[i][:3, 3]
            R = R @ F[i][:3, :3]
        pts.append(p.copy())
        dirs.append(R @ u[i])
    signs = [_unit_sign(dirs[0], 2), _unit_sign(dirs[1], 1), _unit_sign(dirs[2], 1),
             _unit_sign(dirs[3], 0), _unit_sign(dirs[4], 1), _unit_sign(dirs[5], 0)]
    if any(s is None for s in signs):
        return None
    p2, p3, p4, p5, p6 = pts[1], pts[2], pts[3], pts[4], pts[5]
    # the link A2-A3 along x; the wrist axes A4, A6 on one line; A5 crossing it
    if abs(p3[2] - p2[2]) > _GEOM_EPS or abs(p3[0] - p2[0]) < _GEOM_EPS:
        return None
    if abs(p6[1] - p4[1]) > _GEOM_EPS or abs(p6[2] - p4[2]) > _GEOM_EPS or abs(p5[2] - p4[2]) > _GEOM_EPS:
        return None
    wc = np.array([p5[0], p4[1], p4[2]])
    flange = np.eye(4)
    flange[:3, :3] = R @ F[6][:3, :3]
    flange[:3, 3] = p + R @ F[6][:3, 3]
    # OPW's end frame at A = 0: at the wrist point, +Z along the forearm, +X down (Ry(90 deg))
    canon = np.eye(4)
    canon[:3, :3] = Rotation.from_euler("y", 90.0, degrees=True).as_matrix()
    canon[:3, 3] = wc
    end = np.linalg.inv(canon) @ flange
    end[np.abs(end) < 1e-12] = 0.0
    c4 = 0.0
    if np.abs(end[:3, :3] - np.eye(3)).max() < 1e-12 and abs(end[0, 3]) + abs(end[1, 3]) < _GEOM_EPS:
        c4, end = float(end[2, 3]), None
    a2 = -(float(wc[2]) - float(p3[2]))
    c3 = float(wc[0]) - float(p3[0])
    params = OPWParams(a1=float(p2[0]), a2=a2, b=float(wc[1]), c1=float(p2[2]) + c1_add,
                       c2=float(p3[0]) - float(p2[0]), c3=c3, c4=c4, offsets_deg=OPW_OFFSETS_DEG,
                       sign_corrections=tuple(int(s) for s in signs))   # type: ignore[arg-type]
    phi = -math.degrees(math.atan2(a2, c3)) * signs[2]
    return OpwForm(params, base, end, phi)


__all__ = ["Chain", "OPW_OFFSETS_DEG", "OpwForm", "chain_forward", "chain_to_joints", "opw_form"]
