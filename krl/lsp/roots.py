"""Which files form the workspace of an opened file, the way ``krl check`` forms them
(krl/workspace.py ``workspaces_for``, ``find_backups``, ``collect_entries``):

* a file inside a KRC backup (a folder with ``R1/System/$config.dat`` or ``System/$config.dat``,
  any letter case) -> every KRL file of that backup (the outermost one, as ``find_backups``);
* else a file inside a folder the editor opened -> the KRL files of that folder, or, when the
  folder holds backups, of its top-level subfolder holding the file (or of its top level), as
  ``krl check FOLDER`` groups the files outside backups;
* else the file with the .src/.dat/.sub of its module (``krl check FILE``).

Folders are walked by krl.files.walk, the walk of ``krl check`` (links never followed; links,
FIFOs, unreadable and too deep folders come back as entries that are not read, W002), in its
order, which decides which of two duplicate declarations comes first. A walk stops after
:data:`krl.limits.MAX_LSP_WORKSPACE_FILES` KRL files or :data:`krl.limits.MAX_LSP_SCAN_ENTRIES`
files looked at (an editor opened on a home folder must not read the whole disk).
"""

from __future__ import annotations

import os
from pathlib import Path

from krl.files import Entry, walk
from krl.limits import MAX_LSP_SCAN_ENTRIES, MAX_LSP_WORKSPACE_FILES
from krl.syntax.source import is_krl_file


class _Budget(Exception):
    """The walk looked at MAX_LSP_SCAN_ENTRIES files."""


def _child(folder: Path, name: str) -> Path | None:
    try:
        with os.scandir(folder) as it:
            for e in it:
                if e.name.lower() == name:
                    return Path(e.path)
    except OSError:
        return None
    return None


def _is_backup_base(folder: Path) -> bool:
    system = _child(folder, "system")
    if system is None or system.is_symlink() or not system.is_dir():
        return False
    config = _child(system, "$config.dat")
    return config is not None and not config.is_symlink() and config.is_file()


def backup_root(path: Path) -> Path | None:
    """The root of the outermost KRC backup holding `path` (the folder holding R1, or the flat
    export folder holding System), else None."""
    found = None
    for d in path.parents:
        if _is_backup_base(d):
            found = d.parent if d.name.lower() == "r1" else d
        else:
            r1 = _child(d, "r1")       # a file beside R1 (STEU/, KRC/): the backup holding R1
            if r1 is not None and r1.is_dir() and not r1.is_symlink() and _is_backup_base(r1):
                found = d
    return found


def list_entries(folder: Path, limit: int = MAX_LSP_WORKSPACE_FILES,
                 max_entries: int = MAX_LSP_SCAN_ENTRIES) -> list[Entry]:
    """The KRL entries below `folder` in walk order (krl.files.walk), up to `limit` KRL files,
    looking at no more than `max_entries` files."""
    seen = 0

    def match(name: str) -> bool:
        nonlocal seen
        seen += 1
        if seen > max_entries:
            raise _Budget
        return is_krl_file(Path(name))

    out: list[Entry] = []
    files = 0
    try:
        for e in walk(folder, match=match):
            out.append(e)
            files += e.kind == "file"
            if files >= limit:
                break
    except _Budget:
        pass
    return out


def list_krl_files(folder: Path, limit: int = MAX_LSP_WORKSPACE_FILES,
                   max_entries: int = MAX_LSP_SCAN_ENTRIES) -> list[Path]:
    """The regular KRL files of :func:`list_entries`."""
    return [e.path for e in list_entries(folder, limit, max_entries) if e.kind == "file"]


def workspace_of(path: Path, folders: list[Path]) -> tuple[Path, list[Path], list[Entry]]:
    """(root, files, entries not read) of the workspace for the file `path`; `folders` are the
    editor's workspace folders. `path` itself is always among the files (it may not exist on
    disk, an unsaved new buffer)."""
    root = backup_root(path)
    entries: list[Entry]
    if root is not None:
        entries = list_entries(root)
    else:
        folder = next((f for f in folders if f in path.parents), None)
        if folder is not None:
            root, entries = folder, list_entries(folder)
            if any(e.kind == "file" and e.path.name.lower() == "$config.dat"
                   and e.path.parent.name.lower() == "system" for e in entries):
                # the folder holds backups: the entries outside them go by top-level subfolder
                rel = path.relative_to(folder)
                root = folder / rel.parts[0] if len(rel.parts) > 1 else folder
                top = root == folder
                entries = [e for e in entries if (len(e.rel.split("/")) == 1 if top
                                                  else e.rel.split("/")[0] == rel.parts[0])]
        else:
            root = path
            entries = [Entry(path, path.name, "file")]
            try:
                siblings = sorted(path.parent.iterdir()) if path.parent.is_dir() else []
            except OSError:
                siblings = []
            for sib in siblings:
                if sib != path and sib.stem.lower() == path.stem.lower() and is_krl_file(sib) \
                        and not sib.is_symlink():
                    entries.append(Entry(sib, sib.name, "file"))
    files = [e.path for e in entries if e.kind == "file"]
    if path not in files:
        files.append(path)
    return root, files, [e for e in entries if e.kind != "file"]
