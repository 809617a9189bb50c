"""The VS Code extension's TextMate grammar (editors/vscode/syntaxes/krl.tmLanguage.json), tested
with VS Code's own TextMate engine (vscode-textmate + vscode-oniguruma):

- vscode-tmgrammar-test on the hand-annotated snippets of editors/vscode/test/grammar/, each cut
  from a real corpus file named in its header (the cut lines are checked against that file);
- every keyword of the lexer of grammar/KRL.g4 is one token with a keyword scope, in upper,
  lower and mixed case (the list is read from the grammar, so a new lexer keyword that the
  TextMate grammar lacks fails here).
"""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import pytest

from tests.conftest import REPO_ROOT, SHARED_CORPUS, corpus_present
from tests.editors.npm import EXTENSION, node_bin, npm_ci

SNIPPETS = EXTENSION / "test" / "grammar"
GRAMMAR = EXTENSION / "syntaxes" / "krl.tmLanguage.json"
KEYWORD_SCOPES = ("keyword.", "storage.type.krl", "constant.language.boolean.krl")
RUN_TIMEOUT_S = 120

# An assertion line of vscode-tmgrammar-test (its unit/parsing.js): ';' then carets or a left
# arrow, the required scopes, then optionally '-' and the prohibited scopes. The tool silently
# ignores a left-arrow line it cannot parse, and compares prohibited scopes by equality, so a
# malformed or partial name would make an assertion that cannot fail: checked here.
ASSERTION_START = re.compile(r"^;\s*(\^|<~*-+)")
ASSERTION = re.compile(r"^;(\s*<~*-+|\s*(?:\^+\s*)+)((?:\s+\w[\w.-]*)*)(?:\s+-((?:\s+\w[\w.-]*)+))?\s*$")


@pytest.fixture(scope="module")
def extension() -> Path:
    return npm_ci()


def lexer_keywords() -> list[str]:
    """The keywords of grammar/KRL.g4's lexer: rules whose body is one quoted word ('AND', 'E6POS'),
    and BRAKE_F ('BRAKE' [ \\t]+ 'F', written 'BRAKE F')."""
    text = (REPO_ROOT / "grammar" / "KRL.g4").read_text()
    lexer = text[text.index("// ======================================================================== lexer"):]
    words = []
    for body in re.findall(r"^[A-Z][A-Z0-9_]*\s*:\s*(.*?)\s*;\s*$", lexer, re.M):
        if m := re.fullmatch(r"'([A-Z][A-Z0-9_]*)'", body):
            words.append(m[1])
        elif m := re.fullmatch(r"'([A-Z]+)'\s*\[ \\t\]\+\s*'([A-Z]+)'", body):
            words.append(f"{m[1]} {m[2]}")
    return words


def tokenize(lines: list[str], grammar: Path = GRAMMAR) -> list[list[dict]]:
    run = subprocess.run(["node", str(EXTENSION / "test" / "tokenize.js"), str(grammar)], input=json.dumps(lines),
                         capture_output=True, text=True, timeout=RUN_TIMEOUT_S, check=False)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


def keywords_without_keyword_scope(grammar: Path = GRAMMAR) -> list[str]:
    """The lexer keywords (in three spellings) that do not come out as one keyword-scoped token."""
    words = lexer_keywords()
    spellings = [s for w in words for s in (w, w.lower(), w[0] + w[1:].lower())]
    # each keyword alone on a line, after a space (no line-start rule such as a header applies)
    tokens = tokenize([" " + s for s in spellings], grammar)
    missing = []
    for spelling, line in zip(spellings, tokens):
        word = [t for t in line if t["text"].strip()]
        if not (len(word) == 1 and word[0]["text"] == spelling
                and any(s.startswith(KEYWORD_SCOPES) for s in word[0]["scopes"])):
            missing.append(spelling)
    return missing


def test_the_keyword_list_is_read_from_the_grammar():
    words = lexer_keywords()
    # some of each kind, counted by hand from grammar/KRL.g4's lexer section
    for w in ("AND", "ASYCANCEL", "BRAKE F", "BRAKE", "C_SPL", "DEFFCT", "ENDSPLINE", "ON_ERROR_PROCEED",
              "SCIRC_REL", "TIME_BLOCK", "WITH", "AXIS", "E6POS", "FRAME"):
        assert w in words
    assert len(words) == len(set(words)) and len(words) > 120
    assert "IDENTIFIER" not in words and "HEADER" not in words and "FOLD" not in words


def test_every_lexer_keyword_is_highlighted_as_a_keyword(extension):
    assert keywords_without_keyword_scope() == []


def test_a_keyword_missing_from_the_textmate_grammar_fails_the_check(extension, tmp_path):
    grammar = json.loads(GRAMMAR.read_text())
    control = next(p for p in grammar["repository"]["keywords"]["patterns"] if p["name"] == "keyword.control.krl")
    assert "|WAIT|" in control["match"]
    control["match"] = control["match"].replace("|WAIT|", "|")
    broken = tmp_path / "krl.tmLanguage.json"
    broken.write_text(json.dumps(grammar))
    assert keywords_without_keyword_scope(broken) == ["WAIT", "wait", "Wait"]


def snippet_files() -> list[Path]:
    return sorted(p for p in SNIPPETS.iterdir() if p.suffix in (".src", ".dat", ".sub"))


def test_snippet_assertions_are_well_formed():
    files = snippet_files()
    assert {p.suffix for p in files} == {".src", ".dat", ".sub"}
    for path in files:
        lines = path.read_text().split("\n")
        assert lines[0].startswith('; SYNTAX TEST "source.krl"'), path
        count = 0
        for n, line in enumerate(lines[1:], 2):
            if ASSERTION_START.match(line):
                m = ASSERTION.match(line)
                assert m, f"{path.name}:{n}: not an assertion vscode-tmgrammar-test reads: {line!r}"
                scopes = (m[2] or "").split() + (m[3] or "").split()
                assert scopes and all(s.endswith(".krl") or s == "source.krl" for s in scopes), \
                    f"{path.name}:{n}: scopes must be whole names (prohibited ones compare by equality)"
                count += 1
        assert count >= 10, f"{path.name}: only {count} assertions"


def test_snippets_are_cut_unchanged_from_the_corpus_files_they_name():
    if not corpus_present():
        pytest.skip("../shared/krl-corpus is not present")
    for path in snippet_files():
        lines = path.read_text().split("\n")
        origin = lines[1].removeprefix("; origin: ").strip()
        if origin.startswith("none (hand-written"):
            continue
        source = (SHARED_CORPUS / origin).read_text(encoding="latin-1").splitlines()
        code = [ln for ln in lines[1:] if ln and not ASSERTION_START.match(ln)
                and not ln.startswith(("; origin: ", "; cut from "))]
        assert len(code) >= 8, path
        missing = [ln for ln in code if ln not in source]
        assert missing == [], f"{path.name}: lines not in {origin}: {missing}"


def test_grammar_snippets_pass_vscode_tmgrammar_test(extension):
    files = snippet_files()
    run = subprocess.run([str(node_bin("vscode-tmgrammar-test")), *(str(p.relative_to(extension)) for p in files)],
                         cwd=extension, capture_output=True, text=True, timeout=RUN_TIMEOUT_S, check=False)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out
    for p in files:
        assert f"✓ {p.relative_to(extension)} run successfuly." in out, out
