"""Hostile corpus folders (issue 12, "a scan never hangs, never dies, never lies"): FIFOs and
sockets named like KRL files, undecodable file names, symbolic links, unreadable and very deep
folders. Each entry gets a classified row; nothing hangs, crashes or is read through a link."""

from __future__ import annotations

import csv
import hashlib
import json
import os
import socket
import subprocess
from pathlib import Path

import pytest

from krl import files as files_mod, limits
from krl.source import read_source
from recovery.report import summarise, write_report
from recovery.scan import scan
from tests.deep import deep_chain, remove_bottom_up
from tests.forkserver import krl_command
from app.check import run_check

REPO_ROOT = Path(__file__).resolve().parents[2]
VALID = "DEF t()\n  x = 1\nEND\n"


def rows_of(corpus: Path, **kw) -> dict:
    kw = {"jobs": 1, "use_cache": False, "progress": False, **kw}
    return {r.path: r for r in scan(corpus, "g", **kw)}


def make_fifo_and_socket(folder: Path) -> socket.socket:
    os.mkfifo(folder / "x.src")
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(folder / "s.dat"))
    return sock


def test_fifo_and_socket_get_rows_without_being_opened(tmp_path: Path) -> None:
    (tmp_path / "ok.src").write_text(VALID)
    sock = make_fifo_and_socket(tmp_path)
    try:
        rows = rows_of(tmp_path)
    finally:
        sock.close()
    assert {p: r.status for p, r in rows.items()} == {"ok.src": "ok", "x.src": "not_regular",
                                                     "s.dat": "not_regular"}
    assert "FIFO" in rows["x.src"].detail and "socket" in rows["s.dat"].detail
    # read_source, the one reader of every command, classifies them the same way
    assert read_source(tmp_path / "x.src").status == "not_regular"
    assert read_source(tmp_path / "s.dat").status == "not_regular"


@pytest.mark.parametrize("command", [["parse"], ["check"], ["run"], ["recover", "--no-cache"]])
def test_commands_on_a_fifo_end_with_a_clear_error(tmp_path: Path, command: list[str]) -> None:
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    sock = make_fifo_and_socket(corpus)
    try:
        target = corpus if command[0] == "recover" else corpus / "x.src"
        extra = ["--out", str(tmp_path / "out")] if command[0] == "recover" else []
        # `krl` as a fork of the worker's fork server (tests/forkserver.py): the command's own
        # app.main, descriptors, environment and exit status, without the project's import
        run = subprocess.run([*krl_command(), *command, str(target), *extra], capture_output=True, text=True,
                             cwd=REPO_ROOT, timeout=300, env={**os.environ, "KRL_CACHE_DIR": str(tmp_path / "c")})
    finally:
        sock.close()
    out = run.stdout + run.stderr
    assert "Traceback" not in out and "internal error" not in out
    if command[0] == "recover":
        assert run.returncode == 1
        with (tmp_path / "out" / "files.csv").open(newline="", encoding="utf-8") as fh:
            statuses = {r["path"]: r["status"] for r in csv.DictReader(fh)}
        assert statuses == {"x.src": "not_regular", "s.dat": "not_regular"}
    else:
        assert run.returncode == 1, out
        assert "not_regular" in out and "FIFO" in out


def test_undecodable_file_name_gets_a_readable_row(tmp_path: Path) -> None:
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    name = os.fsdecode(b"Pr\xfcfung.src")          # a Latin-1 name on a UTF-8 file system
    (corpus / name).write_bytes(VALID.encode())
    (corpus / os.fsdecode(b"b\xe4d.src")).write_bytes(b"DEF t()\n  IF x THEN\nEND\n")
    results = scan(corpus, "g", jobs=1, use_cache=False, progress=False)
    assert sorted(r.path for r in results) == ["Pr\\xfcfung.src", "b\\xe4d.src"]
    out = tmp_path / "out"
    write_report(out, summarise(results, "g", str(corpus), 0.0), results)
    with (out / "files.csv").open(newline="", encoding="utf-8") as fh:
        rows = {r["path"]: r for r in csv.DictReader(fh)}
    assert rows["Pr\\xfcfung.src"]["status"] == "ok"
    assert rows["b\\xe4d.src"]["status"] == "syntax_error"
    json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert "b\\xe4d.src" in (out / "report.html").read_text(encoding="utf-8")


def test_symlinks_are_rows_and_never_followed(tmp_path: Path) -> None:
    outside = tmp_path / "outside"
    outside.mkdir()
    secret = "SECRET_TOKEN_4711"
    (outside / "secret.src").write_text(f"DEF s()\n  ; {secret}\n  IF x THEN\nEND\n")
    corpus = tmp_path / "corpus"
    (corpus / "R1").mkdir(parents=True)
    (corpus / "R1" / "a.src").write_text(VALID)
    (corpus / "R1" / "link.src").symlink_to(outside / "secret.src")
    (corpus / "linked_dir").symlink_to(outside, target_is_directory=True)
    (corpus / "loop").symlink_to(corpus, target_is_directory=True)
    rows = rows_of(corpus)
    assert {p: r.status for p, r in rows.items()} == {
        "R1/a.src": "ok", "R1/link.src": "symlink", "linked_dir": "symlink", "loop": "symlink"}
    out = tmp_path / "out"
    results = list(rows.values())
    write_report(out, summarise(results, "g", str(corpus), 0.0), results)
    for f in out.iterdir():
        assert secret not in f.read_bytes().decode("utf-8", "replace"), f.name
    # krl check reports the link and never quotes the linked file

    lines: list[str] = []
    run_check([str(corpus)], echo=lines.append)
    text = "\n".join(lines)
    assert secret not in text
    assert "W002" in text and "symbolic link" in text


def test_unreadable_folder_is_reported(tmp_path: Path, monkeypatch) -> None:
    (tmp_path / "ok").mkdir()
    (tmp_path / "ok" / "a.src").write_text(VALID)
    (tmp_path / "locked").mkdir()
    (tmp_path / "locked" / "b.src").write_text(VALID)
    real = os.scandir

    def scandir(path):   # chmod 000 does not stop root: simulate the refusal
        if Path(path).name == "locked":
            raise PermissionError(13, "Permission denied", str(path))
        return real(path)

    monkeypatch.setattr(files_mod.os, "scandir", scandir)
    rows = rows_of(tmp_path)
    assert {p: r.status for p, r in rows.items()} == {"ok/a.src": "ok", "locked": "unreadable_folder"}
    assert "Permission denied" in rows["locked"].detail

    lines: list[str] = []
    run_check([str(tmp_path)], echo=lines.append)
    assert any("W002" in ln and "locked" in ln and "Permission denied" in ln for ln in lines), lines


def test_thousand_levels_deep_tree_does_not_crash_recover_or_check(tmp_path: Path) -> None:
    MAX_FOLDER_DEPTH = getattr(limits, "MAX_FOLDER_DEPTH", 100)  # noqa: N806
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    (corpus / "top.src").write_text("DEF top()\nEND\n")
    folders: list[Path] = []
    deep_chain(corpus, 1000, folders)
    try:
        (folders[MAX_FOLDER_DEPTH - 2] / "shallow.src").write_text("DEF shallow()\nEND\n")
        (folders[-1] / "bottom.src").write_text("DEF bottom()\n  IF\nEND\n")
        rows = rows_of(corpus)
        deep_rel = "/".join(["d"] * (MAX_FOLDER_DEPTH + 1))
        assert {p: r.status for p, r in rows.items()} == {
            "top.src": "ok", "/".join(["d"] * (MAX_FOLDER_DEPTH - 1)) + "/shallow.src": "ok",
            deep_rel: "too_deep_folder"}

        lines: list[str] = []
        assert run_check([str(corpus)], echo=lines.append) == 0, lines
        assert any("W002" in ln and "levels deep" in ln for ln in lines)
        assert lines[-1] == "1 warning in 2 files"
    finally:
        remove_bottom_up(folders)
