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
    assert rt.scheduler.idle.clock == slow.scheduler.idle.clock > 0
    assert rt.spin.diverged == rt.spin.missed == 0
    return rt


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_comparing_a_running_timer_is_parked_until_the_crossing(tmp_path, interp):
    """Parked before 1.008 s, between the crossings and after 1.512 s, woken at each crossing:
    the outputs change at the cycles worked out by hand. On the code before this change the pass
    was never parked (its reads of the running timer were clock reads: 0 parks)."""
    rt = _same(tmp_path, interp, SPS)
    log = [(round(t, 3), name, v) for t, name, v, _src in rt.controller.io.log]
    assert log == [(1.008, "$OUT[2]", True), (1.512, "$OUT[3]", True)]
    assert rt.spin.parks >= 3 and rt.spin.wakes >= 2
    assert rt.spin.skipped > 0.9 * rt.clock.steps


@pytest.mark.parametrize("interp", INTERPS)
def test_a_timer_compared_with_a_variable_is_not_parked(tmp_path, interp):
    rt = _same(tmp_path, interp, VARIABLE)
    assert [(round(t, 3), name) for t, name, _v, _s in rt.controller.io.log] == [(1.008, "$OUT[2]"), (1.512, "$OUT[3]")]
    assert rt.spin.parks == 0
