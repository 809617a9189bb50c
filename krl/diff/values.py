"""Values of data-list declarations, flattened for comparison (reference 1.5, 2.5, 3.9).

An initial value becomes a mapping of component path to scalar: ``{X 1.5, CM {X 2}}`` ->
``{"X": 1.5, "CM.X": 2.0}``; a plain value is the mapping ``{"": value}``. Scalars are
numbers (INT and REAL literals, with a leading sign), booleans, strings, ``#ENUM`` words
(upper-case) and, for anything else, the AST's case-folded structure (krl/ast/compare.py),
so two spellings of one value compare equal and nothing is ever evaluated.
"""

from __future__ import annotations

from krl.ast import nodes as N
from krl.ast.compare import structure

__all__ = ["POINT_TYPES", "CARTESIAN", "flatten", "number", "data_items"]

# the point types of a data list (reference 3.7: POS, E6POS, AXIS, E6AXIS, FRAME)
POINT_TYPES = frozenset({"E6POS", "E6AXIS", "POS", "AXIS", "FRAME"})
# cartesian types: X Y Z in mm, A B C in degrees (their differences wrap into -180..180)
CARTESIAN = frozenset({"E6POS", "POS", "FRAME"})


def number(e: N.Expr | None) -> float | int | None:
    """The value of an INT/REAL literal with an optional sign, else None."""
    sign = 1
    while isinstance(e, N.Unary) and e.op in ("-", "+"):
        sign = -sign if e.op == "-" else sign
        e = e.operand
    if isinstance(e, (N.IntLit, N.RealLit)):
        return sign * e.value
    return None


def _scalar(e: N.Expr):
    n = number(e)
    if n is not None:
        return n
    if isinstance(e, N.BoolLit):
        return e.value
    if isinstance(e, N.StrLit):
        return e.value
    if isinstance(e, N.EnumLit):
        return "#" + e.name.upper()
    if isinstance(e, N.Name):
        return e.name.upper()
    return repr(structure(e, fold_case=True))


def flatten(e: N.Expr | None) -> dict[str, object]:
    """``{component path: scalar}`` of an initial value (see the module docstring); nested
    aggregates are walked with a work list (no recursion)."""
    out: dict[str, object] = {}
    if e is None:
        return out
    work: list[tuple[str, N.Expr]] = [("", e)]
    while work:
        prefix, v = work.pop()
        if isinstance(v, N.Aggregate):
            for item in reversed(v.items):
                key = item.name.upper() + ("[]" if item.array else "")
                work.append((f"{prefix}.{key}" if prefix else key, item.value))
        else:
            out[prefix] = _scalar(v)
    return dict(sorted(out.items()))


def data_items(dl: N.DataList) -> list[tuple[str, str, N.Expr, N.Node]]:
    """(NAME, TYPE, value, node) of every declaration with a value in a data list: ``DECL T
    NAME = value`` and ``NAME[i, j] = value`` (named ``NAME[i,j]``, with the type its DECL gives).
    Names and types upper-case."""
    types: dict[str, str] = {}
    out = []
    for d in dl.items:
        if isinstance(d, N.VarDecl):
            for v in d.names:
                types[v.name.upper()] = d.type.name.upper()
            if d.init is not None:
                for v in d.names:
                    out.append((v.name.upper(), d.type.name.upper(), d.init, d))
        elif isinstance(d, N.ArrayInit):
            idx = ",".join("" if i is None else str(i) for i in d.indices)
            out.append((f"{d.name.upper()}[{idx}]", types.get(d.name.upper(), ""), d.value, d))
    return out
