"""Every place a declared thing is named, read from the checker's annotations.

One resolution: a use is a node the checker annotated (``node.ann.symbol``: Name, Call, the
FOR counter, a declared VarName); a declaration is the node that entered the symbol into its
scope (VarName, Param, SignalDecl, ImportDecl, ExtDecl, Routine); a label is a Label/Goto of
one routine. Nothing is looked up again from the text: the text of a line is only read to place
a name whose node starts at an earlier keyword (``GLOBAL DEF helper``, ``SIGNAL x``, ``GOTO l``).

An :class:`Occurrence` has a kind: ``decl`` (the declaration), ``write`` (assignment target,
FOR counter, argument of an OUT parameter), ``read`` (every other use). Rename, document
highlight and the never-read hints all read this one list.
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.ast import nodes as N
from krl.lsp.analysis import Analysis
from krl.lsp.navigate import Place, Target, routine_target, symbol_target, value_target
from krl.lsp.text import find_name
from krl.semantics.symbols import Symbol

DECL, READ, WRITE = "decl", "read", "write"


@dataclass(frozen=True)
class Occurrence:
    """One place where a target is named, with its kind (decl/read/write) and target key."""
    place: Place
    kind: str
    key: tuple
    name: str


def _root_name(e: N.Node | None) -> N.Name | None:
    """The variable a target expression writes: ``a`` of ``a[i].b``."""
    while isinstance(e, (N.Index, N.Field)):
        e = e.base
    return e if isinstance(e, N.Name) else None


def written_names(node: N.Node) -> set[int]:
    """ids of the Name nodes a statement in `node` (a module, a routine) writes (assignment
    targets, FOR counters, arguments passed to OUT parameters: reference 2.3 treats a parameter
    without a mode as OUT)."""
    out: set[int] = set()
    for n in node.walk():
        if isinstance(n, N.Assign):
            r = _root_name(n.target)
            if r is not None:
                out.add(id(r))
        elif isinstance(n, N.For):
            out.add(id(n.var))
        elif isinstance(n, N.Call):
            sym = N.symbol_of(n)
            sig = getattr(sym, "signature", None)
            if sig is None or not isinstance(sym.decl, (N.Routine, N.ExtDecl)):
                continue
            for p, a in zip(sig.params, n.args):
                if a is not None and p.mode != "IN":
                    r = _root_name(a)
                    if r is not None:
                        out.add(id(r))
    return out


def _scope_symbol(an: Analysis, path: str, line: int, table: str, name: str, decl) -> Symbol | None:
    """The symbol `decl` entered under `name` in the scope chain at (path, line)."""
    sc = an.scope_at(path, line)
    key = name.upper()
    while sc is not None:
        got = getattr(sc, table).get(key)
        if got is not None and got.decl is decl:
            return got
        sc = sc.parent
    return None


def _routine_of(module: N.Module) -> dict[int, N.Routine]:
    out: dict[int, N.Routine] = {}
    for r in module.routines:
        for n in r.walk():
            out[id(n)] = r
    return out


def file_occurrences(an: Analysis, path: str) -> list[Occurrence]:
    """Every occurrence of a program-declared or built-in name in one file (see the module
    docstring), in file order."""
    fi = an.files.get(path)
    if fi is None:
        return []
    cache = an.__dict__.setdefault("_occurrences", {})
    got = cache.get(path)
    if got is None:
        got = cache[path] = _file_occurrences(an, path, fi)
    return got


def _file_occurrences(an: Analysis, path: str, fi) -> list[Occurrence]:
    lines = fi.lines
    module = fi.source.module
    written = written_names(module)
    routine_of = None
    out: list[Occurrence] = []

    def add(line: int, col: int, name: str, kind: str, t: Target | None) -> None:
        if t is None or not col:
            return
        out.append(Occurrence(Place(path, line, col, len(name)), kind, t.key, name))

    for n in module.walk():
        if isinstance(n, N.VarName):
            sym = N.symbol_of(n)
            if isinstance(sym, Symbol):
                add(n.span.line, n.span.column, n.name, DECL, value_target(sym))
        elif isinstance(n, (N.Name, N.Call)):
            sym = N.symbol_of(n)
            if isinstance(sym, Symbol):
                kind = WRITE if id(n) in written else READ
                add(n.span.line, n.span.column, n.name, kind, symbol_target(an, sym, n.name))
        elif isinstance(n, N.Param):
            sc = an.scope_at(path, n.span.line)
            sym = sc.values.get(n.name.upper()) if sc is not None and sc.kind == "routine" else None
            if sym is not None:
                add(n.span.line, n.span.column, n.name, DECL, value_target(sym))
        elif isinstance(n, (N.SignalDecl, N.ImportDecl)):
            sym = _scope_symbol(an, path, n.span.line, "values", n.name, n)
            if sym is not None:
                add(n.span.line, find_name(lines, n.span.line, n.name, n.span.column), n.name, DECL, value_target(sym))
        elif isinstance(n, N.ExtDecl):
            sym = _scope_symbol(an, path, n.span.line, "routines", n.name, n)
            t = routine_target(an, sym, n.name)
            add(n.span.line, find_name(lines, n.span.line, n.name, n.span.column), n.name, DECL, t)
        elif isinstance(n, N.Routine):
            t = Target("routine", ("routine", id(n)), n.name, None, None, n, path)
            add(n.span.line, find_name(lines, n.span.line, n.name, n.span.column), n.name, DECL, t)
        elif isinstance(n, (N.Label, N.Goto)):
            if routine_of is None:
                routine_of = _routine_of(module)
            r = routine_of.get(id(n))
            name = n.name if isinstance(n, N.Label) else n.label
            if r is None:
                continue
            t = Target("label", ("label", id(r), name.upper()), name, None, None, None, path, r)
            col = n.span.column if isinstance(n, N.Label) else find_name(lines, n.span.line, name, n.span.column + 4)
            add(n.span.line, col, name, DECL if isinstance(n, N.Label) else READ, t)
    out.sort(key=lambda o: (o.place.line, o.place.column))
    return out


def occurrences(an: Analysis, t: Target) -> list[Occurrence]:
    """Every occurrence of `t` in the analysis (labels: in their file only)."""
    paths = [t.path] if t.kind == "label" else list(an.files)
    return [o for p in paths for o in file_occurrences(an, p) if o.key == t.key]
