"""Which files form the workspace of an opened file, the way ``krl check`` forms them
(krl/workspace.py ``workspaces_for`` and ``find_backups``):

* a file inside a KRC backup (a folder with ``R1/System/$config.dat`` or ``System/$config.dat``,
  any letter case) -> every KRL file of that backup (the outermost one, as ``find_backups``);
* else a file inside a folder the editor opened -> the KRL files of that folder's top-level
  subfolder holding the file (or of the folder itself for a file at its top), as ``krl check
  FOLDER`` groups the files outside backups;
* else the file with the .src/.dat/.sub of its module (``krl check FILE``).

A folder is listed up to :data:`krl.limits.MAX_LSP_WORKSPACE_FILES` KRL files and
:data:`krl.limits.MAX_LSP_SCAN_ENTRIES` directory entries (an editor opened on a home folder must
not read the whole disk).
"""

from __future__ import annotations

import os
from pathlib import Path

from krl.limits import MAX_LSP_SCAN_ENTRIES, MAX_LSP_WORKSPACE_FILES
from krl.syntax.source import is_krl_file


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
    if system is None or not system.is_dir():
        return False
    config = _child(system, "$config.dat")
    return config is not None and config.is_file()


def backup_root(path: Path) -> Path | None:
    """The root of the outermost KRC backup holding `path` (the folder holding R1, or the flat
    export folder holding System), else None."""
    found = None
    for d in path.parents:
        if _is_backup_base(d):
            found = d.parent if d.name.lower() == "r1" else d
        else:
            r1 = _child(d, "r1")       # a file beside R1 (STEU/, KRC/): the backup holding R1
            if r1 is not None and r1.is_dir() and _is_backup_base(r1):
                found = d
    return found


def list_krl_files(folder: Path, limit: int = MAX_LSP_WORKSPACE_FILES,
                   max_entries: int = MAX_LSP_SCAN_ENTRIES) -> list[Path]:
    """KRL files below `folder`, sorted, at most `limit`, looking at no more than `max_entries`
    directory entries (symbolic links to folders not followed)."""
    out: list[Path] = []
    stack = [folder]
    seen = 0
    while stack and len(out) < limit and seen < max_entries:
        d = stack.pop()
        try:
            with os.scandir(d) as it:
                entries = sorted(it, key=lambda e: e.name)
        except OSError:
            continue
        seen += len(entries)
        for e in entries:
            try:
                if e.is_dir(follow_symlinks=False):
                    stack.append(Path(e.path))
                elif e.is_file() and is_krl_file(Path(e.name)):
                    out.append(Path(e.path))
                    if len(out) >= limit:
                        break
            except OSError:
                continue
    return sorted(out)


def workspace_of(path: Path, folders: list[Path]) -> tuple[Path, list[Path]]:
    """(root, files) of the workspace for the file `path`; `folders` are the editor's
    workspace folders. `path` itself is always among the files (it may not exist on disk)."""
    root = backup_root(path)
    files: list[Path]
    if root is not None:
        files = list_krl_files(root)
    else:
        folder = next((f for f in folders if f in path.parents), None)
        if folder is not None:
            root, files = folder, list_krl_files(folder)
            if any(f.name.lower() == "$config.dat" and f.parent.name.lower() == "system" for f in files):
                # the folder holds backups: the files outside them go by top-level subfolder
                rel = path.relative_to(folder)
                root = folder / rel.parts[0] if len(rel.parts) > 1 else folder
                files = [f for f in files if (root in f.parents if root != folder else f.parent == folder)]
        else:
            root = path
            files = []
            try:
                for sib in path.parent.iterdir():
                    if sib.stem.lower() == path.stem.lower() and is_krl_file(sib) and sib.is_file():
                        files.append(sib)
            except OSError:
                pass
    if path not in files:
        files.append(path)
    return root, sorted(set(files))
