"""Compiler-style diagnostics with stable codes: the one model that `krl parse`, `krl check`,
the language server and SARIF output share.

Text form (krl/diagnostics/render.py): ``path:line:col: error[CODE]: message``, then the source line
and a caret under the span. JSON form: :meth:`Diagnostic.as_json`. Lines and columns are 1-based
everywhere (columns count characters, a tab is one column).

Codes are stable: tests, reports, ``krl.toml`` and users refer to them, and every code has a
section in docs/diagnostics.md. Groups:
E0xx input and syntax, E1xx names and declarations, E2xx types, E3xx calls,
E4xx control flow, E5xx system variables / write protection, E9xx internal.
Warnings use the same number with a W prefix where the same rule has a soft form.
"""

from __future__ import annotations

from dataclasses import dataclass, field

# code -> (severity, short kind name used in reports)
CODES: dict[str, tuple[str, str]] = {
    "E001": ("error", "unreadable or binary input"),
    "W002": ("warning", "entry of a folder not read (symbolic link, FIFO/socket/device, folder unreadable or too deep)"),
    "E002": ("error", "syntax error"),
    "W003": ("warning", "construct not understood by the AST builder"),
    "E003": ("error", "construct that cannot be built (too large or malformed)"),
    "E004": ("error", "backup archive refused (unsafe entry or past a limit)"),
    "E005": ("error", "file not parsed within the time limit (--timeout)"),
    "E010": ("error", "block not closed"),
    "E011": ("error", "block closer without its opener"),
    "E012": ("error", "statement missing a keyword or a part"),
    "E013": ("error", "`==` where an assignment `=` is meant"),
    "E014": ("error", "declaration after the first statement (syntax)"),
    "E015": ("error", "bracket or string not closed"),
    "E016": ("error", "unexpected text after a complete statement"),
    "E017": ("error", "character that is not KRL"),
    "E018": ("error", "nesting too deep"),
    "E019": ("error", "expression too long"),
    "E020": ("error", "unexpected end of file"),
    "W021": ("warning", "unbalanced ;FOLD / ;ENDFOLD"),
    "E101": ("error", "undeclared name"),
    "W101": ("warning", "name not in the backup, declared by installed software (once per backup)"),
    "E102": ("error", "duplicate declaration"),
    "E103": ("error", "identifier longer than 24 characters"),
    "E104": ("error", "declaration after the first statement"),
    "E105": ("error", "unknown type"),
    "W105": ("warning", "type not in the backup, declared by installed software (once per backup)"),
    "E106": ("error", "undeclared routine"),
    "W106": ("warning", "routine not in the backup, provided by installed software (once per backup)"),
    "W107": ("warning", "system variable the platform tables do not list (once per backup)"),
    "E108": ("error", "unknown structure component"),
    "W108": ("warning", "component not in the built-in structure table"),
    "E109": ("error", "not an array / wrong number of indices"),
    "E110": ("error", "array index out of range"),
    "W111": ("warning", "main routine name differs from the file name"),
    "E201": ("error", "incompatible types in assignment"),
    "W201": ("warning", "aggregate for a built-in type that the tables do not describe as a structure"),
    "W202": ("warning", "lossy conversion (REAL to INT rounds)"),
    "E203": ("error", "operator applied to wrong operand types"),
    "E204": ("error", "condition is not BOOL"),
    "E205": ("error", "ENUM literal not of the expected type"),
    "W205": ("warning", "ENUM literal not in the built-in enum table"),
    "E206": ("error", "unknown aggregate component"),
    "W206": ("warning", "aggregate component not in the built-in structure table"),
    "E207": ("error", "invalid SWITCH selector or CASE value"),
    "E208": ("error", "FOR counter must be an INT variable"),
    "E209": ("error", "invalid motion target"),
    "W210": ("warning", "string longer than the CHAR array"),
    "E211": ("error", "invalid array index type"),
    "E212": ("error", "FOR STEP is not a non-zero INT constant"),
    "E301": ("error", "too many arguments"),
    "E302": ("error", ":OUT argument is not a variable"),
    "E303": ("error", "argument type mismatch"),
    "E304": ("error", "procedure used as a function or function as a statement"),
    "E401": ("error", "GOTO target not found in the routine"),
    "E402": ("error", "GOTO into a block"),
    "E403": ("error", "EXIT outside a loop"),
    "E404": ("error", "RETURN value mismatch"),
    "E405": ("error", "duplicate label"),
    "E406": ("error", "motion statement in a submit program"),
    "E408": ("error", "interrupt priority outside 1..128"),
    "E409": ("error", "TRIGGER calling a routine without PRIO"),
    "E501": ("error", "write to a write-protected variable or an input"),
    "W501": ("warning", "write to a SIGNAL name of an input"),
    "E502": ("error", "assignment to a constant"),
    "E503": ("error", "not an assignable variable"),
    "E901": ("error", "internal checker error"),
}

# The codes of syntax errors (the file does not parse; krl/syntax/messages.py); E001 and E003 are
# input and build errors of the same group.
SYNTAX_CODES = frozenset({"E002", *(f"E0{n}" for n in range(10, 21))})


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
