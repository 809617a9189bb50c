"""The robot as the planner sees it (issue 76: out of robot/planner.py): :class:`RobotModel`,
the adapter between the planner and the kinematics (mm, deg, 4x4 frames; the robot's axes A1..An,
then the external axes E1..En), and its view with a ``$BASE`` on a BASE kinematic."""

from __future__ import annotations

from typing import Any

import numpy as np

from .errors import RobotError, SoftLimitError, WorkspaceError
from .frames import frame_to_matrix, inv_pos
from .planmemo import _BOTTOM_ROW
from . import kinematics
from .axismap import AxisMap
from .external import ExternalAxes
from .kinematics import Kinematics
from .limits import DEFAULT_MODE
from .machinememo import derived


#: Passes of the batched IK chain (:meth:`RobotModel.ik_chain`) before it gives up and the
#: chain is solved pose by pose (each pass fixes at least one more row).
IK_CHAIN_PASSES = 6
#: Shortest chain solved at once: below it numpy's fixed cost per pass (two passes at least)
#: is more than the per-pose solves (measured 2026-11-24: even at 40 poses, about 1.1x slower).
MIN_CHAIN = 64


def _constants(machine: Any, n: int) -> tuple:
    """(``$ROBROOT`` 4x4, whether it is the null frame, its inverse, the external axis count, the
    AxisMap, the axes' speeds (deg/s, mm/s) and accelerations, their PTP approximation distances
    (deg; an external axis 90), the external axes' lower and upper limits (None without)) of
    `machine` with `n` robot axes: :class:`RobotModel`'s, derived once per machine."""
    robroot_T = frame_to_matrix(*machine.robroot_frame)
    n_ext = len(getattr(machine, "external_axes", ()))
    axes = AxisMap.of(machine)
    axes._index.flags.writeable = False
    e_lo = e_hi = None
    if n_ext:
        v_max = np.array(machine.all_max_speed, dtype=float)
        a_max = np.array(machine.all_max_acc, dtype=float)
        apo = np.array(list(machine.apo_dis_ptp_deg)[:n] + [90.0] * n_ext, dtype=float)
        e_lo = np.array([e.limit[0] for e in machine.external_axes], dtype=float)
        e_hi = np.array([e.limit[1] for e in machine.external_axes], dtype=float)
    else:
        v_max = np.array(machine.max_speed_deg_s, dtype=float)
        a_max = np.array(machine.max_acc_deg_s2, dtype=float)
        apo = np.array(machine.apo_dis_ptp_deg[:n], dtype=float)
    return (robroot_T, bool(np.allclose(robroot_T, np.eye(4))), inv_pos(robroot_T), n_ext, axes, v_max, a_max, apo,
            e_lo, e_hi)


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
        # what the machine data alone give, the same read-only objects for every model of this
        # machine (robot/machinememo.py): $ROBROOT and its inverse, where each axis sits in KRL's
        # E6AXIS (robot/axismap.py: the one mapping), the axes' speeds, accelerations, PTP
        # approximation distances and the external axes' limits
        (self.robroot_T, self._robroot_is_null, self._robroot_inv_T, self.n_ext, self.axes, self.v_max, self.a_max,
         self.apo_dis_ptp, self._e_lo, self._e_hi) = derived(machine, "robot model", lambda: _constants(machine, self.n))
        #: external axes (robot/external.py), None without; axis vectors are A1..An, E1..En
        self.ext = None
        self._ersys = False
        if self.n_ext:
            self.ext = ExternalAxes(machine)
            self._ersys = self.ext.robroot_kin is not None

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
        the compiled inverse (robot/kinematics/fastpath.py) solves one pose faster than numpy's
        passes over a chain, measured);
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

    def tcp_points(self, q0: np.ndarray, dq: np.ndarray, us: np.ndarray, tool_T: np.ndarray,
                   base_inv_T: np.ndarray) -> np.ndarray | None:
        """TCP positions (m, 3), mm in $BASE, of the axes ``q0 + u * dq`` for each u of `us` ((m,)):
        :meth:`tcp`'s translations bit for bit, in one call (robot/kinematics ``Kinematics.tcp_points``:
        a PTP motion's path-length table); None where the products would not be the same calls (a
        $ROBROOT on external axes, a linked $BASE, frames that are not C-contiguous float64) or the
        family's forward is not the joints' (the caller then calls :meth:`tcp` point by point)."""
        if self._ersys or type(self) is not RobotModel or not (_c_frame(tool_T) and _c_frame(base_inv_T)):
            return None
        robroot = None if self._robroot_is_null else self.robroot_T
        if robroot is not None and not _c_frame(robroot):
            return None
        return self.kin.tcp_points(q0, dq, us, robroot, base_inv_T, tool_T)

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


def _c_frame(T: Any) -> bool:
    """`T` is a C-contiguous float64 4x4 array (numpy multiplies it by ``cblas_dgemm`` as it stands)."""
    return (isinstance(T, np.ndarray) and T.dtype == np.float64 and T.shape == (4, 4)
            and T.flags.c_contiguous)


__all__ = ["RobotModel", "IK_CHAIN_PASSES", "MIN_CHAIN"]
