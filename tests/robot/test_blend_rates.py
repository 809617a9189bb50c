"""A blend's axis rates along a CP motion (robot/blending.py ``_rates_at``, ``plan_blend``'s
acceleration check in axis space): the axes at the window's samples solved in one call of the
segment's compiled path (``_chained_axes``: robot/cartpath.py ``CartPath.chain_u``) are the ones
the pose-by-pose loop solves (``seg.ik(*seg.pose_u(u), ref)``, each the next one's reference),
bit for bit, from the start and from the end (issue 86)."""

from __future__ import annotations

import numpy as np
import pytest

from robot import blending, kinematics
from robot.bench import bench_program
from robot.machine import ROBOT_LIBRARY
from robot.mada import load_mada
from robot.motion import MotionParams, MotionRequest
from tests.robot.test_simcore import _segments


def _palletizer_program(machine):
    """PTP home, then LINs down, across (A1 turns: ``#VAR``) and up, as examples/palletizer5's
    place: the flange pointing down (A = 0, B = 0, C = 180)."""
    P = MotionParams.initmov(machine)
    down = {"A": 0.0, "B": 0.0, "C": 180.0}
    return [MotionRequest("PTP", {"A1": 0.0, "A2": -90.0, "A3": 90.0, "A4": 0.0, "A5": 90.0, "A6": 0.0}, P),
            MotionRequest("LIN", {"X": 2200.0, "Y": 0.0, "Z": 1400.0, **down}, P),
            MotionRequest("LIN", {"X": 2200.0, "Y": 0.0, "Z": 900.0, **down}, P),
            MotionRequest("LIN", {"X": 1500.0, "Y": 1500.0, "Z": 900.0, "A": 45.0, "B": 0.0, "C": 180.0}, P),
            MotionRequest("LIN", {"X": 1500.0, "Y": 1500.0, "Z": 1500.0, "A": 45.0, "B": 0.0, "C": 180.0}, P)]


def _pose_by_pose(monkeypatch, seg, us, from_end):
    with monkeypatch.context() as m:
        m.setattr(blending, "_chained_axes", lambda *a: None)
        return blending._rates_at(seg, us, from_end)


@pytest.mark.parametrize("robot", ["kr6", "palletizer5"])
def test_a_blends_cp_rates_are_the_pose_by_pose_ones(monkeypatch, robot):
    if kinematics.compiled_module() is None:
        pytest.skip("robot/cartpath.py is not built here (python -m robot.build): nothing compiled to compare")
    if robot == "kr6":
        machine, program = None, bench_program(None)
    else:
        machine = load_mada(ROBOT_LIBRARY / "kr180_r3200_pa5.dat")
        program = _palletizer_program(machine)
    rng = np.random.default_rng(86)
    chained = 0
    for seg in _segments(machine, program):
        if seg.path_length <= 0:
            continue
        for from_end in (True, False):
            lo = rng.uniform(0.0, 0.6)
            us = np.sort(rng.uniform(lo, lo + 0.4, 9))
            grid = np.linspace(float(us.min()), float(us.max()), blending._BLEND_SAMPLES + 1)
            chain = blending._chained_axes(seg, grid, from_end, seg.q1 if from_end else seg.q0)
            got = blending._rates_at(seg, us, from_end)
            want = _pose_by_pose(monkeypatch, seg, us, from_end)
            assert got[0].tobytes() == want[0].tobytes() and got[1].tobytes() == want[1].tobytes()
            if chain is not None:
                chained += 1
                # the chain's rows are the loop's axes: from the end, its first row is the last one solved
                ref = seg.q1 if from_end else seg.q0
                for j in (range(len(grid) - 1, -1, -1) if from_end else range(len(grid))):
                    ref = seg.ik(*seg.pose_u(float(grid[j])), ref)
                    assert chain[j].tobytes() == ref.tobytes()
    assert chained >= 4
