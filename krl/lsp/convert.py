"""krl diagnostics (krl/diagnostics/__init__.py, 1-based, characters) as LSP diagnostics
(0-based, code units): same code, same message, severity error/warning, notes as related
information. A one-character span on a name is widened to the whole name."""

from __future__ import annotations

import re

from lsprotocol import types as L

from krl.lsp.text import to_position
from krl.diagnostics import Diagnostic

_NAME = re.compile(r"[\w$#]+")


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
