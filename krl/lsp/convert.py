"""The server's shell with :mod:`krl.lsp.server`: the one place, with it, that imports the
protocol's types (lsprotocol; tests/lsp/test_shell.py holds it). The feature modules return plain
project types (1-based lines, columns in characters); this makes LSP values of them (0-based,
code units of the negotiated ``codec``).

krl diagnostics (krl/diagnostics/__init__.py) become LSP diagnostics: same code, same message,
severity error/warning, notes as related information; a one-character span on a name is widened
to the whole name."""

from __future__ import annotations

import re

from lsprotocol import types as L

from krl.diagnostics import Diagnostic
from krl.lsp.calls import CallItem, CallPlace
from krl.lsp.complete import Completion
from krl.lsp.folding import FoldRange
from krl.lsp.outline import FoundSymbol, Item
from krl.lsp.text import units

_NAME = re.compile(r"[\w$#]+")


def to_position(lines: list[str], line: int, column: int, codec=None) -> L.Position:
    """A 1-based KRL (line, character column) as an LSP Position."""
    li = max(line - 1, 0)
    text = lines[li] if li < len(lines) else ""
    col = min(max(column - 1, 0), len(text))
    return L.Position(line=li, character=units(codec, text[:col]))


def from_position(lines: list[str], pos: L.Position, codec=None) -> tuple[int, int]:
    """An LSP Position as a 1-based KRL (line, character column)."""
    li = max(pos.line, 0)
    text = lines[li] if li < len(lines) else ""
    if codec is None:
        return li + 1, min(pos.character, len(text)) + 1
    n = 0
    for i, ch in enumerate(text):
        if n >= pos.character:
            return li + 1, i + 1
        n += units(codec, ch)
    return li + 1, len(text) + 1


def to_range(lines: list[str], line: int, column: int, length: int, codec=None) -> L.Range:
    """The LSP range of `length` characters from a 1-based (line, column)."""
    return L.Range(start=to_position(lines, line, column, codec),
                   end=to_position(lines, line, column + max(length, 0), codec))


def completion(c: Completion) -> L.CompletionItem:
    return L.CompletionItem(label=c.label, kind=L.CompletionItemKind[c.kind], detail=c.detail)


def folding_range(f: FoldRange) -> L.FoldingRange:
    return L.FoldingRange(start_line=f.first - 1, end_line=f.last - 1,
                          kind=L.FoldingRangeKind.Region if f.region else None)


def document_symbol(it: Item, lines: list[str], codec=None) -> L.DocumentSymbol:
    end_text = lines[it.end - 1] if 0 < it.end <= len(lines) else ""
    rng = L.Range(start=to_position(lines, it.start, 1, codec), end=to_position(lines, it.end, len(end_text) + 1, codec))
    sel = to_range(lines, it.sel_line, it.sel_col, it.sel_len, codec)
    return L.DocumentSymbol(name=it.name or "?", kind=L.SymbolKind[it.kind], range=rng, selection_range=sel,
                            detail=it.detail or None, children=[document_symbol(c, lines, codec) for c in it.children])


def workspace_symbol(s: FoundSymbol, uri_of, codec=None) -> L.WorkspaceSymbol:
    it = s.item
    loc = L.Location(uri=uri_of(s.path), range=to_range(s.lines, it.sel_line, it.sel_col, it.sel_len, codec))
    return L.WorkspaceSymbol(name=it.name, kind=L.SymbolKind[it.kind], location=loc, container_name=s.container)


def call_item(it: CallItem, lines: list[str], uri_of, codec=None) -> L.CallHierarchyItem:
    full = L.Range(start=to_position(lines, it.line, 1, codec), end=to_position(lines, it.end_line, it.end_column, codec))
    return L.CallHierarchyItem(name=it.name, kind=L.SymbolKind.Function, uri=uri_of(it.path), range=full,
                               selection_range=to_range(lines, it.line, it.name_column, len(it.name), codec),
                               detail=it.detail, data=it.node_id)


def call_range(p: CallPlace, lines: list[str], codec=None) -> L.Range:
    return to_range(lines, p.line, p.column, p.length, codec)


def lsp_diagnostic(d: Diagnostic, lines: list[str], codec=None, uri_of=None) -> L.Diagnostic:
    end_line, end_col = d.span_end
    if d.end_line <= 0 and 0 < d.line <= len(lines):
        m = _NAME.match(lines[d.line - 1], max(d.column - 1, 0))
        if m:
            end_col = m.end() + 1
    start = to_position(lines, d.line, d.column, codec)
    end = to_position(lines, end_line, end_col, codec)
    if (end.line, end.character) < (start.line, start.character):
        end = start
    related = None
    if d.notes and uri_of is not None:
        related = [L.DiagnosticRelatedInformation(
            location=L.Location(uri=uri_of(n.path), range=L.Range(start=to_position(lines, n.line, n.column, codec),
                                                                  end=to_position(lines, n.line, n.column + 1, codec))),
            message=n.message) for n in d.notes]
    return L.Diagnostic(range=L.Range(start=start, end=end), message=d.message,
                        severity=L.DiagnosticSeverity.Error if d.is_error else L.DiagnosticSeverity.Warning,
                        code=d.code, source="krl", related_information=related)
