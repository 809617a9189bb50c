"""Run-time errors: the VM names the same message, number and source line as the tree
interpreter (the assembler's regions are the line table), and that error is the one the case
is about: its kind (a message pattern) and its line, worked out by hand from the program (line 1
is ``DEF prog()``, the body starts on line 2; EXTRA's routines follow END on line 3 + body)."""

from __future__ import annotations

import json
import re
import weakref

import pytest

from interp.cli import run
from robot.errors import RobotError
from robot.monitor import Monitor
from click.testing import CliRunner

from .test_statements import both

EXTRA = """
DEFFCT INT DIV(a:IN, b:IN)
  DECL INT a, b
  RETURN a / b
ENDFCT

DEFFCT INT NORET()
  N1 = 1
ENDFCT

DEFFCT INT BARE()
  RETURN
ENDFCT

DEF DEEP(n:IN)
  DECL INT n
  IF n > 0 THEN
    DEEP(n - 1)
  ELSE
    N1 = ARR[n]
  ENDIF
END

DEF NOP()
  N2 = 2
END

DEF SETOV(v:OUT)
  DECL INT v
  v = 250
END
"""
# EXTRA's line numbers, counted from its first routine: DIV's RETURN is its line 4, NORET's
# ENDFCT its line 9, BARE's RETURN its line 12, DEEP's `N1 = ARR[n]` its line 20, SETOV's
# `v = 250` its line 30.
EXTRA_LINE = {"div_return": 4, "noret_end": 9, "bare_return": 12, "deep_index": 20, "setov": 30}

# name -> (program body, message pattern, line within the body (1 = first body line) or
#          ("extra", key) for a line of EXTRA)
PROGRAMS = {
    "division_by_zero_in_function": ("N1 = DIV(1, 0)", r"division by zero", ("extra", "div_return")),
    "function_without_return": ("N2 = NORET()", r"NORET ended without RETURN", ("extra", "noret_end")),
    "error_deep_in_calls": ("DEEP(3)", r"array index inadmissible: ARR\[0\]", ("extra", "deep_index")),
    "unknown_routine": ("NOSUCH(1)", r"routine NOSUCH not found", 1),
    "unknown_name": ("N1 = NOSUCHVAR + 1", r"unknown name NOSUCHVAR", 1),
    "unset_value": ("N1 = N3 + 1", r"value invalid: N3", 1),
    "index_out_of_range": ("ARR[6] = 1", r"array index inadmissible: ARR\[6\]", 1),
    "real_index": ("ARR[1.5] = 1", r"array index is not an INT", 1),
    "bool_condition": ("N1 = 1\n  IF N1 THEN\n    N2 = 1\n  ENDIF", r"condition is not BOOL", 2),
    "for_step_zero": ("FOR N1 = 1 TO 3 STEP 0\n  ENDFOR", r"FOR with STEP 0", 1),
    "while_condition": ("WHILE N3 > 0\n  ENDWHILE", r"value invalid: N3", 1),
    "on_error_proceed": ("ON_ERROR_PROCEED\n  N1 = N3\n  N2 = $ERR.NUMBER\n  N1 = N3", r"value invalid: N3", 4),
    "write_protected": ("$POS_ACT = {X 1}", r"\$POS_ACT is write-protected", 1),
    "stack_overflow": ("DEEP(200)", r"stack overflow", ("extra", "deep_recursion")),
    "interrupt_not_declared": ("INTERRUPT ON 7", r"interrupt 7 not declared", 1),
    "goto_into_a_block": ("N1 = 0\n  GOTO inside\n  IF N1 == 0 THEN\n  inside:\n    N2 = 1\n  ENDIF",
                          r"GOTO INSIDE: label not found", 2),
    "return_without_value": ("N1 = BARE()", r"RETURN without a value in function BARE", ("extra", "bare_return")),
    "procedure_in_expression": ("N1 = NOP() + 1", r"NOP does not return a value", 1),
    # the write rules (interp/runtime/writerules.py, issue 61): $OV_PRO = 1000 was kept, and A1
    # then moved at 123 % of its maximum speed
    "override_out_of_range": ("N1 = 5\n  $OV_PRO = N1 * 200",
                              r"value assignment inadmissible: \$OV_PRO = 1000 out of limits \[0; 100\]", 2),
    "override_below_range": ("$OV_PRO = -5", r"value assignment inadmissible: \$OV_PRO = -5 out of limits", 1),
    "advance_out_of_range": ("$ADVANCE = 6", r"value assignment inadmissible: \$ADVANCE = 6 out of limits \[0; 5\]", 1),
    "override_through_out_parameter": ("SETOV($OV_PRO)", r"value assignment inadmissible: \$OV_PRO = 250",
                                       ("extra", "setov")),
    # a signal of the safety controller (the checker's E501 stops such a program before it
    # starts; unchecked, the statement does)
    "safety_signal": ("$DRIVES_ON = TRUE", r"\$DRIVES_ON is write-protected \(a signal of the safety controller\)", 1),
}
EXTRA_LINE["deep_recursion"] = 18      # DEEP's recursive call `DEEP(n - 1)`


@pytest.mark.parametrize("name", list(PROGRAMS))
def test_same_error(tmp_path, name):
    body, pattern, where = PROGRAMS[name]
    res, ev, _ = both(tmp_path, body, extra=EXTRA)
    assert res.reason == "error", (res.reason, res.text)
    assert re.search(pattern, res.text), f"{name}: stopped on {res.text!r} (line {res.line})"
    end_of_prog = 3 + body.count("\n")            # the END line of prog
    line = end_of_prog + EXTRA_LINE[where[1]] if isinstance(where, tuple) else 1 + where
    assert res.line == line, f"{name}: error at line {res.line}, expected {line}: {res.text}"
    end = ev[-1]
    assert end["kind"] == "end" and end["line"] == line and re.search(pattern, end["text"])
    # the run-time error is an `error` event right before `end` (robot/trace.py), with the
    # same place, text and KSS number (1422 "value invalid" where the reference gives it)
    error = ev[-2]
    assert error["kind"] == "error", ev[-3:]
    assert (error["line"], error["text"], error.get("number")) == (line, end["text"], end.get("number"))
    assert error["file"].endswith("prog.src")
    if pattern.startswith("value invalid"):
        assert error["number"] == 1422
    if pattern.startswith("value assignment inadmissible"):
        assert error["number"] == 1446
    if "write-protected" in pattern:
        assert error["number"] == 1388
    assert sum(e["kind"] == "error" for e in ev) == 1


def test_error_event_trace_files_are_byte_identical(tmp_path):
    """`krl run --trace` of a program stopped by a run-time error: both interpreters write the
    same bytes, the error event (line 4, division by zero) right before the end event."""
    (tmp_path / "prog.src").write_text("DEF prog()\n  INT i, n\n  n = 0\n  i = 1 / n\nEND\n")
    traces = {}
    for kind in ("tree", "vm"):
        out = tmp_path / f"{kind}.jsonl"
        res = CliRunner().invoke(run, [str(tmp_path / "prog.src"), "--interp", kind, "--trace", str(out)])
        assert res.exit_code == 1, res.output
        traces[kind] = out.read_bytes()
    assert traces["tree"] == traces["vm"]
    events = [json.loads(x) for x in traces["vm"].splitlines()]
    assert [e["kind"] for e in events[-2:]] == ["error", "end"]
    assert (events[-2]["line"], events[-2]["text"]) == (4, "division by zero")


def test_a_main_run_fault_is_one_error_event(tmp_path, monkeypatch):
    """A fault of the main run (here forced in the controller's speed check while the LIN of
    line 4 moves) is written once, by the controller, with the motion's id and line; the
    program then stops with that error and the interpreter does not write it a second time."""
    real = Monitor.check_speed
    cycles: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

    def check(self, q, q_prev):
        k = cycles[self] = cycles.get(self, 0) + 1             # the IPO cycle of this run
        if k > 42:                                              # 0.504 s
            raise RobotError("forced main-run fault")
        return real(self, q, q_prev)

    monkeypatch.setattr(Monitor, "check_speed", check)
    body = ("PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}\n"
            "LIN_REL {Z -100}\n"
            "LIN_REL {Y 100}\n"
            "N1 = 1")
    res, ev, _ = both(tmp_path, body)
    assert res.reason == "error" and res.text == "forced main-run fault"
    errors = [e for e in ev if e["kind"] == "error"]
    assert len(errors) == 1, errors
    assert errors[0]["text"] == "forced main-run fault" and errors[0].get("id") is not None
    assert ev[-1]["kind"] == "end"
