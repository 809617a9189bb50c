"""The automatic cell and a state machine driven by interrupts (issue 85, item 9;
krl/semantics/inputflow.py ``interrupt_flags``, interp/runtime/autocell.py ``_through_interrupts``),
on both interpreters.

Rebuilt from the issue's description: a main program whose LOOP runs a SWITCH on its own state
variable; interrupts on inputs set the flags its states wait for. Before, the cell saw only
conditions on variables and never moved it (the held-out program: 180 answers in 300 s, 25 M
statements, 0 motions; this one: 0 answers, only its first PTP, in 8 s). Now an IF on a flag is
answered with the inputs of the interrupt whose handler sets the flag to the value the IF wants
(reference §5.16: the handler runs on the rising edge of the WHEN condition); where that input
is TRUE already the cell gives FALSE, then TRUE two IPO cycles later (autocell.py EDGE_S)."""

from __future__ import annotations

import pytest

from interp.run import load_program, make_runtime, run_spec, RunSinks
from krl.semantics.inputflow import interrupt_flags

from .helpers import write

INTERPS = ("tree", "vm")

MACHINE = """
DEF sm()
  INTERRUPT DECL 10 WHEN StartIn DO OnStart()
  INTERRUPT ON 10
  INTERRUPT DECL 11 WHEN $IN[6] DO OnPart()
  INTERRUPT ON 11
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  LOOP
    SWITCH State
    CASE #IDLE
      IF StartFlag THEN
        State = #WAITPART
      ENDIF
    CASE #WAITPART
      IF PartFlag THEN
        State = #PICK
      ENDIF
    CASE #PICK
      PTP {A1 20}
      PTP {A1 0}
      StartFlag = FALSE
      PartFlag = FALSE
      Cycles = Cycles + 1
      State = #IDLE
    ENDSWITCH
  ENDLOOP
END

DEF OnStart()
  StartFlag = TRUE
END

DEF OnPart()
  PartFlag = TRUE
END
"""
DAT = """
DEFDAT sm
  ENUM SM_STATE IDLE, WAITPART, PICK
  DECL SM_STATE State = #IDLE
  DECL BOOL StartFlag = FALSE
  DECL BOOL PartFlag = FALSE
  DECL INT Cycles = 0
  SIGNAL StartIn $IN[5]
ENDDAT
"""


def _run(tmp, interp):
    prog = write(tmp, "sm.src", MACHINE)
    write(tmp, "sm.dat", DAT)
    rt, _ = make_runtime(run_spec(prog, inputs="auto", max_sim_time=8.0, mujoco=False, check=False,
                                  interp=interp), RunSinks())
    return rt, rt.run()


@pytest.mark.parametrize("interp", INTERPS)
def test_a_state_machine_driven_by_interrupts_is_answered_through_them(tmp_path, interp):
    rt, res = _run(tmp_path, interp)
    assert res.reason == "max_sim_time", res.text
    given = [(sig, v, a.line) for a in rt.autocell.answers for sig, _name, v in a.items]
    # IDLE waits on StartFlag (OnStart, $IN[5]); WAITPART on PartFlag (OnPart, $IN[6]); after the
    # first PICK both inputs are still TRUE: each is given FALSE, then TRUE (a new rising edge)
    assert given[:6] == [("$IN[5]", True, 10), ("$IN[6]", True, 14),
                         ("$IN[5]", False, 10), ("$IN[5]", True, 10),
                         ("$IN[6]", False, 14), ("$IN[6]", True, 14)]
    a = rt.autocell.answers
    assert a[0].describe().endswith("releases sm.src:10 (IF, through the interrupt of ONSTART)")
    assert round(a[3].t - a[2].t, 3) == 0.024          # two IPO cycles between FALSE and TRUE
    assert rt.program.module("sm").data["CYCLES"].get() >= 1     # the PICK state ran: it moved


def test_the_flags_interrupts_set(tmp_path):
    """inputflow.interrupt_flags on its own: the data-list flags each handler sets, with the value."""
    prog = write(tmp_path, "sm.src", MACHINE)
    write(tmp_path, "sm.dat", DAT)
    loaded = load_program(run_spec(prog, mujoco=False, check=False))
    flags = interrupt_flags(loaded.program.ws)
    got = sorted((f.handler, f.value, f.decl.span.line) for fl in flags.values() for f in fl)
    assert got == [("ONPART", True, 4), ("ONSTART", True, 2)]
