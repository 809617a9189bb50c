"""Every expression the parser accepts is checked, printed, pickled and compared without a
recursion error (krl/limits.py: MAX_EXPRESSION_TERMS terms in one statement, MAX_NESTING levels
of blocks, brackets and prefix operators). A left-associative chain of 500 terms nests 499
levels in ``Binary.left``; the builder, the checker, the printer and the AST's pickling walk it
in a loop, so only brackets and prefix operators (bounded by MAX_NESTING) recurse.

Expected types and AST shapes are derived by hand from the reference (4.1: operators associate
to the left; AND binds tighter than OR; an INT and a REAL operand give REAL)."""

from __future__ import annotations

import json
import pickle
import sys

import pytest

from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.ast.printer import print_module
from krl.limits import MAX_CHECK_FRAMES, MAX_EXPRESSION_TERMS, MAX_NESTING
from krl.semantics import types as T
from app.check import run_check
from krl.diagnostics import DiagnosticSink
from krl.syntax.parse import parse_text
from krl.workspace import check_texts

TERMS = MAX_EXPRESSION_TERMS              # 500: the longest chain the parser accepts
DEEP = MAX_NESTING                         # 100: the deepest nesting the parser accepts


def chain(op: str, operands: list[str]) -> str:
    return f" {op} ".join(operands)


# (name, declared type, expression, expected type)
CASES = [
    ("sum", "INT", chain("+", ["1"] * TERMS), T.INT),
    ("product", "INT", chain("*", ["2"] * 20 + ["1"] * (TERMS - 20)), T.INT),
    ("difference", "INT", chain("-", ["1000"] + ["1"] * (TERMS - 1)), T.INT),
    ("real_sum", "REAL", chain("+", ["0.5"] + ["1"] * (TERMS - 1)), T.REAL),
    ("products_in_a_sum", "INT", chain("+", ["2 * 3"] * ((TERMS - 1) // 2) + ["1"]), T.INT),
    ("and_chain", "BOOL", chain("AND", ["TRUE"] * (TERMS - 1) + ["FALSE"]), T.BOOL),
    ("and_below_or", "BOOL", "TRUE OR " + chain("AND", ["TRUE"] * (TERMS - 2) + ["FALSE"]), T.BOOL),
    ("or_of_ands", "BOOL", chain("OR", ["FALSE AND TRUE"] * ((TERMS - 1) // 2) + ["TRUE"]), T.BOOL),
    # comparisons bind loosest (4.1): each needs its brackets inside an AND chain
    ("comparisons", "BOOL", chain("AND", ["(1 < 2)"] * ((TERMS - 1) // 2)) + " AND TRUE", T.BOOL),
    ("parenthesised", "INT", "(" * DEEP + chain("+", ["1"] * TERMS) + ")" * DEEP, T.INT),
    ("right_nested", "INT", "1 - (" * DEEP + chain("+", ["1"] * (TERMS - DEEP)) + ")" * DEEP, T.INT),
    ("not_chain", "BOOL", "NOT " * DEEP + "TRUE", T.BOOL),
    ("minus_chain", "INT", "-(" * (DEEP // 2) + "7" + ")" * (DEEP // 2), T.INT),
]


def program(name: str, typ: str, expr: str, ifs: int = 0) -> str:
    opened = "".join(f"IF TRUE THEN\n" for _ in range(ifs))
    closed = "".join("ENDIF\n" for _ in range(ifs))
    return f"DEF {name}()\nDECL {typ} x\n{opened}x = {expr}\n{closed}END\n"


def terms_of(expr: str) -> int:
    ops = [" + ", " - ", " * ", " AND ", " OR ", " < "]
    return 1 + sum(expr.count(o) for o in ops)


def assignment(ws):
    [f] = ws.files
    node = f.module.routines[0].body[0]
    while isinstance(node, N.If):
        node = node.then[0]
    assert isinstance(node, N.Assign)
    return node


@pytest.mark.parametrize("name, typ, expr, want", CASES, ids=[c[0] for c in CASES])
def test_legal_expression_checks_with_its_type(name, typ, expr, want):
    assert terms_of(expr) <= MAX_EXPRESSION_TERMS
    ws = check_texts({f"{name}.src": program(name, typ, expr)})
    assert [str(d) for d in ws.diagnostics] == []
    value = assignment(ws).value
    assert N.type_of(value) == want
    # every operator of the chain is typed, not only the top one
    untyped = [n for n in value.walk() if isinstance(n, N.Expr) and N.type_of(n) is None]
    assert untyped == []


def test_longest_chain_at_the_deepest_block_nesting():
    # blocks and brackets share the budget: 60 IFs and 40 brackets around 500 terms
    ifs, parens = DEEP - 40, 40
    expr = "(" * parens + chain("+", ["1"] * TERMS) + ")" * parens
    ws = check_texts({"deep.src": program("deep", "INT", expr, ifs=ifs)})
    assert [str(d) for d in ws.diagnostics] == []
    assert N.type_of(assignment(ws).value) == T.INT


def test_one_bracket_more_is_e018_not_a_checker_error():
    ws = check_texts({"deep.src": program("deep", "INT", "(" * (DEEP + 1) + "1" + ")" * (DEEP + 1))})
    assert [d.code for d in ws.diagnostics] == ["E018"]


def test_type_errors_inside_a_long_chain_are_reported_once_each():
    # operand 250 is a BOOL: the '+' that takes it and every '+' above it see UNKNOWN, so one E203
    operands = ["1"] * TERMS
    operands[249] = "TRUE"
    ws = check_texts({"bad.src": program("bad", "INT", chain("+", operands))})
    assert [d.code for d in ws.diagnostics] == ["E203"]
    assert "'+' cannot be applied to INT and BOOL" in ws.diagnostics[0].message


def _built(text: str, path: str = "t.src") -> N.Module:
    result = parse_text(text, path)
    assert result.ok
    sink = DiagnosticSink()
    module = build_module(result, sink)
    assert sink.items == []
    return module


def test_builder_makes_a_left_nested_chain():
    module = _built(program("t", "INT", chain("-", [str(i) for i in range(1, TERMS + 1)])))
    value = module.routines[0].body[0].value
    left, ops = N.left_chain(value)
    assert len(ops) == TERMS - 1 and all(b.op == "-" for b in ops)
    assert left == N.IntLit(1)
    assert [b.right.value for b in ops] == list(range(2, TERMS + 1))     # (((1 - 2) - 3) - ...)


@pytest.mark.parametrize("name, typ, expr, want", CASES, ids=[c[0] for c in CASES])
def test_print_parse_pickle_and_compare_round_trip(name, typ, expr, want):
    module = _built(program(name, typ, expr))
    again = _built(print_module(module))
    assert again == module
    assert pickle.loads(pickle.dumps(module)) == module
    # equality is not blind: change the innermost operand
    changed = pickle.loads(pickle.dumps(module))
    node = changed.routines[0].body[0].value
    while isinstance(node, (N.Binary, N.Unary)):
        parent, node = node, node.left if isinstance(node, N.Binary) else node.operand
    if isinstance(parent, N.Binary):
        parent.left = N.IntLit(12345)
    else:
        parent.operand = N.IntLit(12345)
    assert changed != module


def test_check_command_with_worker_processes(tmp_path):
    # krl check parses in worker processes and pickles each file's AST back
    for name, typ, expr, _want in CASES:
        (tmp_path / f"{name}.src").write_text(program(name, typ, expr))
    out: list[str] = []
    status = run_check([str(tmp_path)], fmt="json", echo=out.append, timeout=60, jobs=2)
    [ws] = [json.loads(line) for line in out]
    assert ws["files"] == len(CASES)
    assert ws["diagnostics"] == []
    assert status == 0


DEEPEST = [
    ("sum", 0, "INT", chain("+", ["1"] * TERMS)),
    ("brackets", 0, "INT", "(" * DEEP + chain("+", ["1"] * TERMS) + ")" * DEEP),
    ("right_nested", 0, "INT", "1 - (" * DEEP + chain("+", ["1"] * (TERMS - DEEP)) + ")" * DEEP),
    ("ifs", DEEP, "INT", "1 + 1"),
    ("ifs_and_brackets", DEEP // 2, "INT", "(" * (DEEP // 2) + chain("+", ["1"] * TERMS) + ")" * (DEEP // 2)),
    ("ifs_and_not", DEEP - 20, "BOOL", "NOT " * 20 + "TRUE"),
]


@pytest.mark.parametrize("name, ifs, typ, expr", DEEPEST, ids=[c[0] for c in DEEPEST])
def test_deepest_legal_files_check_within_the_stack_budget(name, ifs, typ, expr):
    # krl/limits.py MAX_CHECK_FRAMES: parse, build and check need at most that many frames
    # above the caller, whatever the chain's length (the old checker recursed per operator)
    assert MAX_CHECK_FRAMES + 300 <= 1000     # room for the caller under Python's default limit
    src = program(name, typ, expr, ifs=ifs)
    old = sys.getrecursionlimit()
    sys.setrecursionlimit(len(_frames()) + MAX_CHECK_FRAMES)
    try:
        ws = check_texts({f"{name}.src": src})
    finally:
        sys.setrecursionlimit(old)
    assert [str(d) for d in ws.diagnostics] == []
    assert N.type_of(assignment(ws).value) == getattr(T, typ)


def _frames() -> list:
    out, f = [], sys._getframe()
    while f is not None:
        out.append(f)
        f = f.f_back
    return out
