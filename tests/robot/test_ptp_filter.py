"""A PTP's setpoints averaged over their own cycles (issue 88: the drives' settling into $IN_POS_MA).

KSS filters a PTP's setpoints with ``$DEF_FLT_PTP`` and a CP motion's with ``$DEF_FLT_CP`` (every
KR C4 ``$machine.dat`` of ../shared/krl-corpus holds both, the PTP one the longer: 168/120,
180/132, 216/156 ms). The actual-value model (robot/actualvalue.py) averages a row a PTP set over
``ptp_cycles`` rows and any other over ``cycles``; the expected values here are means written out
by hand.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from interp.run import make_runtime, run_spec, RunSinks
from robot.actualvalue import BATCH_ROWS, ActualStream, actual_axes, ptp_rows_of
from robot.kukatrace.model import Motion
from robot.mada import load_robot
from robot.trace import TraceWriter

DT = 0.012


def test_a_ptps_rows_take_the_longer_average():
    """A step of 6° after three rows at rest: over 3 rows (a PTP's) 0, 0, 0, 2, 4, 6, over 2 rows
    (a LIN's) 0, 0, 0, 3, 6, 6; the robot at rest before the first row."""
    q = np.array([0, 0, 0, 6, 6, 6, 6], dtype=float)[:, None]
    ptp = actual_axes(q, 2, None, DT, ptp_rows=np.ones(7, bool), ptp_cycles=3)
    lin = actual_axes(q, 2, None, DT, ptp_rows=np.zeros(7, bool), ptp_cycles=3)
    assert ptp[:, 0].tolist() == pytest.approx([0, 0, 0, 2, 4, 6, 6])
    assert lin[:, 0].tolist() == pytest.approx([0, 0, 0, 3, 6, 6, 6])
    # without a PTP average every row takes the CP one, as before
    assert actual_axes(q, 2, None, DT)[:, 0].tolist() == pytest.approx([0, 0, 0, 3, 6, 6, 6])
    # a row's own kind decides: the LIN's row 3 (1.5 + 1.5), the PTP's row 4 (0 + 6 + 6) / 3
    mixed = actual_axes(q, 2, None, DT, ptp_rows=np.array([0, 0, 0, 0, 1, 1, 1], bool), ptp_cycles=3)
    assert mixed[:, 0].tolist() == pytest.approx([0, 0, 0, 3, 4, 6, 6])


@pytest.mark.parametrize("dead", [0, 2])
def test_the_kind_travels_with_its_row_through_batches_and_the_dead_time(dead):
    """Rows of a random walk in blocks of PTP and LIN rows, more than two batches
    (:data:`BATCH_ROWS`): row k is the mean of the `n` setpoints up to row k - dead, n the kind of
    row k - dead (4 for a PTP's, 2 for the rest), the rows before the first being the first."""
    rng = np.random.default_rng(88)
    n_rows = 2 * BATCH_ROWS + 37
    q = np.cumsum(rng.normal(size=(n_rows, 2)), axis=0)
    flags = (np.arange(n_rows) // 23) % 2 == 1
    got = actual_axes(q, 2, None, DT, dead=dead, ptp_rows=flags, ptp_cycles=4)
    pad = np.vstack([np.repeat(q[:1], 4 + dead, axis=0), q])
    for k in range(n_rows):
        src = k - dead
        n = 4 if flags[max(src, 0)] else 2
        j = src + 4 + dead                      # row src of q in pad
        assert got[k] == pytest.approx(pad[j - n + 1:j + 1].mean(axis=0), abs=1e-12), k


def test_pushed_one_by_one_or_whole_the_same_bits():
    """The kind given only where a motion starts (None: as the row before, the controller's way)
    gives the rows that an array of every row's kind gives, bit for bit, taken in pieces."""
    rng = np.random.default_rng(7)
    q = np.cumsum(rng.normal(size=(150, 3)), axis=0)
    s = ActualStream(3, None, DT, 3, keep=True, dead=1, ptp_cycles=5)
    rows = []
    for k, row in enumerate(q):
        s.push(k * DT, row, ptp=((k // 40) % 2 == 0) if k % 40 == 0 else None)
        if k % 17 == 0:
            rows += s.take()
    s.finish(rest=False)
    rows += s.take()
    flags = np.array([(k // 40) % 2 == 0 for k in range(150)])
    whole = actual_axes(q, 3, None, DT, dead=1, ptp_rows=flags, ptp_cycles=5)
    assert [r for r, _, _ in rows] == list(range(150))
    assert np.array_equal(np.array([a for _, _, a in rows]), whole)


def test_a_sample_belongs_to_the_motion_started_last():
    motions = [Motion("PTP", 1, "a", 0.1), Motion("LIN", 2, "a", 0.5), Motion("SPTP", 3, "a", 0.9)]
    t = np.array([0.0, 0.1, 0.3, 0.5, 0.8, 0.9, 1.5])
    assert ptp_rows_of(t, motions).tolist() == [True, True, True, False, False, True, True]


PROGRAM = ("DEF ptp_lin()\n"
           "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
           "  PTP {A1 40, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
           "  LIN_REL {X 60}\n"
           "END\n")


@pytest.fixture(scope="module")
def ptp_lin_runs(tmp_path_factory):
    """The program on the KR 3 R540 with a plain model: the setpoints averaged over 2 cycles, a
    PTP's over 5, no following error, no dead time, no settling lag (tests/robot/test_settle_lag.py);
    the trace's events of each interpreter."""
    out = {}
    for interp in ("tree", "vm"):
        src = tmp_path_factory.mktemp(interp) / "ptp_lin.src"
        src.write_text(PROGRAM, encoding="latin-1")
        machine = replace(load_robot("kr3_r540"), actual_filter_cycles=2, actual_filter_cycles_ptp=5,
                          actual_following=None, actual_dead_cycles=0, actual_settle_lag=None)
        tw = TraceWriter(keep=True)
        tw.write("robot", 0.0, name=machine.name, source=str(machine.source))
        rt, _ = make_runtime(run_spec(src, mujoco=False, interp=interp, robot=machine, check=True), RunSinks(trace=tw))
        assert rt.run().reason == "completed"
        tw.close()
        out[interp] = tw.events
    return out


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_runs_ptp_rows_and_lin_rows_take_their_own_average(ptp_lin_runs, interp):
    """Each pose's axes_act is the mean of the setpoints of its own and the rows before it (the
    robot at rest before the run): 5 rows from a PTP's start to the next motion's start, 2 from
    the LIN's. Both averages differ while the axes move, so a row taking the other one shows."""
    events = ptp_lin_runs[interp]
    starts = [(e["t"], e["type"]) for e in events if e["kind"] == "motion" and e["phase"] == "start"]
    assert [k for _, k in starts] == ["PTP", "PTP", "LIN_REL"]
    poses = [e for e in events if e["kind"] == "pose"]
    t = np.array([p["t"] for p in poses])
    q = np.array([p["axes"] for p in poses])
    got = np.array([p["axes_act"] for p in poses])
    pad = np.vstack([np.repeat(q[:1], 4, axis=0), q])
    seen = {"PTP": 0, "LIN_REL": 0}
    for k in range(len(q)):
        kind = [m for s, m in starts if s <= t[k] + 1e-9][-1] if t[k] >= starts[0][0] - 1e-9 else "PTP"
        n, other = (5, 2) if kind == "PTP" else (2, 5)
        want = pad[k + 5 - n:k + 5].mean(axis=0)
        assert got[k] == pytest.approx(want, abs=2e-6), (k, kind)
        if np.abs(pad[k + 5 - other:k + 5].mean(axis=0) - want).max() > 1e-3:
            seen[kind] += 1
    assert seen["PTP"] > 10 and seen["LIN_REL"] > 10
