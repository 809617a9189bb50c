"""The clock jump over a WAIT FOR with a timeout (issue 86 item 3; interp/runtime/jump.py): a
robot program that stands in ``WAIT FOR $IN[5] OR ($TIMER[1] >= 2000)`` (the corpus palletizer's
vacuum wait: ``WAIT FOR VACOESTATO OR ... OR ($TIMER[1]>=2000)``) reads a running timer at every
IPO cycle, so the idle watch's quiet window starts again at each. Its condition changes only
when the input does or when the timer reaches 2000 ms (interp/runtime/watch.py ``timer_due``), so
the cycles before are counted in one step, the clock reads of each counted, and the run is the
run without clock jumps (RunSpec ``clock_jumps`` False) and without any fast-forward.

Expected times by hand: an IPO cycle is 12 ms; the program's first statements run in cycle 0 (t =
0), the timer counts 12 ms at each controller step, so the turn of cycle k reads 12 k ms; it
reaches 2000 first at k = 167 (2.004 s). A stimulus ``at: t`` is applied in the first cycle k
with 12 k ms >= t and read in that cycle."""

from __future__ import annotations

import pytest

from interp.run import make_runtime, run_spec

from .helpers import write

INTERPS = ("tree", "vm")

PROG = """
DEF prog()
  $TIMER[1] = 0
  $TIMER_STOP[1] = FALSE
  WAIT FOR $IN[5] OR ($TIMER[1] >= 2000)
  $OUT[1] = TRUE
  $TIMER[1] = 0
  WAIT FOR $IN[6] OR ($TIMER[1] >= 2000)
  $OUT[2] = TRUE
END
"""


def _run(tmp_path, interp: str, stimuli: str | None, inputs: str | None = None, fast: bool = True,
         jumps: bool = True):
    p = write(tmp_path, "prog.src", PROG)
    if stimuli is not None:
        inputs = str(write(tmp_path, "stimuli.yaml", stimuli))
    rt, _ = make_runtime(run_spec(p, inputs=inputs, max_sim_time=6.0, max_steps=10**6, mujoco=False, check=False,
                                  interp=interp, fast_forward=fast, clock_jumps=jumps))
    return rt, rt.run()


def _same_without_jumps(tmp_path, interp: str, rt, res, stimuli, inputs=None) -> None:
    for fast, jumps in ((True, False), (False, False)):
        off, r_off = _run(tmp_path, interp, stimuli, inputs, fast, jumps)
        assert off.scheduler.jumped == 0
        assert off.controller.io.log == rt.controller.io.log
        assert (r_off.reason, r_off.sim_time, r_off.steps, r_off.line) == (res.reason, res.sim_time, res.steps, res.line)
        if rt.autocell is not None:
            assert [(a.t, a.items) for a in off.autocell.answers] == [(a.t, a.items) for a in rt.autocell.answers]


def _log(rt) -> list:
    return [(round(t, 3), name, v, src) for t, name, v, src in rt.controller.io.log]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_wait_for_with_a_timeout_is_jumped_up_to_the_input_or_the_timeout(tmp_path, interp):
    """The first wait ends by its timeout in cycle 167 (2.004 s); the second, started there, by
    $IN[6] set at 3.0 s (cycle 250: 3.0 s). Nearly all of the 250 cycles are jumped."""
    stimuli = "- at: 3.0\n  set: {\"$IN[6]\": true}\n"
    rt, res = _run(tmp_path, interp, stimuli)
    assert res.reason == "completed"
    assert _log(rt) == [(2.004, "$OUT[1]", True, "program"), (3.0, "$IN[6]", True, "stimulus"),
                        (3.0, "$OUT[2]", True, "program")]
    assert rt.scheduler.jumped > 200
    _same_without_jumps(tmp_path, interp, rt, res, stimuli)


@pytest.mark.parametrize("interp", INTERPS)
def test_the_automatic_cell_answers_such_a_wait_as_without_jumps(tmp_path, interp):
    """``--inputs auto`` answers the WAIT FOR once the robot program has starved for the
    idle watch's window (interp/runtime/idle.py ``robot_starves``), jumped or not: the same
    answers at the same times, the same I/O and end."""
    rt, res = _run(tmp_path, interp, None, inputs="auto")
    answers = [e for e in _log(rt) if e[3] == "auto"]
    assert [e[1] for e in answers][:2] == ["$IN[5]", "$IN[6]"] and answers[0][0] < 2.004
    assert rt.scheduler.jumped > 0
    _same_without_jumps(tmp_path, interp, rt, res, None, "auto")
