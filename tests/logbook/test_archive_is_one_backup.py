"""A KUKA archive is one backup, zipped or not, one at a time or a folder of them (issue 85 item 3).

The case as the issue saw it on an unseen KSS 8.7.8 archive, rebuilt from its description and the
layout of ../shared/event-logs/README.md (tests/logbook/archive.py ``build_kss_archive``: KRC/R1,
KRC/STEU, C/KRC/Roboter/Template/*.src, a binary PROFINET file under C/, Log Files/KrcLogI.evt):
`krl graph` and `krl report` exited 2 ("archive holds 2 programs ... name one of them"), `krl
check` exited 1 for C/'s files, `krl audit` ran C/'s templates and refused the .zip, a folder of
archive zips gave "0 entry points" and "no errors in 0 files" with exit 0, `krl cell init` found no
machine data. The expected counts are by hand from the archive's texts: 7 KRL files in KRC (R1's
$config.dat, cell.src, B1 .src, B3 .src and .dat, STEU's $config.dat, R1/Mada/$machine.dat), 3
programs (CELL, B1_Parca_Birakma, B3_Parca_Birakma: DEFs without parameters), and the 26 records
of KrcLogI.evt (../shared/event-logs/README.md: "142, 26 and 1,761 records").
"""

from __future__ import annotations

import json
import re
import shutil
import zipfile
from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main
from krl import backups, limits
from krl.archive import ArchiveError, extract_backup
from tests.logbook.archive import build_fleet, build_kss_archive, zip_folder

pytestmark = [pytest.mark.xdist_group("logbook")]

KRC_FILES = 7
PROGRAMS = 3
RECORDS = 26


@pytest.fixture(scope="module")
def made(tmp_path_factory, event_logs) -> dict[str, Path]:
    """The archive as a folder, zipped, a folder holding the zip alone, a folder of two zips, an
    empty folder."""
    top = tmp_path_factory.mktemp("kss878")
    archive = build_kss_archive(top / "archive", event_logs)
    one = top / "one"
    one.mkdir()
    zipped = zip_folder(archive, top / "archive.zip")
    zip_folder(archive, one / "archive.zip")
    (top / "empty").mkdir()
    return {"folder": archive, "zip": zipped, "one": one, "fleet": build_fleet(top / "fleet", event_logs),
            "empty": top / "empty"}


def krl(*args: str):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.mark.parametrize("kind", ["folder", "zip", "one"])
def test_check_reads_the_krc_backup_only(made, kind):
    res = krl("check", made[kind])
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[-1] == f"no errors in {KRC_FILES} files"
    assert "Template" not in res.output and "PNIO" not in res.output


def test_check_takes_every_archive_of_a_folder(made):
    res = krl("check", "--format", "json", made["fleet"])
    assert res.exit_code == 0, res.output
    got = [json.loads(line) for line in res.output.splitlines()]
    fleet = made["fleet"]
    assert [(g["workspace"], g["files"]) for g in got] == [
        (f"{fleet}/cell_a.zip/KRC", KRC_FILES), (f"{fleet}/cell_b.zip/KRC", KRC_FILES)]


def test_check_of_nothing_is_no_pass(made):
    res = krl("check", made["empty"])
    assert res.exit_code == 2
    assert f"krl check: error: no KRL file in {made['empty']}" in res.output
    assert "no errors in 0 files" not in res.output      # nothing read is said once, as an error


def test_a_refused_archive_of_a_folder_stops_only_itself(made, tmp_path):
    fleet = tmp_path / "fleet"
    fleet.mkdir()
    (fleet / "a.zip").write_bytes(made["zip"].read_bytes())
    with zipfile.ZipFile(fleet / "b.zip", "w") as zf:
        zf.writestr("../evil.src", "DEF evil()\nEND\n")
    res = krl("check", fleet)
    assert res.exit_code == 1
    assert f"{fleet / 'b.zip'}:1:1: error[E004]: entry '../evil.src' leaves the archive folder ('..')" in res.output
    assert res.output.splitlines()[-1] == f"1 error in {KRC_FILES} files"


@pytest.mark.parametrize("kind", ["folder", "zip", "one"])
def test_graph_maps_the_one_backup(made, kind):
    res = krl("graph", "--format", "text", made[kind])
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[0].startswith(f"{made[kind] if kind != 'one' else made['one'] / 'archive.zip'}/KRC: "
                                                 f"3 routines (3 of its own")
    assert re.search(r"^  cell +CELL +R1/cell\.src:1$", res.output, re.M), res.output


@pytest.mark.parametrize("command", [["graph", "--format", "text"], ["robot", "show"], ["cell", "init"], ["run"]])
def test_a_command_of_one_backup_names_the_archives_of_a_folder(made, command):
    fleet = made["fleet"]
    res = krl(*command, fleet)
    assert res.exit_code == 2
    assert (f"{fleet} holds 2 programs (KRC backups or folders): {fleet}/cell_a.zip/KRC, {fleet}/cell_b.zip/KRC; "
            f"name one of them") in res.output


@pytest.mark.parametrize("command", [["log", "summary"], ["diff", "ARCHIVE"]])
def test_log_and_diff_name_the_archives_of_a_folder(made, command):
    fleet = made["fleet"]
    res = krl(*[made["folder"] if c == "ARCHIVE" else c for c in command], fleet)
    assert res.exit_code == 2
    assert f"{fleet} holds 2 archives: {fleet}/cell_a.zip, {fleet}/cell_b.zip; name one of them" in res.output


def test_cell_init_reads_the_archives_machine_data_and_programs(made):
    for kind in ("folder", "zip"):
        res = krl("cell", "init", made[kind])
        assert res.exit_code == 0, res.output
        lines = res.output.splitlines()
        assert lines[1] == ("# Programs: R1/Program/Parca_Birakma/B1_Parca_Birakma.src, "
                            "R1/Program/Parca_Birakma/B3_Parca_Birakma.src, R1/cell.src")
        # the machine data found (it said "this backup has no R1/Mada/$machine.dat" before)
        assert any(line.startswith("# robot: NAME       # the backup's own robot (its R1/Mada/$machine.dat) runs")
                   for line in lines), res.output


def test_robot_show_of_a_folder_holding_one_archive(made):
    res = krl("robot", "show", made["one"])
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[1] == f"source     {made['one']}/archive.zip/KRC/R1/Mada/$machine.dat"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_run_of_a_folder_holding_one_archive_runs_its_cell(made, interp):
    res = krl("run", made["one"], "--interp", interp, "--max-sim-time", "1")
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[0] == f"run {made['one']}/archive.zip/KRC/R1/cell.src ({interp} interpreter)"
    assert "  ended      completed at t=0.000 s" in res.output.splitlines()


def test_log_of_a_folder_holding_one_archive(made):
    res = krl("log", "summary", made["one"])
    assert res.output.splitlines()[0].startswith(f"{RECORDS} records, "), res.output


def test_diff_of_an_archive_compares_its_krc_backup(made):
    res = krl("diff", made["folder"], made["zip"])
    assert res.exit_code == 0, res.output
    assert f"compared {KRC_FILES} file(s)" in res.output
    assert "E102" not in res.output and "Template" not in res.output


def test_audit_of_an_archive_folder(made, tmp_path):
    res = krl("audit", "--jobs", "1", "--out", tmp_path, made["folder"])
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "audit.json").read_text())
    assert [(u["name"], u["files"], len(u["entries"]), u["logbook"]["records"]) for u in data["units"]] == [
        ("KRC", KRC_FILES, PROGRAMS, RECORDS)]


def test_audit_of_a_folder_of_archive_zips(made, tmp_path):
    fleet = made["fleet"]
    res = krl("audit", "--jobs", "1", "--out", tmp_path, fleet)
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "audit.json").read_text())
    assert [(u["name"], u["root"], u["files"], len(u["entries"]), u["logbook"]["records"]) for u in data["units"]] == [
        ("cell_a.zip/KRC", f"{fleet}/cell_a.zip/KRC", KRC_FILES, PROGRAMS, RECORDS),
        ("cell_b.zip/KRC", f"{fleet}/cell_b.zip/KRC", KRC_FILES, PROGRAMS, RECORDS)]
    assert (f"2 backups, 0 program folders ({2 * KRC_FILES} files, {2 * RECORDS} logbook records), "
            f"{2 * PROGRAMS} entry points: 0 attention, 0 review, 2 ok") in res.output.splitlines()


def test_audit_of_nothing_is_no_pass(made, tmp_path):
    res = krl("audit", "--out", tmp_path, made["empty"])
    assert res.exit_code == 2
    assert f"krl audit: error: {made['empty']}: no KRC backup, controller archive or KRL program in it" in res.output


def test_a_folder_of_more_archives_than_the_limit_is_refused(made, monkeypatch):
    monkeypatch.setattr(backups, "MAX_FOLDER_ARCHIVES", 1)
    res = krl("check", made["fleet"])
    assert res.exit_code == 2
    assert (f"krl check: error: {made['fleet']}: 2 archives (.zip) below it (limit MAX_FOLDER_ARCHIVES = 1, "
            f"docs/security.md): name fewer at a time") in res.output


def test_the_archives_of_a_folder_share_one_byte_budget(made, tmp_path):
    """krl/backups.py extracts a folder's archives with what is left of MAX_ARCHIVE_BYTES: an
    archive that would pass it alone is refused past the others' bytes."""
    written: list[int] = []
    extract_backup(made["zip"], tmp_path / "a", budget=None, written_to=written) if (tmp_path / "a").mkdir() is None else None
    assert 0 < written[0] < limits.MAX_ARCHIVE_BYTES
    (tmp_path / "b").mkdir()
    with pytest.raises(ArchiveError, match=r"goes past \d+ bytes \(limit MAX_ARCHIVE_BYTES, shared with the archives "
                                           r"before it\)"):
        extract_backup(made["zip"], tmp_path / "b", budget=written[0] - 1)


def test_report_of_a_folder_holding_one_archive_has_its_cover_and_logbook(made, tmp_path):
    """The report reads the archive a folder holds as it reads the .zip: the cover's archive row
    (am.ini's robot name and serial, tests/logbook/archive.py) and the logbook's records."""
    out = tmp_path / "r.html"
    res = krl("report", "--no-runs", "-o", out, made["one"])
    assert res.exit_code == 0, res.output
    page = out.read_text(encoding="utf-8")
    assert "<th>archive</th><td>Test_Cell_75, serial 750075" in page
    assert f"{RECORDS} records" in page
    res = krl("report", "--no-runs", "-o", out, made["fleet"])
    assert res.exit_code == 2
    assert f"{made['fleet']} holds 2 archives: " in res.output


@pytest.fixture(scope="module")
def recovered(made, tmp_path_factory):
    """`krl recover` of the archive folder, the folder of two archive zips and the empty folder:
    {kind: (exit code, output, the report's files.csv rows)}, one cache for the three (the
    negative corpus parsed once)."""
    out = {}
    cache = tmp_path_factory.mktemp("recover-cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("KRL_CACHE_DIR", str(cache))
        for kind in ("folder", "fleet", "empty"):
            report = tmp_path_factory.mktemp(f"recover-{kind}")
            res = CliRunner().invoke(main, ["recover", str(made[kind]), "--out", str(report / "r"), "--jobs", "1"])
            rows = (report / "r" / "files.csv").read_text(encoding="utf-8").splitlines()[1:] \
                if (report / "r" / "files.csv").exists() else []
            out[kind] = (res.exit_code, res.output, rows)
    return out


def test_recover_reads_an_archives_krc_backup_only(recovered):
    """Before: 12 files of which 10 parsed (C/'s template vorgabe.src a false missing construct,
    C/'s binary PROFINET file a file not parsed)."""
    code, output, rows = recovered["folder"]
    assert code == 0, output
    assert output.startswith(f"{KRC_FILES}/{KRC_FILES} files parse"), output
    assert all(r.startswith("KRC/") for r in rows), rows


def test_recover_reads_every_archive_of_a_folder(recovered):
    """Before: "0/0 files parse", exit 0 (the zips were not read)."""
    code, output, rows = recovered["fleet"]
    assert code == 0, output
    assert output.startswith(f"{2 * KRC_FILES}/{2 * KRC_FILES} files parse"), output
    assert sorted({r.split("/", 1)[0] for r in rows}) == ["cell_a.zip", "cell_b.zip"]
    assert not any("/C/" in r or "Template" in r for r in rows), rows


def test_recover_of_nothing_is_no_pass(recovered):
    code, output, _rows = recovered["empty"]
    assert code == 2 and "no KRL file in" in output, output


def test_fmt_checks_an_archive_zip_and_a_folder_of_them_but_writes_neither(made, tmp_path):
    """Before: the zip was "file not parsed: binary (NUL bytes)", the folder of zips "0 files
    would be reformatted, 0 unchanged", exit 0, and an archive folder formatted C/'s templates."""
    folder = krl("fmt", "--check", made["folder"])
    zipped = krl("fmt", "--check", made["zip"])
    assert folder.exit_code == zipped.exit_code == 1
    counts = folder.output.splitlines()[-1]
    assert counts.endswith(" unchanged") and sum(int(n) for n in re.findall(r"\d+", counts)) == KRC_FILES, counts
    assert zipped.output.splitlines()[-1] == counts
    assert f"--- {made['zip']}/KRC/R1/cell.src (original)" in zipped.output
    assert "Template" not in folder.output + zipped.output
    fleet = tmp_path / "fleet"
    shutil.copytree(made["fleet"], fleet)
    before = {p.name: p.read_bytes() for p in fleet.iterdir()}
    res = krl("fmt", fleet)
    assert res.exit_code == 2
    assert f"{fleet / 'cell_a.zip'}: a .zip archive is not formatted in place" in res.output
    assert {p.name: p.read_bytes() for p in fleet.iterdir()} == before
    empty = krl("fmt", made["empty"])
    assert empty.exit_code == 2 and f"krl fmt: error: no KRL file in {made['empty']}" in empty.output


@pytest.mark.parametrize("kind", ["folder", "zip"])
def test_asm_of_an_archive_is_its_cell_program(made, kind):
    """Before: "; module ARCHIVE: syntax errors, not compiled: ... not_regular (a folder)", exit 0."""
    res = krl("asm", made[kind])
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[:3] == ["; module CELL", ".routine CELL DEF",
                                           f'.file "{made[kind]}/KRC/R1/cell.src"']


def test_asm_of_a_module_with_syntax_errors_fails(tmp_path):
    bad = tmp_path / "bad.src"
    bad.write_text("DEF bad()\n  x =\nEND\n", encoding="utf-8")
    res = krl("asm", bad)
    assert res.exit_code == 1
    assert res.output.startswith(f"; module BAD: syntax errors, not compiled: {bad}:2:"), res.output


def test_growth_of_nothing_is_no_pass(made):
    """Before: every grammar version replayed over no file (4 min here), growth.csv of zeros, exit 0."""
    res = krl("growth", made["empty"], "--out", made["empty"].parent / "growth")
    assert res.exit_code == 2 and f"no KRL file in {made['empty']}" in res.output
    assert not (made["empty"].parent / "growth").exists()


def test_asm_exit_status_comes_from_the_modules_not_from_their_text(tmp_path):
    """A module that compiles exits 0 though its listing quotes a string with the words of the
    failure line (its source line and its CONST; the status was read from the printed text
    before, and was 1)."""
    good = tmp_path / "good.src"
    good.write_text('DEF good()\n  DECL CHAR s[80]\n  s[] = ": syntax errors, not compiled: "\nEND\n', encoding="utf-8")
    res = krl("asm", good)
    assert res.exit_code == 0, res.output
    assert res.output.startswith("; module GOOD\n")
