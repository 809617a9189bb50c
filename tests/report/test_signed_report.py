"""The change report a customer signs (issue 63), in headless Chromium with Playwright, on real
history pairs of ../shared/krl-history.

On rawpython's kukaKRLmagic ``01-53e3f517`` ("Proceding with execution.": the machine data of a
KR 30 L16 on KSS 8.3 replaced by a KR 120 R2700's on KSS 8.6), ``krl report NEW --since OLD
--no-runs``:

* the printed PDF's first page identifies both backups -- their paths, the controller, the
  robot and the software version read here from each ``$machine.dat`` by a regular expression,
  and a SHA-256 computed here from the files -- names the generator and carries the signature
  block; every page is numbered "Page N of M";
* every link of the report opens in the page itself (no file to download) at its line: its
  target is the line of a file of the side it names, whose text is that line of the file on
  disk; a click scrolls the line into view and marks it;
* at the printed page's width no code or change cell wraps, nor a place of up to 30 characters.

Nightly (slow): the PDF of paulovictor237's KUKA-Paletizador ``04-72cb25e4`` ("Novo ConfigDat":
41 modules moved from MainRoutune/ to Main_Program/, the pair with the most files changed) is at
most a third of the 243 pages the report printed before issue 63 (measured on 17116f8 with this
test's Chromium, A4, --no-runs, 2026-11-26).

The three tests of the signed report share its page, loaded once (:func:`report_page`: a load lays
out the report's program map, about 2.5 s of Chromium's CPU each time; the tests ran on three
loads of it before, 2026-11-29); each sets back what it changes (the print media and the
window's size), and clicking a link only moves the page's scroll and its ``:target``.
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from pypdf import PdfReader

from app import main
from tests.chromium import POLL_MS
from tests.report.test_report_chromium import loaded_page
from tests.system_tools import require

# the tests on the report's page share it (a module fixture): one xdist group, so that one
# worker loads it once
ON_REPORT_PAGE = pytest.mark.xdist_group("signed-report-page")

PAIR = "rawpython__kukaKRLmagic/01-53e3f517"
MOVED = "paulovictor237__KUKA-Paletizador/04-72cb25e4"
PAGES_BEFORE = 243           # KUKA-Paletizador 04-72cb25e4's report on 17116f8 (module docstring)


@pytest.fixture(scope="module")
def chromium() -> str:
    return require("chromium")


def _report(pair: Path, out: Path) -> Path:
    r = CliRunner().invoke(main, ["report", str(pair / "new"), "--since", str(pair / "old"), "--no-runs", "-o", str(out)])
    assert r.exit_code == 0, r.output
    return out


@pytest.fixture(scope="module")
def report(shared_history, tmp_path_factory) -> tuple[Path, Path]:
    pair = shared_history / PAIR
    return pair, _report(pair, tmp_path_factory.mktemp("signed") / "report.html")


@pytest.fixture(scope="module")
def report_page(pw, chromium, report):
    """The report's page (:func:`report`), loaded and laid out once for the tests on it."""
    with loaded_page(pw, chromium, report[1]) as page:
        _ready(page)
        yield page


def _ready(page) -> None:
    """Wait until the report's page is laid out (``body[data-ready=1]``)."""
    page.wait_for_function("document.body.dataset.ready === '1'", timeout=180_000, polling=POLL_MS)


def _krl_files(folder: Path) -> dict[str, Path]:
    return {p.relative_to(folder).as_posix().lower(): p for p in folder.rglob("*")
            if p.is_file() and p.suffix.lower() in (".src", ".dat", ".sub")}


def _sha256(folder: Path) -> str:
    """The backup's hash as docs/diff.md defines it: per KRL file, sorted by its lower-case
    path below the backup, ``path sha256-of-its-bytes``; the SHA-256 of those lines."""
    files = _krl_files(folder)
    lines = [f"{k} {hashlib.sha256(files[k].read_bytes()).hexdigest()}" for k in sorted(files)]
    return hashlib.sha256("\n".join(lines).encode()).hexdigest()


def _machine(folder: Path) -> tuple[str, str]:
    """(robot, KSS version) from the backup's $machine.dat, read here by regular expressions."""
    text = (folder / "R1" / "Mada" / "$machine.dat").read_text(encoding="latin-1")
    # the robot's model: $MODEL_NAME[] where the machine data has it (KSS 8.5 and later), else the
    # name of its coordinate transformation, $TRAFONAME[] ("#KR30L16_3A C4 FLR ZH16_2")
    names = {m.group(1).upper(): m.group(2) for m in re.finditer(r'^\s*\$(MODEL_NAME|TRAFONAME)\[\]\s*=\s*"([^"]*)"', text, re.M | re.I)}
    robot = names.get("MODEL_NAME") or names["TRAFONAME"]
    kss = re.search(r'\$V_R1MADA\[\d*\]\s*=\s*"[^"]*KUKA(\d+\.\d+)"', text, re.I).group(1)
    return robot.lstrip("#").strip(), kss


def _print(pw, chromium: str, page_file: Path, pdf: Path) -> list[str]:
    with loaded_page(pw, chromium, page_file) as page:
        _ready(page)
        return _printed(page, pdf)


def _printed(page, pdf: Path) -> list[str]:
    """The text of each page of ``page`` printed (A4) to ``pdf``."""
    page.pdf(path=str(pdf), format="A4", print_background=True)
    # Chromium sets "fi" and "fl" as ligatures
    return [p.extract_text().replace("\ufb01", "fi").replace("\ufb02", "fl") for p in PdfReader(str(pdf)).pages]


@ON_REPORT_PAGE
def test_the_first_printed_page_identifies_both_backups_and_carries_the_signatures(report, report_page, tmp_path):

    pair, _page_file = report
    texts = _printed(report_page, tmp_path / "report.pdf")
    first = re.sub(r"\s+", "", texts[0])            # a path or a hash wraps across lines
    assert "Changereport" in first
    for side in ("old", "new"):
        robot, kss = _machine(pair / side)
        for words in (str(pair / side), robot, f"KSS {kss}", _sha256(pair / side)):
            assert re.sub(r"\s+", "", words) in first, (side, words)
    assert f"KRLfiles{len(_krl_files(pair / 'old'))}{len(_krl_files(pair / 'new'))}" in first
    assert "controllerKRC4KRC4" in first             # KSS 8.x runs on a KR C4 (both sides)
    assert re.search(r"Generatedbykrl-tools\d+\.\d+\.\d+\(krlreport\),\d{4}-\d\d-\d\d\d\d:\d\dUTC", first), first
    for words in ("Signatures", "Changedby", "Reviewedby", "Acceptedby(customer)", "signature", "date"):
        assert words in first, words
    # the cover is a page of its own; every page numbered
    assert "Summary" not in texts[0].split("Signatures")[-1]
    for n, text in enumerate(texts, 1):
        assert f"Page {n} of {len(texts)}" in text, (n, text[:200])


# the target of a link: the side and file of its source view, the line's number and text
_TARGETS = """() => [...document.querySelectorAll('a[href]')].filter(a => !a.closest('#map')).map(a => {
  const href = a.getAttribute('href');
  const t = href.startsWith('#') ? document.getElementById(href.slice(1)) : null;
  const view = t && t.closest('section.source');
  return {href, text: a.textContent, where: a.classList.contains('where'),
          target: t ? t.textContent : null, line: t && t.querySelector('.ln') ? t.querySelector('.ln').textContent : null,
          view: view ? view.querySelector('h3').textContent : null};
})"""


@ON_REPORT_PAGE
def test_every_link_opens_in_the_page_at_its_line(report, report_page):

    pair, _page_file = report
    page = report_page
    links = page.evaluate(_TARGETS)
    places = [x for x in links if x["where"]]
    # read from `diff -r old new` and krl check on each side: 6 points, 105 values, 9
    # declarations, the findings of both sides, the lines not understood of kuka_internals.dat
    assert len(places) > 100
    for x in links:
        assert x["href"].startswith("#"), x          # nothing leaves the page: no file to download
        assert x["target"] is not None, x            # and every anchor exists
    for x in places:
        assert x["view"] is not None, x
        side, file = x["view"].split(": ", 1)
        file = file.split(" (the lines")[0].strip()
        line = int(x["line"])
        if ":" in x["text"]:                         # file:line (a routine's changed line shows its number)
            shown, n = x["text"].rsplit(":", 1)
            assert int(n) == line and shown.lower() in (file.lower(),), x
        text = (pair / side / file).read_bytes().decode("latin-1").splitlines()[line - 1]
        assert x["target"].rstrip() == f"{line} {text.rstrip()}", x
    # a click scrolls the line into view and marks it
    for sel in ("#introduced-table a.where", "#removed-table a.where", "table.diff-points a.where"):
        link = page.locator(sel).first
        href = link.get_attribute("href")
        link.click()
        page.wait_for_function(f"location.hash === '{href}'", polling=POLL_MS)
        target = page.locator(href)
        assert page.evaluate("document.querySelector(':target').id") == href[1:]
        box, height = target.bounding_box(), page.viewport_size["height"]
        assert box is not None and 0 <= box["y"] and box["y"] + box["height"] <= height, (href, box)


# the lines a cell's text takes, at the printed page's width
_LINES = """sel => [...document.querySelectorAll(sel)].filter(e => e.offsetParent !== null).map(e => {
  const r = document.createRange(); r.selectNodeContents(e);
  const tops = new Set([...r.getClientRects()].filter(x => x.width > 0).map(x => Math.round(x.top)));
  return [e.textContent.trim(), tops.size];
})"""


@ON_REPORT_PAGE
def test_tables_are_readable_at_print_width(report_page):
    # issue 63: the findings table squeezed its code column to one character per line. At the
    # printed page's width (A4 less the margins: 186 mm, 703 px) with the print style sheet,
    # every code and change cell is one line, and every place of up to 30 characters too

    page = report_page
    window = page.viewport_size
    page.emulate_media(media="print")
    page.set_viewport_size({"width": 703, "height": 1000})
    try:
        codes = page.evaluate(_LINES, "table.findings td.code, table.codes td.code, .diff-wrap td.change")
        assert len(codes) > 10 and all(n == 1 for _t, n in codes), [c for c in codes if c[1] != 1]
        places = [(t, n) for t, n in page.evaluate(_LINES, ".where") if len(t) <= 30]
        assert len(places) > 10 and all(n == 1 for _t, n in places), [p for p in places if p[1] != 1]
    finally:                                    # the page as the other tests see it
        page.emulate_media(media="null")
        page.set_viewport_size(window)


@pytest.mark.slow
def test_the_pdf_of_a_pair_with_moved_modules_is_a_third_of_what_it_was(chromium, shared_history, tmp_path, pw):

    pair = shared_history / MOVED
    page_file = _report(pair, tmp_path / "moved.html")
    texts = _print(pw, chromium, page_file, tmp_path / "moved.pdf")
    assert len(texts) <= PAGES_BEFORE // 3, len(texts)
    whole = re.sub(r"\s+", " ", " ".join(texts))
    # the 41 modules moved (counted from the two folders' file lists) are moves, not removals
    # and additions
    old, new = _krl_files(pair / "old"), _krl_files(pair / "new")
    only_old = [k.rsplit("/", 1)[-1] for k in old if k not in new]
    only_new = [k.rsplit("/", 1)[-1] for k in new if k not in old]
    moved = [n for n in only_old if only_old.count(n) == 1 and only_new.count(n) == 1]
    assert len(moved) == 41 and "Moved, compared with their old place (41)" in whole
