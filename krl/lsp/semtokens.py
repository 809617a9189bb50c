"""Semantic tokens (full document) from the AST and the checker's symbols.

A name is classified by the node the checker annotated at its place, never by its spelling:
``variable`` (variables, signals, system variables; ``readonly`` for CONST and write-protected
ones, ``defaultLibrary`` for system variables), ``parameter``, ``function`` (routines; built-ins
``defaultLibrary``), ``type`` (STRUC/ENUM names and the simple types), ``enumMember``
(``#VALUE`` and ENUM declarations), ``property`` (structure components), ``declaration`` on
the name a declaration enters. The rest comes from the tokens of the line (krl/lsp/text.py):
``keyword``, ``string``, ``number``, ``comment`` (from ``;`` to the end of the line, ``;FOLD``
lines included) and ``macro`` for ``&`` header lines (reference 2.2).
"""

from __future__ import annotations

from krl.ast import nodes as N
from krl.lsp.analysis import Analysis
from krl.lsp.text import NAME_WORDS, find_name, line_tokens, units
from krl.syntax.folds import comment_start

TYPES = ["keyword", "variable", "parameter", "function", "type", "enumMember", "property",
         "macro", "comment", "string", "number"]
MODIFIERS = ["declaration", "readonly", "defaultLibrary"]
_T = {n: i for i, n in enumerate(TYPES)}
DECLARATION, READONLY, LIBRARY = 1, 2, 4
SIMPLE_TYPES = {"INT", "REAL", "BOOL", "CHAR"}
NUMBERS = {"INTLITERAL", "REALLITERAL", "HEXLITERAL", "BINLITERAL"}


def _symbol_class(sym) -> tuple[str, int]:
    kind = getattr(sym, "kind", "")
    mods = READONLY if getattr(sym, "access", "RW") == "RO" or kind == "const" else 0
    if kind == "param":
        return "parameter", 0
    if kind == "routine":
        return "function", LIBRARY if getattr(sym, "decl", None) is None else 0
    if kind == "sysvar":
        return "variable", mods | LIBRARY
    return "variable", mods


def classify(an: Analysis, path: str) -> dict[tuple[int, int], tuple[str, int]]:
    """(1-based line, column) of a name -> (token type, modifier bits), from the AST."""
    fi = an.files[path]
    lines = fi.lines
    out: dict[tuple[int, int], tuple[str, int]] = {}

    def at(line: int, col: int, typ: str, mods: int = 0) -> None:
        if col:
            out[(line, col)] = (typ, mods)

    def type_at(line: int, col: int, name: str) -> None:
        """A type name: ``defaultLibrary`` when no STRUC/ENUM of the program declares it."""
        sc = an.scope_at(path, line)
        typ = sc.lookup_type(name) if sc is not None else None
        at(line, col, "type", LIBRARY if typ is not None and an.type_symbol(typ) is None else 0)

    for n in fi.source.module.walk():
        ln, col = n.span.line, n.span.column
        if isinstance(n, N.VarName):
            sym = N.symbol_of(n)
            typ, mods = _symbol_class(sym) if sym is not None else ("variable", 0)
            at(ln, col, typ, mods | DECLARATION)
        elif isinstance(n, (N.Name, N.Call)):
            sym = N.symbol_of(n)
            if sym is not None:
                at(ln, col, *_symbol_class(sym))
            elif isinstance(n, N.Call):
                at(ln, col, "function")
        elif isinstance(n, N.Param):
            at(ln, col, "parameter", DECLARATION)
        elif isinstance(n, N.SignalRef):
            at(ln, col, "variable", LIBRARY)
        elif isinstance(n, N.TypeRef):
            type_at(ln, col, n.name)
        elif isinstance(n, N.EnumLit):
            at(ln, col, "enumMember")
        elif isinstance(n, (N.StrucComp, N.AggItem)):
            at(ln, col, "property", DECLARATION if isinstance(n, N.StrucComp) else 0)
        elif isinstance(n, N.StrucDecl):
            at(ln, find_name(lines, ln, n.name, col), "type", DECLARATION)
            for c in n.components:
                c_col = find_name(lines, c.span.line, c.type_name, 1)
                if c_col and c_col < c.span.column:
                    type_at(c.span.line, c_col, c.type_name)
        elif isinstance(n, N.EnumDecl):
            name_col = find_name(lines, ln, n.name, col)
            at(ln, name_col, "type", DECLARATION)
            nxt = name_col + len(n.name)
            for v in n.values:
                vc = find_name(lines, ln, v, nxt)
                at(ln, vc, "enumMember", DECLARATION)
                nxt = vc + len(v) if vc else nxt
        elif isinstance(n, (N.Routine, N.ExtDecl)):
            at(ln, find_name(lines, ln, n.name, col), "function", DECLARATION if isinstance(n, N.Routine) else 0)
        elif isinstance(n, N.SignalDecl):
            at(ln, find_name(lines, ln, n.name, col), "variable", DECLARATION)
        elif isinstance(n, N.ImportDecl):
            at(ln, find_name(lines, ln, n.name, col), "variable", DECLARATION)
    return out


def tokens(an: Analysis, path: str, codec=None) -> list[int]:
    """The LSP ``data`` array (relative line, start, length, type, modifiers) of one file."""
    fi = an.files[path]
    names = classify(an, path)
    rows: list[tuple[int, int, int, int, int]] = []     # 0-based line, start, length (units), type, mods
    for li, text in enumerate(fi.lines):
        if not text.strip():
            continue
        stripped = text.lstrip()
        if stripped.startswith("&"):
            start = len(text) - len(stripped)
            rows.append((li, units(codec, text[:start]), units(codec, stripped), _T["macro"], 0))
            continue
        cut = comment_start(text)
        prev = ""
        for t in line_tokens(text if cut < 0 else text[:cut], li + 1):
            c0 = t.column - 1
            typ, mods = None, 0
            got = names.get((li + 1, t.column))
            if got is not None:                 # a name, also one spelled like a keyword (E6POS)
                typ, mods = got
            elif t.word in NAME_WORDS:
                if prev == ".":           # a component: Field nodes start at their base
                    typ = "property"
            elif t.word == "STRINGLITERAL":
                typ = "string"
            elif t.word in NUMBERS:
                typ = "number"
            elif t.word == "ENUMLITERAL":
                typ = "enumMember"
            elif t.word in SIMPLE_TYPES:
                typ = "type"
                mods = LIBRARY
            elif t.text[:1].isalpha() and t.word == t.text.upper():
                typ = "keyword"
            if typ is not None:
                rows.append((li, units(codec, text[:c0]), units(codec, t.text), _T[typ], mods))
            prev = t.word
        if cut >= 0:
            rows.append((li, units(codec, text[:cut]), units(codec, text[cut:]), _T["comment"], 0))
    data: list[int] = []
    pl, ps = 0, 0
    for li, st, ln, ty, md in rows:
        if ln <= 0:
            continue
        data.extend((li - pl, st - ps if li == pl else st, ln, ty, md))
        pl, ps = li, st
    return data
