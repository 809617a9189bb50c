"""One node-dispatch helper (krl/ast/visit.py) for every pass over the AST, and no pass without
a handler for a node kind.

The statement and expression kinds come from krl/ast/nodes.py itself: a kind added there and
not handled by the tree interpreter, the compiler, the checker, the printer or the front end's
evaluator fails this test (and the pass fails when it is built, never in the middle of a run).
The two back ends have a handler for each control-flow statement kind only; every other kind
they run from its plan (krl/semantics/statements.py, tests/interp/test_statement_table.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from krl.ast import nodes as N
from krl.ast import printer
from krl.ast.visit import EXPRESSIONS, STATEMENTS, MissingHandler, handlers, node_kinds
from krl.semantics.checker import Checker
from krl.semantics.expression import _Compiler as Evaluator
from krl.semantics.statements import KINDS

from interp.tree.interpreter import TreeInterpreter
from interp.vm.compiler import Compiler

PASSES = {
    "tree interpreter": (TreeInterpreter, "s_", "e_"),
    "compiler": (Compiler, "s_", "e_"),
    "checker": (Checker, "s_", "e_"),
    "printer": (printer, "_s_", "_e_"),
}
#: the passes whose statement handlers are control flow only (the back ends)
BACK_ENDS = {TreeInterpreter, Compiler}


def statement_kinds(owner) -> tuple:
    """The statement kinds ``owner`` has a handler for: every one, or a back end's control flow."""
    return tuple(k for k in STATEMENTS if owner not in BACK_ENDS or KINDS[k].control)


def test_the_kinds_are_every_statement_and_expression_of_the_ast():
    assert N.Assign in STATEMENTS and N.SplineBlock in STATEMENTS and N.Unsupported in STATEMENTS
    assert N.Binary in EXPRESSIONS and N.Aggregate in EXPRESSIONS
    assert not set(STATEMENTS) & set(EXPRESSIONS)
    declared = {c for c in vars(N).values() if isinstance(c, type) and issubclass(c, (N.Stmt, N.Expr))}
    assert declared - {N.Stmt, N.Expr} == set(STATEMENTS) | set(EXPRESSIONS)
    assert node_kinds(N.Decl) and N.VarDecl in node_kinds(N.Decl)


@pytest.mark.parametrize("name", sorted(PASSES))
def test_every_pass_handles_every_kind(name):
    owner, s_prefix, e_prefix = PASSES[name]
    stmts = handlers(owner, s_prefix, statement_kinds(owner))
    exprs = handlers(owner, e_prefix, EXPRESSIONS)
    assert set(stmts) == set(statement_kinds(owner)) and set(exprs) == set(EXPRESSIONS)


def test_the_evaluator_handles_every_expression_kind():
    assert set(handlers(Evaluator, "e_", EXPRESSIONS)) == set(EXPRESSIONS)


@pytest.mark.parametrize("name", sorted(PASSES))
def test_a_kind_without_a_handler_fails_when_the_pass_is_built(name):
    @dataclass(slots=True)
    class Teleport(N.Stmt):
        where: str = ""

    owner, s_prefix, _ = PASSES[name]
    with pytest.raises(MissingHandler, match=f"{s_prefix}Teleport"):
        handlers(owner, s_prefix, statement_kinds(owner) + (Teleport,))
