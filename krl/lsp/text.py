"""Lines, code units and the tokens of one line.

KRL spans are 1-based lines and 1-based columns counted in characters (krl/ast/nodes.py); LSP
positions are 0-based lines and 0-based columns in the negotiated code units (UTF-16 unless the
client chose another): the shell converts them (krl/lsp/convert.py ``to_position``). A ``codec``
is pygls' PositionCodec (``client_num_units``); None means characters (:func:`units`). KRL is
line-oriented and its lexer never carries state from one line to the next, so
the tokens of one line are the tokens of the ANTLR lexer on that line alone
(:func:`line_tokens`, krl/syntax/blocks.py ``Tok``: word, text, 1-based line and column).
"""

from __future__ import annotations

from functools import lru_cache

from krl.syntax.blocks import Tok, lines_of
from krl.syntax.parse import default_bundle
from krl.syntax.tokens import lex

NAME_WORDS = ("IDENTIFIER", "SYSNAME")


def units(codec, s: str) -> int:
    return codec.client_num_units(s) if codec is not None else len(s)


@lru_cache(maxsize=8192)
def _lex(line_text: str) -> tuple[Tok, ...]:
    bundle = default_bundle()
    out: list[Tok] = []
    for ln in lines_of(lex(line_text + "\n", bundle), bundle):
        out.extend(ln.toks)
    return tuple(out)


def line_tokens(line_text: str, line_no: int = 1) -> list[Tok]:
    """The default-channel tokens of one line (comments left out), 1-based columns, on line `line_no`."""
    if len(line_text) > 4096:       # a hostile line: navigation looks at its first 4 KiB only
        line_text = line_text[:4096]
    return [Tok(t.word, t.text, line_no, t.column) for t in _lex(line_text)]


def token_at(lines: list[str], line: int, column: int) -> tuple[int, Tok | None, list[Tok]]:
    """(index, token, tokens of the line) for the token under 1-based (line, column); a
    position just after a name counts as on it (the cursor at the end of a word)."""
    text = lines[line - 1] if 0 < line <= len(lines) else ""
    toks = line_tokens(text, line)
    for i, t in enumerate(toks):
        if t.column <= column < t.column + len(t.text):
            return i, t, toks
    for i, t in enumerate(toks):
        if t.column + len(t.text) == column and t.word in NAME_WORDS:
            return i, t, toks
    return -1, None, toks


def find_name(lines: list[str], line: int, name: str, from_column: int = 1) -> int:
    """The 1-based column of the first name token `name` (any case) on `line` at or after
    `from_column`, else 0."""
    if not 0 < line <= len(lines):
        return 0
    key = name.upper()
    for t in line_tokens(lines[line - 1], line):
        if t.column >= from_column and t.text.upper() == key and t.word in NAME_WORDS + ("ENUMLITERAL",):
            return t.column
        if t.column >= from_column and t.word == "ENUMLITERAL" and t.text[1:].upper() == key:
            return t.column + 1
    # a keyword used as a name (soft keyword): match the text
    for t in line_tokens(lines[line - 1], line):
        if t.column >= from_column and t.text.upper() == key:
            return t.column
    return 0
