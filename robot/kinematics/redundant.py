"""The seven-axis arm (family ``"redundant"``: KUKA's LBR iiwa, seven revolute joints J1..J7):
its redundancy held, the six other joints solved numerically.

A seven-axis arm reaches a flange pose with a one-parameter family of configurations. The rule
here (docs/robot.md "Seven-axis arms"; robot/axismap.py carries J3 as KRL's E1): the Cartesian
inverse leaves the redundancy joint J3 where the reference has it and solves J1, J2, J4..J7 — as
KUKA's LBR iiwa does ("only the joints J1, J2 and J4 - J7 are used from the IK. J3 remains
unaffected": robot-forum.com, "automatically Redundancy usage", 2018). So a LIN or CIRC keeps E1
at its value at the motion's start, a PTP to an E6AXIS sets it, and a Cartesian PTP keeps it.

The six free joints are solved by Newton steps on the geometric Jacobian of the joints' chain
(robot/kinematics/joints.py: origins, axes, the flange frame) with Levenberg-Marquardt damping
near a singularity, from the reference (and from HOME with the reference's J3), until the flange
is within 1e-9 mm and 1e-12 rad; a solution is kept when its flange is within 1e-6 mm and 1e-9 of
the target's rotation (robot/kinematics/numeric.py's tolerance for the six-axis numeric family).

Status S (a decision: KUKA's six-axis bits on the arm's elbow and wrist): bit 1 = J4 < 0 (KRL's
A3), bit 2 = J6 < 0 (KRL's A5); bit 0 (overhead) selects nothing (``s_free``). Turn T: bit i =
A(i+1) < 0 over KRL's A1..A6 (J1, J2, J4..J7); J3 has no turn bit (it is held).

Units: mm and deg. n = 7.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ..axismap import REDUNDANT_SLOTS, ROBOT_KEYS
from ..errors import SoftLimitError, WorkspaceError
from .family import KinematicFamily, inverse_rows_many, select

#: the joint a seven-axis arm's inverse holds (J3, KRL's E1)
HELD = REDUNDANT_SLOTS.index("E1")
#: the joints the inverse solves, in KRL's A1..A6 order
FREE = tuple(REDUNDANT_SLOTS.index(k) for k in ROBOT_KEYS)
#: a seed's bend from HOME (deg; J2, J4, J6: the elbow and the wrist off their stretched line)
BENT = np.array([0.0, 30.0, 0.0, -60.0, 0.0, 45.0, 0.0])
#: Newton steps per seed (2-4 from a LIN's previous sample; near the stretched elbow, where the damping
#: slows the steps, a few hundred)
MAX_STEPS = 400
#: convergence: position (mm) and rotation (rad) errors
_TOL_MM, _TOL_RAD = 1e-9, 1e-12
#: the largest error of a kept solution (robot/kinematics/numeric.py's)
_KEEP_MM, _KEEP_R = 1e-6, 1e-9


def _turn_bits_model(turn: int) -> int:
    """KRL's T (bit i: A(i+1) < 0) as bits over the model's joints J1..J7."""
    return sum(1 << j for i, j in enumerate(FREE) if (int(turn) >> i) & 1)


class Redundant(KinematicFamily):
    """The seven-axis family (module docstring)."""

    name = "redundant"
    title = "numeric (seven-axis arm; the redundancy J3 held, carried as E1)"
    s_free = 1
    t_free = 1 << HELD

    @classmethod
    def geometry(cls, values: dict[str, Any], source: str, prov: dict[str, str], a4fix: bool,
                 a5link: bool) -> None:
        """Machine data never describe a seven-axis arm here: None (a description does:
        robot/description.py)."""
        return None

    @classmethod
    def detect(cls, kin: Any) -> Any:
        j = kin.joints
        return True if j.n == len(REDUNDANT_SLOTS) and not j.any_linear else None

    def __init__(self, kin: Any, found: Any = None) -> None:
        super().__init__(kin, found)
        x, y, z = kin.joints.axes.T
        zero = np.zeros_like(x)
        #: each joint's unit axis as a cross-product matrix (7, 3, 3)
        self._K = np.stack([np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1), np.stack([-y, x, zero], -1)], 1)

    joints_forward = True

    def forward(self, a: np.ndarray) -> np.ndarray:
        return self.kin.joints.forward(np.asarray(a, dtype=float))

    def forward_many(self, A: np.ndarray) -> np.ndarray:
        return self.kin.joints.forward_many(A)

    def _frames(self, a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(joint positions (7, 3) mm, joint axes (7, 3) in $ROBROOT, flange 4x4) of axes `a`
        (each joint's rotation by Rodrigues' formula about its unit axis)."""
        j = self.kin.joints
        q = j.kuka_sign * np.radians(a)
        s, c = np.sin(q), np.cos(q)
        R, p = np.eye(3), np.zeros(3)
        pts, axes = np.empty((j.n, 3)), np.empty((j.n, 3))
        for i in range(j.n):
            p = p + R @ j.origins[i]
            if j.origin_rot:
                R = R @ j.R_origin[i]
            pts[i], axes[i] = p, j.kuka_sign[i] * (R @ j.axes[i])
            K = self._K[i]
            R = R @ (np.eye(3) + s[i] * K + (1.0 - c[i]) * (K @ K))
        T = np.eye(4)
        T[:3, :3] = R @ j.R_flange
        T[:3, 3] = p + R @ j.p_flange
        return pts, axes, T

    def solve(self, T: np.ndarray, seed: np.ndarray) -> np.ndarray | None:
        """The axes (deg) reached from `seed` (J3 held at the seed's) whose flange is `T`, or None."""
        a = np.asarray(seed, dtype=float).copy()
        free = list(FREE)
        for _ in range(MAX_STEPS):
            pts, axes, F = self._frames(a)
            dp = T[:3, 3] - F[:3, 3]
            dr = Rotation.from_matrix(T[:3, :3] @ F[:3, :3].T).as_rotvec()
            if float(np.abs(dp).max()) < _TOL_MM and float(np.abs(dr).max()) < _TOL_RAD:
                break
            w, r = axes[free], F[:3, 3] - pts[free]
            J = np.empty((6, len(free)))
            J[0] = w[:, 1] * r[:, 2] - w[:, 2] * r[:, 1]
            J[1] = w[:, 2] * r[:, 0] - w[:, 0] * r[:, 2]
            J[2] = w[:, 0] * r[:, 1] - w[:, 1] * r[:, 0]
            J[3:] = w.T
            J[:3] /= 1000.0                                   # mm -> m: both rows of one scale
            e = np.concatenate([dp / 1000.0, dr])
            lam = 1e-6 if np.linalg.cond(J) < 1e6 else 1e-3
            step = np.linalg.solve(J.T @ J + lam * np.eye(len(free)), J.T @ e)
            a[free] += np.degrees(np.clip(step, -0.5, 0.5))
        a = -((-a + 180.0) % 360.0) + 180.0
        F = self.forward(a)
        if not np.all(np.isfinite(a)) or float(np.abs(F[:3, 3] - T[:3, 3]).max()) > _KEEP_MM \
                or float(np.abs(F[:3, :3] - T[:3, :3]).max()) > _KEEP_R:
            return None
        return a

    def solutions(self, flange_T: np.ndarray, ref: np.ndarray | None) -> list[list[float]]:
        """The distinct solutions (J1..J7, deg, wrapped) reached from the reference, from HOME and
        from HOME bent both ways (:data:`BENT`: an LBR's HOME is the stretched, singular pose), all
        with the reference's J3 (HOME's without a reference)."""
        T = np.asarray(flange_T, dtype=float)
        home = np.array(self.kin._home, dtype=float)
        seeds = [home, home + BENT, home - BENT]
        if ref is not None:
            for seed in seeds:
                seed[HELD] = float(ref[HELD])
            seeds.insert(0, np.asarray(ref, dtype=float))
        out: list[list[float]] = []
        for s in seeds:
            q = self.solve(T, s)
            if q is None or any(max(abs(math.remainder(x - y, 360.0)) for x, y in zip(q, r)) < 1e-6 for r in out):
                continue
            out.append([float(v) for v in q])
        return out

    def status_turn(self, q: np.ndarray) -> tuple[int, int]:
        q = np.asarray(q, dtype=float)
        s = (2 if q[FREE[2]] < 0 else 0) | (4 if q[FREE[4]] < 0 else 0)
        t = sum(1 << i for i, j in enumerate(FREE) if q[j] < 0)
        return s, t

    def inverse(self, flange_T: np.ndarray, status: int | None, turn: int | None,
                ref: np.ndarray | None) -> np.ndarray:
        if ref is None:
            ref = self.kin._home.copy()
        tb = None if turn is None else _turn_bits_model(turn)
        near = self.solve(np.asarray(flange_T, dtype=float), ref)
        if near is not None:
            # the solution reached from the reference (a LIN's previous sample): when its S, T fit
            try:
                return select(self, [[float(v) for v in near]], status, tb, ref)
            except (WorkspaceError, SoftLimitError):
                pass
        rows = self.solutions(flange_T, ref)
        if not rows:
            raise WorkspaceError("workspace error: target not reachable")
        return select(self, rows, status, tb, ref)

    inverse_many = inverse_rows_many

    def wrist_point_x(self, q) -> float:
        """x of the wrist point (J6's origin) in the J1 frame, mm."""
        pts, _, _ = self._frames(np.asarray(q, dtype=float))
        a1 = math.radians(float(q[0]) * self.kin.joints.kuka_sign[0])
        return float(math.cos(a1) * pts[5][0] + math.sin(a1) * pts[5][1])

    def describe(self) -> list[str]:
        return ["redundancy: J3 held at the motion's start (KRL's E1); J1, J2, J4..J7 solved (Newton, "
                "geometric Jacobian)"]


__all__ = ["FREE", "HELD", "MAX_STEPS", "Redundant"]
