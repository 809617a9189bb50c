"""What a name at a position means, where it is declared, and where it is used.

Resolution uses the front end's results, never a guess from the text: a name the checker
resolved carries its symbol (``node.ann.symbol``); a declaration is looked up in the scope of
its position (krl/semantics/symbols.py ``Scope.lookup``/``lookup_routine``/``lookup_type``); a
structure component takes the type of the expression before its ``.`` (variable types, array
element types and component types from the symbol tables). The tokens of the line (krl/lsp/text.py)
only say which name is under the cursor and what precedes it.

A :class:`Target` is one declared thing with a key that is equal for every use of it within one
analysis: ``value`` (variable, constant, parameter, signal, system variable), ``routine`` (an EXT
declaration resolves to the routine it declares when the workspace has it), ``type`` (STRUC,
ENUM), ``comp`` (a STRUC component), ``label`` (a label of one routine) and ``enumval``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from krl.ast import nodes as N
from krl.lsp.analysis import Analysis
from krl.lsp.text import NAME_WORDS, find_name, line_tokens, token_at
from krl.semantics import types as T
from krl.semantics.symbols import Scope, Symbol


@dataclass
class Target:
    """A declared thing (see the module docstring)."""
    kind: str
    key: tuple
    name: str
    symbol: Symbol | None = None
    type: T.KrlType | None = None
    decl: object = None
    path: str = ""
    owner: object = None           # comp: the Struc; label: the Routine; enumval: the Enum


@dataclass(frozen=True)
class Place:
    """A name in a file: 1-based line and column, length in characters."""
    path: str
    line: int
    column: int
    length: int


# ---------------------------------------------------------------------- targets

def routine_target(an: Analysis, sym: Symbol | None, name: str) -> Target:
    decl = sym.decl if sym is not None else None
    if not isinstance(decl, N.Routine) and an.ws.global_scope is not None:
        g = an.ws.global_scope.routines.get(name.upper())       # EXT x() -> the GLOBAL DEF x
        if g is not None and isinstance(g.decl, N.Routine):
            sym, decl = g, g.decl
    if isinstance(decl, N.Routine):
        return Target("routine", ("routine", id(decl)), decl.name, sym, sym.type if sym else None, decl,
                      an.routine_path(decl))
    return Target("routine", ("routine", name.upper()), name, sym, sym.type if sym else None, decl,
                  sym.path if sym is not None else "")


def value_target(sym: Symbol) -> Target:
    kind = "sysvar" if sym.kind == "sysvar" else "value"
    return Target(kind, ("value", id(sym)), sym.name, sym, sym.type, sym.decl, sym.path)


def type_target(an: Analysis, typ: T.KrlType, name: str) -> Target:
    got = an.type_decl(typ)
    decl, path = got if got is not None else (None, "")
    return Target("type", ("type", id(typ)), getattr(typ, "name", name), None, typ, decl, path)


def comp_target(an: Analysis, struc: T.Struc, name: str) -> Target | None:
    got = struc.fields.get(name.upper())
    if got is None:
        return None
    spelling, ctype = got
    decl = an.type_decl(struc)
    return Target("comp", ("comp", id(struc), name.upper()), spelling, None, ctype,
                  decl[0] if decl else None, decl[1] if decl else "", struc)


def symbol_target(an: Analysis, sym: Symbol, name: str) -> Target:
    if sym.kind == "routine":
        return routine_target(an, sym, name)
    return value_target(sym)


def _labels(r: N.Routine) -> dict[str, N.Label]:
    out: dict[str, N.Label] = {}
    for n in r.walk():
        if isinstance(n, N.Label):
            out.setdefault(n.name.upper(), n)
    return out


def chain_type(scope: Scope, toks, j: int) -> T.KrlType | None:
    """The type of the variable chain (``a``, ``a[i].b``, ``$VEL.CP``) whose last token is
    ``toks[j]``, from the symbol tables; None when it cannot be known."""
    suffix: list[tuple[str, str]] = []        # ('field', name) / ('index', '') from the end
    while j >= 0:
        t = toks[j]
        if t.word == "]":
            depth = 0
            while j >= 0:
                if toks[j].word == "]":
                    depth += 1
                elif toks[j].word == "[":
                    depth -= 1
                    if depth == 0:
                        break
                j -= 1
            suffix.append(("index", ""))
            j -= 1
            continue
        if t.word in NAME_WORDS:
            if j >= 1 and toks[j - 1].word == ".":
                suffix.append(("field", t.text))
                j -= 2
                continue
            sym = scope.lookup(t.text)
            if sym is None:
                return None
            typ: T.KrlType | None = sym.type
            for kind, name in reversed(suffix):
                if kind == "index":
                    typ = typ.elem if isinstance(typ, T.Array) else None
                else:
                    typ = typ.field_type(name) if isinstance(typ, T.Struc) else None
                if typ is None:
                    return None
            return typ
        return None
    return None


def resolve(an: Analysis, path: str, line: int, column: int) -> Target | None:
    """The target of the name at 1-based (line, column) of `path`, or None."""
    fi = an.files.get(path)
    if fi is None:
        return None
    i, tok, toks = token_at(fi.lines, line, column)
    if tok is None:
        return None
    scope = an.scope_at(path, line)
    nodes = [n for n in fi.nodes_on(line) if n.span.column == tok.column or isinstance(n, (N.Aggregate, N.StrucDecl, N.EnumDecl, N.ExtDecl, N.Routine, N.SignalDecl, N.ImportDecl))]
    if tok.word == "ENUMLITERAL":
        for n in nodes:
            if isinstance(n, N.EnumLit) and n.span.column == tok.column and isinstance(N.type_of(n), T.Enum):
                e = N.type_of(n)
                got = an.type_decl(e)
                return Target("enumval", ("enumval", id(e), n.name.upper()), n.name, None, e,
                              got[0] if got else None, got[1] if got else "", e)
        return None
    if tok.word not in NAME_WORDS:
        return None
    name = tok.text
    prev = toks[i - 1].word if i > 0 else ""
    if prev == "." and scope is not None:
        base = chain_type(scope, toks, i - 2)
        return comp_target(an, base, name) if isinstance(base, T.Struc) else None
    for n in nodes:
        at = n.span.column == tok.column
        if at and isinstance(n, (N.Name, N.Call, N.VarName)) and isinstance(N.symbol_of(n), Symbol):
            return symbol_target(an, N.symbol_of(n), name)
        if at and isinstance(n, N.TypeRef) and scope is not None:
            typ = scope.lookup_type(n.name)
            return type_target(an, typ, name) if typ is not None else None
        if at and isinstance(n, N.AggItem):
            for a in nodes:
                if isinstance(a, N.Aggregate) and n in a.items and isinstance(N.type_of(a), T.Struc):
                    return comp_target(an, N.type_of(a), name)
            return None
        if at and isinstance(n, N.StrucComp):
            for d in nodes:
                if isinstance(d, N.StrucDecl) and n in d.components and scope is not None:
                    st = _decl_type(an, path, line, d.name, scope)
                    return comp_target(an, st, name) if isinstance(st, T.Struc) else None
        if isinstance(n, (N.StrucDecl, N.EnumDecl)) and n.name.upper() == name.upper() and scope is not None \
                and (i == 0 or toks[i - 1].word in ("STRUC", "ENUM")):
            st = _decl_type(an, path, line, n.name, scope)
            if st is not None:
                return type_target(an, st, name)
        if isinstance(n, N.Routine) and n.name.upper() == name.upper():
            sym = (scope.lookup_routine(name) if scope is not None else None)
            if sym is None or sym.decl is not n:
                sym = None
            return routine_target(an, sym, name) if sym is not None else Target(
                "routine", ("routine", id(n)), n.name, None, None, n, path)
    routine = an.routine_at(path, line)
    if prev == "GOTO" or (routine is not None and i + 1 < len(toks) and toks[i + 1].word == ":" and i == 0):
        if routine is not None:
            lab = _labels(routine).get(name.upper())
            if lab is not None:
                return Target("label", ("label", id(routine), name.upper()), lab.name, None, None, lab, path, routine)
        return None
    if scope is None:
        return None
    sym = scope.lookup(name)
    if sym is not None:
        return value_target(sym)
    rsym = scope.lookup_routine(name)
    if rsym is not None:
        return routine_target(an, rsym, name)
    typ = scope.lookup_type(name)
    if typ is not None:
        return type_target(an, typ, name)
    return None


def _decl_type(an: Analysis, path: str, line: int, name: str, scope: Scope) -> T.KrlType | None:
    """The type a STRUC/ENUM declaration on `line` entered, as the checker's Declarer recorded
    it (:meth:`Analysis.declared_type`); for a declaration that entered none (a duplicate),
    the type the name means at that place."""
    fi = an.files[path]
    for d in fi.nodes_on(line):
        if isinstance(d, (N.StrucDecl, N.EnumDecl)) and d.name.upper() == name.upper():
            t = an.declared_type(d)
            if t is not None:
                return t
    return scope.lookup_type(name)


# ---------------------------------------------------------------------- places

def definition(an: Analysis, t: Target) -> Place | None:
    """Where `t` is declared (the name in its declaration), None for built-ins."""
    d = t.decl
    path = t.path
    if d is None or not path or path not in an.files:
        return None
    lines = an.files[path].lines
    if t.kind == "comp" and isinstance(d, N.StrucDecl):
        for c in d.components:
            if c.name.upper() == t.name.upper():
                return Place(path, c.span.line, c.span.column, len(c.name))
        return None
    if t.kind == "enumval" and isinstance(d, N.EnumDecl):
        col = find_name(lines, d.span.line, t.name, d.span.column + 1)
        if col:
            return Place(path, d.span.line, col, len(t.name))
        return None
    if isinstance(d, N.VarDecl):
        for v in d.names:
            if v.name.upper() == t.name.upper():
                return Place(path, v.span.line, v.span.column, len(v.name))
    if isinstance(d, N.Label):
        return Place(path, d.span.line, d.span.column, len(d.name))
    line = d.span.line
    col = find_name(lines, line, t.name, d.span.column)
    if not col:
        return Place(path, line, d.span.column, 0)
    return Place(path, line, col, len(t.name))


def _pattern(name: str) -> re.Pattern:
    return re.compile(r"(?<![\w$])" + re.escape(name) + r"(?![\w$])", re.IGNORECASE)


def references(an: Analysis, t: Target, include_declaration: bool = True) -> list[Place]:
    """Every place in the workspace where `t` is named (declaration included on request)."""
    pat = _pattern(t.name)
    out: list[Place] = []
    decl = definition(an, t)
    paths = [p for p in an.files if t.kind != "label" or p == t.path]
    for path in paths:
        fi = an.files[path]
        for ln, text in enumerate(fi.lines, start=1):
            if not pat.search(text):
                continue
            for tok in line_tokens(text, ln):
                word = tok.text[1:] if tok.word == "ENUMLITERAL" else tok.text
                if word.upper() != t.name.upper():
                    continue
                col = tok.column + (1 if tok.word == "ENUMLITERAL" else 0)
                got = resolve(an, path, ln, tok.column)
                if got is not None and got.key == t.key:
                    place = Place(path, ln, col, len(word))
                    if include_declaration or place != decl:
                        out.append(place)
    if include_declaration and decl is not None and decl not in out:
        out.insert(0, decl)
    return out
