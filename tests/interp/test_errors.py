"""One test per run-time error: message, number where the reference gives one, line."""

from __future__ import annotations

import pytest

from .helpers import run_krl

DAT = """
DEFDAT prog
  DECL INT N1
  DECL INT A3[3]
ENDDAT
"""

CASES = [
    ("value_invalid", "DECL INT u\n  N1 = u + 1", 1422, "value invalid"),
    ("uninit_component", "DECL FRAME f\n  f.X = 1\n  N1 = f.Y", 1422, "value invalid"),
    ("omitted_argument", "Take( , 2)", 1422, "value invalid"),
    ("div_zero_int", "N1 = 0\n  N1 = 5 / N1", None, "division by zero"),
    ("div_zero_real", "N1 = 0\n  N1 = 5.0 / N1", None, "division by zero"),
    ("int_overflow", "N1 = 2147483647\n  N1 = N1 + 1", None, "INT overflow"),
    ("array_index", "N1 = 4\n  A3[N1] = 1", None, "array index"),
    ("sqrt_negative", "N1 = SQRT(-4)", None, "SQRT"),
    ("acos_range", "N1 = ACOS(2)", None, "ACOS"),
    ("no_return", "N1 = NoRet()", None, "without RETURN"),
    ("unknown_routine", "Nowhere()", None, "not found"),
    ("interrupt_not_declared", "INTERRUPT ON 77", 1430, "not declared"),
    ("resume_outside", "RESUME", None, "RESUME outside"),
    ("recursion", "Rec()", None, "stack overflow"),
    ("unreachable", "PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}\n  LIN {X 3000, Y 0, Z 3000}", None, "workspace"),
    ("soft_limit", "PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}\n  PTP {A1 200}", None, "software limit"),
    ("pos_int_outside_interrupt", "DECL E6POS p\n  p = $POS_INT", 1422, "value invalid"),
    ("write_protected", "$POS_ACT.X = 1", 1388, "write-protected"),
]

SUBS = """
DEF Take(a :IN, b :IN)
  DECL INT a, b
  N1 = a + b
END
DEFFCT INT NoRet()
  N1 = 1
ENDFCT
DEF Rec()
  Rec()
END
"""


@pytest.mark.parametrize("name,body,number,text", CASES, ids=[c[0] for c in CASES])
def test_runtime_error(tmp_path, name, body, number, text):
    lines = body.split("\n")
    src = "DEF prog()\n  " + "\n".join(lines) + "\nEND\n" + SUBS
    r = run_krl(tmp_path, src, DAT)
    assert r.result.reason == "error", r.result
    assert r.result.exit_code == 1
    err = r.result.error
    assert text in err.message
    assert err.number == number
    if name not in ("omitted_argument", "no_return", "recursion"):
        assert r.result.line == len(lines) + 1          # the failing statement's line
    end = r.kinds("end")[-1]
    assert end["reason"] == "error" and end["line"] == r.result.line and text in end["text"]


def test_motion_in_submit_is_an_error_of_the_submit_only(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      WAIT SEC 0.1
      N1 = 1
    END
    """, DAT, files={"bad.sub": "DEF bad()\n  PTP {A1 0}\nEND\n"}, submit=["bad.sub"])
    assert r.result.reason == "completed"
    errs = r.kinds("error")
    assert errs and "submit" in errs[0]["text"] and "not allowed" in errs[0]["text"]
