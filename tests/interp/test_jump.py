"""The clock jump (issue 76, item 4; interp/runtime/jump.py): IPO cycles in which no task runs —
every task parked by the spin watch, the robot standing — are counted in one step up to the next
thing that can change what a task reads, and the run is the run without any fast-forward
(``RunSpec.fast_forward`` False: no jump, no parked pass, no idle skip): every I/O change at its
time, the end, the steps, the automatic cell's answers; on both interpreters.

Expected times are worked out by hand: an IPO cycle is 12 ms; a stimulus ``at: t`` is applied in
the first cycle k with k * 12 ms >= t, and the task reads it in that cycle (its I/O change logged
at k * 12 ms); a .sub run as the program gets SUBMIT_BUDGET (100) steps in each cycle 0..K, where
K * 12 ms reaches the time limit."""

from __future__ import annotations

import pytest

from interp.run import make_runtime, run_spec
from interp.runtime import jump
from interp.runtime.scheduler import SUBMIT_BUDGET

from .helpers import write

INTERPS = ("tree", "vm")

#: a submit program in miniature: mirrors an input on an output, latches another
SPS = """
DEF sps()
  LOOP
    $OUT[1] = $IN[1]
    IF $IN[2] THEN
      $OUT[2] = TRUE
    ENDIF
  ENDLOOP
END
"""

STIMULI = """
- at: 0.31
  set: {"$IN[1]": true}
- at: 0.91
  set: {"$IN[2]": true}
- at: 1.51
  set: {"$IN[1]": false}
"""


def _run(tmp_path, interp: str, fast: bool, src: str = SPS, stimuli: str | None = STIMULI, seconds: float = 2.0,
         jumps: bool = True, **kw):
    """Run `src` as the program; `fast` the fast-forward (RunSpec), `jumps` the clock jumps alone
    (RunSpec.clock_jumps: the spin watch and the idle watch as ever)."""
    s = write(tmp_path, "sps.sub", src)
    inputs = write(tmp_path, "stimuli.yaml", stimuli) if stimuli else kw.pop("inputs", None)
    rt, _ = make_runtime(run_spec(s, inputs=inputs, max_sim_time=seconds, max_steps=10**8, mujoco=False,
                                  check=False, interp=interp, fast_forward=fast, clock_jumps=jumps, **kw))
    return rt, rt.run()


def _same_without_jumps(tmp_path, interp: str, rt, res, **kw) -> None:
    """The run `rt`, `res` is the run without clock jumps: the same I/O, end and steps, the same
    answers of the automatic cell; and its I/O is that of the run without any fast-forward."""
    off, r_off = _run(tmp_path, interp, True, jumps=False, **kw)
    assert off.scheduler.jumped == 0
    assert off.controller.io.log == rt.controller.io.log
    assert (r_off.reason, r_off.sim_time, r_off.steps, r_off.file, r_off.line) == \
        (res.reason, res.sim_time, res.steps, res.file, res.line)
    if rt.autocell is not None:
        assert [(a.t, a.items) for a in off.autocell.answers] == [(a.t, a.items) for a in rt.autocell.answers]
    slow, r_slow = _run(tmp_path, interp, False, **kw)
    assert slow.controller.io.log == rt.controller.io.log
    assert (r_slow.reason, r_slow.sim_time) == (res.reason, res.sim_time)


def _log(rt) -> list:
    return [(round(t, 3), name, v, src) for t, name, v, src in rt.controller.io.log]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_hand_built_submit_program_jumps_and_changes_its_outputs_when_its_inputs_change(tmp_path, interp):
    """The stimuli of 0.31, 0.91 and 1.51 s are applied in cycles 26, 76 and 126 (0.312, 0.912,
    1.512 s), and the pass of that cycle writes the outputs; the run ends in cycle 167, the first
at or past 2.0 s (2.004 s). Between the
    changes the task is parked and the cycles jumped (up to the idle watch's next look); no jump
    covers a cycle in which an input changes."""
    spans = []
    real = jump.count

    def count(sched, n):
        spans.append((sched.controller.cycle, sched.controller.cycle + n - 1))
        real(sched, n)

    jump.count = count
    try:
        rt, res = _run(tmp_path, interp, True)
    finally:
        jump.count = real
    assert _log(rt) == [(0.312, "$IN[1]", True, "stimulus"), (0.312, "$OUT[1]", True, "program"),
                        (0.912, "$IN[2]", True, "stimulus"), (0.912, "$OUT[2]", True, "program"),
                        (1.512, "$IN[1]", False, "stimulus"), (1.512, "$OUT[1]", False, "program")]
    assert (res.reason, res.sim_time) == ("max_sim_time", 2.004)
    assert rt.scheduler.jumped == sum(b - a + 1 for a, b in spans) > 50
    assert not [(a, b) for a, b in spans for k in (26, 76, 126) if a <= k <= b]
    _same_without_jumps(tmp_path, interp, rt, res)


#: a submit program that waits, by polling, for an input nothing but the automatic cell sets
POLLING = """
DEF sps()
  LOOP
    IF $IN[7] THEN
      $OUT[7] = TRUE
    ENDIF
  ENDLOOP
END
"""


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_whose_input_the_automatic_cell_sets_is_not_skipped(tmp_path, interp):
    """``--inputs auto``: the cell answers the IF by setting $IN[7]; the pass of the cycle the
    answer takes effect in reads it and sets $OUT[7] in that same cycle (not a jump later), and
    the answer comes at the time it comes without any fast-forward."""
    kw = dict(src=POLLING, stimuli=None, seconds=2.0, inputs="auto")
    rt, res = _run(tmp_path, interp, True, **kw)
    log = _log(rt)
    first = next(e for e in log if e[1] == "$IN[7]")
    assert first[2:] == (True, "auto")
    assert [e for e in log if e[1] == "$OUT[7]"] == [(first[0], "$OUT[7]", True, "program")]
    assert rt.scheduler.jumped > 0
    _same_without_jumps(tmp_path, interp, rt, res, **kw)


#: a submit program that switches on a cyclic flag over an input and mirrors the flag
CYCLIC = """
DEF sps()
  $CYCFLAG[1] = $IN[3]
  LOOP
    $OUT[3] = $CYCFLAG[1]
  ENDLOOP
END
"""


@pytest.mark.parametrize("interp", INTERPS)
def test_a_cyclic_flag_whose_expression_settles_is_jumped_over(tmp_path, interp):
    """$CYCFLAG[1] = $IN[3] is evaluated again only when the I/O image changed (a flag that
    settles): the cycles between are jumped. The stimulus of 0.51 s is applied in the step of
    cycle 43 (0.516 s), whose cyclic evaluation sets the flag; the pass of cycle 43 reads it."""
    kw = dict(src=CYCLIC, stimuli="- at: 0.51\n  set: {\"$IN[3]\": true}\n")
    rt, res = _run(tmp_path, interp, True, **kw)
    assert [e for e in _log(rt) if e[1] in ("$IN[3]", "$OUT[3]")] == \
        [(0.516, "$IN[3]", True, "stimulus"), (0.516, "$OUT[3]", True, "program")]
    assert rt.scheduler.jumped > 50
    _same_without_jumps(tmp_path, interp, rt, res, **kw)
