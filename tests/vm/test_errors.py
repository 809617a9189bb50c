"""Run-time errors: the VM names the same message, number and source line as the tree
interpreter (the assembler's regions are the line table)."""

from __future__ import annotations

import pytest

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
"""

PROGRAMS = {
    "division_by_zero_in_function": "N1 = DIV(1, 0)",
    "function_without_return": "N2 = NORET()",
    "error_deep_in_calls": "DEEP(3)",
    "unknown_routine": "NOSUCH(1)",
    "unknown_name": "N1 = NOSUCHVAR + 1",
    "unset_value": "N1 = N3 + 1",
    "index_out_of_range": "ARR[6] = 1",
    "real_index": "ARR[1.5] = 1",
    "bool_condition": "IF N1 THEN\n    N2 = 1\n  ENDIF",
    "for_step_zero": "FOR N1 = 1 TO 3 STEP 0\n  ENDFOR",
    "while_condition": "WHILE N3 > 0\n  ENDWHILE",
    "on_error_proceed": "ON_ERROR_PROCEED\n  N1 = N3\n  N2 = $ERR.NUMBER\n  N1 = N3",
    "write_protected": "$POS_ACT = {X 1}",
    "stack_overflow": "DEEP(200)",
    "interrupt_not_declared": "INTERRUPT ON 7",
    "goto_into_a_block": "N1 = 0\n  GOTO inside\n  IF N1 == 0 THEN\n  inside:\n    N2 = 1\n  ENDIF",
    "return_without_value": "N1 = BARE()",
    "procedure_in_expression": "N1 = DEEP(0) + 1",
}


@pytest.mark.parametrize("name", list(PROGRAMS))
def test_same_error(tmp_path, name):
    res, ev, _ = both(tmp_path, PROGRAMS[name], extra=EXTRA)
    assert res.reason == "error"
    end = ev[-1]
    assert end["kind"] == "end" and end["text"] and end["line"]
