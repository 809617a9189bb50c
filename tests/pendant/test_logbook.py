"""The controller's logbook beside the program (issue 75 item 3): `krl pendant ARCHIVE` gives its
page the archive's logbook records (pendant/logbook.py), and stepping through them in the
Logbook tab moves the program view to the file and line a record names.

The archive is tests/logbook/archive.py's (its KRL written by hand, each declaration's line in
its ``LINES``) with copies of the shared archive's logs (read in place, copied into the
temporary folder). Expected records come from python-evtx's own reading of the log (each
record's XML), the lines from ``LINES``, never from the code under test. The page test runs in
Chromium and is slow (a server, a browser and KrcLogU's 1,761 records); the cheap tests call
the function the ``logbook`` operation sends."""

from __future__ import annotations

import datetime as dt
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from Evtx.Evtx import Evtx

from pendant.logbook import _place, logbook_view
from tests.logbook.archive import B3_DAT_PATH, CELL_PATH, LINES, build_archive
from tests.pendant.harness import browser_page, pendant_server

NS = "{http://schemas.microsoft.com/win/2004/08/events/event}"


def _independent(path: Path) -> list[tuple]:
    """(time ISO 8601 UTC to the ms, module, number, key, params) of every record, in time order
    (stable), read from python-evtx's XML of each record."""
    out = []
    with Evtx(str(path)) as log:
        for rec in log.records():
            root = ET.fromstring(rec.xml())
            t = dt.datetime.fromisoformat(root.find(f"{NS}System/{NS}TimeCreated").get("SystemTime"))
            t = t.astimezone(dt.timezone.utc)
            ls = ET.fromstring(next(d.text for d in root.iter(NS + "Data") if d.get("Name") == "LS"))
            out.append((t, (t.strftime("%Y-%m-%dT%H:%M:%S.") + f"{t.microsecond // 1000:03d}Z",
                            ls.findtext("M"), int(ls.findtext("N")), ls.findtext("DB"),
                            [p.get("S") for p in ls.findall("P")])))
    out.sort(key=lambda x: x[0])
    return [x[1] for x in out]


def test_the_page_gets_the_archives_logbook(tmp_path, event_logs):
    root = build_archive(tmp_path / "archive", event_logs, ("KrcLogI.evt",))
    view = logbook_view(root / "KRC")
    assert view["errors"] == [] and view["omitted"] == 0
    got = [(r["time"], r["module"], r["number"], r["key"], r["params"]) for r in view["records"]]
    assert got == _independent(event_logs / "KrcLogI.evt")
    # KrcLogI names no program module (its parameters: users, files of the configuration)
    assert all(r["path"] is None and r["line"] is None for r in view["records"])


def test_the_page_gets_the_newest_records_past_the_limit(tmp_path, event_logs, monkeypatch):
    """Past MAX_PENDANT_LOG_RECORDS (here 10) the newest are sent and the older counted: KrcLogI's
    26 records (../shared/event-logs/README.md) give its last 10 and 16 omitted."""
    monkeypatch.setattr("pendant.logbook.MAX_PENDANT_LOG_RECORDS", 10)
    root = build_archive(tmp_path / "archive", event_logs, ("KrcLogI.evt",))
    view = logbook_view(root / "KRC")
    want = _independent(event_logs / "KrcLogI.evt")
    assert (len(want), view["omitted"], view["errors"]) == (26, 16, [])
    assert [(r["time"], r["module"], r["number"], r["key"], r["params"]) for r in view["records"]] == want[-10:]


def test_a_record_names_a_file_of_the_workspace_only(tmp_path):
    root = build_archive(tmp_path / "archive", None)
    krc = root / "KRC"
    assert _place(krc, root, B3_DAT_PATH) == str(root / B3_DAT_PATH)
    assert _place(krc, root, CELL_PATH) == str(root / CELL_PATH)
    for outside in ("am.ini", "../secret.src", "C/KRC/Roboter/Config/User/Common/readme.txt", "KRC/R1/none.src", ""):
        assert _place(krc, root, outside) is None, outside
    assert _place(krc, None, CELL_PATH) is None


def test_a_backup_without_logs_has_no_logbook(tmp_path):
    (tmp_path / "prog.src").write_text("DEF prog()\nEND\n")
    assert logbook_view(tmp_path) == {"records": [], "errors": [], "omitted": 0}


@pytest.mark.slow
def test_stepping_through_the_logbook_moves_the_program_view(pw, event_logs, tmp_path):
    """The record of a variable set from the pendant (/R1/B3_PARCA_BIRAKMA.SRC/b3_parcasirasi)
    shows its declaration (B3_Parca_Birakma.dat line 3); the selection of the cell program
    (KRC:\\R1\\cell) shows cell.src from its first line; 'next' steps to the following record."""
    root = build_archive(tmp_path / "archive", event_logs, ("KrcLogU.evt",))
    records = _independent(event_logs / "KrcLogU.evt")
    var = next(i for i, r in enumerate(records) if "/R1/B3_PARCA_BIRAKMA.SRC/b3_parcasirasi" in r[4])
    cell = next(i for i, r in enumerate(records) if r[4] == ["KRC:\\R1\\cell"])
    with pendant_server(root, "--no-realtime") as url, browser_page(pw, url) as page:
        page.click('#tabs button[data-tab="logbook"]')
        page.wait_for_selector(f'#logbook li[data-index="{len(records) - 1}"]')
        assert page.locator("#logbook li").count() == len(records)
        page.click(f'#logbook li[data-index="{var}"]')
        file, line = LINES["b3_parcasirasi"]
        page.wait_for_selector(f'#program-view .ln.logged[data-line="{line}"]')
        assert page.inner_text("#module-label") == file       # the archive's folder is the workspace
        page.click(f'#logbook li[data-index="{cell}"]')
        page.wait_for_selector('#program-view .ln.logged[data-line="1"]')
        assert page.inner_text("#module-label") == CELL_PATH
        page.click("#log-next")
        page.wait_for_selector(f'#logbook li.current[data-index="{cell + 1}"]')
        assert page.inner_text("#log-pos") == f"{cell + 2} / {len(records)}"
        assert page.locator("#logbook li.current").count() == 1
        assert page.problems == []
