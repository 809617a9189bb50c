"""Arms without a closed form (robot/kinematics/numeric.py; issue 34): machine data whose chain is not
ortho-parallel with a spherical wrist get the numeric solver (mink on the robot's MuJoCo model),
with the status/turn selection and the errors of the analytic forms.

Expected values: the axes forward kinematics started from (round trip), the machine-data chain
itself (robot/chain.py chain_forward, the product of the frames KUKA's variables define), and
the OPW form found in the geometry when a $TIRORO or $TFLWP only rotates the frame."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robot.chain import chain_forward
from robot.errors import SoftLimitError, WorkspaceError
from robot.frames import frame_to_matrix
from robot.kinematics import Kinematics
from robot.mada import load_mada
from robot.machine import ROBOT_LIBRARY

KR16 = ROBOT_LIBRARY / "kr16_2_krc2.dat"


def _edited(tmp_path: Path, old: str, new: str) -> Path:
    text = KR16.read_text(encoding="utf-8")
    assert old in text
    p = tmp_path / "$machine.dat"
    p.write_text(text.replace(old, new), encoding="utf-8")
    return p


def _round_trips(k: Kinematics, n_max: int = 12) -> int:
    m = k.machine
    rng = np.random.default_rng(4)
    lo = np.maximum(np.array(m.softn_end), -170.0) + 2.0
    hi = np.minimum(np.array(m.softp_end), 170.0) - 2.0
    n = 0
    for q in rng.uniform(lo, hi, size=(3 * n_max, 6)):
        if abs(q[4]) < 5.0 or n >= n_max:
            continue
        T = k.forward(q)
        assert np.abs(T - chain_forward(m.chain, q)).max() < 1e-6
        s, t = k.status_turn(q)
        np.testing.assert_allclose(k.inverse(T, s, t, reference_deg=q), q, atol=1e-6)
        # from HOME, with the status and turn of the target: the same configuration
        got = k.inverse(T, s, t, reference_deg=m.home_deg)
        np.testing.assert_allclose(k.forward(got), T, atol=1e-6)
        n += 1
    return n


def test_a_twisted_forearm_is_solved_numerically(tmp_path):
    m = load_mada(_edited(tmp_path, "$TX3P3={X 670.000,Y 0.0,Z -35.0000,A 0.0,B 90.0000",
                          "$TX3P3={X 670.000,Y 0.0,Z -35.0000,A 20.0,B 90.0000"))
    k = Kinematics(m)
    assert k.family == "numeric"
    assert _round_trips(k) >= 10


def test_a_wrist_offset_is_solved_numerically(tmp_path):
    m = load_mada(_edited(tmp_path, "$DH_5={DHART_A 0.0,DHART_D 0.0,", "$DH_5={DHART_A 0.0,DHART_D 40.0,"))
    k = Kinematics(m)
    assert k.family == "numeric"
    assert _round_trips(k) >= 10


def test_numeric_errors_are_the_analytic_ones(tmp_path):
    m = load_mada(_edited(tmp_path, "$DH_5={DHART_A 0.0,DHART_D 0.0,", "$DH_5={DHART_A 0.0,DHART_D 40.0,"))
    k = Kinematics(m)
    with pytest.raises(WorkspaceError, match="workspace error: target not reachable"):
        k.inverse(frame_to_matrix(4000.0, 0.0, 500.0, 0.0, 90.0, 0.0))
    q = np.array([10.0, -60.0, 100.0, 20.0, 40.0, 30.0])
    with pytest.raises(SoftLimitError, match="-A1"):
        k.inverse(k.forward(q), 2, 1, reference_deg=q)


def test_a_rotated_robot_base_and_flange_keep_the_closed_form(tmp_path):
    """A $TIRORO and a $TFLWP that rotate (and shift) the frame before A1 and after A6: the arm
    is still ortho-parallel with a spherical wrist, and robot/chain.py finds that form."""
    p = _edited(tmp_path, "$TIRORO={X 0.0,Y 0.0,Z 675.000,A 0.0,B 0.0,C 0.0}",
                "$TIRORO={X 20.0,Y -10.0,Z 675.000,A 30.0,B 0.0,C 180.0}")
    text = p.read_text(encoding="utf-8").replace("$TFLWP={X 0.0,Y 0.0,Z 158.000,A 0.0,B 0.0,C 0.0}",
                                                 "$TFLWP={X 5.0,Y 0.0,Z 158.000,A 90.0,B 0.0,C 0.0}")
    p.write_text(text, encoding="utf-8")
    k = Kinematics(load_mada(p))
    assert k.family == "opw"
    assert _round_trips(k) >= 10
