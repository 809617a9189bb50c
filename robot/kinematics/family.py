"""What a kinematic family is: :class:`KinematicFamily`, the protocol every family module
implements (robot/kinematics/families.py registers them), and the parts every family shares:
the choice among candidate solutions by status S and turn T (:func:`select`), the row-by-row
vectorised inverse (:func:`inverse_rows`) and the check of a closed form against the machine
data's chain (:func:`check_closed_form`).

A family's operations (mm, deg; 4x4 frames; n = the robot's axis count,
``len(machine.joints)``):

* ``geometry(values, source, prov, a4fix, a5link)`` (classmethod): the kinematic chain the
  machine data's variables describe (:class:`Geometry`), or None when they describe main axes
  the family does not build; robot/mada.py builds the model's joints from the first answer;
* ``detect(kin)`` (classmethod): whether the robot of ``kin.machine`` (its machine data) and
  ``kin.joints`` (its joints, robot/kinematics/joints.py) is of this family: None if not, else
  what the family found (handed to its constructor as `found`);
* ``forward(a)`` / ``forward_many(A)``: the KUKA flange frame in ``$ROBROOT`` of axes (n,) /
  (N, n);
* ``solutions(T, ref)``: the candidate axis rows (lists of n floats, wrapped to (-180, 180])
  of a flange pose, before the choice by S/T and the soft limits;
* ``status_turn(q)``: KUKA's S and T of axes `q` (reference §6.5, robot-model.md §8);
* ``inverse(T, status, turn, ref)``: the axes (n,) for a flange pose, chosen by S/T nearest to
  `ref`, or :class:`~robot.errors.WorkspaceError` / :class:`~robot.errors.SoftLimitError`;
* ``inverse_many(Ts, status, turn, refs)``: :meth:`inverse` of N poses, (N, n).

A family with none of its own uses the shared implementations explicitly (``inverse =
select_solutions``, ``inverse_many = inverse_rows_many``; the arm families inherit robot/kinematics/
arm.py's ``ArmFamily``), so tests/robot/test_families.py can check that every registered family
declares every operation.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, ClassVar, NamedTuple

import numpy as np

from ..chain import chain_forward
from ..errors import SoftLimitError, WorkspaceError
from ..madavalues import MachineDataError
from .compiled import fastpath_module
from .constants import LIMIT_EPS_DEG

#: The operations of the protocol (tests/robot/test_families.py checks each registered family).
OPERATIONS = ("geometry", "detect", "forward", "forward_many", "solutions", "status_turn", "inverse",
              "inverse_many")


class Geometry(NamedTuple):
    """A robot's kinematic chain as its machine data define it (a family's ``geometry``; robot/
    mada.py builds the joints and the rest of the model from it).

    Attributes:
        chain: robot/chain.py ``Chain``: the fixed frames, joint axes and kinds (n axes).
        opw: the OPW parameters of the standard arm (robot/machine.py ``OPWParams``), None for a
            robot without that arm.
        status_phi_deg: the switching angle of the arm's S bit 1 (deg), 0 without one.
        reach_mm: the reach to the wrist point (mm).
        a5link: the palletizer's led A5 (``$DEF_A5LINK``, or ``$NUM_AX=4`` with ``$DEF_A4FIX``).
    """

    chain: Any
    opw: Any
    status_phi_deg: float
    reach_mm: float
    a5link: bool = False


class KinematicFamily(ABC):
    """One kinematic family's solver for one robot (see the module docstring).

    Attributes:
        name: the family's name (``Kinematics.family``; ``krl robot show``).
        title: how ``krl robot show`` describes it.
        kin: the :class:`~robot.kinematics.Kinematics` it solves for (machine data, joints,
            soft limits, HOME).
        s_free, t_free: the S and T bits that select nothing on this robot (its status has no
            such configuration, or the axis cannot choose its sign).
        reduced_orientation: True when the robot reaches only part of an orientation (its
            inverse drops the component it has no axis for: a palletizer's, a SCARA's tilt);
            robot/blending.py then overlaps the poses the robot reaches.
        solves_chains: True when :meth:`inverse_chain` solves chains of poses at once (the
            planner then plans a CP path's samples in numpy, robot/planner.py ``batch_ik``).
        joints_forward: True when :meth:`forward` is the joints' forward kinematics
            (robot/kinematics/joints.py ``JointChain.forward``: ``Kinematics.tcp_points`` then
            computes many TCP positions in one call).
    """

    name: ClassVar[str] = ""
    title: ClassVar[str] = ""
    s_free = 0
    t_free = 0
    reduced_orientation = False
    solves_chains = False
    joints_forward = False

    def __init__(self, kin: Any, found: Any = None) -> None:
        self.kin = kin

    @classmethod
    @abstractmethod
    def geometry(cls, values: dict[str, Any], source: str, prov: dict[str, str], a4fix: bool,
                 a5link: bool) -> Geometry | None:
        """The robot's :class:`Geometry` from its machine data values (robot/datalist.py
        ``DataValue`` by name; robot/mada.py hands them with the palletizer flags), entering
        each value's file:line in `prov`; None when the machine data describe main axes this
        family does not build (``$MAIN_AXIS``). Raises robot.madavalues.MachineDataError."""

    @classmethod
    @abstractmethod
    def detect(cls, kin: Any) -> Any:
        """None unless ``kin.machine`` is of this family; else what the constructor needs."""

    @abstractmethod
    def forward(self, a: np.ndarray) -> np.ndarray:
        """FLANGE(a), 4x4 mm, for the axes `a` (n,)."""

    @abstractmethod
    def forward_many(self, A: np.ndarray) -> np.ndarray:
        """Flange frames (N, 4, 4) of axes (N, n)."""

    @abstractmethod
    def solutions(self, flange_T: np.ndarray, ref: np.ndarray | None) -> list[list[float]]:
        """The candidate rows of a flange pose (module docstring)."""

    @abstractmethod
    def status_turn(self, q: np.ndarray) -> tuple[int, int]:
        """(S, T) of the axes `q`."""

    @abstractmethod
    def inverse(self, flange_T: np.ndarray, status: int | None, turn: int | None, ref: np.ndarray) -> np.ndarray:
        """The axes (n,) for a flange pose (module docstring)."""

    @abstractmethod
    def inverse_many(self, Ts: np.ndarray, status: int | None, turn: int | None, refs: np.ndarray) -> np.ndarray:
        """:meth:`inverse` of the poses Ts (N, 4, 4) with the references refs (N, n)."""

    # ------------------------------------------------------------------ optional
    def inverse_or_error(self, flange_T: np.ndarray, status: int | None, turn: int | None,
                         ref: np.ndarray | None) -> tuple[np.ndarray | None, type | None]:
        """:meth:`inverse` without raising: ``(axes, None)``, or ``(None, the class of the error it
        raises)`` (WorkspaceError, SoftLimitError or a subclass). ``INVERSE`` needs the kind alone
        for its STATUS, and a status/turn search fails most of its calls (issue 86)."""
        try:
            return self.inverse(flange_T, status, turn, ref), None
        except (SoftLimitError, WorkspaceError) as err:
            return None, type(err)

    def status_row(self, q: list[float]) -> tuple[int, int]:
        """S of one row and the mask of its S bits that sit on a switching point or select
        nothing (:func:`select`); the default: S of :meth:`status_turn`, :attr:`s_free`."""
        return self.status_turn(np.asarray(q, dtype=float))[0], self.s_free

    def inverse_chain(self, Ts: np.ndarray, status: int | None, ref: np.ndarray, passes: int) -> np.ndarray | None:
        """:meth:`inverse` along a chain of poses solved at once, or None (solve pose by pose)."""
        return None

    def check(self, where: str) -> None:
        """Raise robot.mada.MachineDataError (naming `where`) when the machine data's chain is not
        one this family's closed form covers; the default checks nothing."""

    def compiled(self) -> Any:
        """The compiled inverse :meth:`inverse` runs (robot/kinematics/fastpath.py compiled), or False."""
        return False

    def compiled_core(self) -> Any:
        """The compiled inverse that solves flange poses as they stand, or False."""
        return False

    def describe(self) -> list[str]:
        """Lines ``krl robot show`` prints about the solver (after the family's title)."""
        return []

    def chooser(self) -> Any:
        """robot/kinematics/fastpath.py's ``Chooser`` for this robot's limits and this family's
        free turn bits (made once)."""
        c = self.__dict__.get("_chooser")
        if c is None:
            k = self.kin
            c = self._chooser = fastpath_module().Chooser(k.n_axes, k._lo_l, k._hi_l, k._ks_l,
                                                          [bool(v) for v in k.joints.linear], self.t_free)
        return c


def select(fam: KinematicFamily, rows: list[list[float]], status: int | None, turn: int | None,
           ref: np.ndarray, stats: list[tuple[int, int]] | None = None) -> np.ndarray:
    """The solution of `rows` that ``inverse`` returns, or its error (docs/robot.md "Inverse
    kinematics"):

    1. keep the rows whose S equals `status` (masked with 7) — or, with None, the S of `ref`
       (bits the reference sits exactly on are free);
    2. per row and axis the ±360° variant within the soft limits (and with the sign of its
       turn bit) nearest to `ref`;
    3. the row with the least axis motion (the first of equals).

    Raises WorkspaceError (no row, none with the S) or SoftLimitError (the rows with that S/T
    violate ``$SOFTN_END``/``$SOFTP_END``; the axis and value nearest to the limits).
    `stats`: ``fam.status_row`` of each row where the caller has them (:func:`select_solutions`
    keeps them with the rows)."""
    kin = fam.kin
    if not rows:
        raise WorkspaceError("workspace error: target not reachable")
    if status is not None:
        s_target, free = int(status) & 7, 0
    else:
        # keep the reference's status; bits the reference sits exactly on
        # (A5 = 0, A3 = phi, wrist point on the A1 axis) are free
        s_target, free = fam.status_row(ref.tolist())
    keep = ~free
    if stats is None:
        stats = [fam.status_row(r) for r in rows]
    matching_rows = [r for r, (s_r, amb) in zip(rows, stats) if ((s_r ^ s_target) & ~amb & keep & 7) == 0]
    if not matching_rows:
        raise WorkspaceError(f"workspace error: target not reachable with status S={s_target}")
    # per solution and axis the ±360° variant within the limits (and the turn) nearest to
    # the reference, then the solution with the least axis motion (the first of equals):
    # robot/kinematics/fastpath.py's Chooser (compiled when built)
    chooser = fam.chooser()
    q = chooser.choose(matching_rows, ref.tolist(), turn)
    if q is not None:
        return np.array(q)
    # the error: fastpath's Chooser gives _limit_error's axis and value (compiled when built)
    got = chooser.limit_error(len(matching_rows), turn, kin._lo_l0, kin._hi_l0)
    if got is not None:
        i, v = got
        raise SoftLimitError(i + 1, v, positive=bool(v > kin._hi[i]))
    t_free = fam.t_free
    if turn is not None:
        turn = int(turn) & ~t_free
    return _limit_error(kin, np.array(matching_rows), turn, t_free, ref)


def _limit_error(kin: Any, matching: np.ndarray, turn: int | None, t_free: int, ref: np.ndarray) -> np.ndarray:
    """Raise the SoftLimitError of :func:`select` when no row fits the soft limits: the allowed
    (turn) variant nearest to the limits of the row with the least axis motion (numpy; fastpath's
    ``Chooser.limit_error`` gives the same axis and value, tests/robot/test_kinematics_compiled.py)."""
    n = kin.n_axes
    rows_i = np.arange(n)
    if turn is not None:
        neg = ((int(turn) >> rows_i) & 1).astype(bool)[:, None]  # (n, 1)
        free = ((t_free >> rows_i) & 1).astype(bool)[:, None]
    best_ok: tuple[float, np.ndarray] | None = None
    best_bad: tuple[float, np.ndarray, int] | None = None
    for b in matching:
        cands = b[:, None] + kin._ks_rows  # (n, 5): the ±360° variants per axis (a linear one: itself)
        ok = np.ones(cands.shape, dtype=bool)
        if turn is not None:
            ok = ((cands < 0) == neg) | (np.abs(cands) < 1e-6) | free
        inlim = ok & (cands >= kin._lo[:, None] - LIMIT_EPS_DEG) & (cands <= kin._hi[:, None] + LIMIT_EPS_DEG)
        dist = np.where(inlim, np.abs(cands - ref[:, None]), np.inf)
        pick = np.argmin(dist, axis=1)
        q = cands[rows_i, pick]
        axis_bad = ~inlim.any(axis=1)
        if not axis_bad.any():
            cost = float(np.sum(np.abs(q - ref)))
            if best_ok is None or cost < best_ok[0]:
                best_ok = (cost, q)
            continue
        # for the error: the allowed (turn) variant nearest to the limits
        over = np.maximum(kin._lo[:, None] - cands, cands - kin._hi[:, None])
        over = np.where(ok, over, np.inf)
        q_bad = np.where(axis_bad, cands[rows_i, np.argmin(over, axis=1)], q)
        cost = float(np.sum(np.abs(q_bad - ref)))
        if best_bad is None or cost < best_bad[0]:
            best_bad = (cost, q_bad, int(np.argmax(axis_bad)))
    if best_ok is not None:
        return best_ok[1]
    assert best_bad is not None
    _, q, i = best_bad
    raise SoftLimitError(i + 1, float(q[i]), positive=bool(q[i] > kin._hi[i]))


def inverse_rows(fam: KinematicFamily, Ts: np.ndarray, status: int | None, turn: int | None,
                 refs: np.ndarray, rows) -> np.ndarray:
    """``fam.inverse`` row by row for the indices `rows`: (len(rows), n); the first error gets
    the attribute ``row`` (its index)."""
    out = []
    for i in rows:
        try:
            out.append(fam.kin.inverse(Ts[i], status, turn, refs[i]))
        except (WorkspaceError, SoftLimitError) as exc:
            exc.row = int(i)                     # type: ignore[attr-defined]
            raise
    return np.array(out, dtype=float).reshape(-1, fam.kin.n_axes)


def select_solutions(self: KinematicFamily, flange_T: np.ndarray, status: int | None, turn: int | None,
                     ref: np.ndarray | None) -> np.ndarray:
    """The shared ``inverse`` of a family with analytic rows: :func:`select` over its
    ``solutions`` (the reference HOME when `ref` is None). The rows of the last pose and reference
    are kept (by their bytes): a program's search for a point's status and turn (KUKA's
    ``Find_Optimal_ST`` pattern, 8 x 64 S/T pairs through ``INVERSE`` per point, issue 86) asks
    for the same pose again with each S and T, and the rows do not depend on them; nor do their
    statuses (``status_row``), kept with them."""
    if ref is None:
        ref = self.kin._home.copy()
    T = np.asarray(flange_T, dtype=float)
    key = T.tobytes() + np.asarray(ref, dtype=float).tobytes()
    last = self.__dict__.get("_last_rows")
    if last is not None and last[0] == key:
        rows, stats = last[1], last[2]
    else:
        rows = self.solutions(T, ref)
        stats = [self.status_row(r) for r in rows]
        self._last_rows = (key, rows, stats)
    return select(self, rows, status, turn, ref, stats)


def inverse_rows_many(self: KinematicFamily, Ts: np.ndarray, status: int | None, turn: int | None,
                      refs: np.ndarray) -> np.ndarray:
    """The shared ``inverse_many`` of a family: its inverse row by row (:func:`inverse_rows`)."""
    return inverse_rows(self, Ts, status, turn, refs, range(Ts.shape[0]))


def check_closed_form(kin: Any, rows, where: str, message: str, link=None, sample=None) -> None:
    """Raise robot.madavalues.MachineDataError (``"{where}: {message}"``) unless the closed form
    ``rows(T, q)`` (a list of axis rows for the flange pose T, 4x4, mm) gives back four random
    configurations of the machine-data chain within 1e-6: by default six axes within the soft
    limits with A4 = 0 (a palletizer's), `sample(kin, rng)` draws them otherwise; `link(q)` sets
    the axes the arm's linkage leads. Also raises when the chain of the machine data does not
    close on the joints' forward kinematics."""
    rng = np.random.default_rng(0)
    lo = np.maximum(kin._lo, -170.0)
    hi = np.minimum(kin._hi, 170.0)
    draws = [sample(kin, rng) for _ in range(4)] if sample is not None else rng.uniform(lo, hi, size=(4, 6))
    for q in draws:
        if sample is None:
            q[3] = 0.0
        if link is not None:
            link(q)
        T = kin.forward(q)
        if kin.machine.chain is not None and np.abs(chain_forward(kin.machine.chain, q) - T).max() > 1e-6:
            raise MachineDataError(f"{where}: internal chain does not close")
        found = rows(T, q)
        if not found or min(np.abs(kin.forward(r) - T).max() for r in found) > 1e-6:
            raise MachineDataError(f"{where}: {message}")


__all__ = ["Geometry", "KinematicFamily", "OPERATIONS", "select_solutions", "check_closed_form", "inverse_rows", "inverse_rows_many", "select"]
