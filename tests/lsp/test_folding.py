"""Folding ranges of every block kind, counted by hand (0-based lines; a block folds up to the
line before its closer, a FOLD section up to its ;ENDFOLD line)."""

from __future__ import annotations

from krl.lsp.folding import folding_ranges
from krl.semantics.render import split_lines

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
