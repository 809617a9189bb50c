"""The settling lag's time constant of a motion (issue 88; robot/actualvalue.py applies the lag).

The KR 3 R540's A1 settles into ``$IN_POS_MA`` later the more inertia it drives: its actual value
follows a first-order lag while it brakes below ``MachineData.actual_settle_lag['below_deg_s']``,
of time constant ``τ = cycles_per_kg_m2 × I × dt``: ``I`` the axis' inertia (kg m², the mass matrix'
diagonal of robot/dynamics.py, rotor included) at the motion's end pose with the motion's ``$LOAD``
and ``$LOAD_A3``, ``dt`` the IPO cycle. A loop of fixed gains settles the slower the more inertia it
drives ("slow settling ... will move into final position very slowly", Danaher Motion's
troubleshooting page; docs/robot.md "The settling lag on A1"); the factor and the speed are identified
from the recordings (robot/kukatrace/identify.py ``fit_settle_lag``).

:func:`settle_tau` gives one motion's τ (the controller's, per segment); :func:`row_taus` the τ of
each sample of a trace's segment (the bench's, interp/tracebench.py, and the identification's), from
its motions' end poses and loads (:func:`segment_taus`).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .planner import arm_dynamics


def settle_tau(machine: Any, q_end: Sequence[float], load: Sequence[float] | None = None,
               load_a3: Sequence[float] | None = None) -> float:
    """τ (s) of a motion ending at axes `q_end` (deg) with `load` and `load_a3` (robot/dynamics.py
    ``set_load``'s tuples; None: the robot's default load, none on A3) on `machine` (MachineData):
    ``cycles_per_kg_m2`` × the lagged axis' inertia at `q_end` × the IPO cycle. 0.0 for a robot
    without a settling lag (``actual_settle_lag`` None) or without a dynamic model."""
    lag = getattr(machine, "actual_settle_lag", None)
    arm = arm_dynamics(machine) if lag else None
    if arm is None:
        return 0.0
    i = int(lag["axis"]) - 1
    arm.set_load(load, load_a3)
    q = np.asarray(q_end, dtype=float)[:arm.n]
    e = np.zeros(arm.n)
    e[i] = 1.0
    inertia = float((arm.inverse(q, e) - arm.gravity(q))[i])
    return float(lag["cycles_per_kg_m2"]) * inertia * float(machine.ipo_cycle_s)


def row_taus(machine: Any, t: np.ndarray, axes: np.ndarray, starts: Sequence[float],
             loads: Sequence[Sequence[float] | None]) -> np.ndarray:
    """(N,) τ (s) of each sample at times `t` (N,) s of axes `axes` (N, n) deg: a sample takes the
    τ (:func:`settle_tau`) of the last motion started at or before it (`starts` s, in order, each
    with its load of `loads`), whose end pose is the axes at the next motion's start (the last
    motion's: the last sample); 0.0 before the first motion (the robot at rest, as the controller's
    stream before its first motion)."""
    t = np.asarray(t, dtype=float)
    out = np.zeros(len(t))
    if not getattr(machine, "actual_settle_lag", None) or len(t) == 0:
        return out
    for k, t0 in enumerate(starts):
        t1 = starts[k + 1] if k + 1 < len(starts) else np.inf
        rows = (t >= t0 - 1e-9) & (t < t1 - 1e-9)
        end = int(np.argmin(np.abs(t - t1))) if np.isfinite(t1) else len(t) - 1
        out[rows] = settle_tau(machine, axes[end], loads[k], None)
    return out


def segment_taus(machine: Any, seg: Any) -> np.ndarray:
    """:func:`row_taus` of a trace's segment `seg` (robot/kukatrace/model.py ``Segment``: ``t``,
    ``axes``, ``motions`` with ``start`` and ``load``)."""
    return row_taus(machine, seg.t, seg.axes, [m.start for m in seg.motions],
                    [getattr(m, "load", None) for m in seg.motions])


__all__ = ["row_taus", "segment_taus", "settle_tau"]
