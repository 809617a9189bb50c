"""Compiler-style diagnostics with stable codes: the one model that `krl parse`, `krl check`,
the language server and SARIF output share.

Text form (krl/diagnostics/render.py): ``path:line:col: error[CODE]: message``, then the source line
and a caret under the span. JSON form: :meth:`Diagnostic.as_json`. Lines and columns are 1-based
everywhere (columns count characters, a tab is one column).

Codes are stable: tests, reports, ``krl.toml`` and users refer to them. Each is declared once,
as a named constant with its severity, kind and message templates, in krl/diagnostics/codes.py
(``E102(name=...)`` gives the code and its message), and has a section in docs/diagnostics.md.
Groups:
E0xx input and syntax, E1xx names and declarations, E2xx types, E3xx calls,
E4xx control flow, E5xx system variables / write protection, E9xx internal.
Warnings use the same number with a W prefix where the same rule has a soft form.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from krl.diagnostics.codes import CODES, PROGRAM_SYNTAX_CODES, SYNTAX_CODES, Code  # every code, declared once: codes.py


@dataclass(slots=True)
class Note:
    """A related place of a diagnostic ("the IF opened here"), 1-based."""

    path: str
    line: int
    column: int
    message: str

    def as_json(self) -> dict:
        return {"path": self.path, "line": self.line, "column": self.column, "message": self.message}


@dataclass(slots=True)
class Diagnostic:
    """One finding at path:line:col, 1-based; severity is 'error' or 'warning'.

    The span runs from (line, column) to (end_line, end_column), end exclusive; 0 means "one
    character" (see :attr:`span_end`). `notes` point at related places, `help` says how to fix.
    """

    path: str
    line: int
    column: int
    code: str
    message: str
    severity: str = ""
    end_line: int = 0
    end_column: int = 0
    notes: list[Note] = field(default_factory=list)
    help: str = ""

    def __post_init__(self) -> None:
        if type(self.code) is not str:      # a Code constant: stored as its plain text
            self.code = str(self.code)
        if not self.severity:
            self.severity = CODES.get(self.code, ("error" if self.code.startswith("E") else "warning",))[0]

    @property
    def file(self) -> str:
        """The file's path (the name editors and SARIF use)."""
        return self.path

    @property
    def span_end(self) -> tuple[int, int]:
        """(end_line, end_column), 1-based, exclusive; one character when not given."""
        if self.end_line <= 0:
            return self.line, self.column + 1
        return self.end_line, max(self.end_column, 1)

    @property
    def is_error(self) -> bool:
        return self.severity == "error"

    @property
    def kind(self) -> str:
        return CODES.get(self.code, ("", self.code))[1]

    def format(self) -> str:
        """The first line of the text form: `path:line:col: severity[CODE]: message` (raw text;
        krl/diagnostics/render.py makes it safe for a terminal)."""
        return f"{self.path}:{self.line}:{self.column}: {self.severity}[{self.code}]: {self.message}"

    __str__ = format

    def as_json(self) -> dict:
        """The JSON form: path, line, column, end_line, end_column (1-based, end exclusive),
        severity, code, message, and notes/help when present."""
        end_line, end_column = self.span_end
        out = {"path": self.path, "line": self.line, "column": self.column,
               "end_line": end_line, "end_column": end_column,
               "severity": self.severity, "code": self.code, "message": self.message}
        if self.notes:
            out["notes"] = [n.as_json() for n in self.notes]
        if self.help:
            out["help"] = self.help
        return out


class DiagnosticSink:
    """Collects diagnostics, one per (path, line, code, message): the message names the
    symbol, so a name that is wrong several times on one line (an unknown type in each
    parameter of an EXT declaration) is reported once. Syntax diagnostics (E0xx) keep
    their column in the key: two syntax errors on one line are two findings."""

    def __init__(self) -> None:
        self.items: list[Diagnostic] = []
        self._seen: set[tuple] = set()

    def add(self, path: str, line: int, column: int, code: str, message: str,
            severity: str = "", **extra) -> None:
        """Add one diagnostic (a repeat of (path, line, code, message) is dropped); `extra`:
        end_line, end_column, notes, help (see :class:`Diagnostic`)."""
        key = (path, line, column if code.startswith("E0") else 0, code, message)
        if key in self._seen:
            return
        self._seen.add(key)
        self.items.append(Diagnostic(path, line, column, code, message, severity, **extra))

    def add_diagnostic(self, d: Diagnostic) -> None:
        """Add a finished Diagnostic (repeats are dropped as in :meth:`add`)."""
        key = (d.path, d.line, d.column if d.code.startswith("E0") else 0, d.code, d.message)
        if key not in self._seen:
            self._seen.add(key)
            self.items.append(d)

    def remove(self, ids: set[int]) -> None:
        """Drop the diagnostics whose ``id()`` is in `ids` (an editor re-checking one file
        replaces that file's findings); their keys are freed for :meth:`add`."""
        gone = [d for d in self.items if id(d) in ids]
        if not gone:
            return
        self.items = [d for d in self.items if id(d) not in ids]
        for d in gone:
            self._seen.discard((d.path, d.line, d.column if d.code.startswith("E0") else 0, d.code, d.message))

    def at(self, span, code: str, message: str, severity: str = "") -> None:
        """Add a diagnostic at a krl.ast.nodes.Span."""
        self.add(span.file, span.line, span.column, code, message, severity)

    def extend(self, diags) -> None:
        for d in diags:
            self.add_diagnostic(d)

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.items if d.is_error]

    def sorted(self) -> list[Diagnostic]:
        return sorted(self.items, key=lambda d: (d.path, d.line, d.column, d.code))
