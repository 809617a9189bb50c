"""Folding ranges: ``;FOLD`` ... ``;ENDFOLD`` sections and blocks (routines, IF, FOR, WHILE,
LOOP, REPEAT, SWITCH, SPLINE, data lists). Blocks come from the block scan of the syntax layer
(krl/syntax/blocks.py ``scan``: each closer matched with its opener), which works on files with
syntax errors too. FOLD sections are the pairs of krl/syntax/folds.py, the scan behind
``krl check``'s W021, so the server folds exactly the pairs the checker finds balanced. A
block's range ends on the line before its closer, so ENDIF stays visible; a FOLD section's
range ends on its ``;ENDFOLD`` line (the section folds away as on the KUKA pendant)."""

from __future__ import annotations

from dataclasses import dataclass

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


@dataclass(frozen=True)
class FoldRange:
    """Lines `first` .. `last` (1-based) fold; `region`: a FOLD section (else a block)."""
    first: int
    last: int
    region: bool = False


def folding_ranges(lines: list[str]) -> list[FoldRange]:
    """The FOLD sections (to their ENDFOLD line), then the blocks (to the line before their closer)."""
    out = []
    for start, end, _title in fold_sections(lines):
        if end > start:
            out.append(FoldRange(start, end, True))
    for opener, closer in block_pairs(lines):
        if closer - 1 > opener:
            out.append(FoldRange(opener, closer - 1))
    return out
