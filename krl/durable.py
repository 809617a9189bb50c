"""Durable writes: the one way a command replaces a user's file or writes a report (issue 74).

Every file a command writes for the user (``krl fmt``'s formatted file, the pendant's touch-up
of a data list, ``krl construct new``'s row of grammar/CHANGES.md, the reports of
``krl recover``, ``krl growth``, ``krl check --report``, ``krl audit``, ``krl conformance`` and
the nightly's index, the ``-o`` files of ``krl diff``/``graph``/``report``/``plot``/``trace
show``/``robot export``/``cell init``, the ``--json`` of the variants and real-programs sweeps)
goes through :func:`write_bytes` (one file; :func:`write_text`, :func:`write_with` for a
streaming writer) or :class:`TempFolder` + :func:`replace_folder` (a report folder). The discipline, as SQLite's and PostgreSQL's crash
rules have it:

1. the new content goes into a temporary file in the target's own folder
   (``.NAME.krl-XXXXXXXX.tmp``), locked (``flock``) while this process lives;
2. the temporary file gets the target's owner, group and mode (a new file: 0644), then is
   flushed and ``fsync``\\ ed;
3. it is put in place by one rename (with an expected old content: by an atomic *exchange*,
   Linux ``renameat2(RENAME_EXCHANGE)``, then the old content is compared; see below);
4. the folder is ``fsync``\\ ed, so the rename itself survives a power loss.

A reader, a crash or a signal never sees half a file: the target holds the old content or
the new one. A signal (SIGINT; SIGTERM under the ``krl`` command, krl/signals.py) removes the
temporary file on the way out; SIGKILL
cannot, so every write first removes the *stale* temporaries of its folder (:func:`sweep`):
those of this naming scheme whose lock no process holds (a lock dies with its process, even
one killed by SIGKILL). An empty temporary younger than :data:`STALE_GRACE_S` is left alone
(a writer between creating and locking it). A report folder opened beside ``OUT`` also removes
the unlocked ``.OUT.new-XXXXXXXX`` folders older versions left, once nothing in them changed for
:data:`LEGACY_STALE_S` (:func:`sweep_legacy`).

Refusals (:class:`WriteRefused`, an OSError; nothing is written): a target whose mode has no
write bit or that this user may not write (``chmod 0444`` is the owner's "do not touch": black,
gofmt, prettier and clang-format refuse such a file; here root does too); a target on a read-only file system; a
target owned by another user whose owner this process cannot keep (not root).

Lost edits (``expect``): a caller that read the file and computed the new content from it
passes the bytes it read. The new content is exchanged in atomically; what was swapped out is
then compared with ``expect``. When another writer (an editor's save) changed the file since
it was read, the exchange is undone at once (the other writer's content back in place) and
:class:`ChangedMeanwhile` is raised: the other edit is never lost, the caller reports it.
Where the exchange is not available (another system, a file system without it) the comparison
is made just before a plain rename (a window of one system call).

The fault tests (tests/faults/) stop a real process inside its write by slowing its first
``os.fsync`` from outside (tests/faults/slow_fsync.py); this module has no test hook.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import fcntl
import io
import os
import re
import shutil
import stat
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

#: the marker in every temporary name of this module (what :func:`sweep` may remove)
TEMP_MARK = "krl-"
#: the suffix of a temporary file
TEMP_SUFFIX = ".tmp"
#: an empty temporary (file or folder) younger than this is a writer's that has not locked it yet
STALE_GRACE_S = 2.0
#: a report folder left by a version before this module (``.OUT.new-XXXXXXXX``: no lock, so no
#: sign of a live writer) is removed once nothing in it changed for this many seconds (such a
#: version rendered its report into it in seconds, then renamed it)
LEGACY_STALE_S = 300.0
#: the name ``tempfile.mkdtemp`` gave such a folder after ``.OUT.new-`` (8 of [a-z0-9_])
_LEGACY_TAIL = re.compile(r"[a-z0-9_]{8}")
#: the permission bits of a file that did not exist (rw-r--r--)
NEW_FILE_MODE = 0o644


class _Said(OSError):
    """An OSError shown as its message alone (no ``[Errno N]``)."""

    def __str__(self) -> str:
        return self.strerror or super().__str__()


class WriteRefused(_Said):
    """The target may not be written (read-only, read-only file system, another owner); the
    message says why and what to do. Nothing was written."""


class ChangedMeanwhile(_Said):
    """The target changed after it was read (another writer saved it): its content was kept,
    the new content was not written."""


#: the message of :class:`ChangedMeanwhile` in every caller's case (a file formatted, a point touched
#: up): the caller may say what it was doing in front of it
CHANGED = "another program saved the file after it was read: that version is kept, nothing written"


def write_text(path: str | Path, text: str) -> None:
    """:func:`write_bytes` of `text` in UTF-8."""
    write_bytes(path, text.encode("utf-8"))


def write_with(path: str | Path, render: Callable[[io.BytesIO], object]) -> None:
    """:func:`write_bytes` of what `render(stream)` writes into a bytes stream (a matplotlib
    figure's ``savefig``, a CSV writer over a text wrapper)."""
    buf = io.BytesIO()
    render(buf)
    write_bytes(path, buf.getvalue())


def write_bytes(path: str | Path, data: bytes, expect: bytes | None = None) -> None:
    """Replace (or create) the file `path` with `data`, durably (module docstring). The owner,
    group and mode of an existing file are kept; a new file gets mode :data:`NEW_FILE_MODE`.
    expect: the bytes the caller read from `path`; when the file no longer holds them at the
    moment of the rename, nothing is written and :class:`ChangedMeanwhile` is raised. A
    symbolic link is written through: its target is replaced in the target's folder and the link
    stays (as ``Path.write_text`` writes; the callers that must not follow links, krl fmt and the
    pendant's touch-up, refuse or resolve them before).
    Raises :class:`WriteRefused`, :class:`ChangedMeanwhile`, OSError (ENOSPC, EACCES ...)."""
    path = Path(os.path.realpath(path)) if os.path.islink(path) else Path(path)
    folder = path.parent
    old = _target_stat(path)
    if old is not None:
        _check_writable(path, old)
    elif expect is not None:
        raise ChangedMeanwhile(errno.ENOENT, "the file was removed or renamed after it was read: nothing written")
    sweep(folder)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{TEMP_MARK}", suffix=TEMP_SUFFIX, dir=folder)
    except OSError as exc:
        if exc.errno not in (errno.EACCES, errno.EPERM, errno.EROFS):
            raise
        raise WriteRefused(exc.errno, f"its folder cannot be written ({exc.strerror}): not written") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        _write_all(fd, data)
        if old is not None:
            _keep_owner(fd, old)
        os.fchmod(fd, NEW_FILE_MODE if old is None else stat.S_IMODE(old.st_mode))   # after fchown: it clears set-id bits
        os.fsync(fd)
        _commit(Path(tmp), path, expect)
        fsync_folder(folder)
    except BaseException:
        _unlink(tmp)
        raise
    finally:
        os.close(fd)


def _target_stat(path: Path) -> os.stat_result | None:
    try:
        return os.stat(path)
    except FileNotFoundError:
        return None


def _check_writable(path: Path, st: os.stat_result) -> None:
    """Raise WriteRefused for a target that its owner made read-only, one this user may not
    write, or one on a read-only file system."""
    if not stat.S_ISREG(st.st_mode):
        raise WriteRefused(errno.EINVAL, "not a regular file: not written")
    try:
        ro_fs = bool(os.statvfs(path.parent).f_flag & os.ST_RDONLY)
    except OSError:
        ro_fs = False
    if ro_fs:
        raise WriteRefused(errno.EROFS, "on a read-only file system: not written")
    bits = stat.S_IMODE(st.st_mode)
    if not bits & 0o222 or not os.access(path, os.W_OK):
        raise WriteRefused(errno.EACCES, f"read-only file (mode {bits:04o}): not written; "
                                         "make it writable (chmod u+w) to change it")


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        n = os.write(fd, view)
        view = view[n:]


def _keep_owner(fd: int, st: os.stat_result) -> None:
    """Give the temporary file the target's owner and group; WriteRefused when not allowed."""
    mine = os.fstat(fd)
    if (mine.st_uid, mine.st_gid) == (st.st_uid, st.st_gid):
        return
    try:
        os.fchown(fd, st.st_uid, st.st_gid)
    except PermissionError:
        raise WriteRefused(errno.EPERM, f"owned by user {st.st_uid}, group {st.st_gid}: a rewrite would change "
                                        "its owner; not written (run as its owner)") from None


def _commit(tmp: Path, path: Path, expect: bytes | None) -> None:
    """Put `tmp` in place of `path`; with `expect`, never over content other than `expect`."""
    if expect is None:
        os.replace(tmp, path)
        return
    if exchange(tmp, path):
        # `tmp` now names what was at `path` an instant ago
        if _holds(tmp, expect):
            _unlink(tmp)
            return
        exchange(tmp, path)           # undo: the other writer's content back in place
        raise ChangedMeanwhile(errno.EBUSY, CHANGED)
    if not _holds(path, expect):
        raise ChangedMeanwhile(errno.EBUSY, CHANGED)
    os.replace(tmp, path)


def _holds(path: Path, expect: bytes) -> bool:
    try:
        with open(path, "rb") as fh:
            return fh.read(len(expect) + 1) == expect
    except OSError:
        return False


def exchange(a: Path, b: Path) -> bool:
    """Swap the entries `a` and `b` (files or folders) in one atomic step (Linux renameat2
    RENAME_EXCHANGE); False when the system or the file system cannot (nothing changed)."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    return renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0


def fsync_folder(folder: str | Path) -> None:
    """fsync the folder itself (its entries: a rename, a new file) so they survive a crash."""
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def fsync_tree(folder: Path) -> None:
    """fsync every file and folder below `folder` (a report written in a temporary folder)."""
    for root, _dirs, files in os.walk(folder):
        for name in files:
            fd = os.open(os.path.join(root, name), os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
        fsync_folder(root)


def _unlink(path: str | Path) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


# ---- report folders -------------------------------------------------------------------------

class TempFolder:
    """A temporary folder ``.OUT.new-krl-XXXXXXXX`` beside the report folder `out`, locked
    while this process lives (so a later run knows it is not stale). ``path``: the folder.
    :meth:`close` releases the lock (after :func:`replace_folder` or on failure, removing it)."""

    def __init__(self, out: Path):
        out = Path(out)
        out.parent.mkdir(parents=True, exist_ok=True)
        sweep(out.parent)
        sweep_legacy(out)
        self.path = Path(tempfile.mkdtemp(prefix=f".{out.name}.new-{TEMP_MARK}", dir=out.parent))
        self._fd = os.open(self.path, os.O_RDONLY | os.O_DIRECTORY)
        fcntl.flock(self._fd, fcntl.LOCK_EX)

    def close(self, remove: bool = False) -> None:
        if remove:
            shutil.rmtree(self.path, ignore_errors=True)
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1


def replace_folder(tmp: Path, out: Path) -> None:
    """Replace the folder `out` by the finished folder `tmp`, durably: every file of `tmp`
    fsynced, then one atomic exchange where the system has it (a reader sees the old report or
    the new one, never none; the old one is then removed), else two renames; the parent folder
    fsynced last."""
    os.chmod(tmp, 0o755)   # mkdtemp makes it private
    fsync_tree(tmp)
    if not out.exists():
        os.replace(tmp, out)
    elif exchange(tmp, out):
        shutil.rmtree(tmp, ignore_errors=True)      # now holds the old report
    else:
        old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old-{TEMP_MARK}", dir=out.parent))
        os.replace(out, old / out.name)
        os.replace(tmp, out)
        shutil.rmtree(old, ignore_errors=True)
    fsync_folder(out.parent)


# ---- stale temporaries ----------------------------------------------------------------------

_swept: set[str] = set()


def stale_name(name: str) -> bool:
    """True for a name this module gives its temporaries: ``.NAME.krl-XXXXXXXX.tmp`` (a file),
    ``.OUT.new-krl-XXXXXXXX`` / ``.OUT.old-krl-XXXXXXXX`` (a report folder)."""
    if not name.startswith("."):
        return False
    if name.endswith(TEMP_SUFFIX) and f".{TEMP_MARK}" in name:
        return True
    return f".new-{TEMP_MARK}" in name or f".old-{TEMP_MARK}" in name


def sweep(folder: str | Path, again: bool = False) -> list[str]:
    """Remove the stale temporaries in `folder` (module docstring): those named by
    :func:`stale_name` whose lock no process holds. Once per folder and process unless
    `again`. Returns the names removed. Never raises."""
    key = os.path.abspath(folder)
    if key in _swept and not again:
        return []
    _swept.add(key)
    removed = []
    try:
        with os.scandir(folder) as it:
            names = [e.name for e in it if stale_name(e.name)]
    except OSError:
        return removed
    for name in names:
        if _remove_if_stale(os.path.join(folder, name)):
            removed.append(name)
    return removed


def sweep_legacy(out: str | Path, stale_s: float = LEGACY_STALE_S) -> list[str]:
    """Remove the report folders ``.OUT.new-XXXXXXXX`` beside the report folder `out` that a
    version before this module left (a killed ``krl recover``; they carry no lock) and in which
    nothing changed for `stale_s` seconds (:data:`LEGACY_STALE_S`). Only `out`'s own name is
    matched, never another report's. Their ``.OUT.old-XXXXXXXX`` may hold the only copy of the
    previous report (killed between its two renames) and is left alone. Returns the names
    removed. Never raises."""
    out = Path(out)
    head = f".{out.name}.new-"
    removed = []
    try:
        with os.scandir(out.parent) as it:
            names = [e.name for e in it if e.name.startswith(head) and _LEGACY_TAIL.fullmatch(e.name[len(head):])
                     and e.is_dir(follow_symlinks=False)]
    except OSError:
        return removed
    for name in names:
        path = out.parent / name
        if time.time() - _newest_mtime(path) >= stale_s:
            shutil.rmtree(path, ignore_errors=True)
            if not os.path.lexists(path):
                removed.append(name)
    return removed


def _newest_mtime(folder: Path) -> float:
    """The latest modification time of `folder` and of everything below it (links not followed)."""
    newest = 0.0
    for base, dirs, files in os.walk(folder):
        for name in [base, *(os.path.join(base, n) for n in dirs + files)]:
            with contextlib.suppress(OSError):
                newest = max(newest, os.lstat(name).st_mtime)
    return newest


def _remove_if_stale(path: str) -> bool:
    try:
        st = os.lstat(path)
        if stat.S_ISLNK(st.st_mode):
            return False
        young = time.time() - st.st_mtime < STALE_GRACE_S
        is_dir = stat.S_ISDIR(st.st_mode)
        if young and (os.listdir(path) == [] if is_dir else st.st_size == 0):
            return False
        fd = os.open(path, os.O_RDONLY | (os.O_DIRECTORY if is_dir else 0) | os.O_NOFOLLOW)
    except OSError:
        return False
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return False                 # a live process holds it
        if is_dir:
            shutil.rmtree(path, ignore_errors=True)
        else:
            _unlink(path)
        return True
    finally:
        os.close(fd)
