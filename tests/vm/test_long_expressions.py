"""The longest and deepest expressions the parser accepts run alike on both interpreters, with
the value computed by hand (krl/limits.py: MAX_EXPRESSION_TERMS terms, MAX_NESTING levels).

Both interpreters walk a left-nested chain of binary operators in a loop (the tree
interpreter's evaluation; the compiler's constant folding and code generation), left before
right as the operators associate (reference 4.1). Literal chains exercise the VM compiler's
folding, chains of variables the run-time operators."""

from __future__ import annotations

import pytest

from krl.limits import MAX_EXPRESSION_TERMS, MAX_NESTING

from .test_runtime_limits import run_both

TERMS = MAX_EXPRESSION_TERMS      # 500 terms, 499 operators
DEEP = MAX_NESTING                # 100 levels of brackets and prefix operators


def chain(op: str, operands: list[str]) -> str:
    return f" {op} ".join(operands)


# (name, type, expression, value by hand)
CASES = [
    ("sum", "INT", chain("+", ["1"] * TERMS), 500),
    ("sum_of_vars", "INT", chain("+", ["n"] * TERMS), 2 * 500),                       # n = 2
    ("product", "INT", chain("*", ["2"] * 20 + ["1"] * (TERMS - 20)), 2 ** 20),
    ("product_of_vars", "INT", chain("*", ["n"] * 20 + ["1"] * (TERMS - 20)), 2 ** 20),
    # left-associative: ((1000 - 1) - 1) ... = 1000 - 499; right-associative would give 1000 - 0
    ("difference", "INT", chain("-", ["1000"] + ["1"] * (TERMS - 1)), 501),
    ("difference_of_vars", "INT", chain("-", ["1000"] + ["n"] * (TERMS - 1)), 1000 - 2 * 499),
    ("real_sum", "REAL", chain("+", ["0.5"] + ["1"] * (TERMS - 1)), 499.5),
    ("constant_start", "INT", chain("+", ["1"] * 250 + ["n"] + ["1"] * 249), 501),   # 250 + 2 + 249
    # 249 products 2 * 3 and a 1: precedence, * before +
    ("products_in_a_sum", "INT", chain("+", ["2 * 3"] * 249 + ["1"]), 249 * 6 + 1),
    ("and_chain", "BOOL", chain("AND", ["t"] * (TERMS - 1) + ["FALSE"]), False),     # t = TRUE
    # AND binds tighter than OR: TRUE OR (TRUE AND ... AND FALSE) = TRUE; left to right it is FALSE
    ("and_below_or", "BOOL", "TRUE OR " + chain("AND", ["t"] * (TERMS - 2) + ["FALSE"]), True),
    ("or_of_ands", "BOOL", chain("OR", ["FALSE AND t"] * 249 + ["FALSE"]), False),
    ("brackets", "INT", "(" * DEEP + chain("+", ["n"] * (TERMS - 1) + ["1"]) + ")" * DEEP, 2 * 499 + 1),
    # 1 - (1 - (... (1 + ... + 1))): 400 ones inside 100 brackets; f(0) = 400, f(k) = 1 - f(k - 1),
    # so f is 400 for even k and -399 for odd k; k = 100
    ("right_nested", "INT", "1 - (" * DEEP + chain("+", ["1"] * (TERMS - DEEP)) + ")" * DEEP, 400),
    ("not_even", "BOOL", "NOT " * DEEP + "t", True),
    ("not_odd", "BOOL", "NOT " * (DEEP - 1) + "t", False),
    ("minus_even", "INT", "-(" * (DEEP // 2) + "n" + ")" * (DEEP // 2), 2),
    ("minus_odd", "INT", "-(" * (DEEP // 2 - 1) + "7" + ")" * (DEEP // 2 - 1), -7),
]


@pytest.mark.parametrize("name, typ, expr, want", CASES, ids=[c[0] for c in CASES])
def test_longest_and_deepest_expressions_run_alike(tmp_path, name, typ, expr, want):
    src = f"DEF prog()\n  n = 2\n  t = TRUE\n  x = {expr}\nEND\n"
    dat = f"DEFDAT prog\n  DECL INT n\n  DECL BOOL t\n  DECL {typ} x\nENDDAT\n"
    res, _, var = run_both(tmp_path, src, dat)       # traces identical event for event
    assert res.reason == "completed", res.text
    assert var("x") == want
