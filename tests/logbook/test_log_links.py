"""Every logbook record that names a module of the archive, in any form, carries its file and
line (issue 85 item 4): ``Module@line[:point]`` (``B1_Parca_Birakma@48:XPre_Pick_Point``,
``Alt_Programlar@176``: the form of 1,795 of the 6,975 records of the unseen KSS 8.7.8 archive,
the most frequent message CrossMeld 3171 among them; the shared logs hold none, so the records
are built here from the issue's description), a module path of R1 or of STEU (``$MACHINE`` of
R1 is not STEU's), and the summary keeps modules of one name in two files apart. An event log
without records is an error naming it, not an empty success.

The archive is tests/logbook/archive.py's with a second module folder and STEU's machine data;
the expected files and lines are counted by hand from the texts written there."""

from __future__ import annotations

import datetime as dt
import json
import shutil
import struct
import zlib
from pathlib import Path

import pytest
from click.testing import CliRunner

from app.log import log_group
import krl.parsecache as parsecache
import krl.workspace as workspace
from krl.logbook.links import Linker, link_all
from krl.store import Store
from krl.logbook.record import LogRecord
from krl.logbook.summary import summary_json
from tests.logbook.archive import B1_SRC_PATH, CELL_PATH, build_archive, write_files

ALT_PATH = "KRC/R1/Program/Sub_Rutinler/Alt_Programlar.src"
#: five lines: the record's @3 is the WAIT
ALT_SRC = "DEF Alt_Programlar()\n  INT i\n  WAIT SEC 0.1\n  i = 1\nEND\n"
#: a module with KUKA's header lines: its DEF on line 4 (by hand)
HDR_PATH = "KRC/R1/Program/Hdr.src"
HDR_SRC = "&ACCESS RVP\n&REL 1\n&PARAM EDITMASK = *\nDEF Hdr ( )\n  WAIT SEC 0\nEND\n"
R1_MADA = "KRC/R1/Mada/$machine.dat"
STEU_MADA = "KRC/STEU/Mada/$machine.dat"
STEU_MADA_DAT = "DEFDAT $MACHINE PUBLIC\nDECL INT $STEU_ONLY=1\nENDDAT\n"
#: KrcLogI's record of 2025-09-30T06:35:32.180Z names a package in one parameter of 35
#: characters (../shared/event-logs, `krl log show`); the copy names a program line instead
PACKAGE = "26111233990000120003388130 V1.6.0.0"
LINE_REF = "B1_Parca_Birakma@2:XPre_Pick_Point1"


@pytest.fixture(scope="module")
def archive(tmp_path_factory, event_logs) -> Path:
    root = build_archive(tmp_path_factory.mktemp("links") / "archive", None)
    write_files(root, ((ALT_PATH, ALT_SRC), (STEU_MADA, STEU_MADA_DAT), (HDR_PATH, HDR_SRC)))
    (root / "Log Files" / "KrcLogI.evt").write_bytes(_renamed(event_logs / "KrcLogI.evt", PACKAGE, LINE_REF))
    return root


def _renamed(log: Path, old: str, new: str) -> bytes:
    """The EVTX file `log` with the UTF-16 text `old` of its first chunk replaced by `new` (as
    long) and the chunk's two CRC32 checksums made again (libevtx's "Windows XML Event Log"
    format: the records' checksum at chunk offset 52 over bytes 512 .. the free space offset
    at 48; the header's at 124 over bytes 0..120 and 128..512)."""
    assert len(old) == len(new)
    data = bytearray(log.read_bytes())
    a, b = old.encode("utf-16-le"), new.encode("utf-16-le")
    assert data.count(a) == 1
    i = data.index(a)
    data[i:i + len(a)] = b
    c = 0x1000
    free = struct.unpack_from("<I", data, c + 48)[0]
    struct.pack_into("<I", data, c + 52, zlib.crc32(bytes(data[c + 512:c + free])))
    struct.pack_into("<I", data, c + 124, zlib.crc32(bytes(data[c:c + 120]) + bytes(data[c + 128:c + 512])))
    return bytes(data)


def _rec(*params: str, number: int = 3171) -> LogRecord:
    return LogRecord(dt.datetime(2026, 1, 28, tzinfo=dt.timezone.utc), "KrcLog.evt", 1, "KrcLog", 2,
                     source="KRC", module="CrossMeld", number=number, key=f"M_{number}", params=params)


CASES = [
    # (parameter, file, line, names): by hand from tests/logbook/archive.py and ALT_SRC
    ("B1_Parca_Birakma@2:XPre_Pick_Point", B1_SRC_PATH, 2, "B1_PARCA_BIRAKMA"),
    ("Alt_Programlar@3", ALT_PATH, 3, "ALT_PROGRAMLAR"),
    ("ALT_PROGRAMLAR@5", ALT_PATH, 5, "ALT_PROGRAMLAR"),
    ("cell@1", CELL_PATH, 1, "CELL"),
    # a line the file does not have: the module's file, no line
    ("B1_Parca_Birakma@48:XPre_Pick_Point", B1_SRC_PATH, None, "B1_PARCA_BIRAKMA"),
    # a module the archive does not hold: nothing
    ("Elsewhere@5", "", None, ""),
    # R1's machine data and STEU's: each its own file, at its DEFDAT (robot/data/kr180_r3200_pa.dat
    # starts with two header lines: DEFDAT on line 3; STEU_MADA_DAT on line 1)
    ("/R1/$MACHINE.DAT", R1_MADA, 3, "$MACHINE"),
    ("/STEU/$MACHINE.DAT", STEU_MADA, 1, "$MACHINE"),
    # a module named without a line, by its path or its file: its DEF line below the header
    ("/R1/HDR.SRC", HDR_PATH, 4, "HDR"),
    ("KRC:\\R1\\Program\\Hdr.src", HDR_PATH, 4, "HDR"),
    ("KRC:\\R1\\Program\\Hdr", HDR_PATH, 4, "HDR"),
    # a module of R1 named in STEU's namespace: not there
    ("/STEU/CELL.SRC", "", None, ""),
]


@pytest.mark.parametrize("param,file,line,names", CASES)
def test_a_record_naming_a_program_line_carries_its_file_and_line(archive, param, file, line, names):
    rec = _rec("3171", param)
    link_all([rec], archive)
    assert (rec.file, rec.line, rec.names) == (file, line, names)


def test_the_summary_keeps_modules_of_one_name_in_two_files_apart(archive):
    recs = [_rec("/R1/$MACHINE.DAT"), _rec("/R1/$MACHINE.DAT"), _rec("/STEU/$MACHINE.DAT"),
            _rec("B1_Parca_Birakma@2"), _rec("B1_Parca_Birakma@3")]
    link_all(recs, archive)
    got = sorted((p["names"], p["file"], p["line"], p["count"]) for p in summary_json(recs)["programs"])
    assert got == [("$MACHINE", R1_MADA, 3, 2), ("$MACHINE", STEU_MADA, 1, 1),
                   ("B1_PARCA_BIRAKMA", B1_SRC_PATH, 2, 1), ("B1_PARCA_BIRAKMA", B1_SRC_PATH, 3, 1)]


def test_log_show_links_the_program_line_of_a_real_log_s_record(archive):
    res = CliRunner().invoke(log_group, ["show", "--format", "json", str(archive)])
    assert res.exit_code == 0, res.output
    objs = [json.loads(line) for line in res.stdout.splitlines()]
    assert len(objs) == 26                                 # the README's count of KrcLogI
    got = [(o["params"], o.get("file"), o.get("line")) for o in objs if "file" in o]
    assert got == [([LINE_REF], B1_SRC_PATH, 2)]


def _empty_log(like: Path) -> bytes:
    """The file header of `like` saying no chunk and no record (a cleared log): chunk count 0
    at 0x2A, first/last chunk 0 and next record 1 at 8, 16, 24, its CRC32 at 0x7C over bytes
    0..120 (libevtx's format description)."""
    data = bytearray(like.read_bytes()[:0x1000])
    struct.pack_into("<QQQ", data, 8, 0, 0, 1)
    struct.pack_into("<H", data, 0x2A, 0)
    struct.pack_into("<I", data, 0x7C, zlib.crc32(bytes(data[:120])))
    return bytes(data)


@pytest.mark.parametrize("command", ["show", "summary"])
def test_an_event_log_without_records_is_an_error_naming_it(event_logs, tmp_path, command):
    log = tmp_path / "KrcLogB.evt"
    log.write_bytes(_empty_log(event_logs / "KrcLogB.evt"))
    res = CliRunner().invoke(log_group, [command, str(log)])
    assert res.exit_code == 1, res.output
    assert "KrcLogB.evt: no record (an empty event log)" in res.stderr, res.stderr
    assert "0 records" not in res.stdout


def test_filters_that_keep_no_record_say_so_and_fail(event_logs, tmp_path):
    shutil.copyfile(event_logs / "KrcLogI.evt", tmp_path / "KrcLogI.evt")
    res = CliRunner().invoke(log_group, ["show", str(tmp_path / "KrcLogI.evt"), "--module", "Varkor"])
    assert res.exit_code == 1, res.output
    assert "no record of the 26 read passes the filters" in res.stderr, res.stderr


def test_the_archives_workspace_is_read_from_the_store(archive, tmp_path, monkeypatch):
    """The declarations a record's variable links to come from the archive's workspace read as
    `krl check` reads a backup: each file's parse from the one store (krl/store.py), the others in
    worker processes stopped past the parse timeout. A second linker of the same archive parses no
    file (before, every linker parsed the whole backup in this process, with no timeout)."""
    store = Store(tmp_path / "store")
    monkeypatch.setattr(parsecache, "shared_store", lambda: store)
    first = Linker(archive).declared("$MACHINE", "$TRAFONAME")

    def no_parse(*_args, **_kw):
        raise AssertionError("a file was parsed, not read from the store")
    for module in (parsecache, workspace):
        monkeypatch.setattr(module, "load_batch", no_parse)
        monkeypatch.setattr(module, "load_here", no_parse)
    monkeypatch.setattr(workspace, "load_parsed", no_parse)
    monkeypatch.setattr(workspace, "load_file", no_parse)
    assert first is not None
    assert Linker(archive).declared("$MACHINE", "$TRAFONAME") == first
