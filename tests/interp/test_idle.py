"""Idle time costs nothing (issue 34): a run in which nothing changes fast-forwards to its next
event with the clock exact, identically in both interpreters (interp/runtime/idle.py), and a
trace bounds the spins it still writes (robot/trace.py ``repeats``).

Expected times are IPO cycles of 12 ms, worked out by hand from the reference (§5.8: WAIT SEC
t waits ceil(t / 12 ms) cycles) and from the controller's rules (a stimulus ``at: t`` is
applied in the first cycle k with k * 12 ms >= t; a task reads it in that cycle)."""

from __future__ import annotations

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from interp.runtime.idle import freeze, routine_writes
from interp.runtime.values import UNSET, Arr, EnumValue, Struct
from robot.trace import TraceWriter

from .helpers import write

INTERPS = ("tree", "vm")

POLL = """
DEF poll()
  INT n
  n = 0
  LOOP
    IF $IN[3] THEN
      n = n + 1
      $OUT[1] = TRUE
      EXIT
    ENDIF
  ENDLOOP
END
"""


def _run(prog, *, interp="tree", inputs=None, max_sim_time=600.0, max_steps=10_000_000, submit=(),
         fast=True, repeats=None, keep=True):
    tw = TraceWriter(keep=keep, repeats=repeats)
    rt, _ = make_runtime(run_spec(prog, inputs=inputs, max_sim_time=max_sim_time, max_steps=max_steps,
                         mujoco=False, check=False, interp=interp, submit=list(submit), fast_forward=fast),
                         RunSinks(trace=tw))   # traced: the spin watch parks nothing, fast_forward is the idle watch
    res = rt.run()
    tw.close()
    return rt, res, tw


@pytest.mark.parametrize("interp", INTERPS)
def test_a_polling_program_nothing_answers_ends_at_the_time_limit_at_once(tmp_path, interp):
    """LOOP IF $IN[3] ... ENDLOOP with nothing setting $IN[3]: the run ends at the 600 s limit
    as before, but after one quiet window (32 cycles) and the state compared over a second
    one, the clock jumps to the last cycle: at most ~100 cycles execute statements
    (1000 a cycle) instead of 50 000."""
    prog = write(tmp_path, "poll.src", POLL)
    rt, res, tw = _run(prog, interp=interp)
    assert (res.reason, res.sim_time) == ("max_sim_time", pytest.approx(600.0))
    assert res.steps < 100 * 1000
    idle = [e for e in tw.events if e["kind"] == "idle"]
    assert len(idle) == 1
    # the clock jumps from the cycle the state was seen unchanged to the cycle before the limit
    assert idle[0]["until"] == pytest.approx(599.988)
    assert idle[0]["cycles"] == round((599.988 - idle[0]["t"]) / 0.012)
    assert rt.ff.idle.skipped == idle[0]["cycles"]


@pytest.fixture(scope="module")
def stimulus_runs(tmp_path_factory) -> dict:
    """POLL with $IN[3] set at 2.0 s, traced, on each interpreter with the fast-forward and
    without: (interp, fast) -> (result, its trace's events, idle jumps). Read by the two tests
    below (the first ran the fast-forwarded runs again, 2026-11-29)."""
    tmp = tmp_path_factory.mktemp("poll")
    prog = write(tmp, "poll.src", POLL)
    stim = write(tmp, "s.yaml", "- at: 2.0\n  set: {\"$IN[3]\": true}\n")
    out = {}
    for interp in INTERPS:
        for fast in (True, False):
            rt, res, tw = _run(prog, interp=interp, inputs=stim, fast=fast)
            out[interp, fast] = res, tw.events, rt.ff.idle.jumps
    return out


def test_the_two_interpreters_fast_forward_identically(stimulus_runs):
    for interp in INTERPS:
        assert stimulus_runs[interp, True][0].reason == "completed"
    assert stimulus_runs["tree", True][1] == stimulus_runs["vm", True][1]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_stimulus_ends_the_jump_at_its_exact_cycle(stimulus_runs, interp):
    """The stimulus at 2.0 s: cycle ceil(2 / 0.012) = 167 (2.004 s); the program reads
    $IN[3] in that cycle and sets $OUT[1] at once, with and without the fast-forward."""
    got = []
    for fast in (True, False):
        res, events, jumps = stimulus_runs[interp, fast]
        assert res.reason == "completed"
        got.append([(e["t"], e["signal"]) for e in events if e["kind"] == "io"])
        assert jumps == (1 if fast else 0)
    assert got[0] == got[1] == [(2.004, "$IN[3]"), (2.004, "$OUT[1]")]


@pytest.mark.parametrize("interp", INTERPS)
def test_wait_sec_and_a_running_timer_keep_their_time(tmp_path, interp):
    """WAIT SEC 3 beside a submit program that polls: 250 cycles (3.000 s); the timer
    started before runs on through the jump: $TIMER[1] = 250 * 12 ms = 3000 ms at the
    statement after the wait (the submit never reads it, so the run is idle)."""
    prog = write(tmp_path, "timed.src", """
    DEF timed()
      INT t
      $TIMER[1] = 0
      $TIMER_STOP[1] = FALSE
      WAIT SEC 3.0
      t = $TIMER[1]
      $OUT[2] = t == 3000
    END
    """)
    sub = write(tmp_path, "plc.sub", """
    DEF plc()
      LOOP
        IF $IN[9] THEN
          $OUT[9] = TRUE
        ENDIF
      ENDLOOP
    END
    """)
    got = []
    for fast in (True, False):
        rt, res, tw = _run(prog, interp=interp, submit=[sub], fast=fast)
        assert res.reason == "completed", res.text
        got.append([(e["t"], e["signal"], e["value"]) for e in tw.events if e["kind"] == "io"])
        assert (rt.ff.idle.jumps > 0) == fast
    assert got[0] == got[1] == [(3.0, "$OUT[2]", True)]


def test_reading_the_clock_is_not_idle(tmp_path):
    """A loop that waits on $DATE reads time: it is never fast-forwarded past its end."""
    prog = write(tmp_path, "clock.src", """
    DEF clock()
      WHILE $DATE.SEC < 2
      ENDWHILE
      $OUT[4] = TRUE
    END
    """)
    rt, res, tw = _run(prog, max_sim_time=10.0)
    assert res.reason == "completed"
    assert rt.ff.idle.jumps == 0
    assert [(e["t"], e["signal"]) for e in tw.events if e["kind"] == "io"] == [(2.004, "$OUT[4]")]


def test_a_bounded_trace_of_a_spin_stays_small(tmp_path):
    """Without the fast-forward a spin writes 1000 steps' statements a cycle; the bounded trace
    writes each repeated pass 10 times and counts the rest in ``repeat`` events: within a cycle
    the IF's pass (one statement), and the cycle itself (its statements and the pose at rest),
    so after 10 cycles (0.12 s) nothing more is written; the events written plus those counted
    are exactly the unbounded trace's."""
    prog = write(tmp_path, "poll.src", POLL)
    _rt, res, full = _run(prog, max_sim_time=0.6, fast=False)
    _rt, res2, tw = _run(prog, max_sim_time=0.6, fast=False, repeats=10)
    assert res.steps == res2.steps > 45_000
    kinds = {}
    for e in full.events:
        kinds[e["kind"]] = kinds.get(e["kind"], 0) + 1
    written = {}
    for e in tw.events:
        written[e["kind"]] = written.get(e["kind"], 0) + 1
    left = {}
    for e in tw.events:
        if e["kind"] == "repeat":
            for k, n in e["kinds"].items():
                left[k] = left.get(k, 0) + n
    assert written["stmt"] <= 10 * (10 + 2) and written["pose"] <= 10
    assert max(e["t"] for e in tw.events if e["kind"] in ("stmt", "pose")) <= 0.12
    assert sum(e["count"] for e in tw.events if e["kind"] == "repeat") == len(full.events) - len(tw.events) \
        + sum(1 for e in tw.events if e["kind"] == "repeat")
    assert written["stmt"] + left["stmt"] == kinds["stmt"]
    assert written["pose"] + left.get("pose", 0) == kinds["pose"] == 50
    assert [e for e in tw.events if e["kind"] == "end"] == [e for e in full.events if e["kind"] == "end"]


def test_an_unbounded_trace_writes_every_statement(tmp_path):
    """The trace without ``repeats`` (the default of TraceWriter) is unchanged: one stmt
    event per statement, 2 steps per pass of the loop (the LOOP's iteration and the IF)."""
    prog = write(tmp_path, "poll.src", POLL)
    _rt, res, tw = _run(prog, max_sim_time=0.12, fast=False)
    assert 2 * sum(1 for e in tw.events if e["kind"] == "stmt") in (res.steps, res.steps + 1, res.steps - 1)


def _elementwise(v):
    """The state image of a value built one element at a time (scalars as they are, an enum
    value by name, UNSET as a marker, a structure or array as its elements' images): what
    :func:`interp.runtime.idle.freeze` must agree with on equality."""
    if isinstance(v, Struct):
        return ("struc", tuple((k, _elementwise(x)) for k, x in v.f.items()))
    if isinstance(v, Arr):
        return ("array", tuple(_elementwise(x) for x in v.data))
    if isinstance(v, EnumValue):
        return ("enum", v.name)
    if v is UNSET:
        return ("unset",)
    return ("scalar", v)


def test_the_state_image_of_a_value_is_equal_exactly_when_its_elements_are():
    """freeze images a structure or array of leaves by a plain copy (the fast path of the
    idle check): two values' images are equal exactly when their element-wise images are,
    across leaves, enum values, UNSET, nested structures and mixed arrays."""
    def arr(*xs):
        return Arr(None, (len(xs),), list(xs))

    def struc(**f):
        return Struct(None, dict(f))

    values = [
        1, 2, 1.5, True, "A", UNSET, EnumValue("ON"), EnumValue("OFF"),
        arr(1, 2, 3), arr(1, 2, 4), arr(1.0, 2, 3), arr(UNSET, UNSET), arr(EnumValue("ON"), 1),
        arr(EnumValue("OFF"), 1), arr(struc(X=1.0), struc(X=2.0)), arr(struc(X=1.0), struc(X=3.0)),
        arr(UNSET, struc(X=1.0)), arr(struc(X=UNSET), UNSET),
        struc(X=1.0, Y=2.0), struc(X=1.0, Y=2.5), struc(X=UNSET, Y=2.0), struc(S=EnumValue("ON")),
        struc(S=EnumValue("OFF")), struc(P=struc(X=1.0)), struc(P=struc(X=2.0)), struc(P=arr(1, 2)),
        struc(P=arr(1, 3)), struc(X=1.0), struc(Y=1.0),
    ]
    # equal copies built afresh (no shared objects) must image equal too
    twins = [
        arr(1, 2, 3), arr(UNSET, UNSET), arr(EnumValue("ON"), 1), arr(struc(X=1.0), struc(X=2.0)),
        struc(X=1.0, Y=2.0), struc(S=EnumValue("ON")), struc(P=struc(X=1.0)), struc(P=arr(1, 2)),
    ]
    allv = values + twins
    for a in allv:
        for b in allv:
            assert (freeze(a) == freeze(b)) == (_elementwise(a) == _elementwise(b)), (_elementwise(a), _elementwise(b))


CONST_PROG = """
DEF cprog()
  INT i
  FOR i = 1 TO 3
    COUNT = COUNT + 1
  ENDFOR
  BUMP(OUTV)
  LOOP
    IF $IN[3] THEN
      EXIT
    ENDIF
  ENDLOOP
END

DEF BUMP(v:OUT)
  INT v
  v = v + 1
END
"""


def test_only_data_lists_a_statement_writes_are_imaged_again(tmp_path):
    """``routine_writes``: a data list an assignment, a FOR or an :OUT argument writes is
    imaged at every state image; one nothing writes (positions, tables) once, and again after
    an outside change (``Runtime.changed_outside``: an operator's edit, a network partner)."""

    prog = write(tmp_path, "cprog.src", CONST_PROG)
    write(tmp_path, "cprog.dat", "DEFDAT cprog PUBLIC\n  DECL GLOBAL INT COUNT = 0\n  DECL GLOBAL INT OUTV = 0\nENDDAT\n")
    write(tmp_path, "table.dat", "DEFDAT table PUBLIC\n  DECL GLOBAL INT TAB[3]\n  TAB[1] = 7\nENDDAT\n")
    rt, res, _tw = _run(prog, max_sim_time=5.0)
    assert res.reason == "max_sim_time"
    by_name = {m.name.lower(): m.index for m in rt.program.modules}
    writes = routine_writes(rt.program)
    written = frozenset().union(*writes.values())
    assert by_name["cprog"] in written and by_name["table"] not in written
    idle = rt.ff.idle
    assert by_name["table"] in idle._const and by_name["cprog"] not in idle._const
    rt.changed_outside()
    assert idle._const is None
    # found once per checked workspace (Program.derived): a second run of the same files gets
    # the first run's set; an edit (a new modification time) checks the files again, and the
    # set is found again from the new ASTs
    again, _res, _tw = _run(prog, max_sim_time=0.1)
    assert again.program.ws is rt.program.ws and routine_writes(again.program) is writes
    write(tmp_path, "table.dat", "DEFDAT table PUBLIC\n  DECL GLOBAL INT TAB[3]\n  TAB[1] = 7\nENDDAT\n\n")
    edited, _res, _tw = _run(prog, max_sim_time=0.1)
    assert edited.program.ws is not rt.program.ws
    assert routine_writes(edited.program) is not writes
    assert frozenset().union(*routine_writes(edited.program).values()) == written


LATE_PROG = """
DEF lprog()
  LOOP
    IF $IN[3] THEN
      EXIT
    ENDIF
  ENDLOOP
  COUNTUP()
END

DEF COUNTUP()
  LOOP
    LATEV = LATEV + 1
  ENDLOOP
END
"""


def _late(prog, interp, stim, fast):
    """:data:`LATE_PROG` traced (the idle watch alone) for 3 s with a time slice of 10 steps per
    IPO cycle (RunSpec ``robot_budget``: the 2-step pass stands at the same step at every window's
    end, and the run executes 2 500 statements at most)."""
    tw = TraceWriter(keep=False)
    rt, _ = make_runtime(run_spec(prog, inputs=stim, max_sim_time=3.0, max_steps=10_000_000, mujoco=False,
                                  check=False, interp=interp, fast_forward=fast, robot_budget=10), RunSinks(trace=tw))
    res = rt.run()
    tw.close()
    return rt, res


@pytest.mark.parametrize("interp", INTERPS)
def test_a_data_list_is_imaged_again_once_a_routine_that_writes_it_is_entered(tmp_path, interp):
    """A data list only routine COUNTUP writes is imaged once while the run has not entered
    COUNTUP (interp/runtime/calls.py ``Calls.entered``), and at every state image after: once
    $IN[3] (set at 1 s) lets the program call it, LATEV counts in its LOOP, the run is never
    idle again and runs to its 3 s limit statement by statement: 5 of its 10 steps a cycle, in
    the 167 cycles from the stimulus's (84, at 1.008 s) to the limit's (250), about 830. Kept,
    the old image would call the run idle and jump to the limit (LATEV 327, not 832: seen with the
    image kept): LATEV is that of the run without the idle watch (fast_forward False); without the
    stimulus COUNTUP is never entered and the list stays imaged once."""
    prog = write(tmp_path, "lprog.src", LATE_PROG)
    write(tmp_path, "lprog.dat", "DEFDAT lprog PUBLIC\nENDDAT\n")
    write(tmp_path, "late.dat", "DEFDAT late PUBLIC\n  DECL GLOBAL INT LATEV = 0\nENDDAT\n")
    stim = write(tmp_path, "stim.yaml", "- at: 1.0\n  set: {\"$IN[3]\": true}\n")
    (rt, res), (slow, r_slow) = [_late(prog, interp, stim, f) for f in (True, False)]
    late = {m.name.lower(): m for m in rt.program.modules}["late"]
    value = late.store[0]
    assert value == {m.name.lower(): m for m in slow.program.modules}["late"].store[0]
    assert 800 <= value <= 850, value
    assert res.reason == r_slow.reason == "max_sim_time"
    assert late.index not in rt.ff.idle._const
    quiet, _res = _late(prog, interp, None, True)
    assert late.index in quiet.ff.idle._const
