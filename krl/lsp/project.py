"""Open buffers over disk files, and one checked analysis per workspace root.

The text of an open buffer wins over the file on disk (unsaved changes are what the user sees).
Files that are not open are read with krl.source.read_source (the project's one decoding
function: UTF-8 with or without BOM, else cp1252) and re-read when their size or modification
time changes (a file changed by another program, a ``git checkout``). Every analysis re-checks
the whole workspace from the cached parses; only changed buffers and files are parsed again.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from krl.lsp.analysis import Analysis, build_analysis
from krl.lsp.names import is_uri, norm
from krl.lsp.parsing import ParseCache, Parsed, parse_disk
from krl.lsp.roots import workspace_of

ROOTS_TTL_S = 2.0        # seconds a workspace's file list is trusted before it is listed again


class Project:
    """Documents and analyses of one editor session."""

    def __init__(self) -> None:
        self.docs: dict[str, str] = {}          # open buffers: path -> text
        self.folders: list[Path] = []           # the editor's workspace folders
        self.parser = ParseCache()
        self._buffers: dict[str, tuple[str, Parsed]] = {}
        self._disk: dict[str, tuple[int, int, Parsed]] = {}
        self._roots: dict[str, tuple[float, str, list[str], list]] = {}
        self.analyses: dict[str, Analysis] = {}  # root -> latest analysis
        self._root_of: dict[str, str] = {}       # path -> root of its latest analysis
        self.watched = False    # the client reports file changes: file lists kept until it does

    # ------------------------------------------------------------------ documents

    def open(self, path: str, text: str) -> None:
        self.docs[norm(path)] = text

    def change(self, path: str, text: str) -> None:
        self.docs[norm(path)] = text

    def close(self, path: str) -> None:
        p = norm(path)
        self.docs.pop(p, None)
        self._buffers.pop(p, None)
        # a workspace without open documents is forgotten (workspace symbols, memory)
        for root, an in list(self.analyses.items()):
            if not any(d in an.files for d in self.docs):
                del self.analyses[root]
                for f in an.files:
                    if self._root_of.get(f) == root:
                        del self._root_of[f]

    def files_changed(self) -> None:
        """Files were created or deleted on disk: list the workspaces again."""
        self._roots.clear()

    # ------------------------------------------------------------------ analysis

    def workspace_files(self, path: str, docs: dict[str, str] | None = None) -> tuple[str, list[str], list]:
        """(root, files in krl check's order, entries not read) of the workspace of `path`."""
        p = norm(path)
        if is_uri(p):
            return p, [p], []       # not a file: checked on its own
        got = self._roots.get(p)
        now = time.monotonic()
        if got is None or (not self.watched and now - got[0] > ROOTS_TTL_S):
            root, files, skipped = workspace_of(Path(p), self.folders)
            got = (now, norm(root), [norm(f) for f in files], skipped)
            self._roots[p] = got
        root, files = got[1], list(dict.fromkeys(got[2]))
        seen = set(files)
        for d in (docs if docs is not None else self.docs):      # open buffers not (yet) on disk that belong to this workspace
            if d not in seen and (d == root or d.startswith(root.rstrip(os.sep) + os.sep)) and \
                    Path(root).is_dir() and d.lower().endswith((".src", ".dat", ".sub")):
                files.append(d)
        return root, files, got[3]

    def parsed(self, path: str, docs: dict[str, str] | None = None) -> Parsed:
        """The parse of one file: its open buffer, else its disk content (cached)."""
        text = (docs if docs is not None else self.docs).get(path)
        if text is not None:
            got = self._buffers.get(path)
            if got is None or got[0] is not text and got[0] != text:
                got = (text, self.parser.parse(path, text))
                self._buffers[path] = got
            return got[1]
        try:
            st = os.stat(path)
            stamp = (st.st_mtime_ns, st.st_size)
        except OSError:
            stamp = (-1, -1)
        got = self._disk.get(path)
        if got is None or (got[0], got[1]) != stamp:
            got = (*stamp, parse_disk(path))
            self._disk[path] = got
        return got[2]

    def analyze(self, path: str, docs: dict[str, str] | None = None) -> Analysis:
        """Check the workspace of `path` with the buffers `docs` (default: the open ones); the
        result is remembered as the latest analysis of that workspace."""
        docs = dict(self.docs) if docs is None else docs
        root, files, skipped = self.workspace_files(path, docs)
        parsed = [self.parsed(f, docs) for f in files]
        an = self._recheck(root, files, parsed, skipped)
        if an is None:
            an = build_analysis(root, parsed, skipped)
        self.analyses[root] = an
        for f in files:
            self._root_of[f] = root
        return an

    def _recheck(self, root: str, files: list[str], parsed: list[Parsed], skipped) -> Analysis | None:
        """The latest analysis of `root` with the one file whose parse changed re-checked on its
        own (krl/lsp/incremental.py), else None (check the whole workspace)."""
        prev = self.analyses.get(root)
        if prev is None or skipped or list(prev.files) != files:
            return None
        changed = [p for p in parsed if prev.files[p.path].parsed is not p]
        if not changed:
            return prev
        if len(changed) != 1:
            return None
        from krl.lsp.incremental import recheck  # noqa: PLC0415
        try:
            return recheck(prev, changed[0].path, changed[0])
        except Exception:  # noqa: BLE001 - the whole workspace is checked again from the parses
            import logging  # noqa: PLC0415
            logging.getLogger("krl.lsp").error("incremental re-check failed; checking the workspace", exc_info=True)
            return None

    def latest(self, path: str) -> Analysis | None:
        """The latest analysis holding `path`, or None."""
        root = self._root_of.get(norm(path))
        return self.analyses.get(root) if root is not None else None
