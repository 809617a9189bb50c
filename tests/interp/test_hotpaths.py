"""The runtime's per-statement paths made faster for the real-programs report (issue 39) keep
their meaning, on both interpreters: an output written with the value it has logs nothing
(robot/io.py logs changes only), a bad output index is still the run-time error at its line,
a SIGNAL group writes only the bits that change, CHAR assignment pads with NUL and truncates
(reference §3.4), and $PRO_STATE1 reads as the enum value of the running program."""

from __future__ import annotations

import pytest

from .helpers import run_krl

DAT = """
DEFDAT prog
  DECL CHAR S[6]
  DECL INT K = 0
  DECL BOOL ACTIVE = FALSE
ENDDAT
"""

PROG = """
DEF prog()
  SIGNAL GRP $OUT[10] TO $OUT[13]
  $OUT[5] = TRUE
  $OUT[5] = TRUE
  $OUT[5] = FALSE
  $OUT[5] = FALSE
  GRP = 5
  GRP = 5
  GRP = 6
  S[] = "ab"
  K = STRLEN(S[])
  S[] = "abcdefgh"
  K = K * 10 + STRLEN(S[])
  ACTIVE = $PRO_STATE1 == #P_ACTIVE
  WAIT SEC 0.012
  $OUT[0] = TRUE
END
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_output_writes_chars_and_program_state(tmp_path, interp):
    run = run_krl(tmp_path, PROG, DAT, interp=interp)
    assert [v for _t, v in run.io("$OUT[5]")] == [True, False]
    # GRP = 5 sets bits 10 and 12; 5 again changes nothing; 6 clears bit 10, sets bit 11
    assert [v for _t, v in run.io("$OUT[10]")] == [True, False]
    assert [v for _t, v in run.io("$OUT[11]")] == [True]
    assert [v for _t, v in run.io("$OUT[12]")] == [True]
    assert run.io("$OUT[13]") == []
    assert run.var("prog", "S").text() == "abcdef"
    assert run.var("prog", "K") == 26
    assert run.var("prog", "ACTIVE") is True
    assert run.result.reason == "error" and run.result.line == 16
    assert run.result.text == "array index 0 outside 1..8192 ($OUT)"
