"""Data-list values, typed and flattened for comparison (reference 1.5, 3.1-3.9).

:func:`data_values` lists every value a data list gives (``DECL T NAME = value``,
``NAME[i,j] = value``) as a :class:`DataValue`: the variable (name as written, declared type)
and its *leaves*, one per scalar -- ``{VEL 100, APO_DIST 500}`` of ``PPDAT13`` gives the leaves
``VEL`` and ``APO_DIST``; a plain value is the one leaf ``""``. A leaf is a :class:`Leaf` with
the type the declaration gives it (the checker's types, krl/semantics/types.py: the declared
type of the variable, the component types of its STRUC), so that :func:`same` compares

* REAL by number: equal when equal as 32-bit floats (KRL's REAL, so ``87.03`` and the
  controller's re-saved ``87.0299988`` are one value) or within the tolerance;
* INT, BOOL exactly; ENUM values by name, letter case ignored (``#cdis`` is ``#CDIS``);
* STRING (a CHAR array's text) exactly, letter case included;
* any other expression by its AST with names case-folded (krl/ast/compare.py): nothing is
  ever evaluated.

Every text a leaf shows is KRL as written in the file (the literal's own text, read at its
span; else the pretty-printer's KRL, krl/ast/printer.py), never a Python representation.
Nested aggregates are walked with a work list (no recursion).
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.ast import printer
from krl.ast.compare import structure
from krl.semantics import types as T

__all__ = ["POINT_TYPES", "CARTESIAN", "DataValue", "Leaf", "data_values", "number", "same", "real32"]

# the point types of a data list (reference 3.7: POS, E6POS, AXIS, E6AXIS, FRAME, E3POS, E3AXIS)
POINT_TYPES = frozenset({"E6POS", "E6AXIS", "POS", "AXIS", "FRAME", "E3POS", "E3AXIS"})
# cartesian types: X Y Z in mm, A B C in degrees (their differences wrap into -180..180)
CARTESIAN = frozenset({"E6POS", "POS", "FRAME", "E3POS"})

# the text of a literal at its span: a number with its sign, a string, an enum value, a boolean
_LITERAL = re.compile(r"""[-+]?\s*(?:'[HhBb][0-9A-Fa-f]+'|(?:\d+\.?\d*|\.\d+)(?:[Ee][-+]?\d+)?)"""
                      r"""|"[^"\r\n]*"|\#\s*[A-Za-z_$][A-Za-z0-9_$]*|[A-Za-z_$][A-Za-z0-9_$]*""")


@dataclass
class Leaf:
    """One scalar of a value. ``path``: the component path as written (``CM.X``,
    ``POINT2[]``; "" for a plain value); ``kind``: REAL, INT, BOOL, CHAR, STRING, ENUM or
    ``expression``; ``type``: the declared type's name (``APO_MODE_T`` for an ENUM); ``value``:
    the number (REAL, INT), bool, string, or the ENUM name as written; ``key``: what is
    compared for every kind but REAL; ``text``: the KRL text as written; ``line``."""
    path: str
    kind: str
    type: str
    value: object
    key: object
    text: str
    line: int


@dataclass
class DataValue:
    """A variable (or array element ``NAME[i]``) with a value in a data list: ``name`` as
    written, ``type`` the declared (element) type's name as written, ``leaves`` by upper-case
    path in source order, ``node`` the declaration, ``text`` the whole value as written."""
    name: str
    type: str
    node: N.Node
    text: str
    leaves: dict[str, Leaf] = field(default_factory=dict)

    @property
    def line(self) -> int:
        return self.node.span.line


def number(e: N.Expr | None) -> float | int | None:
    """The value of an INT/REAL literal with an optional sign, else None."""
    sign = 1
    while isinstance(e, N.Unary) and e.op in ("-", "+"):
        sign = -sign if e.op == "-" else sign
        e = e.operand
    if isinstance(e, (N.IntLit, N.RealLit)):
        return sign * e.value
    return None


def real32(x: float) -> float:
    """`x` rounded to a 32-bit float (KRL's REAL); out-of-range values stay as they are."""
    try:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    except (OverflowError, struct.error):
        return x


def same(a: Leaf, b: Leaf, tolerance: float = 0.0) -> bool:
    """Whether two leaves hold one value (see the module docstring)."""
    if a.kind == "REAL" or b.kind == "REAL":
        if isinstance(a.value, (int, float)) and isinstance(b.value, (int, float)) \
                and not isinstance(a.value, bool) and not isinstance(b.value, bool):
            return real32(a.value) == real32(b.value) or abs(b.value - a.value) <= tolerance
    return (a.kind, a.key) == (b.kind, b.key)


def _type_name(t: T.KrlType | None) -> str:
    if t is None or t is T.UNKNOWN:
        return ""
    if isinstance(t, T.Array):
        return _type_name(t.elem)
    return t.name


def _kind_of(t: T.KrlType | None) -> str:
    """REAL, INT, BOOL, CHAR, STRING (a CHAR array), ENUM, or "" when the type does not say."""
    if isinstance(t, T.Array):
        return "STRING" if t.elem == T.CHAR else ""
    if isinstance(t, T.Simple):
        return t.name
    if isinstance(t, T.Enum):
        return "ENUM"
    return ""


def _component(t: T.KrlType | None, name: str) -> T.KrlType | None:
    if isinstance(t, T.Array):
        t = t.elem
    if isinstance(t, T.Struc):
        f = t.fields.get(name.upper())
        return f[1] if f is not None else None
    return None


def _written(lines: list[str], e: N.Expr) -> str | None:
    """The literal's text at its span, when the span is in `lines` and a literal is there."""
    ln, col = e.span.line, e.span.column
    if not (0 < ln <= len(lines)) or col <= 0:
        return None
    m = _LITERAL.match(lines[ln - 1], col - 1)
    return m.group(0).replace(" ", "").replace("\t", "") if m else None


def _leaf(path: str, e: N.Expr, t: T.KrlType | None, lines: list[str]) -> Leaf:
    kind, tname = _kind_of(t), _type_name(t)
    n = number(e)
    text = None
    if n is not None and not isinstance(n, bool):
        if kind not in ("REAL", "INT", "CHAR"):
            kind = "REAL" if isinstance(_base_literal(e), N.RealLit) else "INT"
        value: object = float(n) if kind == "REAL" else n
        key: object = value
        text = _written(lines, e)
    elif isinstance(e, N.BoolLit):
        kind, value, key = "BOOL", e.value, e.value
        text = _written(lines, e)
    elif isinstance(e, N.StrLit):
        kind, value, key = "STRING" if kind != "CHAR" else "CHAR", e.value, e.value
    elif isinstance(e, N.EnumLit):
        kind, value, key = "ENUM", e.name, e.name.upper()
        text = _written(lines, e)
    else:
        kind, value, key = "expression", None, structure(e, fold_case=True)
    if kind == "expression" or not tname:
        tname = tname or ("" if kind == "expression" else kind)
    if text is None or (kind in ("REAL", "INT") and number_text(text) != n):
        text = printer.expr(e)
    if kind != "expression" and value is None:
        value = text
    return Leaf(path, kind, tname, value, key, text, e.span.line)


def number_text(text: str) -> float | int | None:
    """The number a literal's text gives (for checking a span's text), else None."""
    t = text.replace(" ", "")
    try:
        if t.lstrip("+-").startswith("'"):
            body = t.lstrip("+-").strip("'")
            v = int(body[1:], 16 if body[0] in "Hh" else 2)
            return -v if t.startswith("-") else v
        return float(t) if any(c in t for c in ".eE") else int(t)
    except (ValueError, IndexError):
        return None


def value_text(lines: list[str], node: N.Node) -> str | None:
    """The text after the first ``=`` of the declaration's line (outside strings, without a
    comment), as written; None when the line has none."""
    ln = node.span.line
    if not 0 < ln <= len(lines):
        return None
    line, quoted, start = lines[ln - 1], False, None
    for i, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif ch == "=" and not quoted and start is None:
            start = i + 1
        elif ch == ";" and not quoted:
            line = line[:i]
            break
    return line[start:].strip() or None if start is not None else None


def _base_literal(e: N.Expr) -> N.Expr:
    while isinstance(e, N.Unary):
        e = e.operand
    return e


def leaves(e: N.Expr | None, t: T.KrlType | None, lines: list[str]) -> dict[str, Leaf]:
    """{UPPER path: Leaf} of an initial value of type `t` (None when not known), in source
    order; `lines` are the file's lines (for the literals' text)."""
    out: dict[str, Leaf] = {}
    if e is None:
        return out
    work: list[tuple[str, str, N.Expr, T.KrlType | None]] = [("", "", e, t)]
    while work:
        key, path, v, vt = work.pop()
        if isinstance(v, N.Aggregate):
            for item in reversed(v.items):
                suffix = "[]" if item.array else ""
                ik = f"{key}.{item.name.upper()}{suffix}" if key else item.name.upper() + suffix
                ip = f"{path}.{item.name}{suffix}" if path else item.name + suffix
                work.append((ik, ip, item.value, _component(vt, item.name)))
        else:
            out.setdefault(key, _leaf(path, v, vt, lines))
    return out


def _decl_type(d: N.VarDecl, v: N.VarName) -> T.KrlType | None:
    ann = v.ann
    t = ann.type if ann is not None else None
    if t is None or t is T.UNKNOWN:
        t = T.SIMPLE.get(d.type.name.upper())
        if t is not None and (v.dims or d.type.size is not None):
            t = T.Array(t, tuple(v.dims) or (d.type.size,))
    return t


def data_values(dl: N.DataList | None, lines: list[str]) -> list[DataValue]:
    """Every value the data list gives, in source order (see the module docstring). Types come
    from the checker's annotations when the workspace was checked, else from the declared
    simple type (INT, REAL, BOOL, CHAR) and the literals. `lines`: the file's text lines."""
    if dl is None:
        return []
    types: dict[str, tuple[str, T.KrlType | None]] = {}
    out: list[DataValue] = []
    for d in dl.items:
        if isinstance(d, N.VarDecl):
            for v in d.names:
                t = _decl_type(d, v)
                types.setdefault(v.name.upper(), (d.type.name, t))
                if d.init is not None:
                    out.append(DataValue(v.name, d.type.name, d, value_text(lines, d) or printer.expr(d.init),
                                         leaves(d.init, t, lines)))
        elif isinstance(d, N.ArrayInit):
            idx = ",".join("" if i is None else str(i) for i in d.indices)
            tname, t = types.get(d.name.upper(), ("", None))
            elem = t.elem if isinstance(t, T.Array) and len(t.dims) == len(d.indices) else None
            if isinstance(t, T.Array) and t.elem == T.CHAR and (elem is None or d.indices[-1] is None):
                elem = T.Array(T.CHAR, t.dims[-1:])       # NAME[] = "text", a row of a CHAR matrix: text
            out.append(DataValue(f"{d.name}[{idx}]", tname, d, value_text(lines, d) or printer.expr(d.value),
                                 leaves(d.value, elem, lines)))
    return out
