"""Segment-vectorised IK (issue 39, "Simulator"): a chain of poses solved at once
(Kinematics.inverse_chain) equals the per-pose chain where each solution is the next one's
reference, bit for bit, or declines (None); the main run with Controller.batch writes the
same trace bytes as cycle by cycle. (The comparison with the traces of 8175047 is
``python -m robot.tracecheck --against DIR``.)"""

from __future__ import annotations

import numpy as np
import pytest

from robot import kinematics, tracecheck
from robot.controller import Controller
from robot.errors import SoftLimitError, WorkspaceError
from robot.kinematics import Kinematics
from robot.machine import load_machine


def _sequential(k: Kinematics, T: np.ndarray, status: int, ref: np.ndarray) -> np.ndarray:
    out = []
    for i in range(len(T)):
        ref = k.inverse(T[i], status, None, ref)
        out.append(ref)
    return np.array(out)


def _path(q_a, q_b, n: int) -> np.ndarray:
    f = np.linspace(0.0, 1.0, n)[:, None]
    return np.asarray(q_a, dtype=float) + f * (np.asarray(q_b, dtype=float) - np.asarray(q_a, dtype=float))


@pytest.mark.parametrize("q_a, q_b", [
    # A4/A6 through ±180° (the turn nearest to the last solution, pass after pass)
    ([10.0, -80.0, 95.0, 150.0, 40.0, 170.0], [-20.0, -95.0, 110.0, 230.0, 60.0, 330.0]),
    # A5 to 0 exactly (the wrist singularity: A4 taken from the reference)
    ([0.0, -90.0, 90.0, 30.0, 30.0, -40.0], [25.0, -70.0, 80.0, 30.0, 0.0, 20.0]),
])
def test_the_chain_is_the_per_pose_chain_bit_for_bit(q_a, q_b):
    k = Kinematics(load_machine())
    Q = _path(q_a, q_b, 120)
    T = k.forward_many(Q)
    ref = np.array(q_a, dtype=float) + 0.3
    status = k.status_turn(q_a)[0]
    want = _sequential(k, T, status, ref)
    got = k.inverse_chain(T, status, ref, passes=12)
    assert got is not None
    assert got.tobytes() == want.tobytes()
    # the result is the path itself (turns followed, not wrapped back)
    assert np.max(np.abs(got[:, [0, 1, 2, 4]] - Q[:, [0, 1, 2, 4]])) < 1e-4    # acos near A5 = 0: 1e-6 deg


def test_a_pose_out_of_reach_declines_the_chain():
    k = Kinematics(load_machine())
    Q = _path([0.0, -90.0, 90.0, 0.0, 60.0, 0.0], [30.0, -80.0, 100.0, 10.0, 50.0, 20.0], 20)
    T = k.forward_many(Q)
    T[7, :3, 3] = (5000.0, 0.0, 0.0)
    with pytest.raises(WorkspaceError):
        _sequential(k, T, 2, Q[0])
    assert k.inverse_chain(T, 2, Q[0], passes=6) is None


def test_beyond_the_passes_the_chain_declines():
    k = Kinematics(load_machine())
    Q = _path([0.0, -90.0, 90.0, -150.0, 40.0, -170.0], [0.0, -90.0, 90.0, 200.0, 40.0, 300.0], 60)
    T = k.forward_many(Q)
    assert k.inverse_chain(T, 2, Q[0], passes=0) is None       # the first pass alone is a guess
    try:
        want = _sequential(k, T, 2, Q[0])
    except (WorkspaceError, SoftLimitError):
        want = None
    got = k.inverse_chain(T, 2, Q[0], passes=20)
    assert (got is None) == (want is None)
    if want is not None:
        assert got.tobytes() == want.tobytes()


@pytest.mark.parametrize("case", ["random-00", "random-02"])
def test_the_main_run_batched_writes_the_same_trace(case, monkeypatch):
    if case == "random-02" and tracecheck._corpus() is None:
        pytest.skip("the KR 210 of random-02 comes from the corpus")
    calls = {"n": 0}
    orig = Kinematics.inverse_chain

    def counting(self, *a, **kw):
        calls["n"] += 1
        return orig(self, *a, **kw)

    monkeypatch.setattr(Kinematics, "inverse_chain", counting)
    # the numpy chains run where the compiled inverse (robot/kinematics/fastpath.py) does not
    monkeypatch.setattr(kinematics.compiled, "USE_COMPILED", False)
    monkeypatch.setattr(Controller, "batch", False)
    per_cycle = tracecheck.run_case(case)
    n_planning = calls["n"]
    monkeypatch.setattr(Controller, "batch", True)
    batched = tracecheck.run_case(case)
    assert calls["n"] - 2 * n_planning > 0      # the main run solved chains of cycles
    assert batched == per_cycle
