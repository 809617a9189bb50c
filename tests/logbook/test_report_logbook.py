"""The logbook in the change report (issue 75 item 3), in headless Chromium: `krl report NEW
--since OLD` of two archives of one controller (tests/logbook/archive.py; OLD's logs KrcLogB and
KrcLogI, NEW's those and KrcLogU) lists NEW's records since OLD's last one, and each variable the
operator set links to the report's view of its declaration. Marked slow: KrcLogU's 1,761 records
and a browser cost about 3 s of CPU (make nightly); the cheap default-suite check of the section
is tests/logbook/test_archive.py's report test."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import pytest
from click.testing import CliRunner
from Evtx.Evtx import Evtx
from Evtx.Views import evtx_template_readable_view

from app import main
from tests.logbook.archive import LINES, build_archive
from tests.report.test_report_chromium import loaded_page
from tests.system_tools import require

pytestmark = pytest.mark.slow


def _times(path: Path) -> list[dt.datetime]:
    """Every record's TimeCreated, from python-evtx's substitutions (the template checked)."""
    out = []
    with Evtx(str(path)) as log:
        for rec in log.records():
            root = rec.root()
            assert 'SystemTime="[Conditional Substitution(index=6, type=17)]"' in evtx_template_readable_view(root)
            out.append(dt.datetime.fromisoformat(root.substitutions()[6].string()))
    return out


def test_the_report_shows_the_logbook_since_the_older_archive(event_logs, tmp_path, pw):  # noqa: F811
    old = build_archive(tmp_path / "old", event_logs, ("KrcLogB.evt", "KrcLogI.evt"))
    new = build_archive(tmp_path / "new", event_logs, ("KrcLogB.evt", "KrcLogI.evt", "KrcLogU.evt"))
    out = tmp_path / "report.html"
    res = CliRunner().invoke(main, ["report", str(new), "--since", str(old), "--no-runs", "-o", str(out)])
    assert res.exit_code == 0, res.output
    since = max(_times(event_logs / "KrcLogB.evt") + _times(event_logs / "KrcLogI.evt"))
    newer = [t for name in ("KrcLogB.evt", "KrcLogI.evt", "KrcLogU.evt") for t in _times(event_logs / name)
             if t > since]
    with loaded_page(pw, require("chromium"), out) as page:
        section = page.locator("section#logbook-new")
        assert f"{len(newer)} of {142 + 26 + 1761} records since" in section.locator("p").first.inner_text()
        assert page.locator("section#logbook-old").locator("p").first.inner_text().startswith(f"{142 + 26} of {142 + 26}")
        rows = section.locator("table.logbook-actions tr.action-variable")
        assert rows.count() > 0
        checked = 0
        for row in rows.all():
            var = row.locator("td").nth(2).inner_text().split(":")[0].rsplit("/", 1)[1]
            if var not in LINES:
                continue
            link = row.locator("a.where")
            file, line = LINES[var]
            rel = file.split("/", 1)[1]          # the report's links are below the backup root, KRC
            assert link.inner_text().replace("\u200b", "") == f"{rel}:{line}"
            href = link.get_attribute("href")
            shown = page.locator(href).text_content()
            assert shown.split(" ", 1)[1].strip() == (new / file).read_text().splitlines()[line - 1].strip()
            assert var in shown
            checked += 1
        assert checked > 0
        # the map marks the modules the new side's records name (B1 and CELL by the logs) with a
        # red halo: drawn folded, the module cell and the folder of B1 and B3 carry it
        page.wait_for_function("document.body.dataset.ready === '1'", timeout=180_000)
        marked = [x.split("\n")[0] for x in page.evaluate("window.krlMap.cy.nodes('.logbook').map(n => n.data('label'))")]
        assert sorted(marked) == ["R1/Program/Parca_Birakma", "cell"]
