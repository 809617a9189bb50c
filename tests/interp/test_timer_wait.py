"""A WAIT FOR that compares a running timer with a number stands until the timer reaches it
(issue 48, "a timer reaching a compared value"; interp/runtime/watch.py ``timer_watch``): the
scheduler does not resume the waiting task every IPO cycle, yet the wait ends in the cycle it
would have, and the idle watch sees the same clock reads, identically in both interpreters.

Expected times are worked out by hand: the timer is started in cycle 0, each controller step adds
12 ms (robot/io.py ``tick_timers``), so the tasks of cycle k read 12·k ms, and an output the
program writes in cycle k is logged at k · 12 ms."""

from __future__ import annotations

import pytest

from interp.run import make_runtime, run_spec
from interp.runtime import core
from interp.runtime.scheduler import Scheduler

from .helpers import write

INTERPS = ("tree", "vm")

WAIT = """
DEF prog()
  $TIMER[1] = 0
  $TIMER_STOP[1] = FALSE
  WAIT FOR $IN[1] OR ({cond})
  $OUT[1] = TRUE
END
"""


def _run(tmp_path, cond: str, interp: str, stimuli: str | None = None, timers: bool = True):
    p = write(tmp_path, "prog.src", WAIT.format(cond=cond))
    inputs = write(tmp_path, "stimuli.yaml", stimuli) if stimuli else None
    rt, _ = make_runtime(run_spec(p, inputs=inputs, max_sim_time=30.0, max_steps=10**7, mujoco=False,
                         check=False, interp=interp))
    resumes = [0]
    resume = Scheduler._resume

    def counted(sched, task):
        resumes[0] += 1
        return resume(sched, task)

    with pytest.MonkeyPatch.context() as mp:      # the code counted, not the run's state set
        mp.setattr(Scheduler, "_resume", counted)
        if not timers:
            # the run as before timer_watch: no key for a condition that reads a running timer,
            # so the task is resumed and evaluates it every cycle
            mp.setattr(core, "timer_watch", lambda expr: None)
        res = rt.run()
    return rt, res, resumes[0]


@pytest.mark.parametrize("interp", INTERPS)
@pytest.mark.parametrize("cond, cycle", [("$TIMER[1] >= 500", 42),      # 504 >= 500
                                         ("$TIMER[1] > 504", 43),       # 504 is not > 504
                                         ("2000 <= $TIMER[1]", 167),    # 2004
                                         ("NOT ($TIMER[1] < 120)", 10)])
def test_the_wait_ends_in_the_cycle_the_timer_reaches_its_bound(tmp_path, interp, cond, cycle):
    rt, res, resumes = _run(tmp_path, cond, interp)
    assert res.reason == "completed"
    assert [(round(t, 6), n) for t, n, v, _s in rt.controller.io.log if n == "$OUT[1]"] == \
        [(round(cycle * 0.012, 6), "$OUT[1]")]
    assert resumes < 10                 # not once per cycle of the wait
    _rt0, res0, resumes0 = _run(tmp_path, cond, interp, timers=False)
    assert resumes0 > cycle
    assert _rt0.controller.io.log == rt.controller.io.log
    assert (res0.sim_time, res0.steps) == (res.sim_time, res.steps)
    # the condition's reads of the running timer are clock reads either way (idle watch)
    assert rt.ff.idle.clock == _rt0.ff.idle.clock > cycle


@pytest.mark.parametrize("interp", INTERPS)
def test_an_input_before_the_bound_ends_the_wait_at_its_cycle(tmp_path, interp):
    """$IN[1] set at 0.3 s (cycle 25: 25 · 12 ms >= 300 ms) ends the wait before the timer's
    2 s: the rest of the condition's key moved."""
    rt, res, _n = _run(tmp_path, "$TIMER[1] >= 2000", interp, stimuli="- {at: 0.3, set: {'$IN[1]': true}}\n")
    assert res.reason == "completed"
    assert [round(t, 6) for t, n, v, _s in rt.controller.io.log if n == "$OUT[1]"] == [0.3]


@pytest.mark.parametrize("cond", ["$TIMER[1] + 4 >= 508", "$TIMER[1 + 0] >= 504"])
def test_other_reads_of_the_timer_are_evaluated_every_cycle(tmp_path, cond):
    """A timer in arithmetic or with a computed index: no deadline (the task is resumed every
    cycle, as before), the same end."""
    rt, res, resumes = _run(tmp_path, cond, "vm")
    assert [round(t, 6) for t, n, v, _s in rt.controller.io.log if n == "$OUT[1]"] == [0.504]
    assert resumes > 42
