"""Forward and inverse kinematics of any robot model (:class:`~robot.machine.MachineData`: the
KR 6 R900 yaml or a backup's machine data) in KUKA's conventions.

Sources: robot-model.md §2-§4 (chain, OPW parameters), §7 (frame chain), §8 (status S and
turn T), reference §6.4-§6.5 and §8.2 (errors).

Units: mm and degrees everywhere (axis values A1..An in deg, a linear axis in mm, frames as
4x4 homogeneous transforms in mm). The FLANGE frame is KUKA's flange (= URDF ``tool0``: +Z
out of the flange), expressed in ``$ROBROOT``. n is the robot's axis count,
``len(machine.joints)`` (:attr:`Kinematics.n_axes`): six for the arms and the palletizers (whose
fixed A4 and led A5 keep KUKA's axis numbers), four for a SCARA; external axes E1..E6 are not
part of it (robot/external.py).

The package:

* :class:`Kinematics` (here): one robot's kinematics; it chooses the robot's kinematic family
  from its machine data (never from its name) and holds what every family shares: the joints
  (robot/kinematics/joints.py), the soft limits, HOME, the frame chain ``$BASE``/``$TOOL``/
  ``$ROBROOT``, the memo of recent forward results;
* robot/kinematics/family.py: the protocol every family implements (detect, forward, inverse,
  inverse of many, status and turn) and the selection by S and T they share;
* one module per family: opw.py (six axes, spherical wrist), palletizer4.py, palletizer5.py,
  numeric.py (any other six-axis arm); robot/kinematics/families.py registers them.

The OPW family's inverse runs robot/kinematics/fastpath.py and the joints' forward robot/ipocycle.py,
each compiled from its Python file when it is built and current (robot/kinematics/compiled.py
:func:`fastpath_compiled`, ``pure_module``), else as Python: the same results bit for bit
(tests/robot/test_simcore.py).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import SoftLimitError
from ..frames import as_matrix, inv_pos, matrix_to_frame
from ..machine import MachineData, load_machine
from ..machinememo import derived
from ..madavalues import MachineDataError
from .constants import BOUNDARY_EPS, LIMIT_EPS_DEG, OVERHEAD_SINGULAR_MM, WRIST_SINGULAR_DEG

from . import compiled  # noqa: F401  (the switch: compiled.USE_COMPILED)
from .compiled import compiled_module, fastpath_compiled, fastpath_module  # noqa: F401
from .families import FAMILIES
from .joints import JointChain

_F64 = np.dtype(np.float64)

#: Results :meth:`Kinematics.forward` keeps (by the axes' bytes; cleared when full).
FK_MEMO = 256


def _limits(m: MachineData, joints: JointChain) -> tuple:
    """The soft limits of the machine data `m` (``$SOFTN_END``, ``$SOFTP_END``) as arrays and
    lists (within LIMIT_EPS_DEG and exact), HOME, the ±360° variants a choice of axes tries
    (per axis: a linear axis has none, itself; and as (n, 5) rows, inf where a linear axis has
    no variant): :class:`Kinematics`'s, derived once per machine (robot/machinememo.py)."""
    n = joints.n
    lo = np.array([j.limit_deg[0] for j in m.joints], dtype=float)
    hi = np.array([j.limit_deg[1] for j in m.joints], dtype=float)
    home = np.array(m.home_deg, dtype=float)[:n]
    ks = np.arange(-2, 3) * 360.0
    ks_l = [float(v) for v in ks]
    rows = np.where(joints.linear[:, None] & (ks[None, :] != 0.0), np.inf, ks[None, :] + np.zeros((n, 1)))
    return (lo, hi, home, ks, [float(v) for v in lo], [float(v) for v in hi],
            [float(v) - LIMIT_EPS_DEG for v in lo], [float(v) + LIMIT_EPS_DEG for v in hi], ks_l,
            [(0.0,) if lin else ks_l for lin in joints.linear], rows)


class Kinematics:
    """Kinematics of one robot, built from :class:`~robot.machine.MachineData`.

    Public methods: :meth:`forward`, :meth:`forward_many`, :meth:`solutions`, :meth:`inverse`,
    :meth:`inverse_many`, :meth:`inverse_chain`, :meth:`status_turn`, :meth:`check_soft_limits`,
    :meth:`within_limits`, :meth:`tcp_pose`, :meth:`flange_target`, :meth:`pos_act`,
    :meth:`wrist_point_x`. :attr:`family` names the kinematic family, :attr:`impl` is its solver.

    Raises robot.mada.MachineDataError when the machine data's chain is not one its family's
    closed form covers (the palletizers).
    """

    def __init__(self, machine: MachineData | None = None) -> None:
        self.machine = machine if machine is not None else load_machine()
        m = self.machine
        self.joints = JointChain(m)
        #: the robot's axis count (A1..An; the external axes are not counted)
        self.n_axes = self.joints.n
        self._shape = (self.n_axes,)        # a reference's shape as it stands (inverse_or_error)
        # the soft limits, HOME and the ±360° variants: the machine data's, read-only and the
        # same objects for every Kinematics of this machine (robot/machinememo.py)
        (self._lo, self._hi, self._home, self._ks, self._lo_l0, self._hi_l0, self._lo_l, self._hi_l, self._ks_l,
         self._ks_axes, self._ks_rows) = derived(m, "kinematics limits", lambda: _limits(m, self.joints))
        #: FLANGE of recent forward() axes, by their bytes (a robot at rest asks for the same axes
        #: every IPO cycle; a program's cycle plans the same points again); at most FK_MEMO
        self._fk_memo: dict[bytes, np.ndarray] = {}
        self._fk = self.joints.forward
        #: the kinematic family's solver (robot/kinematics/family.py), this object's own (its
        #: scratch rows); which family and its parameters are found once per machine
        self.impl: Any = None
        fam, found = derived(m, "kinematic family", self._choose_form if m.chain is not None else self._declared_family)
        if self.impl is None:
            self.impl = fam(self, found)
        self._fk = self.impl.forward

    def _choose_form(self) -> tuple[Any, Any]:
        """The kinematic family of a robot from machine data and what its constructor takes
        (its ``detect``'s answer): the first of robot/kinematics/families.py whose ``detect``
        answers for it; its closed form is checked against the machine data's chain where the
        family says so (``check``). Sets :attr:`impl`. Raises robot.mada.MachineDataError when
        no family takes it."""
        m = self.machine
        for fam in FAMILIES:
            found = fam.detect(self)
            if found is not None:
                self.impl = fam(self, found)
                self.impl.check(m.provenance.get("$DEF_A4FIX", m.source))
                return fam, found
        raise MachineDataError(f"{m.source or m.name}: no kinematic family of robot/kinematics/families.py "
                               f"takes this robot ({self.n_axes} axes)")

    def _declared_family(self) -> tuple[Any, Any]:
        """The family of a robot YAML (robot/machine.py; no machine data to detect it from) and
        what its constructor takes: the one its ``family`` key names, by default ``opw`` (the
        yaml's ``opw`` parameters). Sets :attr:`impl`."""
        name = str(self.machine.raw.get("family", "opw"))
        for fam in FAMILIES:
            if fam.name == name:
                found = fam.detect(self)
                if found is not None:
                    self.impl = fam(self, found)
                    return fam, found
        raise ValueError(f"{self.machine.source or self.machine.name}: family {name!r} does not take this robot")

    @property
    def family(self) -> str:
        """The kinematic family's name: ``"opw"``, ``"palletizer4"``, ``"palletizer5"``,
        ``"numeric"``, ... (robot/kinematics/families.py)."""
        return self.impl.name

    @property
    def phi_deg(self) -> float:
        """The switching angle of S bit 1 (deg) of a family with the OPW arm's status."""
        return self.impl.solver.phi_deg

    # ------------------------------------------------------------------ FK
    def forward(self, axes_deg: Sequence[float]) -> np.ndarray:
        """FLANGE(A1..An): KUKA flange frame in ``$ROBROOT`` (robot-model.md §2-§3).

        Args:
            axes_deg: A1..An in degrees (a linear axis in mm); values past n are ignored.
        Returns:
            4x4 homogeneous transform, translation in mm.

        Recent results are kept by the axes' bytes (at most :data:`FK_MEMO`): a robot at rest
        asks for the same axes every IPO cycle, and a program's cycle plans the same points again.
        """
        a = np.asarray(axes_deg, dtype=float)[:self.n_axes]
        key = a.tobytes()
        known = self._fk_memo.get(key)
        if known is not None:
            return known.copy()
        T = self._fk(a)
        if len(self._fk_memo) >= FK_MEMO:
            self._fk_memo.clear()
        self._fk_memo[key] = T.copy()
        return T

    def tcp_points(self, q0: np.ndarray, dq: np.ndarray, us: np.ndarray, robroot: np.ndarray | None,
                   base_inv: np.ndarray, tool: np.ndarray) -> np.ndarray | None:
        """TCP positions (m, 3), mm, of the axes ``q0 + u * dq`` for each u of `us` ((m,)):
        ``(base_inv @ (robroot @ forward(q))) @ tool``'s translation, bit for bit (`robroot` None:
        :meth:`forward` alone; 4x4 frames), in one call (robot/kinematics/joints.py
        ``JointChain.tcp_points``); None for a family whose forward is not the joints' (the
        caller then calls :meth:`forward` point by point)."""
        if not self.impl.joints_forward:
            return None
        return self.joints.tcp_points(q0, dq, us, robroot, base_inv, tool)

    def forward_many(self, axes_deg: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`forward`: axes (N, n) in deg -> flange frames (N, 4, 4), mm."""
        return self.impl.forward_many(np.atleast_2d(np.asarray(axes_deg, dtype=float))[:, :self.n_axes])

    # ------------------------------------------------------------------ S/T
    def wrist_point_x(self, axes_deg: Sequence[float]) -> float:
        """x of the wrist point in the A1 frame, mm (robot-model.md §4.4; S bit 0)."""
        return self.impl.wrist_point_x(axes_deg)

    def status_turn(self, axes_deg: Sequence[float]) -> tuple[int, int]:
        """Status S and turn T of an axis configuration (robot-model.md §8, reference §6.5), as
        the robot's family defines them. For the arms: S bit 0 = 1 if the wrist point is behind
        the A1 axis (overhead area); bit 1 = 1 if A3 >= phi (4.764° on the KR 6 R900); bit 2 =
        1 if A5 < 0 (A5 = 0 counts as 0, matching the HOME test vector S = 2). T bit i = 1 if
        A(i+1) < 0 (0 counts as positive). Values within 1e-9 deg/mm of a switching point count
        as on its non-negative side (floating-point noise).

        Returns:
            (S, T) as ints.
        """
        return self.impl.status_turn(np.asarray(axes_deg, dtype=float)[:self.n_axes])

    # ------------------------------------------------------------------ limits
    def check_soft_limits(self, axes_deg: Sequence[float]) -> None:
        """Raise :class:`~robot.errors.SoftLimitError` for the first axis outside
        ``$SOFTN_END``/``$SOFTP_END`` (reference §8.2): message
        ``"software limit switch +A1"`` / ``"... -A2"``. Returns None otherwise."""
        # as Python floats against the limits as lists (the same doubles: _lo_l is each _lo - eps)
        q = np.asarray(axes_deg, dtype=float)[:self.n_axes].tolist()
        lo, hi = self._lo_l, self._hi_l
        for i in range(self.n_axes):
            if q[i] < lo[i]:
                raise SoftLimitError(i + 1, q[i], positive=False)
            if q[i] > hi[i]:
                raise SoftLimitError(i + 1, q[i], positive=True)

    def within_limits(self, axes_deg: Sequence[float]) -> bool:
        """True if every axis lies within its soft limits."""
        q = np.asarray(axes_deg, dtype=float)[:self.n_axes]
        return bool(np.all(q >= self._lo - LIMIT_EPS_DEG) and np.all(q <= self._hi + LIMIT_EPS_DEG))

    # ------------------------------------------------------------------ IK
    def solutions(self, flange_T: np.ndarray) -> list[np.ndarray]:
        """All analytic solutions for a flange pose (robot-model.md §4.2, §8).

        Args:
            flange_T: 4x4 flange frame in ``$ROBROOT``, mm.
        Returns:
            list of up to 8 arrays of shape (n,), A1..An in deg wrapped to (-180, 180], any
            order, before soft-limit filtering and without the ±360° variants. Empty if the pose
            is out of reach. At a singularity the split of the free angles is arbitrary.
        """
        rows = self.impl.solutions(flange_T, None)
        return [row.copy() for row in (np.array(rows) if rows else np.empty((0, self.n_axes)))]

    def inverse(self, flange_T: np.ndarray, status: int | None = None, turn: int | None = None,
                reference_deg: Sequence[float] | None = None) -> np.ndarray:
        """Axis values for a flange pose, selected by status and turn (robot-model.md §8,
        reference §6.5; robot/kinematics/family.py ``select``).

        Args:
            flange_T: 4x4 flange frame in ``$ROBROOT``, mm.
            status: S; bits 0..2 select the IK branch (masked with 7). None: keep
                the status of ``reference_deg`` (a bit whose switching point the
                reference sits on, e.g. A5 = 0 for bit 2, is left free).
            turn: T; bit i = 1 means A(i+1) < 0, selecting the ±360° variant of
                each axis. None: each axis takes the value nearest to
                ``reference_deg`` (shortest axis motion).
            reference_deg: current axes A1..An (deg); default HOME. Also supplies
                the free angle at singularities (A4 when A5 = 0, A1 when the wrist
                point is on the A1 axis).
        Returns:
            array (n,) A1..An in deg.
        Raises:
            WorkspaceError: no solution (out of reach) or none with the requested S.
            SoftLimitError: the solution(s) with the requested S/T violate
                ``$SOFTN_END``/``$SOFTP_END``.
        """
        ref = None if reference_deg is None else np.asarray(reference_deg, dtype=float)[:self.n_axes]
        return self.impl.inverse(flange_T, status, turn, ref)

    def inverse_or_error(self, flange_T: np.ndarray, status: int | None = None, turn: int | None = None,
                         reference_deg: Sequence[float] | None = None) -> tuple[np.ndarray | None, type | None]:
        """:meth:`inverse` without raising: ``(axes, None)``, or ``(None, the class of the error
        it would raise)`` (robot/kinematics/family.py ``Family.inverse_or_error``; INVERSE's STATUS).
        A float64 array of the robot's axes is the reference as it stands (the slice :meth:`inverse`
        takes would be a view of the same numbers: a status/turn search calls this 512 times a point)."""
        ref = reference_deg
        if ref is not None and not (ref.__class__ is np.ndarray and ref.dtype is _F64 and ref.shape == self._shape):
            ref = np.asarray(ref, dtype=float)[:self.n_axes]
        return self.impl.inverse_or_error(flange_T, status, turn, ref)

    @property
    def compiled_inverse(self) -> bool:
        """True when :meth:`inverse` runs the compiled OPW code (robot/kinematics/fastpath.py) on poses as
        they stand."""
        return bool(self.impl.compiled())

    def compiled_core(self) -> Any:
        """The compiled inverse that solves flange poses as they stand (robot/kinematics/fastpath.py
        ``OPW``), or False."""
        return self.impl.compiled_core()

    # ------------------------------------------------------------------ vectorised IK
    def inverse_many(self, flange_T: np.ndarray, status: int | None = None, turn: int | None = None,
                     reference_deg: Sequence[float] | np.ndarray | None = None) -> np.ndarray:
        """:meth:`inverse` of N flange poses at once.

        Args:
            flange_T: (N, 4, 4) flange frames in ``$ROBROOT``, mm.
            status, turn: as for :meth:`inverse`, the same for every target.
            reference_deg: (n,) or (N, n) axes (deg); default HOME.
        Returns:
            (N, n) A1..An in deg, row i equal to ``inverse(flange_T[i], status, turn,
            reference_deg[i])`` — bit for bit on the OPW family, which solves every row at once
            in numpy (robot/kinematics/opw.py); the other families solve the rows one by one.
        Raises:
            WorkspaceError, SoftLimitError: those of the first row that fails, with the
                attribute ``row`` (its index).
        """
        Ts = np.asarray(flange_T, dtype=float).reshape(-1, 4, 4)
        N, n = Ts.shape[0], self.n_axes
        if reference_deg is None:
            refs = np.broadcast_to(self._home, (N, n)).astype(float)
        else:
            refs = np.broadcast_to(np.asarray(reference_deg, dtype=float)[..., :n], (N, n)).astype(float)
        if N == 0:
            return np.empty((0, n))
        return self.impl.inverse_many(Ts, status, turn, refs)

    def inverse_chain(self, flange_T: np.ndarray, status: int | None, reference_deg: Sequence[float],
                      passes: int) -> np.ndarray | None:
        """:meth:`inverse` along a chain of N flange poses, each solution the reference of the
        next one (the first one's: `reference_deg`; turn None): (N, n) axes, bit for bit those
        of N calls in turn, or None when the chain is to be solved call by call (a family
        without a chain solver, an error on some pose, no fixed point within `passes`).
        Raises nothing."""
        Ts = np.asarray(flange_T, dtype=float).reshape(-1, 4, 4)
        return self.impl.inverse_chain(Ts, status, np.asarray(reference_deg, dtype=float), passes)

    # ------------------------------------------------------------------ frame chain
    def tcp_pose(self, axes_deg: Sequence[float], tool: Any = None, base: Any = None,
                 robroot: Any = None) -> np.ndarray:
        """``$POS_ACT`` as a matrix: TCP in ``$BASE`` for ``$IPO_MODE=#BASE``.

        ``INV_POS($BASE) : $ROBROOT : FLANGE(q) : $TOOL`` (robot-model.md §7,
        reference §6.4). ``tool``, ``base``, ``robroot``: 4x4 arrays, 6-tuples
        (X, Y, Z, A, B, C) or None (= ``$NULLFRAME``). Returns 4x4, mm.
        """
        return inv_pos(as_matrix(base)) @ as_matrix(robroot) @ self.forward(axes_deg) @ as_matrix(tool)

    def flange_target(self, tcp_in_base: Any, tool: Any = None, base: Any = None,
                      robroot: Any = None) -> np.ndarray:
        """Flange frame in ``$ROBROOT`` that puts the TCP at ``tcp_in_base``
        (a Cartesian KRL target in ``$BASE``): the inverse of :meth:`tcp_pose`,
        ``INV_POS($ROBROOT) : $BASE : P : INV_POS($TOOL)`` (robot-model.md §7).
        Arguments as in :meth:`tcp_pose`; returns 4x4, mm."""
        return inv_pos(as_matrix(robroot)) @ as_matrix(base) @ as_matrix(tcp_in_base) @ inv_pos(as_matrix(tool))

    def pos_act(self, axes_deg: Sequence[float], tool: Any = None, base: Any = None,
                robroot: Any = None) -> tuple[float, float, float, float, float, float, int, int]:
        """``$POS_ACT`` as an E6POS-like tuple (X, Y, Z, A, B, C, S, T): TCP of
        :meth:`tcp_pose` in mm/deg (ABC as in :func:`~robot.frames.matrix_to_frame`)
        with the status and turn of the axes (robot-model.md §7-§8)."""
        x, y, z, a, b, c = matrix_to_frame(self.tcp_pose(axes_deg, tool, base, robroot))
        s, t = self.status_turn(axes_deg)
        return (x, y, z, a, b, c, s, t)


__all__ = ["BOUNDARY_EPS", "FK_MEMO", "Kinematics", "LIMIT_EPS_DEG", "OVERHEAD_SINGULAR_MM", "USE_COMPILED",
           "WRIST_SINGULAR_DEG", "compiled_module", "fastpath_compiled", "fastpath_module"]
