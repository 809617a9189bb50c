"""The six-axis arm with a spherical wrist: KUKA's standard articulated robot (``$MAIN_AXIS=#NR``,
``$WRIST_AXIS=#ZEH``), solved by the OPW closed form (robot-model.md §4.2; robot/kinematics/
opwsolver.py) with up to 8 solutions, one per status S.

Detection (from the machine data, never the robot's name): six rotary axes, no palletizer flag,
and the OPW parameters reproduce the chain on sample poses (1e-6 mm) — the standard ones of
robot/mada.py (``a1=$LENGTH_A, a2=-$TX3P3.Z, b=$TX3P3.Y, c1=$TIRORO.Z, c2=$LENGTH_B,
c3=$TX3P3.X, c4=$TFLWP.Z``), else the form robot/chain.py ``opw_form`` finds in the geometry
(with a frame before A1 and one after A6). The yaml robot (no machine-data chain) is of this
family with the yaml's ``opw`` parameters.

Status S (robot-model.md §8): bit 0 the wrist point behind the A1 axis, bit 1 A3 >= phi, bit 2
A5 < 0; turn T bit i: A(i+1) < 0.

:meth:`OPW.inverse` runs robot/kinematics/fastpath.py's ``OPWCore`` (the rows, those with the
status, the choice; compiled from that file when it is built); :meth:`OPW.inverse_many`
solves N poses in numpy, bit for bit the scalar rows; :meth:`OPW.inverse_chain` a chain of
poses each the next one's reference.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..chain import chain_forward, opw_form
from ..errors import SoftLimitError, WorkspaceError
from .arm import ArmFamily, opw_line
from .family import inverse_rows, select
from .opwsolver import OPWSolver


class OpwFound(NamedTuple):
    """What :meth:`OPW.detect` found: the parameters, the switching angle of S bit 1 and the
    inverses of the frames before A1 and after A6 (None: identity)."""

    params: Any
    phi_deg: float
    base_inv: np.ndarray | None
    end_inv: np.ndarray | None


def six_rotary(machine: Any) -> bool:
    """True for an arm of six rotary axes without the palletizers' fixed A4."""
    return (len(machine.joints) == 6 and not machine.a4fix
            and all(getattr(j, "kind", "rotary") != "linear" for j in machine.joints))


class OPW(ArmFamily):
    """The OPW family (module docstring)."""

    name = "opw"
    title = "analytic (OPW: six axes, spherical wrist)"
    solves_chains = True

    def __init__(self, kin: Any, found: OpwFound) -> None:
        super().__init__(kin, found)
        self.solver = OPWSolver(found.params, found.phi_deg, kin, self.s_free, self.t_free)
        self.base_inv = found.base_inv
        self.end_inv = found.end_inv

    @classmethod
    def detect(cls, kin: Any) -> OpwFound | None:
        m = kin.machine
        if not six_rotary(m):
            return None
        std = OpwFound(m.opw, float(m.status_phi_deg), None, None)
        if m.chain is None:
            return std
        if cls._agrees(kin, std):
            return std
        form = opw_form(m.chain)
        if form is None:
            return None
        found = OpwFound(form.params, form.phi_deg,
                         np.linalg.inv(form.base) if form.base is not None else None,
                         np.linalg.inv(form.end) if form.end is not None else None)
        return found if cls._agrees(kin, found) else None

    @classmethod
    def _agrees(cls, kin: Any, found: OpwFound) -> bool:
        """True when the joints reproduce the machine-data chain and the analytic solutions
        reproduce every sample pose (1e-6 mm; robot/chain.py ``chain_forward``)."""
        trial = cls(kin, found)
        chain = kin.machine.chain
        rng = np.random.default_rng(0)
        lo = np.maximum(kin._lo, -170.0)
        hi = np.minimum(kin._hi, 170.0)
        for q in rng.uniform(lo, hi, size=(4, 6)):
            T = chain_forward(chain, q)
            if np.abs(kin.forward(q) - T).max() > 1e-6:
                return False
            rows = trial.solutions(T, None)
            if not rows or min(np.abs(kin.forward(r) - T).max() for r in rows) > 1e-6:
                return False
        return True

    # ------------------------------------------------------------------ IK
    def _in_arm(self, flange_T: np.ndarray) -> np.ndarray:
        """The pose in the OPW arm's own frames (the frames before A1 and after A6 removed)."""
        T = np.asarray(flange_T, dtype=float)
        if self.base_inv is not None:
            T = self.base_inv @ T
        if self.end_inv is not None:
            T = T @ self.end_inv
        return T

    def solutions(self, flange_T: np.ndarray, ref: np.ndarray | None) -> list[list[float]]:
        if self.base_inv is not None or self.end_inv is not None:
            return self.solver.core(self._in_arm(flange_T), ref)
        return self.solver.core(flange_T, ref)

    def inverse(self, flange_T: np.ndarray, status: int | None, turn: int | None,
                ref: np.ndarray | None) -> np.ndarray:
        if ref is None:
            ref = self.kin._home.copy()
        # robot/kinematics/fastpath.py (compiled when built): the rows, those with the status,
        # the choice; None where it raises: select() gives the error
        q = self.solver.c.inverse(self._in_arm(flange_T), status, turn, ref)
        if q is not None:
            return q
        return select(self, self.solutions(flange_T, ref), status, turn, ref)

    def compiled(self) -> Any:
        """The compiled fastpath's OPWCore of this robot, or False (not built)."""
        return self.solver.c if self.solver.compiled else False

    def compiled_core(self) -> Any:
        if self.base_inv is not None or self.end_inv is not None:
            return False
        return self.compiled()

    # ------------------------------------------------------------------ vectorised IK
    def inverse_many(self, Ts: np.ndarray, status: int | None, turn: int | None, refs: np.ndarray) -> np.ndarray:
        """Every row at once in numpy: bit for bit :meth:`inverse` of each row, where every
        operation is the scalar one in the same order (``math.acos`` is used, as numpy's
        ``arccos`` may differ in the last bit)."""
        orig = Ts
        if self.base_inv is not None:
            Ts = self.base_inv @ Ts
        if self.end_inv is not None:
            Ts = Ts @ self.end_inv
        Q, valid, _ = self.solver.core_many(Ts, refs)                # (n, 8, 6), (n, 8)
        return self._select_many(Q, valid, orig, status, turn, refs)

    def inverse_chain(self, Ts: np.ndarray, status: int | None, ref: np.ndarray, passes: int) -> np.ndarray | None:
        """:meth:`inverse` along a chain of N flange poses, each solution the reference of the
        next one (the first one's: `ref`; turn None): (N, 6) axes, bit for bit those of N calls
        in turn, or None when the chain is to be solved call by call (an error on some pose, no
        fixed point within `passes`).

        Each pass solves every row at once (:meth:`inverse_many`) with a guess of the rows,
        shifted by one, as references (first pass: `ref` for all; then the previous pass's
        rows, unwrapped); a pass that gives back its guess is the sequential chain (row i's
        reference is row i-1's solution, by induction over i). The analytic solutions are
        computed once unless a pose sits at a singularity, where they take a free angle from
        the reference. Raises nothing: errors give None (the caller's per-pose solve raises them)."""
        orig = Ts
        n = Ts.shape[0]
        if n == 0:
            return None
        refs = np.empty((n, 6))
        refs[:] = np.asarray(ref, dtype=float)[:6]
        if self.base_inv is not None:
            Ts = self.base_inv @ Ts
        if self.end_inv is not None:
            Ts = Ts @ self.end_inv
        lo, hi = self.kin._lo, self.kin._hi
        try:
            Q, valid, ref_free = self.solver.core_many(Ts, refs)
            out = self._select_many(Q, valid, orig, status, None, refs)
            for _ in range(passes):
                # the guess: each axis continued from the row before (±360°, np.unwrap), so a
                # turn past ±180° is followed in one pass, within the soft limits (past one
                # the pass's own value); unchanged values keep their bits
                g = np.unwrap(out, period=360.0, axis=0)
                g = np.where((g == out) | (g < lo) | (g > hi), out, g)
                refs[1:] = g[:-1]
                if not ref_free:
                    Q, valid, _ = self.solver.core_many(Ts, refs)
                new = self._select_many(Q, valid, orig, status, None, refs)
                if new.tobytes() == g.tobytes():
                    return new
                out = new
        except (WorkspaceError, SoftLimitError):
            return None
        return None

    def _select_many(self, Q: np.ndarray, valid: np.ndarray, orig: np.ndarray, status: int | None,
                     turn: int | None, refs: np.ndarray) -> np.ndarray:
        """:func:`~robot.kinematics.family.select` over the analytic solutions Q (N, 8, 6) of the
        flange poses `orig` (rows without a usable solution are solved by the scalar inverse,
        raising its error)."""
        k = self.kin
        n = Q.shape[0]
        S, amb = self.solver.status_many(Q, self.s_free)                  # (n, 8)
        if status is not None:
            s_target = np.full(n, int(status) & 7)
            free = np.zeros(n, dtype=int)
        else:
            s_target, free = self.solver.status_many(refs[:, None, :], self.s_free)
            s_target, free = s_target[:, 0], free[:, 0]
        keep = ~free
        match = valid & ((((S ^ s_target[:, None]) & ~amb & keep[:, None] & 7) == 0))
        cands = Q[:, :, :, None] + np.array(k._ks_l)[None, None, None, :]   # (n, 8, 6, 5)
        lo = np.array(k._lo_l)[None, None, :, None]
        hi = np.array(k._hi_l)[None, None, :, None]
        ok = (cands >= lo) & (cands <= hi)
        if turn is not None:
            t = int(turn) & ~self.t_free
            neg = (((t >> np.arange(6)) & 1) == 1)[None, None, :, None]
            free_t = (((self.t_free >> np.arange(6)) & 1) == 1)[None, None, :, None]
            ok &= ((cands < 0) == neg) | (np.abs(cands) < 1e-6) | free_t
        dist = np.where(ok, np.abs(cands - refs[:, None, :, None]), np.inf)
        pick = np.argmin(dist, axis=3)                                          # first of equals
        best = np.take_along_axis(cands, pick[..., None], axis=3)[..., 0]       # (n, 8, 6)
        axis_ok = np.isfinite(np.take_along_axis(dist, pick[..., None], axis=3)[..., 0]).all(axis=2)
        d = np.abs(best - refs[:, None, :])
        cost = ((((d[..., 0] + d[..., 1]) + d[..., 2]) + d[..., 3]) + d[..., 4]) + d[..., 5]
        usable = match & axis_ok
        cost = np.where(usable, cost, np.inf)
        j = np.argmin(cost, axis=1)
        out = best[np.arange(n), j]
        bad = ~usable.any(axis=1)
        if bad.any():
            out[bad] = inverse_rows(self, orig, status, turn, refs, np.flatnonzero(bad))
        return out

    def describe(self) -> list[str]:
        return [opw_line(self.solver.o)]


__all__ = ["OPW", "OpwFound", "six_rotary"]
