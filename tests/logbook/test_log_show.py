"""`krl log show` on the shared archive's three event logs against an independent reading of
them with python-evtx (issue 75, "Done when"), a truncated and a damaged log, and the links of
the records to a small archive's code (tests/logbook/archive.py).

The independent reading uses python-evtx's own ``Record.xml()`` and the standard library's XML
parser, none of krl/logbook. ``Record.xml()`` costs 3.4 ms a record: KrcLogB and KrcLogI are read
whole with it, KrcLogU (1,761 records) every 20th record whole and every record's TimeCreated and
EventRecordID from python-evtx's substitutions (the template checked to put them there); the slow
test reads every KrcLogU record with ``Record.xml()``. Each log is read once per module: the
command runs once on the archive (module-scoped fixture) and every test reads its output.
"""

from __future__ import annotations

import datetime as dt
import json
import re
import struct
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from click.testing import CliRunner
from jsonschema import Draft202012Validator
from Evtx.Evtx import Evtx
from Evtx.Views import evtx_template_readable_view

from app.log import log_group
from interp.runtime.kssmessages import KNOWN_MESSAGES
from krl.logbook.record import LogRecord
from krl.logbook.summary import messages, timeline
from tests.logbook.archive import LINES, MODULES, build_archive

LOGS = ("KrcLogB.evt", "KrcLogI.evt", "KrcLogU.evt")
SCHEMAS = Path(__file__).resolve().parents[2] / "docs" / "schemas"
NS = "{http://schemas.microsoft.com/win/2004/08/events/event}"
SAMPLE = 20

# one worker takes the module (make test: --dist loadgroup), so its module fixtures read each log once
pytestmark = [pytest.mark.xdist_group("logbook")]


def validate(name: str, obj) -> None:
    """`obj` against docs/schemas/<name>.schema.json (tests/test_json_schemas.py checks the schemas)."""
    Draft202012Validator(json.loads((SCHEMAS / f"{name}.schema.json").read_text())).validate(obj)


def _ms(text: str) -> str:
    """python-evtx's ``2026-01-27 10:43:12.084162+00:00`` as ISO 8601 UTC cut to the ms."""
    t = dt.datetime.fromisoformat(text).astimezone(dt.timezone.utc)
    return t.strftime("%Y-%m-%dT%H:%M:%S.") + f"{t.microsecond // 1000:03d}Z"


def _from_xml(xml: str) -> dict:
    root = ET.fromstring(xml)
    system = root.find(NS + "System")
    ls = next(d.text for d in root.iter(NS + "Data") if d.get("Name") == "LS")
    le = ET.fromstring(ls)
    return {"time": _ms(system.find(NS + "TimeCreated").get("SystemTime")),
            "precise": system.find(NS + "TimeCreated").get("SystemTime"),
            "record": int(system.find(NS + "EventRecordID").text), "channel": system.find(NS + "Channel").text,
            "module": le.findtext("M"), "number": int(le.findtext("N")), "key": le.findtext("DB"),
            "params": [p.get("S") for p in le.findall("P")]}


def independent(path: Path, every: int = 1) -> list[dict]:
    """Every record of `path`: time and record id always; with `every` > 1 the other fields only
    for every `every`-th record (``Record.xml()``), the rest from the substitutions, whose places
    each template (checked once per chunk and template) says."""
    out = []
    checked = set()
    with Evtx(str(path)) as log:
        i = 0
        for chunk in log.chunks():
            for rec in chunk.records():
                i += 1
                if (i - 1) % every == 0:
                    out.append(_from_xml(rec.xml()))
                    continue
                root = rec.root()
                key = (chunk.offset(), root.template_instance().template_offset())
                if key not in checked:
                    view = evtx_template_readable_view(root)
                    assert 'SystemTime="[Conditional Substitution(index=6, type=17)]"' in view
                    assert "<EventRecordID>[Conditional Substitution(index=10, type=10)]" in view
                    checked.add(key)
                subs = root.substitutions()
                out.append({"time": _ms(subs[6].string()), "precise": subs[6].string(),
                            "record": int(subs[10].string())})
    return out


@pytest.fixture(scope="module")
def archive(event_logs, tmp_path_factory) -> Path:
    return build_archive(tmp_path_factory.mktemp("archive") / "archive", event_logs, LOGS)


@pytest.fixture(scope="module")
def shown(archive) -> list[dict]:
    """`krl log show --format json` of the archive: every record of its three logs."""
    res = CliRunner().invoke(log_group, ["show", "--format", "json", str(archive)])
    assert res.exit_code == 0, res.output
    objs = [json.loads(line) for line in res.output.splitlines()]
    for o in objs[::50] + [o for o in objs if "file" in o][:20]:
        validate("log-record", o)
    return objs


@pytest.fixture(scope="module")
def expected(event_logs) -> list[dict]:
    """The independent reading of the three logs, in the order the command promises: the logs
    by name, then stably by TimeCreated (full precision)."""
    rows = []
    for name in LOGS:
        for r in independent(event_logs / name, SAMPLE if name == "KrcLogU.evt" else 1):
            rows.append(dict(r, log=name))
    return sorted(rows, key=lambda r: dt.datetime.fromisoformat(r["precise"]))


def test_the_same_records_in_order_time_module_number_params(shown, expected):
    # the README's counts: 142, 26 and 1,761 records
    assert len(expected) == 142 + 26 + 1761
    assert [(r["record"], r["time"]) for r in shown] == [(r["record"], r["time"]) for r in expected]
    assert [Path(r["log"]).name for r in shown] == [r["log"] for r in expected]
    full = [(s, e) for s, e in zip(shown, expected) if "module" in e]
    assert len(full) == 142 + 26 + (1761 + SAMPLE - 1) // SAMPLE
    for s, e in full:
        assert (s["channel"], s["module"], s["number"], s["key"], s["params"]) == \
            (e["channel"], e["module"], e["number"], e["key"], e["params"]), e


def test_links_to_the_archive_code(shown):
    """Every record whose parameter names a module the archive holds carries its file; a variable
    declared there its declaration's line (tests/logbook/archive.py, by hand); one that is not
    declared keeps the module's file and no line; the module alone, its DEF's line."""
    pattern = re.compile(r"^/R1/(\w+)\.SRC(?:/(\w+))?$|^KRC:\\R1\\(?:.*\\)?(\w+?)(?:\.SRC)?$", re.I)
    named = 0
    for r in shown:
        want = None
        for p in r["params"]:
            m = pattern.match(p)
            if m and (m.group(1) or m.group(3)).upper() in MODULES:
                module, var = (m.group(1) or m.group(3)).upper(), m.group(2)
                # a variable: its declaration, or the file alone; the module alone: its DEF, line 1
                # of each module of tests/logbook/archive.py
                want = LINES.get(var, (MODULES[module], None)) if var else (MODULES[module], 1)
                break
            if m:
                break
        if want is None:
            assert "file" not in r, r
            continue
        named += 1
        assert (r["file"], r.get("line")) == want, r
    # the logs name CELL, B1 and B3 in 15+3+14+8 (cell), 6+9+50+6+9 (B1), ... records: more than 100
    assert named > 100


def test_log_show_filters_and_text(archive, expected):
    res = CliRunner().invoke(log_group, ["show", str(archive / "Log Files" / "KrcLogB.evt"), "--number", "1008",
                                         "--since", "2026-01-01", "--until", "2026-01-29T04:30:31.901Z"])
    assert res.exit_code == 0, res.output
    want = [e for e in expected if e["log"] == "KrcLogB.evt" and e.get("number") == 1008
            and "2026-01-01" <= e["time"] <= "2026-01-29T04:30:31.901Z"]
    lines = res.output.splitlines()
    assert len(lines) == len(want) > 0
    assert all(" CrossMeld/" in line and " 1008 M_1008" in line for line in lines)


def _truncated(src: Path, dest: Path, keep: int) -> Path:
    dest.write_bytes(src.read_bytes()[:keep])
    return dest


def test_truncated_and_damaged_logs_are_named_and_the_others_read(event_logs, tmp_path, expected):
    folder = tmp_path / "Log Files"
    folder.mkdir()
    (folder / "KrcLogB.evt").write_bytes((event_logs / "KrcLogB.evt").read_bytes())
    # KrcLogU cut in its third chunk (4 KiB header + 64 KiB chunks); its header's chunk count:
    # the little-endian 16-bit word at 0x2A (libevtx's "Windows XML Event Log" format description)
    count = struct.unpack_from("<H", (event_logs / "KrcLogU.evt").read_bytes(), 0x2A)[0]
    _truncated(event_logs / "KrcLogU.evt", folder / "KrcLogU.evt", 0x1000 + 2 * 0x10000 + 1000)
    # KrcLogI with one byte of its only chunk's records changed: the chunk's checksum fails
    data = bytearray((event_logs / "KrcLogI.evt").read_bytes())
    data[0x1000 + 0x400] ^= 0xFF
    (folder / "KrcLogI.evt").write_bytes(bytes(data))
    (folder / "KrcLog.evt").write_bytes(b"not an event log" * 300)
    res = CliRunner().invoke(log_group, ["show", "--format", "json", str(folder)])
    assert res.exit_code == 1
    got = [json.loads(line) for line in res.stdout.splitlines()]
    u = [e for e in expected if e["log"] == "KrcLogU.evt"]
    read_u = [g for g in got if g["channel"] == "KrcLogU"]
    # the first two chunks of KrcLogU stand, in order; every record of KrcLogB is there
    assert len(read_u) > 0 and [g["record"] for g in read_u] == [e["record"] for e in u[:len(read_u)]]
    assert sorted(g["record"] for g in got if g["channel"] == "KrcLogB") == \
        sorted(e["record"] for e in expected if e["log"] == "KrcLogB.evt")
    err = res.stderr
    assert f"KrcLogU.evt: truncated: the header names {count} chunks of records, the file (136168 bytes) " \
           f"holds 2" in err
    assert f"the records after record {read_u[-1]['record']} are missing" in err
    assert "KrcLogI.evt: chunk 1 (byte 4096) is damaged (its checksum fails); the records after its start" in err
    assert "KrcLog.evt: not an EVTX event log" in err
    assert "Traceback" not in err


def test_no_log_and_bad_time_are_usage_errors(tmp_path):
    res = CliRunner().invoke(log_group, ["show", str(tmp_path)])
    assert res.exit_code == 2 and "no event log (.evt) here" in res.stderr
    res = CliRunner().invoke(log_group, ["show", str(tmp_path / "nothing.evt")])
    assert res.exit_code == 2 and "no such file or folder" in res.stderr
    (tmp_path / "a.evt").write_bytes(b"x")
    res = CliRunner().invoke(log_group, ["show", str(tmp_path), "--since", "yesterday"])
    assert res.exit_code == 2 and "not an ISO 8601 time" in res.stderr


@pytest.mark.slow
def test_every_record_of_krclogu_against_record_xml(event_logs, shown):
    want = independent(event_logs / "KrcLogU.evt")
    got = {r["record"]: r for r in shown if r["channel"] == "KrcLogU"}
    assert len(got) == len(want) == 1761
    for e in want:
        g = got[e["record"]]
        assert (g["time"], g["module"], g["number"], g["key"], g["params"]) == \
            (e["time"], e["module"], e["number"], e["key"], e["params"])


def test_summary_of_krclogb_by_number_and_module(archive, expected):
    res = CliRunner().invoke(log_group, ["summary", "--format", "json", str(archive / "Log Files" / "KrcLogB.evt")])
    assert res.exit_code == 0, res.output
    got = json.loads(res.output)
    validate("log-summary", got)
    b = [e for e in expected if e["log"] == "KrcLogB.evt"]
    groups: dict = {}
    for e in b:
        g = groups.setdefault((e["module"], e["number"]), [0, e["time"], e["time"]])
        g[0] += 1
        g[2] = e["time"]
    assert {(m["module"], m["number"]): [m["count"], m["first"], m["last"]] for m in got["messages"]} == groups
    assert (got["records"], got["first"], got["last"]) == (len(b), b[0]["time"], b[-1]["time"])
    # KrcLogB's CrossMeld numbers (5005, 1008) are not messages the simulated controller raises
    assert {m["text"] for m in got["messages"] if m["module"] == "CrossMeld"} == {"text not in the archive"}


def _records(objs: list[dict]) -> list[LogRecord]:
    return [LogRecord(dt.datetime.fromisoformat(o["time"].replace("Z", "+00:00")), o["log"], o["record"], o["channel"],
                      o["level"], o["source"], o["module"], o["number"], o["key"], o["short"], tuple(o["params"]),
                      tuple(o["param_kinds"]), file=o.get("file", ""), line=o.get("line"), names=o.get("names", ""))
            for o in objs]


def test_the_operator_timeline(shown, expected):
    actions = timeline(_records(shown))
    assert [a.record.time for a in actions] == sorted(a.record.time for a in actions)
    overrides = [r for r in shown if r["module"] == "Jogging" and r["key"] == "ProgramOverrideChanged"]
    assert sum(a.count for a in actions if a.kind == "override") == len(overrides) > 1000
    variables = [a for a in actions if a.kind == "variable"]
    want = [e for e in expected if e.get("module") == "Varkor"]      # the sampled ones, read independently
    assert want
    for e in want:
        (a,) = [a for a in variables if a.record.record == e["record"]]
        assert a.text == f"set {e['params'][0]}: {e['params'][1]} -> {e['params'][2]}"
        var = e["params"][0].rsplit("/", 1)[1]
        if var in LINES:
            assert a.place == f"{LINES[var][0]}:{LINES[var][1]}"


def test_override_changes_in_a_row_are_one_action_and_known_numbers_have_texts():
    t = dt.datetime(2026, 1, 27, 10, 0, tzinfo=dt.timezone.utc)
    recs = [LogRecord(t, "u", 1, "KrcLogU", 4, "JOG", "Jogging", 3, "ProgramOverrideChanged", params=("100", "97")),
            LogRecord(t, "u", 2, "KrcLogU", 4, "JOG", "Jogging", 3, "ProgramOverrideChanged", params=("97", "50")),
            LogRecord(t, "u", 3, "KrcLogU", 4, "KcpKeys", "HardKey", 1, "LogStartPlus"),
            LogRecord(t, "u", 4, "KrcLogU", 4, "JOG", "Jogging", 3, "ProgramOverrideChanged", params=("50", "10")),
            LogRecord(t, "u", 5, "KrcLog", 2, "System", "CrossMeld", 1422, "M_1422"),
            LogRecord(t, "u", 6, "KrcLog", 2, "System", "CrossMeld", 1008, "M_1008")]
    assert [(a.kind, a.text, a.count) for a in timeline(recs)] == [
        ("override", "override 100 -> 50 %", 2), ("start", "start key (forward)", 1), ("override", "override 50 -> 10 %", 1)]
    texts = {g.number: g.text for g in messages(recs, KNOWN_MESSAGES)}
    # reference §8.2: 1422 "value invalid"; a number the project does not raise has no text
    assert (texts[1422], texts[1008]) == ("value invalid", "text not in the archive")
    assert KNOWN_MESSAGES[1430][0] == "interrupt not declared"


def test_a_dirty_header_lagging_behind_its_chunks(event_logs, tmp_path, expected):
    """A log copied while open: its header's chunk count (16-bit word at 0x2A) lags and its flags
    (32-bit word at 0x78) say dirty (bit 0; libevtx's format description). The chunks after the
    counted ones are read while they verify; with a clean header they are not (the log holds no
    record then)."""
    data = bytearray((event_logs / "KrcLogB.evt").read_bytes())
    struct.pack_into("<H", data, 0x2A, 0)
    for name, flags in (("dirty.evt", 1), ("clean.evt", 0)):
        struct.pack_into("<I", data, 0x78, flags)
        (tmp_path / name).write_bytes(bytes(data))
    res = CliRunner().invoke(log_group, ["show", "--format", "json", str(tmp_path / "dirty.evt")])
    assert res.exit_code == 0, res.output
    assert [json.loads(line)["record"] for line in res.stdout.splitlines()] == \
        [e["record"] for e in expected if e["log"] == "KrcLogB.evt"]
    # a clean header naming no chunk: a log without records, an error naming it (issue 85)
    res = CliRunner().invoke(log_group, ["show", str(tmp_path / "clean.evt")])
    assert (res.exit_code, res.stdout) == (1, "")
    assert "clean.evt: no record (an empty event log)" in res.stderr
