"""The statement table (krl/semantics/statements.py) is complete, as the opcode table is
(tests/vm/test_opcodes.py): every statement class of the AST has one row; a planned kind has
no hand-written handler in either back end and a runtime entry that takes the operands its
plan gives; a control-flow kind has a handler in both; the compiler emits each planned
statement as its operands and one STATEMENT naming the entry (an assignment: the store
instructions); and the check fails when a row is missing."""

from __future__ import annotations

import inspect
from pathlib import Path

import pytest

from interp.runtime.statements import ENTRIES
from interp.tree.interpreter import TreeInterpreter
from interp.vm.compiler import Compiler
from krl.ast import nodes as N
from krl.ast.visit import STATEMENTS
from krl.semantics import statements as S
from krl.workspace import check_texts

#: one routine with a statement of every planned kind the grammar gives (a declaration after
#: the first statement is a syntax error, E014, and an Unsupported has no source form: built below)
EVERY = """DEF every()
  DECL INT N
  DECL REAL R
  SIGNAL SIG_IN $ANIN[1]
  SIGNAL SIG_OUT $ANOUT[1]
  N = 1
  $CYCFLAG[1] = $IN[1] AND $IN[2]
  WAIT FOR $IN[1]
  WAIT SEC 0.1
  CONTINUE
  ON_ERROR_PROCEED
  INTERRUPT DECL 3 WHEN $IN[2] DO hit(N)
  INTERRUPT DECL 4 WHEN $IN[3] DO BRAKE F
  INTERRUPT ON 3
  INTERRUPT OFF
  BRAKE
  RESUME
  ANIN ON R = 1.0 * SIG_IN
  ANIN OFF SIG_IN
  ANOUT ON SIG_OUT = 0.5 * R MINIMUM=-0.5 MAXIMUM=0.9
  ANOUT OFF SIG_OUT
  TRIGGER WHEN DISTANCE=0 DELAY=10 DO $OUT[1]=TRUE
  TRIGGER WHEN PATH=20 ONSTART DELAY=0 DO hit(N) PRIO=-1
  STOP WHEN PATH = 10 IF $IN[1]
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  SLIN {X 1000, Y 0, Z 900, A 0, B 90, C 0} WITH $VEL.CP = 0.2 C_SPL
  SPLINE WITH $VEL.CP = 0.1
    SPL {X 1000, Y 10, Z 1000, A 0, B 90, C 0}
    TRIGGER WHEN PATH=0 DELAY=0 DO $OUT[2]=TRUE
    SPL {X 1000, Y 20, Z 1000, A 0, B 90, C 0} WITH $VEL.CP = 0.2
  ENDSPLINE
  CONFIRM 1
  MOVE_EMI N "a" KEY 1
  this is not krl at all
END
DEF hit(K:IN)
  INT K
END
"""


@pytest.fixture(scope="module")
def every():
    """The routine EVERY, checked; its statements of each kind (nested ones included)."""
    ws = check_texts({"every.src": EVERY})
    routine = ws.files[0].module.routines[0]
    by_kind: dict = {}
    for n in routine.walk():
        if isinstance(n, N.Stmt):
            by_kind.setdefault(type(n), []).append(n)
    decl = N.DeclStmt(routine.decls[0], span=routine.decls[0].span)
    other = N.Unsupported("someStatement", "SOME STATEMENT", span=routine.body[0].span)
    by_kind[N.DeclStmt] = [decl]
    by_kind[N.Unsupported] = [other]
    return routine, by_kind


def test_every_statement_class_has_one_row():
    assert set(S.KINDS) == set(STATEMENTS)
    for cls, kind in S.KINDS.items():
        if kind.control:
            assert kind.operands is None and not kind.entries, cls
        else:
            assert kind.guard in (S.GUARDED, S.PLAIN, S.BARE) and kind.entries and kind.operands, cls


def test_control_flow_is_the_back_ends_and_nothing_else():
    """A planned kind has no handler of its own in the tree interpreter or the compiler (both
    dispatch it to ``s_planned``); a control-flow kind has one in each."""
    for cls, kind in S.KINDS.items():
        name = "s_" + cls.__name__
        for back_end in (TreeInterpreter, Compiler):
            assert hasattr(back_end, name) == kind.control, (back_end.__name__, name)


def test_every_entry_exists_and_is_used():
    named = {e for kind in S.KINDS.values() for e in kind.entries}
    assert named == set(ENTRIES)


def test_each_plan_fits_its_entry(every):
    """Each planned statement of EVERY: its operands of known kinds, its entry one its row names,
    taking (rt, frame, info) and exactly the plan's operands."""
    _, by_kind = every
    planned = {cls for cls, kind in S.KINDS.items() if not kind.control}
    assert planned <= set(by_kind), planned - set(by_kind)
    for cls in planned:
        for st in by_kind[cls]:
            p = S.plan(st)
            assert p.entry in S.KINDS[cls].entries
            assert all(k in S.OPERANDS for k, _ in p.operands), p
            inspect.signature(ENTRIES[p.entry]).bind(None, None, None, *[None] * len(p.operands))
            with pytest.raises(TypeError):
                inspect.signature(ENTRIES[p.entry]).bind(None, None, None, *[None] * (len(p.operands) + 1))


def test_a_control_kind_has_no_plan(every):
    _, by_kind = every
    with pytest.raises(KeyError):
        S.plan(by_kind[N.CallStmt][0])


def test_the_compiler_calls_the_entry_with_the_plans_operands(every):
    """The listing of EVERY holds one STATEMENT per planned statement that is not a plain
    assignment, naming its plan's entry with as many operands, in source order."""
    routine, by_kind = every
    lst = Compiler(routine).compile()
    got = [(ops[0], ops[1]) for name, ops, _ in lst.instrs if name == "STATEMENT"]
    want = []
    for st in routine.body:
        inner = [s for s in st.body if not isinstance(s, N.Motion)] if isinstance(st, N.SplineBlock) else []
        for s in inner + [st]:          # a SPLINE block's TRIGGERs are compiled before its STATEMENT
            p = S.plan(s)
            if p.entry != "assign":
                want.append((p.entry, len(p.operands)))
    # the thunks (a TRIGGER's assignment action) come after the routine's END, in the order
    # of their statements: compare as multisets, then the routine's body in order
    assert sorted(got) == sorted(want)
    assert got[:3] == [("cyclic_assign", 3), ("wait_for", 1), ("wait_sec", 1)]


def test_the_check_fails_without_a_row(monkeypatch):
    """The table check can fail: a statement class without a row is found."""
    monkeypatch.delitem(S.KINDS, N.WaitSec)
    with pytest.raises(AssertionError):
        test_every_statement_class_has_one_row()


def test_the_doc_says_where_to_add_one():
    text = (Path(__file__).parents[2] / "docs" / "architecture.md").read_text(encoding="utf-8")
    assert "### Statements: where to add one" in text
