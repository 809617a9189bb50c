"""The drives' system variables in a folder without Mada/ (issue 59: OsmanMarangoz's
motion_eki.src computes its joints' top speed from $VEL_AXIS_MA and $RAT_MOT_AX and streams
$VEL_AXIS_ACT and $TORQUE_AXIS_ACT to its partner; each read "value invalid" before): the machine
data of the simulated robot (robot/data/kr6_r900.yaml, cited from a $machine.dat), each axis's
velocity in % of its top speed, and torques of 0.0 with one note (no drive model). Both
interpreters."""

from __future__ import annotations

import pytest

from .helpers import run_krl

SRC = """
DEF prog()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  TRIGGER WHEN DISTANCE=0 DELAY=150 DO v1=$VEL_AXIS_ACT[1]
  PTP {A1 60}
  rpm = $VEL_AXIS_MA[1]
  n = $RAT_MOT_AX[1].N
  d = $RAT_MOT_AX[1].D
  tq = $TORQUE_AXIS_ACT[2]
  tq = $TORQUE_AXIS_ACT[3]
  rest = $VEL_AXIS_ACT[1]
END
"""
DAT = """
DEFDAT prog
  DECL REAL v1 = -1.0
  DECL REAL rpm, tq, rest
  DECL INT n, d
ENDDAT
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_drives_read_the_simulated_robots_values(tmp_path, interp):
    run = run_krl(tmp_path, SRC, DAT, interp=interp)
    assert run.result.reason == "completed", run.result.text
    assert (run.var("prog", "rpm"), run.var("prog", "n"), run.var("prog", "d")) == (6000.0, -100, 1)
    # A1 at its top speed mid-motion: 6000 rpm / 100 * 6 = 360 deg/s, 100 %
    assert 50.0 < run.var("prog", "v1") <= 100.0 + 1e-6
    assert 0.0 <= run.var("prog", "rest") < 2.0        # the last cycle of the deceleration
    assert run.var("prog", "tq") == 0.0
    notes = [e["text"] for e in run.kinds("message") if "TORQUE" in e["text"]]
    assert notes == ["not simulated: system variable $TORQUE_AXIS_ACT (the simulator has no drive model): reads 0.0"]
