"""What identifies a backup on the cover of the change report (``krl report``, issue 63).

:func:`identify` reads one loaded side (krl/diff/load.py ``Side``): the path as the user named
it, whether it is a folder, a ``.zip`` or a file, its KRL files (count), the date of its newest
KRL file, a SHA-256 of its KRL files, what a controller archive says of itself (its am.ini and
ArchiveInfo.xml, krl/kssarchive.py: the robot's name and serial, its type, the KSS version, the
installed technology packages: :func:`archive_identity`), and what its machine data names
(krl.workspace.machine_identity, the rule krl audit names its units by): the robot
(``$MODEL_NAME[]``, else ``$TRAFONAME[]``), the machine data's version (``$V_R1MADA[]``, whose
``KUKA8.6`` is the KSS version) and so the controller (KSS 8 runs on a KR C4, KSS 5 on a KR C2;
KUKA's KSS release notes). A backup without machine data names the robot its ``$config.dat``
names in ``MACHINE_DEF[1]`` (a KUKA model's name), else none, and the cover says so.

**The SHA-256** is of the backup's KRL files as the diff compares them: for each file, sorted by
its key (its path below the backup root, ``/``-separated, lower-case), the line
``<key> <sha256 of its bytes>``; the digest of those lines joined with ``\\n``. A byte changed in
any KRL file changes it; the files' dates, other files and the archive's packing do not.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import zipfile
from pathlib import Path

from krl import __version__
from krl.archive import ArchiveError
from krl.diff.load import Side
from krl.kssarchive import packages_text, read_info
from krl.limits import MAX_FILE_BYTES
from krl.workspace import machine_identity

__all__ = ["archive_identity", "identify", "backup_hash", "generator"]



def backup_hash(side: Side) -> str:
    """The SHA-256 of `side`'s KRL files (see the module docstring), hex."""
    lines = []
    for key in sorted(side.files):
        p = Path(side.files[key].path)
        try:
            with p.open("rb") as fh:
                data = fh.read(MAX_FILE_BYTES + 1)
        except OSError:
            data = b""
        lines.append(f"{key} {hashlib.sha256(data).hexdigest()}")
    return hashlib.sha256("\n".join(lines).encode("utf-8")).hexdigest()


def _date(side: Side) -> str:
    """The date and time (UTC) of the side's newest KRL file: its archive entry's, else its file's."""
    newest = None
    archive = side.shown_of.archive if side.shown_of is not None else ""
    if archive:
        try:
            with zipfile.ZipFile(archive) as zf:
                stamps = [dt.datetime(*i.date_time) for i in zf.infolist()
                          if i.filename.lower().endswith((".src", ".dat", ".sub"))]
            newest = max(stamps) if stamps else None
            return newest.strftime("%Y-%m-%d %H:%M") + " (archive entry)" if newest else ""
        except (OSError, zipfile.BadZipFile, ValueError):
            return ""
    for f in side.files.values():
        try:
            m = Path(f.path).stat().st_mtime
        except OSError:
            continue
        newest = m if newest is None else max(newest, m)
    if newest is None:
        return ""
    return dt.datetime.fromtimestamp(newest, dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def generator(now: dt.datetime | None = None) -> str:
    """``krl-tools 0.1.0 (krl report), 2026-11-26 05:40 UTC``: what made the report, and when."""
    now = now or dt.datetime.now(dt.timezone.utc)
    return f"krl-tools {__version__} (krl report), {now.strftime('%Y-%m-%d %H:%M UTC')}"


def archive_identity(path: str) -> dict | None:
    """What the controller archive at `path` (a folder inside one, or a ``.zip``) says of itself:
    {name, serial, type, kss, build, date, packages} ("" where it does not say it; packages as
    ``NAME VERSION, ...``); None when `path` is no such archive or cannot be read."""
    try:
        info = read_info(path)
    except (ArchiveError, OSError):
        return None
    if info is None:
        return None
    return {"name": info.robot_name, "serial": info.serial, "type": info.robot_type, "kss": info.kss.lstrip("Vv"),
            "build": info.build, "date": info.date,
            "packages": packages_text(info.techpacks)}


def identify(side: Side, role: str = "") -> dict:
    """{role, path, kind, files, date, sha256, robot, robot_from, robot_note, mada, kss,
    controller, archive} of one loaded side (`role`: how the report names it, "old", "new"); ""
    for what the backup does not name. ``robot_from`` says where the robot is named
    (``$machine.dat``, ``$config.dat MACHINE_DEF[1]``); ``robot_note`` is left to the caller that
    knows the robots (app/changes.py: whether the catalogue has a robot named in ``$config.dat``);
    ``archive``: :func:`archive_identity` of its path (None for a backup that is no archive)."""
    md = machine_identity(side.files.values())
    archive = side.shown_of.archive if side.shown_of is not None else ""
    kind = "archive (.zip)" if archive else ("folder" if side.folder is not None and side.folder.is_dir() else "file")
    return {"role": role, "path": side.path, "kind": kind, "files": len(side.files), "date": _date(side),
            "sha256": backup_hash(side),
            "robot": md["robot"], "robot_from": md["robot_from"], "robot_note": "",
            "mada": md["mada"], "kss": md["kss"], "controller": md["controller"],
            "archive": archive_identity(side.path) if kind != "file" else None}
