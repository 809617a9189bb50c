"""Parsing for the editor: the same results as ``krl check`` (krl/workspace.py ``load_file``:
syntax diagnostics, FOLD balance, the AST and its build diagnostics, the template folds), with
a cache of pieces so that a change re-parses only the piece it touches, whatever the file's size.
tests/lsp/test_parsing.py compares the two on generated files and on every corpus file.

**Pieces.** A .src/.sub file is cut before every line that starts a routine (``[GLOBAL] DEF``/
``DEFFCT``) after the first one; a .dat file is cut between declaration lines where the line's
content says so (a content-defined cut, :func:`_data_cuts`, so that an inserted line moves no
other cut). Each piece is parsed on its own, its lexer counting lines from the piece's first
line, so that its spans carry the file's own line numbers (a .dat piece is parsed between a
``DEFDAT`` and an ``ENDDAT`` line of its own). When every piece parses, the routines (data-list
items) of the pieces form the file's Module: the grammar's ``module`` rule is a sequence of
routines (a data list a sequence of declaration lines), so the AST is the one of the whole file.

**Reuse.** A piece that parsed is kept by its text, not by its place: when lines are inserted
or removed above it, its AST is moved (every span shifted, in place: :func:`_shift`) instead of
parsed again, so that the workspace's re-check sees the same routine (krl/workspace.py
``Workspace.replace``) and only moves its findings. :meth:`ParseCache.seed` fills the pieces
from a whole-file parse (the first parse of a file, by the fast engine) so that the first edit
parses one piece too.

**Engines.** A piece is parsed by the fast (Java) engine when it runs here (its worker is one
long-lived process: a request costs a few milliseconds, where the Python engine takes tens of
milliseconds for a routine it has not seen constructs of), else by the Python engine.

**Errors.** A piece with a syntax error is parsed again preceded by as many empty lines as
come before it, so that its messages, which quote line numbers, are the file's. Its messages
are those of the whole file only when the error stays inside the routine: when it is the only
piece with an error and the block scan of the piece (krl/syntax/blocks.py) finds every block
closed, END included; otherwise (and for any error in a .dat piece) the whole file is parsed in
one go, so that the messages are exactly those of ``krl check``. Small files are parsed whole.
"""

from __future__ import annotations

import re
import time
import zlib
from collections import OrderedDict
from dataclasses import dataclass

from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.diagnostics import Diagnostic, DiagnosticSink
from krl.diagnostics.codes import E001
from krl.limits import MAX_FILE_BYTES
from krl.semantics.outside import template_lines
from krl.source import SourceText, read_source
from krl.pool import default_jobs
from krl.syntax.engines import java_answers, parse_piece, result_from_answer, unavailable_reason
from krl.syntax.folds import fold_diagnostics
from krl.syntax.messages import syntax_diagnostics
from krl.syntax.parse import parse_source, parse_text
from krl.workspace import LoadedFile, load_file

_ROUTINE_START = re.compile(r"^[ \t]*(?:GLOBAL[ \t]+)?DEF(?:FCT)?\b", re.IGNORECASE)
_DEFDAT = re.compile(r"^[ \t]*DEFDAT\b", re.IGNORECASE)
_ENDDAT = re.compile(r"^[ \t]*ENDDAT\b", re.IGNORECASE)
_WORD = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")
MIN_CHUNKED_LINES = 200          # smaller files are parsed whole: nothing to gain
CACHE_PIECES = 8192              # parsed pieces kept (least recently used dropped)
DATA_PIECE_LINES = (8, 64)       # a .dat piece holds at least / at most this many lines
DATA_CUT = 16                    # ... and is cut before a line whose CRC32 is 0 modulo this


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


def _failed(status: str, ok: bool, text: str) -> tuple[set, bool]:
    if ok:
        return set(), False
    if status in ("binary", "too_large", "unreadable"):
        return set(), True
    return {w.upper() for w in _WORD.findall(text)}, False


def parse_disk(path: str) -> Parsed:
    """A file on disk, read, parsed and built by krl/workspace.py ``load_file`` (what
    ``krl check`` does for each file)."""
    lf = load_file(path)
    src = read_source(path)
    return Parsed(lf.path, src.text if src.status == "ok" else "", lf)


def _loaded(path: str, text: str, module: N.Module, ok: bool, status: str, diags: list,
            unreadable: bool = False, seconds: float = 0.0) -> LoadedFile:
    words, gone = _failed(status, ok, text)
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


@dataclass(eq=False)
class _Piece:
    """A parsed piece: its AST (a Module of its routines, or of its data-list items), the line
    its first line has now (1-based), and, for a piece that does not parse, its diagnostics
    (then it is kept for that place only)."""
    module: N.Module
    first: int
    ok: bool
    diagnostics: list


def _shift(nodes, delta: int) -> None:
    """Move parsed nodes `delta` lines down (up when negative), in place: every span, and the
    END line of routines."""
    span = N.Span
    for top in nodes:
        for n in top.walk():
            s = n.span
            n.span = span(s.file, s.line + delta, s.column)
            if isinstance(n, N.Routine) and n.end_line:
                n.end_line += delta


def _code_cuts(lines: list[str]) -> list[int] | None:
    starts = [i for i, ln in enumerate(lines) if _ROUTINE_START.match(ln)]
    if len(starts) < 2:
        return None
    return [0] + starts[1:] + [len(lines)]


def _data_cuts(lines: list[str]) -> list[int] | None:
    """Cuts of a data list: after its DEFDAT line and before its ENDDAT line, between lines, each
    piece DATA_PIECE_LINES long; a cut falls before a line whose content hashes to 0 modulo
    DATA_CUT, so that the cuts follow the content, not the line numbers."""
    head = next((i for i, ln in enumerate(lines) if _DEFDAT.match(ln)), None)
    if head is None:
        return None
    end = next((i for i in range(len(lines) - 1, head, -1) if _ENDDAT.match(lines[i])), None)
    if end is None:
        return None
    low, high = DATA_PIECE_LINES
    cuts = [0]
    last = head + 1
    for i in range(head + 1, end):
        if i - last >= high or (i - last >= low and zlib.crc32(lines[i].encode("utf-8", "surrogatepass")) % DATA_CUT == 0):
            cuts.append(i)
            last = i
    if len(cuts) < 2:
        return None
    return cuts + [len(lines)]


class ParseCache:
    """Parses buffers (text in memory), re-using the pieces that did not change (see the
    module docstring)."""

    def __init__(self, fast: bool = True) -> None:
        self._pieces: OrderedDict[tuple, _Piece] = OrderedDict()
        self.pieces_parsed = 0      # statistics for the benchmark and the tests
        self.fast = fast            # pieces parsed by the fast engine when it runs here

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

    def _full(self, text: str, path: str):
        """A whole text parsed with error recovery and messages (``parse_text``), by the fast
        engine when it runs here (the same result: tests/syntax/test_engines.py)."""
        if self.fast and unavailable_reason() is None:
            src = SourceText(path, text, "", len(text.encode("utf-8", "surrogatepass")))
            [(_k, src, raw)] = list(java_answers([(0, src)], threads=default_jobs(), trees=True))
            return result_from_answer(src, raw, keep_tree=True)     # the Python engine when raw is None
        return parse_text(text, path)

    def _whole(self, path: str, text: str, started: float) -> Parsed:
        sink = DiagnosticSink()
        result = self._full(text, path)
        sink.extend(syntax_diagnostics(result, text))
        sink.extend(fold_diagnostics(path, text))
        module = build_module(result, sink)
        return Parsed(path, text, _loaded(path, text, module, result.ok, result.status, sink.items,
                                          seconds=time.perf_counter() - started))

    @staticmethod
    def _cut(path: str, text: str) -> tuple[list[str], list[int]] | None:
        lines = text.split("\n")
        if len(lines) < MIN_CHUNKED_LINES:
            return None
        cuts = _data_cuts(lines) if path.lower().endswith(".dat") else _code_cuts(lines)
        return (lines, cuts) if cuts is not None else None

    @staticmethod
    def _piece_text(lines: list[str], a: int, b: int) -> str:
        piece = "\n".join(lines[a:b])
        return piece + "\n" if b < len(lines) else piece

    def _parse_pieces(self, path: str, text: str, started: float) -> Parsed | None:
        got = self._cut(path, text)
        if got is None:
            return None
        lines, cuts = got
        data = path.lower().endswith(".dat")
        pieces: list[_Piece] = []
        used: set[int] = set()
        bad = 0
        for k, (a, b) in enumerate(zip(cuts, cuts[1:])):
            piece = self._piece_text(lines, a, b)
            key = (path, k == 0, piece)
            p = self._pieces.get(key)
            if p is None or id(p) in used:
                key = (path, k == 0, piece, a)          # a piece with an error: at this place only
                p = self._pieces.get(key)
            if p is not None and id(p) not in used:
                self._pieces.move_to_end(key)
                if p.first != a + 1:
                    _shift(p.module.routines or (p.module.data.items if p.module.data is not None else ()),
                           a + 1 - p.first)
                    p.first = a + 1
            else:
                p = self._parse_piece(path, lines, a, b, piece, k, data)
                if p is None:
                    return None     # the whole file says which errors count
                key = (path, k == 0, piece) if p.ok else (path, k == 0, piece, a)
                if key not in self._pieces:
                    self._pieces[key] = p
                    while len(self._pieces) > CACHE_PIECES:
                        self._pieces.popitem(last=False)
            used.add(id(p))
            if not p.ok:
                bad += 1
                if bad > 1:
                    return None     # errors in two pieces: the whole file says which ones count
            pieces.append(p)
        ok = bad == 0
        first = pieces[0].module
        if data:
            dl = first.data
            if dl is None or any(p.module.data is None for p in pieces):
                return None
            items = [it for p in pieces for it in p.module.data.items]
            module = N.Module(path, "dat", list(first.headers), [],
                              N.DataList(dl.name, items, dl.public, span=dl.span), span=first.span)
        else:
            module = N.Module(path, first.kind, list(first.headers),
                              [r for p in pieces for r in p.module.routines], None, span=first.span)
        sink = DiagnosticSink()
        for p in pieces:
            sink.extend(p.diagnostics)
        sink.extend(fold_diagnostics(path, text))
        return Parsed(path, text, _loaded(path, text, module, ok, "ok" if ok else "syntax_error", sink.items,
                                          seconds=time.perf_counter() - started))

    def _parse_piece(self, path: str, lines: list[str], a: int, b: int, piece: str, k: int,
                     data: bool) -> _Piece | None:
        """Parse one piece at its place; None when only the whole file can say what is wrong."""
        self.pieces_parsed += 1
        if data:
            # a data list's piece between a DEFDAT and an ENDDAT of its own (the header on the
            # line before the piece's first line, so that the piece's lines keep their numbers)
            body = piece if k == 0 else "DEFDAT PIECE\n" + piece
            if b < len(lines):
                body += "ENDDAT\n"
            result = self._parse(body, path, 1 if k == 0 else a)
            sink = DiagnosticSink()
            if not result.ok:
                # at its place, for the messages; the error stays on its line (a data list has no
                # blocks), unless a line ends the data list early
                if any(_ENDDAT.match(ln) for ln in lines[a:b]) and b < len(lines):
                    return None
                padded = ("\n" * a + piece) if k == 0 else ("\n" * (a - 1) + "DEFDAT PIECE\n" + piece)
                if b < len(lines):
                    padded += "ENDDAT\n"
                result = self._full(padded, path)
                if result.status != "syntax_error":
                    return None
                sink.extend(syntax_diagnostics(result, padded))
            module = build_module(result, sink)
            return _Piece(module, a + 1, result.ok, sink.items) if module.data is not None else None
        # the lexer counts lines from the piece's first line: spans are the file's
        result = self._parse(piece, path, a + 1)
        sink = DiagnosticSink()
        if result.ok:
            return _Piece(build_module(result, sink), a + 1, True, sink.items)
        # messages quote line numbers and lines: parse the piece at its place
        padded = "\n" * a + piece
        result = self._full(padded, path)
        if result.status != "syntax_error" or not _closed(lines[a:b], a):
            return None
        sink.extend(syntax_diagnostics(result, padded))
        return _Piece(build_module(result, sink), a + 1, False, sink.items)

    def _parse(self, text: str, path: str, first_line: int):
        """One piece, by the fast engine when it runs here (with its tree), else by the Python
        engine: a ParseResult, not ok (without errors) when the piece does not parse."""
        if self.fast:
            got = parse_piece(text, path, first_line, default_jobs())
            if got is not None:
                return got
        return parse_text(text, path, first_line=first_line, recover=False)

    def seed(self, parsed: Parsed) -> bool:
        """Keep the pieces of a whole-file parse (the disk file's, or the fast engine's first
        parse of a buffer) as if each had been parsed alone: its routines, or its data-list
        items, share out by the lines of the cuts. Only a file that parsed with nothing but
        FOLD findings is used (a piece's own parse would have the same AST and no finding).
        Returns True when the pieces were kept."""
        lf = parsed.loaded
        if not lf.ok or not parsed.text:
            return False
        got = self._cut(parsed.path, parsed.text)
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
        for k, (a, b) in enumerate(zip(cuts, cuts[1:])):
            if data:
                dl = mod.data
                m = N.Module(path, "dat", list(mod.headers) if k == 0 else [], [],
                             N.DataList(dl.name, groups[k], dl.public, span=dl.span), span=mod.span)
            else:
                m = N.Module(path, mod.kind, list(mod.headers) if k == 0 else [], groups[k], None, span=mod.span)
            key = (path, k == 0, self._piece_text(lines, a, b))
            self._pieces[key] = _Piece(m, a + 1, True, [])
        while len(self._pieces) > CACHE_PIECES:
            self._pieces.popitem(last=False)
        return True


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
