"""The interactive map's overview fits a screen (issue 49), in headless Chromium with Playwright.

On every KRC backup of the shared corpus, in a 1600 x 1000 window: the overview (the backup's
modules grouped by folder, KUKA's system software folded into one node) is drawn whole and with
readable labels at once; *Expand all* (every folder and module of the backup's own open, KUKA's
folded) then *Fit* shows every node inside the window at a zoom of at least 0.5 (12 px labels
drawn at 6 px or more); the check box for KUKA's system software opens KUKA's modules. The
numbers of nodes are counted here from the map's JSON (the page's ``map-data``: the map ``krl graph``
built), not from what the page draws. (The test built each backup's map a second time for them,
its workspace parsed and checked again: 5.5 s of CPU for the four backups, twice alike at load
30, 2026-11-29.)

One page in the window's size from the start loads the backups' maps one after the other: its
first layout is the overview in that window (before: a page of Playwright's 1280 x 720 for each
backup, laid out there and again in the window after a click on *Overview*; 15.8 -> 13.3 s of
Chromium's CPU for the four backups, a cgroup, 2026-11-29). The waits look every
:data:`tests.chromium.POLL_MS`, not at each of the map's frames.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main
from krl.project import find_backups
from tests.chromium import POLL_MS
from tests.system_tools import require
from tests.report.test_report_chromium import load_checked, loaded_page

WINDOW = {"width": 1600, "height": 1000}
READABLE = 0.5

_INFO = """() => { const cy = window.krlMap.cy; const ext = cy.extent();
  const leaves = cy.nodes().filter((n) => !n.isParent());
  const inside = leaves.filter((n) => { const b = n.boundingBox();
    return b.x1 >= ext.x1 - 1 && b.x2 <= ext.x2 + 1 && b.y1 >= ext.y1 - 1 && b.y2 <= ext.y2 + 1; });
  return { zoom: cy.zoom(), leaves: leaves.length, inside: inside.length,
           ids: leaves.map((n) => n.id()) }; }"""


@pytest.fixture(scope="module")
def chromium() -> str:
    return require("chromium")


def test_overview_and_expand_all_fit_the_window(chromium, shared_corpus, tmp_path, pw):

    backups = find_backups(shared_corpus)
    assert len(backups) >= 4
    pages = []
    for b in backups:
        page_file = tmp_path / f"{b.parent.name}-{b.name}.html"
        r = CliRunner().invoke(main, ["graph", "--format", "html", str(b), "-o", str(page_file)])
        assert r.exit_code == 0, r.output
        pages.append((b, page_file))
    with loaded_page(pw, chromium, pages[0][1], viewport=WINDOW) as page:
        for i, (b, page_file) in enumerate(pages):
            if i:
                load_checked(page, page_file)
            nodes = map_nodes(page_file)
            own = [n for n in nodes if n["kind"] != "routine" or not n["system"]]
            kuka = [n for n in nodes if n["kind"] == "routine" and n["system"]]
            # the page's first layout: the overview, in this window
            ready(page)
            assert page.evaluate("document.body.dataset.view") == "overview"
            info = page.evaluate(_INFO)
            # folded: a few dozen nodes at most, all in view, readable
            assert info["leaves"] <= max(30, len(own) // 2), (b, info["leaves"])
            assert "group:KUKA" in info["ids"] or not kuka
            assert info["inside"] == info["leaves"] and info["zoom"] >= READABLE, (b, info["zoom"])
            if i == 0:      # the *Overview* button lays the same overview out again (one backup: a layout each)
                page.evaluate("document.body.dataset.ready = 'before'")     # so the wait sees the new layout
                page.click("#map-overview")
                ready(page)
                again = page.evaluate(_INFO)
                assert page.evaluate("document.body.dataset.view") == "overview"
                assert again["leaves"] == info["leaves"] and again["inside"] == again["leaves"], again
                assert again["zoom"] >= READABLE, again["zoom"]
            page.click("#map-expand-all")
            ready(page)
            page.click("#map-fit")
            info = page.evaluate(_INFO)
            # every routine of the backup's own (and channel) is a node; of KUKA's, those of
            # a module the controller starts (sps.sub in System/), the rest one node
            kept = {n["module"].upper() for n in kuka if n["entry_kind"] in ("cell", "plc", "submit", "selected")}
            shown = [n for n in kuka if n["module"].upper() in kept]
            assert info["leaves"] == len(own) + len(shown) + (len(kuka) > len(shown)), (b, info["leaves"])
            assert info["inside"] == info["leaves"], (b, info)
            assert info["zoom"] >= READABLE, (b.name, info["zoom"])
            page.check("#map-show-kuka")
            ready(page)
            assert "group:KUKA" not in page.evaluate(_INFO)["ids"] or not kuka


def map_nodes(page_file: Path) -> list[dict]:
    """The nodes of the map a ``krl graph`` page holds (its ``map-data`` JSON, written by
    krl.programmap.render.page_data: id, kind, module, system, entry_kind ...)."""
    found = re.search(r'<script type="application/json" id="map-data">(.*?)</script>', page_file.read_text("utf-8"), re.S)
    assert found, f"{page_file}: no map-data"
    return json.loads(found.group(1))["nodes"]


def ready(page) -> None:
    """Wait until the map's layout is drawn (``body[data-ready=1]``)."""
    page.wait_for_function("document.body.dataset.ready === '1'", timeout=180_000, polling=POLL_MS)
