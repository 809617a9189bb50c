"""The syntax layer's incremental reparse (krl/syntax/pieces.py) on its own, with a value that is
not an AST: which pieces are parsed again after an edit, and by how many lines a kept one moves.
tests/lsp/test_parsing.py checks the language server's use of it against ``krl check``."""

from __future__ import annotations

from krl.syntax.pieces import MIN_CHUNKED_LINES, PieceCache, code_cuts, cut


def _file(routines: int, body: int) -> str:
    out = []
    for r in range(routines):
        out.append(f"DEF r{r}()" if r == 0 else f"GLOBAL DEF r{r}()")
        out += [f"  i = {r * 1000 + k}" for k in range(body)]
        out.append("END")
    return "\n".join(out) + "\n"


class _Recorder:
    """A piece's value: the first line it was parsed at, moved by `shift`."""

    def __init__(self) -> None:
        self.shifts: list[int] = []

    def build(self, result, sink):
        return {"ok": result.ok, "line": result.tree.start.line if result.tree is not None else None}

    def shift(self, value, delta):
        self.shifts.append(delta)
        value["line"] += delta


def test_an_edit_reparses_the_piece_it_touches_and_moves_the_rest():
    text = _file(5, 60)
    assert len(text.split("\n")) >= MIN_CHUNKED_LINES
    lines, cuts = cut("x.src", text)
    assert cuts == code_cuts(lines) and len(cuts) == 6
    rec = _Recorder()
    cache = PieceCache(rec.build, rec.shift, fast=False)
    first = cache.pieces("x.src", text)
    assert cache.pieces_parsed == 5 and all(p.ok for p in first)
    assert [p.value["line"] for p in first] == [c + 1 for c in cuts[:-1]]
    # two lines inserted into the second routine: it is parsed again, the three after it move
    edited = text.replace("  i = 1000\n", "  i = 1000\n  j = 1\n  j = 2\n")
    again = cache.pieces("x.src", edited)
    assert cache.pieces_parsed == 6
    assert rec.shifts == [2, 2, 2]
    assert again[0] is first[0] and again[1] is not first[1] and again[4] is first[4]
    assert [p.value["line"] for p in again] == [c + 1 for c in cut("x.src", edited)[1][:-1]]


def test_an_error_that_leaves_its_routine_open_is_for_the_whole_file():
    text = _file(5, 60)
    cache = PieceCache(lambda r, s: r.ok, lambda v, d: None, fast=False)
    broken = text.replace("GLOBAL DEF r2()\n  i = 2000\n", "GLOBAL DEF r2()\n  IF i THEN\n")
    assert cache.pieces("x.src", broken) is None          # the IF runs to the next routine
    bad = cache.pieces("x.src", text.replace("  i = 2000\n", "  i = = 2000\n"))
    assert bad is not None and [p.ok for p in bad] == [True, True, False, True, True]
    assert bad[2].diagnostics and bad[2].diagnostics[0].line == text.split("\n").index("  i = 2000") + 1


def test_small_files_are_parsed_whole():
    assert cut("x.src", _file(2, 10)) is None
    assert PieceCache(lambda r, s: r, lambda v, d: None, fast=False).pieces("x.src", _file(2, 10)) is None
