"""The front end's expression API (krl/semantics/expression.py): parse, check, place, evaluate.

Expected values are worked out by hand from the reference (§4.1 operators and precedence, §3.9
conversions, the decisions of krl/semantics/values.py), not taken from a run.
"""

from __future__ import annotations

import sys

import pytest

from krl.ast import nodes as N
from krl.semantics import expression as X
from krl.semantics import types as T
from krl.semantics.symbols import Scope, Symbol, system_scopes
from krl.semantics.values import EnumValue, KrlRuntimeError

SYSTEM = system_scopes()[0]


def value(text: str, env: X.Env | None = None):
    return X.evaluate(X.parse(text), env)


@pytest.mark.parametrize("text, expected", [
    ("7 / 2", 3),                  # INT / INT truncates toward zero
    ("-7 / 2", -3),
    ("7 / 2.0", 3.5),
    ("2 + 3 * 4", 14),             # * before +
    ("(1 < 2) AND TRUE", True),
    ("1 < 2 == TRUE", True),       # comparisons: one level, the weakest, left first
    ("NOT FALSE EXOR TRUE", False),
    ("'HFF' B_AND 'H0F'", 15),
    ("B_NOT 0", -1),
    ("\"A\" + 1", 66),             # a CHAR takes part in arithmetic as its code
    ("#ON", EnumValue("ON")),
    ("{X 1, Y -2.5}", {"X": 1, "Y": -2.5}),
])
def test_constant_values(text, expected):
    got = value(text)
    assert got == expected and type(got) is type(expected)


@pytest.mark.parametrize("text, message", [
    ("2147483647 + 1", "INT overflow"),
    ("1 / 0", "division by zero"),
    ("TRUE + 1", "BOOL operand where a number is needed"),
    ("#A < #B", "enum values have no order"),
])
def test_run_time_errors_of_operators(text, message):
    with pytest.raises(KrlRuntimeError, match=message):
        value(text)


@pytest.mark.parametrize("text, message, column", [
    ("", "empty expression", 1),
    ("1 +", "not a KRL expression", 4),
    ("a b", "unexpected 'b' after the expression", 3),
    ("x = 1", "not a KRL expression", None),
    ("1\nHALT", "an expression is one line", 1),
    ("1" + "+1" * 600, "more than 500 terms", 1),
    ("1 " * 3000, "at most 4096 characters", 1),
])
def test_parse_refuses_what_is_no_single_expression(text, message, column):
    with pytest.raises(X.ExpressionError) as info:
        X.parse(text)
    assert message in info.value.message
    if column is not None:
        assert info.value.column == column


def test_the_token_limit_is_the_callers():
    X.parse(" OR ".join(["TRUE"] * 50), max_tokens=100)
    with pytest.raises(X.ExpressionError, match="99 tokens, more than the limit of 20"):
        X.parse(" OR ".join(["TRUE"] * 50), max_tokens=20)


def test_check_types_in_a_scope_with_the_checkers_messages():
    scope = Scope("test", "<test>", SYSTEM)
    scope.define("values", Symbol("COUNT", "var", T.INT, "test"))
    scope.define("values", Symbol("READY", "signal", T.BOOL, "test"))
    assert X.check(X.parse("count * 2.5"), scope) == T.REAL
    assert X.check(X.parse("$IN[3] AND ready"), scope) == T.BOOL
    e = X.parse("ready AND count")
    with pytest.raises(X.ExpressionError) as info:
        X.check(e, scope)
    assert info.value.message == "'AND' cannot be applied to BOOL and INT"
    assert info.value.column == 7
    with pytest.raises(X.ExpressionError, match="'nope' is not declared"):
        X.check(X.parse("nope + 1"), scope)
    # the annotations krl check leaves: each name's symbol and type
    e = X.parse("count + 1")
    X.check(e, scope)
    assert N.symbol_of(e.left).name == "COUNT" and N.type_of(e) == T.INT


def test_an_env_reads_variables_and_the_base_env_none():
    class Env(X.Env):
        def __init__(self):
            self.values = {"A": 5, "B": 2.0}
            self.reads = 0

        def name(self, node):
            key = node.name.upper()

            def read():
                self.reads += 1
                return self.values[key]
            return read

    env = Env()
    read = X.compile_expression(X.parse("a * b - a / 2"), env)   # 5 * 2.0 - 5 / 2 = 10.0 - 2
    assert env.reads == 0                                         # compiled, not yet read
    assert read() == 8.0 and env.reads == 3
    env.values["A"] = 7                                           # 7 * 2.0 - 3 = 11.0
    assert read() == 11.0
    with pytest.raises(KrlRuntimeError, match="the variable a is not allowed here"):
        value("a + 1")
    with pytest.raises(KrlRuntimeError, match="a call of f is not allowed here"):
        value("f(1)")


def test_a_long_chain_costs_no_stack():
    text = "+".join(["1"] * 500)
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(200)
    try:
        assert value(text) == 500
    finally:
        sys.setrecursionlimit(limit)
