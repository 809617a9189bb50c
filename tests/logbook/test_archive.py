"""A controller archive as KUKA writes it is one thing every command accepts (issue 72 item 8,
issue 75 item 4): its KRC folder is the backup (also when its $config.dat is in KRC/STEU and
R1/System has none), its machine data found in KRC/R1/Mada, its am.ini and ArchiveInfo.xml shown
by `krl robot show` and the report's cover, folder or .zip. The archive is tests/logbook/archive.py's;
the expected values are the texts written there, and for the shared archive's manifest the
values of its am.ini and ArchiveInfo.xml as ../shared/event-logs/README.md describes them."""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import threading
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from click.testing import CliRunner
from Evtx.Evtx import Evtx

from app import main
from app.changes import load_map
from krl.programmap.render import logbook_marks, page_data
from krl.logbook.links import module_reference
from krl.kssarchive import archive_root, log_files, parse_am_ini, parse_archive_info, read_info
from tests.logbook.archive import build_archive, zip_folder

NS = "{http://schemas.microsoft.com/win/2004/08/events/event}"

# one worker takes the module (make test: --dist loadgroup), so its module fixtures build each archive once
pytestmark = [pytest.mark.xdist_group("logbook")]


@pytest.fixture(scope="module")
def archive(tmp_path_factory, event_logs) -> Path:
    return build_archive(tmp_path_factory.mktemp("kss") / "archive", event_logs, ("KrcLogI.evt",))


@pytest.fixture(scope="module")
def steu_only(tmp_path_factory) -> Path:
    """The archive with its $config.dat in KRC/STEU and none in KRC/R1/System."""
    root = build_archive(tmp_path_factory.mktemp("steu") / "archive", None)
    shutil.move(root / "KRC" / "R1" / "System" / "$config.dat", root / "KRC" / "STEU" / "$config.dat")
    return root


def krl(*args: str):
    return CliRunner().invoke(main, list(args))


def test_an_archive_whose_config_is_in_steu_is_a_backup(steu_only):
    """Failed before krl/project.py knew the layout: `krl robot show` said "no R1/Mada/$machine.dat
    in this folder" and `krl graph` "a folder, not a KRC backup"."""
    res = krl("robot", "show", str(steu_only))
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[1] == f"source     {steu_only / 'KRC' / 'R1' / 'Mada' / '$machine.dat'}"
    res = krl("graph", str(steu_only), "--format", "text")
    assert res.exit_code == 0, res.output
    assert "a folder, not a KRC backup" not in res.output
    assert re.search(r"^  cell +CELL +R1/cell\.src:1$", res.output, re.M), res.output


@pytest.mark.parametrize("zipped", [False, True])
def test_robot_show_names_the_archive(archive, tmp_path, zipped):
    path = zip_folder(archive, tmp_path / "archive.zip") if zipped else archive
    res = krl("robot", "show", str(path))
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert lines[1] == f"source     {path / 'KRC' / 'R1' / 'Mada' / '$machine.dat'}"
    assert "named      Test_Cell_75, serial 750075" in lines
    assert "type       #KR180R3200PA C4 FLR (ArchiveInfo.xml)" in lines
    assert "software   KSS 8.7.8 build 671" in lines
    assert "packages   KUKA.PROFINET MS 6.0.8, KUKA.UpdateService 1.1.24" in lines


def test_the_report_cover_names_the_archive_and_its_logbook(archive, tmp_path, event_logs):
    out = tmp_path / "report.html"
    res = krl("report", str(zip_folder(archive, tmp_path / "archive.zip")), "--no-runs", "-o", str(out))
    assert res.exit_code == 0, res.output
    page = out.read_text(encoding="utf-8")
    row = re.search(r'<tr id="cover-archive">(.*?)</tr>', page, re.S).group(1)
    text = html.unescape(re.sub(r"<[^>]+>", " ", row))
    assert "Test_Cell_75, serial 750075, #KR180R3200PA C4 FLR, KSS 8.7.8 build 671" in " ".join(text.split())
    assert "technology packages: KUKA.PROFINET MS 6.0.8, KUKA.UpdateService 1.1.24" in " ".join(text.split())
    # the logbook section: KrcLogI's 26 records, by module and number as python-evtx reads them
    section = re.search(r'<section class="logbook" id="logbook-backup">(.*?)</section>', page, re.S).group(1)
    assert "26 of 26 records" in section
    counts: dict = {}
    with Evtx(str(event_logs / "KrcLogI.evt")) as log:
        for rec in log.records():
            ls = ET.fromstring(next(d.text for d in ET.fromstring(rec.xml()).iter(NS + "Data")))
            key = (ls.findtext("M"), ls.findtext("N"))
            counts[key] = counts.get(key, 0) + 1
    rows = re.findall(r'<tr><td class="num">(\d+)</td><td>(\w+)</td><td class="num">(\d*)</td>', section)
    assert {(m, n): int(c) for c, m, n in rows} == counts


def test_the_archive_is_found_from_inside_and_its_logs_listed(tmp_path):
    archive = build_archive(tmp_path / "archive", None)
    assert archive_root(archive / "KRC" / "R1" / "Program" / "Parca_Birakma" / "B3_Parca_Birakma.src") == archive
    (tmp_path / "other").mkdir()
    assert archive_root(tmp_path / "other") is None
    (archive / "Log Files" / "KrcLogU.evt").write_bytes(b"")
    (archive / "Log Files" / "KrcLog.evt").write_bytes(b"")
    (archive / "Log Files" / "notes.txt").write_text("")
    assert [p.name for p in log_files(archive)] == ["KrcLog.evt", "KrcLogU.evt"]


def test_the_shared_archive_manifest(event_logs):
    """The values of ../shared/event-logs' am.ini and ArchiveInfo.xml (README: a KR 470 PA-2 on KSS
    V8.7.8; the files' own lines)."""
    ini = parse_am_ini((event_logs / "am.ini").read_text(encoding="utf-8"))
    assert (ini["robot_name"], ini["serial"], ini["kss"]) == ("Ambalajli_Paletleme_Robotu", "996627", "V8.7.8")
    assert len(ini["techpacks"]) == 9
    assert ini["techpacks"][0] == ("DiagnosisSafety", "3.2.4")
    assert ("KUKA.DeviceConnector pre-installed", "2.1.13") in ini["techpacks"]
    xml = parse_archive_info((event_logs / "ArchiveInfo.xml").read_bytes())
    assert (xml["robot_type"], xml["build"], xml["kss"]) == ("#KR470PA_2 S C4 FLR", "671", "V8.7.8")
    assert xml["logs"] == ["KrcLog", "KrcLogI", "KrcLogU", "KrcLogS", "KrcLogP", "KrcLogB", "KrcLogC"]
    assert ("KUKA.PROFINET MS", "6.0.8") in xml["techpacks"]
    info = read_info(event_logs)
    assert (info.robot_name, info.robot_type, info.techpacks[0]) == \
        ("Ambalajli_Paletleme_Robotu", "#KR470PA_2 S C4 FLR", ("DiagnosisSafety", "3.2.4"))


def test_a_bad_manifest_is_a_note_never_an_error(tmp_path):
    (tmp_path / "am.ini").write_text("this is no ini file\n[")
    (tmp_path / "ArchiveInfo.xml").write_text('<!DOCTYPE x [<!ENTITY a "b">]><ArchiveInformation>&a;</ArchiveInformation>')
    info = read_info(tmp_path)
    assert info.robot_name == "" and len(info.notes) == 2
    assert "am.ini: not an INI file" in info.notes[0]
    assert "ArchiveInfo.xml: not readable XML" in info.notes[1]


def test_a_manifest_that_is_no_regular_file_is_a_note(tmp_path):
    """An archive folder whose am.ini is a FIFO (a folder copied from an untrusted place): the
    manifest is not opened (opening a FIFO blocks until someone writes it), a note names it, and
    ArchiveInfo.xml is read. Before the fix read_info waited on the FIFO for ever."""
    fifo = tmp_path / "am.ini"
    os.mkfifo(fifo)
    (tmp_path / "ArchiveInfo.xml").write_text('<ArchiveInformation xmlns="KUKARoboter.Contracts.Archive"><Roboter>'
                                              "<Name>Cell_9</Name></Roboter>"
                                              "</ArchiveInformation>")
    got = []
    reader = threading.Thread(target=lambda: got.append(read_info(tmp_path)), daemon=True)
    reader.start()
    reader.join(5)
    if reader.is_alive():               # release the blocked open before failing
        with open(fifo, "w"):
            pass
    assert got, "read_info blocked on the FIFO am.ini"
    assert got[0].robot_name == "Cell_9"
    assert got[0].notes == (f"{fifo}: not a regular file; not read",)


def test_the_map_marks_what_the_logbook_names(archive):
    """The main routine of each module a logbook record names gets a mark (krl graph, krl report);
    a module the archive does not hold, none."""
    pm = load_map(str(archive))[0]
    marks = logbook_marks(pm, {"B3_PARCA_BIRAKMA.b3_parcasirasi": 5, "CELL": 2, "B3_PARCA_BIRAKMA": 1,
                               "B4_PARCA_BIRAKMA": 3})
    by_name = {pm.nodes[nid].name.upper(): text for nid, text in marks.items()}
    assert by_name == {"B3_PARCA_BIRAKMA": "B3_PARCA_BIRAKMA.b3_parcasirasi (5 records), B3_PARCA_BIRAKMA (1 record)",
                       "CELL": "CELL (2 records)"}
    data = page_data(pm, "none", marks)
    assert {n["name"].upper() for n in data["nodes"] if n["logbook"]} == {"B3_PARCA_BIRAKMA", "CELL"}


def test_log_show_reads_a_zipped_archive(archive, tmp_path):
    path = zip_folder(archive, tmp_path / "archive.zip")
    res = krl("log", "show", "--format", "json", str(path))
    assert res.exit_code == 0, res.output
    objs = [json.loads(line) for line in res.output.splitlines()]
    assert len(objs) == 26 and {o["log"] for o in objs} == {f"{path}/Log Files/KrcLogI.evt"}


@pytest.mark.parametrize("interp,zipped", [("tree", False), ("vm", True)])
def test_krl_run_of_an_archive_runs_its_cell_program(steu_only, tmp_path, interp, zipped):
    """An archive given whole runs KRC/R1/cell.src (CELL calls B1 and B3, which complete), folder
    (tree interpreter) or zip (VM); a folder without a backup is a usage error naming the way to
    name a program. Before, a folder stopped at once ("no main routine in archive") and a zip was
    refused ("name the program to run in it")."""
    path = zip_folder(steu_only, tmp_path / "archive.zip") if zipped else steu_only
    res = krl("run", str(path), "--interp", interp, "--max-sim-time", "1")
    lines = res.output.splitlines()
    assert lines[0] == f"run {path / 'KRC' / 'R1' / 'cell.src'} ({interp} interpreter)", res.output
    assert lines[2].split() == ["ended", "completed", "at", "t=0.000", "s"], res.output
    assert res.exit_code == 0
    (tmp_path / "empty").mkdir()
    res = krl("run", str(tmp_path / "empty"))
    assert res.exit_code == 2 and "holds no KRC backup with a cell program (R1/cell.src)" in res.output


def test_module_references():
    """The forms the shared logs and their README show (docs/log.md), the program line of issue 85
    (``Module@line[:point]``), and near misses."""
    assert module_reference("/R1/B3_PARCA_BIRAKMA.SRC/b3_parcasirasi") == \
        ("module", "B3_PARCA_BIRAKMA", "b3_parcasirasi", "R1")
    assert module_reference("/R1/CELL.SRC") == ("module", "CELL", "", "R1")
    assert module_reference("/R1/B4_PARCA_BIRAKMA.SRC/p") == ("module", "B4_PARCA_BIRAKMA", "p", "R1")
    assert module_reference("/R1/X.SRC/arr[3].pos") == ("module", "X", "arr", "R1")
    assert module_reference("/R1/X.SRC/MAIN/i") == ("module", "X", "i", "R1")
    assert module_reference("/STEU/$MACHINE.DAT") == ("module", "$MACHINE", "", "STEU")
    assert module_reference("KRC:\\R1\\Program\\Parca_Birakma\\B3_Parca_Birakma") == \
        ("file", "R1/Program/Parca_Birakma/B3_Parca_Birakma", "", "")
    assert module_reference("krc:\\R1\\cell.src") == ("file", "R1/cell.src", "", "")
    assert module_reference("B1_Parca_Birakma@48:XPre_Pick_Point") == ("line", "B1_Parca_Birakma", "48", "R1")
    assert module_reference("Alt_Programlar@176") == ("line", "Alt_Programlar", "176", "R1")
    for other in ("$OUT[235]", "RobotData.xml", "/R1", "KrcSecurity#Operator", "R1/CELL.SRC", "user@host",
                  "@48", "Alt_Programlar@", "Alt_Programlar@17x", "B1@48:", "/X1/CELL.SRC"):
        assert module_reference(other) is None, other
