"""KRC backup archives: a ``.zip`` given where a backup folder is expected.

`krl check`, `krl recover` and `krl run --workspace` accept a backup archive as they accept a
folder: :func:`backup_source` inspects every entry, extracts the KRL files (``.src``, ``.dat``,
``.sub``, any case), a ``krl.toml`` and, when the caller asks (``also``: ``krl log`` asks for a
controller archive's event logs and manifest), more files by name into a fresh temporary
folder, yields that folder, and removes it afterwards whatever happens. The archive is untrusted (docs/security.md); it is
refused whole, with an :class:`ArchiveError` naming the archive and the entry, when

* an entry's path is absolute (``/x``, ``\\x``, ``C:x``), has a ``..`` component or a NUL, or is
  more than ``MAX_ARCHIVE_DEPTH`` path levels deep;
* an entry is a symbolic link, a device, a FIFO or a socket (only files and folders), or is
  encrypted;
* there are more than ``MAX_ARCHIVE_ENTRIES`` entries, or their declared sizes add up to more
  than ``MAX_ARCHIVE_BYTES``;
* an entry larger than ``MAX_ARCHIVE_RATIO_FLOOR`` bytes expands more than ``MAX_ARCHIVE_RATIO``
  times its compressed size (a zip bomb);
* the file is not a zip archive, or an entry is damaged (CRC, sizes) or appears twice.

All limits live in krl/limits.py. Every check happens before the first byte is written, and the
bytes written are counted again while extracting (a lying header cannot get past the total).
Files are created with O_EXCL and O_NOFOLLOW below the temporary folder only.
"""

from __future__ import annotations

import os
import re
import shutil
import stat
import tempfile
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path

from krl import limits

_DRIVE = re.compile(r"^[A-Za-z]:")
_KEEP_SUFFIXES = (".src", ".dat", ".sub")
_CHUNK = 1 << 16


class ArchiveError(ValueError):
    """An archive refused: the message names the archive and, where there is one, the entry."""


def is_archive(path: str | Path) -> bool:
    """True for an existing file whose name ends in .zip (any case)."""
    p = Path(path)
    return p.suffix.lower() == ".zip" and p.is_file()


def _entry_parts(archive: str, name: str) -> list[str]:
    """The safe relative path components of an entry name, or ArchiveError."""
    shown = name if len(name) <= 120 else name[:117] + "..."
    if "\x00" in name:
        raise ArchiveError(f"{archive}: entry '{shown}' has a NUL character in its name")
    norm = name.replace("\\", "/")
    if norm.startswith("/") or _DRIVE.match(norm):
        raise ArchiveError(f"{archive}: entry '{shown}' has an absolute path")
    parts = [p for p in norm.split("/") if p not in ("", ".")]
    if ".." in parts:
        raise ArchiveError(f"{archive}: entry '{shown}' leaves the archive folder ('..')")
    if len(parts) > limits.MAX_ARCHIVE_DEPTH:
        raise ArchiveError(f"{archive}: entry '{shown}' has {len(parts)} path levels "
                           f"(limit MAX_ARCHIVE_DEPTH = {limits.MAX_ARCHIVE_DEPTH})")
    return parts


def _check_kind(archive: str, info: zipfile.ZipInfo) -> None:
    if info.flag_bits & 0x1:
        raise ArchiveError(f"{archive}: entry '{info.filename}' is encrypted")
    mode = info.external_attr >> 16
    if info.create_system == 3 and mode:          # made on Unix: st_mode in the high bits
        kind = stat.S_IFMT(mode)
        if kind == stat.S_IFLNK:
            raise ArchiveError(f"{archive}: entry '{info.filename}' is a symbolic link")
        if kind not in (0, stat.S_IFREG, stat.S_IFDIR):
            raise ArchiveError(f"{archive}: entry '{info.filename}' is a device or special file, not a file")
    if info.create_system == 0 and info.external_attr & 0x400:   # Windows reparse point
        raise ArchiveError(f"{archive}: entry '{info.filename}' is a symbolic link (reparse point)")


def _wanted(parts: list[str], also: tuple[str, ...] = ()) -> bool:
    name = parts[-1].lower()
    return name.endswith(_KEEP_SUFFIXES + also) or name == "krl.toml"


def inspect(zf: zipfile.ZipFile, archive: str,
            also: tuple[str, ...] = ()) -> list[tuple[zipfile.ZipInfo, list[str]]]:
    """Check every entry against the limits; returns the (entry, path parts) to extract: the KRL
    files, ``krl.toml``, and the files whose lower-case name ends in one of `also`."""
    infos = zf.infolist()
    if len(infos) > limits.MAX_ARCHIVE_ENTRIES:
        raise ArchiveError(f"{archive}: {len(infos)} entries (limit MAX_ARCHIVE_ENTRIES = "
                           f"{limits.MAX_ARCHIVE_ENTRIES})")
    total = 0
    keep = []
    for info in infos:
        parts = _entry_parts(archive, info.filename)
        _check_kind(archive, info)
        total += info.file_size
        if total > limits.MAX_ARCHIVE_BYTES:
            raise ArchiveError(f"{archive}: entries up to '{info.filename}' expand to more than "
                               f"{limits.MAX_ARCHIVE_BYTES} bytes (limit MAX_ARCHIVE_BYTES)")
        if info.file_size > limits.MAX_ARCHIVE_RATIO_FLOOR:
            ratio = info.file_size / max(info.compress_size, 1)
            if ratio > limits.MAX_ARCHIVE_RATIO:
                raise ArchiveError(f"{archive}: entry '{info.filename}' expands {ratio:.0f} times "
                                   f"(limit MAX_ARCHIVE_RATIO = {limits.MAX_ARCHIVE_RATIO}): a zip bomb?")
        if parts and not info.is_dir() and _wanted(parts, also):
            keep.append((info, parts))
    return keep


def extract_backup(archive: str | Path, dest: str | Path, also: tuple[str, ...] = (),
                   budget: int | None = None, written_to: list | None = None) -> int:
    """Extract the KRL files (and krl.toml, and the files whose lower-case name ends in one of
    `also`) of `archive` into the existing empty folder `dest` after checking every entry;
    returns the number of files written. `budget`: the bytes it may write (default, and at
    most, MAX_ARCHIVE_BYTES: krl/backups.py shares one budget among a folder's archives);
    `written_to`: a list the bytes written are appended to. Raises ArchiveError."""
    archive_s = str(archive)
    dest = Path(dest)
    try:
        zf = zipfile.ZipFile(archive)
    except (zipfile.BadZipFile, OSError, ValueError) as exc:
        raise ArchiveError(f"{archive_s}: not a readable zip archive ({exc})") from None
    most = limits.MAX_ARCHIVE_BYTES if budget is None else min(budget, limits.MAX_ARCHIVE_BYTES)
    written = 0
    count = 0
    with zf:
        keep = inspect(zf, archive_s, also)
        for info, parts in keep:
            target = dest.joinpath(*parts)
            try:
                target.parent.mkdir(parents=True, exist_ok=True)
                fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o600)
            except FileExistsError:
                raise ArchiveError(f"{archive_s}: entry '{info.filename}' appears twice") from None
            except OSError as exc:
                raise ArchiveError(f"{archive_s}: entry '{info.filename}' cannot be extracted "
                                   f"({exc.strerror or exc})") from None
            try:
                with os.fdopen(fd, "wb") as out, zf.open(info) as src:
                    while chunk := src.read(_CHUNK):
                        written += len(chunk)
                        if written > most:
                            shared = "" if most == limits.MAX_ARCHIVE_BYTES else ", shared with the archives before it"
                            raise ArchiveError(f"{archive_s}: entry '{info.filename}' goes past "
                                               f"{most} bytes (limit MAX_ARCHIVE_BYTES{shared})")
                        out.write(chunk)
            except (zipfile.BadZipFile, EOFError, OSError, NotImplementedError, RuntimeError) as exc:
                raise ArchiveError(f"{archive_s}: entry '{info.filename}' is damaged ({exc})") from None
            count += 1
    if written_to is not None:
        written_to.append(written)
    return count


@dataclass(frozen=True)
class Shown:
    """Maps paths below an extracted archive's folder to how users see them:
    ``backup.zip/KRC/R1/Program/x.src``. Identity for a plain folder."""

    folder: str = ""
    archive: str = ""

    def __call__(self, path: str) -> str:
        if not self.archive or not path.startswith(self.folder):
            return path
        rest = path[len(self.folder):].lstrip("/\\").replace("\\", "/")
        return f"{self.archive}/{rest}" if rest else self.archive

    def diagnostic(self, d):
        """A Diagnostic with its path and its notes' paths shown as the user sees them."""
        if not self.archive:
            return d
        notes = [replace(n, path=self(n.path)) for n in d.notes]
        return replace(d, path=self(d.path), notes=notes)


@contextmanager
def backup_source(path: str | Path, also: tuple[str, ...] = ()) -> Iterator[tuple[Path, Shown]]:
    """``with backup_source(p) as (folder, shown)``: for a .zip, the checked and extracted
    temporary folder (removed on exit) and the path mapping; otherwise `p` itself and the
    identity. `also`: lower-case name endings of more files to extract than the KRL files
    (``krl log``: ``(".evt", "am.ini", "archiveinfo.xml")``). Raises ArchiveError for a refused
    archive (before yielding)."""
    p = Path(path)
    if not is_archive(p):
        yield p, Shown()
        return
    tmp = tempfile.mkdtemp(prefix="krl-backup-")
    try:
        extract_backup(p, tmp, also)
        yield Path(tmp), Shown(tmp, str(path))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
