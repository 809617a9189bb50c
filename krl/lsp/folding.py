"""Folding ranges: ``;FOLD`` ... ``;ENDFOLD`` sections and blocks (routines, IF, FOR, WHILE,
LOOP, REPEAT, SWITCH, SPLINE, data lists). Blocks come from the block scan of the syntax layer
(krl/syntax/blocks.py ``scan``: each closer matched with its opener), which works on files with
syntax errors too. FOLD sections are the pairs of krl/syntax/folds.py, the scan behind
``krl check``'s W021, so the server folds exactly the pairs the checker finds balanced. A
block's range ends on the line before its closer, so ENDIF stays visible; a FOLD section's
range ends on its ``;ENDFOLD`` line (the section folds away as on the KUKA pendant)."""

from __future__ import annotations

from lsprotocol import types as L

from krl.syntax.blocks import Line, scan
from krl.syntax.folds import scan_fold_lines
from krl.lsp.text import line_tokens


def fold_sections(lines: list[str]) -> list[tuple[int, int, str]]:
    """(first line, ENDFOLD line, title) of every FOLD section, 1-based, nested ones included
    (krl/syntax/folds.py pairs; the title is the fold's text, "FOLD" when it has none)."""
    return [(f.line, f.end_line, f.text or "FOLD") for f in scan_fold_lines(lines).pairs]


def block_pairs(lines: list[str]) -> list[tuple[int, int]]:
    """(opener line, closer line), 1-based, of the matched blocks."""
    toks = [Line(n, t) for n, text in enumerate(lines, start=1) if (t := line_tokens(text, n))]
    res = scan(toks)
    return sorted((opener, closer) for closer, opener in res.matched.items())


def folding_ranges(lines: list[str]) -> list[L.FoldingRange]:
    out = []
    for start, end, _title in fold_sections(lines):
        if end > start:
            out.append(L.FoldingRange(start_line=start - 1, end_line=end - 1, kind=L.FoldingRangeKind.Region))
    for opener, closer in block_pairs(lines):
        if closer - 1 > opener:
            out.append(L.FoldingRange(start_line=opener - 1, end_line=closer - 2))
    return out
