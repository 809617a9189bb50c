"""The documents of an editor session and the analyses of their workspaces.

An open document's text (the buffer) takes the place of its file on disk. Each workspace (the
files of one KRC backup, or of the folder the editor opened: krl/lsp/roots.py) is analysed as
one :class:`krl.workspace.Workspace`.

* **Files on disk** are read once per change of their size or time stamp. Those not read yet
  are loaded together (:meth:`Project.load_files`): from the persistent parse cache
  (krl/store.py, krl/parsecache.py ``read_parses``) by content hash, and the others parsed by the fast (Java) engine when it
  runs here: in this process while the engine's threads parse, or in worker processes when
  there is enough to share out and more than two cores (krl/workspace.py ``load_batch``).
* **Closed files past the size bound** (krl/lsp/roots.py) are not read whole: the server's
  indexer (krl/lsp/index.py) hands their outline to :meth:`Project.indexed`, which takes the
  file's place in its workspace while its content is unchanged (:meth:`Project.to_index` lists
  those still to index).
* **Buffers** are parsed by pieces (krl/lsp/parsing.py). A buffer that is its file as on disk
  is that file's parse; the first parse of another is one whole-file parse by the fast engine,
  whose pieces are kept, so that an edit re-parses the piece it touches.
* **Analyses.** The first analysis of a workspace checks it whole (its diagnostics are kept in
  the cache and published at once when the same files are opened again, while the check runs).
  After that, each changed file's new parse goes to the workspace, which re-checks what the
  change can affect (krl/lsp/analysis.py ``updated``, krl/workspace.py ``Workspace.replace``).

The list of a workspace's files is kept for :data:`ROOTS_TTL_S` seconds, or until the client
reports created or deleted files when it watches them.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import logging
import os
import threading
import time
from collections.abc import Callable
from pathlib import Path

from krl import collector
from krl.diagnostics import Diagnostic
from krl.limits import MAX_LSP_INDEX_FILE_BYTES, PARSE_TIMEOUT_S
from krl.lsp.analysis import Analysis, build_analysis, updated
from krl.lsp.parsing import MIN_CHUNKED_LINES, ParseCache, Parsed
from krl.lsp.paths import is_uri, norm
from krl.lsp.roots import NOT_INDEXED, workspace_of
from krl.parsecache import (CorruptEntry, decode_diagnostics, encode_diagnostics, keep_parses, parse_entries,
                            read_parses)
from krl.pool import default_jobs
from krl.source import SourceText, read_source
from krl.store import Store, check_key, parse_key
from krl.syntax.engines import EngineUnavailable, java_answers, resolve
from krl.workspace import failed_load, load_batch, load_parsed

__all__ = ["Project", "is_uri", "norm"]

log = logging.getLogger("krl.lsp")
ROOTS_TTL_S = 2.0        # seconds a workspace's file list is trusted before it is listed again
# Files to parse past this many bytes are shared out to worker processes (each rebuilds the Java
# engine's trees and builds the ASTs) on PARALLEL_MIN_JOBS cores or more.
# On 2 cores the Java engine's threads are the parallel part: its parse runs on one core while
# this process builds the ASTs of the files it answered, on the other. Workers there cost twice
# the CPU (the ASTs pickled and unpickled) and lost in wall time too: 400 files (1.8 MB),
# 2026-11-24, load 8-9, CPU 8.0 s / wall 22-25 s through workers against 4.7-5.1 s / 8-11 s
# in this process (/tmp profile of Project.analyze, cold cache).
PARALLEL_BYTES = 1024 * 1024
PARALLEL_MIN_JOBS = 3
# While the fast engine has not answered yet in this process (its JVM starting: 0.5-1.6 s), a
# batch up to this size (the file just opened) is parsed by the Python engine instead of waiting
# for it: about 20 us per byte at load 9 (Main_2.src, 6.7 kB: 0.17 s; bas.src, 45 kB: 0.89 s,
# against 1.1-1.6 s for the JVM's first answer), 2026-11-24.
FIRST_PYTHON_BYTES = 48 * 1024
MAX_RECHECKED_FILES = 16        # more changed files at once: the workspace is checked whole again


@contextlib.contextmanager
def collector_off(freeze: bool = False):
    """Python's cyclic garbage collector paused (then restored as it was). A whole analysis
    creates millions of long-lived objects (ASTs, scopes, annotations) and next to no cyclic
    garbage: the collector's repeated passes over the growing heap were half its CPU time (400
    files, 2026-11-24, load ~20: cold through the workers 4.6 -> 3.4 s, from the cache 1.8 ->
    0.7 s). Measured garbage left after such an analysis: 38 objects from the cache, 5,304 through
    the workers; the parse trees of an in-process parse are freed as each AST is built
    (krl/workspace.py ``release_tree``).

    `freeze`: what was made is moved to the collector's permanent generation before it runs
    again (``gc.freeze``, as the language server keeps a whole check's objects: krl/lsp/server.py),
    so that the first allocation after it does not start a pass over the objects just made
    (400 files from the cache: 0.43 of 4.7 s profiled, 2026-11-24)."""
    with collector.paused():
        try:
            yield
        finally:
            if freeze:
                collector.keep()


def _java() -> bool:
    try:
        return resolve() == "java"
    except EngineUnavailable:
        return False


def text_sha(text: str) -> str:
    """The content key of a buffer (a file's key is the SHA-256 of its bytes)."""
    return "t" + hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


class Project:
    """Documents and analyses of one editor session; `store`: the persistent cache (None:
    none); `threaded`: the caller runs other threads (the server), so worker processes come from
    a fork server, never from a fork of this process (krl/workspace.py ``load_batch``);
    `defer_writes`: the parse entries of files read from disk are put in the cache by
    :meth:`write_cache`, which the caller runs once the analysis is published (the server),
    instead of before the check (encoding 400 files: 0.3 s of CPU); so are the entries of open
    files and of the check's diagnostics, encoded at once (:attr:`unwritten_entries`); `freeze`: a whole check's
    objects go to the cyclic collector's permanent generation (:func:`collector_off`)."""

    def __init__(self, store: Store | None = None, threaded: bool = False, defer_writes: bool = False,
                 freeze: bool = False) -> None:
        self.threaded = threaded
        self.freeze = freeze
        self.defer_writes = defer_writes
        self.unwritten: list[tuple[str, str, object, str]] = []     # (parse key, path, LoadedFile, outcome status) to cache
        # entries encoded already, to put in the cache: (kind, {key: entry}); with defer_writes,
        # so that no commit of the cache's database (0.17 s of wall time for the open file's entry
        # and the check's on the 400-file bench at load 14, 2026-11-24) comes before a publication
        self.unwritten_entries: list[tuple[str, dict[str, bytes]]] = []
        self.docs: dict[str, str] = {}          # open buffers: path -> text
        self.folders: list[Path] = []           # the editor's workspace folders
        self.parser = ParseCache()
        self.store = store
        self._buffers: dict[str, tuple[str, Parsed]] = {}
        self._disk: dict[str, tuple[tuple, Parsed, str]] = {}     # path -> (stamp, parse, content key)
        # closed files past MAX_LSP_INDEX_FILE_BYTES indexed in the background (krl/lsp/index.py):
        # path -> (stamp, outline's parse, content key); those whose outline failed: path -> (stamp, why)
        self._index: dict[str, tuple[tuple, Parsed, str]] = {}
        self._not_indexed: dict[str, tuple[tuple, str]] = {}
        self._keys: dict[int, str] = {}         # id(Parsed) -> content key, for the check cache
        self._roots: dict[str, tuple[float, str, list[str], list]] = {}
        self.analyses: dict[str, Analysis] = {}  # root -> latest analysis
        self._root_of: dict[str, str] = {}       # path -> root of its latest analysis
        # set once the fast engine answered in this process (the server's warm-up); None: no
        # warm-up runs (the fast engine is used whenever it runs here)
        self.engine_started: threading.Event | None = None
        self.watched = False    # the client reports file changes: file lists kept until it does
        self._disk_known = False    # ... and the files read stay as read until it does

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
        """Files were created, changed or deleted on disk: list the workspaces and look at
        their files again."""
        self._roots.clear()
        self._disk_known = False

    # ------------------------------------------------------------------ files and parses

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
        docs = docs if docs is not None else self.docs
        for d in docs:      # open buffers not (yet) on disk, or not indexed when closed, of this workspace
            if d not in seen and (d == root or d.startswith(root.rstrip(os.sep) + os.sep)) and \
                    Path(root).is_dir() and d.lower().endswith((".src", ".dat", ".sub")):
                files.append(d)
        skipped = []
        for e in got[3]:
            p = norm(str(e.path))
            if e.kind != NOT_INDEXED:
                skipped.append(e)
            elif p not in docs and self._indexed_now(p):
                files.append(p)         # its outline takes its place
            elif p not in docs:
                why = self._not_indexed.get(p)
                skipped.append(e if why is None or why[0] != self._stamp(p) else
                               dataclasses.replace(e, detail=f"{e.size} bytes, more than {MAX_LSP_INDEX_FILE_BYTES}, "
                                                             f"not indexed: {why[1]}"))
        return root, files, skipped

    # ------------------------------------------------------------------ the background index

    def _indexed_now(self, path: str) -> bool:
        got = self._index.get(path)
        return got is not None and got[0] == self._stamp(path)

    def to_index(self, path: str) -> list[tuple[str, tuple]]:
        """(path, stamp) of the closed files of `path`'s workspace past the size bound that
        have no index of their current content yet (nor a failed one)."""
        got = self._roots.get(norm(path))
        if got is None:
            return []
        out = []
        for e in got[3]:
            p = norm(str(e.path))
            if e.kind != NOT_INDEXED or p in self.docs or self._indexed_now(p):
                continue
            stamp, failed = self._stamp(p), self._not_indexed.get(p)
            if failed is None or failed[0] != stamp:
                out.append((p, stamp))
        return out

    def indexed(self, path: str, stamp: tuple, parsed: Parsed) -> None:
        """Keep the background index of `path` (krl/lsp/index.py) made of its content at `stamp`."""
        self._index[path] = (stamp, parsed, "i" + hashlib.sha256(
            parsed.text.encode("utf-8", "surrogatepass")).hexdigest())
        self._not_indexed.pop(path, None)

    def index_failed(self, path: str, stamp: tuple, why: str) -> None:
        """Its outline could not be made (too large, unreadable): W002 says why."""
        self._not_indexed[path] = (stamp, why)

    @staticmethod
    def _stamp(path: str) -> tuple:
        try:
            st = os.stat(path)
            return st.st_mtime_ns, st.st_size
        except OSError:
            return -1, -1

    def load_files(self, paths: list[str], read: dict[str, tuple[tuple, SourceText]] | None = None) -> None:
        """Read the files `paths` from disk (the ones not read since they last changed): their
        parses from the persistent cache by content hash, the others parsed together (see the
        module docstring) and put in the cache. `read`: path -> (stamp, source) of files read
        already (:meth:`_read_keys`)."""
        todo = []
        for p in paths:
            stamp = self._stamp(p)
            got = self._disk.get(p)
            if got is None or got[0] != stamp:
                pre = (read or {}).get(p)
                todo.append((p, stamp, pre[1] if pre is not None and pre[0] == stamp else read_source(p)))
        if not todo:
            return
        keys = {p: parse_key(src.sha, p) for p, _stamp, src in todo if src.status == "ok" and src.sha}
        found: dict[str, object] = {} if self.store is None else \
            read_parses(self.store, {p: (key, p) for p, key in keys.items()})
        missing = [(p, stamp, src) for p, stamp, src in todo if p not in found]
        made = self._parse_files([src for _p, _stamp, src in missing])
        if self.store is not None and made:
            entries = [(keys[p], p, lf, status) for p, (lf, status) in made.items() if p in keys]
            later = self.defer_writes
            self.unwritten.extend(t for t in entries if later and t[1] not in self.docs)
            now = [(k, lf, status) for k, p, lf, status in entries if not later or p in self.docs]
            if later:       # open files encoded now, before an edit moves their lines
                if now and (items := parse_entries(now)):
                    self.unwritten_entries.append(("parse", items))
            else:
                keep_parses(self.store, now)
        found.update((p, lf) for p, (lf, _status) in made.items())
        for p, stamp, src in todo:
            lf = found[p]
            parsed = Parsed(p, src.text if src.status == "ok" else "", lf)
            self._disk[p] = (stamp, parsed, "b" + src.sha if src.sha else "")

    def write_cache(self, limit: int | None = None) -> int:
        """Put the entries encoded already (:attr:`unwritten_entries`) and up to `limit` (None:
        all) of the parse entries :meth:`load_files` deferred in the cache; returns how many of
        those are left. A file opened in the meantime is left out: the
        pieces of an edited buffer move its AST's lines in place (krl/lsp/parsing.py), so
        only ASTs no buffer shares are encoded."""
        part = self.unwritten[:limit] if limit is not None else self.unwritten
        self.unwritten = self.unwritten[len(part):]
        encoded, self.unwritten_entries = self.unwritten_entries, []
        if self.store is not None:
            for kind, items in encoded:
                self.store.put(kind, items)
            keep_parses(self.store, [(k, lf, status) for k, p, lf, status in part
                                     if p not in self.docs and p not in self._buffers])
        return len(self.unwritten)

    def _parse_files(self, sources: list[SourceText]) -> dict:
        """path -> (LoadedFile, outcome status: "done", or how a worker's parse was stopped:
        krl.pool.Outcome) for decoded files: by the fast engine when it runs here (in worker
        processes past PARALLEL_BYTES on PARALLEL_MIN_JOBS cores or more), else (or while it
        starts, for a small batch: FIRST_PYTHON_BYTES) by the Python engine, in this process."""
        if not sources:
            return {}
        size = sum(s.size for s in sources)
        jobs = default_jobs()
        if _java() and size >= PARALLEL_BYTES and jobs >= PARALLEL_MIN_JOBS:
            out = {}
            for src, o in zip(sources, load_batch([s.path for s in sources], PARSE_TIMEOUT_S, jobs,
                                                   threaded=self.threaded)):
                out[src.path] = (o.value if o.status == "done" else failed_load(src.path, o, PARSE_TIMEOUT_S), o.status)
            return out
        if _java() and not self._engine_starting(size):
            out = {src.path: (load_parsed(src, raw), "done")
                   for _i, src, raw in java_answers(enumerate(sources), threads=jobs, trees=True)}
        else:
            out = {src.path: (load_parsed(src, None), "done") for src in sources}
        return out

    def _engine_starting(self, size: int) -> bool:
        """True when `size` bytes are better parsed by the Python engine now than by the fast
        engine, which is still starting (FIRST_PYTHON_BYTES)."""
        return self.engine_started is not None and not self.engine_started.is_set() and size <= FIRST_PYTHON_BYTES

    def first_parse(self, path: str, text: str) -> Parsed:
        """The parse of a buffer seen for the first time: the file's own parse when the buffer
        holds the file as it is on disk, else one whole-file parse by the fast engine (a small
        file: by pieces); its pieces are kept for the edits to come."""
        if not is_uri(path):
            got = self._disk.get(path)
            if got is None or got[0] != self._stamp(path):
                src = read_source(path)
                if src.status == "ok" and src.text == text:
                    self.load_files([path])
            got = self._disk.get(path)
            if got is not None and got[1].text == text:
                self.parser.seed(got[1])
                return got[1]
        if text.count("\n") < MIN_CHUNKED_LINES or not _java():
            return self.parser.parse(path, text)
        src = SourceText(path, text, "", len(text.encode("utf-8", "surrogatepass")))
        [(_i, src, raw)] = list(java_answers([(0, src)], threads=default_jobs(), trees=True))
        parsed = Parsed(path, text, load_parsed(src, raw))
        self.parser.seed(parsed)        # a file with syntax errors: its pieces are parsed at its first edit
        return parsed

    def parsed(self, path: str, docs: dict[str, str] | None = None) -> Parsed:
        """The parse of one file: its open buffer, else its disk content (cached)."""
        text = (docs if docs is not None else self.docs).get(path)
        if text is not None:
            got = self._buffers.get(path)
            if got is None or got[0] is not text and got[0] != text:
                p = self.first_parse(path, text) if got is None else self.parser.parse(path, text)
                got = (text, p)
                self._buffers[path] = got
                if p is not self._disk.get(path, (None, None))[1]:
                    self._keys[id(p)] = text_sha(text)
            return got[1]
        if path in self._index and path not in self._disk and self._indexed_now(path):
            return self._index[path][1]
        if path not in self._disk:
            self.load_files([path])
        return self._disk[path][1]

    def content_key(self, parsed: Parsed) -> str:
        """The content hash of a parse (its file's bytes, or its buffer's text)."""
        for kept in (self._disk, self._index):
            got = kept.get(parsed.path)
            if got is not None and got[1] is parsed:
                return got[2]
        return self._keys.get(id(parsed)) or text_sha(parsed.text)

    # ------------------------------------------------------------------ analysis

    def analyze(self, path: str, docs: dict[str, str] | None = None,
                on_parsed: Callable[[Parsed], None] | None = None,
                on_cached: Callable[[str, list[Diagnostic]], None] | None = None) -> Analysis:
        """Check the workspace of `path` with the buffers `docs` (default: the open ones); the
        result is remembered as the latest analysis of that workspace. When the workspace has
        no analysis yet: `on_parsed(parsed)` is called with the parse of `path` as soon as it is
        made (its file's own diagnostics), and `on_cached(root, diagnostics)` when the cache
        holds the diagnostics of the whole check to come."""
        docs = dict(self.docs) if docs is None else docs
        root, files, skipped = self.workspace_files(path, docs)
        first = root not in self.analyses
        with collector_off(self.freeze) if first else contextlib.nullcontext():
            return self._analyze(path, docs, root, files, skipped, first, on_parsed, on_cached)

    def _analyze(self, path: str, docs: dict[str, str], root: str, files: list[str], skipped, first: bool,
                 on_parsed, on_cached) -> Analysis:
        p = norm(path)
        if on_parsed is not None and first and p in files:
            on_parsed(self.parsed(p, docs))
        read: dict[str, tuple[tuple, SourceText]] = {}
        cached = False
        if on_cached is not None and first and self.store is not None and self.store.db is not None:
            # the check's diagnostics from the cache before any parse is decoded: its key needs
            # only the files' content hashes
            key = check_key(self._read_keys(files, docs, read), [(str(e.path), e.message) for e in skipped])
            got = self.store.get("check", [key]).get(key)
            if got is not None:
                try:
                    on_cached(root, decode_diagnostics(got))
                    cached = True
                except CorruptEntry:
                    self.store.corrupt += 1
        outlined = {f for f in files if f not in docs and f not in self._disk and self._indexed_now(f)}
        if not (self.watched and self._disk_known):     # else the client says when files change
            self.load_files([f for f in files if f not in docs and f not in outlined], read)
        else:
            self.load_files([f for f in files if f not in docs and f not in self._disk and f not in outlined], read)
        self._disk_known = True
        parsed = [self.parsed(f, docs) for f in files]
        an = self._recheck(root, files, parsed, skipped)
        if an is None:
            with collector_off(self.freeze):
                an = self._check(root, parsed, skipped, None if first else on_cached, cached)
        self.analyses[root] = an
        for f in files:
            self._root_of[f] = root
        return an

    def _read_keys(self, files: list[str], docs: dict[str, str],
                   read: dict[str, tuple[tuple, SourceText]]) -> list[tuple[str, str]]:
        """(path, content key) of `files` as :meth:`content_key` will give them once parsed,
        from the files' bytes (a file read now is put in `read` for :meth:`load_files`)."""
        out = []
        for f in files:
            text = docs.get(f)
            if text is None and f not in self._disk and self._indexed_now(f):
                out.append((f, self._index[f][2]))
                continue
            got = self._disk.get(f)
            if got is None or got[0] != self._stamp(f):
                stamp = self._stamp(f)
                src = read_source(f) if not is_uri(f) and stamp[0] != -1 else None
                if src is not None:
                    read[f] = (stamp, src)
                disk = (src.text if src.status == "ok" else "", "b" + src.sha if src.sha else "") \
                    if src is not None else None
            else:
                disk = (got[1].text, got[2])
            if text is None:
                out.append((f, disk[1] if disk is not None else ""))
            else:
                out.append((f, disk[1] if disk is not None and disk[0] == text else text_sha(text)))
        return out

    def _check(self, root: str, parsed: list[Parsed], skipped, on_cached, cached: bool = False) -> Analysis:
        """Check the workspace whole; `on_cached(root, diagnostics)` when the cache holds its
        diagnostics, which are put in the cache unless `cached` (they were found already)."""
        key = None
        if not cached and self.store is not None and self.store.db is not None:
            key = check_key([(p.path, self.content_key(p)) for p in parsed],
                                   [(str(e.path), e.message) for e in skipped])
            if on_cached is not None:
                got = self.store.get("check", [key]).get(key)
                if got is not None:
                    try:
                        on_cached(root, decode_diagnostics(got))
                        key = None              # kept already
                    except CorruptEntry:
                        self.store.corrupt += 1
        an = build_analysis(root, parsed, skipped)
        if key is not None:
            items = {key: encode_diagnostics(an.ws.diagnostics)}
            if self.defer_writes:
                self.unwritten_entries.append(("check", items))
            else:
                self.store.put("check", items)
        return an

    def _recheck(self, root: str, files: list[str], parsed: list[Parsed], skipped) -> Analysis | None:
        """The latest analysis of `root` with each file whose parse changed handed to its
        workspace for a re-check (krl/lsp/analysis.py ``updated``), else None (check the
        whole workspace)."""
        prev = self.analyses.get(root)
        if prev is None or skipped or list(prev.files) != files:
            return None
        changed = [p for p in parsed if prev.files[p.path].parsed is not p]
        if len(changed) > MAX_RECHECKED_FILES:
            return None
        an = prev
        for p in changed:
            an = updated(an, p)
        return an

    def latest(self, path: str) -> Analysis | None:
        """The latest analysis holding `path`, or None."""
        root = self._root_of.get(norm(path))
        return self.analyses.get(root) if root is not None else None
