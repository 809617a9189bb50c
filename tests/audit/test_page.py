"""The audit of a sample of the corpus (conftest.py ``fleet_sample_audit``: a backup and a program
folder of each status) as a maintainer opens it, in headless Chromium: it loads without a console error, its tables sort by the column clicked (numbers as
numbers), and every item's link leads to its evidence, whose lines are the file's own."""

from __future__ import annotations

import pytest

from tests.report.test_report_chromium import chromium, loaded_page  # noqa: F401  (fixture)

pytestmark = [pytest.mark.corpus, pytest.mark.xdist_group("audit-corpus"), pytest.mark.timeout(3600)]


def _column(page, table: str, col: int) -> list[str]:
    return page.eval_on_selector_all(
        f"{table} tbody tr", f"rows => rows.map(r => r.cells[{col}].getAttribute('data-sort') ?? r.cells[{col}].textContent.trim())")


def test_the_fleet_page_sorts_and_links_to_its_evidence(chromium, fleet_sample_audit, pw):  # noqa: F811
    data, html, _res = fleet_sample_audit
    # the sample (conftest.py FLEET_SAMPLE): one backup, three program folders, each status once at least
    assert [u["name"] for u in data["units"]][0] == "rawpython__kukaKRLmagic" and len(data["units"]) == 4
    assert {u["status"] for u in data["units"]} == {"attention", "review", "ok"}
    with loaded_page(pw, chromium, html) as page:
        assert page.title() == "Fleet audit: 1 backup, 3 program folders"
        assert page.locator("table#units tbody tr").count() == 4
        heads = page.locator("table#units thead th")
        names = heads.all_inner_texts()
        # files, numerically: descending after two clicks (a text sort would put "9" above "35")
        files = heads.nth(names.index("files"))
        files.click()
        up = [int(x) for x in _column(page, "table#units", names.index("files"))]
        assert up == sorted(up) and files.get_attribute("aria-sort") == "ascending"
        files.click()
        down = [int(x) for x in _column(page, "table#units", names.index("files"))]
        assert down == sorted(up, reverse=True) and down[0] > 9
        # status: attention first, then review, then ok
        heads.nth(names.index("status")).click()
        order = [t.strip() for t in page.locator("table#units tbody td.status").all_inner_texts()]
        assert order == sorted(order, key=("attention", "review", "ok").index)
        # every link inside the page has its target
        missing = page.eval_on_selector_all(
            "a[href^='#']", "as => as.filter(a => !document.getElementById(a.getAttribute('href').slice(1)))"
                            ".map(a => a.getAttribute('href'))")
        assert missing == []
        # rawpython's sample_program.src:26 is `print('1')` (read in the file): its entry row's
        # "where" link leads to those lines, the heading of the evidence to the file itself
        (u,) = [i for i, u in enumerate(data["units"], 1) if u["name"] == "rawpython__kukaKRLmagic"]
        link = page.locator(f"#unit{u} a.where", has_text="R1/Program/sample_program.src:26").first   # the entries table comes first
        link.click()
        target = page.locator(".evidence:target")
        assert "print('1')" in target.locator("span.hit").inner_text()
        assert target.locator("a").get_attribute("href").endswith(
            "rawpython__kukaKRLmagic/R1/Program/sample_program.src")
        # a reason links to the table behind it
        page.locator(f"#unit{u} ul.reasons a", has_text="program error").click()
        assert page.evaluate("location.hash") == f"#unit{u}-causes"
