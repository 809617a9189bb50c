"""Walking an untrusted folder (a corpus, a KRC backup): iterative, never following a link.

:func:`walk` is the one folder walk of ``krl recover`` and ``krl check`` (and of finding KRC
backups). It never recurses (an explicit stack: a tree 1,000 levels deep costs a list, not the
Python stack), never follows a symbolic link (a link is listed, never read, so nothing outside
the root is reached or quoted), and never opens a file: it only lists folders and ``lstat``\\ s
their entries. Every entry that is not a plain file of interest is reported, not dropped:

========================  ==========================================================
kind                      meaning
========================  ==========================================================
``file``                  a regular file whose name matches (``.src``/``.dat``/``.sub``)
``symlink``               a symbolic link named like a KRL file, or linking to a folder
``not_regular``           a FIFO, socket or device named like a KRL file (never opened)
``unreadable_folder``     a folder that cannot be listed (permissions, I/O error)
``too_deep``              a folder past :data:`krl.limits.MAX_FOLDER_DEPTH`, not entered
``folder``                a folder entered (only when asked for: ``walk(..., folders=True)``)
========================  ==========================================================

Order: within a folder, entries sorted by name; the files of a folder come before its
sub-folders (the order of ``os.walk`` with sorted names).

Also here: :func:`spelled` (a path in the user's spelling, links kept: what every command shows
and sends), :func:`same_file` (identity by resolved paths), :func:`child` (a folder's entry in any
letter case; each folder's listing kept while the folder is as it was listed) and
:data:`SHARED_CORPUS`. Writing a file: krl/durable.py.
"""

from __future__ import annotations

import os
import stat
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from krl.limits import MAX_FOLDER_DEPTH
from krl.source import file_kind, is_krl_file

WARNING_KINDS = ("symlink", "not_regular", "unreadable_folder", "too_deep")

# The shared corpus of real KRL (docs: README "Quick start"), read in place beside the repository
# (../shared/krl-corpus): the default corpus of the benchmarks, the real-program runs and the
# conformance suite. Absent on a machine without it; every user checks is_dir().
SHARED_CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "krl-corpus"


@dataclass(slots=True)
class Entry:
    """One listed entry. ``rel``: the path relative to the root, '/'-separated, as the file
    system spells it (an undecodable byte stays a surrogate escape; show it with
    :func:`display_path`). ``size``: bytes, by lstat (0 for anything but a file)."""

    path: Path
    rel: str
    kind: str
    detail: str = ""
    size: int = 0

    @property
    def message(self) -> str:
        """Why the entry is not read, in words (for a diagnostic or a report row)."""
        return {"symlink": "a symbolic link (never followed)",
                "not_regular": f"{self.detail or 'not a regular file'} (never opened)",
                "unreadable_folder": f"folder cannot be read: {self.detail}",
                "too_deep": f"folder more than {MAX_FOLDER_DEPTH} levels deep (not entered)",
                }.get(self.kind, self.detail)


def child(folder: str | Path, name: str) -> Path | None:
    """The entry of ``folder`` whose name is ``name`` in any letter case (``name`` given in
    lower case: KUKA's file system, Windows', ignores case), or None: a symbolic link is never
    returned (never followed, as :func:`walk` never follows one), nor anything of a folder that
    cannot be read. Used to find an archive's ``am.ini``, ``R1/System/$config.dat``, ``Log
    Files`` (krl/kssarchive.py, krl/project.py), and on every parent folder of a program at
    each run's start (krl/project.py ``backup_of``: is it in a KRC backup?).

    A folder's listing is kept (:data:`_LISTINGS`) and used again while the folder's identity
    and its modification and change times (one ``stat``) are those it was listed with, once
    they were settled when it was listed (:func:`_settled`): adding, removing or renaming an
    entry changes a folder's modification time, so a kept listing is always the folder's as it
    is now. A run of a program in ``/tmp/x`` looked at ``/tmp`` (about 500 entries in a test
    session) eight times: 2 of its 10 ms of CPU (2026-11-29)."""
    key = str(folder)
    try:
        st = os.stat(key)
    except OSError:
        st = None
    if st is not None:
        kept = _LISTINGS.get(key)
        if kept is not None and kept[0] == (st.st_dev, st.st_ino, st.st_mtime_ns, st.st_ctime_ns):
            found = kept[1].get(name)
            return None if found is None else Path(os.path.join(key, found))
    if st is None or not _settled(st, time.time_ns()):
        return _first(folder, name)         # changed just now: listed again at the next look
    names: dict[str, str] = {}
    try:
        with os.scandir(folder) as it:
            for e in it:
                if not e.is_symlink():
                    names.setdefault(e.name.lower(), e.name)
    except OSError:             # a folder that cannot be read (or no longer can): never kept
        found = names.get(name)
        return None if found is None else Path(os.path.join(key, found))
    if len(_LISTINGS) >= _LISTINGS_KEPT:
        del _LISTINGS[next(iter(_LISTINGS))]
    _LISTINGS[key] = ((st.st_dev, st.st_ino, st.st_mtime_ns, st.st_ctime_ns), names)
    found = names.get(name)
    return None if found is None else Path(os.path.join(key, found))


def _first(folder: str | Path, name: str) -> Path | None:
    """:func:`child` without keeping the listing: the first entry of that name that is no link."""
    try:
        with os.scandir(folder) as it:
            for e in it:
                if e.name.lower() == name and not e.is_symlink():
                    return Path(e.path)
    except OSError:
        return None
    return None


#: folder (as given) -> ((device, inode, modification and change times in ns), {lower-case name:
#: name of its first entry of that name that is no link}): :func:`child`'s kept listings, at most
#: :data:`_LISTINGS_KEPT` (the oldest goes first)
_LISTINGS: dict[str, tuple] = {}
_LISTINGS_KEPT = 512


def _settled(st: os.stat_result, listed_at: int) -> bool:
    """True when a folder with the times of `st` is listed late enough after its last change
    (`listed_at`: the clock in ns before the listing begins) that any later change gives it other
    times: the clock that stamps a change may lag the system clock by a tick (up to 10 ms;
    Linux's coarse clock) and a file system may keep coarse times (whole seconds: FAT's 2 s), so
    a change in the same tick as the last one could leave the folder's times as they were. A
    folder changed within 30 ms (2 s for whole-second times) of its listing is listed again at
    each look until a listing is settled."""
    last = max(st.st_mtime_ns, st.st_ctime_ns)
    coarse = st.st_mtime_ns % 1_000_000_000 == 0 and st.st_ctime_ns % 1_000_000_000 == 0
    return listed_at - last > (2_100_000_000 if coarse else 30_000_000)


def spelled(path: str | Path) -> Path:
    """``path`` made absolute as the user (or the editor) spelled it: symbolic links kept, not
    resolved, so that every path a command shows or sends (a run's summary and trace, the
    debugger's stack frames, the pendant, the reports) is the one the user gave (issue 46).

    A relative path is taken against the working directory as the shell names it (``$PWD``
    when it is the working directory, else ``os.getcwd()``); ``.`` parts are dropped; a ``..``
    after a symbolic link goes to the parent of the link's target (what the system opens), any
    other ``..`` drops the part before it. Identity and containment compare resolved paths
    (:func:`same_file`, pendant/security.py ``inside``): two spellings of one file are one file.
    ``spelled("../shared/x.src")`` in /work/main, with /work/shared a link to /data/shared, is
    ``/work/shared/x.src``. Never raises for a path that does not exist."""
    p = Path(path)
    if not p.is_absolute():
        cwd = os.environ.get("PWD", "")
        try:
            ok = bool(cwd) and os.path.isabs(cwd) and os.path.samefile(cwd, os.curdir)
        except OSError:
            ok = False
        p = Path(cwd if ok else os.getcwd()) / p
    if ".." not in p.parts:
        return p                # nothing to walk: the parts again are `p` (``.`` parts are never kept)
    out = Path(p.anchor)
    for part in p.parts[1:]:
        if part == ".":
            continue
        if part == "..":
            out = Path(os.path.realpath(out)).parent if out.is_symlink() else out.parent
        else:
            out = out / part
    return out


def spelled_within(path: str | Path, within: str | Path | None) -> Path:
    """:func:`spelled` ``path``, written below the folder ``within`` as spelled there when the
    file lies in it but was named through another spelling (the workspace an editor opened
    behind a link, the program named by its resolved path): the workspace's spelling wins."""
    p = spelled(path)
    if within is None:
        return p
    w = spelled(within)
    n = len(p.parts) - len(w.parts)
    if p == w or (n > 0 and p.parents[n - 1] == w):     # `w` is `p` or one of its folders
        return p
    try:
        rel = Path(os.path.realpath(p)).relative_to(os.path.realpath(w))
    except ValueError:
        return p
    return w / rel


def same_file(a: str | Path, b: str | Path) -> bool:
    """True when ``a`` and ``b`` name the same file or folder (links resolved)."""
    return os.path.realpath(a) == os.path.realpath(b)


def display_path(path: str) -> str:
    """A path for reports (CSV, JSON, Markdown, HTML): undecodable bytes of a file name (held
    by Python as surrogate escapes ``\\udcXX``) shown as ``\\xNN``; every other character kept.
    ``display_path(os.fsdecode(b"Pr\\xfcfung.src")) == "Pr\\\\xfcfung.src"``."""
    if not any("\udc80" <= ch <= "\udcff" for ch in path):
        return path
    return "".join(f"\\x{ord(ch) - 0xDC00:02x}" if "\udc80" <= ch <= "\udcff" else ch for ch in path)


def walk(root: str | Path, match: Callable[[str], bool] | None = None,
         max_depth: int = MAX_FOLDER_DEPTH, folders: bool = False) -> Iterator[Entry]:
    """Entries below the folder `root` (see the module docstring). `match(name)` selects the
    files of interest (default: KRL files); a symbolic link or a non-regular file is listed
    when its name matches (a link to a folder always). With `folders`, every folder entered
    (the root too, rel "") is also listed, as kind ``folder``, before anything in it (a caller
    that splits one walk into several roots applies their own depth limits with it,
    krl/workspace.py). Never raises for what it finds."""
    root = Path(root)
    match = match or (lambda name: is_krl_file(Path(name)))
    stack: list[tuple[Path, str, int]] = [(root, "", 0)]
    while stack:
        folder, rel, depth = stack.pop()
        if depth > max_depth:
            yield Entry(folder, rel, "too_deep")
            continue
        if folders:
            yield Entry(folder, rel, "folder")
        try:
            with os.scandir(folder) as it:
                listed = sorted(it, key=lambda e: e.name)
        except OSError as exc:
            yield Entry(folder, rel or ".", "unreadable_folder", exc.strerror or str(exc))
            continue
        subfolders = []
        for e in listed:
            sub = f"{rel}/{e.name}" if rel else e.name
            try:
                st = e.stat(follow_symlinks=False)
                mode, size = st.st_mode, st.st_size
            except OSError as exc:
                if match(e.name):
                    yield Entry(Path(e.path), sub, "unreadable", exc.strerror or str(exc))
                continue
            if stat.S_ISLNK(mode):
                if match(e.name) or _links_to_folder(e):
                    yield Entry(Path(e.path), sub, "symlink")
            elif stat.S_ISDIR(mode):
                subfolders.append((Path(e.path), sub))
            elif stat.S_ISREG(mode):
                if match(e.name):
                    yield Entry(Path(e.path), sub, "file", size=size)
            elif match(e.name):
                yield Entry(Path(e.path), sub, "not_regular", file_kind(mode))
        stack.extend((path, sub, depth + 1) for path, sub in reversed(subfolders))


def _links_to_folder(e: os.DirEntry) -> bool:
    try:
        return e.is_dir(follow_symlinks=True)
    except OSError:
        return False
