"""KRC backup archives (.zip) for krl check / recover / run (krl/archive.py, krl/limits.py).

A good archive checks exactly like its folder; every unsafe or oversized archive is refused with
a message naming the archive and the entry, and the temporary folder never outlives the command.
"""

from __future__ import annotations

import json
import stat
import tempfile
import zipfile
from pathlib import Path

import pytest
from click.testing import CliRunner

from krl import limits
from krl.archive import ArchiveError, backup_source, extract_backup
from app.check import run_check
from interp.cli import run
from krl.workspace import on_each_file, workspaces_for
from recovery.cli import recover

CONFIG = "DEFDAT $CONFIG\n  DECL INT counter = 0\nENDDAT\n"
DEMO = ("DEF demo()\n"                    # 1
        "  INT i\n"                       # 2
        "  ;FOLD x\n"                     # 3  W021 at 3:3 (never closed)
        "  i = counter + undeclared\n"    # 4  E101 at 4:17
        "END\n")                          # 5
DONE = "DEF done()\n  INT i\n  i = counter + 1\nEND\n"


def make_backup(root: Path) -> Path:
    """A small synthetic KRC backup folder: KRC/R1/System/$config.dat and two programs."""
    (root / "KRC/R1/System").mkdir(parents=True)
    (root / "KRC/R1/Program").mkdir(parents=True)
    (root / "KRC/R1/System/$config.dat").write_text(CONFIG)
    (root / "KRC/R1/Program/demo.src").write_text(DEMO)
    (root / "KRC/R1/Program/done.src").write_text(DONE)
    (root / "KRC/R1/Program/notes.txt").write_text("not KRL")
    return root / "KRC"


def zip_folder(folder: Path, archive: Path) -> Path:
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zf:
        for p in sorted(folder.parent.rglob("*")):
            zf.write(p, p.relative_to(folder.parent).as_posix())
    return archive


def check_json(path: Path) -> tuple[int, list[dict]]:
    out: list[str] = []
    status = run_check([str(path)], fmt="json", echo=out.append)
    return status, [d for line in out for d in json.loads(line)["diagnostics"]]


@pytest.fixture
def own_tmp(tmp_path, monkeypatch) -> Path:
    """Temporary folders of the code under test go here, so that the test can see them."""
    t = tmp_path / "tmpdirs"
    t.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(t))
    return t


def test_good_archive_checks_like_its_folder(tmp_path, own_tmp, monkeypatch):
    monkeypatch.chdir(tmp_path)
    folder = make_backup(Path("src"))
    zip_folder(folder, Path("backup.zip"))
    s_dir, d_dir = check_json(folder)
    s_zip, d_zip = check_json(Path("backup.zip"))
    assert s_dir == s_zip == 1
    expected = [("W021", 3, 3), ("E101", 4, 17)]
    assert [(d["code"], d["line"], d["column"]) for d in d_dir] == expected
    assert [(d["code"], d["line"], d["column"]) for d in d_zip] == expected
    assert {d["path"] for d in d_dir} == {"src/KRC/R1/Program/demo.src"}
    assert {d["path"] for d in d_zip} == {"backup.zip/KRC/R1/Program/demo.src"}
    assert [d["message"] for d in d_dir] == [d["message"] for d in d_zip]
    assert list(own_tmp.iterdir()) == []


def test_text_output_shows_the_source_line_from_the_archive(tmp_path, own_tmp):
    archive = zip_folder(make_backup(tmp_path / "src"), tmp_path / "backup.zip")
    out: list[str] = []
    run_check([str(archive)], echo=out.append)
    text = "\n".join(out)
    assert f"{archive}/KRC/R1/Program/demo.src:4:17: error[E101]: 'undeclared' is not declared" in text
    assert " 4 |   i = counter + undeclared" in text
    assert text.rstrip().endswith("1 error, 1 warning in 3 files")


def write_zip(path: Path, entries) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for e in entries:
            if isinstance(e, zipfile.ZipInfo):
                zf.writestr(e, "target")
            else:
                zf.writestr(e[0], e[1])
    return path


def refused(archive: Path) -> str:
    status, diags = check_json(archive)
    assert status == 1
    assert [d["code"] for d in diags] == ["E004"]
    assert diags[0]["path"] == str(archive)
    return diags[0]["message"]


def test_zip_bomb_is_refused_by_its_ratio(tmp_path, own_tmp):
    bomb = write_zip(tmp_path / "bomb.zip", [("KRC/R1/Program/big.src", b"\0" * (8 * 1024 * 1024))])
    info = zipfile.ZipFile(bomb).getinfo("KRC/R1/Program/big.src")
    assert info.file_size / info.compress_size > limits.MAX_ARCHIVE_RATIO
    message = refused(bomb)
    assert "'KRC/R1/Program/big.src' expands" in message and "MAX_ARCHIVE_RATIO" in message
    assert list(own_tmp.iterdir()) == []


def test_ordinary_krl_compresses_far_below_the_ratio(tmp_path, own_tmp):
    # 200 repeated point lines, the most compressible real shape (about 67x in the corpus)
    text = "".join(f"DECL E6POS XP{i}={{X 1.0,Y 2.0,Z 3.0,A 0.0,B 0.0,C 0.0,S 2,T 10}}\n" for i in range(200))
    archive = write_zip(tmp_path / "ok.zip", [("KRC/R1/Program/p.dat", "DEFDAT p\n" + text + "ENDDAT\n")])
    status, diags = check_json(archive)
    assert "E004" not in [d["code"] for d in diags]


def test_too_many_entries(tmp_path, own_tmp, monkeypatch):
    monkeypatch.setattr(limits, "MAX_ARCHIVE_ENTRIES", 5)
    archive = write_zip(tmp_path / "many.zip", [(f"KRC/f{i}.src", "DEF f()\nEND\n") for i in range(6)])
    assert refused(archive) == "6 entries (limit MAX_ARCHIVE_ENTRIES = 5)"


def test_total_size(tmp_path, own_tmp, monkeypatch):
    monkeypatch.setattr(limits, "MAX_ARCHIVE_BYTES", 1000)
    archive = write_zip(tmp_path / "big.zip", [("a.src", "x" * 600), ("b.src", "y" * 600)])
    message = refused(archive)
    assert "'b.src'" in message and "MAX_ARCHIVE_BYTES" in message


@pytest.mark.parametrize("name, why", [
    ("../x.src", "leaves the archive folder ('..')"),
    ("KRC/../../x.src", "leaves the archive folder ('..')"),
    ("..\\x.src", "leaves the archive folder ('..')"),
    ("/abs.src", "has an absolute path"),
    ("C:/KRC/abs.src", "has an absolute path"),
])
def test_paths_leaving_the_folder(tmp_path, own_tmp, name, why):
    archive = write_zip(tmp_path / "evil.zip", [("KRC/ok.src", "DEF ok()\nEND\n"), (name, "DEF x()\nEND\n")])
    assert refused(archive) == f"entry '{name}' {why}"
    assert not (tmp_path / "x.src").exists() and not Path("/abs.src").exists()
    assert list(own_tmp.iterdir()) == []


def _special(name: str, kind: int) -> zipfile.ZipInfo:
    info = zipfile.ZipInfo(name)
    info.create_system = 3
    info.external_attr = (kind | 0o777) << 16
    return info


def test_symlink_entry(tmp_path, own_tmp):
    archive = write_zip(tmp_path / "link.zip", [_special("KRC/R1/Program/link.src", stat.S_IFLNK)])
    assert refused(archive) == "entry 'KRC/R1/Program/link.src' is a symbolic link"


def test_device_entry(tmp_path, own_tmp):
    archive = write_zip(tmp_path / "dev.zip", [_special("KRC/dev.src", stat.S_IFCHR)])
    assert refused(archive) == "entry 'KRC/dev.src' is a device or special file, not a file"


def test_not_a_zip(tmp_path, own_tmp):
    bad = tmp_path / "broken.zip"
    bad.write_bytes(b"PK\x03\x04 this is not an archive")
    assert refused(bad).startswith("not a readable zip archive")


def test_temp_folder_removed_when_extraction_fails_half_way(tmp_path, own_tmp):
    # the first entry is written before the duplicate is met
    archive = tmp_path / "dup.zip"
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("a.src", "DEF a()\nEND\n")
        with pytest.warns(UserWarning):
            zf.writestr("a.src", "DEF a()\nEND\n")
    with pytest.raises(ArchiveError, match="'a.src' appears twice"):
        with backup_source(archive):
            pass
    assert list(own_tmp.iterdir()) == []


def test_only_krl_files_are_extracted(tmp_path):
    archive = zip_folder(make_backup(tmp_path / "src"), tmp_path / "backup.zip")
    dest = tmp_path / "out"
    dest.mkdir()
    assert extract_backup(archive, dest) == 3
    assert sorted(p.relative_to(dest).as_posix() for p in dest.rglob("*") if p.is_file()) == [
        "KRC/R1/Program/demo.src", "KRC/R1/Program/done.src", "KRC/R1/System/$config.dat"]


def test_krl_run_runs_a_program_of_the_archive(tmp_path, own_tmp):
    archive = zip_folder(make_backup(tmp_path / "src"), tmp_path / "backup.zip")
    res = CliRunner().invoke(run, ["--workspace", str(archive), "done"])
    assert res.exit_code == 0, res.output
    assert f"run {archive}/KRC/R1/Program/done.src" in res.output
    assert "completed" in res.output
    assert list(own_tmp.iterdir()) == []
    res = CliRunner().invoke(run, ["--workspace", str(archive), "nope"])
    assert res.exit_code == 2 and f"no program nope in {archive}" in res.output


def test_krl_recover_reads_the_archive(tmp_path, own_tmp):
    archive = zip_folder(make_backup(tmp_path / "src"), tmp_path / "backup.zip")
    res = CliRunner().invoke(recover, [str(archive), "--out", str(tmp_path / "rep")])
    assert res.exit_code == 0, res.output
    assert res.output.startswith("3/3 files parse")
    summary = json.loads((tmp_path / "rep/summary.json").read_text())
    assert summary["corpus"] == str(archive) and summary["files"] == 3
    assert list(own_tmp.iterdir()) == []
    evil = write_zip(tmp_path / "evil.zip", [("../x.src", "DEF x()\nEND\n")])
    res = CliRunner().invoke(recover, [str(evil), "--out", str(tmp_path / "rep2")])
    assert res.exit_code == 2 and "entry '../x.src' leaves the archive folder" in res.output


def test_each_file_read_is_reported_to_the_progress_hook(tmp_path):
    folder = make_backup(tmp_path / "src")
    seen: list[str] = []
    with on_each_file(seen.append):
        workspaces_for(folder)
    assert sorted(Path(p).name for p in seen) == ["$config.dat", "demo.src", "done.src"]
    workspaces_for(folder)                      # outside the block: no more calls
    assert len(seen) == 3


def test_windows_separators_and_letter_case(tmp_path):
    """Archives made on Windows may use backslashes; KRL files in any letter case are kept."""
    archive = write_zip(tmp_path / "win.zip", [("KRC\\R1\\Program\\Demo.SRC", DONE),
                                               ("KRC\\R1\\System\\$CONFIG.DAT", CONFIG)])
    dest = tmp_path / "out"
    dest.mkdir()
    assert extract_backup(archive, dest) == 2
    assert sorted(p.relative_to(dest).as_posix() for p in dest.rglob("*") if p.is_file()) == [
        "KRC/R1/Program/Demo.SRC", "KRC/R1/System/$CONFIG.DAT"]


def test_depth_limit(tmp_path, own_tmp, monkeypatch):
    monkeypatch.setattr(limits, "MAX_ARCHIVE_DEPTH", 4)
    archive = write_zip(tmp_path / "deep.zip", [("a/b/c/d/e.src", "DEF e()\nEND\n")])
    assert refused(archive) == "entry 'a/b/c/d/e.src' has 5 path levels (limit MAX_ARCHIVE_DEPTH = 4)"
