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


def _opened(page, link) -> tuple[str, str, int, str]:
    """(side, file, line, text) of the line `link` opens: the report's view of the file
    (its section's heading ``side: file``) and the line it marks."""
    href = link.get_attribute("href")
    assert href.startswith("#src-"), href
    side, file = page.evaluate("""id => {
        const h = document.getElementById(id).closest('section.source').querySelector('h3');
        return [h.textContent.split(':')[0], h.querySelector('code').textContent]; }""", href[1:])
    text = page.locator(href).text_content()
    n, _, line_text = text.partition(" ")
    return side, file, int(n), line_text


def test_summary_and_diff_on_the_first_screen(chromium, example, pw):

    _work, page_file = example
    with loaded_page(pw, chromium, page_file) as page:
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


def _check_links(page, root: Path, findings: str = "table.findings tr.finding", side: str = "new") -> int:
    """Every place of the diff and of the findings (rows `findings`) opens the report's view of
    a file below `root` at a line that holds what its row says; returns the number of links
    checked."""
    n = 0
    for row in page.locator(findings).all():
        link = row.locator("a.where")
        assert link.count() == 1, row.inner_text()
        opened_side, file, opened, shown = _opened(page, link)
        rel, line = link.inner_text().rsplit(":", 1)
        assert (opened_side, file, opened) == (side, rel, int(line)) and (root / rel).is_file()
        text = (root / rel).read_text(encoding="latin-1").splitlines()[int(line) - 1]
        assert shown.rstrip() == text.rstrip()
        pre = row.locator("pre")
        assert pre.inner_text() == f"{line} | {text.rstrip()}"
        n += 1
    for row in page.locator("table.diff-points tr, table.diff-frames tr").all()[1:]:
        if row.locator("th").count():
            continue
        link = row.locator("a.where")
        _side, file, opened, shown = _opened(page, link)
        rel, line = link.inner_text().rsplit(":", 1)
        assert (file, opened) == (rel, int(line))
        name = row.locator("td").nth(1).inner_text()
        assert name in (root / rel).read_text(encoding="latin-1").splitlines()[int(line) - 1] and name in shown
        n += 1
    return n


def test_every_finding_and_change_links_to_its_file_and_line(chromium, example, pw):
    work, page_file = example
    with loaded_page(pw, chromium, page_file) as page:
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


def test_the_printed_pdf_is_legible(chromium, example, tmp_path, pw):
    _work, page_file = example
    pdf = tmp_path / "change.pdf"
    with loaded_page(pw, chromium, page_file) as page:
        page.wait_for_function("document.body.dataset.ready === '1'", timeout=180_000)
        page.pdf(path=str(pdf), format="A4", print_background=True)
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
