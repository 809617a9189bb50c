"""An independent value comparison of two backup folders, the oracle of tests/diff/test_history.py.

It shares no code with krl/diff: it walks both folders itself, parses every data list with the
front end (krl.parsecache.load_files, through the one store: AST only, no checker; each distinct content once per
process; a file with syntax errors gives what parsed), and compares every value declared with an
initial value, by the rules docs/diff.md states for ``krl diff``:

* a file is the same file whatever the letter case of its path;
* a file only OLD has and a file only NEW has are one file moved when they have the same name
  and no other file of either side alone has it (issue 63): compared with each other, its
  changes named by NEW's path (:func:`moves`);
* a name given twice in one data list is compared by its first definition;
* REAL numbers are equal when equal as 32-bit floats (numpy.float32), INT exactly, an angle A,
  B or C of a cartesian point modulo 360 degrees; ENUM values by name in any letter case;
  strings exactly; any other expression by its text with names upper-cased.

Result: the set of ``(file, NAME.PATH, change)`` -- ``file`` lower-case relative to the side's
folder, ``NAME.PATH`` upper-case (``PPDAT13.APO_DIST``, ``TOOL_DATA[1].X``; a whole variable
``NAME`` when it is added or removed), ``change`` one of added, removed, changed.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np

from krl.ast import nodes as N
from krl.ast.printer import expr as krl_expr
from krl.parsecache import load_files

_CARTESIAN = {"E6POS", "POS", "FRAME", "E3POS"}
_ANGLES = {"A", "B", "C"}


def krl_files(folder: Path) -> dict[str, Path]:
    """{path below `folder`, lower-case: path} of the KRL files (.src/.dat/.sub, any case)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file() and p.suffix.lower() in (".src", ".dat", ".sub"):
            out.setdefault(p.relative_to(folder).as_posix().lower(), p)
    return out


def _number(e):
    sign = 1
    while isinstance(e, N.Unary) and e.op in ("-", "+"):
        sign = -sign if e.op == "-" else sign
        e = e.operand
    if isinstance(e, N.RealLit):
        return "R", sign * float(e.value)
    if isinstance(e, N.IntLit):
        return "I", sign * int(e.value)
    return None


def _scalar(e: N.Expr):
    """(kind, compared value) of a leaf expression."""
    num = _number(e)
    if num is not None:
        return num
    if isinstance(e, N.BoolLit):
        return "B", bool(e.value)
    if isinstance(e, N.StrLit):
        return "S", e.value
    if isinstance(e, N.EnumLit):
        return "E", e.name.upper()
    return "X", krl_expr(e).upper()


def _leaves(e: N.Expr) -> dict[str, tuple]:
    out: dict[str, tuple] = {}

    def walk(prefix: str, v: N.Expr) -> None:
        if isinstance(v, N.Aggregate):
            for item in v.items:
                name = item.name.upper() + ("[]" if item.array else "")
                walk(f"{prefix}.{name}" if prefix else name, item.value)
        else:
            out.setdefault(prefix, _scalar(v))

    walk("", e)
    return out


def declared_values(dl: N.DataList) -> dict[str, tuple[str, bool, dict]]:
    """{NAME: (declared type, real-typed, leaves)} of one data list; the first of a name."""
    types: dict[str, str] = {}
    out: dict[str, tuple[str, bool, dict]] = {}
    for d in dl.items:
        if isinstance(d, N.VarDecl):
            for v in d.names:
                types.setdefault(v.name.upper(), d.type.name.upper())
                if d.init is not None:
                    out.setdefault(v.name.upper(), (d.type.name.upper(), d.type.name.upper() == "REAL",
                                                    _leaves(d.init)))
        elif isinstance(d, N.ArrayInit):
            name = f"{d.name.upper()}[{','.join('' if i is None else str(i) for i in d.indices)}]"
            t = types.get(d.name.upper(), "")
            out.setdefault(name, (t, t == "REAL", _leaves(d.value)))
    return out


def _f32(x: float) -> np.float32:
    with np.errstate(over="ignore"):
        return np.float32(x)


def same_leaf(a: tuple, b: tuple, real: bool, angle: bool) -> bool:
    (ka, va), (kb, vb) = a, b
    if ka in "RI" and kb in "RI":
        if ka == kb == "I" and not real:
            return va == vb
        if angle:
            wrapped = math.remainder(vb - va, 360.0)
            return _f32(va) == _f32(va + wrapped)
        return _f32(va) == _f32(vb)
    return (ka, va) == (kb, vb)


#: content hash -> module AST (None: did not parse), for the contents parsed before in this
#: process: two sides of a pair, and consecutive pairs, hold mostly the same files (bounded)
_PARSED: dict[str, N.Module | None] = {}
_PARSED_MAX = 4000


def parse_all(paths: list[Path]) -> dict[Path, N.Module | None]:
    """{path: module AST (of what parsed), None when it was not read or not parsed}; each distinct
    content is parsed once."""
    digest = {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}
    if len(_PARSED) + len(set(digest.values())) > _PARSED_MAX:
        _PARSED.clear()
    first: dict[str, Path] = {}
    for p in paths:
        if digest[p] not in _PARSED:
            first.setdefault(digest[p], p)
    todo = list(first.values())
    # through the one store (krl/store.py): the files `krl diff` parsed a moment before are
    # not parsed again (the parser is the front end's either way; the comparison is this module's)
    for p, lf in zip(todo, load_files(todo, timeout=900.0)):
        # a file with syntax errors is compared from what parsed (issue 63): its data list's items;
        # one not read or not parsed at all (E001, E005, past a limit) is skipped
        _PARSED[digest[p]] = lf.module if lf is not None and lf.status in ("ok", "syntax_error") else None
    return {p: _PARSED[digest[p]] for p in paths}


def moves(fo: dict[str, Path], fn: dict[str, Path]) -> dict[str, str]:
    """{OLD's key: NEW's key} of the files moved (module docstring): of the keys only one side
    has, those whose last part (lower-case) occurs exactly once among OLD's and once among NEW's."""
    only_old = [k for k in fo if k not in fn]
    only_new = [k for k in fn if k not in fo]
    name = lambda k: k.split("/")[-1]  # noqa: E731
    out = {}
    for k in only_old:
        a = [x for x in only_old if name(x) == name(k)]
        b = [x for x in only_new if name(x) == name(k)]
        if len(a) == 1 and len(b) == 1:
            out[k] = b[0]
    return out


def compare(old: Path, new: Path) -> tuple[set[tuple[str, str, str]], set[str]]:
    """(changes, files skipped): the value changes between the folders `old` and `new` (see the
    module docstring), and the .dat files not compared because a side's could not be read or
    parsed at all (a file with syntax errors is compared from what parsed)."""
    fo, fn = krl_files(old), krl_files(new)
    for a, b in moves(fo, fn).items():            # a moved file: compared under NEW's key
        fo[b] = fo.pop(a)
    dats = sorted(k for k in set(fo) | set(fn) if k.endswith(".dat"))
    modules = parse_all([fo[k] for k in dats if k in fo] + [fn[k] for k in dats if k in fn])
    changes: set[tuple[str, str, str]] = set()
    skipped: set[str] = set()
    for k in dats:
        mo = modules.get(fo[k]) if k in fo else None
        mn = modules.get(fn[k]) if k in fn else None
        if (k in fo and mo is None) or (k in fn and mn is None):
            skipped.add(k)
            continue
        vo = declared_values(mo.data) if mo is not None and mo.data is not None else {}
        vn = declared_values(mn.data) if mn is not None and mn.data is not None else {}
        for name in set(vo) | set(vn):
            if name not in vo or name not in vn:
                changes.add((k, name, "added" if name not in vo else "removed"))
                continue
            (ta, ra, la), (tb, rb, lb) = vo[name], vn[name]
            cartesian = tb in _CARTESIAN or (tb == "" and name.split("[")[0] in ("TOOL_DATA", "BASE_DATA"))
            for path in set(la) | set(lb):
                full = f"{name}.{path}" if path else name
                if path not in la or path not in lb:
                    changes.add((k, full, "added" if path not in la else "removed"))
                elif not same_leaf(la[path], lb[path], ra or rb, cartesian and path in _ANGLES):
                    changes.add((k, full, "changed"))
    return changes, skipped


def reported(doc: dict) -> set[tuple[str, str, str]]:
    """The value changes a ``krl diff --format json`` document reports, in the oracle's form
    (``file`` as the diff names it, lower-case)."""
    out: set[tuple[str, str, str]] = set()
    for section in ("points", "frames"):
        for e in doc[section]:
            f, name = e["file"].lower(), e["name"].upper()
            if e["change"] != "changed":
                out.add((f, name, e["change"]))
                continue
            for comp in e["delta"]:
                out.add((f, f"{name}.{comp.upper()}", "changed"))
            for group in ("status_turn", "values"):
                for comp, (a, b) in e.get(group, {}).items():
                    change = "added" if a is None else "removed" if b is None else "changed"
                    out.add((f, f"{name}.{comp.upper()}" if comp != "value" else name, change))
    for e in doc["values"]:
        out.add((e["file"].lower(), e["name"].upper(), e["change"]))
    return out
