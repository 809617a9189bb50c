"""A clock generator is parked like a spin, exactly (issue 62, interp/runtime/period.py): a
submit program toggles a flag every other IPO cycle on a timer compared with a constant, and a
flip-flop follows the flag. Each test runs the program with the spin watch and without it
(``SpinWatch.enabled``), untraced, and compares the I/O log, the end and the steps, on both
interpreters; expected times are IPO cycles of 12 ms worked out by hand (tests/interp/test_spin.py's
conventions: a task's I/O change is logged at the time of its cycle's start)."""

from __future__ import annotations

import pytest

from .helpers import run_beside, same_run

INTERPS = ("tree", "vm")

#: the clock: $TIMER[30] runs from 0; a pass that reads it above 12 ms (the second cycle after
#: its reset) resets it and toggles CLK, so CLK changes every other cycle; NOR1 and NOR2 follow
CLOCK_SPS = """
DEF sps()
  $TIMER[30] = 0
  $TIMER_STOP[30] = FALSE
  LOOP
    PULSES()
    FLIP()
    IF $IN[5] THEN
      $OUT[5] = TRUE
    ENDIF
  ENDLOOP
END

DEF PULSES()
  IF $TIMER[30] > 12 THEN
    $TIMER[30] = 0
    CLK = NOT CLK
  ENDIF
END

DEF FLIP()
  NOR1 = NOT (CLK AND NOR2)
  NOR2 = NOT (NOR1 AND NOT CLK)
END
"""

DAT = """
DEFDAT prog PUBLIC
  DECL GLOBAL BOOL CLK = FALSE
  DECL GLOBAL BOOL NOR1 = FALSE
  DECL GLOBAL BOOL NOR2 = FALSE
  DECL GLOBAL INT COUNT = 0
ENDDAT
"""

#: counts ten periods of the clock, then sets an output
EDGES = """
DEF prog()
  INT i
  FOR i = 1 TO 10
    WAIT FOR CLK
    WAIT FOR NOT CLK
  ENDFOR
  $OUT[7] = TRUE
  WAIT SEC 0.5
END
"""

#: moves while the clock runs (each motion's statements wake the parked clock), then waits for it
MOVING = """
DEF prog()
  INT i
  FOR i = 1 TO 4
    PTP {A1 20, A2 -90, A3 90, A4 0, A5 30, A6 0}
    PTP {A1 -20, A2 -90, A3 90, A4 0, A5 30, A6 0}
  ENDFOR
  WAIT FOR CLK
  $OUT[7] = TRUE
END
"""


def _run(tmp_path, prog: str, sub: str, *, max_sim_time: float = 3.0, **kw):
    return run_beside(tmp_path, prog, sub, DAT, max_sim_time=max_sim_time, **kw)


def _same_run(tmp_path, prog: str, sub: str, interp: str, *, max_sim_time: float = 3.0, **kw):
    return same_run(tmp_path, prog, sub, DAT, interp, max_sim_time=max_sim_time, **kw)


@pytest.mark.parametrize("interp", INTERPS)
def test_a_clock_generator_is_parked_and_the_run_is_the_same(tmp_path, interp):
    """CLK rises in cycles 2, 6, 10, ... (the submit program's turn, after the robot program's):
    the robot program sees it rise in cycles 3, 7, ... and fall in 5, 9, ...; the tenth fall
    is seen in cycle 5 + 4 * 9 = 41, when $OUT[7] rises: 41 * 12 ms = 0.492 s."""
    rt, res = _same_run(tmp_path, EDGES, CLOCK_SPS, interp)
    assert res.reason == "completed"
    assert [(round(t, 3), n, v) for t, n, v, _s in rt.controller.io.log] == [(0.492, "$OUT[7]", True)]
    sw = rt.ff.spin
    assert sw.periods >= 1 and sw.parks >= 1 and sw.skipped > 0


@pytest.mark.parametrize("interp", INTERPS)
def test_a_robot_that_moves_beside_the_clock_leaves_it_parked(tmp_path, interp):
    """The motion statements write nothing the clock reads or writes: the clock stays parked
    through them (PeriodicSpins._harmless), recorded once, woken once: by the output the robot
    program writes at its end (the clock reads the I/O image)."""
    rt, res = _same_run(tmp_path, MOVING, CLOCK_SPS, interp, max_sim_time=20.0)
    assert res.reason == "completed"
    sw = rt.ff.spin
    assert (sw.periods, sw.parks, sw.wakes) == (1, 1, 1)
    assert sw.skipped > 0.8 * rt.scheduler.tasks[1].steps


#: writes, every 0.1 s, a variable the clock reads (with the value it has)
WRITER = """
DEF prog()
  INT i
  FOR i = 1 TO 20
    COUNT = 0
    WAIT SEC 0.1
  ENDFOR
  WAIT FOR CLK
  $OUT[7] = TRUE
END
"""


@pytest.mark.parametrize("interp", INTERPS)
def test_a_write_of_what_the_clock_reads_wakes_it_and_a_probe_parks_it_again(tmp_path, interp):
    """COUNT = 0, which the clock reads: the clock wakes before each of the 20 writes; its next
    boundary's key is one of its period's and COUNT is still 0, so it is parked again at once,
    never recorded again."""
    sub = CLOCK_SPS.replace("    FLIP()\n", "    FLIP()\n    IF COUNT > 5 THEN\n      $OUT[6] = TRUE\n    ENDIF\n")
    rt, res = _same_run(tmp_path, WRITER, sub, interp, max_sim_time=5.0)
    assert res.reason == "completed"
    sw = rt.ff.spin
    assert sw.periods == 1 and sw.wakes >= 15 and sw.probe_parks >= sw.wakes - 1


def test_parking_predicts_the_clock_at_every_cycle(tmp_path):
    """Shadowed (the task runs on; at every cycle's end its statement, frames, written values and
    timers are compared with the period's): no difference in the 208 cycles of the run but those
    it takes to record the period."""
    rt, _res = _run(tmp_path, EDGES.replace("WAIT SEC 0.5", "WAIT SEC 2.0"), CLOCK_SPS, interp="vm", shadow=True)
    sw = rt.ff.spin
    assert sw.shadow_checks > 100
    assert sw.shadow_errors == 0, sw.why


@pytest.mark.parametrize("interp", INTERPS)
def test_a_counter_is_no_period(tmp_path, interp):
    """A pass that counts never comes back to a state it had: no period, and the run the same."""
    sub = CLOCK_SPS.replace("    FLIP()\n", "    FLIP()\n    COUNT = COUNT + 1\n")
    rt, _res = _same_run(tmp_path, "DEF prog()\n  WAIT SEC 1.5\nEND\n", sub, interp)
    sw = rt.ff.spin
    assert sw.periods == 0
    assert sw.why.get("period: no state repeats", 0) >= 1


#: a pass that settles in two passes after its input changes: A follows $IN[5], B follows A
SETTLING_SPS = """
DEF sps()
  LOOP
    B = A
    A = $IN[5]
    IF B THEN
      $OUT[5] = TRUE
    ELSE
      $OUT[5] = FALSE
    ENDIF
  ENDLOOP
END
"""

SETTLING_DAT = """
DEFDAT prog PUBLIC
  DECL GLOBAL BOOL A = TRUE
  DECL GLOBAL BOOL B = FALSE
ENDDAT
"""

#: $IN[5] on at 1 s, off at 2 s, ... (each change wakes the parked task)
TOGGLES = "".join(f"- at: {t}.0\n  set: {{\"$IN[5]\": {'true' if t % 2 else 'false'}}}\n" for t in range(1, 5))


@pytest.mark.parametrize("interp", INTERPS)
def test_a_task_that_settles_after_its_input_changed_is_parked_as_a_pass(tmp_path, interp):
    """Its first passes write A and B anew, and it settles in two passes: a plain pass is looked
    for twice before a period is (spin.PASSES_BEFORE_PERIOD), which parks it as a pass, and each
    input change wakes it into the same: no periodic recording of dozens of passes at all (the
    palletizer's SPS.SUB at each answer of the automatic cell; until 2026-11-27 the first
    recording looked for a period and parked one). $OUT[5] follows $IN[5] two passes late, in
    the cycle of the change: at 1.008, 2.004, 3.000 and 4.008 s."""
    rt, res = same_run(tmp_path, "DEF prog()\n  WAIT SEC 5.0\nEND\n", SETTLING_SPS, SETTLING_DAT, interp,
                       max_sim_time=6.0, stimuli=TOGGLES)
    assert res.reason == "completed"
    assert [(round(t, 3), n, v) for t, n, v, _s in rt.controller.io.log if n == "$OUT[5]"] == \
        [(0.0, "$OUT[5]", True), (0.0, "$OUT[5]", False), (1.008, "$OUT[5]", True), (2.004, "$OUT[5]", False),
         (3.0, "$OUT[5]", True), (4.008, "$OUT[5]", False)]
    sw = rt.ff.spin
    assert sw.periods == 0 and sw.wakes >= 4 and sw.parks >= 5
    assert sw.skipped > 0.9 * res.steps
