"""`krl audit` groups a fleet's units by their logbooks' messages (issue 75 item 3): two archives
of tests/logbook/archive.py, one with the shared KrcLogI, one with KrcLogI and KrcLogB. The cheap
test reads the logbooks as the audit does (audit/logbook.py) and checks KrcLogI's counts against
python-evtx's own reading; the slow one runs the whole audit and checks its JSON and page."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from click.testing import CliRunner
from Evtx.Evtx import Evtx
from jsonschema import Draft202012Validator

from app import main
from audit.logbook import fleet_logbook, unit_logbook
from tests.logbook.archive import build_archive

NS = "{http://schemas.microsoft.com/win/2004/08/events/event}"
SCHEMA = Path(__file__).resolve().parents[2] / "docs" / "schemas" / "audit.schema.json"


def _counts(path: Path) -> dict[tuple[str, int], int]:
    """(module, number) -> records of the log, read by python-evtx's Record.xml()."""
    out: dict = {}
    with Evtx(str(path)) as log:
        for rec in log.records():
            ls = ET.fromstring(next(d.text for d in ET.fromstring(rec.xml()).iter(NS + "Data")))
            key = (ls.findtext("M"), int(ls.findtext("N")))
            out[key] = out.get(key, 0) + 1
    return out


@pytest.fixture(scope="module")
def fleet(tmp_path_factory, event_logs) -> Path:
    root = tmp_path_factory.mktemp("fleet")
    build_archive(root / "cell_a", event_logs, ("KrcLogI.evt",))
    build_archive(root / "cell_b", event_logs, ("KrcLogI.evt", "KrcLogB.evt"))
    return root


def test_units_grouped_by_message(fleet, event_logs):
    a, b = unit_logbook(str(fleet / "cell_a" / "KRC")), unit_logbook(str(fleet / "cell_b" / "KRC"))
    assert (a["records"], b["records"], a["errors"], b["errors"]) == (26, 26 + 142, [], [])
    assert unit_logbook(str(fleet)) is None          # no archive holds the fleet's folder
    groups = fleet_logbook([{"name": "cell_a/KRC", "logbook": a}, {"name": "cell_b/KRC", "logbook": b},
                            {"name": "plain", "logbook": None}])
    by_key = {(g["module"], g["number"]): g for g in groups}
    for key, n in _counts(event_logs / "KrcLogI.evt").items():
        assert (by_key[key]["units"], by_key[key]["count"]) == (["cell_a/KRC", "cell_b/KRC"], 2 * n)
    only_b = [g for g in groups if g["units"] == ["cell_b/KRC"]]
    assert {g["module"] for g in only_b} == {"CrossMeld", "SmartPadUpdater"}     # KrcLogB's modules (README)
    # the messages of both units rank before those of one
    assert [len(g["units"]) for g in groups] == sorted((len(g["units"]) for g in groups), reverse=True)


@pytest.mark.slow
def test_the_audit_report_lists_the_logbook(fleet, tmp_path):
    out = tmp_path / "out"
    res = CliRunner().invoke(main, ["audit", str(fleet), "--out", str(out), "--jobs", "1", "--max-sim-time", "1"])
    assert (out / "audit.json").is_file(), res.output
    data = json.loads((out / "audit.json").read_text(encoding="utf-8"))
    Draft202012Validator(json.loads(SCHEMA.read_text())).validate(data)
    assert [u["logbook"]["records"] for u in data["units"]] == [26, 168]
    page = (out / "audit.html").read_text(encoding="utf-8")
    assert 'id="logbook-groups"' in page and "NewPackageInstalled" in page
    assert data["summary"]["logbook"][0]["units"] == [u["name"] for u in data["units"]]
