"""Parsing for the editor: the same results as ``krl check`` (krl/workspace.py ``add_file``),
with a cache per routine so that a change re-parses only the routine it touches.

A .src/.sub file is cut before every line that starts a routine (``[GLOBAL] DEF``/``DEFFCT``)
after the first one; each piece is parsed on its own, preceded by as many empty lines as come
before it in the file, so its spans and messages carry the file's own line numbers. When every
piece parses, the routines of the pieces form the file's Module (the grammar's ``module`` rule is
a sequence of routines, so the AST is the one of the whole file). When a piece has a syntax
error the whole file is parsed in one go, so that the messages are exactly those of
``krl check``. Data lists (.dat) and small files are parsed whole.
"""

from __future__ import annotations

import re
from collections import OrderedDict
from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.limits import MAX_FILE_BYTES
from krl.semantics.diagnostics import Diagnostic, DiagnosticSink
from krl.syntax.messages import syntax_diagnostics
from krl.syntax.parse import parse_source, parse_text
from krl.syntax.source import SourceText

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


def parse_disk(source: SourceText) -> Parsed:
    """A file read with krl.syntax.source.read_source, exactly as Workspace.add_file does."""
    sink = DiagnosticSink()
    result = parse_source(source)
    if result.status not in ("ok", "syntax_error") and not result.errors:
        sink.add(source.path, 1, 1, "E001", f"file not checked: {result.status}"
                 + (f" ({source.detail})" if source.detail else ""))
    sink.extend(syntax_diagnostics(result, source.text))
    module = build_module(result, sink)
    words, unreadable = _failed(result.status, result.ok, source.text)
    return Parsed(source.path, source.text, module, result.ok, result.status, sink.items, words, unreadable)


class ParseCache:
    """Parses buffers (text in memory), re-using the pieces that did not change."""

    def __init__(self) -> None:
        self._pieces: OrderedDict[tuple[str, int, str], tuple[N.Module, list[Diagnostic]]] = OrderedDict()
        self.pieces_parsed = 0      # statistics for the benchmark

    def parse(self, path: str, text: str) -> Parsed:
        """Parse a buffer as if it were the file `path` (never raises for bad content)."""
        size = len(text.encode("utf-8", "surrogatepass"))
        if size > MAX_FILE_BYTES:
            return parse_disk(SourceText(path, "", "", size, "too_large", f"{size} bytes > {MAX_FILE_BYTES}"))
        if not text.strip(" \t\r\n\x1a"):
            return parse_disk(SourceText(path, "", "", size, "empty", "no content"))
        if "\x00" in text:
            return parse_disk(SourceText(path, "", "", size, "binary", "NUL bytes"))
        if not path.lower().endswith(".dat"):
            got = self._parse_pieces(path, text)
            if got is not None:
                return got
        return self._whole(path, text)

    def _whole(self, path: str, text: str) -> Parsed:
        sink = DiagnosticSink()
        result = parse_text(text, path)
        sink.extend(syntax_diagnostics(result, text))
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
        for a, b in zip(cuts, cuts[1:]):
            piece = "\n".join(lines[a:b])
            if b < len(lines):
                piece += "\n"
            key = (path, a, piece)
            got = self._pieces.get(key)
            if got is None:
                result = parse_text("\n" * a + piece, path)
                self.pieces_parsed += 1
                if not result.ok:
                    return None
                sink = DiagnosticSink()
                got = (build_module(result, sink), sink.items)
                self._pieces[key] = got
                while len(self._pieces) > CACHE_PIECES:
                    self._pieces.popitem(last=False)
            else:
                self._pieces.move_to_end(key)
            modules.append(got[0])
            diags.extend(got[1])
        first = modules[0]
        module = N.Module(path, first.kind, list(first.headers),
                          [r for m in modules for r in m.routines], None, span=first.span)
        return Parsed(path, text, module, True, "ok", diags)
