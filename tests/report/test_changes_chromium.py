"""The pages of krl diff, krl graph and krl report (issue 26) rendered in headless Chromium, as
report.html is (tests/report/test_report_chromium.py): they load without console errors, their
key elements are there with the values counted by hand from tests/programmap/fixtures, and
markup from a backup (a file name, a KRL string) stays inert text."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main
from tests.report.test_report_chromium import loaded_page
from tests.system_tools import require

FIXTURE = Path(__file__).parents[1] / "programmap" / "fixtures" / "KRC"
IMG = "<img src=x onerror=window.pwned=1>"
SCRIPT = "<script>window.pwned=1</script>"
LONG = "a_long_text_without_spaces_" * 12


@pytest.fixture(scope="module")
def chromium() -> str:
    require("dot")
    return require("chromium")


@pytest.fixture(scope="module")
def pages(tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("pages")
    old, new = root / "old" / "KRC", root / "new" / "KRC"
    shutil.copytree(FIXTURE, old)
    shutil.copytree(FIXTURE, new)
    (new / "R1" / "Program" / f"{IMG}.src").write_text("DEF odd()\nEND\n")
    # an added point (its coordinates are shown) and a long line (it wraps)
    (new / "R1" / "Program" / "points.dat").write_text(
        "DEFDAT points\nDECL E6POS XP_NEW={X 1.5,Y -2.0,Z 300.25,A 0.0,B 90.0,C 180.0,S 6,T 2}\nENDDAT\n")
    pick = new / "R1" / "Program" / "pick.src"
    text = pick.read_text()
    assert text.count("  n = helper_fct(2)\n") == 1
    pick.write_text(text.replace("  DECL EKI_STATUS ret\n", f"  DECL EKI_STATUS ret\n  DECL CHAR msg[40]\n")
                    .replace("  n = helper_fct(2)\n", f'  n = helper_fct(3)\n  msg[] = "{SCRIPT}"\n  msg[] = "{LONG}"\n'))
    out = {}
    runner = CliRunner()
    for name, args in (("report", ["report", str(new), "--since", str(old)]),
                       ("graph", ["graph", str(new), "--format", "html"]),
                       ("diff", ["diff", str(old), str(new), "--format", "html"])):
        out[name] = root / f"{name}.html"
        r = runner.invoke(main, [*args, "-o", str(out[name])])
        assert r.exit_code == (1 if name == "diff" else 0), r.output
    return out


def _open(pw, chromium, page_path: Path, check, scripts: int = 0):
    with loaded_page(pw, chromium, page_path) as page:
        # the interactive map has two: its JSON data and the vendored front end
        assert page.evaluate("document.querySelectorAll('script').length") == scripts
        assert page.evaluate("window.pwned === undefined")
        check(page)


def test_change_pages_render_in_headless_chromium(chromium, pages, pw):

    def graph(page):
        assert page.locator("h1").inner_text() == "Program map"
        page.wait_for_function("document.body.dataset.ready === '1'", timeout=120_000)
        # 13 routines (the 12 of the fixture + odd), 9 edges; the 8 entry points of the fixture
        # (tests/programmap/test_graph.py) and odd, selectable under R1/Program; dead: 1
        assert page.locator("table.map-entries tr[class^=entry-]").count() == 8 + 1
        assert page.locator("table.map-entries tr.entry-operator").count() == 4      # aux, orphan, pick, odd
        assert page.locator("table.map-unreachable tr").count() == 1 + 1
        # orphan and odd: modules only an operator starts
        assert page.locator("table.map-operator-only tr").count() == 1 + 2
        assert page.locator("table.map-edges tr").count() == 1 + 9
        assert IMG in page.locator("table.map-entries").last.text_content()   # the module name, as text
        assert page.locator("img").count() == 0
        assert page.evaluate("document.querySelector('script[type=\"application/json\"]').id") == "map-data"

    def diff(page):
        routines = page.locator("section.diff-routine")
        assert routines.count() == 2                  # pick changed, odd added
        assert f"added {IMG}:odd" in routines.nth(0).inner_text()         # files in name order
        text = routines.nth(1).inner_text()
        assert "changed pick:pick" in text
        assert "- 6: n = helper_fct(2)" in text and "+ 7: n = helper_fct(3)" in text
        assert f'msg[] = "{SCRIPT}"' in text
        assert page.locator("table.diff-declarations tr").count() == 1 + 2   # msg and XP_NEW added
        # the added point with its coordinates
        assert page.locator("table.diff-points .coordinates").inner_text() == \
            "X 1.5, Y -2, Z 300.25, A 0, B 90, C 180, S 6, T 2"
        # the long line wraps inside the page: nothing is wider than the window
        assert LONG in text
        assert page.evaluate("document.documentElement.scrollWidth <= window.innerWidth")
        assert page.evaluate("[...document.querySelectorAll('pre')].every(p => p.scrollWidth <= p.clientWidth + 1)")

    def report(page):
        # the summary first, then the diff; the map is the interactive one (no picture), its
        # tables without the edge list
        assert page.locator("#summary-list li").count() == 5          # changes, findings, runs, retest, map
        assert page.locator("table.map-edges").count() == 0 and page.locator("img").count() == 0
        page.wait_for_function("document.body.dataset.ready === '1'", timeout=120_000)
        assert page.locator("table.map-unreachable tr").count() == 1 + 1
        diff(page)

    _open(pw, chromium, pages["graph"], graph, scripts=2)
    _open(pw, chromium, pages["diff"], diff)
    _open(pw, chromium, pages["report"], report, scripts=2)
