"""The six-axis arm without a closed form (family ``"numeric"``: e.g. a twisted ``$TX3P3`` or a
wrist offset in ``$DH_4``/``$DH_5``): every six-axis arm of rotary axes that no other family
takes (robot/kinematics/families.py registers it last), solved numerically.

The robot's own MuJoCo model (robot/mjcf.py, the same joints as the forward kinematics) is
solved by the ``mink`` library (differential inverse kinematics on MuJoCo, a quadratic program
per step solved by ``daqp``; chosen over pinocchio, 400 MB of compiled dependencies, and ikpy,
which missed the pose by 1.9 mm in 0.85 s per target here): Gauss-Newton steps of a frame task
on the flange site ``tool0`` until the pose error is below 1e-10 (mm and rad scale).

One solve converges from one seed, so the solver starts from several: the reference axes, and
the up to 8 solutions of the nearest OPW arm (robot-model.md §4.2, the standard formulas of
robot/mada.py) — one per status S — and keeps every distinct converged configuration. The
selection by status and turn and the errors are then those of the analytic forms
(robot/kinematics/family.py ``select``). A call with a reference first solves from the
reference alone (the nearest solution; about 1-2 ms) and falls back to all seeds when that one
does not fit the requested S/T. Status S and turn T: those of the nearest OPW arm's formulas
(robot/kinematics/opwsolver.py).

Units: mm and deg at this interface (MuJoCo uses m and rad). About 1.3 ms per seed.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import SoftLimitError, WorkspaceError
from .arm import ArmFamily
from .family import select
from .opw import six_rotary
from .opwsolver import OPWSolver

#: Gauss-Newton steps per seed; convergence takes 4-6 from an OPW seed.
MAX_STEPS = 60
#: Error norm (m and rad) at which a seed has converged.
_TOL = 1e-10
#: Largest pose error (mm) of a solution that is kept.
_KEEP_MM = 1e-6


class NumericIK:
    """Numeric solutions of flange poses for the :class:`robot.kinematics.Kinematics` `kin`."""

    def __init__(self, kin: Any) -> None:
        # deferred: tools/startup_bench.py, krl run +120 ms at the top (2026-11-26)
        import mink  # noqa: PLC0415
        # deferred: tools/startup_bench.py, krl run +75 ms at the top (2026-11-26)
        import mujoco  # noqa: PLC0415

        # deferred: tools/startup_bench.py, krl run +93 ms at the top (2026-11-26)
        from ..mjcf import build_mjcf  # noqa: PLC0415

        self.kin = kin
        arm = replace(kin.machine, robroot_frame=(0.0,) * 6, external_axes=(), external_kinematics=())
        self.model = mujoco.MjModel.from_xml_string(build_mjcf(arm))
        self._mink = mink
        self.config = mink.Configuration(self.model)
        self.task = mink.FrameTask("tool0", "site", position_cost=1.0, orientation_cost=1.0, lm_damping=1e-12)
        self._sign = np.array([j.kuka_sign for j in kin.machine.joints], dtype=float)

    def _seeds(self, T: np.ndarray, ref_deg: np.ndarray | None) -> list[np.ndarray]:
        seeds = [np.asarray(ref_deg, dtype=float)[:6]] if ref_deg is not None else []
        seeds.append(np.array(self.kin.machine.home_deg, dtype=float))
        seeds += [np.array(r, dtype=float) for r in self.kin.impl.solver.core(T, ref_deg)]
        return seeds

    def solve(self, T: np.ndarray, seed_deg: np.ndarray) -> np.ndarray | None:
        """The configuration (deg) reached from `seed_deg` whose flange is `T` (4x4, mm), or None."""
        mink = self._mink
        target = np.array(T, dtype=float)
        target[:3, 3] /= 1000.0
        self.task.set_target(mink.SE3.from_matrix(target))
        self.config.update(self._sign * np.radians(seed_deg))
        for _ in range(MAX_STEPS):
            err = self.task.compute_error(self.config)
            if float(err @ err) < _TOL * _TOL:
                break
            v = mink.solve_ik(self.config, [self.task], dt=1.0, solver="daqp", damping=1e-12, limits=[])
            self.config.integrate_inplace(v, 1.0)
        q = np.degrees(self.config.q * self._sign)
        if not np.all(np.isfinite(q)):
            return None
        q = -((-q + 180.0) % 360.0) + 180.0
        if float(np.abs(self.kin.forward(q)[:3, 3] - T[:3, 3]).max()) > _KEEP_MM or \
                float(np.abs(self.kin.forward(q)[:3, :3] - T[:3, :3]).max()) > 1e-9:
            return None
        return q

    def rows(self, flange_T: np.ndarray, ref_deg: np.ndarray | None, near_only: bool = False
             ) -> list[list[float]]:
        """Distinct solutions (lists of A1..A6, deg, wrapped to (-180, 180]) of the flange
        pose `flange_T` (4x4, mm, in ``$ROBROOT``), from the seeds of the module docstring;
        with `near_only` from the reference `ref_deg` alone (the solution nearest to it)."""
        T = np.asarray(flange_T, dtype=float)
        out: list[list[float]] = []
        seeds = [np.asarray(ref_deg, dtype=float)[:6]] if near_only and ref_deg is not None else \
            self._seeds(T, ref_deg)
        for seed in seeds:
            q = self.solve(T, seed)
            if q is None:
                continue
            if any(max(abs(math.remainder(a - b, 360.0)) for a, b in zip(q, r)) < 1e-6 for r in out):
                continue
            out.append([float(v) for v in q])
        return out


class Numeric(ArmFamily):
    """The numeric family (module docstring): the solver is built on first use."""

    name = "numeric"
    title = "numeric (mink on the MuJoCo model; no closed form for this arm)"

    def __init__(self, kin: Any, found: Any = None) -> None:
        super().__init__(kin, found)
        m = kin.machine
        self.solver = OPWSolver(replace(m.opw), float(m.status_phi_deg), kin, self.s_free, self.t_free)
        self._ik: NumericIK | None = None

    @classmethod
    def detect(cls, kin: Any) -> Any:
        return True if six_rotary(kin.machine) else None


    @property
    def ik(self) -> NumericIK:
        if self._ik is None:
            self._ik = NumericIK(self.kin)
        return self._ik

    def solutions(self, flange_T: np.ndarray, ref: np.ndarray | None) -> list[list[float]]:
        return self.ik.rows(flange_T, ref)

    def inverse(self, flange_T: np.ndarray, status: int | None, turn: int | None,
                ref: np.ndarray | None) -> np.ndarray:
        if ref is not None:
            # the solution reached from the reference: the nearest one, when its S and T fit
            near = self.ik.rows(flange_T, ref, near_only=True)
            if near:
                try:
                    return select(self, near, status, turn, ref)
                except (WorkspaceError, SoftLimitError):
                    pass
        else:
            ref = self.kin._home.copy()
        return select(self, self.solutions(flange_T, ref), status, turn, ref)


__all__ = ["MAX_STEPS", "Numeric", "NumericIK"]
