"""The change report of the README's example (issue 49), in headless Chromium with Playwright.

The README's transcript makes `out/new-backup` (the Palletizer with XC1 retaught and tool 1
5.5 mm longer) and writes `out/change.html` with ``krl report``; tests/docs/conftest.py runs it
once. Here:

* on one screen (1280 x 800), the page opens with its contents, the summary and the whole
  diff of the example (the point and the tool);
* every finding and every change links to its file and line: the link opens the report's own
  view of a file of the backup at that line (issue 63: in the page, not a file: URL Chromium
  downloads), its text is ``path:line`` of that file, and the line holds what the row says
  (the finding's source line; the point's or the tool's name);
* printed by Chromium (``page.pdf``, A4), the PDF is legible: its first page is the cover (the
  backups identified, the signature block; tests/report/test_signed_report.py checks it on a
  history pair), its text (pypdf) holds the summary and the diff on the second page, every run
  of text is at least 7 pt, no part is a picture, and no file:line is cut.

And on a history pair whose change introduces and removes findings (KnoP-01's krl-for-vim9
``01-8fae7e9c``: "Fix typo: Name should come without extension" -- the header
``DEF fahrwege_small.src( )`` fixed, its two syntax errors go, and the parser, now past it, finds
two further down), the introduced and removed findings link to the new and old backup's lines.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from pypdf import PdfReader

from app import main
from tests.system_tools import require
from tests.docs import transcripts as T

# the README's example runs 44 programs for its report: minutes on a loaded machine (the first
# test that asks for the documents' run pays for it)
# and they share that run: one xdist worker takes the whole group (make test: --dist loadgroup)
pytestmark = [pytest.mark.timeout(3600), pytest.mark.xdist_group("docs")]
from tests.report.test_report_chromium import loaded_page

README = T.REPO / "README.md"
SCREEN = {"width": 1280, "height": 800}


@pytest.fixture(scope="module")
def chromium() -> str:
    return require("chromium")


@pytest.fixture(scope="module")
def example(document_runs):
    """(the folder the README's commands ran in, its change report)."""
    _results, work = document_runs(README)
    page = work / "out" / "change.html"
    assert page.is_file(), "the README's example no longer writes out/change.html (krl report ... -o out/change.html)"
    return work, page


@pytest.fixture(scope="module")
def change_page(chromium, example, pw):
    """The README's change report loaded once in Chromium (tests/report/test_report_chromium.py
    ``loaded_page``: no console error or warning, page error or failed request at its load), on
    the one screen (:data:`SCREEN`), its map laid out: the tests below only read it (the first
    screen's boxes, the rows' links, a print), and each load laid the Palletizer's map out again
    (ELK in the page: 2.9 s of Chromium's CPU a load, a cgroup, 2026-11-29)."""
    _work, page_file = example
    with loaded_page(pw, chromium, page_file) as page:
        page.set_viewport_size(SCREEN)
        page.wait_for_function("document.body.dataset.ready === '1'", timeout=180_000)
        yield page


def test_summary_and_diff_on_the_first_screen(change_page):
    page = change_page
    page.set_viewport_size(SCREEN)
    page.wait_for_function("document.body.dataset.ready === '1'", timeout=180_000)
    page.evaluate("window.scrollTo(0, 0)")
    bottom = lambda sel: page.evaluate(f"document.querySelector('{sel}').getBoundingClientRect().bottom")  # noqa: E731
    for sel in ("#toc", "#summary-list", "#changes", "table.diff-points", "table.diff-frames"):
        assert bottom(sel) <= SCREEN["height"], (sel, bottom(sel))
    assert page.locator("table.diff-points").inner_text().count("XC1") == 1
    assert "ΔX +1.5 mm, ΔZ -2 mm" in page.locator("table.diff-points").inner_text()
    assert "ΔZ +5.5 mm" in page.locator("table.diff-frames").inner_text()
    # the summary counts what the sections hold
    summary = page.locator("#summary-list").inner_text()
    assert "Points 1, Frames and loads 1" in summary
    assert f"{page.locator('#introduced-table tr.finding').count()} new" in summary
    # the map is the interactive one, never a picture
    assert page.locator("img").count() == 0 and page.locator("#map canvas").count() > 0


#: what the page shows of each finding row (``findings``, a CSS selector) and of each row of the
#: diff's tables (``places``), read in one pass over the page: a Playwright locator per row and
#: cell (each a round trip, ``all()``'s rows resolved from the whole list again) cost the history
#: pair's test 17.1 s of Chromium's CPU, 3.5 s so (a cgroup, 2026-11-28). The same properties
#: Playwright reads: innerText (``inner_text``), textContent (``text_content``), the attribute
#: ``href``; counts where Playwright's locator is strict (exactly one element).
_ROWS = """([findings, places]) => {
  const opened = (a) => {   // the report's view of a file a link opens: its section's heading "side: file", the line
    const href = a.getAttribute('href');
    if (!href || !href.startsWith('#src-')) return { href };
    const target = document.getElementById(href.slice(1));
    const h = target.closest('section.source').querySelector('h3');
    return { href, targets: document.querySelectorAll(href).length, side: h.textContent.split(':')[0],
             file: h.querySelector('code').textContent, text: target.textContent };
  };
  const row = (tr) => {
    const links = tr.querySelectorAll('a.where');
    const pres = tr.querySelectorAll('pre');
    const tds = tr.querySelectorAll('td');
    return { text: tr.innerText, th: tr.querySelectorAll('th').length, links: links.length,
             where: links.length === 1 ? links[0].innerText : null, opened: links.length === 1 ? opened(links[0]) : null,
             pres: pres.length, pre: pres.length === 1 ? pres[0].innerText : null, name: tds.length > 1 ? tds[1].innerText : null };
  };
  return { findings: [...document.querySelectorAll(findings)].map(row),
           places: [...document.querySelectorAll(places)].slice(1).map(row) };
}"""


def _opened(row: dict) -> tuple[str, str, int, str]:
    """(side, file, line, text) of the line the link of ``row`` (of :data:`_ROWS`) opens: the
    report's view of the file (its section's heading ``side: file``) and the line it marks."""
    o = row["opened"]
    assert o["href"].startswith("#src-") and o["targets"] == 1, o
    n, _, line_text = o["text"].partition(" ")
    return o["side"], o["file"], int(n), line_text


def _check_links(page, root: Path, findings: str = "table.findings tr.finding", side: str = "new") -> int:
    """Every place of the diff and of the findings (rows `findings`) opens the report's view of
    a file below `root` at a line that holds what its row says; returns the number of links
    checked."""
    rows = page.evaluate(_ROWS, [findings, "table.diff-points tr, table.diff-frames tr"])
    n = 0
    for row in rows["findings"]:
        assert row["links"] == 1, row["text"]
        opened_side, file, opened, shown = _opened(row)
        rel, line = row["where"].rsplit(":", 1)
        assert (opened_side, file, opened) == (side, rel, int(line)) and (root / rel).is_file()
        text = (root / rel).read_text(encoding="latin-1").splitlines()[int(line) - 1]
        assert shown.rstrip() == text.rstrip()
        assert row["pres"] == 1 and row["pre"] == f"{line} | {text.rstrip()}"
        n += 1
    for row in rows["places"]:
        if row["th"]:
            continue
        assert row["links"] == 1, row["text"]
        _side, file, opened, shown = _opened(row)
        rel, line = row["where"].rsplit(":", 1)
        assert (file, opened) == (rel, int(line))
        name = row["name"]
        assert name in (root / rel).read_text(encoding="latin-1").splitlines()[int(line) - 1] and name in shown
        n += 1
    return n


def test_every_finding_and_change_links_to_its_file_and_line(example, change_page):
    work, _page_file = example
    page = change_page
    # the example's new backup has warnings (all listed), the point and the tool
    assert page.locator("#all-findings-table tr.finding").count() > 0
    assert _check_links(page, work / "out" / "new-backup") >= 2 + page.locator("#all-findings-table tr.finding").count()


def test_findings_introduced_and_removed_link_to_each_side(chromium, shared_history, tmp_path, pw):
    pair = shared_history / "KnoP-01__krl-for-vim9" / "01-8fae7e9c"
    out = tmp_path / "pair.html"
    # in this process (click's CliRunner): the README's transcript runs `krl report` as a user
    # does, in a process of its own (tests/docs/test_transcripts.py)
    r = CliRunner().invoke(main, ["report", str(pair / "new"), "--since", str(pair / "old"), "--no-runs", "-o", str(out)])
    assert r.exit_code == 0, r.output
    with loaded_page(pw, chromium, out) as page:
        # read from `diff -r old new` and krl check on each side: the header's two errors
        # (lines 5 and 8) are gone; the old header failed, so the old check understood none of
        # the file's 106 code lines (issue 63): what the new check finds on them (the syntax
        # errors of lines 104 and 120 among them, the same text on both sides) is listed apart,
        # not as introduced
        new = page.locator("#introduced-table tr.finding")
        old = page.locator("#removed-table tr.finding")
        apart = page.locator("#newly-read-table tr.finding")
        assert new.count() == 0
        assert [r.locator("a.where").inner_text() for r in old.all()] == [
            "tests/testdir/resource_Folding/fahrwege_small.src:5", "tests/testdir/resource_Folding/fahrwege_small.src:8"]
        where = [r.locator("a.where").inner_text() for r in apart.all()]
        assert {"tests/testdir/resource_Folding/fahrwege_small.src:104",
                "tests/testdir/resource_Folding/fahrwege_small.src:120"} <= set(where)
        assert _check_links(page, pair / "new", "#newly-read-table tr.finding, #all-findings-table tr.finding") >= 2
        assert _check_links(page, pair / "old", "#removed-table tr.finding", side="old") >= 2


def _pdf_text_sizes(pdf: Path) -> tuple[list[str], list[float], int]:
    reader = PdfReader(str(pdf))
    texts, sizes, images = [], [], 0
    for page in reader.pages:
        def visit(text, cm, tm, _font, size):
            if text.strip():
                sizes.append(size * math.hypot(tm[0], tm[1]) * math.hypot(cm[0], cm[1]))
        texts.append(page.extract_text(visitor_text=visit))
        images += len(page.images)
    return texts, sizes, images


def test_the_printed_pdf_is_legible(change_page, tmp_path):
    pdf = tmp_path / "change.pdf"
    change_page.wait_for_function("document.body.dataset.ready === '1'", timeout=180_000)
    change_page.pdf(path=str(pdf), format="A4", print_background=True)
    texts, sizes, images = _pdf_text_sizes(pdf)
    cover = re.sub(r"\s+", " ", texts[0])
    for words in ("Change report", "SHA-256", "Signatures", "Changed by", "Reviewed by", "Accepted by"):
        assert words in cover, words
    assert "Summary" not in cover.split("Signatures")[-1]
    first = re.sub(r"\s+", " ", texts[1])
    for words in ("Change report", "Summary", "Changes: Points 1, Frames and loads 1", "Check ﬁndings:",
                  "Run outcomes:", "Program map:", "Program/CAJA_G/caja_g_m1.dat:24", "XC1", "ΔX +1.5 mm, ΔZ -2 mm",
                  "System/$conﬁg.dat:231", "TOOL_DATA[1]", "ΔZ +5.5 mm"):
        assert words.replace("ﬁ", "fi") in first.replace("ﬁ", "fi"), words
    assert 2 <= len(texts) <= 20
    assert min(sizes) >= 7.0, sorted(sizes)[:5]          # points: nothing in small print
    assert images == 0                                    # the map is not printed as a picture
    whole = re.sub(r"\s+", " ", " ".join(texts))
    assert "The interactive map" in whole and "Dead routines" in whole
