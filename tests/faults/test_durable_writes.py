"""Issue 74, cases 1-4: the durable write of a user's file (krl/durable.py) under real faults.

Each test rebuilds a case of the issue's probe: a real ``krl fmt`` process stopped by a real
signal inside its write (tests/faults/slow_fsync.py slows the first fsync, as the probe did),
a file its owner made read-only, another user's file formatted by root, an editor's save
landing between the "changed?" check and the rename. Expected values are the guarantees of
docs/security.md "Faults", not the program's output: the user's bytes exactly as before (or
exactly as the editor saved them), nothing beside them, the file's owner, group and mode.
"""

from __future__ import annotations

import fcntl
import os
import signal
import shutil
import stat
import tempfile
import time
from pathlib import Path

import pytest

from krl import durable
from krl.fmt.cli import run_fmt
from pendant.touchup import touch_up
from tests.faults.conftest import MAY_SKIP_MOUNT, REPO, start_in_write

# lower-case keywords and no indentation: `krl fmt` rewrites it (keywords upper case, the
# body indented 3 spaces: docs/fmt.md defaults)
UGLY = b"def main()\nptp {a1 0}\nend\n"
FORMATTED = b"DEF main()\n   PTP {a1 0}\nEND\n"
# a data list with one point, for the pendant's touch-up
DEMO_DAT = b"DEFDAT demo\nDECL E6AXIS XP1={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 0.0,A6 0.0}\nENDDAT\n"


def as_root(test):
    """The marks of a test that gives a file to another user or acts as one: only root can; the
    suite runs as root in CI and on the project's machine."""
    test = pytest.mark.may_skip("the suite runs as root in CI and on the project's machine")(test)
    return pytest.mark.skipif(os.geteuid() != 0, reason="only root can give a file to another user or act "
                                                         "as one")(test)


def _fmt(*paths) -> tuple[int, list[str]]:
    lines: list[str] = []
    status = run_fmt([str(p) for p in paths], out=lines.append, err=lines.append)
    return status, lines


def test_the_formatted_form_is_what_these_tests_expect(tmp_path: Path) -> None:
    f = tmp_path / "main.src"
    f.write_bytes(UGLY)
    assert _fmt(f)[0] == 0
    assert f.read_bytes() == FORMATTED


@pytest.mark.parametrize("sig", [signal.SIGTERM, pytest.param(signal.SIGINT, marks=pytest.mark.slow)])
def test_a_signal_inside_the_write_of_krl_fmt_leaves_the_file_whole_and_nothing_beside_it(tmp_path, sig):
    # case 1 (SIGTERM, what `timeout` and a CI cancel send) and case 5 (the same end for every
    # signal): exit 128 + signal, "interrupted", the file as it was, no temporary file (SIGINT
    # in a separate process is nightly's: the default suite sends it in-process,
    # tests/faults/test_signals_and_exit_codes.py)
    work = tmp_path / "work"
    work.mkdir()
    f = work / "bas.src"
    f.write_bytes(UGLY)
    proc = start_in_write(["fmt", str(f)], tmp_path / "in-write", cwd=REPO)
    proc.send_signal(sig)
    _out, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + sig, err
    assert "interrupted" in err and "Traceback" not in err
    assert f.read_bytes() == UGLY
    assert sorted(p.name for p in work.iterdir()) == ["bas.src"]


def test_a_sigkill_inside_the_write_leaves_a_temporary_that_the_next_run_removes(tmp_path: Path) -> None:
    # case 1: SIGKILL cannot be caught; the killed run's temporary is removed by the next run
    work = tmp_path / "work"
    work.mkdir()
    f = work / "bas.src"
    f.write_bytes(UGLY)
    proc = start_in_write(["fmt", str(f)], tmp_path / "in-write", cwd=REPO)
    proc.kill()
    proc.communicate(timeout=60)
    assert f.read_bytes() == UGLY
    left = [p.name for p in work.iterdir() if p.name != "bas.src"]
    assert len(left) == 1 and left[0].startswith(".bas.src.") and left[0].endswith(".tmp")
    assert _fmt(f)[0] == 0
    assert f.read_bytes() == FORMATTED
    assert sorted(p.name for p in work.iterdir()) == ["bas.src"]


def test_a_live_writers_temporary_is_never_removed(tmp_path: Path) -> None:
    # the other side of the sweep: a temporary whose lock a live writer holds stays (flock
    # locks belong to an open file: one held here conflicts with the sweep's own open)
    tmp = tmp_path / ".bas.src.krl-live0001.tmp"
    tmp.write_bytes(b"half")
    fd = os.open(tmp, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        assert durable.sweep(tmp_path, again=True) == []
        assert tmp.exists()
    finally:
        os.close(fd)            # the writer ends (as a killed process's locks end)
    assert durable.sweep(tmp_path, again=True) == [tmp.name]
    assert not tmp.exists()


def _aged(path: Path, seconds: float) -> Path:
    when = time.time() - seconds
    for p in [*path.rglob("*"), path]:
        os.utime(p, (when, when), follow_symlinks=False)
    return path


def test_report_folders_older_versions_left_are_removed_once_untouched_for_five_minutes(tmp_path: Path) -> None:
    # issue 74: a `krl recover` before krl/durable.py, killed, left `.OUT.new-XXXXXXXX` (mkdtemp's
    # 8 characters, no lock): the next report folder opened beside OUT removes it once nothing
    # in it changed for LEGACY_STALE_S (300 s); a younger one may be an older version still
    # writing, another report's is not ours, `.OUT.old-*` may be the only copy of the last report
    def left(name: str, age: float) -> Path:
        (tmp_path / name).mkdir()
        (tmp_path / name / "summary.json").write_text("{}")
        return _aged(tmp_path / name, age)

    left(".recovery.new-ab_12cd3", 301)
    left(".recovery.new-young123", 299)
    left(".growth.new-ab_12cd3", 3600)
    left(".recovery.old-ab_12cd3", 3600)
    inner = left(".recovery.new-inner123", 3600)
    (inner / "fresh.csv").write_text("a\n")          # something inside changed just now
    folder = durable.TempFolder(tmp_path / "recovery")
    folder.close(remove=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == [".growth.new-ab_12cd3", ".recovery.new-inner123",
                                                         ".recovery.new-young123", ".recovery.old-ab_12cd3"]


def test_krl_fmt_refuses_a_file_its_owner_made_read_only(tmp_path: Path) -> None:
    # case 2: mode 0444 is the owner's "do not touch", root included (black, gofmt refuse)
    f = tmp_path / "bas.src"
    f.write_bytes(UGLY)
    f.chmod(0o444)
    status, lines = _fmt(f)
    assert status == 2
    assert any("not written" in line and "read-only" in line for line in lines), lines
    assert any("not written: read-only file (mode 0444)" in line for line in lines), lines    # docs/security.md
    assert f.read_bytes() == UGLY
    assert stat.S_IMODE(f.stat().st_mode) == 0o444
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bas.src"]


@MAY_SKIP_MOUNT
def test_krl_fmt_refuses_a_file_on_a_read_only_file_system(read_only_fs) -> None:
    folder = read_only_fs({"bas.src": UGLY})
    status, lines = _fmt(folder / "bas.src")
    assert status == 2
    assert any("read-only file system" in line for line in lines), lines
    assert (folder / "bas.src").read_bytes() == UGLY


@as_root
def test_krl_fmt_as_root_keeps_another_users_owner_group_and_mode(tmp_path: Path) -> None:
    # case 3: a new inode must get the old one's owner, group and mode
    f = tmp_path / "bas.src"
    f.write_bytes(UGLY)
    os.chown(f, 4242, 4343)
    f.chmod(0o640)
    assert _fmt(f)[0] == 0
    st = f.stat()
    assert (st.st_uid, st.st_gid, stat.S_IMODE(st.st_mode)) == (4242, 4343, 0o640)
    assert f.read_bytes() == FORMATTED


@as_root
def test_the_pendants_touch_up_keeps_another_users_owner(tmp_path: Path) -> None:
    # case 3: "the pendant's touch-up writes through the same function"
    dat = tmp_path / "demo.dat"
    dat.write_bytes(DEMO_DAT)
    os.chown(dat, 4242, 4343)
    dat.chmod(0o664)
    touch_up(dat, "XP1", {}, [10.0, -80.0, 85.0, 0.0, 5.0, 0.0])
    st = dat.stat()
    assert (st.st_uid, st.st_gid, stat.S_IMODE(st.st_mode)) == (4242, 4343, 0o664)
    assert b"XP1={A1 10,A2 -80,A3 85,A4 0,A5 5,A6 0}" in dat.read_bytes()


def _as_user(uid: int, fn) -> int:
    """Run `fn()` in a forked child that became user `uid`; its exit status (fn's int)."""
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            os.setgid(uid)
            os.setuid(uid)
            code = fn()
        finally:
            os._exit(code)
    return os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])


def _refused_with(path: Path, words: str) -> int:
    """0 when the durable write refuses `path` with `words`, and krl fmt so does too with exit 2
    (docs/security.md "Faults"); 2 when written, 3 when refused otherwise."""
    try:
        durable.write_bytes(path, FORMATTED)
    except durable.WriteRefused as exc:
        if words not in str(exc):
            return 3
    else:
        return 2
    status, lines = _fmt(path)
    return 0 if status == 2 and any(f"not written: {words}" in line for line in lines) else 3


@pytest.fixture
def shared_folder():
    folder = Path(tempfile.mkdtemp(prefix="krl-owner-"))      # in /tmp: reachable by any user
    yield folder
    shutil.rmtree(folder)


@as_root
def test_a_user_who_cannot_keep_the_owner_is_refused(shared_folder: Path) -> None:
    # a shared folder, a file of user 4343 that user 4242 may write: a rename would hand the
    # file to 4242, so the durable write refuses (the owner is what `ls -l` promised)
    shared_folder.chmod(0o777)
    f = shared_folder / "bas.src"
    f.write_bytes(UGLY)
    os.chown(f, 4343, 4343)
    f.chmod(0o666)
    assert _as_user(4242, lambda: _refused_with(f, "owned by user 4343")) == 0
    assert f.read_bytes() == UGLY and f.stat().st_uid == 4343
    assert sorted(p.name for p in shared_folder.iterdir()) == ["bas.src"]


@as_root
def test_a_file_in_a_folder_its_user_cannot_write_is_refused_clearly(shared_folder: Path) -> None:
    f = shared_folder / "bas.src"
    f.write_bytes(UGLY)
    os.chown(f, 4242, 4242)
    os.chown(shared_folder, 4242, 4242)
    shared_folder.chmod(0o555)
    assert _as_user(4242, lambda: _refused_with(f, "its folder cannot be written (Permission denied)")) == 0
    assert f.read_bytes() == UGLY
    shared_folder.chmod(0o755)


def _editor_saves_at_first_fsync(monkeypatch, path: Path, text: bytes, in_place: bool) -> None:
    """The probe's case 4: fsync slowed, an editor's save lands meanwhile (after fmt's re-read,
    before its rename). VS Code and vim save by a new file renamed over (`in_place` False) or
    by writing the file itself (True)."""
    real = os.fsync
    done = []

    def fsync(fd):
        real(fd)
        if not done:
            done.append(1)
            if in_place:
                path.write_bytes(text)
            else:
                side = path.with_name("editor.swp")
                side.write_bytes(text)
                os.replace(side, path)

    monkeypatch.setattr(os, "fsync", fsync)


@pytest.mark.parametrize("in_place, exchange", [(False, True), (True, True), (False, False)],
                         ids=["saved-by-rename", "saved-in-place", "saved-by-rename-no-exchange"])
def test_an_editors_save_during_krl_fmts_write_is_never_lost(tmp_path, monkeypatch, in_place, exchange) -> None:
    # case 4: before, the save was lost silently and fmt exited 0. Without RENAME_EXCHANGE
    # (another system, a file system without it) the comparison is made before a plain rename.
    f = tmp_path / "bas.src"
    f.write_bytes(UGLY)
    edited = b"def main()\nptp {a1 45}\nend\n"
    if not exchange:
        monkeypatch.setattr(durable, "exchange", lambda a, b: False)
    _editor_saves_at_first_fsync(monkeypatch, f, edited, in_place)
    status, lines = _fmt(f)
    monkeypatch.undo()
    assert f.read_bytes() == edited
    assert status == 2
    assert any("changed while it was formatted" in line for line in lines), lines
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bas.src"]


def test_an_editors_save_during_the_pendants_touch_up_is_never_lost(tmp_path, monkeypatch) -> None:
    # docs/security.md "the touch-up likewise": the operator's touch-up never overwrites a save
    # made meanwhile, and the message speaks of a save, not of formatting (krl fmt's words)
    dat = tmp_path / "demo.dat"
    dat.write_bytes(DEMO_DAT)
    edited = DEMO_DAT.replace(b"A1 0.0", b"A1 45.0")
    _editor_saves_at_first_fsync(monkeypatch, dat, edited, in_place=False)
    with pytest.raises(durable.ChangedMeanwhile) as caught:
        touch_up(dat, "XP1", {}, [10.0, -80.0, 85.0, 0.0, 5.0, 0.0])
    monkeypatch.undo()
    assert dat.read_bytes() == edited
    assert "another program saved the file" in str(caught.value) and "formatted" not in str(caught.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo.dat"]


def _fsynced(monkeypatch) -> list[str]:
    """The paths fsync is called on from now (what each fd names, /proc/self/fd)."""
    real, seen = os.fsync, []

    def fsync(fd):
        seen.append(os.readlink(f"/proc/self/fd/{fd}"))
        real(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    return seen


def test_a_durable_write_fsyncs_the_file_then_its_folder(tmp_path: Path, monkeypatch) -> None:
    # case 11: "no folder is fsynced after a rename"
    seen = _fsynced(monkeypatch)
    durable.write_bytes(tmp_path / "out.txt", b"new")
    assert len(seen) == 2
    assert Path(seen[0]).parent == tmp_path and Path(seen[0]).name.startswith(".out.txt.krl-")
    assert seen[1] == str(tmp_path)


def test_every_file_of_a_report_folder_is_fsynced_before_it_is_put_in_place(tmp_path: Path, monkeypatch) -> None:
    # case 11: "the report's files are never fsynced"
    folder = durable.TempFolder(tmp_path / "report")
    for name in ("summary.json", "report.md"):
        (folder.path / name).write_text(name)
    seen = _fsynced(monkeypatch)
    durable.replace_folder(folder.path, tmp_path / "report")
    folder.close()
    names = [Path(p).name for p in seen]
    assert sorted(names[:2]) == ["report.md", "summary.json"]          # the files, then their folder
    assert Path(seen[2]).name.startswith(".report.new-krl-") and seen[-1] == str(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]


def test_a_rewritten_report_keeps_the_mode_its_user_gave_it(tmp_path: Path) -> None:
    # docs/security.md "Faults": the temporary file gets the target's mode (a private report
    # stays private); a new file gets rw-r--r--
    report = tmp_path / "report.md"
    report.write_text("old")
    report.chmod(0o600)
    durable.write_text(report, "new")
    assert report.read_text() == "new" and stat.S_IMODE(report.stat().st_mode) == 0o600
    durable.write_text(tmp_path / "new.md", "new")
    assert stat.S_IMODE((tmp_path / "new.md").stat().st_mode) == 0o644


def test_a_write_through_a_symbolic_link_keeps_the_link_and_writes_its_target(tmp_path):
    """A report or data list reached through a link (``-o out/report.html`` where report.html
    links to a shared folder): the target gets the new bytes and the link stays a link, as
    ``Path.write_text`` did before the durable write."""
    target = tmp_path / "shared" / "report.html"
    target.parent.mkdir()
    target.write_text("old", encoding="utf-8")
    link = tmp_path / "report.html"
    link.symlink_to(target)
    durable.write_text(link, "new")
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text(encoding="utf-8") == "new"
