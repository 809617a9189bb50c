"""What a path given where a backup is expected holds: a folder, a ``.zip``, or a folder of them.

Controller archives are kept as zips, one per controller and date, in a folder (issue 85 item 3);
a command that takes a backup takes any of the three (docs/security.md, "Archives"):

* a ``.zip``: the archive checked and extracted (krl/archive.py ``backup_source``: every entry
  inspected, the limits of krl/limits.py);
* a folder: the folder itself, when it holds a KRL file outside its zips (krl/project.py
  ``folder_groups`` splits it: one program per backup, a controller archive's ``C`` and ``Log
  Files`` never one, rule 8), then each ``.zip`` below it (any case; the walk of krl/files.py:
  links never followed, MAX_FOLDER_DEPTH), in path order, extracted as above: at most
  ``MAX_FOLDER_ARCHIVES`` of them, their extracted bytes together at most ``MAX_ARCHIVE_BYTES``;
* anything else: itself (the command says what it is not).

:func:`opened` yields the :class:`Opened` parts; :func:`programs_in` the programs (backups and
program folders) of each; :func:`one_backup` the one backup a command of one backup takes, or
:class:`BackupsError` listing them when the path holds several (or none); :func:`one_source` the
one archive of a path (``krl log``, ``krl diff``: a folder of archives holding one). Extracted folders are
removed when the ``with`` block ends, whatever happens. :func:`one_folder` lays every part of a
path out in one temporary folder, for a command that reads every KRL file below one folder
(``krl recover``).
"""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from krl.archive import ArchiveError, Shown, backup_source, extract_backup, is_archive
from krl.limits import MAX_ARCHIVE_BYTES, MAX_FOLDER_ARCHIVES, MAX_FOLDER_DEPTH
from krl.project import folder_groups, group_walk
from krl.terminal import printable

__all__ = ["BackupsError", "Opened", "archive_named", "archives_below", "holds_archives", "one_backup", "one_folder", "one_source", "opened",
           "programs_in"]


class BackupsError(ValueError):
    """A path that does not hold the one backup a command takes (it holds several, or none), or
    more archives than the limits allow; the message names the path and what it holds."""


@dataclass(frozen=True)
class Opened:
    """One part of a path given as a backup: ``folder`` to read (an extracted archive's temporary
    folder, or the folder itself), ``shown`` mapping its paths to the user's (krl.archive.Shown),
    ``source``: the folder or ``.zip`` as the user names it; ``error``: why an archive of a
    folder of archives was refused (krl/archive.py's message; its ``folder`` is then the ``.zip``
    and nothing of it is read: one refused archive never stops the others)."""

    folder: Path
    shown: Shown
    source: str
    error: str = ""
    #: the folder's walk (krl/project.py ``group_walk``) when :func:`opened` made it: read once
    walked: list | None = field(default=None, compare=False, repr=False)

    @property
    def archive(self) -> bool:
        """True for an extracted ``.zip``."""
        return bool(self.shown.archive)


def _zips_and_krl(folder: Path, walked: list | None = None) -> tuple[list[Path], bool]:
    """The ``.zip`` files below `folder` (within MAX_FOLDER_DEPTH levels, walk order: krl/files.py)
    and whether it holds a KRL file there; `walked`: krl/project.py ``group_walk(folder)``, the
    one walk that rule 6 then splits too (made here when None)."""
    zips, krl = [], False
    for e in (walked if walked is not None else group_walk(folder)):
        if e.kind != "file" or e.rel.count("/") > MAX_FOLDER_DEPTH:
            continue
        if e.path.name.lower().endswith(".zip"):
            zips.append(e.path)
        else:
            krl = True
    return sorted(zips), krl


def archives_below(folder: str | Path) -> list[Path]:
    """The ``.zip`` files below `folder`, sorted (the walk of :func:`opened`)."""
    return _zips_and_krl(Path(folder))[0]


def holds_archives(folder: str | Path) -> bool:
    """True when a ``.zip`` lies below `folder` (the walk of :func:`opened`)."""
    return bool(archives_below(folder))


@contextmanager
def opened(path: str | Path, also: tuple[str, ...] = ()) -> Iterator[list[Opened]]:
    """``with opened(p) as parts``: the parts of `p` (module docstring), zips extracted for the
    block (`also`: more name endings to extract, krl/archive.py). Raises ArchiveError for a
    refused archive (naming it), BackupsError past MAX_FOLDER_ARCHIVES."""
    p = Path(path)
    if is_archive(p):
        with backup_source(p, also) as (folder, shown):
            yield [Opened(folder, shown, str(path))]
        return
    if not p.is_dir():
        yield [Opened(p, Shown(), str(path))]
        return
    walked = group_walk(p)
    zips, krl = _zips_and_krl(p, walked)
    if len(zips) > MAX_FOLDER_ARCHIVES:
        raise BackupsError(f"{printable(path)}: {len(zips)} archives (.zip) below it (limit MAX_FOLDER_ARCHIVES = "
                           f"{MAX_FOLDER_ARCHIVES}, docs/security.md): name fewer at a time")
    parts = [Opened(p, Shown(), str(path), walked=walked)] if krl or not zips else []
    with ExitStack() as stack:
        budget = MAX_ARCHIVE_BYTES
        for z in zips:
            tmp = tempfile.mkdtemp(prefix="krl-backup-")
            stack.callback(shutil.rmtree, tmp, True)
            written: list[int] = []
            try:
                extract_backup(z, tmp, also, budget=budget, written_to=written)
            except ArchiveError as exc:
                parts.append(Opened(z, Shown(), str(z), str(exc).removeprefix(f"{z}: ")))
                continue
            budget -= written[0]
            parts.append(Opened(Path(tmp), Shown(tmp, str(z)), str(z)))
        yield parts


def programs_in(parts: list[Opened]) -> list[tuple[Opened, str, list]]:
    """``(part, root, entries)`` of each program of `parts` (krl/project.py ``folder_groups``:
    one per backup, one per program folder; an archive's ``C`` and ``Log Files`` none), in order;
    a part that is no folder (a file named) is one, with entries None."""
    out = []
    for part in parts:
        if part.error:
            continue
        groups = folder_groups(part.folder, part.walked)
        if groups is None:
            out.append((part, str(part.folder), None))
        for root, entries in groups or ():
            if entries:                    # a folder of archives only: the archives are the programs
                out.append((part, root, entries))
    return out


@contextmanager
def one_source(path: str | Path, also: tuple[str, ...] = ()) -> Iterator[tuple[Path, Shown]]:
    """``with one_source(p) as (folder, shown)``: the one archive a path names, as
    krl/archive.py ``backup_source`` gives it (a ``.zip`` extracted, anything else itself), where
    a folder holding ``.zip`` files and no KRL file of its own is its one archive (``krl log``,
    ``krl diff``: what they read of an archive is more than its programs). Raises BackupsError
    naming the archives when it holds several, ArchiveError for a refused one."""
    with backup_source(archive_named(path), also) as (folder, shown):
        yield folder, shown


def archive_named(path: str | Path) -> str:
    """`path` itself, or the one ``.zip`` of a folder holding archive zips and no KRL file of its
    own (what a command that reads an archive's manifest and logbook reads: the report's cover,
    ``krl robot show``). Raises BackupsError naming the archives when it holds several."""
    p = Path(path)
    if p.is_dir():
        zips, krl = _zips_and_krl(p)
        if len(zips) > 1 and not krl:
            names = ", ".join(printable(z) for z in zips[:20]) + (", ..." if len(zips) > 20 else "")
            raise BackupsError(f"{printable(path)} holds {len(zips)} archives: {names}; name one of them")
        if zips and not krl:
            return str(zips[0])
    return str(path)


@contextmanager
def one_backup(path: str | Path, also: tuple[str, ...] = ()) -> Iterator[tuple[Opened, str, list]]:
    """``with one_backup(p) as (part, root, entries)``: the one backup or program folder `p`
    holds (a folder, a ``.zip``, or a folder holding one ``.zip``): the :class:`Opened` part it is
    in (``part.shown`` maps its paths to the user's), its root to read and the entries of its walk
    (krl/project.py ``folder_groups``). Raises BackupsError naming them when `p` holds several (a folder of
    archives: name one of them), or none; ArchiveError for a refused archive."""
    with opened(path, also) as parts:
        progs = programs_in(parts)
        if len(progs) > 1:
            names = ", ".join(printable(part.shown(root)) for part, root, _e in progs)
            raise BackupsError(f"{printable(path)} holds {len(progs)} programs (KRC backups or folders): {names}; "
                               "name one of them")
        refused = [part for part in parts if part.error]
        if not progs and refused:
            raise ArchiveError(f"{printable(refused[0].source)}: {refused[0].error}")
        if not progs:
            raise BackupsError(f"{printable(path)} holds no KRL file (no KRC backup, archive or program)")
        yield progs[0]


@contextmanager
def one_folder(path: str | Path) -> Iterator[tuple[Path, str | None, list[tuple[str, str]]]]:
    """``with one_folder(p) as (folder, label, refused)``: `p` as the one folder a command that
    reads every KRL file below a folder reads (``krl recover``): a folder holding no archive is
    itself (label None); a ``.zip`` is its extracted folder (krl/archive.py ``backup_source``,
    label `p`); a folder holding ``.zip`` archives is one temporary
    folder (removed when the block ends) holding each archive extracted under its own path
    relative to `p` (``cell_a.zip/KRC/R1/...``) and the folder's KRL files outside its zips
    copied under theirs, with label `p` (the report names it, not the temporary folder).
    `refused`: (archive, why) of each archive of the folder that the limits refused, which is
    left out (one refused archive never stops the others). Raises ArchiveError for a refused
    ``.zip`` named alone, BackupsError past MAX_FOLDER_ARCHIVES or when the folder's own files
    copied would exceed MAX_ARCHIVE_BYTES (krl/limits.py, docs/security.md)."""
    p = Path(path)
    if is_archive(p):
        with backup_source(p) as (folder, _shown):
            yield folder, str(path), []
        return
    if not (p.is_dir() and holds_archives(p)):
        yield p, None, []
        return
    with opened(p) as parts:
        tmp = Path(tempfile.mkdtemp(prefix="krl-corpus-"))
        try:
            refused = []
            for part in parts:
                if part.error:
                    refused.append((part.source, part.error))
                elif part.archive:
                    dest = tmp / Path(part.source).relative_to(p)
                    dest.parent.mkdir(parents=True, exist_ok=True)
                    shutil.move(str(part.folder), dest)
                else:
                    _copy_loose(part, tmp)
            yield tmp, str(path), refused
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


def _copy_loose(part: Opened, dest: Path) -> None:
    """Copy the KRL files of the folder `part` outside its zips (its walk, regular files only)
    under `dest` at their paths; BackupsError past MAX_ARCHIVE_BYTES together."""
    total = 0
    for e in part.walked or group_walk(part.folder):
        if e.kind != "file" or e.path.name.lower().endswith(".zip"):
            continue
        total += e.size
        if total > MAX_ARCHIVE_BYTES:
            raise BackupsError(f"{printable(part.source)}: its KRL files beside its archives exceed "
                               f"MAX_ARCHIVE_BYTES = {MAX_ARCHIVE_BYTES} bytes (docs/security.md): "
                               "name the archives and the folder apart")
        target = dest / e.rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(e.path, target, follow_symlinks=False)
