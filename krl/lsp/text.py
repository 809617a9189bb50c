"""Lines, positions and the tokens of one line.

KRL spans are 1-based lines and 1-based columns counted in characters (krl/ast/nodes.py); LSP
positions are 0-based lines and 0-based columns in the negotiated code units (UTF-16 unless the
client chose another). A ``codec`` is pygls' PositionCodec (``client_num_units``); None means
characters. KRL is line-oriented and its lexer never carries state from one line to the next, so
the tokens of one line are the tokens of the ANTLR lexer on that line alone
(:func:`line_tokens`, krl/syntax/blocks.py ``Tok``: word, text, 1-based line and column).
"""

from __future__ import annotations

from functools import lru_cache

from lsprotocol import types as L

from krl.syntax.blocks import Tok, lines_of

NAME_WORDS = ("IDENTIFIER", "SYSNAME")


def units(codec, s: str) -> int:
    return codec.client_num_units(s) if codec is not None else len(s)


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


@lru_cache(maxsize=8192)
def _lex(line_text: str) -> tuple[Tok, ...]:
    from krl.syntax.parse import default_bundle  # noqa: PLC0415
    from krl.syntax.tokens import lex  # noqa: PLC0415

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
