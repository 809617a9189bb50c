"""A submit program beside a moving robot while a cell waits for the TCP to reach a point (issue 86,
item 2; interp/runtime/spin.py, robot/controller.py ``Controller.may_reach``): a stimulus ``when:
{motion: n, reached: true}`` sets an input only once motion n executes, so while it waits for a
motion not yet planned the controller's step changes no input, and a submit program whose pass
reads inputs stays parked beside the moving robot. Until 2026-11-28 any such stimulus not yet
fired counted as an input about to change at every step: the pass was woken and recorded again in
every IPO cycle the robot moved, and the spin watch cost more than it saved.

Each run is made with the spin watch and without it; the I/O log (time, signal, value, source),
the end, the steps, the robot's motions and where it ends must be the same. Times are IPO cycles
of 12 ms; the submit program reads an input in the cycle the stimulus sets it (the tasks run
after the controller's step that applied it), so its output follows at the same time."""

from __future__ import annotations

import pytest

from .helpers import run_beside

INTERPS = ("tree", "vm")

#: a robot program of pick-and-place shape: 1 + 4 * 3 = 13 motions, TRIGGERs that switch an
#: output on and off on the way, a global counter the submit program reads
PROG = """
DEF prog()
  INT i
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
  FOR i = 1 TO 3
    TRIGGER WHEN DISTANCE = 0 DELAY = 0 DO $OUT[10] = TRUE
    LIN_REL {X 150, Z 100} C_DIS
    TRIGGER WHEN DISTANCE = 1 DELAY = 0 DO $OUT[10] = FALSE
    PTP {A1 30, A2 -80, A3 80, A4 0, A5 30, A6 0}
    LIN_REL {Y 200, Z -100}
    PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
    PICKS = PICKS + 1
  ENDFOR
  WAIT FOR $OUT[5]
END
"""

DAT = """
DEFDAT prog PUBLIC
  DECL GLOBAL INT PICKS = 0
ENDDAT
"""

#: KUKA's template in miniature: the AUTOEXT interrupt, the power-fail wait, a handshake of an
#: input and a TRIGGER's output, an output that follows the robot program's counter
SPS = """
DEF sps()
  INTERRUPT DECL 91 WHEN $PRO_STATE1==#P_FREE DO RESET_OUT()
  INTERRUPT ON 91
  LOOP
    WAIT FOR NOT($POWER_FAIL)
    IF $IN[7] AND NOT $OUT[10] THEN
      $OUT[5] = TRUE
    ENDIF
    $OUT[6] = PICKS > 1
  ENDLOOP
END

DEF RESET_OUT()
  $OUT[6] = FALSE
END
"""

#: the cell answers when the TCP reaches the last motion's end point (motion 13)
STIMULI = "- when: {motion: 13, reached: true}\n  set: {\"$IN[7]\": true}\n"


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_that_reads_inputs_stays_parked_while_a_stimulus_waits_for_a_later_motion(tmp_path, interp):
    off, r_off = run_beside(tmp_path, PROG, SPS, DAT, interp=interp, enabled=False, stimuli=STIMULI)
    rt, res = run_beside(tmp_path, PROG, SPS, DAT, interp=interp, stimuli=STIMULI)
    assert rt.controller.io.log == off.controller.io.log
    assert (res.reason, res.line, res.sim_time, res.steps) == (r_off.reason, r_off.line, r_off.sim_time, r_off.steps)
    assert (rt.scheduler.spin.diverged, rt.scheduler.spin.missed) == (0, 0)
    assert res.reason == "completed"
    assert rt.controller.queue.next_id - 1 == off.controller.queue.next_id - 1 == 13     # every motion planned
    assert list(rt.controller.actual.axis_act()) == list(off.controller.actual.axis_act())
    log = [(round(t, 3), name, v) for t, name, v, _src in rt.controller.io.log]
    t_in = next(t for t, name, v in log if name == "$IN[7]")
    assert (t_in, "$OUT[5]", True) in log           # the submit program answers in the same cycle
    assert [v for _t, name, v in log if name == "$OUT[10]"] == [True, False] * 3
    assert [v for _t, name, v in log if name == "$OUT[6]"] == [True]    # after the second pick
    # the submit program's steps: counted by parking, not run, for most of the motions
    # (before: every IPO cycle the robot moved ran it, 0 of them counted)
    sw = rt.scheduler.spin
    assert sw.moving > 0.6 * sw.skipped > 0.6 * 0.6 * res.steps, (sw.moving, sw.skipped, res.steps)
