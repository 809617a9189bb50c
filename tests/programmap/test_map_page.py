"""The interactive program map (`krl graph --format html`, issue 37) read in headless Chromium.

On the largest backup of the shared corpus (by routines; found here, not named), Playwright
searches a routine, opens its neighbourhood and follows the link to its source; the page loads
offline (no request leaves the file), with no console error, and text from the backup stays
text. The vendored front end names the versions its lock file pins.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from urllib.parse import quote

import pytest
from click.testing import CliRunner

from app import main
from krl.programmap import build_map
from krl.project import find_backups
from krl.workspace import workspaces_for
from tests.system_tools import require
from tests.report.test_report_chromium import loaded_page

WEB = Path(__file__).parents[2] / "krl" / "programmap" / "web"
STATIC = Path(__file__).parents[2] / "krl" / "programmap" / "static" / "programmap.js"


def test_the_vendored_front_end_names_the_locked_versions():
    lock = json.loads((WEB / "package-lock.json").read_text())
    pkg = json.loads((WEB / "package.json").read_text())
    head = STATIC.read_text(encoding="utf-8").splitlines()[0]
    versions = {name: lock["packages"][f"node_modules/{name}"]["version"] for name in ("cytoscape", "elkjs")}
    assert head == (f"/* krl-programmap-web {pkg['version']} (cytoscape {versions['cytoscape']}, "
                    f"elkjs {versions['elkjs']}): built by make programmap-js from krl/programmap/web */")
    assert pkg["devDependencies"]["cytoscape"] == versions["cytoscape"]
    assert pkg["devDependencies"]["elkjs"] == versions["elkjs"]
    assert "</script" not in STATIC.read_text(encoding="utf-8").lower()


@pytest.fixture(scope="module")
def largest(shared_corpus):
    """(backup root, its map) of the corpus backup with the most routines."""
    best = None
    for b in find_backups(shared_corpus):
        pm = build_map(workspaces_for(b, timeout=60)[0])
        n = sum(x.kind == "routine" for x in pm.nodes.values())
        if best is None or n > best[2]:
            best = (b, pm, n)
    assert best is not None and best[2] >= 200, best and best[2]
    return best[0], best[1]


@pytest.fixture(scope="module")
def chromium() -> str:
    return require("chromium")


def test_search_neighbourhood_and_source_link_in_chromium(chromium, largest, tmp_path, pw):

    root, pm = largest
    page_file = tmp_path / "map.html"
    r = CliRunner().invoke(main, ["graph", "--format", "html", str(root), "-o", str(page_file)])
    assert r.exit_code == 0, r.output
    # the routine to look for: a user routine that calls others and is called (found from the
    # map's JSON, the page's own data being what is tested)
    out = {e.source for e in pm.edges if e.kind == "call"}
    inc = {e.target for e in pm.edges if e.kind == "call"}
    target = next(n for n in sorted(pm.nodes.values(), key=lambda n: n.id)
                  if n.kind == "routine" and not n.kuka and n.id in out and n.id in inc and not n.main)
    callers = sorted({pm.nodes[e.source].name for e in pm.edges if e.target == target.id})
    callees = sorted({pm.nodes[e.target].name for e in pm.edges if e.source == target.id})
    with loaded_page(pw, chromium, page_file) as page:
        page.wait_for_function("document.body.dataset.ready === '1'", timeout=180_000)
        assert page.evaluate("document.body.dataset.view") == "overview"
        shown = page.evaluate("window.krlMap.cy.nodes().filter(n => !n.isParent()).length")
        assert 0 < shown < len(pm.nodes) / 2           # modules and KUKA's software collapsed
        # search: the routine is among the results; Enter opens its neighbourhood
        page.fill("#map-search", target.name.lower())
        results = page.locator("#search-results li").all_inner_texts()
        assert any(t.startswith(f"{target.name} {target.module} ") for t in results), results
        page.locator(f"#search-results button[data-id='{target.id}']").first.click()
        page.wait_for_function("document.body.dataset.view === 'neighbourhood' && document.body.dataset.ready === '1'",
                               timeout=120_000)
        ids = set(page.evaluate("window.krlMap.cy.nodes().filter(n => !n.isParent()).map(n => n.id())"))
        expected = {target.id} | {e.source for e in pm.edges if e.target == target.id} \
            | {e.target for e in pm.edges if e.source == target.id}
        assert ids == expected
        assert page.locator("#details h2").inner_text() == target.name
        assert sorted(page.locator("#details ul.called-by button").all_inner_texts()) == callers
        assert sorted(page.locator("#details ul.calls button").all_inner_texts()) == callees
        # zoom and pan are there
        z = page.evaluate("window.krlMap.cy.zoom()")
        page.click("#map-zoom-in")
        assert page.evaluate("window.krlMap.cy.zoom()") > z
        # the link to the source: file:line, opening the routine's lines from its DEF line on
        link = page.locator("#source-link")
        rel = Path(target.path).relative_to(pm.root).as_posix()
        assert link.inner_text() == f"{rel}:{target.line}"
        link.click()
        assert page.url.endswith("#source=" + quote(target.id, safe=""))
        page.wait_for_selector("#source pre", state="visible")
        assert page.locator("#source-where").inner_text() == f"{rel}:{target.line}"
        first = page.locator("#source .src-def")
        assert first.get_attribute("data-line") == str(target.line)
        text = Path(target.path).read_text(encoding="latin-1").splitlines()
        shown = first.inner_text().lstrip()                       # "181  DEF LeaveCut(...)"
        assert shown.startswith(f"{target.line}  ")
        assert shown[len(str(target.line)) + 2:].rstrip() == text[target.line - 1].strip()
        assert re.search(rf"\bDEF(FCT)?\b.*\b{re.escape(target.name)}\s*\(", text[target.line - 1], re.I)
        assert page.locator("#source .src-line").count() == target.end - target.line + 1
        # and from there to the file itself
        assert page.locator("#source-file").get_attribute("href") == Path(target.path).as_uri()


def test_markup_in_names_stays_text(chromium, tmp_path, pw):

    evil = "<img src=x onerror=window.pwned=1>"
    (tmp_path / f"{evil}.src").write_text("DEF odd()\n  helper()\nEND\nDEF helper()\nEND\n")
    page_file = tmp_path / "map.html"
    r = CliRunner().invoke(main, ["graph", "--format", "html", str(tmp_path), "-o", str(page_file)])
    assert r.exit_code == 0, r.output
    assert evil not in page_file.read_text(encoding="utf-8")           # escaped in the page's JSON
    with loaded_page(pw, chromium, page_file) as page:
        page.wait_for_function("document.body.dataset.ready === '1'", timeout=60_000)
        page.fill("#map-search", "helper")
        page.keyboard.press("Enter")
        page.wait_for_function("document.body.dataset.view === 'neighbourhood' && document.body.dataset.ready === '1'")
        assert page.evaluate("window.pwned === undefined")
        assert page.locator("img").count() == 0
        assert evil in page.locator("#details").inner_text()            # the module name, as text
