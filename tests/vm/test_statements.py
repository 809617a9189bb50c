"""One test per statement kind: the VM and the tree interpreter give the same trace and the
same variable values (and the value the reference gives, where it is simple to state)."""

from __future__ import annotations

import textwrap

import pytest

from interp.runtime.values import UNSET, is_char_array

from .differential import compare, first_difference, run_trace

DAT = """
DEFDAT prog
  STRUC PAIR INT A, REAL B
  DECL INT N1, N2, N3
  DECL REAL R1
  DECL BOOL B1
  DECL CHAR S1[20]
  DECL INT ARR[5]
  DECL PAIR P1
  DECL E6AXIS HOME = {A1 0.0, A2 -90.0, A3 90.0, A4 0.0, A5 45.0, A6 0.0, E1 0.0, E2 0.0, E3 0.0, E4 0.0, E5 0.0, E6 0.0}
ENDDAT
"""


def both(tmp_path, body: str, extra: str = "", stimuli: str | None = None, submit: str | None = None,
         max_sim_time: float = 20.0):
    src = "DEF prog()\n" + textwrap.dedent(body).strip("\n") + "\nEND\n" + textwrap.dedent(extra)
    (tmp_path / "prog.src").write_text(src)
    (tmp_path / "prog.dat").write_text(DAT)
    kw = {"max_sim_time": max_sim_time}
    if stimuli:
        (tmp_path / "stim.yaml").write_text(textwrap.dedent(stimuli))
        kw["inputs"] = tmp_path / "stim.yaml"
    if submit:
        (tmp_path / "side.sub").write_text(textwrap.dedent(submit))
        kw["submit"] = [tmp_path / "side.sub"]
    values = {}

    def keep(kind):
        def before(rt):
            values[kind] = rt
        return before
    tree_res, tree_ev = run_trace(tmp_path / "prog.src", "tree", before=keep("tree"), **kw)
    vm_res, vm_ev = run_trace(tmp_path / "prog.src", "vm", before=keep("vm"), **kw)
    diff = first_difference(tree_ev, vm_ev)
    assert diff is None, f"first difference at event {diff[0]}:\n tree {diff[1]}\n vm   {diff[2]}"
    assert (tree_res.reason, tree_res.text, tree_res.line) == (vm_res.reason, vm_res.text, vm_res.line)

    def var(name):
        vals = []
        for kind in ("tree", "vm"):
            ref = values[kind].program.module("prog").data[name.upper()]
            v = ref.peek()
            vals.append(v.text() if is_char_array(v) else (dict(v.f) if hasattr(v, "f") else
                                                            (list(v.data) if hasattr(v, "data") else v)))
        assert vals[0] == vals[1], (name, vals)
        return vals[1]
    return vm_res, vm_ev, var


def test_assignment_and_expressions(tmp_path):
    res, _, var = both(tmp_path, """
      N1 = 7 / 2 + 3 * (2 - 5)
      R1 = N1 * 0.5 - 1
      B1 = ((N1 < 0) AND NOT (R1 > 0)) OR ((N1 B_AND 3) == 3)
      S1[] = "ABC"
      S1[2] = 66
      ARR[2] = N1
      P1 = {A 3, B 2.5}
      P1.A = P1.A + ARR[2]
      N2 = STRLEN(S1[])
    """)
    assert res.reason == "completed"
    assert var("N1") == 3 + 3 * -3
    assert var("R1") == -4.0
    assert var("B1") is True
    assert var("S1") == "ABC"
    assert var("P1") == {"A": -3, "B": 2.5}
    assert var("N2") == 3


def test_if_else(tmp_path):
    res, _, var = both(tmp_path, """
      N1 = 5
      IF N1 > 3 THEN
        N2 = 1
      ELSE
        N2 = 2
      ENDIF
      IF N1 < 3 THEN
        N3 = 1
      ELSE
        N3 = 2
      ENDIF
    """)
    assert (var("N2"), var("N3")) == (1, 2)


def test_switch(tmp_path):
    res, _, var = both(tmp_path, """
      N1 = 0
      FOR N2 = 1 TO 4
        SWITCH N2
        CASE 1, 3
          N1 = N1 + 10
        CASE 2
          N1 = N1 + 100
        DEFAULT
          N1 = N1 + 1000
        ENDSWITCH
      ENDFOR
    """)
    assert var("N1") == 1120


def test_for_while_repeat_loop_exit(tmp_path):
    res, _, var = both(tmp_path, """
      N1 = 0
      FOR N2 = 10 TO 1 STEP -3
        N1 = N1 + N2
      ENDFOR
      WHILE N1 > 5
        N1 = N1 - 7
      ENDWHILE
      REPEAT
        N1 = N1 + 1
      UNTIL N1 >= 4
      N3 = 0
      LOOP
        N3 = N3 + 1
        IF N3 == 3 THEN
          EXIT
        ENDIF
      ENDLOOP
    """)
    assert var("N2") == -2
    assert var("N1") == 4
    assert var("N3") == 3


def test_goto(tmp_path):
    res, _, var = both(tmp_path, """
      N1 = 0
      start:
      N1 = N1 + 1
      IF N1 < 3 THEN
        GOTO start
      ENDIF
      GOTO done
      N1 = 100
      done:
    """)
    assert var("N1") == 3


def test_calls_out_parameters_and_functions(tmp_path):
    res, ev, var = both(tmp_path, """
      N1 = 1
      ARR[3] = 5
      P1 = {A 1, B 1.0}
      BUMP(N1, ARR[3], P1.A, 7)
      R1 = HALF(ARR[3])
    """, extra="""
    DEF BUMP(x:OUT, y:OUT, z:OUT, w:IN)
      DECL INT x, y, z, w
      x = x + w
      y = y * 2
      z = -z
      w = 0
    END

    DEFFCT REAL HALF(v:IN)
      DECL INT v
      RETURN v / 2.0
    ENDFCT
    """)
    assert var("N1") == 8
    assert var("ARR")[2] == 10
    assert var("P1")["A"] == -1
    assert var("R1") == 5.0
    assert [e["name"] for e in ev if e["kind"] == "call"] == ["prog", "BUMP", "HALF"]


def test_wait_halt_continue_on_error_proceed(tmp_path):
    res, _, var = both(tmp_path, """
      WAIT SEC 0.1
      WAIT FOR $IN[1]
      CONTINUE
      $OUT[2] = TRUE
      ON_ERROR_PROCEED
      N1 = ARR[9]
      N2 = $ERR.NUMBER
      HALT
      N3 = 1
    """, stimuli="""
    stimuli:
      - at: 0.3
        set: {"$IN[1]": true}
    """)
    assert res.reason == "halt"
    assert var("N2") != 0


def test_motion_trigger_interrupt_brake_resume(tmp_path):
    res, ev, var = both(tmp_path, """
      INTERRUPT DECL 3 WHEN $IN[2] DO STOPIT()
      PTP HOME
      INTERRUPT ON 3
      TRIGGER WHEN DISTANCE=0 DELAY=20 DO $OUT[3] = TRUE
      LIN_REL {X 30, Z -20} C_DIS
      TRIGGER WHEN PATH=-10 DELAY=0 DO MARK(4)
      LIN_REL {Y 20}
      PTP_REL {A1 20}
      WAIT SEC 1.0
      INTERRUPT OFF 3
      N1 = 1
    """, extra="""
    DEF STOPIT()
      BRAKE
      $OUT[1] = TRUE
    END

    DEF MARK(n:IN)
      DECL INT n
      $OUT[n] = TRUE
    END
    """, stimuli="""
    stimuli:
      - at: 1.0
        set: {"$IN[2]": true}
    """)
    kinds = {e["kind"] for e in ev}
    assert {"motion", "stmt", "call", "interrupt", "io"} <= kinds
    assert res.reason == "completed"


def test_trigger_assignment_action_evaluates_value_before_target(tmp_path):
    """A TRIGGER's assignment action is an assignment (krl/semantics/statements.py: run from its
    plan when the trigger fires), so its value is evaluated before its target's index, as in
    ``ARR[NEXT()] = NEXT()`` written as a statement: the value is 1, the index 2. (Before issue
    76 the tree interpreter took the target first and wrote ARR[1] = 2; the VM wrote ARR[2] = 1.)"""
    res, _, var = both(tmp_path, """
      N1 = 0
      PTP HOME
      TRIGGER WHEN DISTANCE=0 DELAY=0 DO ARR[NEXT()] = NEXT()
      PTP_REL {A1 10}
      WAIT SEC 0.1
    """, extra="""
    DEFFCT INT NEXT()
      N1 = N1 + 1
      RETURN N1
    ENDFCT
    """)
    assert res.reason == "completed"
    assert var("N1") == 2
    arr = var("ARR")
    assert arr[1] == 1 and arr[0] is UNSET

def test_spline_block(tmp_path):
    res, ev, _ = both(tmp_path, """
      PTP HOME
      SPLINE
        SPL {X 520, Y 0, Z 820, A 180, B 45, C 180}
        TRIGGER WHEN PATH=0 DELAY=0 DO $OUT[5] = TRUE
        SLIN {X 530, Y 20, Z 800, A 180, B 45, C 180} WITH $VEL.CP = 0.2
      ENDSPLINE
    """)
    assert res.reason == "completed"
    assert any(e["kind"] == "motion" and e["type"] == "SPLINE" for e in ev)


def test_submit_interpreter(tmp_path):
    """The submit program toggles $OUT[7] while the robot program waits 0.5 s. Expected from
    the reference (WAIT SEC in the submit interpreter, 12 ms IPO cycle) and docs/architecture.md
    (a wait ends on the 12 ms grid: 0.1 s -> 9 cycles = 0.108 s): toggles at 0, 0.108, 0.216,
    0.324, 0.432 s, TRUE first; the robot program completes at 0.504 s with N1 = N2 = 5."""
    res, ev, var = both(tmp_path, """
      N2 = 5
      WAIT SEC 0.5
      N1 = N2
    """, submit="""
    DEF side()
      LOOP
        $OUT[7] = NOT $OUT[7]
        WAIT SEC 0.1
      ENDLOOP
    END
    """, max_sim_time=2.0)
    assert res.reason == "completed", (res.reason, res.text, res.line)
    assert var("N1") == 5
    toggles = [e for e in ev if e["kind"] == "io" and e["signal"] == "$OUT[7]"]
    assert [e["value"] for e in toggles] == [True, False, True, False, True]
    assert [e["t"] for e in toggles] == pytest.approx([0.0, 0.108, 0.216, 0.324, 0.432], abs=1e-9)
    assert ev[-1]["kind"] == "end" and ev[-1]["t"] == pytest.approx(0.504, abs=1e-9)


def test_analog_and_stub_statements(tmp_path):
    """ANOUT ON recomputes the output every IPO cycle, clamped to MINIMUM/MAXIMUM, until
    ANOUT OFF (reference 5.x analog I/O): 0.5 * 0.4 = 0.2 at once; after R1 = 4.0 the next
    cycle writes min(2.0, 0.9) = 0.9; after ANOUT OFF, R1 = 0 changes nothing. $CYCFLAG and
    CONFIRM run to completion."""
    res, ev, var = both(tmp_path, """
      SIGNAL AOUT1 $ANOUT[1]
      R1 = 0.4
      ANOUT ON AOUT1 = 0.5 * R1 MINIMUM=0.1 MAXIMUM=0.9
      WAIT SEC 0.1
      R1 = 4.0
      WAIT SEC 0.1
      ANOUT OFF AOUT1
      R1 = 0.0
      WAIT SEC 0.1
      $CYCFLAG[1] = $IN[3]
      N1 = 1
      CONFIRM N1
    """)
    assert res.reason == "completed", (res.reason, res.text, res.line)
    out = [e for e in ev if e["kind"] == "io" and e["signal"] == "$ANOUT[1]"]
    assert [e["value"] for e in out] == pytest.approx([0.2, 0.9])
    assert out[0]["t"] == 0.0 and 0.108 <= out[1]["t"] <= 0.108 + 0.012 + 1e-9


@pytest.mark.parametrize("program", ["N1 = 1\n  N1 = N1 + 2147483647", "N1 = ARR[0]", "N1 = N3"])
def test_errors_are_identical(tmp_path, program):
    res, ev, _ = both(tmp_path, program)
    assert res.reason == "error"
    assert ev[-1]["kind"] == "end" and ev[-1]["line"] == program.count("\n") + 2
