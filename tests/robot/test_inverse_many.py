"""The vectorised inverse kinematics (Kinematics.inverse_many; issue 34, for planning a motion's
IPO cycles at once): row i equals inverse(T[i], S, T, ref[i]) bit for bit on the OPW family,
and row by row on the others; the error is the first failing row's, with its index."""

from __future__ import annotations

import numpy as np
import pytest

from robot.errors import SoftLimitError, WorkspaceError
from robot.frames import frame_to_matrix
from robot.kinematics import Kinematics
from robot.mada import load_mada, load_robot
from robot.machine import ROBOT_LIBRARY, load_machine


def _targets(k: Kinematics, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    m = k.machine
    rng = np.random.default_rng(seed)
    Q = rng.uniform(np.maximum(m.softn_end, -160.0), np.minimum(m.softp_end, 160.0), size=(n, 6))
    return Q, k.forward_many(Q)


def _scalar(k, T, status, turn, refs):
    return np.array([k.inverse(T[i], status, turn, refs[i]) for i in range(len(T))])


@pytest.mark.parametrize("robot", ["kr6", "kr16_2_krc2"])
def test_rows_are_bit_identical_to_the_per_target_solver(robot):
    m = load_machine() if robot == "kr6" else load_mada(ROBOT_LIBRARY / f"{robot}.dat")
    k = Kinematics(m)
    Q, T = _targets(k, 400, 3)
    # a CP path: each reference a little off the target (the previous IPO cycle)
    refs = Q + np.random.default_rng(4).normal(0.0, 1.5, Q.shape)
    ok = []
    for i in range(len(T)):
        try:
            k.inverse(T[i], None, None, refs[i])
            ok.append(i)
        except (WorkspaceError, SoftLimitError):
            pass
    assert len(ok) > 300
    T, refs, Q = T[ok], refs[ok], Q[ok]
    many = k.inverse_many(T, None, None, refs)
    assert np.array_equal(many, _scalar(k, T, None, None, refs))
    same = [i for i in range(len(T)) if k.status_turn(refs[i])[0] == k.status_turn(Q[i])[0]
            and abs(Q[i][4]) > 2.0]
    assert np.abs(many[same] - Q[same]).max() < 1e-6         # the path's own axes, same status
    # with the status and turn of one target for all: compare where the scalar solver succeeds
    s, t = k.status_turn(Q[0])
    sel = [i for i in range(len(T)) if k.status_turn(Q[i]) == (s, t)]
    assert np.array_equal(k.inverse_many(T[sel], s, t, refs[sel]), _scalar(k, T[sel], s, t, refs[sel]))


def test_other_families_solve_row_by_row():
    k = Kinematics(load_mada(ROBOT_LIBRARY / "kr180_r3200_pa5.dat"))
    axes = np.array([[10.0, -60.0, 100.0, 0.0, 20.0, 5.0], [-30.0, -80.0, 120.0, 0.0, -40.0, 90.0]])
    T = k.forward_many(axes)
    np.testing.assert_array_equal(k.inverse_many(T, reference_deg=axes), _scalar(k, T, None, None, axes))


def test_the_error_is_the_first_failing_rows():
    k = Kinematics(load_machine())
    Q, T = _targets(k, 5, 8)
    T[3] = frame_to_matrix(5000.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    with pytest.raises(WorkspaceError) as err:
        k.inverse_many(T, None, None, Q)
    assert err.value.row == 3


def test_a_corpus_robot(shared_corpus):
    k = Kinematics(load_robot(shared_corpus / "khrzysio__KRC4_test"))
    Q, T = _targets(k, 200, 5)
    good = [i for i in range(len(T)) if k.within_limits(Q[i])]
    many = k.inverse_many(T[good], None, None, Q[good])
    assert np.array_equal(many, _scalar(k, T[good], None, None, Q[good]))
