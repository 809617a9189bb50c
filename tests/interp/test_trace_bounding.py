"""The bounded trace of ``krl run --trace`` (issue 34, robot/trace.py ``repeats``): a pass of
events that repeats with nothing changed but time is written ``--trace-repeats`` times (10),
then counted in a ``repeat`` event; a loop whose state changes from pass to pass keeps every
event; a polling loop with a WAIT SEC that nothing answers ends at its time limit at once
(interp/runtime/idle.py, periodic jump) with a small trace. Both interpreters write the same
bytes.

Expected values are counted from the programs by hand: one ``stmt`` event per executed
statement of a loop body (the loop's own test is not a statement event), one ``io`` event per
change of an output, WAIT SEC t = ceil(t / 12 ms) IPO cycles (reference §5.8)."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from interp.run import make_runtime, run_spec, RunSinks
from app import main
from robot.trace import (
    PROBE_CREDIT_VALUES, PROBE_VALUES_PER_EVENT, TRACE_REPEATS, TraceWriter, validate_event,
)

from .helpers import write

INTERPS = ("tree", "vm")

COUNTER = """
DEF counter()
  INT I, N
  N = 0
  FOR I = 1 TO 50
    $OUT[I] = TRUE
  ENDFOR
  WHILE N < 50
    N = N + 1
  ENDWHILE
  FOR I = 1 TO 50
    $OUT[60] = TRUE
  ENDFOR
  $OUT[61] = N == 50
END
"""

POLL = """
DEF poll()
  WHILE NOT $IN[5]
    WAIT SEC 0.1
  ENDWHILE
  $OUT[1] = TRUE
END
"""

BLINK = """
DEF blink()
  LOOP
    $OUT[1] = NOT $OUT[1]
  ENDLOOP
END
"""


def _cli_trace(tmp_path, prog, interp, *extra):
    trace = tmp_path / f"{prog.stem}-{interp}.jsonl"
    out = CliRunner().invoke(main, ["run", str(prog), "--interp", interp, "--trace", str(trace), *extra])
    assert "Traceback" not in out.output, out.output
    return out, trace.read_text(encoding="utf-8"), [json.loads(x) for x in trace.read_text().splitlines()]


def _run(prog, *, interp="tree", repeats=TRACE_REPEATS, max_sim_time=600.0, fast=True, inputs=None):
    tw = TraceWriter(keep=True, repeats=repeats)
    rt, _ = make_runtime(run_spec(prog, max_sim_time=max_sim_time, mujoco=False, check=False, interp=interp,
                         inputs=inputs, fast_forward=fast), RunSinks(trace=tw))   # traced: the idle watch alone
    res = rt.run()
    tw.close()
    return rt, res, tw.events


def test_a_counter_loop_keeps_every_event_with_the_default_options(tmp_path):
    """Three loops of 50 passes whose statements repeat while their state (I, N) changes:
    krl run --trace (default --trace-repeats 10) keeps all 50 output changes of the first,
    all 50 assignments `N = N + 1` (line 8) of the second, all 50 statements of the third
    (the same output set again: no io event, I changes); nothing is left out. The same bytes
    from both interpreters."""
    prog = write(tmp_path, "counter.src", COUNTER)
    texts = []
    for interp in INTERPS:
        out, text, events = _cli_trace(tmp_path, prog, interp)
        assert out.exit_code == 0, out.output
        texts.append(text)
        for e in events:
            validate_event(e)
        assert not [e for e in events if e["kind"] == "repeat"]
        outs = [e["signal"] for e in events if e["kind"] == "io"]
        assert outs == [f"$OUT[{i}]" for i in range(1, 51)] + ["$OUT[60]", "$OUT[61]"]
        lines = [e["line"] for e in events if e["kind"] == "stmt"]
        assert lines.count(5) == 50        # $OUT[I] = TRUE
        assert lines.count(8) == 50        # N = N + 1
        assert lines.count(11) == 50       # $OUT[60] = TRUE, again and again
        assert events[-1]["kind"] == "end" and events[-1]["reason"] == "completed"
    assert texts[0] == texts[1]


def test_a_polling_loop_nothing_answers_ends_at_its_time_limit_with_a_small_trace(tmp_path):
    """WHILE NOT $IN[5] / WAIT SEC 0.1 for 600 s: 5556 passes of 9 cycles and 50 000 poses
    without bounding; the run ends at the time limit on the WAIT SEC line, the clock having
    jumped whole periods (one `idle` event reaches 599.988 s, the cycle before the limit),
    and the trace holds fewer than 1000 lines, the same bytes from both interpreters."""
    prog = write(tmp_path, "poll.src", POLL)
    texts = []
    for interp in INTERPS:
        out, text, events = _cli_trace(tmp_path, prog, interp)
        assert out.exit_code == 3, out.output
        texts.append(text)
        assert len(text.splitlines()) < 1000
        for e in events:
            validate_event(e)
        end = events[-1]
        assert (end["kind"], end["reason"], end["t"], end["line"]) == ("end", "max_sim_time", 600.0, 3)
        assert max(e["until"] for e in events if e["kind"] == "idle") == pytest.approx(599.988)
    assert texts[0] == texts[1]


@pytest.mark.parametrize("interp", INTERPS)
def test_the_periodic_jump_keeps_the_phase_of_the_polling_loop(tmp_path, interp):
    """$IN[5] set at 60.05 s: applied in cycle ceil(60.05 / 0.012) = 5005 (60.06 s). The loop's
    passes wake every 9 cycles from cycle 0 (WAIT SEC 0.1 = 9 cycles): at cycles 9k, so it
    reads the input at cycle 5013 (60.156 s) and sets $OUT[1] there — with and without the
    fast-forward."""
    prog = write(tmp_path, "poll.src", POLL)
    stim = write(tmp_path, "s.yaml", "- at: 60.05\n  set: {\"$IN[5]\": true}\n")
    got = []
    for fast in (True, False):
        rt, res, events = _run(prog, interp=interp, inputs=stim, fast=fast)
        assert res.reason == "completed"
        got.append([(e["t"], e["signal"]) for e in events if e["kind"] == "io"])
        assert (rt.ff.idle.jumps > 0) == fast
    assert got[0] == got[1] == [(60.06, "$IN[5]"), (60.156, "$OUT[1]")]


def test_a_spin_that_returns_to_its_state_is_bounded(tmp_path):
    """LOOP $OUT[1] = NOT $OUT[1] ENDLOOP changes an output every pass (never idle, never
    fast-forwarded), but every two passes the state and the events are the same again: the
    bounded trace writes the pass (stmt, io True, stmt, io False) 10 times a run of it, counts
    the rest, and events written plus counted are the unbounded trace's; the same events from
    both interpreters."""
    prog = write(tmp_path, "blink.src", BLINK)
    _rt, full_res, full = _run(prog, repeats=None, max_sim_time=0.12, fast=False)
    per = []
    for interp in INTERPS:
        _rt, res, events = _run(prog, interp=interp, max_sim_time=0.12, fast=False)
        assert res.steps == full_res.steps
        per.append(events)
        for e in events:
            validate_event(e)
        reps = [e for e in events if e["kind"] == "repeat"]
        assert reps and all(e["period"] == 4 for e in reps)   # every repeat says its pass: 4 events
        written = sum(1 for e in events if e["kind"] != "repeat")
        assert written + sum(e["count"] for e in reps) == len(full)
        assert sum(1 for e in events if e["kind"] == "io") < len([e for e in full if e["kind"] == "io"]) // 10
        assert events[-1] == full[-1]
    assert per[0] == per[1]


def test_a_loop_whose_state_changes_is_never_bounded(tmp_path):
    """LOOP N = N + 1 ENDLOOP: the same statement pass after pass, N different each time: the
    bounded trace is the unbounded one, event for event."""
    prog = write(tmp_path, "count.src", """
    DEF count()
      INT N
      N = 0
      LOOP
        N = N + 1
      ENDLOOP
    END
    """)
    _rt, _res, full = _run(prog, repeats=None, max_sim_time=0.06, fast=False)
    for interp in INTERPS:
        _rt, _res, events = _run(prog, interp=interp, max_sim_time=0.06, fast=False)
        assert events == full
    assert sum(1 for e in full if e["kind"] == "stmt") > 2000


def test_the_writer_alone_bounds_by_the_events():
    """Without a state probe (a TraceWriter used by itself), passes of equal events are
    bounded: 30 passes of (stmt 4, io $OUT[2] TRUE... and back): the pass written 10 times,
    the 20 others in one `repeat` event with passes 20 and period 3; an idle jump's times and a
    motion's id do not make an event new."""
    tw = TraceWriter(keep=True, repeats=10)
    t = 0.0
    for k in range(30):
        t += 0.012
        tw.write("stmt", t, file="a.src", line=4, context="main")
        tw.write("motion", t, id=k + 1, type="PTP", target={"A1": 0}, approximation=None, phase="start")
        tw.write("idle", t, until=t + 0.01 * k, since=0.0, cycles=k + 1)
    tw.write("stmt", t, file="a.src", line=5, context="main")
    tw.close()
    ev = tw.events
    reps = [e for e in ev if e["kind"] == "repeat"]
    assert len(reps) == 1
    assert (reps[0]["count"], reps[0]["passes"], reps[0]["period"]) == (60, 20, 3)
    assert reps[0]["kinds"] == {"idle": 20, "motion": 20, "stmt": 20}
    assert sum(1 for e in ev if e["kind"] == "stmt") == 11
    for e in ev:
        validate_event(e)


def test_the_state_probes_keep_to_their_budget():
    """A probe that images 2 000 000 values (more than the start credit of 2**20) may run again
    only once (2 000 000 - 2**20) / PROBE_VALUES_PER_EVENT (16) = 59 464 events are accounted:
    over 200 events of a 2-event pass the first probe (the capture at the end of pass 9) is the
    only one, so the spin is never confirmed and every event is written; a probe of 10 values
    confirms it at the end of pass 10 (capture at 9, comparison at 10), as without a budget:
    20 events written, 180 counted, and 10 probes: each of the two trackers (every event; the
    events other than poses, here the same) captures at 9, compares at 10 and again after
    passes 20, 40 and 80."""
    assert (PROBE_CREDIT_VALUES, PROBE_VALUES_PER_EVENT) == (1 << 20, 16)
    for values, probes_expected, written_expected in ((2_000_000, 1, 200), (10, 10, 20)):
        tw = TraceWriter(keep=True, repeats=10)
        calls = []

        def probe(values=values, calls=calls):
            calls.append(values)
            return "same", values

        tw.state_probe = probe
        for k in range(100):
            tw.write("stmt", 0.012 * k, file="a.src", line=4, context="main")
            tw.write("io", 0.012 * k, signal="$OUT[2]", value=True, source="program")
        tw.close()
        ev = tw.events
        assert sum(1 for e in ev if e["kind"] != "repeat") == written_expected
        assert sum(e["count"] for e in ev if e["kind"] == "repeat") == 200 - written_expected
        assert len(calls) == probes_expected


BIG = """
DEF bigblink()
  INT BIG[40000]
  INT I
  FOR I = 1 TO 40000
    BIG[I] = I
  ENDFOR
  LOOP
    $OUT[1] = NOT $OUT[1]
  ENDLOOP
END
"""


def test_a_large_state_costs_probes_in_proportion_to_the_events(tmp_path):
    """The blink loop beside a local array of 40 000 values: each state probe images them all.
    The probes image at most the start credit (2**20) and PROBE_VALUES_PER_EVENT (16) values per
    event, plus one probe's worth, the events written and counted are still the unbounded trace's, and both
    interpreters write the same events. 1.6 s: the probes spend past the start credit from about
    1.3 s and have spent all they spend by 1.6 s (1 190 618 values, as in 2 s, 2026-11-29: the
    test ran 2 s until then, a quarter more events and nothing more probed)."""
    assert PROBE_VALUES_PER_EVENT == 16
    prog = write(tmp_path, "bigblink.src", BIG)
    _rt, full_res, full = _run(prog, repeats=None, max_sim_time=1.6, fast=False)
    per = []
    for interp in INTERPS:
        tw = TraceWriter(keep=True, repeats=TRACE_REPEATS)
        rt, _ = make_runtime(run_spec(prog, max_sim_time=1.6, mujoco=False, check=False, interp=interp,
                                      fast_forward=False), RunSinks(trace=tw))
        res = rt.run()
        tw.close()
        events = tw.events
        assert res.steps == full_res.steps
        assert tw._probe_spent > 1 << 20      # past the start credit: the bound per event holds
        written = sum(1 for e in events if e["kind"] != "repeat")
        assert written + sum(e["count"] for e in events if e["kind"] == "repeat") == len(full)
        assert tw._probe_spent <= (1 << 20) + 16 * len(full) + 40_002 + 100
        assert any(e["kind"] == "repeat" for e in events)
        per.append(events)
    assert per[0] == per[1]
