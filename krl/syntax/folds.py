"""FOLD balance: warning W021 for an unmatched ``;FOLD`` / ``;ENDFOLD`` pair.

The KUKA editor (smartPad, WorkVisual) folds the lines between a comment that starts with
``FOLD`` and the matching comment that starts with ``ENDFOLD``; folds nest. They are comments
to the language (reference 1.4), so an unbalanced pair never stops a program, but it makes the
editor show the file wrongly and usually means lines were cut or pasted by hand. Three cases,
each reported with the lines involved (1-based):

* a ``;FOLD`` never closed: at the FOLD's line, with a note at the END of its routine (or the
  last line of the file when it was opened outside a routine);
* a ``;ENDFOLD`` without an open FOLD: at its line;
* a pair that straddles a routine's end, the FOLD inside one routine and its ENDFOLD inside
  another: at the FOLD's line, with notes at the first routine's END and at the ENDFOLD.

A fold may wrap whole routines: KUKA's own files open ``;FOLD BAS ()`` after the DEF line and
close it after END, and sps.sub hides its later routines in a ``;FOLD ;%{H}`` opened before
END. A pair with one end outside every routine is therefore not a mismatch. Over the 596 files
of the real corpus the scan reports 7 warnings in 6 files, each a genuinely unbalanced fold.

The scan works on the text alone, statement by statement with the lexer's line ends (``\\r\\n``,
``\\n``, ``\\r``): a comment starts at the first ``;`` outside a string; a marker is the comment's
first word, in any letter case (``;FOLD``, ``; fold``, ``;EndFold (BASISTECH INI)``), also after
code on its line (``x = 1 ;FOLD``). Routines are the lines between DEF/DEFFCT/DEFDAT (optionally
GLOBAL) and END/ENDFCT/ENDDAT. A file that does not parse is scanned all the same. Lines and
columns are numbered as the parser numbers them (and krl/diagnostics/render.py ``split_lines``):
a new line after each LF only, so a lone CR ends a comment but not the line's number.

:func:`scan_folds` is the one recogniser of fold markers outside the lexer: ``krl check``'s
W021 (:func:`fold_diagnostics`) and the language server's folding ranges and document symbols
(``scan_fold_lines(...).pairs``, krl/lsp/folding.py and outline.py) read the same scan.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from krl.diagnostics import Diagnostic, Note
from krl.diagnostics.codes import W021
from krl.diagnostics.render import split_lines

_MARKER = re.compile(r";[ \t]*(END)?FOLD(?![A-Za-z0-9_$])", re.I)
_OPEN = re.compile(r"[ \t\f]*(?:GLOBAL[ \t]+)?(DEF|DEFFCT|DEFDAT)[ \t]+([A-Za-z_$][A-Za-z0-9_$]*)", re.I)
_CLOSE = re.compile(r"[ \t\f]*(END|ENDFCT|ENDDAT)(?![A-Za-z0-9_$])", re.I)
# a line that can matter to the scan: a comment, a lone CR, or the start of a routine or its end
_MAYBE = re.compile(r"[ \t\f]*(?:GLOBAL|DEF|END)", re.I)


@dataclass(frozen=True, slots=True)
class Fold:
    """One ``;FOLD`` ... ``;ENDFOLD`` pair. `line`, `column`: the FOLD marker's ``;`` (1-based);
    `end_line`, `end_column`: the ENDFOLD marker's ``;``; `text`: the fold's text as the KUKA
    editor shows it folded, the comment after ``FOLD`` up to an inline form's ``;%{...}``
    parameters, blanks stripped ("" for a bare ``;FOLD``); `marker_end`: the column just after
    the word FOLD (the span of a diagnostic at the FOLD)."""

    line: int
    column: int
    end_line: int
    end_column: int
    text: str
    marker_end: int = 0


@dataclass(slots=True)
class FoldScan:
    """The markers of one text (see the module docstring). `pairs`: matched folds, in the order
    their ENDFOLDs come; `unclosed`: FOLDs never closed, (line, column, marker end column,
    routine index); `stray`: ENDFOLDs without an open FOLD, (line, column, marker end column);
    `crossing`: pairs whose FOLD opens in one routine and closes in another, as (the pair, the
    FOLD's routine index); `routines`: (name, first line, END line) in order; `last`: the
    number of the last line."""

    pairs: list[Fold] = field(default_factory=list)
    unclosed: list[tuple[int, int, int, int | None]] = field(default_factory=list)
    stray: list[tuple[int, int, int]] = field(default_factory=list)
    crossing: list[tuple[Fold, int]] = field(default_factory=list)
    routines: list[tuple[str, int, int]] = field(default_factory=list)
    last: int = 0


def _comment_start(line: str) -> int:
    """Index of the `;` that starts the line's comment (outside a string), or -1."""
    semi = line.find(";")
    if semi < 0:
        return -1
    quote = line.find('"', 0, semi)
    if quote < 0:
        return semi         # no string before the first `;` (most lines): found without a loop
    in_string = False
    for i in range(quote, len(line)):
        ch = line[i]
        if ch == '"':
            in_string = not in_string
        elif ch == ";" and not in_string:
            return i
    return -1


comment_start = _comment_start      # the public name (the language server's tokens and hints)


def _lines(text: str) -> list[str]:

    return split_lines(text)


def scan_folds(text: str) -> FoldScan:
    """Scan `text` (a whole file) for FOLD markers and routines; never raises."""
    return scan_fold_lines(_lines(text))


def scan_fold_lines(lines: list[str]) -> FoldScan:
    """:func:`scan_folds` of a text already split as krl/diagnostics/render.py ``split_lines``
    splits it (the language server's lines)."""
    out = FoldScan()
    routines = out.routines
    stack: list[tuple[int, int, int, int | None, str]] = []   # open FOLDs: line, column, end column, routine, text
    current: int | None = None                                 # index into routines, None outside
    out.last = len(lines) - (1 if len(lines) > 1 and lines[-1] == "" else 0)
    for number, whole in enumerate(lines, start=1):
        if ";" not in whole and "\r" not in whole and not _MAYBE.match(whole):
            continue                             # a statement line: nothing to see
        offset = 0
        for line in whole.split("\r"):           # a lone CR ends a statement and its comment
            semi = _comment_start(line)
            code = line if semi < 0 else line[:semi]
            if current is None:
                m = _OPEN.match(code)
                if m:
                    routines.append((m.group(2), number, 0))
                    current = len(routines) - 1
            marker = _MARKER.match(line, semi) if semi >= 0 else None
            if marker is not None:
                col = offset + semi + 1
                end_col = col + marker.end() - marker.start()
                if marker.group(1) is None:
                    title = line[marker.end():].split(";%", 1)[0].strip()
                    stack.append((number, col, end_col, current, title))
                elif not stack:
                    out.stray.append((number, col, end_col))
                else:
                    o_line, o_col, o_end, o_ctx, title = stack.pop()
                    fold = Fold(o_line, o_col, number, col, title, o_end)
                    out.pairs.append(fold)
                    if o_ctx is not None and current is not None and o_ctx != current:
                        out.crossing.append((fold, o_ctx))
            if current is not None and _CLOSE.match(code):
                name, first, _ = routines[current]
                routines[current] = (name, first, number)
                current = None
            offset += len(line) + 1
    if current is not None:
        name, first, _ = routines[current]
        routines[current] = (name, first, out.last)
    out.unclosed = [(ln, col, end, ctx) for ln, col, end, ctx, _title in stack]
    return out


def fold_diagnostics(path: str, text: str) -> list[Diagnostic]:
    """W021 warnings for the unbalanced FOLD markers of `text` (the file `path`), by line."""
    found = scan_folds(text)
    out: list[Diagnostic] = []
    last = found.last

    def routine_end(idx: int | None) -> tuple[str, int] | None:
        if idx is None:
            return None
        name, _first, end = found.routines[idx]
        return name, end

    for number, col, end_col in found.stray:
        out.append(Diagnostic(path, number, col, *W021(),
                              end_line=number, end_column=end_col,
                              help="remove it, or add the `;FOLD` it closes"))
    for fold, o_ctx in found.crossing:
        end = routine_end(o_ctx)
        c_line, c_col = fold.end_line, fold.end_column
        notes = []
        if end is not None:
            what = f"{end[0]} ends here"
            notes.append(Note(path, end[1], 1, what))
            warned = W021("after_end", line=c_line, routine=end[0], end=end[1])
        else:
            warned = W021("into_routine", line=c_line)
        notes.append(Note(path, c_line, c_col, "the `;ENDFOLD` that closes it"))
        out.append(Diagnostic(path, fold.line, fold.column, *warned, end_line=fold.line,
                              end_column=fold.marker_end, notes=notes, help="keep each fold inside one routine"))
    for o_line, o_col, o_end, o_ctx in found.unclosed:
        end = routine_end(o_ctx)
        if end is not None:
            warned = W021("unclosed", routine=end[0], end=end[1])
            note = Note(path, end[1], 1, f"{end[0]} ends here")
            help_ = f"add `;ENDFOLD` before line {end[1]}"
        else:
            warned = W021("unclosed_file", line=last)
            note = Note(path, last, 1, "the file ends here")
            help_ = "add the missing `;ENDFOLD`"
        out.append(Diagnostic(path, o_line, o_col, *warned, end_line=o_line, end_column=o_end,
                              notes=[note], help=help_))
    out.sort(key=lambda d: (d.line, d.column))
    return out
