"""Which lines of a file the AST holds: the lines a file with syntax errors did not give (issue 63).

A KRL file is line-oriented (reference 1.4): each declaration, statement, routine header and
data-list header stands on a line of its own. :func:`lines_not_understood` counts a file's code lines
(not blank, not a comment, not an ``&`` header line, not a block's closer: ``ENDIF``,
``ELSE``, ``END``, ...; those mean nothing of their own once their block is understood) and
returns those on which no node of the AST starts, with the lines the parser reported an error
on (a closer with an error included). So a line the error recovery skipped without an error of
its own (the rest of a routine whose header failed) is not understood too, and the count
"understood of total" is the file's own, whatever the recovery did.
"""

from __future__ import annotations

import re

from krl.ast import nodes as N
from krl.diagnostics.render import split_lines

__all__ = ["lines_not_understood", "code_lines"]

#: the words that close or divide a block: a line starting with one holds no statement of its own
CLOSERS = frozenset({"ENDIF", "ELSE", "ENDFOR", "ENDWHILE", "UNTIL", "ENDLOOP", "ENDSWITCH", "CASE",
                     "DEFAULT", "ENDSPLINE", "END", "ENDFCT", "ENDDAT"})
_FIRST = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")


def _code(text: str) -> str:
    """The line's code: the text before a comment's ``;`` (not inside a string), stripped."""
    quoted = False
    for i, ch in enumerate(text):
        if ch == '"':
            quoted = not quoted
        elif ch == ";" and not quoted:
            return text[:i].strip()
    return text.strip()


def code_lines(text: str) -> list[int]:
    """The 1-based numbers of the lines of `text` that hold code (see the module docstring)."""
    out = []
    for i, line in enumerate(split_lines(text), 1):
        code = _code(line)
        if not code or code.startswith("&"):
            continue
        m = _FIRST.match(code)
        if m is not None and m.group(0).upper() in CLOSERS:
            continue
        out.append(i)
    return out


def lines_not_understood(module: N.Module, text: str, error_lines) -> tuple[list[int], int]:
    """(lines not understood, code lines counted) of a built module and its text; `error_lines`:
    the lines the parser reported an error on. A line on which a node starts (a routine, a data
    list, a declaration, a statement; an :class:`N.Unparsed` node does not count) is understood."""
    starts: set[int] = set()
    for node in module.walk():
        if not isinstance(node, N.Unparsed) and node.span.line:
            starts.add(node.span.line)
    counted = code_lines(text)
    n_lines = text.count("\n") + (0 if text.endswith("\n") else 1)
    errors = {ln for ln in error_lines if 0 < ln <= n_lines}     # not the end of file's line
    lost = sorted(errors | {ln for ln in counted if ln not in starts})
    total = len(set(counted) | errors)
    return lost, total
