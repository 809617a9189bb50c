"""Parsing for the editor: the same results as ``krl check`` (krl/workspace.py ``add_file``:
syntax diagnostics, FOLD balance, the AST and its build diagnostics), with a cache per routine so
that a change re-parses only the routine it touches. tests/lsp/test_parsing.py compares the two.

A .src/.sub file is cut before every line that starts a routine (``[GLOBAL] DEF``/``DEFFCT``)
after the first one; each piece is parsed on its own, its lexer counting lines from the piece's
first line, so that its spans carry the file's own line numbers (a piece with a syntax error is
parsed again preceded by as many empty lines as come before it, so that its messages, which
quote line numbers, are the file's). When every
piece parses, the routines of the pieces form the file's Module (the grammar's ``module`` rule is
a sequence of routines, so the AST is the one of the whole file). When a piece has a syntax
error, its messages are those of the whole file only when the error stays inside the routine:
when it is the only piece with an error and the block scan of the piece (krl/syntax/blocks.py)
finds every block closed, END included, the piece's diagnostics are used; otherwise the whole file is parsed in one go, so that the
messages are exactly those of ``krl check``. Data lists (.dat) and small files are parsed whole.
"""

from __future__ import annotations

import re
from collections import OrderedDict
from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.limits import MAX_FILE_BYTES
from krl.diagnostics import Diagnostic, DiagnosticSink
from krl.syntax.folds import fold_diagnostics
from krl.syntax.messages import syntax_diagnostics
from krl.syntax.parse import parse_source, parse_text
from krl.source import SourceText

_ROUTINE_START = re.compile(r"^[ \t]*(?:GLOBAL[ \t]+)?DEF(?:FCT)?\b", re.IGNORECASE)
_WORD = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")
MIN_CHUNKED_LINES = 200          # smaller files are parsed whole: nothing to gain
CACHE_PIECES = 4096              # parsed pieces kept (least recently used dropped)


@dataclass
class Parsed:
    """One parsed file: what Workspace.add_file would have added for it."""
    path: str
    text: str
    module: N.Module
    ok: bool
    status: str
    diagnostics: list[Diagnostic] = field(default_factory=list)
    failed_words: frozenset = frozenset()
    unreadable: bool = False


def _failed(status: str, ok: bool, text: str) -> tuple[frozenset, bool]:
    if ok:
        return frozenset(), False
    if status in ("binary", "too_large", "unreadable"):
        return frozenset(), True
    return frozenset(w.upper() for w in _WORD.findall(text)), False


def parse_disk(path: str) -> Parsed:
    """A file on disk, read, parsed and built by krl/workspace.py ``load_file`` (what
    ``krl check`` does for each file)."""
    from krl.workspace import load_file  # noqa: PLC0415

    lf = load_file(path)
    return Parsed(lf.path, _text_of(lf), lf.module, lf.ok, lf.status, list(lf.diagnostics),
                  frozenset(lf.failed_words), lf.unreadable)


def _text_of(lf) -> str:
    """The decoded text the editor features work on (load_file keeps only the AST)."""
    from krl.source import read_source  # noqa: PLC0415
    src = read_source(lf.path)
    return src.text if src.status == "ok" else ""


def _not_parsed(path: str, size: int, status: str, detail: str) -> Parsed:
    """A buffer that is not parsed (empty, binary, too large): E001 as for a file."""
    sink = DiagnosticSink()
    result = parse_source(SourceText(path, "", "", size, status, detail))
    sink.add(path, 1, 1, "E001", f"file not checked: {status}" + (f" ({detail})" if detail else ""))
    module = build_module(result, sink)
    return Parsed(path, "", module, False, status, sink.items, frozenset(), status != "empty")


class ParseCache:
    """Parses buffers (text in memory), re-using the pieces that did not change."""

    def __init__(self) -> None:
        self._pieces: OrderedDict[tuple[str, int, str], tuple[N.Module, list[Diagnostic]]] = OrderedDict()
        self.pieces_parsed = 0      # statistics for the benchmark

    def parse(self, path: str, text: str) -> Parsed:
        """Parse a buffer as if it were the file `path` (never raises for bad content)."""
        size = len(text.encode("utf-8", "surrogatepass"))
        if size > MAX_FILE_BYTES:
            return _not_parsed(path, size, "too_large", f"{size} bytes > {MAX_FILE_BYTES}")
        if not text.strip(" \t\r\n\x1a"):
            return _not_parsed(path, size, "empty", "no content")
        if "\x00" in text:
            return _not_parsed(path, size, "binary", "NUL bytes")
        if not path.lower().endswith(".dat"):
            got = self._parse_pieces(path, text)
            if got is not None:
                return got
        return self._whole(path, text)

    def _whole(self, path: str, text: str) -> Parsed:
        sink = DiagnosticSink()
        result = parse_text(text, path)
        sink.extend(syntax_diagnostics(result, text))
        sink.extend(fold_diagnostics(path, text))
        module = build_module(result, sink)
        words, unreadable = _failed(result.status, result.ok, text)
        return Parsed(path, text, module, result.ok, result.status, sink.items, words, unreadable)

    def _parse_pieces(self, path: str, text: str) -> Parsed | None:
        lines = text.split("\n")
        if len(lines) < MIN_CHUNKED_LINES:
            return None
        starts = [i for i, ln in enumerate(lines) if _ROUTINE_START.match(ln)]
        if len(starts) < 2:
            return None
        cuts = [0] + starts[1:] + [len(lines)]
        modules: list[N.Module] = []
        diags: list[Diagnostic] = []
        ok = True
        for a, b in zip(cuts, cuts[1:]):
            piece = "\n".join(lines[a:b])
            if b < len(lines):
                piece += "\n"
            key = (path, a, piece)
            got = self._pieces.get(key)
            if got is None:
                # the lexer counts lines from the piece's first line: spans are the file's
                result = parse_text(piece, path, first_line=a + 1, recover=False)
                self.pieces_parsed += 1
                sink = DiagnosticSink()
                if not result.ok:
                    # messages quote line numbers and lines: parse the piece at its place
                    padded = "\n" * a + piece
                    result = parse_text(padded, path)
                    if result.status != "syntax_error" or not _closed(lines[a:b], a):
                        return None
                    sink.extend(syntax_diagnostics(result, padded))
                got = (build_module(result, sink), sink.items, result.ok)
                self._pieces[key] = got
                while len(self._pieces) > CACHE_PIECES:
                    self._pieces.popitem(last=False)
            else:
                self._pieces.move_to_end(key)
            modules.append(got[0])
            diags.extend(got[1])
            if not got[2]:
                if not ok:
                    return None     # errors in two routines: the whole file says which ones count
                ok = False
        first = modules[0]
        module = N.Module(path, first.kind, list(first.headers),
                          [r for m in modules for r in m.routines], None, span=first.span)
        words, _ = _failed("syntax_error", ok, text)
        sink = DiagnosticSink()
        sink.extend(diags)
        sink.extend(fold_diagnostics(path, text))
        return Parsed(path, text, module, ok, "ok" if ok else "syntax_error", sink.items, words)


def _closed(lines: list[str], offset: int) -> bool:
    """True when the block scan of a piece finds no block finding: every block it opens,
    its routine included, is closed inside it."""
    from krl.lsp.text import line_tokens  # noqa: PLC0415
    from krl.syntax.blocks import Line, scan  # noqa: PLC0415

    if any(len(t) > 4096 for t in lines):
        return False            # line_tokens reads 4 KiB of a line: let the whole file be parsed
    toks = [Line(offset + n, t) for n, text in enumerate(lines, start=1) if (t := line_tokens(text, offset + n))]
    res = scan(toks)
    return res.limit is None and not res.blocks and bool(res.matched)
