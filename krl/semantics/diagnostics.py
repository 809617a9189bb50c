"""Compiler-style diagnostics with stable codes.

Text form: ``path:line:col: error|warning CODE message`` (1-based line and column).
JSON form: ``{"path", "line", "column", "severity", "code", "message"}``.

Codes are stable: tests, reports and users refer to them. Groups:
E0xx input and syntax, E1xx names and declarations, E2xx types, E3xx calls,
E4xx control flow, E5xx system variables / write protection, E9xx internal.
Warnings use the same number with a W prefix where the same rule has a soft form.
"""

from __future__ import annotations

from dataclasses import dataclass

# code -> (severity, short kind name used in reports)
CODES: dict[str, tuple[str, str]] = {
    "E001": ("error", "unreadable or binary input"),
    "E002": ("error", "syntax error"),
    "W003": ("warning", "construct not understood by the AST builder"),
    "E101": ("error", "undeclared name"),
    "W101": ("warning", "name not found (may be declared in an unparsable or controller-side file)"),
    "E102": ("error", "duplicate declaration"),
    "E103": ("error", "identifier longer than 24 characters"),
    "E104": ("error", "declaration after the first statement"),
    "E105": ("error", "unknown type"),
    "W105": ("warning", "unknown type (may be declared in an unparsable or controller-side file)"),
    "E106": ("error", "undeclared routine"),
    "W106": ("warning", "routine not found (may be declared in an unparsable or controller-side file)"),
    "W107": ("warning", "unknown system variable"),
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
    "E501": ("error", "write to a write-protected variable"),
    "W501": ("warning", "write to an input"),
    "E502": ("error", "assignment to a constant"),
    "E503": ("error", "not an assignable variable"),
    "E901": ("error", "internal checker error"),
}


@dataclass(slots=True)
class Diagnostic:
    """One finding at path:line:col (1-based). severity is 'error' or 'warning'."""

    path: str
    line: int
    column: int
    code: str
    message: str
    severity: str = ""

    def __post_init__(self) -> None:
        if not self.severity:
            self.severity = CODES.get(self.code, ("error" if self.code.startswith("E") else "warning",))[0]

    @property
    def is_error(self) -> bool:
        return self.severity == "error"

    @property
    def kind(self) -> str:
        return CODES.get(self.code, ("", self.code))[1]

    def format(self) -> str:
        """`path:line:col: severity CODE message`."""
        return f"{self.path}:{self.line}:{self.column}: {self.severity} {self.code} {self.message}"

    __str__ = format

    def as_json(self) -> dict:
        """The JSON form: path, line, column, severity, code, message."""
        return {"path": self.path, "line": self.line, "column": self.column,
                "severity": self.severity, "code": self.code, "message": self.message}


class DiagnosticSink:
    """Collects diagnostics, one per (path, line, code, message): the message names the
    symbol, so a name that is wrong several times on one line (an unknown type in each
    parameter of an EXT declaration) is reported once. Syntax diagnostics (E0xx) keep
    their column in the key: two syntax errors on one line are two findings."""

    def __init__(self) -> None:
        self.items: list[Diagnostic] = []
        self._seen: set[tuple] = set()

    def add(self, path: str, line: int, column: int, code: str, message: str,
            severity: str = "") -> None:
        """Add one diagnostic (a repeat of (path, line, code, message) is dropped)."""
        key = (path, line, column if code.startswith("E0") else 0, code, message)
        if key in self._seen:
            return
        self._seen.add(key)
        self.items.append(Diagnostic(path, line, column, code, message, severity))

    def at(self, span, code: str, message: str, severity: str = "") -> None:
        """Add a diagnostic at a krl.ast.nodes.Span."""
        self.add(span.file, span.line, span.column, code, message, severity)

    def extend(self, diags) -> None:
        for d in diags:
            self.add(d.path, d.line, d.column, d.code, d.message, d.severity)

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.items if d.is_error]

    def sorted(self) -> list[Diagnostic]:
        return sorted(self.items, key=lambda d: (d.path, d.line, d.column, d.code))
