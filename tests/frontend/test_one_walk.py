"""`krl check FOLDER` walks the folder once (krl/files.py `walk`, the one walker) and loads
what that walk found: backups, the entries of each backup, the files outside the backups and
the progress bar's count (krl/project.py `folder_groups`).

The expected workspaces and diagnostics are derived from the fixtures built here: which
files each workspace holds (reference 2.7: a backup is one workspace; the files outside are one
workspace per top-level folder) and the one error planted in some files (E201: BOOL assigned to
INT, at the value's column)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import krl.files
from krl.limits import MAX_FOLDER_DEPTH
from app import check as cli
from app.check import run_check
from tests.deep import deep_chain, remove_bottom_up

CONFIG = "DEFDAT $CONFIG\n  INT gCount = 0\nENDDAT\n"
CLEAN = "DEF {name}()\n  gCount = 1\nEND\n"
BAD = "DEF {name}()\n  INT i\n  i = TRUE\nEND\n"          # E201 at 3:7


def backup(root: Path, r1: str, program: str, text: str) -> Path:
    (root / "KRC" / r1 / "System").mkdir(parents=True)
    (root / "KRC" / r1 / "Program").mkdir(parents=True)
    (root / "KRC" / r1 / "System" / "$config.dat").write_text(CONFIG)
    (root / "KRC" / r1 / "Program" / f"{program}.src").write_text(text.format(name=program))
    return root / "KRC"


def fixture(tmp: Path) -> dict:
    """Two backups and loose files; {workspace root: (files, [(file, line, col, code)])}."""
    a = backup(tmp / "a", "R1", "job", BAD)
    b = backup(tmp / "b", "r1", "cell", CLEAN)
    (tmp / "loose").mkdir()
    (tmp / "loose" / "x.src").write_text(BAD.format(name="x"))
    (tmp / "loose" / "y.src").write_text("DEF y()\nEND\n")
    (tmp / "top.src").write_text("DEF top()\nEND\n")
    return {
        str(a): (2, [(str(a / "R1" / "Program" / "job.src"), 3, 7, "E201")]),
        str(b): (2, []),
        str(tmp): (1, []),
        str(tmp / "loose"): (2, [(str(tmp / "loose" / "x.src"), 3, 7, "E201")]),
    }


def counting(monkeypatch) -> list:
    calls: list = []
    real = krl.files.walk

    def walk(root, *args, **kw):
        calls.append(Path(root))
        return real(root, *args, **kw)
    monkeypatch.setattr(krl.files, "walk", walk)
    return calls


def checked(folder: Path) -> tuple[int, dict]:
    out: list[str] = []
    status = run_check([str(folder)], fmt="json", echo=out.append)
    got = {}
    for line in out:
        ws = json.loads(line)
        got[ws["workspace"]] = (ws["files"], [(d["path"], d["line"], d["column"], d["code"])
                                              for d in ws["diagnostics"]])
    return status, got


@pytest.mark.parametrize("progress", [False, True], ids=["piped", "progress_bar"])
def test_check_of_a_folder_walks_it_once(tmp_path, monkeypatch, progress):
    want = fixture(tmp_path)
    monkeypatch.setattr(cli, "_progress_shown", lambda: progress)
    calls = counting(monkeypatch)
    status, got = checked(tmp_path)
    assert calls == [tmp_path]
    assert got == want
    assert status == 1


def test_workspaces_come_in_the_old_order(tmp_path):
    want = fixture(tmp_path)
    out: list[str] = []
    run_check([str(tmp_path)], fmt="json", echo=out.append)
    # backups first (sorted), then the folders outside them (sorted by path)
    assert [json.loads(line)["workspace"] for line in out] == list(want)


def test_folder_without_backups_is_walked_once(tmp_path, monkeypatch):
    (tmp_path / "s").mkdir()
    (tmp_path / "s" / "p.src").write_text(BAD.format(name="p"))
    (tmp_path / "q.src").write_text("DEF q()\nEND\n")
    calls = counting(monkeypatch)
    status, got = checked(tmp_path)
    assert calls == [tmp_path]
    assert got == {str(tmp_path): (2, [(str(tmp_path / "s" / "p.src"), 3, 7, "E201")])}
    assert status == 1


def test_each_root_keeps_its_own_depth_limit(tmp_path):
    # A backup 3 levels down (x/y/KRC): the depth limit counts from the backup, as when the
    # backup was walked on its own; the loose folders count from the checked folder.
    top = tmp_path / "top"
    krc = backup(top / "x" / "y", "R1", "job", CLEAN)
    program = krc / "R1" / "Program"
    (program / "e").mkdir()
    (top / "loose").mkdir()
    made: list[Path] = []
    try:
        inside = deep_chain(program, MAX_FOLDER_DEPTH - 2, made)        # 100 levels below KRC
        (inside / "deep.src").write_text("DEF deep()\nEND\n")
        past = deep_chain(program / "e", MAX_FOLDER_DEPTH - 2, made)    # 101 levels below KRC
        (past / "deeper.src").write_text("DEF deeper()\nEND\n")
        loose = deep_chain(top / "loose", MAX_FOLDER_DEPTH, made)      # 101 levels below top
        (loose / "far.src").write_text("DEF far()\nEND\n")
        _status, got = checked(top)
        assert got == {
            # $config.dat, job.src and deep.src (103 levels below top, 100 below KRC)
            str(krc): (3, [(str(past), 1, 1, "W002")]),
            str(top / "loose"): (0, [(str(loose), 1, 1, "W002")]),
        }
        out: list[str] = []
        run_check([str(top)], fmt="json", echo=out.append)
        too_deep = f"not read: folder more than {MAX_FOLDER_DEPTH} levels deep (not entered)"
        assert {d["message"] for line in out for d in json.loads(line)["diagnostics"]} == {too_deep}
    finally:
        remove_bottom_up(made)
