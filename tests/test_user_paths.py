"""The user's paths (issue 46): every path shown or sent — `krl run`'s summary, the trace, the
debugger's stack frames and breakpoints, the pendant's paths — is the path the user or the editor
gave, links kept, not the path resolved through a link; identity and the workspace's containment
still compare resolved paths (docs/security.md: a link out of the workspace stays refused).

The path-sensitive cases run here with the corpus behind a symbolic link made for the test
(``tmp/shared/krl-corpus`` -> ``../shared/krl-corpus``), as on a clone whose ``../shared`` is a
link. Expected paths are the link's spelling joined with the files' places in the backup, read
off the backups by hand (the comments say where)."""

from __future__ import annotations

import json
import os
import subprocess
import threading
import time
from pathlib import Path

import pytest

from interp.debug.client import DapClient
from krl.files import child, same_file, spelled, spelled_within
from pendant.engine import Engine
from pendant.security import PathRefused, inside
from pendant.view import module_view, programs
from tests import forkserver
from tests.conftest import REPO_ROOT, SHARED_CORPUS
from tests.forkserver import krl_command

MILLING = "HugoDanielson__ChinaMilling/KRC"
BLOCK = "R1/Program/KukaMiling/Subprogs/BaseCalib/BlockCalibration.src"
GET3 = "R1/Program/KukaMiling/Subprogs/BaseCalib/Get3Basepoints.src"
CELL = REPO_ROOT / "corpus" / "cells" / "HugoDanielson__ChinaMilling.yaml"


@pytest.fixture
def linked(shared_corpus, tmp_path) -> Path:
    """The corpus behind a link: ``tmp/shared/krl-corpus`` -> the real corpus."""
    (tmp_path / "shared").mkdir()
    link = tmp_path / "shared" / "krl-corpus"
    link.symlink_to(os.path.realpath(shared_corpus), target_is_directory=True)
    return link


def test_spelled_keeps_links_and_the_working_folder(tmp_path, monkeypatch):
    real = tmp_path / "real" / "sub"
    real.mkdir(parents=True)
    (tmp_path / "link").symlink_to(tmp_path / "real")
    assert spelled(tmp_path / "link" / "sub" / "a.src") == tmp_path / "link" / "sub" / "a.src"
    assert spelled(tmp_path / "link" / "./sub" / "a.src") == tmp_path / "link" / "sub" / "a.src"
    # ".." after a link: the parent of the link's target, the folder the system opens
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "real" / "up").symlink_to(tmp_path / "elsewhere" / ".")
    (tmp_path / "elsewhere" / "x").mkdir()
    assert spelled(tmp_path / "link" / "sub" / ".." / "a.src") == tmp_path / "link" / "a.src"
    assert same_file(spelled(tmp_path / "link" / "up" / "x" / ".."), tmp_path / "elsewhere")
    assert spelled(tmp_path / "real" / "up" / ".." / "b") == Path(os.path.realpath(tmp_path)) / "b"   # not real/b
    # a relative path against the working folder as the shell names it ($PWD, links kept)
    monkeypatch.chdir(tmp_path / "link" / "sub")
    monkeypatch.setenv("PWD", str(tmp_path / "link" / "sub"))
    assert spelled("a.src") == tmp_path / "link" / "sub" / "a.src"
    monkeypatch.setenv("PWD", str(tmp_path))                  # stale: not the working folder
    assert spelled("a.src") == Path(os.getcwd()) / "a.src"
    # a program named through another spelling than its workspace: the workspace's wins
    assert spelled_within(tmp_path / "real" / "sub" / "a.src", tmp_path / "link") == tmp_path / "link" / "sub" / "a.src"


def test_krl_run_shows_and_traces_the_users_paths(linked, tmp_path):
    """BlockCalibration.src (ChinaMilling) with its cell stops at Get3Basepoints.src:21
    (tests/interp/test_realprograms.py): the summary's program, workspace, submit, error place and
    machine data, and every file of the trace, are spelled through the link."""
    root = linked / MILLING
    trace = tmp_path / "run.jsonl"
    # `krl` as a fork of the worker's fork server (tests/forkserver.py): app.main in a process of
    # its own with this environment and folder, without the project's import at its start
    run = subprocess.run([*krl_command(), "run", str(root / BLOCK), "--inputs", str(CELL),
                          "--max-sim-time", "30", "--trace", str(trace)], cwd=REPO_ROOT, capture_output=True,
                         text=True, timeout=900, check=False)
    out = run.stdout
    assert run.returncode == 1, out + run.stderr
    real = os.path.realpath(linked)
    assert real not in out, out
    assert f"  workspace  {root} (KRC backup found above the program)" in out
    assert f"  submit     {root / 'R1/System/sps.sub'} " in out
    assert f"{root / GET3}:21: software limit switch -A5" in out
    assert f"({root / 'R1/Mada/$machine.dat'})" in out
    files = {e["file"] for e in map(json.loads, trace.read_text().splitlines()) if e.get("file")}
    assert str(root / BLOCK) in files and str(root / GET3) in files
    assert all(f.startswith(str(root)) for f in files), sorted(files)[:5]


def test_debugger_frames_and_breakpoints_keep_the_editors_path(linked):
    """`krl debug` launched on the program named through the link (as an editor that opened the
    folder behind the link names it): a breakpoint set in Get3Basepoints.src through the link
    is hit at line 21 (its LIN), and the frames carry the link's spelling."""
    root = linked / MILLING
    main, get3 = root / BLOCK, root / GET3
    with DapClient(timeout=900, python=str(forkserver.shared().launcher)) as c:     # a fork, as tests/debug's
        st = c.start(main, breakpoints={get3: [21]}, inputs=str(CELL))
        assert st["body"]["reason"] == "breakpoint"
        frames = c.stack()
        assert (frames[0]["line"], frames[0]["source"]["path"]) == (21, str(get3))
        assert str(main) in [f["source"]["path"] for f in frames]
        assert all(f["source"]["path"].startswith(str(root)) for f in frames if f.get("source")), frames


def test_the_pendant_keeps_the_users_paths_and_refuses_links_out(linked, tmp_path):
    """The pendant on the backup named through the link: the programs, a module's path, the
    selected program's pointers are spelled through the link; a path named by its resolved
    spelling is shown in the link's; a link inside the workspace that leaves it is refused."""
    root = linked / MILLING
    assert "R1/Program/KukaMiling/Main.src" in programs(root)
    p = inside(root, BLOCK, suffixes=(".src",))
    assert p == root / BLOCK
    assert inside(root, os.path.realpath(root / BLOCK)) == root / BLOCK
    assert module_view(p, root)["path"] == str(root / BLOCK)
    # a workspace of our own behind a link, with a link inside it that leaves it
    outside = tmp_path / "outside.src"
    outside.write_text("DEF outside()\nEND\n")
    ws = tmp_path / "ws"
    ws.mkdir()
    (ws / "escape.src").symlink_to(outside)
    (tmp_path / "wslink").symlink_to(ws)
    with pytest.raises(PathRefused, match="outside the workspace"):
        inside(tmp_path / "wslink", "escape.src")
    with pytest.raises(PathRefused, match="outside the workspace"):
        inside(tmp_path / "wslink", str(outside))
    # the run under the pendant's engine: its pointers name the files through the link
    ended = threading.Event()
    eng = Engine(lambda name, body: ended.set() if name == "terminated" else None, realtime=False)
    try:
        eng.select(str(p), workspace=str(root), inputs=str(CELL), mode="AUT", run_mode="GO", trace=None)
        ptr = eng.do(lambda core: core.pointers())
        assert ptr["advanceRun"]["path"] == str(root / BLOCK)
        eng.do(lambda core: core.resume())
        end = time.monotonic() + 600
        while eng.do(lambda core: core.state) != "stopped" or eng.do(lambda core: core.stop_error) is None:
            assert time.monotonic() < end and not ended.is_set(), "no stop at the error"
            time.sleep(0.05)
        rows = eng.system.rows()
        assert [(r["path"], r["line"]) for r in rows] == [(str(root / GET3), 21)]
    finally:
        eng.cancel()


def test_child_finds_any_letter_case_and_never_a_link(tmp_path):
    """krl.files.child: KUKA's (Windows') file system ignores case, so ``R1/SYSTEM`` is the
    ``system`` folder; a symbolic link is never returned, as the folder walk never follows one."""
    (tmp_path / "SYSTEM").mkdir()
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "Mada").symlink_to(tmp_path / "elsewhere")
    assert child(tmp_path, "system") == tmp_path / "SYSTEM"
    assert child(tmp_path, "mada") is None
    assert child(tmp_path, "steu") is None
    assert child(tmp_path / "missing", "system") is None
