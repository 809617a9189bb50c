"""Folding ranges of every block kind, counted by hand (0-based lines; a block folds up to the
line before its closer, a FOLD section up to its ;ENDFOLD line)."""

from __future__ import annotations

from krl.lsp import convert
from krl.lsp import folding
from krl.diagnostics.render import split_lines
from krl.lsp.analysis import build_analysis
from krl.lsp.outline import document_symbols
from krl.lsp.parsing import ParseCache
from krl.syntax.folds import fold_diagnostics


def folding_ranges(lines):
    """The protocol's folding ranges, as the server sends them (krl/lsp/convert.py)."""
    return [convert.folding_range(f) for f in folding.folding_ranges(lines)]

PROGRAM = """DEF blocks( )
  DECL INT i
  ;FOLD outer
  ;FOLD inner;%{PE}
  WHILE i < 3
    i = i + 1
  ENDWHILE
  ;ENDFOLD
  LOOP
    EXIT
  ENDLOOP
  ;ENDFOLD
  REPEAT
    i = i - 1
  UNTIL i == 0
  SWITCH i
  CASE 1
    HALT
  ENDSWITCH
  SPLINE
    SPL {X 1.0}
  ENDSPLINE
END
"""


def test_every_block_kind_folds():
    got = sorted((f.start_line, f.end_line, f.kind) for f in folding_ranges(split_lines(PROGRAM)))
    assert got == sorted([
        (0, 21, None),            # DEF .. END (line 22)
        (2, 11, "region"),        # ;FOLD outer .. ;ENDFOLD (line 11)
        (3, 7, "region"),         # ;FOLD inner .. ;ENDFOLD (line 7)
        (4, 5, None),             # WHILE .. ENDWHILE (line 6)
        (8, 9, None),             # LOOP .. ENDLOOP (line 10)
        (12, 13, None),           # REPEAT .. UNTIL (line 14)
        (15, 17, None),           # SWITCH .. ENDSWITCH (line 18)
        (19, 20, None),           # SPLINE .. ENDSPLINE (line 21)
    ])


def test_unbalanced_text_still_folds_what_is_closed():
    text = "DEF x( )\n  IF a THEN\n    b = 1\n  FOR i = 1 TO 2\n    c = 1\n  ENDFOR\nEND\n"
    got = sorted((f.start_line, f.end_line) for f in folding_ranges(split_lines(text)))
    assert (3, 4) in got          # the FOR is closed; the IF is not (no range for it)
    assert not any(start == 1 for start, _ in got)


# Where the server's own FOLD recogniser (line start only, `\s` blanks, `\b` word end, LF lines)
# disagreed with krl check's (krl/syntax/folds.py): both now read the same pairs.
MARKERS = ("DEF odd( )\n"                   # 1
           "  ;FOLD outer;%{PE}\n"          # 2  opens (text "outer")
           "  x = 1 ;FOLD after code\n"     # 3  a marker after code opens a fold too
           "  x = 2\n"                      # 4
           "  ;ENDFOLD\n"                   # 5  closes line 3 (the server closed line 2 here)
           "  ;FOLD$x is a comment\n"       # 6  FOLD$X is one word: not a marker (the server opened one)
           "  y = 0\r  ; fold cr\n"         # 7  after a lone CR, in lower case: opens (still line 7)
           "  y = 1\n"                      # 8
           "  ;ENDFOLD\n"                   # 9  closes line 7
           "  ; endfold (outer)\n"          # 10 closes line 2
           "END\n")                         # 11


def test_fold_sections_are_the_checkers_pairs():
    got = sorted((f.start_line, f.end_line, f.kind) for f in folding_ranges(split_lines(MARKERS)))
    assert got == sorted([
        (0, 9, None),             # DEF .. END (line 11)
        (1, 9, "region"),         # ;FOLD outer (2) .. ; endfold (10)
        (2, 4, "region"),         # x = 1 ;FOLD after code (3) .. ;ENDFOLD (5)
        (6, 8, "region"),         # ; fold cr (7) .. ;ENDFOLD (9)
    ])
    assert fold_diagnostics("odd.src", MARKERS) == []       # krl check finds the same pairs balanced


def test_unbalanced_folds_fold_what_w021_does_not_report():
    text = ("DEF u( )\n"          # 1
            "  ;ENDFOLD\n"        # 2  stray: W021, no range
            "  ;FOLD a\n"         # 3  never closed: W021, no range
            "  ;FOLD b\n"         # 4
            "  x = 1\n"           # 5
            "  ;ENDFOLD\n"        # 6  closes line 4
            "END\n")              # 7
    regions = [(f.start_line, f.end_line) for f in folding_ranges(split_lines(text)) if f.kind == "region"]
    assert regions == [(3, 5)]
    assert [d.line for d in fold_diagnostics("u.src", text)] == [2, 3]


def test_document_symbols_name_folds_by_their_text(tmp_path):
    path = str(tmp_path / "odd.src")
    an = build_analysis(path, [ParseCache().parse(path, MARKERS)])
    (routine,) = [convert.document_symbol(it, an.files[path].lines) for it in document_symbols(an, path)]

    def tree(sym):
        return (sym.name, sym.range.start.line, sym.range.end.line, [tree(c) for c in sym.children or []])

    assert tree(routine) == ("odd", 0, 10, [
        ("outer", 1, 9, [("after code", 2, 4, []), ("cr", 6, 8, [])]),
    ])
