"""One side of a diff: a backup folder, a backup ``.zip`` or a single file, read the way
``krl check`` reads it (krl/archive.py for archives, krl/workspace.py for the files; the same
limits and the same messages; each file's parse from the one store, krl/store.py, when it
holds a file of the same content).

``with side(path) as s``: ``s.files`` maps a file's key (its path relative to the backup root,
``/``-separated, lower-case, so a file renamed only in letter case is the same file, as on the
controller; for a single file, ``""``) to its :class:`krl.workspace.SourceFile`. The workspace
is checked (krl/semantics): the diff reads the declared types from the checker's annotations,
and ``s.duplicates`` holds the workspace's facts of the names declared twice (the checker's
E102: ``Workspace.declared_twice``, krl/semantics/checker.py ``DeclaredTwice``) with their file
keys. Of two files whose paths differ only in letter case (impossible on the
controller), the first in walk order is compared and the other is an E102 there too;
``s.shown(key)`` is how the user names it (``backup.zip/R1/Program/a.src``); ``s.not_understood``
the files with lines not understood (krl.workspace.NotUnderstood, issue 63); ``s.errors`` the
input and syntax errors (:class:`krl.diagnostics.Diagnostic`, paths as shown; ``s.sources`` the
text of an archive's files that have errors, by shown path, for the caret lines). An extracted archive is removed
when the block ends. Raises :class:`DiffInputError` for a path that does not exist or a refused
archive (the message names the path, as ``krl check`` does: E001, E004).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from krl.archive import ArchiveError
from krl.backups import one_source
from krl.diagnostics import Diagnostic
from krl.diagnostics.codes import E001, E004
from krl.diagnostics.render import split_lines
from krl.limits import PARSE_TIMEOUT_S
from krl.parsecache import through_store
from krl.project import archive_parts, find_backups
from krl.source import read_source
from krl.workspace import SourceFile, Workspace, load_workspace, not_understood

__all__ = ["DiffInputError", "Side", "side"]


class DiffInputError(ValueError):
    """An input that cannot be compared; ``diagnostic`` says why (E001, E004)."""

    def __init__(self, diagnostic: Diagnostic):
        super().__init__(f"{diagnostic.path}:{diagnostic.line}:{diagnostic.column}: "
                         f"error[{diagnostic.code}]: {diagnostic.message}")
        self.diagnostic = diagnostic


@dataclass
class Side:
    """One loaded side (see the module docstring)."""
    path: str
    root: Path
    workspace: Workspace
    folder: Path | None = None
    files: dict[str, SourceFile] = field(default_factory=dict)
    errors: list[Diagnostic] = field(default_factory=list)
    shown_of: object = None
    sources: dict[str, str] = field(default_factory=dict)     # shown path -> text, for the errors
    duplicates: list[tuple[Diagnostic, str]] = field(default_factory=list)
    # the files with lines not understood (krl.workspace.NotUnderstood), in file order
    not_understood: list = field(default_factory=list)
    _lines: dict[str, list[str]] = field(default_factory=dict)
    _keys: dict[str, str] = field(default_factory=dict)

    def key_of(self, path: str) -> str:
        """The key of the file at `path` (one of :attr:`files`' values)."""
        if not self._keys:
            self._keys = {f.path: k for k, f in self.files.items()}
        return self._keys.get(path, "")

    def shown(self, key: str) -> str:
        """The file of `key` as the user names it."""
        f = self.files.get(key)
        return self.shown_of(f.path) if f is not None else key

    def rel(self, key: str) -> str:
        """The file of `key` relative to the backup root (else to the folder given), in its own
        letter case."""
        f = self.files.get(key)
        if f is None:
            return key
        for base in (self.root, self.folder):
            try:
                return Path(f.path).relative_to(base).as_posix()
            except (ValueError, TypeError):
                continue
        return Path(f.path).name

    def text(self, key: str) -> str | None:
        """The decoded text of the file of `key` (krl.source.read_source), None if unreadable."""
        f = self.files.get(key)
        return read_source(f.path).text if f is not None else None

    def lines(self, key: str) -> list[str]:
        """The text lines of the file of `key` ([] if unreadable)."""
        f = self.files.get(key)
        return self._file_lines(f.path) if f is not None else []

    def _file_lines(self, path: str) -> list[str]:
        lines = self._lines.get(path)
        if lines is None:
            lines = self._lines[path] = split_lines(read_source(path).text or "")
        return lines

    def line(self, path: str, number: int) -> str:
        """Line `number` (1-based) of the file `path`, stripped ("" past the end)."""
        lines = self._file_lines(path)
        return lines[number - 1].strip() if 0 < number <= len(lines) else ""

    def relative(self, path: str) -> str:
        """`path` (a file's path, or a place ``path:line:col``) relative to the backup root
        when it lies below it."""
        return path.replace(str(self.root) + "/", "", 1) if path.startswith(str(self.root) + "/") else path


@contextmanager
def side(path: str | Path, single: bool | None = None, timeout: float | None = None) -> Iterator[Side]:
    """Load `path` (see the module docstring). `single`: treat it as one file (default: when
    it is a file other than a .zip). `timeout`: seconds one file may parse (default
    krl.limits.PARSE_TIMEOUT_S; past it the file is E005, not compared)."""
    p = Path(path)
    timeout = PARSE_TIMEOUT_S if timeout is None else timeout
    if not p.exists() and not p.is_symlink():
        raise DiffInputError(Diagnostic(str(p), 1, 1, *E001("missing")))
    try:
        with one_source(p) as (folder, shown):       # a .zip, or a folder holding one (krl/backups.py)
            is_file = not folder.is_dir() if single is None else single
            # each file's parse from the one store (krl/store.py) when it holds the same content,
            # as `krl check` reads it: two versions of a backup share most of their files
            with through_store():
                if is_file:
                    ws = load_workspace([folder], str(folder), timeout=timeout)
                    root = folder.parent
                else:
                    backups = find_backups(folder)
                    root = backups[0] if len(backups) == 1 else folder
                    # a controller archive: its KRC backup, never its C/ templates (krl/project.py rule 8)
                    whole = root if len(backups) == 1 and archive_parts(folder, backups) else folder
                    ws = load_workspace([whole], str(root), timeout=timeout)
            s = Side(str(path), root, ws, folder=folder, shown_of=shown)
            for f in ws.files:
                key = "" if is_file else _key(f.path, root, folder)
                s.files.setdefault(key, f)
            errors = [d for d in ws.sink.sorted() if d.is_error]      # input and syntax errors
            s.not_understood = not_understood(ws)      # before check_only: of every file
            ws.check_only = set()     # declarations only (names, types, E102): no routine body is checked
            ws.check(resolve=False)   # and no storage placed: the diff never runs the program
            keys = {f.path: k for k, f in s.files.items()}
            once: dict[tuple, object] = {}     # one entry per line and name, as the checker reports it
            for f in ws.declared_twice():
                if f.span.file in keys:
                    once.setdefault((f.span.file, f.span.line, f.name, f.kind, f.struc, str(f.first)), f)
            s.duplicates = [(f, keys[f.span.file])
                            for f in sorted(once.values(), key=lambda f: (f.span.file, f.span.line, f.span.column))]
            for real in {d.path for d in errors} if shown.archive else ():
                s.sources[shown(real)] = read_source(real).text or ""
            s.errors = [shown.diagnostic(d) for d in errors]
            yield s
    except ArchiveError as exc:
        raise DiffInputError(Diagnostic(str(path), 1, 1, *E004(detail=str(exc).removeprefix(f"{path}: ")))) from None


def _key(path: str, root: Path, folder: Path) -> str:
    """The file's path below the backup root, else below the folder given, lower-case."""
    for base in (root, folder):
        try:
            return Path(path).relative_to(base).as_posix().lower()
        except ValueError:
            continue
    return Path(path).name.lower()
