"""docs/diagnostics.md documents every diagnostic code, and its examples are true.

The codes are declared once, as named constants in krl/diagnostics/codes.py (severity, kind,
message templates). Each has a ``## CODE`` section in docs/diagnostics.md and the doc has no
section for a code that does not exist; no code is spelled as a string anywhere else in the
project's code (an emit site names the constant), and every declared code is named by some
emit site. The
``krl`` blocks of a section form one small program (the info string names the file); the
checker run on exactly those files must report the section's code. Codes whose trigger is not
a small text (a binary file, a generated 101-level nesting, a zip archive) are produced here by
a generator instead (W002 a symbolic link, E005 a parse that never ends); four codes have no trigger (toolkit bugs, or a tree the grammar never builds), and the doc says so.
"""

from __future__ import annotations

import ast
import json
import re
import string
import time
import zipfile
from pathlib import Path
from unittest import mock

import pytest

from krl.diagnostics import CODES
from krl.diagnostics.codes import ALL, E102
from app.check import run_check
from krl.workspace import check_texts, load_workspace
import krl.workspace as workspace_mod

DOC = Path(__file__).resolve().parents[2] / "docs" / "diagnostics.md"
SECTION = re.compile(r"^## ([EW]\d{3})\s*$", re.M)
BLOCK = re.compile(r"^```krl(?:[ \t]+(\S+))?[ \t]*\n(.*?)^```", re.M | re.S)

# Codes no input can produce: they report a bug of the toolkit (the doc says "Example: none").
NO_TRIGGER = {"E003", "W003", "E104", "E901"}


def sections() -> dict[str, str]:
    text = DOC.read_text(encoding="utf-8")
    parts = SECTION.split(text)
    out: dict[str, str] = {}
    for code, body in zip(parts[1::2], parts[2::2]):
        body = re.split(r"^# ", body, flags=re.M)[0]  # up to the next group heading
        assert code not in out, f"two sections for {code}"
        out[code] = body
    return out


def examples(body: str) -> dict[str, str]:
    return {(name or "demo.src"): text for name, text in BLOCK.findall(body)}


def _codes_of_files(files: dict[str, str]) -> set[str]:
    return {d.code for d in check_texts(files).diagnostics}


def _generated(code: str, tmp: Path) -> set[str]:
    """The codes reported for the generated trigger of `code`."""
    if code == "E001":
        (tmp / "image.src").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR")
        ws = load_workspace([tmp / "image.src", tmp / "missing.src"])
        ws.check()
        got = [d for d in ws.diagnostics if d.code == "E001"]
        assert {Path(d.path).name for d in got} == {"image.src", "missing.src"}
        return {d.code for d in got}
    if code == "E018":
        n = 101
        text = "DEF demo()\nINT i\n" + "IF TRUE THEN\n" * n + "i = 1\n" + "ENDIF\n" * n + "END\n"
        return _codes_of_files({"demo.src": text})
    if code == "E019":
        text = "DEF demo()\nINT i\ni = " + " + ".join(["1"] * 501) + "\nEND\n"
        return _codes_of_files({"demo.src": text})
    if code == "E004":
        z = tmp / "evil.zip"
        with zipfile.ZipFile(z, "w") as zf:
            zf.writestr("../x.src", "DEF x()\nEND\n")
        out: list[str] = []
        assert run_check([str(z)], fmt="json", echo=out.append) == 1
        return {d["code"] for line in out for d in json.loads(line)["diagnostics"]}
    if code == "W002":
        (tmp / "a.src").write_text("DEF a()\nEND\n")
        (tmp / "link.src").symlink_to(tmp / "a.src")
        out = []
        run_check([str(tmp)], fmt="json", echo=out.append)
        return {d["code"] for line in out for d in json.loads(line)["diagnostics"]}
    if code == "E005":
        # a parse that never ends: the worker is killed after the timeout

        def stuck(src, *a, **kw):
            while True:
                time.sleep(3600)

        (tmp / "slow.src").write_text("DEF slow()\nEND\n")
        out = []
        with mock.patch.object(workspace_mod, "parse_source", stuck):
            assert run_check([str(tmp)], fmt="json", echo=out.append, timeout=1, jobs=1) == 1
        return {d["code"] for line in out for d in json.loads(line)["diagnostics"]}
    raise AssertionError(f"no generator for {code}")


def test_every_code_has_a_section_and_every_section_a_code():
    documented = set(sections())
    assert documented - set(CODES) == set(), "sections for codes that do not exist"
    assert set(CODES) - documented == set(), "codes without a section in docs/diagnostics.md"


ROOT = Path(__file__).resolve().parents[2]
SOURCES = ["krl", "interp", "net", "robot", "recovery", "pendant", "conformance", "tools", "examples"]
CODE_TEXT = re.compile(r"[EW]\d{3}")


def _source_files():
    for top in SOURCES:
        for p in sorted((ROOT / top).rglob("*.py")):
            if "generated" not in p.parts and p != ROOT / "krl" / "diagnostics" / "codes.py":
                yield p


def _docstrings(tree) -> set[int]:
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                out.add(id(first.value))
    return out


#: the two tests that read every source of the project (the spelled codes, the emit sites) parse
#: it once (:func:`source_trees`) on one worker of make test (--dist loadgroup)
SOURCES_GROUP = pytest.mark.xdist_group("diagnostics-doc-sources")


#: a code as a token of a source's text: a name ``E102`` or a string ``"E102"`` is spelled so
CODE_TOKEN = re.compile(r"\b[EW]\d{3}\b")


@pytest.fixture(scope="module")
def source_trees() -> list[tuple[Path, ast.Module]]:
    """(path, parsed module) of every source :func:`_source_files` names whose text holds a
    code as a token (:data:`CODE_TOKEN`), parsed once for the module's tests. A source without
    one has neither a name nor a string constant that is a code (a constant spelled in pieces,
    ``"E1" "02"``, or with escapes would be missed): 48 of the 385 sources are parsed (all of
    them took 3.9 and 2.7 s of CPU in the two tests, 2026-11-28)."""
    return code_sources(_source_files())


def code_sources(paths) -> list[tuple[Path, ast.Module]]:
    """(path, parsed module) of those of `paths` whose text holds a code as a token."""
    out = []
    for p in paths:
        text = p.read_text(encoding="utf-8")
        if CODE_TOKEN.search(text):
            out.append((p, ast.parse(text)))
    return out


def spelled_codes(path: Path, root: Path = ROOT, tree: ast.Module | None = None) -> list[str]:
    """``file:line CODE`` of each string constant of `path` (its parse `tree`, else parsed here)
    that is a code (docstrings aside)."""
    tree = ast.parse(path.read_text(encoding="utf-8")) if tree is None else tree
    skip = _docstrings(tree)
    return [f"{path.relative_to(root)}:{n.lineno} {n.value}" for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and CODE_TEXT.fullmatch(n.value)
            and id(n) not in skip]


@SOURCES_GROUP
def test_no_code_is_spelled_outside_its_declaration(source_trees):
    """An emit site names the constant (``E102(...)``), a comparison too (``d.code == E102``)."""
    assert [hit for p, tree in source_trees for hit in spelled_codes(p, tree=tree)] == []


def test_the_spelling_check_finds_a_bare_code(tmp_path):
    p = tmp_path / "sample.py"
    p.write_text('"""E102 in a docstring is prose."""\nsink.add(path, 1, 1, "E102", "x")\n', encoding="utf-8")
    assert spelled_codes(p, tmp_path) == ["sample.py:2 E102"]
    # the sources the test reads keep such a file (and its parse finds the same)
    (kept, tree), = code_sources([p])
    assert spelled_codes(kept, tmp_path, tree=tree) == ["sample.py:2 E102"]
    q = tmp_path / "other.py"
    q.write_text('CODE = "E1021"\nx = E10\n', encoding="utf-8")
    assert code_sources([q]) == [] and spelled_codes(q, tmp_path) == []


@SOURCES_GROUP
def test_every_code_is_named_by_an_emit_site(source_trees):
    named = set()
    for _p, tree in source_trees:
        named |= {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and CODE_TEXT.fullmatch(n.id)}
    assert sorted(set(CODES) - named) == [], "declared codes that nothing emits"


def test_every_template_is_a_format_of_named_fields():
    for code in ALL:
        for variant, template in code.messages.items():
            fields = [f for _lit, f, _spec, _conv in string.Formatter().parse(template) if f is not None]
            assert all(f.isidentifier() for f in fields), (code, variant, template)
    assert E102(name="X", where="") == ("E102", "'X' is declared more than once")
    assert type(E102(name="X", where="")[0]) is str and E102 == "E102"


def test_sections_without_example_are_exactly_the_generated_and_untriggerable_ones():
    without = {c for c, body in sections().items() if not examples(body)}
    assert without == NO_TRIGGER | {"E001", "W002", "E004", "E005", "E018", "E019"}
    for code in NO_TRIGGER:
        assert "Example: none" in sections()[code]


def test_every_section_says_how_to_fix():
    missing = [c for c, body in sections().items() if "**Fix:**" not in body]
    assert missing == []


@pytest.mark.parametrize("code", sorted(set(CODES) - NO_TRIGGER))
def test_documented_example_produces_its_code(code, tmp_path):
    body = sections()[code]
    files = examples(body)
    got = _codes_of_files(files) if files else _generated(code, tmp_path)
    assert code in got, f"{code}: the example gives {sorted(got)}"
