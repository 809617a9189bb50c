"""The pose the drives reach beside the setpoint, and the settled cycle time (issue 73, item 2).

A KRL program of one single-axis PTP runs on the simulated KR 3 R540, whose actual-value model was
identified from its real recordings (robot/data/identified/kr3_r540.yaml ``actual``). The
expected actual axes are computed here by hand from that yaml's parameters, read with a YAML
parser (not through robot/identified.py or robot/actualvalue.py): each setpoint row averaged with
the ``filter_cycles_ptp`` - 1 rows before it (a PTP's average, issue 88; the robot at rest before
the run), less the following
error ``m·q̈ + c·tanh(q̇/v0) + k·q̇`` of the averaged rows, q̇ and q̈ central differences over one
IPO cycle of 12 ms, all of it ``dead_time_cycles`` rows late (row k computed from the setpoints up to
row k - dead; before the first, the first); then A1 through the yaml's ``settle_lag`` (issue 88), written
out here as a loop: ``y += (x - y)·(1 - e^(-dt/τ))`` on the rows where A1's backward-difference speed is
below ``below_deg_s`` and not rising, else ``y = x``; τ of both motions the same (A1's inertia does not
depend on A1: robot/settlelag.py ``settle_tau`` at the end pose, tested in tests/robot/test_settle_lag.py).
The settling window is ``$IN_POS_MA`` of robot/data/kr3_r540.dat's base (KUKA
Machine Data §2.1.119: 0.1° for A1-A3, 0.5° for the wrist here).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from interp.run import make_runtime, run_spec, RunSinks
from interp.summary import cycle_lines, settled_end
from robot.actualvalue import LAG_REST_ROWS, ActualStream, actual_axes
from robot.kukatrace.actual import actual_tcp
from robot.kukatrace.model import run_view
from robot.mada import load_robot
from robot.settlelag import segment_taus, settle_tau
from robot.trace import TraceWriter, validate_event

YAML = Path(__file__).resolve().parents[2] / "robot" / "data" / "identified" / "kr3_r540.yaml"
DT = 0.012
PROGRAM = ("DEF one_ptp()\n"
           "  PTP {A1 0, A2 -110, A3 110, A4 0, A5 0, A6 0}\n"
           "  PTP {A1 90, A2 -110, A3 110, A4 0, A5 0, A6 0}\n"
           "END\n")


def _run(tmp_path, interp: str, robot: str = "kr3_r540"):
    src = tmp_path / "one_ptp.src"
    src.write_text(PROGRAM, encoding="latin-1")
    machine = load_robot(robot)
    tw = TraceWriter(keep=True)
    tw.write("robot", 0.0, name=machine.name, source=str(machine.source))
    rt, _ = make_runtime(run_spec(src, mujoco=False, interp=interp, robot=machine, check=True), RunSinks(trace=tw))
    res = rt.run()
    assert res.reason == "completed"
    tw.close()
    return rt, res, tw.events


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return {i: _run(tmp_path_factory.mktemp(i), i) for i in ("tree", "vm")}


def _by_hand(q: np.ndarray) -> np.ndarray:
    """The actual axes of setpoint rows `q` (N, 6) deg by the yaml's model (the module's docstring)."""
    act = yaml.safe_load(YAML.read_text())["actual"]
    # every row is a PTP's: the PTP average (issue 88; the CP one where the yaml has none)
    n = act.get("filter_cycles_ptp", act["filter_cycles"])
    f, dead = act["following_error"], act.get("dead_time_cycles", 0)
    lag = act.get("settle_lag")
    rest = n + 2 + (LAG_REST_ROWS if lag else 0)
    rows = [q[0]] * (n - 1 + 2 + dead) + list(q) + [q[-1]] * rest      # at rest before and after
    qf = [sum(rows[j - k] for k in range(n)) / n for j in range(n - 1, len(rows))]
    out = []
    for j in range(2, len(qf) - 2):
        v = lambda i: (qf[i + 1] - qf[i - 1]) / (2 * DT)      # noqa: E731
        a = (v(j + 1) - v(j - 1)) / (2 * DT)
        vj = v(j)
        e = [f["inertia_s2"][i] * a[i] + f["coulomb_deg"][i] * math.tanh(vj[i] / f["coulomb_speed_deg_s"])
             + f["viscous_s"][i] * vj[i] for i in range(6)]
        out.append(qf[j] - np.array(e))
    out = np.array(out)
    if lag:
        tau = settle_tau(load_robot("kr3_r540"), [90.0, -110.0, 110.0, 0.0, 0.0, 0.0])
        i, y, x0, v0 = lag["axis"] - 1, out[0, lag["axis"] - 1], out[0, lag["axis"] - 1], 0.0
        for k in range(len(out)):
            x = out[k, i]
            v = abs(x - x0) / DT
            y = y + (x - y) * (1.0 - math.exp(-DT / tau)) if v < lag["below_deg_s"] and v <= v0 else x
            x0, v0, out[k, i] = x, v, y
    return out           # rows of q, then the rest rows after the last setpoint


def _poses(events):
    return [e for e in events if e["kind"] == "pose"]


def test_pose_act_lags_the_setpoint_by_the_model(runs):
    """Each pose carries the actual axes the model gives (to the trace's rounding, 1e-6 deg in,
    amplified by m/dt² ≈ 0.2 at most), A1 lags its setpoint while it moves, the TCP of the actual
    axes equals the setpoint's TCP where the axes are equal (at rest before the motion: the
    program ends before the robot has settled, 3 cycles of dead time after it), and every pose
    event follows the schema."""
    poses = _poses(runs["vm"][2])
    q = np.array([p["axes"] for p in poses])
    got = np.array([p["axes_act"] for p in poses])
    want = _by_hand(q)[:len(q)]
    assert np.abs(got - want).max() < 1e-5
    moving = np.flatnonzero(np.abs(np.diff(q[:, 0])) > 1e-3) + 1
    assert len(moving) > 5
    lag = q[moving, 0] - got[moving, 0]
    assert (lag[len(lag) // 4: len(lag) // 2] > 0.05).all()      # accelerating towards +90°: behind
    same = [p for p in poses if np.abs(np.subtract(p["axes_act"], p["axes"])).max() < 1e-9]
    assert same and all(np.allclose(p["tcp_act"], p["tcp"], atol=1e-5) for p in same)
    assert not np.allclose(poses[-1]["axes_act"], poses[-1]["axes"], atol=1e-3)    # still moving in
    for p in poses[:3] + poses[-3:]:
        validate_event(p)


def test_both_interpreters_give_the_same_pose_act(runs):
    a, b = (_poses(runs[i][2]) for i in ("tree", "vm"))
    assert len(a) == len(b) > 30
    assert [(p["t"], p["axes_act"], p["tcp_act"]) for p in a] == [(p["t"], p["axes_act"], p["tcp_act"]) for p in b]


def test_the_settled_cycle_time_exceeds_the_setpoints_by_the_settling_time(runs):
    """The setpoints end at the last cycle A1's setpoint changes; the robot has settled at the
    first cycle from which the hand-computed actual axes stay within $IN_POS_MA of the setpoint
    (the rest rows after the run included); the summary says both and which one is the cycle time."""
    for interp in ("tree", "vm"):
        rt, res, events = runs[interp]
        poses = _poses(events)
        t = np.array([p["t"] for p in poses])
        q = np.array([p["axes"] for p in poses])
        act = _by_hand(q)
        tt = np.concatenate([t, t[-1] + DT * np.arange(1, len(act) - len(t) + 1)])
        qq = np.vstack([q, np.repeat(q[-1:], len(act) - len(q), axis=0)])
        window = np.array([0.1, 0.1, 0.1, 0.5, 0.5, 0.5])
        outside = np.flatnonzero(np.any(np.abs(act - qq) > window, axis=1))
        settled = tt[outside[-1] + 1]
        changed = np.flatnonzero(np.any(np.diff(q, axis=0) != 0, axis=1))
        setpoints = t[changed[-1] + 1]
        assert settled > setpoints + DT
        assert settled_end(rt) == pytest.approx((setpoints, settled), abs=1e-9)
        (line,) = cycle_lines(res, rt)
        which = "the robot settled" if settled >= res.sim_time - 1e-9 else "the program ended"      # a tie: settled
        assert f"cycle time {max(settled, res.sim_time):.3f} s, until {which}" in line
        assert f"setpoints ended at {setpoints:.3f} s" in line and f"settled at {settled:.3f} s" in line
        assert f"+{round(1000 * (settled - setpoints))} ms" in line


def test_trace_compare_takes_the_same_model(runs):
    """krl trace compare's actual TCP (robot/kukatrace/actual.py) of the run, with the settling lag
    and each motion's τ, equals the trace's tcp_act inside the run (its first and last rows take
    one-sided differences: a window)."""
    events = runs["vm"][2]
    view = run_view(events, "trace", "one_ptp")
    seg = view.segments[0]
    machine = load_robot("kr3_r540")
    # a trace holds no $LOAD: compare leaves the settling lag out unless given it (the program set none: the default)
    got = actual_tcp(view, seg, settle_lag=machine.actual_settle_lag, taus=segment_taus(machine, seg))
    want = np.array([p["tcp_act"][:3] for p in _poses(events)])
    assert got.shape == want.shape
    assert np.abs(got[3:-3] - want[3:-3]).max() < 1e-4


def test_the_stream_gives_the_same_rows_in_any_batches():
    """Rows pushed one at a time and computed at arbitrary points equal the whole array's."""
    follow = yaml.safe_load(YAML.read_text())["actual"]["following_error"]
    q = np.cumsum(np.random.default_rng(7).normal(size=(200, 6)), axis=0)
    for dead, every, at in ((0, 29, 3), (3, 31, 5)):     # (a dead time of 3 cycles: computed at other points)
        whole = actual_axes(q, 4, follow, DT, dead=dead)
        s = ActualStream(4, follow, DT, 6, keep=True, dead=dead)
        for k, row in enumerate(q):
            s.push(k * DT, row)
            if k % every == at:
                s._compute(final=False)
        s.finish(rest=False)
        assert np.array_equal(np.array([r for _, _, r in s.take()]), whole), dead


def test_a_dead_time_delays_the_model_and_the_settling_by_hand():
    """Setpoints of A1 0, 0, 1, 2, 2, ... deg at rows 0, 1, 2, 3, ... (cycles 1, no following
    error, window 0.1°). Without a dead time the actual axes are the setpoints, never outside the
    window: settled from the first row (t = 0). With 3 cycles they are the setpoints 3 rows earlier
    (0 before the first): rows 2..5 are outside (0, 0, 0, 1 against 1, 2, 2, 2), so the robot has
    settled at row 6 (t = 0.072 s), 3 cycles after the setpoints' last change at row 3."""
    q = np.zeros((8, 6))
    q[2:, 0] = [1.0, 2.0, 2.0, 2.0, 2.0, 2.0]
    for dead, settled in ((0, 0.0), (3, 6 * DT)):
        s = ActualStream(1, None, DT, 6, window=(0.1,) * 6, keep=True, at_rest=True, dead=dead)
        for k, row in enumerate(q):
            s.push(k * DT, row)
        s.finish()
        got = np.array([r for _, _, r in s.take()])
        assert got[:, 0].tolist() == ([0.0] * dead + [0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 2.0, 2.0])[:8]
        assert s.settled_at() == pytest.approx(settled)


def test_a_robot_without_a_model_writes_the_trace_as_before(tmp_path):
    rt, res, events = _run(tmp_path, "vm", "kr6_r900")
    poses = _poses(events)
    assert poses and all(set(p) == {"t", "kind", "axes", "tcp"} for p in poses)
    assert cycle_lines(res, rt) == []
