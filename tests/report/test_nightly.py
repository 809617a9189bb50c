"""The nightly's history, flags and index (issue 27), on two real nights made by the tools.

Night 1 and night 2 are written by the project's own tools on small inputs: `krl recover`
over a folder of three KRL files and the conformance runner over two hand-written cases, on
the tree interpreter. Between the nights one file is made unparsable and one case is broken
(its expected flow is changed), the regressions the index must flag; nothing else changes.
"""

from __future__ import annotations

import json
import shutil
import sqlite3
from pathlib import Path

import pytest

from conformance import harness as H
from conformance.nightly import flags as F
from conformance.nightly import history
from conformance.nightly.figures import Night, kind_of, read_night
from conformance.nightly.index import write_index
from conformance.report import run_cases, write_report
from recovery.pipeline import run_recovery as recover_run

REPO = Path(__file__).resolve().parents[2]
CASES = ("001_assign_arith", "002_if_else")
GOOD = "DEF {name}()\n  DECL INT n\n  n = 1\nEND\n"


def _night(root: Path, date: str, corpus: Path, cases: Path) -> Path:
    day = root / date
    recover_run(corpus, day / "recovery", jobs=1, use_cache=False)
    outcomes = run_cases([H.load_case(cases / c) for c in CASES], ["tree"])
    write_report(day / "conformance", outcomes, plots=False)
    return day


@pytest.fixture(scope="module")
def two_nights(tmp_path_factory):
    """(the nightly root, night 1's index, night 2's index): made once for the two tests that
    read them (1.9 s of CPU a time, 2026-11-26); they share one xdist group (make test)."""
    tmp_path = tmp_path_factory.mktemp("two-nights")
    corpus, cases, root = tmp_path / "corpus", tmp_path / "cases", tmp_path / "nightly"
    corpus.mkdir()
    for name in ("a", "b", "c"):
        (corpus / f"{name}.src").write_text(GOOD.format(name=name), encoding="ascii")
    for c in CASES:
        shutil.copytree(REPO / "conformance" / "cases" / c, cases / c)
    _night(root, "2026-11-20", corpus, cases)
    first = write_index(root)
    # the regressions injected on purpose: b.src loses its END, case 002 expects another flow
    (corpus / "b.src").write_text("DEF b()\n  DECL INT n\n  n = 1\n", encoding="ascii")
    expect = cases / CASES[1] / "expect.yaml"
    text = expect.read_text(encoding="utf-8")
    start = text.index("flow:")
    expect.write_text(text[:start] + "flow: [99]\n" + text[text.index("\n", start) + 1:], encoding="utf-8")
    _night(root, "2026-11-21", corpus, cases)
    return root, first, write_index(root)


@pytest.mark.xdist_group("nightly-two-nights")
def test_two_nights_make_a_history_of_two_points_and_charts(two_nights):
    root, first, index = two_nights
    assert history.nights(root / "history.sqlite") == ["2026-11-20", "2026-11-21"]
    series = history.series(root / "history.sqlite")
    # three files, all parse the first night; two the second (hand count)
    assert series["corpus.files_ok"] == [("2026-11-20", 3.0), ("2026-11-21", 2.0)]
    assert series["conformance.passed"] == [("2026-11-20", 2.0), ("2026-11-21", 1.0)]
    html = index.read_text(encoding="utf-8")
    assert (root / "trends" / "corpus.files_ok.png").stat().st_size > 1000
    assert 'src="trends/corpus.files_ok.png"' in html
    assert "2 night(s) in the history" in html


@pytest.mark.xdist_group("nightly-two-nights")
def test_the_injected_regressions_are_flagged_with_links(two_nights):
    root, _, index = two_nights
    html = index.read_text(encoding="utf-8")
    md = (root / "index.md").read_text(encoding="utf-8")
    assert "Changes since 2026-11-20" in html
    assert "case 002_if_else: pass -&gt; FAIL" in html
    assert 'href="2026-11-21/conformance/report.html#002_if_else"' in html
    assert "corpus_file b.src: ok -&gt; syntax_error" in html
    assert 'href="2026-11-21/recovery/report.html"' in html
    assert "conformance.passed: 2 -&gt; 1" in html
    # exactly the injected changes and the counts they move, nothing else
    lines = [ln for ln in md.splitlines() if ln.startswith("- **")]
    subjects = sorted(ln.split("[", 1)[1].split(":", 1)[0] for ln in lines)
    assert subjects == ["case 002_if_else", "conformance.passed", "corpus.files_ok", "corpus_file b.src"]
    assert all(ln.startswith("- **regression**") for ln in lines)


def test_first_night_has_no_changes(tmp_path):
    day = tmp_path / "2026-11-20" / "conformance"
    day.mkdir(parents=True)
    (day / "summary.json").write_text(json.dumps({"cases": 1, "passed": 1, "case_status": {"x": "pass"}}))
    html = write_index(tmp_path).read_text(encoding="utf-8")
    assert "Changes since" not in html and "1 night(s)" in html


def test_noise_band_is_measured_from_the_history():
    assert F.noise_band([5.0, 6.0]) is None                    # too few nights
    # sorted 5 5 6 7: median 5.5; deviations 0.5 0.5 1.5 0.5 -> MAD 0.5, 3 * 1.4826 * 0.5 = 2.2239;
    # night-to-night steps 1 1 2 -> 2; the wider wins: 5.5 +- 2.2239
    low, high = F.noise_band([5.0, 6.0, 7.0, 5.0])
    assert (round(low, 4), round(high, 4)) == (3.2761, 7.7239)
    series = {"bench.vm_vs_tree": [("d1", 6.0), ("d2", 6.2), ("d3", 5.9), ("d4", 3.0)]}
    (flag,) = F.figure_flags(series, "d4")
    assert flag.severity == "regression" and "outside its noise band" in flag.text
    series["bench.vm_vs_tree"][-1] = ("d4", 6.1)
    assert F.figure_flags(series, "d4") == []


def test_item_changes_and_missing_reports():
    before = {("case", "a"): "pass", ("case", "b"): "FAIL", ("corpus_file", "x.src"): "ok"}
    after = {("case", "a"): "FAIL", ("case", "b"): "pass", ("case", "c"): "pass"}
    got = {f.subject: f.severity for f in F.item_flags(before, after, "d")}
    assert got == {"case:a": "regression", "case:b": "improvement", "case:c": "change", "corpus_file:*": "change"}


def test_kinds_and_a_damaged_night(tmp_path):
    assert (kind_of("bench.vm_vs_tree"), kind_of("corpus.files_ok"), kind_of("bench.parse_kb_per_s")) == \
        ("ratio", "count", "info")
    day = tmp_path / "2026-11-22"
    (day / "conformance").mkdir(parents=True)
    (day / "conformance" / "summary.json").write_text("{not json")
    night = read_night(day)
    assert night.figures == {} and any("unreadable" in n for n in night.notes)


def test_a_foreign_history_file_is_a_clear_error(tmp_path):
    (tmp_path / "history.sqlite").write_text("not a database" * 100)
    with pytest.raises(history.HistoryError, match="not a nightly history"):
        write_index(tmp_path)


def test_recording_a_night_twice_replaces_it(tmp_path):
    h = tmp_path / "h.sqlite"
    history.record(h, Night("d1", {"x": 1.0}, {("case", "a"): "pass"}))
    history.record(h, Night("d1", {"x": 2.0}, {}))
    assert history.series(h) == {"x": [("d1", 2.0)]} and history.items(h, "d1") == {}
    with sqlite3.connect(h) as con:
        assert con.execute("SELECT count(*) FROM nights").fetchone() == (1,)
