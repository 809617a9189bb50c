"""What holds the robot still at a motion when a run ends (issue 85, item 9: "A production program
sits at LIN XDejarCNC from 150 s to 300 s with the robot still (29 motions by 150 s, none after),
and the summary does not say what holds it"), on both interpreters: a conditional stop whose
condition stays TRUE (STOP WHEN PATH, KSS 8.3 "Conditional stop": the robot stands at the stop
point while it holds) is named, with the motion it holds, in ``krl run``'s summary."""

from __future__ import annotations

import pytest

from interp.summary import RunObserver, summary_lines

from .helpers import run_krl

#: the stop point is the start of the SPTP of line 4 (ONSTART, 0 mm); nothing sets $IN[9], so the
#: condition NOT $IN[9] stays TRUE and the robot stands there until the time limit
HELD = """
DEF prog()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  STOP WHEN PATH = 0 ONSTART IF NOT $IN[9]
  SPTP {A1 20}
  SPTP {A1 0}
END
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_summary_says_which_conditional_stop_holds_the_robot(tmp_path, interp):
    r = run_krl(tmp_path, HELD, max_sim_time=3.0, trace=False, interp=interp)
    assert r.result.reason == "max_sim_time", r.result.text
    prog = str(tmp_path / "prog.src")
    lines = summary_lines(r.result, RunObserver(), program=prog, interp=interp, run=r.rt)
    held = [x for x in lines if x.startswith("  held ")]
    assert held == [f"  held       STOP WHEN PATH (line 3) of the SPTP at {prog}:4: its condition is still TRUE, "
                    "the robot stands at its stop point"]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_nothing_is_said_to_hold_a_robot_that_completed(tmp_path, interp):
    """The same program with $IN[9] set from the start: the condition does not hold, the robot
    goes on, the program completes, no 'held' line."""
    r = run_krl(tmp_path, HELD.replace("IF NOT $IN[9]", "IF $IN[9]"), max_sim_time=3.0, trace=False, interp=interp)
    assert r.result.reason == "completed", r.result.text
    lines = summary_lines(r.result, RunObserver(), program="prog.src", interp=interp, run=r.rt)
    assert not [x for x in lines if x.startswith("  held ")]
