"""The pages of krl diff, krl graph and krl report (issue 26) rendered in headless Chromium, as
report.html is (tests/report/test_report_chromium.py): they load without console errors, their
key elements are there with the values counted by hand from tests/programmap/fixtures, and
markup from a backup (a file name, a KRL string) stays inert text."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from krl.cli import main
from tests.report.test_report_chromium import loaded_page

FIXTURE = Path(__file__).parents[1] / "programmap" / "fixtures" / "KRC"
IMG = "<img src=x onerror=window.pwned=1>"
SCRIPT = "<script>window.pwned=1</script>"


@pytest.fixture(scope="module")
def chromium() -> str:
    from tests.report.test_report_chromium import CHROMIUM  # noqa: PLC0415
    from tests.apt import apt_install  # noqa: PLC0415

    if not Path(CHROMIUM).exists() and apt_install("chromium", "chromium") is None:
        pytest.skip("chromium is not installed and cannot be installed with apt-get")
    if apt_install("graphviz", "dot") is None:
        pytest.skip("graphviz's dot is not installed and cannot be installed with apt-get")
    return CHROMIUM


@pytest.fixture(scope="module")
def pages(tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("pages")
    old, new = root / "old" / "KRC", root / "new" / "KRC"
    shutil.copytree(FIXTURE, old)
    shutil.copytree(FIXTURE, new)
    (new / "R1" / "Program" / f"{IMG}.src").write_text("DEF odd()\nEND\n")
    pick = new / "R1" / "Program" / "pick.src"
    text = pick.read_text()
    assert text.count("  n = helper_fct(2)\n") == 1
    pick.write_text(text.replace("  DECL EKI_STATUS ret\n", f"  DECL EKI_STATUS ret\n  DECL CHAR msg[40]\n")
                    .replace("  n = helper_fct(2)\n", f'  n = helper_fct(3)\n  msg[] = "{SCRIPT}"\n'))
    out = {}
    runner = CliRunner()
    for name, args in (("report", ["report", str(new), "--since", str(old)]),
                       ("graph", ["graph", str(new), "--format", "html"]),
                       ("diff", ["diff", str(old), str(new), "--format", "html"])):
        out[name] = root / f"{name}.html"
        r = runner.invoke(main, [*args, "-o", str(out[name])])
        assert r.exit_code == (1 if name == "diff" else 0), r.output
    return out


def _open(pw, chromium, page_path: Path, check):
    with loaded_page(pw, chromium, page_path) as page:
        assert page.evaluate("document.querySelectorAll('script').length") == 0
        assert page.evaluate("window.pwned === undefined")
        check(page)


@pytest.mark.may_skip("chromium or graphviz is missing and cannot be installed (not root, or apt-get has no network)")
def test_change_pages_render_in_headless_chromium(chromium, pages):
    import playwright.sync_api as playwright  # a dev dependency: missing is a failure, not a skip

    def graph(page):
        assert page.locator("h1").inner_text() == "Program map"
        # 13 routines (the 12 of the fixture + odd), 9 edges; entries cell, sps, bg; dead: 3 + odd
        assert page.locator("table.map-entries tr").count() == 1 + 3
        assert page.locator("table.map-dead tr").count() == 1 + 4
        assert page.locator("table.map-edges tr").count() == 1 + 9
        assert page.evaluate("document.getElementById('map-image').naturalWidth") > 200
        assert IMG in page.locator("table.map-dead").inner_text()      # the module name, as text
        assert page.locator("img").count() == 1                          # only the drawing

    def diff(page):
        routines = page.locator("section.diff-routine")
        assert routines.count() == 2                  # pick changed, odd added
        assert f"added {IMG}:odd" in routines.nth(0).inner_text()         # files in name order
        text = routines.nth(1).inner_text()
        assert "changed pick:pick" in text
        assert "- 6: n = helper_fct(2)" in text and "+ 7: n = helper_fct(3)" in text
        assert f'msg[] = "{SCRIPT}"' in text
        assert page.locator("table.diff-declarations tr").count() == 1 + 1   # msg added

    def report(page):
        assert page.locator("#check-summary").count() == 1
        graph_part = page.locator("table.map-edges tr").count()
        assert graph_part == 1 + 9
        diff(page)

    with playwright.sync_playwright() as pw:
        _open(pw, chromium, pages["graph"], graph)
        _open(pw, chromium, pages["diff"], diff)
        _open(pw, chromium, pages["report"], report)
