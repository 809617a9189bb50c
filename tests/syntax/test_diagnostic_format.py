"""The compiler-style diagnostic format of `krl parse` and `krl check` (issue 13).

Lines, columns (1-based, counted by hand below), caret spans, the note and help lines, the JSON
and SARIF columns, colour only on a terminal without NO_COLOR, the closing count line, and the
message rules: KRL words, at most six grouped alternatives, at most 160 characters (krl.limits.MAX_MESSAGE_CHARS).
"""

from __future__ import annotations

import io
import json
import re
from pathlib import Path

import pytest

from app.check import run_check
from krl.diagnostics.render import count_line, use_colour
from app.parse import run_parse
from krl.workspace import check_texts

REPO = Path(__file__).resolve().parents[2]

# col:  123456789012345
T = ("DEF t()\n"            # 1
     "  INT i\n"            # 2
     "  IF i > 1 THEN\n"    # 3  IF at 3:3..3:5, never closed
     "    i == 2\n"         # 4  `==` at 4:7..4:9
     "  FOR i = 1 3\n"      # 5  `3` at 5:13
     "  ENDFOR\n"           # 6
     "END\n")               # 7  END: where the open IF is noticed


@pytest.fixture
def t_src(tmp_path, monkeypatch) -> Path:
    monkeypatch.chdir(tmp_path)
    Path("t.src").write_text(T)
    return Path("t.src")


def test_text_form_line_caret_note_help_and_count(t_src):
    out: list[str] = []
    assert run_parse([t_src], echo=out.append) == 1
    assert out == [
        "t.src:3:3: error[E010]: missing ENDIF for the IF at line 3",
        " 3 |   IF i > 1 THEN",
        "   |   ^~",
        "t.src:7:1: note: END reached here while the IF is open",
        "   = help: add ENDIF before line 7",
        "t.src:4:7: error[E013]: `==` compares; to assign use `=`",
        " 4 |     i == 2",
        "   |       ^~",
        "t.src:5:13: error[E012]: FOR needs TO before the end value, found `3`",
        " 5 |   FOR i = 1 3",
        "   |             ^",
        "3 errors in 1 file",
    ]


def test_check_prints_the_same_text(t_src):
    """krl check prints krl parse's diagnostics, after naming the lines not understood first
    (issue 63): lines 3 (the IF without ENDIF, E010), 4 and 5, once each; of the 5 code lines
    (DEF, INT i and those three; ENDFOR and END close blocks) 2 are checked."""
    parsed: list[str] = []
    checked: list[str] = []
    run_parse([t_src], echo=parsed.append)
    assert run_check([str(t_src)], echo=checked.append) == 1
    assert checked[:4] == [
        "t.src:3, 4, 5 not understood: 2 of 5 statements checked",
        "  t.src:3: missing ENDIF for the IF at line 3",
        "  t.src:4: `==` compares; to assign use `=`",
        "  t.src:5: FOR needs TO before the end value, found `3`",
    ]
    assert checked[4:] == parsed


def _places(diags):
    return [(d["code"], d["line"], d["column"], d["end_line"], d["end_column"]) for d in diags]


EXPECTED = [("E010", 3, 3, 3, 5), ("E013", 4, 7, 4, 9), ("E012", 5, 13, 5, 14)]


def test_json_columns_are_one_based_in_parse_and_check(t_src):
    out: list[str] = []
    run_parse([t_src], fmt="json", echo=out.append)
    parsed = json.loads(out[0])
    assert _places(parsed["diagnostics"]) == EXPECTED
    assert "errors" not in parsed and "antlr_errors" not in parsed     # one truth: the diagnostics
    out.clear()
    run_parse([t_src], fmt="json", echo=out.append, antlr_errors=True)
    parsed = json.loads(out[0])
    # the parser's raw errors on request: `==` is the 7th character of line 4
    assert (parsed["antlr_errors"][0]["line"], parsed["antlr_errors"][0]["column"]) == (4, 7)
    out.clear()
    run_check([str(t_src)], fmt="json", echo=out.append)
    assert _places(json.loads(out[0])["diagnostics"]) == EXPECTED


@pytest.mark.parametrize("command", ["parse", "check"])
def test_sarif_regions_are_one_based(t_src, command):
    out: list[str] = []
    if command == "parse":
        run_parse([t_src], fmt="sarif", echo=out.append)
    else:
        run_check([str(t_src)], fmt="sarif", echo=out.append)
    log = json.loads("\n".join(out))
    assert log["version"] == "2.1.0"
    results = log["runs"][0]["results"]
    regions = [(r["ruleId"], r["locations"][0]["physicalLocation"]["region"]) for r in results]
    assert [(c, g["startLine"], g["startColumn"], g["endLine"], g["endColumn"]) for c, g in regions] == EXPECTED
    assert results[0]["relatedLocations"][0]["physicalLocation"]["region"]["startLine"] == 7


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_colour_only_on_a_terminal_without_no_color(monkeypatch, t_src):
    monkeypatch.delenv("NO_COLOR", raising=False)
    assert use_colour(_Tty()) is True
    assert use_colour(io.StringIO()) is False          # piped
    monkeypatch.setenv("NO_COLOR", "1")
    assert use_colour(_Tty()) is False
    out: list[str] = []
    run_check([str(t_src)], echo=out.append, colour=True)
    assert any("\x1b[" in line for line in out)
    out.clear()
    run_check([str(t_src)], echo=out.append)
    assert not any("\x1b" in line for line in out)


def test_count_line():
    assert count_line(3, 2, 14) == "3 errors, 2 warnings in 14 files"
    assert count_line(1, 1, 1) == "1 error, 1 warning in 1 file"
    assert count_line(0, 0, 2) == "no errors in 2 files"
    assert count_line(0, 4, 3) == "4 warnings in 3 files"


@pytest.mark.parametrize("body, code, line, column, message", [
    ("  IF i > 1 THEN\n    i = 1\n", "E010", 3, 3, "missing ENDIF for the IF at line 3"),
    ("  FOR i = 1 3\n  ENDFOR\n", "E012", 3, 13, "FOR needs TO before the end value, found `3`"),
    ("  i == 2\n", "E013", 3, 5, "`==` compares; to assign use `=`"),
    ("  i = 1\n  INT k\n", "E014", 4, 3, "declarations must come before the first statement"),
    ("  IF i = 1 THEN\n  ENDIF\n", "E013", 3, 8, "`=` assigns; to compare use `==`"),
    ("  INTERRUPT5 ON\n", "E002", 3, 3, "`INTERRUPT5` is read as one name; write `INTERRUPT 5`"),
    ("  GLOBALSTRUC x INT a\n", "E002", 3, 3, "`GLOBALSTRUC` is read as one name; write `GLOBAL STRUC`"),
    ("  FORWARD x\n", "E002", 3, 11, "unexpected `x`"),
    ("   TODO \n", "E012", 3, 4, "`TODO` alone is not a statement; to call the routine write `TODO()`"),
])
def test_messages_in_krl_words(body, code, line, column, message):
    ws = check_texts({"t.src": "DEF t()\n  INT i\n" + body + "END\n"})
    first = ws.diagnostics[0]
    assert (first.code, first.line, first.column, first.message) == (code, line, column, message)


def test_no_message_quotes_the_parser_or_glues_tokens():
    """Over the negative corpus and corpus/broken: every syntax message is at most 160
    characters, lists at most six alternatives and never carries ANTLR's own wording."""
    files = sorted((REPO / "tests/negative").glob("*.src")) + sorted((REPO / "corpus/broken").glob("*.*"))
    assert len(files) > 200
    seen = 0
    for f in files:
        out: list[str] = []
        run_parse([f], fmt="json", echo=out.append)
        for d in json.loads(out[0])["diagnostics"]:
            seen += 1
            m = d["message"]
            assert len(m) <= 160, m
            assert not re.search(r"no viable alternative|extraneous input|mismatched input|expecting \{", m), m
            _, _, alternatives = m.partition("; expected ")
            alternatives = re.sub(r"`[^`]*`", "X", alternatives)   # a quoted `,` is one token
            if alternatives:
                assert alternatives.count(",") + alternatives.count(" or ") + 1 <= 6, m
    assert seen > 200
