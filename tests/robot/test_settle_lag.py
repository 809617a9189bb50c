"""The settling lag on one axis (issue 88: A1 settles into $IN_POS_MA later the more inertia it drives).

robot/actualvalue.py puts the lagged axis' actual value through ``y_k = y_(k-1) + (x_k - y_(k-1))·(1 -
e^(-dt/τ))`` while that axis brakes below ``below_deg_s`` (its speed, the backward difference, below it and
not rising), else ``y_k = x_k``; robot/settlelag.py gives τ = ``cycles_per_kg_m2`` × the axis' inertia at
the motion's end pose with its load × the IPO cycle. The expected values here are worked out by hand
(the lag's numbers below, e^-1 = 0.367879...), and the inertia from MuJoCo's own mass matrix
(``mj_fullM``, not the inverse dynamics robot/dynamics.py takes it from) and from the load's distance to
A1's axis (m·r², a point mass).
"""

from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np
import pytest

from interp.run import make_runtime, run_spec, RunSinks
from robot.actualvalue import ActualStream, actual_axes
from robot.identified import apply_identified, read_identified
from robot.madavalues import MachineDataError
from robot.mada import load_robot
from robot.planner import arm_dynamics
from robot.settlelag import row_taus, settle_tau
from robot.trace import TraceWriter

DT = 0.012
LAG = {"axis": 1, "below_deg_s": 50.0, "cycles_per_kg_m2": 0.5}
#: A1 braking: 83.3, 50, 33.3, 16.7 deg/s, then at rest (backward differences over 12 ms)
BRAKING = [0.0, 1.0, 1.6, 2.0, 2.2, 2.2, 2.2, 2.2]


def _axes(col):
    q = np.zeros((len(col), 2))
    q[:, 0] = col
    q[:, 1] = 5.0
    return q


def test_the_lag_acts_while_the_axis_brakes_below_the_speed():
    """τ = one IPO cycle: each row active closes 1 - e^-1 = 0.632121 of the gap. Row 2 (50 deg/s, not
    below) is the model's own 1.6; row 3: 1.6 + 0.4 × 0.632121 = 1.852848; row 4: + 0.347152 ×
    0.632121 = 2.072290; at rest the gap 0.127710 shrinks by e^-1 a row: 0.046982, 0.017284, 0.006358.
    The other axis is untouched."""
    got = actual_axes(_axes(BRAKING), 1, None, DT, lag=LAG, taus=np.full(len(BRAKING), DT))
    assert got[:, 0].tolist() == pytest.approx(
        [0.0, 1.0, 1.6, 1.852848, 2.072290, 2.2 - 0.046982, 2.2 - 0.017284, 2.2 - 0.006358], abs=2e-6)
    assert got[:, 1].tolist() == [5.0] * len(BRAKING)


def test_no_lag_where_tau_is_zero_or_the_axis_speeds_up():
    """τ 0 (a motion without one) or no lag given: the model's values; a start from rest that speeds
    up (0, 8.3, 25, 41.7 deg/s: below 50 but rising) is not lagged either."""
    q = _axes(BRAKING)
    assert actual_axes(q, 1, None, DT, lag=LAG, taus=np.zeros(len(BRAKING)))[:, 0].tolist() == BRAKING
    assert actual_axes(q, 1, None, DT)[:, 0].tolist() == BRAKING
    rising = [0.0, 0.0, 0.1, 0.4, 0.9]
    got = actual_axes(_axes(rising), 1, None, DT, lag=LAG, taus=np.full(5, DT))
    assert got[:, 0].tolist() == pytest.approx(rising)


def test_the_stream_settles_later_with_the_lag():
    """``$IN_POS_MA`` 0.1°: without the lag the actual value is the setpoint (one cycle, no following
    error), settled from the first row; with τ one cycle the gap is 0.252 (row 3), 0.128 (row 4),
    0.047 (row 5): settled from row 5."""
    times = [k * DT for k in range(len(BRAKING))]

    def settled(lag):
        s = ActualStream(1, None, DT, 2, window=(0.1, 0.1), lag=lag)
        for t, row in zip(times, _axes(BRAKING)):
            s.push(t, row, ptp=True, tau=DT)
        s.finish(rest=True)
        return s.settled_at()

    assert settled(None) == pytest.approx(0.0)
    assert settled(LAG) == pytest.approx(5 * DT)


def test_tau_follows_a1s_inertia_with_the_load():
    """τ = 0.5 cycles per kg m² × A1's inertia × 12 ms: the inertia MuJoCo's mass matrix gives at the
    end pose; a 3 kg point load at the flange adds 3 kg × r², r its distance (m) from A1's axis."""
    m = load_robot("kr3_r540")
    assert m.actual_settle_lag == {"axis": 1, "below_deg_s": 50.0, "cycles_per_kg_m2": 0.5}
    arm = arm_dynamics(m)
    q = np.array([30.0, -60.0, 100.0, 0.0, 40.0, 0.0])
    none = (0.0,) * 10
    load = (3.0,) + (0.0,) * 9
    arm.set_load(none, None)
    d = arm.data
    d.qpos[:] = arm.sign * np.radians(q)
    mujoco.mj_forward(arm.model, d)
    full = np.zeros((arm.n, arm.n))
    mujoco.mj_fullM(arm.model, d, full)
    flange = d.xpos[mujoco.mj_name2id(arm.model, mujoco.mjtObj.mjOBJ_BODY, "load")].copy()
    axis = d.xanchor[0].copy()
    r2 = (flange[0] - axis[0]) ** 2 + (flange[1] - axis[1]) ** 2
    assert settle_tau(m, q, none) == pytest.approx(0.5 * full[0, 0] * DT, rel=1e-6)
    assert settle_tau(m, q, load) == pytest.approx(0.5 * (full[0, 0] + 3.0 * r2) * DT, rel=1e-6)
    assert settle_tau(replace(m, actual_settle_lag=None), q, load) == 0.0


def test_row_taus_take_each_motions_end_pose():
    """Two motions starting at 0.024 and 0.060 s: rows before the first τ 0, the first's rows τ at its
    end pose (the axes at 0.060 s), the second's at the last row's."""
    m = load_robot("kr3_r540")
    t = np.arange(8) * DT
    axes = np.zeros((8, 6))
    axes[:, 1], axes[:, 2] = -90.0, 90.0
    axes[5:, 0] = 40.0
    axes[7:, 1] = -60.0
    got = row_taus(m, t, axes, [0.024, 0.060], [None, None])
    first, second = settle_tau(m, axes[5]), settle_tau(m, axes[7])
    assert got.tolist() == pytest.approx([0.0, 0.0, first, first, first, second, second, second])
    assert first != pytest.approx(second)


@pytest.mark.parametrize("text, word", [("settle_lag: 3", "a mapping"),
                                        ("settle_lag: {axis: 0, below_deg_s: 50, cycles_per_kg_m2: 0.5}", "axis"),
                                        ("settle_lag: {axis: 1, below_deg_s: 0, cycles_per_kg_m2: 0.5}", "below_deg_s"),
                                        ("settle_lag: {axis: 1, below_deg_s: 50}", "cycles_per_kg_m2")])
def test_a_bad_settle_lag_is_named(tmp_path, text, word):
    f = tmp_path / "x.yaml"
    f.write_text(f"actual:\n  {text}\n", encoding="utf-8")
    with pytest.raises(MachineDataError, match=word):
        read_identified(f)


PROGRAM = ("DEF settle()\n"
           "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
           "  PTP {A1 40, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
           "  PTP {A1 10, A2 -80, A3 90, A4 0, A5 45, A6 0}\n"
           "END\n")


def test_a_runs_stream_lags_a1_with_each_motions_tau(tmp_path):
    """``krl run``'s actual axes (the trace's ``axes_act``, the controller's stream) are the model of
    the setpoints with the lag, each row's τ its motion's (robot/settlelag.py ``settle_tau`` at the
    segment's target with the program's load, the default one here), the same as the stream over the
    whole trace with :func:`row_taus` (the end pose read at the next START); the lag shows on A1
    (2 cycles per kg m², larger than the KR 3's, so that it does)."""
    src = tmp_path / "settle.src"
    src.write_text(PROGRAM, encoding="latin-1")
    lag = {"axis": 1, "below_deg_s": 50.0, "cycles_per_kg_m2": 2.0}
    machine = replace(load_robot("kr3_r540"), actual_filter_cycles=2, actual_filter_cycles_ptp=5,
                      actual_following=None, actual_dead_cycles=0, actual_settle_lag=lag)
    tw = TraceWriter(keep=True)
    tw.write("robot", 0.0, name=machine.name, source=str(machine.source))
    rt, _ = make_runtime(run_spec(src, mujoco=False, interp="vm", robot=machine, check=True), RunSinks(trace=tw))
    assert rt.run().reason == "completed"
    tw.close()
    poses = [e for e in tw.events if e["kind"] == "pose"]
    starts = [e["t"] for e in tw.events if e["kind"] == "motion" and e["phase"] == "start"]
    t = np.array([p["t"] for p in poses])
    q = np.array([p["axes"] for p in poses])
    got = np.array([p["axes_act"] for p in poses])
    taus = row_taus(machine, t, q, starts, [None] * len(starts))
    # A1's inertia does not depend on A1: the first two motions end at the same τ, the third (A2) not
    assert len(set(np.round(taus[taus > 0], 9))) == 2
    want = actual_axes(q, 2, None, DT, ptp_rows=np.ones(len(q), bool), ptp_cycles=5, lag=lag, taus=taus)
    plain = actual_axes(q, 2, None, DT, ptp_rows=np.ones(len(q), bool), ptp_cycles=5)
    assert got[:, :6] == pytest.approx(want[:, :6], abs=2e-6)
    assert np.abs(want[:, 0] - plain[:, 0]).max() > 0.01
    assert np.abs(want[:, 1:6] - plain[:, 1:6]).max() == 0.0


def test_the_lagged_stream_gives_the_same_rows_in_any_batches():
    """The lag runs row by row with its state carried between computations: rows pushed one at a time
    and computed at arbitrary points equal the whole array's, bit for bit (a random walk braking to rest
    in stretches, two values of τ, a dead time of 3 cycles)."""
    rng = np.random.default_rng(88)
    steps = np.where((np.arange(300) // 40) % 2 == 0, rng.normal(size=300), 0.0)
    q = np.cumsum(np.column_stack([steps * 0.3, rng.normal(size=300)]), axis=0)
    taus = np.where((np.arange(300) // 70) % 2 == 0, 0.012, 0.006)
    whole = actual_axes(q, 4, None, DT, dead=3, lag=LAG, taus=taus)
    assert np.abs(whole - actual_axes(q, 4, None, DT, dead=3)).max() > 1e-3
    s = ActualStream(4, None, DT, 2, keep=True, dead=3, lag=LAG)
    for k, row in enumerate(q):
        s.push(k * DT, row, tau=float(taus[k]))
        if k % 31 == 5:
            s._compute(final=False)
    s.finish(rest=False)
    assert np.array_equal(np.array([r for _, _, r in s.take()]), whole)


def test_a_settle_lag_on_an_axis_the_robot_lacks_is_named(tmp_path):
    """The KR 3 R540 has 6 axes: a lag on axis 7 is refused where the file is applied to it."""
    f = tmp_path / "x.yaml"
    f.write_text("actual:\n  settle_lag: {axis: 7, below_deg_s: 50, cycles_per_kg_m2: 0.5}\n", encoding="utf-8")
    with pytest.raises(MachineDataError, match="7, .* has 6 axes"):
        apply_identified(load_robot("kr3_r540"), f)
