"""The text form of diagnostics, as gcc, clang and rustc print them (`krl parse`, `krl check`).

One diagnostic::

    R1/Program/demo.src:4:3: error[E010]: missing ENDIF for the IF at line 4
        4 |   IF a > 0 THEN
          |   ^~
    R1/Program/demo.src:9:1: note: END reached while the IF is still open
          = help: add ENDIF before END

then, after all of them, a count line: ``3 errors, 2 warnings in 14 files``.

Lines and columns are 1-based; the caret runs under the span (when a diagnostic has no end,
under the word that starts at its column). Every piece of text from the input (file names,
source lines, messages quoting tokens) goes through :func:`krl.terminal.printable`, so a
control character in a KRL file never reaches the terminal raw. Source lines are split at LF only,
as the KRL lexer counts lines (not ``str.splitlines``, which also breaks at form feeds).

Colour (bold red errors, yellow warnings) only when writing to a terminal and ``NO_COLOR`` is
not set (https://no-color.org); plain text for pipes and files.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterable
from pathlib import Path

from krl.diagnostics import Diagnostic
from krl.limits import MAX_MESSAGE_CHARS
from krl.terminal import printable, printable_path
from krl.source import read_source

TAB = "    "

_WORD = re.compile(r"[A-Za-z0-9_$#]+|\S")

_STYLE = {"error": "\x1b[1;31m", "warning": "\x1b[1;33m", "note": "\x1b[1;36m", "help": "\x1b[1;32m",
          "bold": "\x1b[1m", "gutter": "\x1b[1;34m", "caret": "\x1b[1;32m"}
_RESET = "\x1b[0m"


def use_colour(stream) -> bool:
    """True when `stream` is a terminal and NO_COLOR is not set (to any value)."""
    if os.environ.get("NO_COLOR", "") != "":
        return False
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


class SourceLines:
    """Source lines by path, read once (decoded as the parser decodes them); `texts` seeds it
    with text that is not in a file (editors, tests)."""

    def __init__(self, texts: dict[str, str] | None = None) -> None:
        self._lines: dict[str, list[str] | None] = {}
        for path, text in (texts or {}).items():
            self._lines[path] = split_lines(text)

    def add(self, path: str, text: str) -> None:
        self._lines[path] = split_lines(text)

    def line(self, path: str, number: int) -> str | None:
        """Line `number` (1-based) of `path` without its line end, or None."""
        if path not in self._lines:
            self._lines[path] = self._read(path)
        lines = self._lines[path]
        if lines is None or not 0 < number <= len(lines):
            return None
        return lines[number - 1]

    @staticmethod
    def _read(path: str) -> list[str] | None:
        # never through a link (a linked file is not quoted) and never a FIFO/device (not opened)
        src = read_source(path, follow_symlinks=False)
        return split_lines(src.text) if src.status == "ok" else None


def split_lines(text: str) -> list[str]:
    """Lines as the KRL lexer counts them: split at LF, a CR before it dropped."""
    return [ln[:-1] if ln.endswith("\r") else ln for ln in text.split("\n")]


def _shown(text: str) -> str:
    return printable(text.replace("\t", TAB))


def snippet(line_text: str, column: int, end_column: int | None) -> tuple[str, str]:
    """(source line, caret line) for a span from `column` to `end_column` (1-based, exclusive;
    None: the word at `column`). Both are safe to print; long lines are cut around the span."""
    col = max(column, 1)
    if col > len(line_text) + 1:
        col = len(line_text) + 1
    if end_column is None or end_column <= col:
        m = _WORD.match(line_text, col - 1)
        end_column = col + (len(m.group()) if m else 1)
    end_column = min(end_column, max(len(line_text) + 1, col + 1))
    before, span, after = line_text[:col - 1], line_text[col - 1:end_column - 1], line_text[end_column - 1:]
    lead = ""
    if len(before) > MAX_MESSAGE_CHARS // 2:
        before, lead = before[-(MAX_MESSAGE_CHARS // 2):], "..."
    if len(span) > MAX_MESSAGE_CHARS:
        span = span[:MAX_MESSAGE_CHARS]
        after = ""
    tail = ""
    if len(after) > MAX_MESSAGE_CHARS // 2:
        after, tail = after[:MAX_MESSAGE_CHARS // 2], "..."
    b, s = lead + _shown(before), _shown(span) or " "
    return b + s + _shown(after) + tail, " " * len(b) + "^" + "~" * (len(s) - 1)


class Renderer:
    """Writes diagnostics in the text form; `colour` adds ANSI styles (see :func:`use_colour`)."""

    def __init__(self, echo: Callable[[str], None] = print, colour: bool = False,
                 sources: SourceLines | None = None) -> None:
        self.echo = echo
        self.colour = colour
        self.sources = sources if sources is not None else SourceLines()
        self.errors = 0
        self.warnings = 0

    def _c(self, style: str, text: str) -> str:
        return f"{_STYLE[style]}{text}{_RESET}" if self.colour else text

    def lines(self, d: Diagnostic) -> list[str]:
        """The text form of one diagnostic, as lines."""
        sev = d.severity if d.severity in ("error", "warning") else "error"
        head = (self._c("bold", f"{printable_path(d.path)}:{d.line}:{d.column}:") + " "
                + self._c(sev, f"{sev}[{printable(d.code)}]:") + " " + self._c("bold", printable(d.message)))
        out = [head]
        text = self.sources.line(d.path, d.line)
        if text is not None:
            end_line, end_col = d.span_end
            end = end_col if (d.end_line > 0 and end_line == d.line) else (
                None if d.end_line <= 0 else len(text) + 1)
            src, caret = snippet(text, d.column, end)
            num = str(d.line)
            pad = " " * len(num)
            out.append(self._c("gutter", f" {num} | ") + src)
            out.append(self._c("gutter", f" {pad} | ") + self._c("caret", caret))
        for n in d.notes:
            out.append(self._c("bold", f"{printable_path(n.path)}:{n.line}:{n.column}:") + " "
                       + self._c("note", "note:") + " " + printable(n.message))
        if d.help:
            out.append("   = " + self._c("help", "help:") + " " + printable(d.help))
        return out

    def emit(self, diags: Iterable[Diagnostic]) -> None:
        """Write each diagnostic and count errors and warnings."""
        for d in diags:
            if d.is_error:
                self.errors += 1
            else:
                self.warnings += 1
            for line in self.lines(d):
                self.echo(line)

    def summary(self, files: int) -> str:
        """The closing count line, e.g. ``3 errors, 2 warnings in 14 files``."""
        return count_line(self.errors, self.warnings, files)


def _plural(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if n == 1 else "s")


def count_line(errors: int, warnings: int, files: int) -> str:
    """``3 errors, 2 warnings in 14 files`` (``no errors in 1 file`` when there are none)."""
    parts = []
    if errors or not warnings:
        parts.append(_plural(errors, "error") if errors else "no errors")
    if warnings:
        parts.append(_plural(warnings, "warning"))
    return ", ".join(parts) + " in " + _plural(files, "file")
