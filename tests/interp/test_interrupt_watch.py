"""When interrupt conditions are evaluated again (interp/runtime/watch.py, issue 39): the
class each condition gets from the names it reads, the evaluations it saves, and the oracle —
the same traces as evaluating every condition at every poll (stamp_key patched to None,
contexts.WATCHED False)."""

from __future__ import annotations

import pytest

import interp.runtime.contexts as contexts
from interp.runtime.contexts import InterruptTable, Irq

from .helpers import run_krl

DAT = """
DEFDAT prog
  DECL INT N1 = 0
  DECL INT N2 = 0
  DECL INT N3 = 0
  DECL INT N4 = 0
  DECL INT N5 = 0
  DECL BOOL GO = FALSE
ENDDAT
"""

#: every kind of condition: constant, an input, an output the handlers write, a timer, the
#: motion state, a variable, a SIGNAL group; stimuli toggle the input, handlers toggle outputs
PROG = """
DEF prog()
  SIGNAL GRP $IN[5] TO $IN[6]
  GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO Never()
  GLOBAL INTERRUPT DECL 10 WHEN $IN[3] AND NOT $OUT[7] DO OnIn()
  GLOBAL INTERRUPT DECL 11 WHEN $TIMER_FLAG[1] DO OnTimer()
  GLOBAL INTERRUPT DECL 12 WHEN $PRO_MOVE == TRUE DO OnMove()
  GLOBAL INTERRUPT DECL 13 WHEN GO DO OnGo()
  GLOBAL INTERRUPT DECL 14 WHEN GRP == 3 DO OnGrp()
  INTERRUPT ON
  $TIMER[1] = -100
  $TIMER_STOP[1] = FALSE
  PTP {A1 10, A2 -90, A3 90, A4 0, A5 0, A6 0}
  PTP {A1 -10, A2 -90, A3 90, A4 0, A5 0, A6 0}
  GO = TRUE
  WAIT SEC 0.2
  GO = FALSE
  $OUT[7] = FALSE
  GO = TRUE
  WAIT SEC 0.6
END
DEF Never()
  N1 = N1 + 100
END
DEF OnIn()
  N1 = N1 + 1
  $OUT[7] = TRUE
END
DEF OnTimer()
  N2 = N2 + 1
  $TIMER[1] = -50
END
DEF OnMove()
  N3 = N3 + 1
END
DEF OnGo()
  N4 = N4 + 1
END
DEF OnGrp()
  N5 = N5 + 1
END
"""

STIMULI = """stimuli:
  - at: 0.05
    set: {"$IN[3]": true}
  - at: 0.3
    set: {"$IN[3]": false}
  - at: 0.5
    set: {"$IN[3]": true, "$IN[5]": true}
  - at: 0.9
    set: {"$IN[6]": true}
"""


def _run(tmp_path, interp):
    return run_krl(tmp_path, PROG, DAT, stimuli=STIMULI, interp=interp)


def test_each_condition_gets_its_class(tmp_path):
    r = _run(tmp_path, "tree")
    irqs = r.rt.robot.irqs.irqs
    got = {n: (irqs[n].watch, len(irqs[n].probes)) for n in (3, 10, 11, 12, 13, 14)}
    # 13 reads a variable: SETTLES (evaluated again after a statement ran)
    assert got == {3: ("K", 0), 10: ("I", 0), 11: ("T", 0), 12: ("K", 1), 13: ("V", 0), 14: ("I", 0)}


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_trace_is_that_of_evaluating_at_every_poll(tmp_path, monkeypatch, interp):
    watched = _run(tmp_path, interp)
    monkeypatch.setattr(contexts, "stamp_key", lambda *a, **k: None)
    monkeypatch.setattr(contexts, "WATCHED", False)
    every = _run(tmp_path, interp)
    assert watched.result.reason == every.result.reason == "completed"
    assert watched.events == every.events
    n = {k: watched.var("prog", k) for k in ("N1", "N2", "N3", "N4", "N5")}
    # each condition rose: the input twice (the handler's $OUT[7] masks it until reset), the
    # timer at least twice (the handler restarts it), the motion state, GO twice, the group
    assert n["N1"] == 2 and n["N2"] >= 2 and n["N3"] >= 1 and n["N4"] == 2 and n["N5"] == 1
    assert n == {k: every.var("prog", k) for k in n}


def _table(watch, probes=()):
    calls = []
    t = InterruptTable()
    t.declare(Irq(7, lambda: calls.append(1) or False, lambda: None, "H", None, watch=watch, probes=probes))
    return t, calls


def test_a_constant_condition_is_evaluated_once_per_on():
    t, calls = _table("K")
    t.control("ON", 7, io_version=1, now=0.0)
    for k in range(100):
        t.poll(io_version=k, now=k * 0.012)
    assert len(calls) == 1


def test_a_condition_over_variables_is_evaluated_when_something_may_have_written():
    """SETTLES: the same I/O version and the same ``written`` (steps executed, cyclic flag
    changes) keep the value; either changing evaluates; no ``written`` (a debugger) evaluates."""
    t, calls = _table("V")
    t.control("ON", 7, io_version=1, now=0.0, written=(10, 0))
    for k in range(50):
        t.poll(io_version=1, now=k * 0.012, written=(10, 0))
    assert len(calls) == 1
    t.poll(io_version=1, written=(11, 0))
    t.poll(io_version=1, written=(11, 1))
    t.poll(io_version=2, written=(11, 1))
    assert len(calls) == 4
    t.poll(io_version=2, written=None)
    t.poll(io_version=2, written=None)
    assert len(calls) == 6


def test_an_io_condition_is_evaluated_when_the_image_changed():
    t, calls = _table("I")
    t.control("ON", 7, io_version=1, now=0.0)
    for k in range(100):
        t.poll(io_version=1 + k // 10, now=k * 0.012)
    assert len(calls) == 10            # at ON, then once per new version (2..10)


def test_a_clock_condition_is_evaluated_once_per_cycle():
    t, calls = _table("T")
    t.control("ON", 7, io_version=1, now=0.0)
    for k in range(100):
        t.poll(io_version=1, now=(k // 4) * 0.012)     # four polls per cycle
    assert len(calls) == 25


def test_a_probed_condition_follows_its_values_and_others_every_poll():
    state = {"v": 0}
    t, calls = _table("K", probes=(lambda: state["v"],))
    t.control("ON", 7)
    for k in range(30):
        state["v"] = k // 10
        t.poll()
    assert len(calls) == 3             # at ON (0), then 1 and 2
    t, calls = _table("")
    t.control("ON", 7)
    for _ in range(30):
        t.poll()
    assert len(calls) == 31


def test_a_poll_says_whether_an_interrupt_is_ready():
    """poll returns True exactly when an armed interrupt is pending and enabled (the runtime
    looks for one to run only then), also on a poll that keeps a condition's value."""
    state = {"v": False}
    t = InterruptTable()
    t.declare(Irq(7, lambda: state["v"], lambda: None, "H", None, watch="I"))
    t.control("ON", 7, io_version=1)
    assert t.poll(io_version=1) is False
    state["v"] = True
    assert t.poll(io_version=1) is False          # the image did not change: value kept
    assert t.poll(io_version=2) is True           # the rising edge: pending
    assert t.poll(io_version=2) is True           # still pending, key unchanged
    t.control("DISABLE", 7)
    assert t.poll(io_version=2) is False          # pending but disabled
    t.control("ENABLE", 7)
    assert t.poll(io_version=2) is True
    t.irqs[7].pending = False
    assert t.poll(io_version=3) is False          # TRUE stays TRUE: no new edge


#: the backups' SPS.SUB pattern (KRC4 System/sps.sub): interrupts over the probed run state,
#: armed for the whole run, beside a loop of cheap statements; each handler notes the loop
#: count at which it ran, so a handler one statement late shows
SPS = """
DEF plc()
  INTERRUPT DECL 91 WHEN $PRO_STATE1==#P_END DO OnFree()
  INTERRUPT DECL 92 WHEN $PRO_MOVE==TRUE DO OnMove()
  INTERRUPT DECL 93 WHEN $STOPMESS==TRUE DO OnFree()
  INTERRUPT ON 91
  INTERRUPT ON 92
  INTERRUPT ON 93
  LOOP
    K = K + 1
    IF K > 100000 THEN
      K = 0
    ENDIF
  ENDLOOP
END
DEF OnFree()
  NF = NF + 1
END
DEF OnMove()
  NM = NM + 1
  AT[NM] = K
END
"""
SPS_DAT = """
DEFDAT plc
  DECL INT K = 0
  DECL INT NF = 0
  DECL INT NM = 0
  DECL INT AT[20]
ENDDAT
"""
MOVER = """
DEF prog()
  PTP {A1 10, A2 -90, A3 90, A4 0, A5 0, A6 0}
  WAIT SEC 0.1
  PTP {A1 -10, A2 -90, A3 90, A4 0, A5 0, A6 0}
  WAIT SEC 0.2
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  WAIT SEC 0.05
END
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_settled_interrupts_poll_once_per_state_epoch(tmp_path, monkeypatch, interp):
    """Interrupts over constants and the probed run state ($PRO_MOVE, $PRO_STATE1) keep the
    VM's quiet steps and are polled once per state epoch (an IPO cycle, ...), not at each
    statement; each handler still runs at the loop count of evaluating every condition at
    every poll, untraced (quiet steps need no trace) and traced."""
    polls = []
    real = InterruptTable.poll

    def counting(self, *a, **k):
        polls.append(1)
        return real(self, *a, **k)

    monkeypatch.setattr(InterruptTable, "poll", counting)
    files = {"plc.sub": SPS, "plc.dat": SPS_DAT}

    def run(trace):
        polls.clear()
        r = run_krl(tmp_path, MOVER, files=files, submit=["plc.sub"], trace=trace, interp=interp)
        assert r.result.reason == "completed", r.result.text
        got = {k: r.var("plc", k) for k in ("K", "NF", "NM")}
        got["AT"] = list(r.var("plc", "AT").data[:got["NM"]])
        return got, r.rt.clock.steps, len(polls), r.events

    watched, steps, n_watched, _ = run(False)
    traced, steps_t, _, events = run(True)
    monkeypatch.setattr(contexts, "stamp_key", lambda *a, **k: None)
    monkeypatch.setattr(contexts, "WATCHED", False)
    every, steps_e, n_every, _ = run(False)
    _, _, _, events_e = run(True)
    # three motions, each a rising edge of $PRO_MOVE seen by the submit interpreter; the
    # robot program's end, $PRO_STATE1 P_ACTIVE -> P_END (it stays selected: KUKA's states,
    # interp/runtime/cmdchannel.py), seen in its last cycle
    assert watched["NM"] == 3 and watched["NF"] == 1
    assert watched == traced == every and steps == steps_t == steps_e
    assert events == events_e
    assert n_every >= steps // 2                  # the submit interpreter polls at each step
    assert n_watched * 20 < n_every               # settled: once per IPO cycle


#: a BRAKE in an interrupt routine that returns without RESUME: the held motion runs again at
#: the routine's end (robot/controller.py ``release``), a change of $PRO_MOVE outside an IPO
#: cycle; the loop counter at which OnMove runs shows whether the next poll saw it at once
BRAKER = """
DEF prog()
  INTERRUPT DECL 5 WHEN $IN[1] DO Stopper()
  INTERRUPT DECL 6 WHEN $PRO_MOVE==TRUE DO OnMove()
  INTERRUPT ON 5
  INTERRUPT ON 6
  PTP {A1 150, A2 -90, A3 90, A4 0, A5 0, A6 0}
  LOOP
    K = K + 1
    IF (NM >= 2) OR (K > 100000) THEN
      EXIT
    ENDIF
  ENDLOOP
END
DEF Stopper()
  BRAKE
  NB = NB + 1
END
DEF OnMove()
  NM = NM + 1
  AT[NM] = K
END
"""
BRAKER_DAT = SPS_DAT.replace("plc", "prog").replace("NF", "NB")
BRAKER_STIMULI = """stimuli:
  - at: 0.1
    set: {"$IN[1]": true}
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_motion_released_after_brake_is_seen_by_the_next_poll(tmp_path, monkeypatch, interp):
    """The motion a BRAKE held runs again when its interrupt routine returns: $PRO_MOVE rises
    outside an IPO cycle, so that return begins a new state epoch, and OnMove runs at the
    loop count of evaluating every condition at every poll."""
    def run():
        r = run_krl(tmp_path, BRAKER, BRAKER_DAT, stimuli=BRAKER_STIMULI, trace=False, interp=interp)
        assert r.result.reason == "completed", r.result.text
        nm = r.var("prog", "NM")
        return r.var("prog", "NB"), nm, list(r.var("prog", "AT").data[:nm])

    watched = run()
    monkeypatch.setattr(contexts, "stamp_key", lambda *a, **k: None)
    monkeypatch.setattr(contexts, "WATCHED", False)
    every = run()
    assert watched[0] == 1 and watched[1] == 2      # one BRAKE; moving at the start and again after
    assert watched[2][1] > watched[2][0]
    assert watched == every
