"""report.html rendered in headless Chromium (issue 13): it loads without console errors, its key
elements are there, and markup from the corpus stays inert (issue 12)."""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import pytest

from recovery.report import summarise, write_report
from tests.report.test_recovery_report import corpus_results
from tests.chromium import shared_browser
from tests.system_tools import require

CHROMIUM = "/usr/bin/chromium"
PWNED = "<script>window.pwned=1</script>"


@pytest.fixture(scope="module")
def chromium() -> str:
    """The Debian chromium (make test installs it; missing: a failure naming the command)."""
    return require("chromium")


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("report")
    results = corpus_results()
    # markup in a KRL line and in a file name
    results[1].issues[0].line_text = f"IF nCount = 2 THEN ; {PWNED}"
    results[1].path = f"prog/{PWNED}.src"
    s = summarise(results, "g" * 64, str(out / "corpus"), 1.0, known_invalid={"tmpl/k.src"})
    s.extra["check"] = {"markdown": f"## Front end: `krl check`\n\n| backup | errors |\n|---|---:|\n| {PWNED} | 3 |\n"}
    write_report(out, s, results)
    return out / "report.html"


@contextmanager
def loaded_page(pw, chromium: str, path: Path, viewport: dict | None = None):
    """A page of a fresh browser context (no cookie, storage or cache of another page) with
    `path` loaded, after checking that loading it logged no console error or warning, no page
    error and no failed request (:func:`load_checked`); the browser is the driver's one
    (tests/chromium.py). ``viewport``: the window's size from the start (Playwright's default,
    1280 x 720, when None)."""
    ctx = shared_browser(pw, chromium).new_context(**({"viewport": viewport} if viewport else {}))
    try:
        page = ctx.new_page()
        page.problems = []
        page.on("console", lambda m: page.problems.append(f"{m.type}: {m.text}") if m.type in ("error", "warning") else None)
        page.on("pageerror", lambda e: page.problems.append(f"page error: {e}"))
        page.on("requestfailed", lambda r: page.problems.append(f"request failed: {r.url}"))
        load_checked(page, path)
        yield page
    finally:
        ctx.close()


def load_checked(page, path: Path) -> None:
    """Load `path` into ``page`` (one of :func:`loaded_page`) and check that loading it logged no
    console error or warning, no page error and no failed request."""
    page.problems.clear()
    page.goto(path.as_uri())
    page.wait_for_load_state("load")
    assert page.problems == []


def test_report_renders_in_headless_chromium(chromium, report, pw):
    with loaded_page(pw, chromium, report) as page:
        assert page.title() == "KRL grammar recovery report"
        assert page.locator("h1").inner_text() == "Grammar recovery report"
        assert page.locator("table#summary tr").count() == 3
        # one ranked construct (IF, 2 files), shown with its line shape and example links
        cards = page.locator("#missing ~ section.cluster")
        assert page.locator("section.cluster").count() == 2          # IF ranked + TODO known-invalid
        first = cards.first.inner_text()
        assert "IF — 2 files, 2 occurrences" in first and "Line shape: IF ‹name› =" in first
        assert page.locator("a.example").count() == 3
        # the chart loaded and has a size
        assert page.evaluate("document.getElementById('chart').naturalWidth") > 500
        assert page.locator("#known-invalid").count() == 1 and page.locator("#internal").count() == 1
        assert "deep/i.src" in page.locator("#internal ~ table").first.inner_text()
        # the static-check Markdown is a real table
        assert page.locator("#static-check table tr").count() == 2
        # markup from the corpus is text: no script element, nothing ran
        assert page.evaluate("document.querySelectorAll('script').length") == 0
        assert page.evaluate("window.pwned === undefined")
        assert PWNED in page.locator("#missing ~ section.cluster").first.inner_text()
        page.screenshot(path=str(report.with_name("report.png")), full_page=True)
    assert report.with_name("report.png").stat().st_size > 10_000
