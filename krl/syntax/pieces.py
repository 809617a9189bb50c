"""The incremental reparse: a file's text cut into pieces, each parsed on its own and kept by its
text, so that a change re-parses only the piece it touches, whatever the file's size.

**Pieces.** A .src/.sub file is cut before every line that starts a routine (``[GLOBAL] DEF``/
``DEFFCT``) after the first one; a .dat file is cut between declaration lines where the line's
content says so (a content-defined cut, :func:`data_cuts`, so that an inserted line moves no
other cut). Each piece is parsed on its own, its lexer counting lines from the piece's first
line, so that its spans carry the file's own line numbers (a .dat piece is parsed between a
``DEFDAT`` and an ``ENDDAT`` line of its own). The grammar's ``module`` rule is a sequence of
routines (a data list a sequence of declaration lines), so the pieces' routines (data-list
items) are the whole file's. Files under :data:`MIN_CHUNKED_LINES` lines are not cut.

**Reuse.** A piece that parsed is kept by its text, not by its place: when lines are inserted
or removed above it, what was built from it is moved (the caller's `shift`) instead of parsed
again. :meth:`PieceCache.keep` fills the pieces from a whole-file parse, so that the first edit
parses one piece too.

**Engines.** A piece is parsed by the fast (Java) engine when it runs here (its worker is one
long-lived process: a request costs a few milliseconds, where the Python engine takes tens of
milliseconds for a routine it has not seen constructs of), else by the Python engine.

**Errors.** A piece with a syntax error is parsed again preceded by as many empty lines as
come before it, so that its messages, which quote line numbers, are the file's. Its messages
are those of the whole file only when the error stays inside the routine: when it is the only
piece with an error and the block scan of the piece (krl/syntax/blocks.py) finds every block
closed, END included; otherwise (and for any error in a .dat piece) :meth:`PieceCache.pieces`
returns None and the caller parses the whole file (:func:`parse_whole`), so that the messages
are exactly those of ``krl check``.

What a piece's parse is built into (the AST: krl/lsp/parsing.py gives ``build_module`` and a
span shift) is the caller's: this layer parses and keeps, it does not read the trees.
"""

from __future__ import annotations

import re
import zlib
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, TypeVar

from krl.diagnostics import DiagnosticSink
from krl.source import SourceText
from krl.syntax.blocks import lines_of, scan
from krl.syntax.engines import java_answers, parse_piece, result_from_answer, unavailable_reason
from krl.syntax.messages import syntax_diagnostics
from krl.syntax.parse import ParseResult, default_bundle, parse_text
from krl.syntax.tokens import lex

_ROUTINE_START = re.compile(r"^[ \t]*(?:GLOBAL[ \t]+)?DEF(?:FCT)?\b", re.IGNORECASE)
_DEFDAT = re.compile(r"^[ \t]*DEFDAT\b", re.IGNORECASE)
_ENDDAT = re.compile(r"^[ \t]*ENDDAT\b", re.IGNORECASE)
MIN_CHUNKED_LINES = 200          # smaller files are parsed whole: nothing to gain
CACHE_PIECES = 8192              # parsed pieces kept (least recently used dropped)
DATA_PIECE_LINES = (8, 64)       # a .dat piece holds at least / at most this many lines
DATA_CUT = 16                    # ... and is cut before a line whose CRC32 is 0 modulo this
MAX_SCANNED_LINE = 4096          # a longer line in an erroneous piece: the whole file is parsed

V = TypeVar("V")
#: builds a piece's value from its parse, adding findings to the sink; None: not a piece
#: (the whole file is parsed then)
Build = Callable[[ParseResult, DiagnosticSink], "V | None"]


@dataclass(eq=False)
class Piece(Generic[V]):
    """A parsed piece: what the caller built from it (``value``), the line its first line has
    now (1-based), and, for a piece that does not parse, its diagnostics (then it is kept for
    that place only)."""
    value: V
    first: int
    ok: bool
    diagnostics: list


def code_cuts(lines: list[str]) -> list[int] | None:
    """Cuts (0-based line indices, first 0, last ``len(lines)``) of a .src/.sub file: before
    every routine start after the first; None for fewer than two routines."""
    starts = [i for i, ln in enumerate(lines) if _ROUTINE_START.match(ln)]
    if len(starts) < 2:
        return None
    return [0] + starts[1:] + [len(lines)]


def data_cuts(lines: list[str]) -> list[int] | None:
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


def cut(path: str, text: str) -> tuple[list[str], list[int]] | None:
    """The lines of `text` and its cuts (by `path`'s extension), or None when it is parsed whole."""
    lines = text.split("\n")
    if len(lines) < MIN_CHUNKED_LINES:
        return None
    cuts = data_cuts(lines) if path.lower().endswith(".dat") else code_cuts(lines)
    return (lines, cuts) if cuts is not None else None


def piece_text(lines: list[str], a: int, b: int) -> str:
    """The text of lines ``a`` .. ``b - 1`` (0-based), with its line end unless it is the last."""
    piece = "\n".join(lines[a:b])
    return piece + "\n" if b < len(lines) else piece


def parse_whole(text: str, path: str, fast: bool = True, jobs: int = 1) -> ParseResult:
    """A whole text parsed with error recovery and messages (``parse_text``), by the fast
    engine (`jobs` threads) when `fast` and it runs here (the same result:
    tests/syntax/test_engines.py)."""
    if fast and unavailable_reason() is None:
        src = SourceText(path, text, "", len(text.encode("utf-8", "surrogatepass")))
        [(_k, src, raw)] = list(java_answers([(0, src)], threads=jobs, trees=True))
        return result_from_answer(src, raw, keep_tree=True)     # the Python engine when raw is None
    return parse_text(text, path)


class PieceCache(Generic[V]):
    """The pieces of the texts parsed so far (least recently used dropped past CACHE_PIECES),
    each with the value `build` made of it; `shift(value, delta)` moves a value `delta` lines
    (a reused piece's new place). `fast`: pieces parsed by the fast engine when it runs here,
    with `jobs` threads."""

    def __init__(self, build: Build, shift: Callable[[V, int], None], fast: bool = True,
                 jobs: int = 1) -> None:
        self._pieces: OrderedDict[tuple, Piece[V]] = OrderedDict()
        self._build = build
        self._shift = shift
        self.pieces_parsed = 0      # statistics for the benchmark and the tests
        self.fast = fast
        self.jobs = jobs

    def pieces(self, path: str, text: str) -> list[Piece[V]] | None:
        """The pieces of `text` (as the file `path`), in order, each reused or parsed; None when
        the text is parsed whole (small, not cut, or errors only the whole file words right)."""
        got = cut(path, text)
        if got is None:
            return None
        lines, cuts = got
        data = path.lower().endswith(".dat")
        out: list[Piece[V]] = []
        used: set[int] = set()
        bad = 0
        for k, (a, b) in enumerate(zip(cuts, cuts[1:])):
            piece = piece_text(lines, a, b)
            key = (path, k == 0, piece)
            p = self._pieces.get(key)
            if p is None or id(p) in used:
                key = (path, k == 0, piece, a)          # a piece with an error: at this place only
                p = self._pieces.get(key)
            if p is not None and id(p) not in used:
                self._pieces.move_to_end(key)
                if p.first != a + 1:
                    self._shift(p.value, a + 1 - p.first)
                    p.first = a + 1
            else:
                p = self._parse_piece(path, lines, a, b, piece, k, data)
                if p is None:
                    return None     # the whole file says which errors count
                key = (path, k == 0, piece) if p.ok else (path, k == 0, piece, a)
                if key not in self._pieces:
                    self._pieces[key] = p
                    self._trim()
            used.add(id(p))
            if not p.ok:
                bad += 1
                if bad > 1:
                    return None     # errors in two pieces: the whole file says which ones count
            out.append(p)
        return out

    def keep(self, path: str, lines: list[str], cuts: list[int], values: list[V]) -> None:
        """Keep `values` (one per piece of ``cut(path, text)``, from a whole-file parse that had
        no syntax error) as if each piece had been parsed alone."""
        for k, (a, b) in enumerate(zip(cuts, cuts[1:])):
            self._pieces[(path, k == 0, piece_text(lines, a, b))] = Piece(values[k], a + 1, True, [])
        self._trim()

    def _trim(self) -> None:
        while len(self._pieces) > CACHE_PIECES:
            self._pieces.popitem(last=False)

    def _parse_piece(self, path: str, lines: list[str], a: int, b: int, piece: str, k: int,
                     data: bool) -> Piece[V] | None:
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
                result = parse_whole(padded, path, self.fast, self.jobs)
                if result.status != "syntax_error":
                    return None
                sink.extend(syntax_diagnostics(result, padded))
            value = self._build(result, sink)
            return Piece(value, a + 1, result.ok, sink.items) if value is not None else None
        # the lexer counts lines from the piece's first line: spans are the file's
        result = self._parse(piece, path, a + 1)
        sink = DiagnosticSink()
        if result.ok:
            value = self._build(result, sink)
            return Piece(value, a + 1, True, sink.items) if value is not None else None
        # messages quote line numbers and lines: parse the piece at its place
        padded = "\n" * a + piece
        result = parse_whole(padded, path, self.fast, self.jobs)
        if result.status != "syntax_error" or not closed(lines[a:b]):
            return None
        sink.extend(syntax_diagnostics(result, padded))
        value = self._build(result, sink)
        return Piece(value, a + 1, False, sink.items) if value is not None else None

    def _parse(self, text: str, path: str, first_line: int) -> ParseResult:
        """One piece, by the fast engine when it runs here (with its tree), else by the Python
        engine: a ParseResult, not ok (without errors) when the piece does not parse."""
        if self.fast:
            got = parse_piece(text, path, first_line, self.jobs)
            if got is not None:
                return got
        return parse_text(text, path, first_line=first_line, recover=False)


def closed(lines: list[str]) -> bool:
    """True when the block scan of a piece's `lines` finds no block finding: every block it
    opens, its routine included, is closed inside it. KRL's lexer carries no state from one
    line to the next, so the lines are lexed as one text."""
    if any(len(t) > MAX_SCANNED_LINE for t in lines):
        return False
    bundle = default_bundle()
    res = scan(lines_of(lex("\n".join(lines) + "\n", bundle), bundle))
    return res.limit is None and not res.blocks and bool(res.matched)
