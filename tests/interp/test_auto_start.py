"""Where a run of ``--inputs auto`` starts when the backup's home is no pose of the robot driven
(interp/run.py ``plan_cell``; found by the variants sweep, issue 85: the ``a4fix-limits`` variant
of ChinaMilling drives a five-axis palletizer whose A4 is held at 0, and ChinaMilling's XHOME
has A4 -90: the run ended in an internal error, "StartError: start XHOME: software limit switch
-A4"). The run itself chose XHOME (a cell starts at home); a home the robot cannot take is not the
program's error: the run starts where the robot stands by default ($AXIS_HOME[1]) and its summary
says why XHOME was not taken. A start the user asks for (``--start``) stays a clear refusal.

Rebuilt here: a backup whose ``$config.dat`` has XHOME at A4 -90, run on the robot library's
KR 180 R3200 PA5 (A4 held at 0 by ``$DEF_A4FIX``: its model's A4 range is 0 .. 0), so XHOME is
outside it by hand; the program's one PTP is a pose of that robot and completes."""

from __future__ import annotations

import pytest

from interp.run import RunSinks, make_runtime, run_spec
from interp.summary import RunObserver, summary_lines
from robot.machine import ROBOT_LIBRARY
from robot.mada import load_mada
from robot.stimuli import StartError

from .helpers import write

PROG = """
DEF prog()
  PTP {A1 10, A2 -90, A3 90, A4 0, A5 30, A6 0}
END
"""
CONFIG = """
DEFDAT $CONFIG
  DECL E6AXIS XHOME={A1 0.0,A2 -90.0,A3 90.0,A4 -90.0,A5 30.0,A6 0.0}
ENDDAT
"""


def _backup(tmp):
    write(tmp, "R1/System/$config.dat", CONFIG)
    return write(tmp, "R1/Program/prog.src", PROG)


def _spec(prog, interp, **kw):
    return run_spec(prog, inputs="auto", max_sim_time=5.0, mujoco=False, check=False, interp=interp,
                    robot=load_mada(ROBOT_LIBRARY / "kr180_r3200_pa5.dat"), **kw)


@pytest.mark.parametrize("interp", ("tree", "vm"))
def test_a_home_the_robot_cannot_take_is_not_where_an_auto_run_starts(tmp_path, interp):
    prog = _backup(tmp_path)
    rt, _ = make_runtime(_spec(prog, interp), RunSinks())
    res = rt.run()
    assert res.reason == "completed", res.text
    lines = summary_lines(res, RunObserver(), program=str(prog), interp=interp, run=rt)
    start = [x for x in lines if x.startswith("  start ")]
    assert len(start) == 1 and "XHOME not taken" in start[0] and "-A4" in start[0], lines


def test_a_start_the_user_asks_for_stays_a_refusal(tmp_path):
    prog = _backup(tmp_path)
    with pytest.raises(StartError, match="start XHOME"):
        make_runtime(_spec(prog, "vm", start="XHOME"), RunSinks())
