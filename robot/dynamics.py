"""The arm's inertia, for the accelerations a synchronised PTP can have (issue 60).

A KR C4 takes a PTP's accelerations from its dynamic model: on the real KR 3 R540 an axis moving
alone at one pose accelerates at a fixed rate, but moving A2 and A3 together the same way (HOME to
{A2 -130, A3 80}) takes 24 % longer than either alone, and A1 swings the folded arm faster than
the stretched one (KUKA Trace recordings, tools/identify_kr3.py). :class:`Inertia` models that
with the arm's mass matrix: the links' masses, centres of mass and inertia tensors (in the joint
chain's link frames, robot/kinematics/joints.py) and each axis' motor inertia seen at the axis
(``rotor``), all identified for a robot (robot/identified.py ``dynamics``).

:meth:`Inertia.ptp_acceleration` gives the normalised acceleration (1/s²) of a synchronised PTP
from ``q0`` to ``q1``: with ``H = M(q) + diag(rotor)`` at the middle of the motion (``q`` in
rad), axis ``i`` needs the torque ``|(H·Δq)_i|·ü`` for the normalised acceleration ``ü`` and has
``τ_i`` (its *acceleration torque*: what its identified single-axis acceleration times its
inertia at the pose it was identified at gives), so ``ü ≤ τ_i·f_i/|(H·Δq)_i|`` with ``f_i`` the
axis' acceleration factor (``$ACC_AXIS``, the override's square). Gravity and the velocity terms
are left out (simplified).

Units: mm and deg at the interface; kg, m, rad inside.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from .kinematics.joints import JointChain


class Inertia:
    """The mass matrix of the arm of `machine` from its ``dynamics`` (robot/identified.py):
    ``link_mass_kg`` (n,), ``link_com_mm`` (n, 3), ``link_inertia_kg_m2`` (n, 6: xx, yy, zz, xy,
    xz, yz about the centre of mass), ``rotor_inertia_kg_m2`` (n,), ``torque_nm`` (n,)."""

    def __init__(self, machine: Any, dynamics: dict[str, Any]) -> None:
        self.chain = JointChain(machine)
        self.n = self.chain.n
        self.mass = np.asarray(dynamics["link_mass_kg"], dtype=float)
        self.com = np.asarray(dynamics["link_com_mm"], dtype=float) / 1000.0
        i6 = np.asarray(dynamics["link_inertia_kg_m2"], dtype=float)
        self.inertia = np.array([[[a[0], a[3], a[4]], [a[3], a[1], a[5]], [a[4], a[5], a[2]]] for a in i6])
        self.rotor = np.asarray(dynamics["rotor_inertia_kg_m2"], dtype=float)
        self.torque = np.asarray(dynamics["torque_nm"], dtype=float)

    def _frames(self, a_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(R (n, 3, 3), p (n, 3) m of each link frame after its joint, z (n, 3) its joint's axis)
        in the robot's base frame."""
        c = self.chain
        R, p = np.eye(3), np.zeros(3)
        Rs, ps, zs = [], [], []
        for i in range(self.n):
            p = p + R @ (c.origins[i] / 1000.0)
            R = R @ c.R_origin[i]
            z = R @ c.axes[i]
            R = R @ Rotation.from_rotvec(c.axes[i] * np.radians(c.kuka_sign[i] * a_deg[i])).as_matrix()
            Rs.append(R)
            ps.append(p)
            zs.append(z)
        return np.array(Rs), np.array(ps), np.array(zs)

    def mass_matrix(self, a_deg: np.ndarray) -> np.ndarray:
        """M(a) (n, n), kg·m², for the axes `a_deg` (deg): sum over the links of
        ``Jv^T m Jv + Jw^T R I R^T Jw`` (the links' Jacobians at their centres of mass), without
        the rotor inertias."""
        R, p, z = self._frames(np.asarray(a_deg, dtype=float))
        n = self.n
        M = np.zeros((n, n))
        for k in range(n):
            c = p[k] + R[k] @ self.com[k]
            Jv = np.zeros((3, n))
            Jw = np.zeros((3, n))
            for j in range(k + 1):
                Jw[:, j] = z[j] * self.chain.kuka_sign[j]
                Jv[:, j] = np.cross(Jw[:, j], c - p[j])
            Iw = R[k] @ self.inertia[k] @ R[k].T
            M += self.mass[k] * Jv.T @ Jv + Jw.T @ Iw @ Jw
        return M

    def ptp_accelerations(self, q0: np.ndarray, q1: np.ndarray, factor: np.ndarray) -> np.ndarray:
        """The normalised acceleration (1/s², (n,)) each axis allows a synchronised PTP from `q0`
        to `q1` (deg; the module's docstring); `factor` (n,) each axis' acceleration factor. inf
        for an axis that needs no torque."""
        q0 = np.asarray(q0, dtype=float)[:self.n]
        dq = np.radians(np.asarray(q1, dtype=float)[:self.n] - q0)
        H = self.mass_matrix(q0 + 0.5 * np.degrees(dq)) + np.diag(self.rotor)
        need = np.abs(H @ dq)
        cap = self.torque * np.asarray(factor, dtype=float)[:self.n]
        with np.errstate(divide="ignore"):
            return np.where(need > 1e-12, cap / np.maximum(need, 1e-300), np.inf)

    def ptp_acceleration(self, q0: np.ndarray, q1: np.ndarray, factor: np.ndarray) -> float:
        """The normalised acceleration (1/s²) of a synchronised PTP from `q0` to `q1`: the least
        of :meth:`ptp_accelerations`. inf when nothing moves."""
        return float(np.min(self.ptp_accelerations(q0, q1, factor)))


__all__ = ["Inertia"]
