"""Document symbols (hierarchical: routines and data lists, their declarations, FOLD sections)
and workspace symbols (routines, data-list declarations and types of every analysed workspace)."""

from __future__ import annotations

from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.limits import MAX_LSP_SYMBOLS
from krl.lsp.analysis import Analysis
from krl.lsp.folding import fold_sections
from krl.lsp.text import find_name


class SK:
    """Kinds of symbols: names of LSP's ``SymbolKind`` (the server's shell, krl/lsp/convert.py,
    makes the protocol's symbols)."""
    Function = "Function"
    Module = "Module"
    Namespace = "Namespace"
    Constant = "Constant"
    Variable = "Variable"
    Struct = "Struct"
    Enum = "Enum"


@dataclass
class Item:
    """A symbol: its lines (1-based, first and last), its name's place on its line, the
    symbols inside it."""
    name: str
    kind: str                  # an :class:`SK` name
    start: int                 # 1-based first line
    end: int                   # 1-based last line
    sel_line: int
    sel_col: int
    sel_len: int
    detail: str = ""
    children: list["Item"] = field(default_factory=list)


def _decl_items(lines: list[str], decls: list[N.Decl]) -> list[Item]:
    out = []
    for d in decls:
        if isinstance(d, N.VarDecl):
            for v in d.names:
                kind = SK.Constant if d.is_const else SK.Variable
                out.append(Item(v.name, kind, v.span.line, v.span.line, v.span.line, v.span.column, len(v.name),
                                d.type.name + ("[]" if v.dims else "")))
        elif isinstance(d, (N.StrucDecl, N.EnumDecl, N.SignalDecl, N.ImportDecl, N.ExtDecl)):
            kind = {N.StrucDecl: SK.Struct, N.EnumDecl: SK.Enum, N.SignalDecl: SK.Variable,
                    N.ImportDecl: SK.Variable, N.ExtDecl: SK.Function}[type(d)]
            col = find_name(lines, d.span.line, d.name, d.span.column) or d.span.column
            detail = {N.StrucDecl: "STRUC", N.EnumDecl: "ENUM", N.SignalDecl: "SIGNAL",
                      N.ImportDecl: "IMPORT", N.ExtDecl: "EXT"}[type(d)]
            out.append(Item(d.name, kind, d.span.line, d.span.line, d.span.line, col, len(d.name), detail))
    return out


def _nest(items: list[Item]) -> list[Item]:
    """Put each item inside the smallest earlier item whose lines hold it."""
    items = sorted(items, key=lambda i: (i.start, -i.end))
    roots: list[Item] = []
    stack: list[Item] = []
    for it in items:
        while stack and not (stack[-1].start <= it.start and it.end <= stack[-1].end):
            stack.pop()
        (stack[-1].children if stack else roots).append(it)
        stack.append(it)
    return roots


def _items(an: Analysis, path: str) -> list[Item]:
    fi = an.files[path]
    lines = fi.lines
    mod = fi.source.module
    items: list[Item] = []
    for r in mod.routines:
        col = find_name(lines, r.span.line, r.name, r.span.column) or r.span.column
        end = r.end_line or r.span.line
        detail = ("GLOBAL " if r.is_global else "") + r.kind
        items.append(Item(r.name, SK.Function, r.span.line, max(end, r.span.line), r.span.line, col, len(r.name), detail))
        items.extend(_decl_items(lines, r.decls))
    if mod.data is not None:
        dl = mod.data
        end = next((n for n in range(len(lines), 0, -1) if lines[n - 1].strip().upper().startswith("ENDDAT")), len(lines))
        col = find_name(lines, dl.span.line, dl.name, dl.span.column) or dl.span.column
        items.append(Item(dl.name, SK.Module, dl.span.line, max(end, dl.span.line), dl.span.line, col, len(dl.name),
                          "DEFDAT" + (" PUBLIC" if dl.public else "")))
        items.extend(_decl_items(lines, dl.items))
    for start, end, title in fold_sections(lines):
        items.append(Item(title, SK.Namespace, start, end, start, 1, len(lines[start - 1]) if start <= len(lines) else 0, "FOLD"))
    return items


def document_symbols(an: Analysis, path: str) -> list[Item]:
    """The symbols of `path`, nested (each inside the smallest one whose lines hold it)."""
    return _nest(_items(an, path))


@dataclass(frozen=True)
class FoundSymbol:
    """A workspace symbol: the item, its file (and that file's lines), the module that holds it."""
    item: Item
    path: str
    container: str
    lines: list[str] = field(compare=False, repr=False, default_factory=list)


def workspace_symbols(analyses: list[Analysis], query: str) -> list[FoundSymbol]:
    """Routines, data-list declarations and FOLD-free top-level names whose name contains
    `query` (any case); at most MAX_LSP_SYMBOLS."""
    q = query.upper()
    out: list[FoundSymbol] = []
    seen: set = set()
    for an in analyses:
        for path, fi in an.files.items():
            for it in _items(an, path):
                if it.kind == SK.Namespace or q not in it.name.upper():
                    continue
                key = (path, it.sel_line, it.sel_col)
                if key in seen:
                    continue
                seen.add(key)
                out.append(FoundSymbol(it, path, fi.source.module.name, fi.lines))
                if len(out) >= MAX_LSP_SYMBOLS:
                    return out
    return out
