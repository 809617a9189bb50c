"""A pass that compares a running timer with a constant is parked until the timer crosses it
(issue 76, item 4: "the run jumps to the next change of anything it reads (... a timer reaching a
compared value ...)"; interp/runtime/passes.py ``timer_compares``, interp/runtime/spin.py
``SpinWatch._clock_ok``). Each run is compared with the run without any fast-forward
(``RunSpec.fast_forward`` False): the same I/O at the same times, the same end and steps, the same
clock reads counted by the idle watch; on both interpreters.

Expected times by hand (tests/interp/test_jump.py's conventions): an IPO cycle is 12 ms; the
program, run as a .sub, sets ``$TIMER[1]`` to 0 and starts it in cycle 0, each controller step
adds 12 ms, so the pass of cycle k reads 12·k ms, and an output it then sets is logged at k·12 ms."""

from __future__ import annotations

import pytest

from interp.run import make_runtime, run_spec

from .helpers import write

INTERPS = ("tree", "vm")

#: 12·k >= 1000 first at k = 84 (1.008 s); 12·k > 1500 first at k = 126 (1.512 s)
SPS = """
DEF sps()
  $TIMER[1] = 0
  $TIMER_STOP[1] = FALSE
  LOOP
    IF $TIMER[1] >= 1000 THEN
      $OUT[2] = TRUE
    ENDIF
    IF 1500 < $TIMER[1] THEN
      $OUT[3] = NOT $IN[3]
    ENDIF
  ENDLOOP
END
"""

#: the same limit in a variable: not a comparison with a constant, so never parked
VARIABLE = SPS.replace("DEF sps()", "DEF sps()\n  DECL INT LIMIT\n  LIMIT = 1000").replace(
    "$TIMER[1] >= 1000", "$TIMER[1] >= LIMIT")


def _run(tmp_path, interp: str, fast: bool, src: str):
    s = write(tmp_path, "sps.sub", src)
    rt, _ = make_runtime(run_spec(s, max_sim_time=2.0, max_steps=10**8, mujoco=False, check=False,
                                  interp=interp, fast_forward=fast))
    return rt, rt.run()


def _same(tmp_path, interp: str, src: str):
    rt, res = _run(tmp_path, interp, True, src)
    slow, r_slow = _run(tmp_path, interp, False, src)
    assert rt.controller.io.log == slow.controller.io.log
    assert (res.reason, res.sim_time, res.steps) == (r_slow.reason, r_slow.sim_time, r_slow.steps)
    assert rt.ff.idle.clock == slow.ff.idle.clock > 0
    assert rt.ff.spin.diverged == rt.ff.spin.missed == 0
    return rt


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_comparing_a_running_timer_is_parked_until_the_crossing(tmp_path, interp):
    """Parked before 1.008 s, between the crossings and after 1.512 s, woken at each crossing:
    the outputs change at the cycles worked out by hand. On the code before this change the pass
    was never parked (its reads of the running timer were clock reads: 0 parks)."""
    rt = _same(tmp_path, interp, SPS)
    log = [(round(t, 3), name, v) for t, name, v, _src in rt.controller.io.log]
    assert log == [(1.008, "$OUT[2]", True), (1.512, "$OUT[3]", True)]
    assert rt.ff.spin.parks >= 3 and rt.ff.spin.wakes >= 2
    assert rt.ff.spin.skipped > 0.9 * rt.clock.steps


@pytest.mark.parametrize("interp", INTERPS)
def test_a_timer_compared_with_a_variable_is_not_parked(tmp_path, interp):
    rt = _same(tmp_path, interp, VARIABLE)
    assert [(round(t, 3), name) for t, name, _v, _s in rt.controller.io.log] == [(1.008, "$OUT[2]"), (1.512, "$OUT[3]")]
    assert rt.ff.spin.parks == 0


#: a blinker on a timer (a period of 42 cycles: 12·42 = 504 > 500 ms) beside a robot program that
#: waits for inputs the automatic cell gives (--inputs auto)
BLINK = """
DEF sps()
  $TIMER[2] = 0
  $TIMER_STOP[2] = FALSE
  LOOP
    $OUT[1] = $IN[1]
    IF $TIMER[2] > 500 THEN
      $TIMER[2] = 0
      $OUT[9] = NOT $OUT[9]
    ENDIF
  ENDLOOP
END
"""

CELL = """
DEF cell()
  INT i
  FOR i = 1 TO 3
    WAIT FOR $IN[3]
    $OUT[4] = TRUE
    WAIT FOR NOT $IN[3]
    $OUT[4] = FALSE
  ENDFOR
END
"""


@pytest.mark.parametrize("interp", INTERPS)
def test_a_blinker_on_a_timer_beside_the_automatic_cell_is_the_same_parked(tmp_path, interp):
    """The pass reads 12·k ms k cycles after the timer's reset and toggles $OUT[9] when that is
    over 500 (k = 42), resetting it in the same pass: $OUT[9] changes every 42 cycles, at 0.504,
    1.008, 1.512 s ...; parked between the toggles, the run is the run without the fast-forward:
    the same I/O, answers of the automatic cell, steps, end and idle clock."""
    cell, sub = write(tmp_path, "cell.src", CELL), write(tmp_path, "sps.sub", BLINK)
    runs = []
    for fast in (True, False):
        rt, _ = make_runtime(run_spec(cell, submit=[sub], inputs="auto", max_sim_time=30.0, max_steps=10**8,
                                      mujoco=False, check=False, interp=interp, fast_forward=fast))
        res = rt.run()
        runs.append((rt, (rt.controller.io.log, res.reason, res.steps, rt.ff.idle.clock,
                          [(a.t, a.items) for a in rt.autocell.answers])))
    (rt, fast), (_slow, slow) = runs
    assert fast == slow and fast[1] == "completed"
    toggles = [round(t, 3) for t, name, _v, _s in rt.controller.io.log if name == "$OUT[9]"]
    assert toggles[:3] == [0.504, 1.008, 1.512]
    assert rt.ff.spin.parks >= len(toggles) and rt.ff.spin.diverged == rt.ff.spin.missed == 0
