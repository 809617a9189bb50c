"""The shared call protocol (interp/runtime/calls.py ``Calls.run_routine``, ``FramePlan``) keeps its
meaning on both interpreters: every activation gets fresh locals (a recursive function's local
array of nested structures is its own), a local passed to an :OUT parameter is changed in place,
an :IN structure is a copy, a function's value is converted to its return type (§2.4: a REAL
rounded to INT, an INT made REAL), and a local read before it is set stops the program at its
line, the same in both. The values below are worked out by hand from the program text."""

from __future__ import annotations

import pytest

from krl.semantics import types as T
from interp.runtime.values import UNSET, Arr, Struct, make_value, maker

from .helpers import run_krl

DAT = """
DEFDAT prog
  STRUC INNER REAL A, B
  STRUC OUTER INT N, INNER IN1, CHAR TAG[3]
  DECL INT DEPTHSUM = 0
  DECL INT NKEEP = 0
  DECL INT I1 = 0
  DECL REAL R1 = 0.0
  DECL REAL R2 = 0.0
ENDDAT
"""

PROG = """
DEF prog()
  DECL OUTER o
  o.N = 5
  o.IN1.A = 1.5
  FILL(o)
  R1 = o.IN1.A + o.IN1.B
  MODIN(o)
  NKEEP = o.N
  DEPTHSUM = REC(3)
  I1 = ROUND2(2.6)
  R2 = HALF(3)
  NKEEP = NKEEP + BAD()
END

DEF FILL(x:OUT)
  DECL OUTER x
  x.IN1.B = 2.5
END

DEF MODIN(y:IN)
  DECL OUTER y
  y.N = 99
  y.IN1.A = 7.0
END

DEFFCT INT REC(n:IN)
  DECL INT n
  DECL OUTER loc[2]
  DECL INT r
  loc[1].N = n
  IF n > 0 THEN
    r = REC(n - 1)
  ELSE
    r = 0
  ENDIF
  RETURN r + loc[1].N
ENDFCT

DEFFCT INT ROUND2(x:IN)
  DECL REAL x
  RETURN x
ENDFCT

DEFFCT REAL HALF(k:IN)
  DECL INT k
  RETURN k / 2
ENDFCT

DEFFCT INT BAD()
  DECL OUTER q
  q.IN1.A = 1.0
  RETURN q.N
ENDFCT
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_activations_parameters_and_return_values(tmp_path, interp):
    run = run_krl(tmp_path, PROG, DAT, interp=interp)
    assert run.var("prog", "R1") == 4.0            # 1.5 + 2.5: FILL wrote into o itself
    assert run.var("prog", "NKEEP") == 5              # MODIN changed its copy only
    assert run.var("prog", "DEPTHSUM") == 6        # 3 + 2 + 1 + 0: each activation's own loc
    assert run.var("prog", "I1") == 3              # 2.6 as INT
    r2 = run.var("prog", "R2")
    assert r2 == 1.0 and r2.__class__ is float     # 3 / 2 = 1 (INT division), as REAL
    # q.N was never set: the run stops in BAD at its RETURN (line 52)
    assert run.result.reason == "error" and run.result.line == 52
    assert run.result.text == "value invalid: q.N"


def test_both_interpreters_stop_alike(tmp_path):
    a = run_krl(tmp_path, PROG, DAT, interp="tree")
    b = run_krl(tmp_path, PROG, DAT, interp="vm")
    assert (a.result.reason, a.result.line, a.result.text) == (b.result.reason, b.result.line, b.result.text)


def test_makers_give_fresh_values_in_the_type_order():
    inner = T.Struc("INNER", {"A": (None, T.REAL), "B": (None, T.REAL)})
    outer = T.Struc("OUTER", {"N": (None, T.INT), "IN1": (None, inner),
                              "TAG": (None, T.Array(T.CHAR, (3,)))})
    arr = T.Array(outer, (2,))
    make = maker(arr)
    v, w = make(), make()
    assert isinstance(v, Arr) and v.dims == (2,) and len(v.data) == 2
    first = v.data[0]
    assert isinstance(first, Struct) and list(first.f) == ["N", "IN1", "TAG"]
    assert first.f["N"] is UNSET and list(first.f["IN1"].f.items()) == [("A", UNSET), ("B", UNSET)]
    assert first.f["TAG"].data == [UNSET, UNSET, UNSET]
    # nothing is shared: between the elements of one value, nor between two values
    first.f["IN1"].f["A"] = 1.0
    first.f["TAG"].data[0] = "x"
    assert v.data[1].f["IN1"].f["A"] is UNSET and w.data[0].f["IN1"].f["A"] is UNSET
    assert v.data[1].f["TAG"].data[0] is UNSET and w.data[0].f["TAG"].data[0] is UNSET
    # make_value gives the same shape
    u = make_value(arr)
    assert [list(s.f) for s in u.data] == [["N", "IN1", "TAG"]] * 2
    assert maker(T.INT)() is UNSET
