"""W021: unbalanced ;FOLD / ;ENDFOLD (krl/syntax/folds.py). Expected lines counted by hand."""

from __future__ import annotations

import pytest

from krl.syntax.folds import fold_diagnostics
from krl.workspace import check_texts
from krl.source import is_krl_file, read_source
from krl.syntax.parse import parse_text


def found(text: str):
    """(line, column, note lines) of each W021."""
    return [(d.line, d.column, [n.line for n in d.notes]) for d in fold_diagnostics("t.src", text)]


def test_balanced_nested_folds_in_any_case_are_quiet():
    text = ("DEF t()\n"
            ";FOLD INI;%{PE}\n"
            "  ;fold BASISTECH INI\n"
            "  ; ENDFOLD (BASISTECH INI)\n"
            ";EndFold (INI)\n"
            "END\n")
    assert found(text) == []


def test_unclosed_fold_is_reported_at_its_line_with_the_routine_end():
    text = ("DEF t()\n"          # 1
            "  INT i\n"          # 2
            "  ;FOLD init\n"     # 3  <- never closed
            "  i = 0\n"          # 4
            "END\n")             # 5
    assert found(text) == [(3, 3, [5])]
    d = fold_diagnostics("t.src", text)[0]
    assert d.code == "W021" and d.severity == "warning"
    assert "line 5" in d.message


def test_unclosed_fold_outside_routines_notes_the_last_line():
    text = ";FOLD header\nDEF t()\nEND\n"   # 3 lines; the fold at 1 is never closed
    assert found(text) == [(1, 1, [3])]


def test_stray_endfold_is_reported_at_its_line():
    text = ("DEF t()\n"           # 1
            ";FOLD a\n"           # 2
            ";ENDFOLD\n"          # 3
            ";ENDFOLD (a)\n"      # 4  <- stray
            "END\n")
    assert found(text) == [(4, 1, [])]


def test_fold_in_one_routine_closed_in_the_next_gives_both_lines():
    text = ("DEF t()\n"           # 1
            "  ;FOLD a\n"         # 2  <- opened in t
            "END\n"               # 3  t ends
            "DEF u()\n"           # 4
            "  ;ENDFOLD\n"        # 5  <- closed in u
            "END\n")              # 6
    assert found(text) == [(2, 3, [3, 5])]
    assert "line 5" in fold_diagnostics("t.src", text)[0].message


def test_folds_wrapping_whole_routines_are_kukas_idiom():
    # bas.src: the fold opens after DEF and closes after END; sps.sub: a hidden fold opened
    # before END wraps the later routines and closes at the end of the file.
    bas = "DEF bas()\n;FOLD BAS ()\n  INT i\nEND\n;ENDFOLD BAS ()\n"
    sps = ("DEF sps()\n  ;FOLD ;%{H}\n  ;FOLD\nEND\n  ;ENDFOLD\n"
           "DEF reset_out()\nEND\n;ENDFOLD\n")
    header = ";FOLD >>> USER >>>\nGLOBAL DEF user_x()\n;ENDFOLD\n  INT i\n;FOLD <<< END <<<\nEND\n;ENDFOLD\n"
    assert found(bas) == [] and found(sps) == [] and found(header) == []


def test_markers_inside_strings_and_other_words_do_not_count():
    text = ('DEF t()\n'
            '  CHAR s[20]\n'
            '  s[] = ";FOLD no"\n'         # inside a string: not a comment
            '  ;FOLDER is a word\n'        # FOLDER is not FOLD
            '  ;ENDFOLDED\n'
            'END\n')
    assert found(text) == []


@pytest.mark.parametrize("eol, expected", [
    ("\r\n", [(3, 3, [4])]),
    # a lone CR ends the statement and the comment (a NEWLINE token) but, as in the parser and
    # every other diagnostic, not the line number: all is line 1; ';' is character 19
    ("\r", [(1, 19, [1])]),
])
def test_line_ends_are_the_lexers(eol, expected):
    text = eol.join(["DEF t()", "  INT i", "  ;FOLD x", "END", ""])
    assert found(text) == expected


def test_fold_lines_are_the_parsers_lines():
    text = "DEF t()\r\n  x = 1\r  ;FOLD a\n  y = 2\rEND\n"
    fold_tokens = [t for t in parse_text(text).tree.parser.getTokenStream().tokens if t.text.startswith(";FOLD")]
    assert [(t.line, t.column + 1) for t in fold_tokens] == [(2, 11)]   # "  x = 1" CR "  ;": 11th
    assert found(text) == [(2, 11, [3])]          # the END is on the parser's line 3


def test_check_reports_the_warning_and_it_does_not_stop_the_file():
    ws = check_texts({"t.src": "DEF t()\n  INT i\n  ;FOLD init\n  i = 0\nEND\n"})
    assert [(d.code, d.line) for d in ws.diagnostics] == [("W021", 3)]
    assert all(f.ok for f in ws.files)


@pytest.mark.corpus
def test_real_corpus_fires_only_on_unbalanced_files(shared_corpus):
    hits = {}
    for p in sorted(shared_corpus.rglob("*")):
        if p.is_file() and is_krl_file(p):
            ds = fold_diagnostics(str(p), read_source(p).text or "")
            if ds:
                hits[p.relative_to(shared_corpus).as_posix()] = [d.line for d in ds]
    # each checked by hand (2026-11-21): two FOLDs of EXTERNAL DECLARATIONS never closed, a
    # "FOLD Signal read" never closed, ";ENDFOLD (USER GLOBALS)" twice, an ENDFOLD (INI) whose
    # FOLD BASISTECH INI line is missing, a ";ENDFOLDDI_..." closer glued to pasted text
    assert hits == {
        "HugoDanielson__ChinaMilling/KRC/R1/TP/Milling/amm_main.src": [252],
        "LiorSkoury-git__Kuka_EthernetKrl_Python/KRL/ethernetkrl_workshop.dat": [7, 8],
        "WeiminZhang__Kuka_Robot_Control_through_LAN/Kuka/app1b.src": [87],
        "khrzysio__KRC4_test/R1/System/$config.dat": [895],
        "msstachnik__KCT3p0/kctrsi/kctrsiclient.src": [26],
        "rawpython__kukaKRLmagic/R1/System/$config.dat": [950],
    }
