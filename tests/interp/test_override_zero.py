"""A motion planned at ``$OV_PRO = 0`` holds (issue 85 item 9c), on both interpreters.

Rebuilt from the issue's description: "a production program sits at ``LIN XDejarCNC`` from 150 s
to 300 s with the robot still, and the summary does not say what holds it". On KSS the program
override is 0..100 % (the robot's own range, docs/robot.md; KUKA's mxAutomation block
KRC_SetOverride: "Override INT 0 ... 100 %", the robot takes a change as it comes); at 0 % the
robot stands while its program runs, and moves again when the override rises. Before this
change the simulator ended the run at the motion with "$OV_PRO must be positive".

Expected values by hand: the submit program raises the override when its own timer reaches
1000 ms, so the held PTP starts at 1.0 s, within one pass of the submit program's loop (a
few IPO cycles of 12 ms); an interrupt on an input the cell sets at 1.5 s raises it there.
"""

from __future__ import annotations

import re

import pytest

from interp.summary import RunObserver, summary_lines

from .helpers import run_krl

INTERPS = ("tree", "vm")

#: the file starts at DEF (helpers.write strips the first newline): the held PTP is line 3
PROG = """
DEF prog()
  $OV_PRO = 0
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  PTP {A1 20}
END
"""

#: the submit program raises the override at 1 s of its own timer
RAISES = """
DEF sps()
  $TIMER[1] = 0
  $TIMER_STOP[1] = FALSE
  LOOP
    IF $TIMER[1] >= 1000 THEN
      $OV_PRO = 100
    ENDIF
  ENDLOOP
END
"""

#: a submit program that never touches the override: it runs on, counting its passes
COUNTS = """
DEF sps()
  LOOP
    Passes = Passes + 1
  ENDLOOP
END
"""
COUNTS_DAT = """
DEFDAT prog PUBLIC
  DECL GLOBAL INT Passes = 0
ENDDAT
"""

#: an interrupt raises the override when the cell sets $IN[5] at 1.5 s
BY_INTERRUPT = """
DEF prog()
  INTERRUPT DECL 3 WHEN $IN[5] DO Raise()
  INTERRUPT ON 3
  $OV_PRO = 0
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  PTP {A1 20}
END

DEF Raise()
  $OV_PRO = 100
END
"""
AT_1_5 = "- at: 1.5\n  set: {\"$IN[5]\": true}\n"


def _starts(r) -> list[float]:
    return [e["t"] for e in r.kinds("motion") if e["phase"] == "start"]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_motion_at_override_zero_waits_for_the_submit_program_to_raise_it(tmp_path, interp):
    r = run_krl(tmp_path, PROG, files={"sps.sub": RAISES}, submit=["sps.sub"], max_sim_time=4.0, interp=interp)
    assert r.result.reason == "completed", r.result.text
    starts = _starts(r)
    assert len(starts) == 2
    assert 1.0 <= starts[0] < 1.1            # held until the override rose at 1 s
    assert len([e for e in r.kinds("motion") if e["phase"] == "end"]) == 2


@pytest.mark.parametrize("interp", INTERPS)
def test_an_interrupt_raises_the_override_while_the_motion_is_held(tmp_path, interp):
    r = run_krl(tmp_path, BY_INTERRUPT, stimuli=AT_1_5, max_sim_time=6.0, interp=interp)
    assert r.result.reason == "completed", r.result.text
    starts = _starts(r)
    assert len(starts) == 2 and 1.5 <= starts[0] < 1.6


@pytest.mark.parametrize("interp", INTERPS)
def test_a_run_that_ends_held_says_what_holds_it(tmp_path, interp):
    """The override never rises: the robot stands, the submit program runs on to the time
    limit, and the summary names the motion, the cause and since when."""
    r = run_krl(tmp_path, PROG, COUNTS_DAT, files={"sps.sub": COUNTS}, submit=["sps.sub"], max_sim_time=1.0,
                interp=interp)
    assert r.result.reason == "max_sim_time", r.result.text
    assert r.var("prog", "Passes") > 40       # kept running: 1 s is 83 IPO cycles of 12 ms
    assert _starts(r) == []                   # the robot never moved
    prog = str(tmp_path / "prog.src")
    lines = summary_lines(r.result, RunObserver(), program=prog, interp=interp, run=r.rt)
    held = [x for x in lines if x.startswith("  held ")]
    assert len(held) == 1, lines
    m = re.fullmatch(r"  held       motion at (.*):3 held: \$OV_PRO = 0 since t = ([0-9.]+) s(.*)", held[0])
    assert m is not None, held
    assert m.group(1) == prog and float(m.group(2)) < 0.05


@pytest.mark.parametrize("interp", INTERPS)
def test_a_hold_nothing_can_end_is_a_deadlock_at_the_motion(tmp_path, interp):
    """No submit program, no interrupt: nothing can raise the override, the run ends at once
    as deadlocked at the held motion (not as an error of the planner)."""
    r = run_krl(tmp_path, PROG, max_sim_time=5.0, trace=False, interp=interp)
    assert r.result.reason == "deadlock", r.result.text
    assert "$OV_PRO = 0" in r.result.text and "prog.src:3" in r.result.text
    assert r.result.sim_time < 1.0
