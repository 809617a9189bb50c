"""The logbook's display limits in HTML (docs/security.md): a crafted logbook may name any
number of programs and variables, and the report and the map list a bounded number of them, the
rest counted. The records are the shared logs' (they name at least the test archive's three
modules: tests/logbook/test_log_show.py); the bounds are set small so that the cut shows."""

from __future__ import annotations

from types import SimpleNamespace

import app.reportlog as reportlog
from krl.programmap import render
from tests.logbook.archive import build_archive


def test_the_reports_programs_named_are_bounded_and_the_rest_counted(tmp_path, monkeypatch, event_logs):
    root = build_archive(tmp_path / "archive", event_logs, ("KrcLogB.evt", "KrcLogI.evt", "KrcLogU.evt"))
    records = reportlog._records(str(root))
    whole = reportlog.side_logbook("backup", str(root), root / "KRC", records=records)
    named = len(whole["summary"]["programs"])
    assert named >= 3 and whole["more"]["programs"] == 0
    monkeypatch.setattr(reportlog, "MAX_REPORT_PROGRAMS", 2)
    monkeypatch.setattr(reportlog, "MAX_NAMES_SHOWN", 1)
    cut = reportlog.side_logbook("backup", str(root), root / "KRC", records=records)
    assert len(cut["summary"]["programs"]) == 2 and cut["more"]["programs"] == named - 2
    for m in cut["summary"]["messages"]:
        assert len(m["programs"]) <= 2
        if len(m["programs"]) == 2:
            assert m["programs"][1].startswith("and ") and m["programs"][1].endswith(" more")


def test_a_modules_map_mark_lists_at_most_max_mark_names(monkeypatch):
    node = SimpleNamespace(id="n1", module="B3", kind="routine", main=True, kuka=False)
    pm = SimpleNamespace(nodes={"n1": node})
    named = {f"B3.v{i:02d}": 30 - i for i in range(25)}
    monkeypatch.setattr(render, "MAX_MARK_NAMES", 20)
    text = render.logbook_marks(pm, named)["n1"]
    assert text.count(" record") == 20 and text.endswith("and 5 more")
    assert text.startswith("B3.v00 (30 records)")
