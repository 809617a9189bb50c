"""Which files form the workspace of an opened file: the program of that file by the project
model's one rule (krl/project.py ``project_of``), the editor's folder taking the place of
``krl run --workspace``:

* a file inside a KRC backup -> every KRL file of that backup (the outermost one);
* else a file inside a folder the editor opened -> the KRL files of that folder, or, when the
  folder holds backups, of its top-level subfolder holding the file (or of its top level), as
  ``krl check FOLDER`` groups the files outside backups;
* else the KRL files of the file's own folder, as ``krl run FILE`` and ``krl check FILE`` read them.

A walk stops after :data:`krl.limits.MAX_LSP_WORKSPACE_FILES` KRL files or
:data:`krl.limits.MAX_LSP_SCAN_ENTRIES` entries looked at (an editor opened on a home folder
must not make the server read the whole disk). A file larger than
:data:`krl.limits.MAX_LSP_INDEX_FILE_BYTES` is left out as an entry of kind
:data:`NOT_INDEXED` (a W002 warning) unless it is the file opened: the open document first, and
memory bounded (issue 74); the server indexes its declarations in the background
(krl/lsp/index.py: its outline then takes its place in the workspace), krl/lsp/project.py reads
it whole once the editor opens it.
"""

from __future__ import annotations

from pathlib import Path

from krl.files import Entry
from krl.limits import MAX_LSP_INDEX_FILE_BYTES, MAX_LSP_SCAN_ENTRIES, MAX_LSP_WORKSPACE_FILES
from krl.project import list_entries, project_of

#: the kind of a walk entry (krl.files.Entry) for a file too large to index while it is closed
NOT_INDEXED = "not_indexed"


def list_krl_files(folder: Path, limit: int = MAX_LSP_WORKSPACE_FILES,
                   max_entries: int = MAX_LSP_SCAN_ENTRIES) -> list[Path]:
    """The regular KRL files below `folder`, in walk order, within the server's bounds."""
    return [e.path for e in list_entries(folder, limit, max_entries) if e.kind == "file"]


def workspace_of(path: Path, folders: list[Path]) -> tuple[Path, list[Path], list[Entry]]:
    """(root, files, entries not read) of the workspace for the file `path`; `folders` are the
    editor's workspace folders. `path` itself is always among the files (it may not exist on
    disk, an unsaved new buffer)."""
    folder = next((f for f in folders if f in path.parents), None)
    project = project_of(path, within=folder, limit=MAX_LSP_WORKSPACE_FILES, max_entries=MAX_LSP_SCAN_ENTRIES)
    unread = [e for e in project.entries if e.kind != "file"]
    large = {e.path for e in project.entries
             if e.kind == "file" and e.size > MAX_LSP_INDEX_FILE_BYTES and e.path != path}
    if not large:
        return project.root, project.files, unread
    unread += [Entry(e.path, e.rel, NOT_INDEXED, f"{e.size} bytes, more than {MAX_LSP_INDEX_FILE_BYTES}: not "
                     "read whole by the language server until it is opened (its declarations are "
                     "indexed in the background)", e.size)
               for e in project.entries if e.path in large]
    return project.root, [f for f in project.files if f not in large], unread
