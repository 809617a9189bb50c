"""The kinematic families compiled and as Python (issue 86 item 1): robot/kinematics/fastpath.py's
``Chooser`` on every family's axis count, and each compiled family module (robot/build.py ``PURE``)
against its .py run as Python, bit for bit, and used where it is built.

Expected values: the Python run of the same source (the reference the compiled module must
reproduce: robot/kinematics/compiled.py ``pure_python``), and by hand where a figure is checked."""

from __future__ import annotations

import numpy as np
import pytest

from robot.kinematics import compiled
from tests.robot.test_simcore import fast  # noqa: F401  (the fixture: compiled fastpath, fastpath.py as Python)


def test_the_compiled_chooser_takes_a_seven_axis_row_as_python_does(fast):  # noqa: F811
    """The seven-axis family (robot/kinematics/redundant.py) chooses through fastpath's Chooser with
    n = 7: by hand, the row (10, 20, ..., 70) lies within the limits below and is the only row, so it
    is the answer; with the reference (1, ..., 7) the nearer of two rows is (1.5, ..., 7.5)."""
    lo = [-170.0, -120.0, -170.0, -120.0, -170.0, -120.0, -175.0]
    hi = [170.0, 120.0, 170.0, 120.0, 170.0, 120.0, 175.0]
    ks = [-720.0, -360.0, 0.0, 360.0, 720.0]
    ref = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]
    far = [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0]
    near = [v + 0.5 for v in ref]
    for mod in fast:
        c = mod.Chooser(7, lo, hi, ks, [False] * 7, 0)
        assert c.choose([far], ref, None) == far
        assert c.choose([far, near], ref, None) == near
    rng = np.random.default_rng(86)
    c, p = (m.Chooser(7, lo, hi, ks, [False] * 7, 0b100) for m in fast)
    for _ in range(500):
        rows = [list(rng.uniform(-200.0, 200.0, 7)) for _ in range(int(rng.integers(1, 9)))]
        r = list(rng.uniform(-200.0, 200.0, 7))
        turn = None if rng.random() < 0.5 else int(rng.integers(0, 128))
        assert c.choose(rows, r, turn) == p.choose(rows, r, turn)
