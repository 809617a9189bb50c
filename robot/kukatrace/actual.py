"""The actual-value model: what a simulated run's setpoints give as a KUKA Trace's measured
("Act") TCP (issue 60). The model itself is robot/actualvalue.py's (``actual_axes``), the one
``krl run``'s trace writes its ``axes_act``/``tcp_act`` with (issue 73); this module applies it to
a run's segment for ``krl trace compare``.

A simulated run's trace holds the interpolator's setpoints (robot/trace.py ``pose``). A KR C4's
recording holds measured values: the setpoints averaged in axis space over a few IPO cycles by
the controller, then followed by the drives. Along a straight LIN at 1 m/s the real TCP leaves
the line by up to 0.6 mm (1.05 mm on the vertical one), growing with the square of the speed, as
an average in axis space makes it. :func:`actual_tcp` puts a run's axes through that average
(``MachineData.actual_filter_cycles`` cycles, causal: each sample the mean of its cycle and the
ones before; identified from the recordings, robot/identified.py) and the forward kinematics with
each motion's ``$TOOL`` and ``$BASE`` (and the robot's ``$ROBROOT``): the TCP that ``krl trace compare`` measures a simulated
run's path deviation on. A robot without an identified average (one cycle) keeps its setpoints.
The lag it adds does not matter there: the path deviation is geometric.

Behind the averaged setpoints the drives follow with an error (robot/actualvalue.py
``following_error``, re-exported here; a robot's ``MachineData.actual_following``, identified from
its recordings): the torque an axis needs over
its loop's stiffness, ``m_i·q̈ + c_i·tanh(q̇/v0) + k_i·q̇`` (inertia, Coulomb and viscous
friction; a position loop without torque feed-forward). On the KR 3 R540 it is what makes a LIN's
wrist axes fall 0.05-0.1° behind as they leave rest (docs/robot.md "The drives' following error").
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np

from ..actualvalue import actual_axes, following_error, mean_window, ptp_rows_of
from ..frames import frame_to_matrix, inv_pos
from .model import RunView, Segment
from .recording import IPO_CYCLE_S
from ..kinematics import Kinematics
from ..mada import MachineDataError, load_robot


@cache
def _robot(source: str):
    """(MachineData, Kinematics) of the robot a trace names, or None when it cannot be loaded
    (the trace made elsewhere)."""
    if not source or not Path(source).exists():
        return None
    try:
        m = load_robot(source)
        return m, Kinematics(m)
    except (MachineDataError, ValueError, OSError):
        return None


def filter_cycles(view: RunView) -> int:
    """The cycles of the average for `view`'s robot (1: none; a recording is measured already)."""
    if view.kind != "trace":
        return 1
    got = _robot(view.robot_source)
    return int(got[0].actual_filter_cycles) if got is not None else 1


def average(q: np.ndarray, n: int) -> np.ndarray:
    """Setpoints `q` (N, n_axes) averaged over `n` cycles, causal: each row the mean of its own and
    the `n` - 1 before (the first row repeated before the start): robot/actualvalue.py's average."""
    return mean_window(np.vstack([np.repeat(q[:1], n - 1, axis=0), q]), n) if n > 1 else np.array(q, dtype=float)


def actual_tcp(view: RunView, seg: Segment, cycles: int | None = None,
               following: dict | None = None, dead: int | None = None, ptp_cycles: int | None = -1,
               settle_lag: dict | None = None, taus: np.ndarray | None = None) -> np.ndarray:
    """The measured TCP positions (N, 3) mm the setpoints of `seg` give (the module's
    docstring): averaged over `cycles` (default the robot's :func:`filter_cycles`), a PTP's samples
    over `ptp_cycles` (default -1: the robot's ``actual_filter_cycles_ptp`` where `cycles` is the robot's
too, else `cycles`; None: `cycles`), less the
    :func:`following_error` of `following` (default the robot's ``actual_following``; ``{}``:
    none), `dead` IPO cycles behind (default the robot's ``actual_dead_cycles``), with the
    `settle_lag` (default none: a trace holds no ``$LOAD`` to give its τ) and `taus` (N,) each sample's τ s
    (robot/settlelag.py ``row_taus``); its own TCP when there is no average to apply."""
    n = filter_cycles(view) if cycles is None else cycles
    if n <= 1 or len(seg.t) == 0 or _robot(view.robot_source) is None:
        return seg.tcp[:, :3]
    machine, kin = _robot(view.robot_source)
    follow = machine.actual_following if following is None else following
    lag = machine.actual_dead_cycles if dead is None else dead
    if ptp_cycles == -1:
        ptp_cycles = machine.actual_filter_cycles_ptp if cycles is None else None
    qf = actual_axes(seg.axes[:, :machine.n_axes], n, follow, IPO_CYCLE_S, dead=lag,
                     ptp_rows=ptp_rows_of(seg.t, seg.motions), ptp_cycles=ptp_cycles, lag=settle_lag, taus=taus)
    out = seg.tcp[:, :3].copy()
    starts = [m.start for m in seg.motions]
    for k, m in enumerate(seg.motions):
        if m.tool is None:
            continue
        t0 = m.start if k else -np.inf
        t1 = starts[k + 1] if k + 1 < len(starts) else np.inf
        rows = np.flatnonzero((seg.t >= t0 - 1e-9) & (seg.t < t1 - 1e-9))
        if len(rows) == 0:
            continue
        F = kin.forward_many(qf[rows])
        T = (inv_pos(frame_to_matrix(*(m.base or (0.0,) * 6))) @ frame_to_matrix(*machine.robroot_frame)
             @ F @ frame_to_matrix(*m.tool))
        out[rows] = T[:, :3, 3]
    return out


__all__ = ["actual_tcp", "average", "filter_cycles", "following_error"]
