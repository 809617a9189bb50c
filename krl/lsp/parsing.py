"""Parsing for the editor: the same results as ``krl check`` (krl/workspace.py ``load_file``:
syntax diagnostics, FOLD balance, the AST and its build diagnostics, the template folds), through
the syntax layer's incremental reparse (krl/syntax/pieces.py: a change re-parses only the piece
it touches, whatever the file's size). tests/lsp/test_parsing.py compares the two on generated
files and on every corpus file.

What is here is the AST side of it: each piece's parse is built into a Module (``build_module``),
a reused piece's AST is moved (every span shifted, in place: :func:`_shift`) instead of parsed
again, so that the workspace's re-check sees the same routine (krl/workspace.py
``Workspace.replace``) and only moves its findings; the pieces' routines (data-list items) form
the file's Module. :meth:`ParseCache.seed` shares a whole-file parse out to the pieces (the first
parse of a file, by the fast engine) so that the first edit parses one piece too. When the syntax
layer says only the whole file can word the errors, the whole file is parsed.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.diagnostics import Diagnostic, DiagnosticSink
from krl.diagnostics.codes import E001
from krl.limits import MAX_FILE_BYTES
from krl.semantics.outside import template_lines
from krl.source import SourceText, read_source
from krl.pool import default_jobs
from krl.syntax.folds import fold_diagnostics
from krl.syntax.messages import syntax_diagnostics
from krl.syntax.parse import parse_source
from krl.syntax.pieces import MIN_CHUNKED_LINES, PieceCache, cut, parse_whole
from krl.workspace import LoadedFile, load_file, record_unparsed

__all__ = ["MIN_CHUNKED_LINES", "ParseCache", "Parsed", "parse_disk"]


@dataclass
class Parsed:
    """One parsed file: its text and what ``Workspace.add_loaded`` takes for it."""
    path: str
    text: str
    loaded: LoadedFile

    @property
    def module(self) -> N.Module:
        return self.loaded.module

    @property
    def ok(self) -> bool:
        return self.loaded.ok

    @property
    def status(self) -> str:
        return self.loaded.status

    @property
    def diagnostics(self) -> list[Diagnostic]:
        return self.loaded.diagnostics

    @property
    def failed_words(self) -> set:
        return self.loaded.failed_words

    @property
    def unreadable(self) -> bool:
        return self.loaded.unreadable


def _failed(status: str, ok: bool, text: str, module: N.Module, diags: list) -> tuple[set, bool]:
    if ok:
        return set(), False
    if status in ("binary", "too_large", "unreadable"):
        return set(), True
    return (record_unparsed(module, text, diags) if text else set()), False


def parse_disk(path: str) -> Parsed:
    """A file on disk, read, parsed and built by krl/workspace.py ``load_file`` (what
    ``krl check`` does for each file)."""
    lf = load_file(path)
    src = read_source(path)
    return Parsed(lf.path, src.text if src.status == "ok" else "", lf)


def _loaded(path: str, text: str, module: N.Module, ok: bool, status: str, diags: list,
            unreadable: bool = False, seconds: float = 0.0) -> LoadedFile:
    words, gone = _failed(status, ok, text, module, diags)
    return LoadedFile(path, module, ok, status, seconds, 0.0, diags, unreadable or gone, words,
                      template_lines(text))


def _not_parsed(path: str, text: str, size: int, status: str, detail: str) -> Parsed:
    """A buffer that is not parsed (empty, binary, too large): E001 as for a file."""
    sink = DiagnosticSink()
    result = parse_source(SourceText(path, "", "", size, status, detail))
    sink.add(path, 1, 1, *E001("not_checked", why=status + (f" ({detail})" if detail else "")))
    module = build_module(result, sink)
    lf = LoadedFile(path, module, False, status, 0.0, 0.0, sink.items, status != "empty", set(),
                    (frozenset(), frozenset()))
    return Parsed(path, "", lf)


def _shift(module: N.Module, delta: int) -> None:
    """Move a piece's AST `delta` lines down (up when negative), in place: every span of its
    routines (data-list items), and the END line of routines."""
    span = N.Span
    nodes = module.routines or (module.data.items if module.data is not None else ())
    for top in nodes:
        for n in top.walk():
            s = n.span
            n.span = span(s.file, s.line + delta, s.column)
            if isinstance(n, N.Routine) and n.end_line:
                n.end_line += delta


def _build_code(result, sink: DiagnosticSink) -> N.Module:
    return build_module(result, sink)


def _build_data(result, sink: DiagnosticSink) -> N.Module | None:
    module = build_module(result, sink)
    return module if module.data is not None else None


class ParseCache:
    """Parses buffers (text in memory), re-using the pieces that did not change (see the
    module docstring; the pieces are krl/syntax/pieces.py's)."""

    def __init__(self, fast: bool = True) -> None:
        self.fast = fast            # pieces parsed by the fast engine when it runs here
        jobs = default_jobs()
        self._code = PieceCache(_build_code, _shift, fast, jobs)
        self._data = PieceCache(_build_data, _shift, fast, jobs)

    @property
    def pieces_parsed(self) -> int:
        """Pieces parsed so far (statistics for the benchmark and the tests)."""
        return self._code.pieces_parsed + self._data.pieces_parsed

    def parse(self, path: str, text: str) -> Parsed:
        """Parse a buffer as if it were the file `path` (never raises for bad content)."""
        t = time.perf_counter()
        size = len(text.encode("utf-8", "surrogatepass"))
        if size > MAX_FILE_BYTES:
            return _not_parsed(path, text, size, "too_large", f"{size} bytes > {MAX_FILE_BYTES}")
        if not text.strip(" \t\r\n\x1a"):
            return _not_parsed(path, text, size, "empty", "no content")
        if "\x00" in text:
            return _not_parsed(path, text, size, "binary", "NUL bytes")
        got = self._parse_pieces(path, text, t)
        return got if got is not None else self._whole(path, text, t)

    def _whole(self, path: str, text: str, started: float) -> Parsed:
        sink = DiagnosticSink()
        result = parse_whole(text, path, self.fast, default_jobs())
        sink.extend(syntax_diagnostics(result, text))
        sink.extend(fold_diagnostics(path, text))
        module = build_module(result, sink)
        return Parsed(path, text, _loaded(path, text, module, result.ok, result.status, sink.items,
                                          seconds=time.perf_counter() - started))

    def _parse_pieces(self, path: str, text: str, started: float) -> Parsed | None:
        data = path.lower().endswith(".dat")
        pieces = (self._data if data else self._code).pieces(path, text)
        if pieces is None:
            return None
        ok = all(p.ok for p in pieces)
        first = pieces[0].value
        if data:
            dl = first.data
            items = [it for p in pieces for it in p.value.data.items]
            module = N.Module(path, "dat", list(first.headers), [],
                              N.DataList(dl.name, items, dl.public, span=dl.span), span=first.span)
        else:
            module = N.Module(path, first.kind, list(first.headers),
                              [r for p in pieces for r in p.value.routines], None, span=first.span)
        sink = DiagnosticSink()
        for p in pieces:
            sink.extend(p.diagnostics)
        sink.extend(fold_diagnostics(path, text))
        return Parsed(path, text, _loaded(path, text, module, ok, "ok" if ok else "syntax_error", sink.items,
                                          seconds=time.perf_counter() - started))

    def seed(self, parsed: Parsed) -> bool:
        """Keep the pieces of a whole-file parse (the disk file's, or the fast engine's first
        parse of a buffer) as if each had been parsed alone: its routines, or its data-list
        items, share out by the lines of the cuts. Only a file that parsed with nothing but
        FOLD findings is used (a piece's own parse would have the same AST and no finding).
        Returns True when the pieces were kept."""
        lf = parsed.loaded
        if not lf.ok or not parsed.text:
            return False
        got = cut(parsed.path, parsed.text)
        if got is None:
            return False
        lines, cuts = got
        if len(lf.diagnostics) != len(fold_diagnostics(parsed.path, parsed.text)):
            return False
        mod, path = lf.module, parsed.path
        data = path.lower().endswith(".dat")
        if data:
            if mod.data is None or mod.routines:
                return False
            nodes = mod.data.items
        else:
            nodes = mod.routines
            if mod.data is not None or len(nodes) != len(cuts) - 1:
                return False
        groups: list[list] = [[] for _ in cuts[1:]]
        k = 0
        for n in nodes:
            line = n.span.line - 1
            while k < len(groups) and line >= cuts[k + 1]:
                k += 1
            if k >= len(groups) or line < cuts[k]:
                return False
            groups[k].append(n)
        if not data and any(len(g) != 1 for g in groups):
            return False
        values = []
        for k, group in enumerate(groups):
            if data:
                dl = mod.data
                values.append(N.Module(path, "dat", list(mod.headers) if k == 0 else [], [],
                                       N.DataList(dl.name, group, dl.public, span=dl.span), span=mod.span))
            else:
                values.append(N.Module(path, mod.kind, list(mod.headers) if k == 0 else [], group, None,
                                       span=mod.span))
        (self._data if data else self._code).keep(path, lines, cuts, values)
        return True
