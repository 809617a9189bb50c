"""A controller archive as KUKA writes it: where its parts are and what its manifest says.

KUKA's archive function (KSS 8: *File > Archive > All*; KUKA System Software 8.7 operating
manual, "Archiving and restoring data") writes one folder, zipped or not (the layout of
``../shared/event-logs/README.md``)::

    am.ini  ArchiveInfo.xml  Archive.log
    KRC/R1/{Program,System,TP,Mada}  KRC/R1/cell.src  KRC/STEU/{Mada,$config.dat}
    C/KRC/Roboter/{Config/...,Rdc,Template,log}  C/KRC/User/ProjectRoot/<id>/
    Log Files/KrcLog{,B,C,I,P,S,U}.evt  Registry/*.amr

The KRL backup is ``KRC`` (krl/project.py finds it as ``KRC/R1/System/$config.dat``; the
machine data in ``KRC/R1/Mada`` as for any backup). This module reads the rest:

* ``am.ini`` (an INI file): ``[Archive] ID, Date``, ``[Roboter] RobName, IRSerialNr``,
  ``[Version] Version`` (the KSS version, ``V8.7.8``), ``[TechPacks] TechPacks`` (the installed
  technology packages, ``|``-separated) with each package's version as its own key;
* ``ArchiveInfo.xml`` (namespace ``KUKARoboter.Contracts.Archive``): ``Roboter/Type`` (the
  robot's ``$MODEL_NAME``: ``#KR470PA_2 S C4 FLR``), ``Roboter/Name``, ``Serialnumber``,
  ``System/Version``, ``Build``, ``ActiveProject``, ``Options/OptionData`` (the packages again),
  ``LogConfig/ProtokollNames`` (the event logs the archive took);
* ``Log Files/*.evt``: the controller's logbook (krl/logbook reads it).

:func:`archive_root` finds the archive's folder from any path inside it; :func:`read_info`
reads its manifest (:class:`ArchiveInfo`; a folder or a ``.zip``); :func:`log_files` lists its
event logs. The files are untrusted: each is read up to ``MAX_ARCHIVE_INFO_BYTES``, the XML with
defusedxml (no DTD, no entities: docs/security.md), a zip's entries checked by krl/archive.py
before one is read. A file that cannot be read or parsed is left out with a note, never an error.
"""

from __future__ import annotations

import configparser
import os
import stat
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from defusedxml import ElementTree as SafeET
from defusedxml.common import DefusedXmlException
from xml.etree.ElementTree import ParseError

from krl.archive import ArchiveError, inspect, is_archive
from krl.files import child
from krl.limits import MAX_ARCHIVE_INFO_BYTES

__all__ = ["ARCHIVE_MANIFESTS", "ArchiveInfo", "archive_root", "info_lines", "log_files", "packages_text",
           "parse_am_ini", "parse_archive_info", "read_info"]

_NS = "{KUKARoboter.Contracts.Archive}"
_MANIFESTS = ("am.ini", "archiveinfo.xml")
#: the name endings krl/archive.py backup_source extracts of a zipped archive besides its KRL
#: files so that the manifest is read (krl check, krl run: the installed packages)
ARCHIVE_MANIFESTS = _MANIFESTS
LOG_FOLDER = "log files"


@dataclass(frozen=True)
class ArchiveInfo:
    """What a controller archive says about itself ("" where it does not say it).

    ``source``: the archive as the user named it; ``archive_id``, ``date`` (am.ini's
    ``2026-01-29_08-26-45``, else ArchiveInfo.xml's ISO date); ``robot_name`` (the controller's
    robot name), ``serial`` (the robot's serial number), ``robot_type`` (``$MODEL_NAME``),
    ``kss`` (``V8.7.8``), ``build``, ``project`` (the active WorkVisual project);
    ``techpacks``: (name, version) of each installed technology package, in am.ini's order;
    ``logs``: the event logs the archive took; ``notes``: what could not be read."""

    source: str
    archive_id: str = ""
    date: str = ""
    robot_name: str = ""
    serial: str = ""
    robot_type: str = ""
    kss: str = ""
    build: str = ""
    project: str = ""
    techpacks: tuple[tuple[str, str], ...] = ()
    logs: tuple[str, ...] = ()
    notes: tuple[str, ...] = field(default=(), compare=False)


def parse_am_ini(text: str) -> dict:
    """The fields of an ``am.ini`` text: {archive_id, date, robot_name, serial, kss, techpacks}
    (techpacks a list of (name, version)). Raises ValueError for text that is no INI file."""
    cp = configparser.ConfigParser(interpolation=None, strict=False)
    cp.optionxform = str                     # keep the packages' spelling ("KUKA.PROFINET MS")
    try:
        cp.read_string(text)
    except configparser.Error as exc:
        raise ValueError(f"not an INI file ({str(exc).splitlines()[0]})") from None

    def get(section: str, key: str) -> str:
        return cp.get(section, key, fallback="").strip()

    packs = cp["TechPacks"] if cp.has_section("TechPacks") else {}
    names = [n.strip() for n in get("TechPacks", "TechPacks").split("|") if n.strip()]
    return {"archive_id": get("Archive", "ID"), "date": get("Archive", "Date"),
            "robot_name": get("Roboter", "RobName"), "serial": get("Roboter", "IRSerialNr"),
            "kss": get("Version", "Version"),
            "techpacks": [(n, str(packs.get(n, "")).strip()) for n in names]}


def _text(node, name: str) -> str:
    got = node.find(_NS + name) if node is not None else None
    return (got.text or "").strip() if got is not None else ""


def parse_archive_info(data: bytes) -> dict:
    """The fields of an ``ArchiveInfo.xml``: {archive_id, date, robot_name, serial, robot_type,
    kss, build, project, techpacks, logs}. Raises ValueError for bytes that are no such XML
    (or that declare a DTD or entities: defusedxml)."""
    try:
        root = SafeET.fromstring(data)
    except (ParseError, DefusedXmlException, ValueError) as exc:
        raise ValueError(f"not readable XML ({exc})") from None
    arch, robot, system = (root.find(_NS + n) for n in ("Archive", "Roboter", "System"))
    packs = []
    for opt in root.iter(_NS + "OptionData"):
        v = opt.find(_NS + "Version")
        ver = ".".join(v.get(k, "") for k in ("Major", "Minor", "Build")) if v is not None else ""
        packs.append((opt.get("Name", ""), ver))
    logs = [(s.text or "").strip() for names in root.iter(_NS + "ProtokollNames") for s in names]
    return {"archive_id": _text(arch, "Id"), "date": _text(arch, "Date"),
            "robot_name": _text(robot, "Name"), "serial": _text(robot, "Serialnumber"),
            "robot_type": _text(robot, "Type"), "kss": _text(system, "Version"),
            "build": _text(system, "Build"), "project": _text(system, "ActiveProject"),
            "techpacks": packs, "logs": [s for s in logs if s]}


def archive_root(path: str | Path) -> Path | None:
    """The folder of the controller archive holding `path` (a file or folder inside it, or the
    archive's folder itself): the nearest folder, `path` first, that holds ``am.ini`` or
    ``ArchiveInfo.xml`` (any case); None when there is none."""
    p = Path(path)
    for d in ([p] if p.is_dir() else []) + list(p.parents):
        if any(child(d, n) is not None for n in _MANIFESTS):
            return d
    return None


def log_files(root: str | Path) -> list[Path]:
    """The event logs of the archive at `root`: ``Log Files/*.evt`` (any case), sorted by name;
    links are never followed."""
    folder = child(Path(root), LOG_FOLDER)
    if folder is None or not folder.is_dir():
        return []
    return evt_files(folder)


def evt_files(folder: Path) -> list[Path]:
    """The ``*.evt`` files (any case) directly in `folder`, sorted by name; links are never
    followed; [] for a folder that cannot be read."""
    try:
        with os.scandir(folder) as it:
            found = [Path(e.path) for e in it if e.name.lower().endswith(".evt") and e.is_file(follow_symlinks=False)]
    except OSError:
        return []
    return sorted(found, key=lambda f: f.name.lower())


def _read_folder(root: Path) -> dict[str, bytes | str]:
    """{lower-case manifest name: its bytes, or a note why not} of an archive folder (a manifest
    that is no regular file, a FIFO or a folder, is not opened)."""
    out: dict[str, bytes | str] = {}
    for name in _MANIFESTS:
        f = child(root, name)
        if f is None:
            continue
        try:
            st = f.stat()
            if not stat.S_ISREG(st.st_mode):        # a FIFO would block the read, a folder fail it
                out[name] = f"{f}: not a regular file; not read"
                continue
            if st.st_size > MAX_ARCHIVE_INFO_BYTES:
                out[name] = f"{f}: larger than {MAX_ARCHIVE_INFO_BYTES} bytes (MAX_ARCHIVE_INFO_BYTES), not read"
                continue
            out[name] = f.read_bytes()
        except OSError as exc:
            out[name] = f"{f}: cannot be read ({exc.strerror or exc})"
    return out


def _read_zip(archive: Path) -> dict[str, bytes | str]:
    """{lower-case manifest name: its bytes, or a note} of a zipped archive: the manifest at the
    archive's top or in its one top folder. Raises ArchiveError for a refused archive."""
    try:
        zf = zipfile.ZipFile(archive)
    except (zipfile.BadZipFile, OSError, ValueError) as exc:
        raise ArchiveError(f"{archive}: not a readable zip archive ({exc})") from None
    out: dict[str, bytes | str] = {}
    with zf:
        inspect(zf, str(archive))
        for info in zf.infolist():
            parts = info.filename.replace("\\", "/").strip("/").split("/")
            name = parts[-1].lower()
            if name not in _MANIFESTS or len(parts) > 2 or name in out:
                continue
            if info.file_size > MAX_ARCHIVE_INFO_BYTES:
                out[name] = f"{archive}/{info.filename}: larger than {MAX_ARCHIVE_INFO_BYTES} bytes, not read"
                continue
            try:
                out[name] = zf.read(info)
            except (zipfile.BadZipFile, OSError, EOFError, NotImplementedError, RuntimeError) as exc:
                out[name] = f"{archive}/{info.filename}: damaged ({exc})"
    return out


def _merge(source: str, found: dict[str, bytes | str]) -> ArchiveInfo | None:
    """One ArchiveInfo from the manifests read: am.ini's fields first, ArchiveInfo.xml's fill in."""
    if not found:
        return None
    fields: dict = {}
    notes = []
    for name, parse in (("am.ini", lambda b: parse_am_ini(b.decode("utf-8", "replace"))),
                        ("archiveinfo.xml", parse_archive_info)):
        got = found.get(name)
        if isinstance(got, str):
            notes.append(got)
            continue
        if got is None:
            continue
        try:
            parsed = parse(got)
        except ValueError as exc:
            notes.append(f"{source}: {'am.ini' if name == 'am.ini' else 'ArchiveInfo.xml'}: {exc}")
            continue
        for k, v in parsed.items():
            if v and not fields.get(k):
                fields[k] = v
    fields["techpacks"] = tuple(tuple(t) for t in fields.get("techpacks", ()))
    fields["logs"] = tuple(fields.get("logs", ()))
    return ArchiveInfo(source=source, notes=tuple(notes), **fields)


def read_info(path: str | Path) -> ArchiveInfo | None:
    """The manifest of the controller archive at or around `path`: a ``.zip`` (its top or its one
    top folder), else the folder :func:`archive_root` finds; None when neither ``am.ini`` nor
    ``ArchiveInfo.xml`` is there. Raises krl.archive.ArchiveError for a refused ``.zip``."""
    p = Path(path)
    if is_archive(p):
        return _merge(str(path), _read_zip(p))
    root = archive_root(p)
    return _merge(str(root), _read_folder(root)) if root is not None else None


def packages_text(techpacks) -> str:
    """``KUKA.PROFINET MS 6.0.8, KUKA.UpdateService 1.1.24``: (name, version) pairs as one text
    (from the archive, unescaped)."""
    return ", ".join(f"{n} {v}".strip() for n, v in techpacks)


def info_lines(info: ArchiveInfo) -> list[str]:
    """The lines ``krl robot show`` prints for an archive (text from the archive, unescaped:
    the caller passes each through krl.terminal.printable)."""
    out = [f"archive    {info.source}" + (f" ({info.date})" if info.date else "")]
    if info.robot_name or info.serial:
        out.append(f"named      {info.robot_name or '(no name)'}" + (f", serial {info.serial}" if info.serial else ""))
    if info.robot_type:
        out.append(f"type       {info.robot_type} (ArchiveInfo.xml)")
    if info.kss:
        out.append(f"software   KSS {info.kss.lstrip('Vv')}" + (f" build {info.build}" if info.build else ""))
    if info.techpacks:
        out.append("packages   " + packages_text(info.techpacks))
    for note in info.notes:
        out.append(f"note       {note}")
    return out
