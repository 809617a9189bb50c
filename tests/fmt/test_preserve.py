"""What krl fmt must never change: comments, FOLD lines, inline-form payloads, & header lines,
line ends, a BOM, a missing final line end, string contents, names' case; and the meaning
(the AST before and after is equal). Expected texts are written by hand."""

from __future__ import annotations

import pytest

import krl.fmt.core as core
from krl.ast.build import build_module
from krl.ast.compare import first_difference, same_tree
from krl.fmt import FormatSafetyError, format_text
from krl.syntax.parse import parse_text

INLINE_FORM = [
    "  ;FOLD PTP HOME1 Vel=12 % PHome1;%{PE}%R8.3.21,%MKUKATPBASIS,%CMOVE,%VPTP,%P 1:PTP, 2:HOME1, 3:, 5:12, 7:PHome1",
    "  $BWDSTART=FALSE",
    "  PDAT_ACT= PPHome1",
    "  FDAT_ACT= FHOME1",
    "  BAS(#PTP_PARAMS,12)",
    "  ptp XHOME1",
    "  ;ENDFOLD",
]


def ast(text: str):
    result = parse_text(text, "t.src")
    assert result.ok, [e.message for e in result.errors]
    return build_module(result)


def test_crlf_stays_crlf():
    src = "DEF t()\r\nx=1\r\nEND\r\n"
    assert format_text(src) == "DEF t()\r\n   x = 1\r\nEND\r\n"


def test_mixed_line_ends_stay_per_line():
    src = "DEF t()\r\nx=1\ny=2\rEND\r\n"
    assert format_text(src) == "DEF t()\r\n   x = 1\n   y = 2\rEND\r\n"


def test_no_final_line_end_stays_missing_and_bom_is_kept():
    src = "\ufeffDEF t()\nx=1\nEND"
    assert format_text(src) == "\ufeffDEF t()\n   x = 1\nEND"


def test_inline_form_lines_keep_their_exact_text():
    src = "\r\n".join(["DEF t()", "x=1", *INLINE_FORM, "y=2", "END", ""])
    want = "\r\n".join(["DEF t()", "   x = 1", *INLINE_FORM, "   y = 2", "END", ""])
    assert format_text(src) == want


def test_nested_fold_inside_an_inline_form_is_kept_to_the_outer_endfold():
    body = [";FOLD INI;%{PE}", "  ;FOLD BASISTECH INI", "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
            "INTERRUPT ON 3 ", "  ;ENDFOLD (BASISTECH INI)", "BAS (#INITMOV,0 )", ";ENDFOLD (INI)"]
    src = "\n".join(["DEF t()", *body, "x=1", "END", ""])
    assert format_text(src) == "\n".join(["DEF t()", *body, "   x = 1", "END", ""])


def test_plain_fold_lines_are_kept_and_their_content_formatted():
    src = "\n".join(["DEF t()", "  ;FOLD my section  ", "x=1", " ;ENDFOLD  (my section)", "END", ""])
    want = "\n".join(["DEF t()", "  ;FOLD my section  ", "      x = 1", " ;ENDFOLD  (my section)", "END", ""])
    assert format_text(src) == want


def test_comments_are_untouched_and_move_with_their_code():
    src = "\n".join(["DEF t()", "; column one stays", "  ; aligned with x: moves", "  x=1   ;  trailing  =  kept ",
                     "        ; aligned with nothing: stays", "IF a THEN", "  ;about y", "  y=2", "ENDIF", "END", ""])
    want = "\n".join(["DEF t()", "; column one stays", "   ; aligned with x: moves",
                      "   x = 1   ;  trailing  =  kept ", "        ; aligned with nothing: stays", "   IF a THEN",
                      "      ;about y", "      y = 2", "   ENDIF", "END", ""])
    assert format_text(src) == want


def test_header_lines_strings_and_names_are_untouched():
    src = "\n".join(["&ACCESS  RVP", "&PARAM TEMPLATE = C:\\KRC\\Roboter\\Template\\vorgabe",
                     "DEF t()", 'msg[]="a  =  b ; not a comment"', "MyVar=myvar", "END", ""])
    want = "\n".join(["&ACCESS  RVP", "&PARAM TEMPLATE = C:\\KRC\\Roboter\\Template\\vorgabe",
                      "DEF t()", '   msg[] = "a  =  b ; not a comment"', "   MyVar = myvar", "END", ""])
    assert format_text(src) == want


def test_ast_is_equal_after_formatting():
    src = "\n".join(["def t(a:in)", "decl e6pos p", "int i", "for i=1 to 10 step 2",
                     "p={x -1.5e3,y 'h1F',z 'b101'}:$nullframe", "if not (a==1 or i<>2) then",
                     "ptp p c_ptp", "endif", "endfor", "end", ""])
    out = format_text(src)
    assert out != src
    assert same_tree(ast(src), ast(out), fold_keywords=True), first_difference(ast(src), ast(out), True)


def test_keyword_case_is_the_only_ast_difference_that_is_folded():
    a, b = ast("DEF t()\nDECL int i\nEND\n"), ast("DEF t()\nDECL INT i\nEND\n")
    assert same_tree(a, b, fold_keywords=True)
    # names are compared exactly: a renamed variable is a different program text
    c = ast("DEF t()\nDECL INT j\nEND\n")
    assert not same_tree(a, c, fold_keywords=True)
    # string contents are never folded
    assert not same_tree(ast('DEF t()\nx[]="int"\nEND\n'), ast('DEF t()\nx[]="INT"\nEND\n'), fold_keywords=True)


def test_the_token_check_refuses_a_result_that_lexes_differently(monkeypatch):
    # a spacing rule that glued two words would turn `a AND b` into the one name `aANDb`:
    # the final re-lex must catch it instead of returning another program
    monkeypatch.setattr(core, "_would_merge", lambda ta, tb: False)
    monkeypatch.setattr(core, "_gap", lambda *args: "")
    with pytest.raises(FormatSafetyError):
        format_text("DEF t()\nx = a AND b\nEND\n")
