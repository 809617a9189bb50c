"""A submit program beside a moving robot while the cell waits for the TCP to reach a point (issue 86,
item 2; interp/runtime/spin.py ``SpinWatch.reaching``, robot/signals.py ``Signals.on_reach``): a
stimulus ``when: {motion: n, reached: true}`` sets an input in the controller's step in which the
TCP comes within its distance of motion n's end point, which no step before can tell. A parked pass
that reads inputs is caught up inside that step, just before the input is set, over the inputs its
parked passes saw, so it stays parked beside the moving robot. Until 2026-11-28 any such stimulus
not yet fired counted as an input about to change at every step: the pass was woken and recorded
again in every IPO cycle the robot moved (the spin watch cost more than it saved), and the
scheduler's steady cycles were off.

Each run is made with the spin watch and without it; the I/O log (time, signal, value, source),
the end, the steps, the robot's motions and where it ends must be the same. Times are IPO cycles
of 12 ms; the submit program reads an input in the cycle after the step that set it (the tasks
run before the controller's step in a cycle), and its output is logged at that cycle's time,
which is the input's (robot/io.py logs a change at the time of the cycle being made)."""

from __future__ import annotations

import pytest

from .helpers import run_beside

INTERPS = ("tree", "vm")

#: a robot program of pick-and-place shape: 1 + 4 * 2 = 9 motions, TRIGGERs that switch an
#: output on and off on the way, a global counter the submit program reads
PROG = """
DEF prog()
  INT i
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
  FOR i = 1 TO 2
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
    $OUT[8] = $IN[8]
    $OUT[6] = PICKS > 0
  ENDLOOP
END

DEF RESET_OUT()
  $OUT[6] = FALSE
END
"""

#: the cell answers when the TCP reaches the last motion's end point (motion 9)
STIMULI = "- when: {motion: 9, reached: true}\n  set: {\"$IN[7]\": true}\n"


def _same(tmp_path, interp: str, stimuli: str):
    """The run with the spin watch and without it: the same I/O, end, steps, motions and final
    axes, no catch-up that left its pass, no change missed; the parked run."""
    off, r_off = run_beside(tmp_path, PROG, SPS, DAT, interp=interp, enabled=False, stimuli=stimuli)
    rt, res = run_beside(tmp_path, PROG, SPS, DAT, interp=interp, stimuli=stimuli)
    assert rt.controller.io.log == off.controller.io.log
    assert (res.reason, res.line, res.sim_time, res.steps) == (r_off.reason, r_off.line, r_off.sim_time, r_off.steps)
    assert (rt.ff.spin.diverged, rt.ff.spin.missed) == (0, 0)
    assert res.reason == "completed"
    assert rt.controller.queue.next_id - 1 == off.controller.queue.next_id - 1 == 9     # every motion planned
    assert list(rt.controller.actual.axis_act()) == list(off.controller.actual.axis_act())
    return rt, res, [(round(t, 3), name, v) for t, name, v, _src in rt.controller.io.log]


#: inputs set on reaching the end points of motions 2 and 6 (the first LIN of each pick), each while the submit program is parked
REACHED = "".join(f"- when: {{motion: {m}, reached: true}}\n  set: {{\"$IN[8]\": {v}}}\n"
                  for m, v in ((2, "true"), (6, "false")))


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_that_reads_inputs_stays_parked_beside_a_moving_robot_and_reached_stimuli(tmp_path, interp):
    """$IN[7] waits for the last motion all along; $IN[8] is set on reaching motions 2 and 6, and
    the pass mirrors it on $OUT[8]: each change at the input's time, as unparked (the catch-up
    inside the step read the input before it changed), the pass parked again after each."""
    rt, res, log = _same(tmp_path, interp, REACHED + STIMULI)
    t_in = next(t for t, name, v in log if name == "$IN[7]")
    assert (t_in, "$OUT[5]", True) in log           # the submit program answers in that cycle
    assert [v for _t, name, v in log if name == "$OUT[10]"] == [True, False] * 2
    assert [v for _t, name, v in log if name == "$OUT[6]"] == [True]    # after the first pick
    ins = [(t, v) for t, name, v in log if name == "$IN[8]"]
    assert [v for _t, v in ins] == [True, False]
    assert [(t, v) for t, name, v in log if name == "$OUT[8]"] == ins
    # the submit program's steps: counted by parking, not run, for most of the motions
    # (before: every IPO cycle the robot moved ran it, 0 of them counted)
    sw = rt.ff.spin
    assert sw.parks >= 3 and sw.moving > 0.6 * sw.skipped > 0.6 * 0.6 * res.steps, (sw.parks, sw.moving, sw.skipped, res.steps)


def test_parking_beside_a_reached_stimulus_predicts_every_cycle(tmp_path):
    """Shadowed (the pass runs, and parking's prediction is checked at every cycle's end), on the VM."""
    rt, _res = run_beside(tmp_path, PROG, SPS, DAT, interp="vm", shadow=True, stimuli=REACHED + STIMULI)
    sw = rt.ff.spin
    assert sw.shadow_checks > 100 and sw.shadow_errors == 0, (sw.shadow_checks, sw.why)


#: a clock generator (tests/interp/test_period.py's, in miniature) that mirrors $IN[8]: parked as a period
CLOCK = """
DEF sps()
  $TIMER[30] = 0
  $TIMER_STOP[30] = FALSE
  LOOP
    IF $TIMER[30] > 12 THEN
      $TIMER[30] = 0
      CLK = NOT CLK
    ENDIF
    NOR1 = NOT (CLK AND NOR2)
    NOR2 = NOT (NOR1 AND NOT CLK)
    $OUT[8] = $IN[8]
  ENDLOOP
END
"""

CLOCK_DAT = DAT.replace("ENDDAT", "  DECL GLOBAL BOOL CLK = FALSE\n  DECL GLOBAL BOOL NOR1 = FALSE\n"
                        "  DECL GLOBAL BOOL NOR2 = FALSE\nENDDAT")


@pytest.mark.parametrize("interp", INTERPS)
def test_a_parked_period_catches_up_before_an_input_set_on_reaching_a_point(tmp_path, interp):
    """The period's catch-up inside the step (its timers as the step left them) gives the run
    without the watch: the same I/O log, end and steps; shadowed (on the VM), every cycle as predicted."""
    modes = (("off", {"enabled": False}), ("on", {})) + ((("shadow", {"shadow": True}),) if interp == "vm" else ())
    runs = {mode: run_beside(tmp_path, PROG, CLOCK, CLOCK_DAT, interp=interp, stimuli=REACHED, max_sim_time=4.0, **kw)
            for mode, kw in modes}
    (off, r_off), (on, r_on) = runs["off"], runs["on"]
    assert on.controller.io.log == off.controller.io.log
    assert (r_on.reason, r_on.sim_time, r_on.steps) == (r_off.reason, r_off.sim_time, r_off.steps)
    log = [(round(t, 3), name, v) for t, name, v, _src in on.controller.io.log]
    assert [(t, v) for t, name, v in log if name == "$OUT[8]"] == [(t, v) for t, name, v in log if name == "$IN[8]"] != []
    sw = on.ff.spin
    assert sw.periods > 0 and (sw.diverged, sw.missed) == (0, 0)
    if "shadow" in runs:
        sh = runs["shadow"][0]
        assert sh.controller.io.log == off.controller.io.log
        assert sh.ff.spin.shadow_checks > 30 and sh.ff.spin.shadow_errors == 0
