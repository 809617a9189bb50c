"""Issue 63: one line the grammar does not know never hides a file.

The case the issue describes, rebuilt: a cell's ``$config.dat`` holds one line the project does
not accept (``CHAR sReg_01[]`` in a data list), and ``krl diff`` then listed the whole file as
"not compared (syntax errors)", naming the wrong side's file, while tools, bases and about sixty
signals had changed. Here two corpus backups whose tools, bases, loads, points and signals
differ (HugoDanielson ChinaMilling's KRC and khrzysio's KRC4_test, both KRC/R1 layouts: their
``R1/System/$config.dat`` are one file to the diff) get such a line in their ``$config.dat``, at
another line on each side and with another name on the new side. The expected changes come from
the intact copies, by means that share no code with krl/diff: every value by
tests/diff/oracle.py, every SIGNAL by reading the lines with a regular expression, and the
count of declarations by counting the data list's code lines.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from krl.diff.core import diff_sides
from krl.diff.load import side as load_side
from krl.diff.text import diff_text
from tests.diff import oracle
from tests.test_json_schemas import validate

OLD, NEW = "HugoDanielson__ChinaMilling/KRC", "khrzysio__KRC4_test"
CONFIG = "R1/System/$config.dat"
#: (side, line after which the line not understood goes, its text)
BROKEN = {"old": (60, "CHAR sReg_01[]"), "new": (69, "CHAR sReg_02[]")}
_SIGNAL = re.compile(r"^\s*(GLOBAL\s+)?SIGNAL\s+(\w+)\s+(.*?)\s*(;.*)?$", re.IGNORECASE)

pytestmark = pytest.mark.xdist_group("diff-partial")


def signals(path: Path) -> dict[str, str]:
    """{NAME: what it is wired to, spaces collapsed, upper-case} of a data list's SIGNAL lines."""
    out: dict[str, str] = {}
    for line in path.read_bytes().decode("latin-1").splitlines():
        m = _SIGNAL.match(line)
        if m:
            out.setdefault(m.group(2).upper(), " ".join(m.group(3).split()).upper())
    return out


def declaration_lines(path: Path) -> int:
    """The code lines of a data list (not blank, not a comment, not an `&` header line, not
    ENDDAT), DEFDAT included."""
    n = 0
    for line in path.read_bytes().decode("latin-1").splitlines():
        code = line.split(";", 1)[0].strip()
        if code and not code.startswith("&") and not code.upper().startswith("ENDDAT"):
            n += 1
    return n


@pytest.fixture(scope="module")
def pair(shared_corpus, tmp_path_factory):
    """(intact old, intact new, broken old, broken new) copies, and the reports of `krl diff`
    between the broken ones: its JSON document and its text lines."""
    root = tmp_path_factory.mktemp("partial")
    out = {}
    for side, name in (("old", OLD), ("new", NEW)):
        intact = root / f"intact-{side}"
        broken = root / f"broken-{side}"
        shutil.copytree(shared_corpus / name, intact)
        shutil.copytree(shared_corpus / name, broken)
        after, text = BROKEN[side]
        cfg = broken / CONFIG
        lines = cfg.read_bytes().decode("latin-1").split("\n")
        assert lines[after - 1].lstrip().upper().startswith(("STRUC", "DECL", "SIGNAL", "ENUM", "INT", "REAL",
                                                              "BOOL", "CHAR", "FRAME", "E6POS", "GLOBAL")), lines[after - 1]
        lines.insert(after, text)
        cfg.write_bytes("\n".join(lines).encode("latin-1"))
        out[side] = (intact, broken)
    # one comparison of the broken copies for both reports: `krl diff --format json` prints
    # ``as_json()`` and the text report ``diff_text`` of the same Diff (app/changes.py), so the
    # second run of the command the text test made loaded both sides again (2.1 s of CPU,
    # 2026-11-29); its exit status is 1 for changes (``d.changed``), 2 for files not compared
    with load_side(out["old"][1]) as a, load_side(out["new"][1]) as b:
        d = diff_sides(a, b)
    assert d.changed and not d.not_compared
    doc = json.loads(json.dumps(d.as_json(), indent=2, ensure_ascii=False))
    validate("diff", doc)
    return out["old"][0], out["new"][0], out["old"][1], out["new"][1], doc, "\n".join(diff_text(d)).splitlines()


def test_every_value_of_config_dat_is_compared(pair):
    intact_old, intact_new, _bo, _bn, doc, _text = pair
    assert not doc["not_compared"]
    expected, skipped = oracle.compare(intact_old, intact_new)
    assert "r1/system/$config.dat" not in skipped
    want = {c for c in expected if c[0] == "r1/system/$config.dat"}
    got = {c for c in oracle.reported(doc) if c[0] == CONFIG.lower()}
    got = {("r1/system/$config.dat", name, change) for _f, name, change in got}
    assert want, "the two backups' $config.dat differ"
    assert got == want
    # the issue's own kinds: tools and bases zeroed or moved, loads changed
    frames = {e["name"].split("[")[0] for e in doc["frames"] if e["file"] == CONFIG}
    assert {"TOOL_DATA", "BASE_DATA", "LOAD_DATA"} <= frames


def test_every_signal_change_is_reported(pair):
    intact_old, intact_new, _bo, _bn, doc, _text = pair
    a, b = signals(intact_old / CONFIG), signals(intact_new / CONFIG)
    want = ({(n, "added") for n in b.keys() - a.keys()} | {(n, "removed") for n in a.keys() - b.keys()}
            | {(n, "retyped") for n in a.keys() & b.keys() if a[n] != b[n]})
    got = {(e["name"].upper(), e["change"]) for e in doc["declarations"]
           if e["file"] == CONFIG and e["kind"] == "signal"}
    assert len(want) > 50          # "about 60 signals added or removed" in the cell
    assert got == want


def test_the_line_not_understood_is_named_on_its_own_side(pair):
    intact_old, intact_new, _bo, _bn, doc, _text = pair
    partial = {e["side"]: e for e in doc["not_understood"] if e["file"] == CONFIG}
    assert set(partial) == {"old", "new"}
    for side, intact in (("old", intact_old), ("new", intact_new)):
        e = partial[side]
        after, _text = BROKEN[side]
        assert [x["line"] for x in e["lines"]] == [after + 1]
        # the decision of grammar/CHANGES.md: the controller rejects the open dimension too
        name = BROKEN[side][1].split()[1].split("[")[0]
        assert e["lines"][0]["message"] == (
            f"`{name}` has no size (`CHAR {name}[24]`): the controller rejects an open dimension outside a "
            f"parameter list and does not declare `{name}` (reference 3.3)")
        total = declaration_lines(intact / CONFIG) + 1
        assert (e["understood"], e["total"], e["noun"]) == (total - 1, total, "declarations")
    # compared by its text: the old line was replaced by the new one at its place
    lines = [e for e in doc["unparsed"] if e["file"] == CONFIG]
    assert lines == [{"file": CONFIG, "line": BROKEN["new"][0] + 1, "old_line": BROKEN["old"][0] + 1,
                      "text": BROKEN["new"][1], "old_text": BROKEN["old"][1], "change": "changed"}]


def test_the_text_report_says_it_first(pair):
    _io, _in, _bo, _bn, _doc, lines = pair
    heads = [i for i, ln in enumerate(lines) if "$config.dat" in ln and "not understood" in ln]
    first_section = next(i for i, ln in enumerate(lines) if re.match(r"^[A-Z][a-z].* \(\d+\):$", ln))
    assert heads and max(heads) < first_section
    total_new = declaration_lines(_in / CONFIG) + 1
    assert f"new: {CONFIG}:{BROKEN['new'][0] + 1} not understood: {total_new - 1:,} of {total_new:,} " \
           "declarations compared" in lines
