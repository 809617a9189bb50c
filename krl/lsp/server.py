"""The pygls language server: handlers for the LSP requests and notifications.

Analysis (parse, link, check: krl/lsp/project.py) runs in one worker thread, debounced after
each change (:data:`DEBOUNCE_S`); requests wait for the analysis of their file when it is out of
date. The first analysis of a workspace publishes, before its check ends, the opened file's own
parse diagnostics (a workspace of :data:`EARLY_MIN_FILES` files or more) and the diagnostics the
persistent cache holds for the same files (the one store: krl/store.py, krl/parsecache.py). The fast parse engine's worker is
started when the client is initialized. An exception in a handler is logged (stderr and
``window/logMessage``) and answered with an empty result: it never ends the server. A closed
file too large to read whole is indexed by its declarations on a thread of its own once the open
document's analysis is published (krl/lsp/index.py); each index made checks the open documents of
its workspace again, so that the names it declares resolve.
"""

from __future__ import annotations

import asyncio
import functools
import logging
import os
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from lsprotocol import types as L
from pygls.lsp.server import LanguageServer
from pygls.uris import from_fs_path, to_fs_path

from krl import __version__, collector
from krl.fmt import format_text
from krl.diagnostics.render import split_lines
from krl.pool import default_jobs, start_fork_server
from krl.semantics.config import config_for
from krl.semantics.symbols import system_scopes
from krl.source import SourceText
from krl.store import Store
from krl.syntax.engines import EngineUnavailable, java_answers, resolve
from krl.workspace import WORKER_MODULES
from krl.lsp import actions as _actions
from krl.lsp import calls as _calls
from krl.lsp import complete as _complete
from krl.lsp import folding as _folding
from krl.lsp import hover as _hover
from krl.lsp import inlay as _inlay
from krl.lsp import navigate as _nav
from krl.lsp import outline as _outline
from krl.lsp import rename as _rename
from krl.lsp import semtokens as _semtokens
from krl.lsp import signature as _signature
from krl.lsp import unused as _unused
from krl.lsp.occurrences import DECL, WRITE, file_occurrences
from krl.lsp.analysis import Analysis
from krl.lsp.sample import generate
from krl.lsp import convert as _convert
from krl.lsp.convert import from_position, lsp_diagnostic, to_range
from krl.lsp.index import Indexer
from krl.lsp.parsing import Parsed
from krl.lsp.paths import norm
from krl.lsp.project import PARALLEL_MIN_JOBS, Project
from krl.lsp.roots import list_krl_files
from krl.lsp.text import token_at, units
from pygls.exceptions import JsonRpcException
from krl.terminal import printable, printable_path

log = logging.getLogger("krl.lsp")       # file names and messages in it pass krl.terminal.printable
TRACEBACKS = {"on": False}                # Python tracebacks only into a --log-file, never to stderr
DEBOUNCE_S = 0.02          # seconds after the last change before the analysis starts, in a burst
BURST_GAP_S = 0.15         # a change this soon after the one before is part of a burst (typing);
                           # a change after a longer pause starts the analysis at once (leading edge)
INDEX_AFTER_S = 1.0        # seconds after a published analysis before the closed large files of its
                           # workspace are indexed (krl/lsp/index.py): the open document's first requests first
EARLY_MIN_FILES = 20       # after opening a file of a workspace of this many files: its own parse
                           # diagnostics at once, before the first check of the workspace ends
CACHE_WRITE_FILES = 25     # parse entries put in the cache per step after an analysis (an edit
                           # waits for one step at most: ~25 ms of CPU)
CACHE_WRITE_PAUSE_S = 0.05  # between those steps, and before the first
STORE_WAIT_S = 30.0        # an analysis waits this long at most for the cache being opened


def path_of(uri: str) -> str:
    """The file path of a ``file:`` URI; other URIs (``untitled:``) name themselves."""
    if uri.startswith("file:"):
        p = to_fs_path(uri)
        if p:
            return norm(p)
    return uri


def uri_of(path: str) -> str:
    return from_fs_path(path) if os.path.isabs(path) else path


class KrlLanguageServer(LanguageServer):
    """pygls server with the project state (see the module docstring)."""

    def __init__(self) -> None:
        super().__init__("krl-lsp", __version__)
        self.project = Project(store=None, threaded=True, defer_writes=True, freeze=True)
        self._store_ready = threading.Event()
        self._writing = False
        self._edits_warm = False
        # the cache is opened beside the start-up (its version hashes the krl package's sources)
        threading.Thread(target=self._open_store, name="krl-cache", daemon=True).start()
        self.debounce_s = DEBOUNCE_S
        self._last_change: dict[str, float] = {}
        self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="krl-analysis")
        self._lock: asyncio.Lock | None = None
        self._pending: dict[str, asyncio.Task] = {}
        self._dirty: set[str] = set()
        self._versions: dict[str, int | None] = {}
        self._gen: dict[str, int] = {}          # path -> count of changes (stale-analysis check)
        # closed files too large to read whole, indexed by their outline on their own thread
        # (krl/lsp/index.py); an index made re-checks the open documents of its workspace
        self._loop: asyncio.AbstractEventLoop | None = None
        self.indexer = Indexer(self._indexed, self._index_failed)

    def _open_store(self) -> None:
        try:
            self.project.store = Store()
        except Exception as exc:  # noqa: BLE001 - Store never raises; a server without cache anyway
            log.error("the parse cache is not used: %s", printable(exc), exc_info=TRACEBACKS["on"])
        finally:
            self._store_ready.set()

    def _run_analysis(self, path: str, docs: dict[str, str], on_parsed, on_cached) -> Analysis:
        """Project.analyze in the analysis thread, once the cache is open."""
        self._store_ready.wait(STORE_WAIT_S)
        return self.project.analyze(path, docs, on_parsed, on_cached)

    def write_cache_later(self) -> None:
        """Put the parse entries the last analysis deferred in the cache, a few per step in
        the analysis thread, while no analysis waits (edits go first)."""
        if self._writing or not (self.project.unwritten or self.project.unwritten_entries):
            return
        self._writing = True
        loop = asyncio.get_running_loop()

        async def run() -> None:
            try:
                while self.project.unwritten or self.project.unwritten_entries:
                    await asyncio.sleep(CACHE_WRITE_PAUSE_S)
                    if self._lock is not None and self._lock.locked() or any(not t.done() for t in self._pending.values()):
                        continue
                    await loop.run_in_executor(self._executor, self.project.write_cache, CACHE_WRITE_FILES)
            except Exception as exc:  # noqa: BLE001 - a cache not written is parsed again next time
                log.error("writing the parse cache failed: %s", printable(exc), exc_info=TRACEBACKS["on"])
            finally:
                self._writing = False
        asyncio.ensure_future(run())

    @property
    def lock(self) -> asyncio.Lock:
        if self._lock is None:
            self._lock = asyncio.Lock()
        return self._lock

    def codec(self):
        try:
            return self.workspace.position_codec
        except Exception:  # noqa: BLE001 - before initialize
            return None

    def folders(self) -> list:
        out = []
        try:
            for f in self.workspace.folders.values():
                p = to_fs_path(f.uri)
                if p:
                    out.append(Path(norm(p)))
            if not out and self.workspace.root_path:
                out.append(Path(norm(self.workspace.root_path)))
        except Exception:  # noqa: BLE001
            pass
        return out

    # ------------------------------------------------------------------ analysis

    async def _analyze(self, path: str) -> Analysis | None:
        async with self.lock:
            if path not in self._dirty and self.project.latest(path) is not None:
                return self.project.latest(path)     # an analysis of its workspace ran meanwhile
            self.project.folders = self.folders()
            docs = dict(self.project.docs)
            versions = dict(self._versions)
            gens = dict(self._gen)
            loop = asyncio.get_running_loop()

            def on_parsed(parsed: Parsed) -> None:
                loop.call_soon_threadsafe(self._publish_parse, parsed, docs, versions)

            def on_cached(root: str, diags: list) -> None:
                loop.call_soon_threadsafe(self._publish_cached, root, diags, docs, versions)
            try:
                an = await loop.run_in_executor(self._executor, self._run_analysis, path, docs, on_parsed, on_cached)
            except Exception as exc:  # noqa: BLE001
                log.error("analysis of %s failed: %s", printable_path(path), printable(exc), exc_info=TRACEBACKS["on"])
                self._report(f"krl lsp: analysis of {printable_path(path)} failed: {type(exc).__name__}: {printable(exc)}")
                self._dirty.discard(path)
                return None
            for f in an.files:          # up to date unless changed while the analysis ran
                if self._gen.get(f) == gens.get(f):
                    self._dirty.discard(f)
            if path not in an.files and self._gen.get(path) == gens.get(path):
                self._dirty.discard(path)
            try:
                self.publish(an, docs, versions)
            except Exception:  # noqa: BLE001 - e.g. the client went away
                log.error("publishing diagnostics failed", exc_info=TRACEBACKS["on"])
            if an.how == "workspace":
                # A whole check's objects (ASTs, scopes, findings) live as long as the workspace:
                # kept out of the cyclic collector's generations, an edit's allocations never
                # start a full collection over them (pauses of 1.7-1.9 s per few edits on the
                # 400-file bench at load 26, none frozen). What the previous check left is
                # unfrozen here and collected as usual. (The project froze the check's objects
                # as it ended already, before the collector ran again: Project(freeze=True).)
                collector.keep(renew=True)
            if an.how == "workspace":
                self.warm_edits({p: t for p, t in docs.items() if p in an.files})
            self.write_cache_later()
            self.index_later(path)
            return an

    def index_later(self, path: str) -> None:
        """Ask the indexer, :data:`INDEX_AFTER_S` seconds after the open document's analysis is
        published (its first requests answered first), for the closed files of `path`'s
        workspace past the size bound."""
        self._loop = asyncio.get_running_loop()
        todo = self.project.to_index(path)
        if todo:
            self._loop.call_later(INDEX_AFTER_S, lambda: [self.indexer.ask(p, stamp) for p, stamp in todo])

    def _indexed(self, path: str, stamp: tuple, parsed: Parsed) -> None:
        """(the indexer's thread) An index made: kept, and the open documents of its workspace
        checked again (on the server's loop)."""
        if self._loop is not None:
            self._loop.call_soon_threadsafe(self._use_index, path, stamp, parsed)

    def _index_failed(self, path: str, stamp: tuple, why: str) -> None:
        log.warning("krl lsp: %s not indexed: %s", printable_path(path), printable(why))
        if self._loop is not None:
            self._loop.call_soon_threadsafe(self.project.index_failed, path, stamp, why)

    def _use_index(self, path: str, stamp: tuple, parsed: Parsed) -> None:
        self.project.indexed(path, stamp, parsed)
        for doc in list(self.project.docs):
            an = self.project.latest(doc)
            root = an.root if an is not None else None
            if root is not None and path.startswith(root.rstrip(os.sep) + os.sep):
                self.schedule(doc, 0.0)

    def publish(self, an: Analysis, docs: dict[str, str], versions: dict[str, int | None]) -> None:
        """Diagnostics of the open documents of an analysis, with the versions it saw."""
        codec = self.codec()
        for path, fi in an.files.items():
            if path not in docs or path not in self.project.docs:
                continue
            diags = [lsp_diagnostic(d, fi.lines, codec, uri_of) for d in an.diagnostics_for(path)]
            for u in _unused.never_read(an, path):
                diags.append(L.Diagnostic(
                    range=to_range(fi.lines, u.place.line, u.place.column, u.place.length, codec), message=u.message,
                    severity=L.DiagnosticSeverity.Hint, tags=[L.DiagnosticTag.Unnecessary], source="krl"))
            self.text_document_publish_diagnostics(L.PublishDiagnosticsParams(
                uri=uri_of(path), diagnostics=diags, version=versions.get(path)))

    def _stale(self, path: str, docs: dict[str, str]) -> bool:
        """True when an analysis of `path` already published, or its buffer changed since."""
        return self.project.latest(path) is not None or self.project.docs.get(path) is not docs.get(path)

    def _publish_parse(self, parsed: Parsed, docs: dict[str, str], versions: dict[str, int | None]) -> None:
        """The opened file's own parse diagnostics (syntax, FOLD balance: they depend on the file
        alone), before the first check of its workspace (of EARLY_MIN_FILES files or more) ends;
        the checked diagnostics replace them."""
        try:
            path = parsed.path
            _root, files, _skipped = self.project.workspace_files(path, docs)
            if len(files) < EARLY_MIN_FILES or self._stale(path, docs):
                return
            lines, codec = split_lines(parsed.text), self.codec()
            self.text_document_publish_diagnostics(L.PublishDiagnosticsParams(
                uri=uri_of(path), version=versions.get(path),
                diagnostics=[lsp_diagnostic(d, lines, codec, uri_of) for d in parsed.diagnostics if d.path == path]))
        except Exception as exc:  # noqa: BLE001 - the checked diagnostics follow anyway
            log.error("first diagnostics failed: %s", printable(exc), exc_info=TRACEBACKS["on"])

    def _publish_cached(self, root: str, diags: list, docs: dict[str, str], versions: dict[str, int | None]) -> None:
        """The diagnostics the cache holds for the whole check to come (the same files, the
        same front end), for the open documents of that workspace."""
        try:
            by: dict[str, list] = {}
            for d in diags:
                by.setdefault(d.path, []).append(d)
            codec = self.codec()
            config = config_for(root)
            for path, text in docs.items():
                if self._stale(path, docs) or not (path == root or path.startswith(root.rstrip(os.sep) + os.sep)):
                    continue
                lines = split_lines(text)
                shown = config.apply(sorted(by.get(path, []), key=lambda d: (d.line, d.column, d.code)))
                self.text_document_publish_diagnostics(L.PublishDiagnosticsParams(
                    uri=uri_of(path), version=versions.get(path),
                    diagnostics=[lsp_diagnostic(d, lines, codec, uri_of) for d in shown]))
        except Exception as exc:  # noqa: BLE001 - the checked diagnostics follow anyway
            log.error("cached diagnostics failed: %s", printable(exc), exc_info=TRACEBACKS["on"])

    def warm(self) -> None:
        """Start the fast parse engine's worker and read the front end's tables, in the
        background (the first parse and check then wait for neither)."""
        started = self.project.engine_started = threading.Event()

        def run() -> None:
            try:
                try:
                    if resolve() == "java":     # the worker's JIT and parse caches warm on a sample
                        text = generate(400)
                        list(java_answers([(0, SourceText("warm.src", text, "", len(text)))],
                                          threads=default_jobs(), trees=False))
                except EngineUnavailable:
                    pass
                finally:
                    started.set()   # (krl/lsp/project.py FIRST_PYTHON_BYTES)
                system_scopes()
                if default_jobs() >= PARALLEL_MIN_JOBS:
                    start_fork_server(WORKER_MODULES)    # for the parallel loads of large workspaces
            except Exception as exc:  # noqa: BLE001 - only a head start
                log.error("warming up failed: %s", printable(exc), exc_info=TRACEBACKS["on"])
        threading.Thread(target=run, name="krl-warm", daemon=True).start()

    def warm_edits(self, docs: dict[str, str]) -> None:
        """Once, after the first whole analysis: the fast engine parses the open documents with
        their trees, as it parses an edited piece, in the background. After a start from the
        cache it had parsed nothing but the warm-up sample, and its JIT compiled the tree
        answers during the first edits (KRC4_test bas.src, 20 value edits, server CPU per edit
        p50/p95 30/70 ms from the cache against 20/30 ms after a cold start, 2026-11-24)."""
        if self._edits_warm:
            return
        self._edits_warm = True
        sources = [SourceText(p, t, "", len(t.encode("utf-8", "surrogatepass"))) for p, t in docs.items()]

        def run() -> None:
            try:
                if sources and resolve() == "java":
                    for _ in java_answers(enumerate(sources), threads=default_jobs(), trees=True, decode=False):
                        pass
            except Exception as exc:  # noqa: BLE001 - only a head start (EngineUnavailable included)
                log.error("warming up for edits failed: %s", printable(exc), exc_info=TRACEBACKS["on"])
        threading.Thread(target=run, name="krl-warm-edits", daemon=True).start()

    def schedule(self, path: str, delay: float | None = None) -> None:
        """Analyse the workspace of `path` after `delay` seconds (a newer change restarts it).

        Without `delay` (an edit): at once when the edit follows a pause of more than
        :data:`BURST_GAP_S` (a single edit waits for no debounce), else after :data:`DEBOUNCE_S`,
        so that a burst of keystrokes is analysed once (edits arriving while an analysis runs
        mark the file dirty and wait for it, as before)."""
        now = time.monotonic()
        last = self._last_change.get(path)
        self._last_change[path] = now
        if delay is None:
            delay = 0.0 if last is None or now - last > BURST_GAP_S else self.debounce_s
        self._dirty.add(path)
        self._gen[path] = self._gen.get(path, 0) + 1
        old = self._pending.pop(path, None)
        if old is not None and not old.done():
            old.cancel()

        async def later() -> None:
            try:
                await asyncio.sleep(delay)
            except asyncio.CancelledError:
                return
            self._pending.pop(path, None)
            await self._analyze(path)

        self._pending[path] = asyncio.ensure_future(later())

    async def fresh(self, path: str) -> Analysis | None:
        """The analysis holding `path`, brought up to date with the buffers first. Returns
        when no analysis is running: the caller reads the annotated trees without awaiting
        anything, so no analysis re-annotates them meanwhile."""
        if path in self._dirty or self.project.latest(path) is None:
            task = self._pending.pop(path, None)
            if task is not None:
                task.cancel()
            return await self._analyze(path)
        async with self.lock:
            return self.project.latest(path)

    def _report(self, message: str, kind: L.MessageType = L.MessageType.Error) -> None:
        try:
            self.window_log_message(L.LogMessageParams(type=kind, message=message))
        except Exception:  # noqa: BLE001
            pass


class RequestFailed(JsonRpcException):
    """A request the server refuses, with the reason for the user (LSP RequestFailed)."""
    CODE = -32803


def guarded(empty=None):
    """Run a handler; an exception is logged and answered with `empty` (a refusal,
    :class:`RequestFailed`, goes to the client as an error with its message)."""
    def wrap(fn):
        @functools.wraps(fn)
        async def run(ls: KrlLanguageServer, params):
            try:
                return await fn(ls, params)
            except RequestFailed:
                raise
            except Exception as exc:  # noqa: BLE001
                log.error("handler %s failed: %s", fn.__name__, printable(exc), exc_info=TRACEBACKS["on"])
                ls._report(f"krl lsp: {fn.__name__} failed: {type(exc).__name__}: {printable(exc)}")
                return empty() if callable(empty) else empty
        return run
    return wrap


def create_server() -> KrlLanguageServer:
    """A server with every feature registered."""
    server = KrlLanguageServer()

    @server.feature(L.INITIALIZED)
    @guarded()
    async def initialized(ls: KrlLanguageServer, params: L.InitializedParams):
        ls.warm()
        caps = ls.client_capabilities
        dyn = getattr(getattr(getattr(caps, "workspace", None), "did_change_watched_files", None),
                      "dynamic_registration", False)
        if dyn:
            watchers = [L.FileSystemWatcher(glob_pattern=g) for g in ("**/*.src", "**/*.dat", "**/*.sub",
                                                                       "**/*.SRC", "**/*.DAT", "**/*.SUB")]
            await ls.client_register_capability_async(L.RegistrationParams(registrations=[L.Registration(
                id="krl-watch", method=L.WORKSPACE_DID_CHANGE_WATCHED_FILES,
                register_options=L.DidChangeWatchedFilesRegistrationOptions(watchers=watchers))]))
            ls.project.watched = True       # created/deleted files arrive as didChangeWatchedFiles

    @server.feature(L.TEXT_DOCUMENT_DID_OPEN)
    @guarded()
    async def did_open(ls: KrlLanguageServer, params: L.DidOpenTextDocumentParams):
        path = path_of(params.text_document.uri)
        ls.indexer.forget(path)         # read whole now
        ls.project.open(path, params.text_document.text)
        ls._versions[path] = params.text_document.version
        ls.schedule(path, 0.0)

    @server.feature(L.TEXT_DOCUMENT_DID_CHANGE)
    @guarded()
    async def did_change(ls: KrlLanguageServer, params: L.DidChangeTextDocumentParams):
        path = path_of(params.text_document.uri)
        doc = ls.workspace.get_text_document(params.text_document.uri)
        ls.project.change(path, doc.source)
        ls._versions[path] = params.text_document.version
        ls.schedule(path)

    @server.feature(L.TEXT_DOCUMENT_DID_SAVE)
    @guarded()
    async def did_save(ls: KrlLanguageServer, params: L.DidSaveTextDocumentParams):
        ls.project.files_changed()
        ls.schedule(path_of(params.text_document.uri))

    @server.feature(L.TEXT_DOCUMENT_DID_CLOSE)
    @guarded()
    async def did_close(ls: KrlLanguageServer, params: L.DidCloseTextDocumentParams):
        path = path_of(params.text_document.uri)
        ls.project.close(path)
        ls._versions.pop(path, None)
        task = ls._pending.pop(path, None)
        if task is not None:
            task.cancel()
        ls.text_document_publish_diagnostics(L.PublishDiagnosticsParams(uri=params.text_document.uri, diagnostics=[]))
        for other in list(ls.project.docs):     # the others now see the file on disk again
            ls.schedule(other)

    @server.feature(L.WORKSPACE_DID_CHANGE_WATCHED_FILES)
    @guarded()
    async def watched(ls: KrlLanguageServer, params: L.DidChangeWatchedFilesParams):
        ls.project.files_changed()
        for path in list(ls.project.docs):
            ls.schedule(path)

    async def holding(ls: KrlLanguageServer, td):
        """(analysis, path) of the document, its analysis fresh; (None, path) when no analysis
        holds it."""
        path = path_of(td.uri)
        an = await ls.fresh(path)
        return (an, path) if an is not None and path in an.files else (None, path)

    async def place(ls: KrlLanguageServer, td, pos: L.Position):
        an, path = await holding(ls, td)
        if an is None:
            return None, None, 0, 0
        line, col = from_position(an.files[path].lines, pos, ls.codec())
        return an, path, line, col

    async def target(ls: KrlLanguageServer, td, pos: L.Position):
        """(analysis, the name under the cursor) or (None, None) when there is none."""
        an, path, line, col = await place(ls, td, pos)
        if an is None:
            return None, None
        t = _nav.resolve(an, path, line, col)
        return (an, t) if t is not None else (None, None)

    def location(ls: KrlLanguageServer, an: Analysis, p: _nav.Place) -> L.Location:
        return L.Location(uri=uri_of(p.path), range=to_range(an.files[p.path].lines, p.line, p.column, p.length, ls.codec()))

    @server.feature(L.TEXT_DOCUMENT_DEFINITION)
    @guarded()
    async def definition(ls: KrlLanguageServer, params: L.DefinitionParams):
        an, t = await target(ls, params.text_document, params.position)
        p = _nav.definition(an, t) if t is not None else None
        return [location(ls, an, p)] if p is not None else None

    @server.feature(L.TEXT_DOCUMENT_REFERENCES)
    @guarded(list)
    async def references(ls: KrlLanguageServer, params: L.ReferenceParams):
        an, t = await target(ls, params.text_document, params.position)
        if t is None:
            return []
        include = params.context.include_declaration if params.context is not None else True
        return [location(ls, an, p) for p in _nav.references(an, t, include)]

    @server.feature(L.TEXT_DOCUMENT_HOVER)
    @guarded()
    async def hover(ls: KrlLanguageServer, params: L.HoverParams):
        an, t = await target(ls, params.text_document, params.position)
        if t is None:
            return None
        text = _hover.hover_text(an, t)
        return L.Hover(contents=L.MarkupContent(kind=L.MarkupKind.Markdown, value=text)) if text else None

    @server.feature(L.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
    @guarded(list)
    async def document_symbol(ls: KrlLanguageServer, params: L.DocumentSymbolParams):
        an, path = await holding(ls, params.text_document)
        if an is None:
            return []
        lines, codec = an.files[path].lines, ls.codec()
        return [_convert.document_symbol(it, lines, codec) for it in _outline.document_symbols(an, path)]

    @server.feature(L.WORKSPACE_SYMBOL)
    @guarded(list)
    async def workspace_symbol(ls: KrlLanguageServer, params: L.WorkspaceSymbolParams):
        for path in list(ls._dirty):
            await ls.fresh(path)
        if not ls.project.analyses:         # nothing open yet: the folders the editor opened
            for folder in ls.folders():
                first = list_krl_files(folder, limit=1)
                if first:
                    await ls.fresh(norm(first[0]))
        codec = ls.codec()
        return [_convert.workspace_symbol(s, uri_of, codec)
                for s in _outline.workspace_symbols(list(ls.project.analyses.values()), params.query or "")]

    @server.feature(L.TEXT_DOCUMENT_FOLDING_RANGE)
    @guarded(list)
    async def folding_range(ls: KrlLanguageServer, params: L.FoldingRangeParams):
        an, path = await holding(ls, params.text_document)
        return [_convert.folding_range(f) for f in _folding.folding_ranges(an.files[path].lines)] if an is not None else []

    @server.feature(L.TEXT_DOCUMENT_COMPLETION, L.CompletionOptions(trigger_characters=[".", "$", "#"]))
    @guarded()
    async def completion(ls: KrlLanguageServer, params: L.CompletionParams):
        an, path, line, col = await place(ls, params.text_document, params.position)
        if an is None:
            return None
        return L.CompletionList(is_incomplete=False,
                                items=[_convert.completion(c) for c in _complete.complete(an, path, line, col)])

    _register_calls(server, place, uri_of)
    def refusing(step, an, *args):
        """`step(an, *args)`, a refusal (krl/lsp/rename.py Refused) sent as the request's error."""
        if an is None:
            raise RequestFailed("the file is not analysed yet")
        try:
            return step(an, *args)
        except _rename.Refused as exc:
            raise RequestFailed(str(exc)) from None

    @server.feature(L.TEXT_DOCUMENT_PREPARE_RENAME)
    @guarded()
    async def prepare_rename(ls: KrlLanguageServer, params: L.PrepareRenameParams):
        an, path, line, col = await place(ls, params.text_document, params.position)
        t = refusing(_rename.renamable, an, _nav.resolve(an, path, line, col) if an is not None else None)
        _, tok, _ = token_at(an.files[path].lines, line, col)
        start = tok.column + (1 if tok.word == "ENUMLITERAL" else 0)
        return L.PrepareRenamePlaceholder(
            range=to_range(an.files[path].lines, line, start, len(t.name), ls.codec()),
            placeholder=tok.text.lstrip("#"))

    @server.feature(L.TEXT_DOCUMENT_RENAME, L.RenameOptions(prepare_provider=True))
    @guarded()
    async def rename(ls: KrlLanguageServer, params: L.RenameParams):
        an, path, line, col = await place(ls, params.text_document, params.position)
        places = refusing(_rename.plan, an, _nav.resolve(an, path, line, col) if an is not None else None,
                          params.new_name)
        codec = ls.codec()
        return L.WorkspaceEdit(changes={
            uri_of(p): [L.TextEdit(range=to_range(an.files[p].lines, x.line, x.column, x.length, codec),
                                   new_text=params.new_name) for x in xs]
            for p, xs in places.items()})

    @server.feature(L.TEXT_DOCUMENT_INLAY_HINT)
    @guarded(list)
    async def inlay_hint(ls: KrlLanguageServer, params: L.InlayHintParams):
        an, path = await holding(ls, params.text_document)
        if an is None:
            return []
        lines = an.files[path].lines
        codec = ls.codec()
        out = []
        for h in _inlay.hints(an, path, params.range.start.line + 1, params.range.end.line + 1):
            io = h.kind == "io"
            out.append(L.InlayHint(
                position=to_range(lines, h.line, h.column, 0, codec).start, label=h.label,
                kind=L.InlayHintKind.Type if io else L.InlayHintKind.Parameter,
                padding_left=io, padding_right=not io, tooltip=h.tooltip or None))
        return out

    @server.feature(L.TEXT_DOCUMENT_SEMANTIC_TOKENS_FULL, L.SemanticTokensLegend(
        token_types=_semtokens.TYPES, token_modifiers=_semtokens.MODIFIERS))
    @guarded()
    async def semantic_tokens(ls: KrlLanguageServer, params: L.SemanticTokensParams):
        an, path = await holding(ls, params.text_document)
        if an is None:
            return L.SemanticTokens(data=[])
        return L.SemanticTokens(data=_semtokens.tokens(an, path, ls.codec()))

    @server.feature(L.TEXT_DOCUMENT_CODE_ACTION, L.CodeActionOptions(code_action_kinds=[L.CodeActionKind.QuickFix]))
    @guarded(list)
    async def code_action(ls: KrlLanguageServer, params: L.CodeActionParams):
        an, path = await holding(ls, params.text_document)
        if an is None:
            return []
        codec = ls.codec()
        out = []
        for fx in _actions.fixes(an, path, params.range.start.line + 1, params.range.end.line + 1):
            changes: dict[str, list[L.TextEdit]] = {}
            for e in fx.edits:
                lines = an.files[e.path].lines
                rng = L.Range(start=to_range(lines, e.line, e.column, 0, codec).start,
                              end=to_range(lines, e.end_line, e.end_column, 0, codec).start)
                changes.setdefault(uri_of(e.path), []).append(L.TextEdit(range=rng, new_text=e.text))
            d = fx.diagnostic
            out.append(L.CodeAction(title=fx.title, kind=L.CodeActionKind.QuickFix, is_preferred=fx.preferred,
                                    diagnostics=[lsp_diagnostic(d, an.files[d.path].lines, codec, uri_of)],
                                    edit=L.WorkspaceEdit(changes=changes)))
        return out

    @server.feature(L.TEXT_DOCUMENT_SIGNATURE_HELP, L.SignatureHelpOptions(trigger_characters=["(", ","]))
    @guarded()
    async def signature_help(ls: KrlLanguageServer, params: L.SignatureHelpParams):
        an, path, line, col = await place(ls, params.text_document, params.position)
        if an is None:
            return None
        sig = _signature.signature_at(an, path, line, col)
        if sig is None:
            return None
        return L.SignatureHelp(signatures=[L.SignatureInformation(
            label=sig.label, documentation=sig.documentation or None,
            parameters=[L.ParameterInformation(label=p) for p in sig.params])],
            active_signature=0, active_parameter=sig.active)

    @server.feature(L.TEXT_DOCUMENT_DOCUMENT_HIGHLIGHT)
    @guarded(list)
    async def document_highlight(ls: KrlLanguageServer, params: L.DocumentHighlightParams):
        an, t = await target(ls, params.text_document, params.position)
        if t is None:
            return []
        path = path_of(params.text_document.uri)
        lines = an.files[path].lines
        kinds = {DECL: L.DocumentHighlightKind.Text, WRITE: L.DocumentHighlightKind.Write}
        return [L.DocumentHighlight(range=to_range(lines, o.place.line, o.place.column, o.place.length, ls.codec()),
                                    kind=kinds.get(o.kind, L.DocumentHighlightKind.Read))
                for o in file_occurrences(an, path) if o.key == t.key]

    @server.feature(L.TEXT_DOCUMENT_FORMATTING)
    @guarded()
    async def formatting(ls: KrlLanguageServer, params: L.DocumentFormattingParams):
        doc = ls.workspace.get_text_document(params.text_document.uri)
        text = doc.source
        try:
            new = format_text(text)
        except Exception as exc:  # noqa: BLE001 - unparsable input: no edit, say why
            ls._report(f"krl lsp: not formatted: {type(exc).__name__}: {printable(exc)}", L.MessageType.Warning)
            return None
        if new == text:
            return []
        lines = text.split("\n")
        end = L.Position(line=len(lines) - 1, character=units(ls.codec(), lines[-1]))
        return [L.TextEdit(range=L.Range(start=L.Position(line=0, character=0), end=end), new_text=new)]

    return server


def _register_calls(server: KrlLanguageServer, place, uri_of) -> None:
    """Call hierarchy from the program map (krl/lsp/calls.py)."""
    @server.feature(L.TEXT_DOCUMENT_PREPARE_CALL_HIERARCHY)
    @guarded(list)
    async def prepare_call_hierarchy(ls: KrlLanguageServer, params: L.CallHierarchyPrepareParams):
        an, path, line, col = await place(ls, params.text_document, params.position)
        return [item(an, it, ls.codec()) for it in _calls.prepare(an, path, line, col)] if an is not None else []

    def lines_of(an: Analysis, path: str) -> list[str]:
        return an.files[path].lines if path in an.files else []

    def item(an: Analysis, it, codec) -> L.CallHierarchyItem:
        return _convert.call_item(it, lines_of(an, it.path), uri_of, codec)

    def ranges(an: Analysis, places, codec) -> list[L.Range]:
        return [_convert.call_range(p, lines_of(an, p.path), codec) for p in places]

    async def item_analysis(ls: KrlLanguageServer, it: L.CallHierarchyItem):
        an = await ls.fresh(path_of(it.uri))
        return (an, str(it.data)) if an is not None and it.data else (None, "")

    @server.feature(L.CALL_HIERARCHY_INCOMING_CALLS)
    @guarded(list)
    async def incoming_calls(ls: KrlLanguageServer, params: L.CallHierarchyIncomingCallsParams):
        an, nid = await item_analysis(ls, params.item)
        if an is None:
            return []
        codec = ls.codec()
        return [L.CallHierarchyIncomingCall(from_=item(an, it, codec), from_ranges=ranges(an, places, codec))
                for it, places in _calls.incoming(an, nid)]

    @server.feature(L.CALL_HIERARCHY_OUTGOING_CALLS)
    @guarded(list)
    async def outgoing_calls(ls: KrlLanguageServer, params: L.CallHierarchyOutgoingCallsParams):
        an, nid = await item_analysis(ls, params.item)
        if an is None:
            return []
        codec = ls.codec()
        return [L.CallHierarchyOutgoingCall(to=item(an, it, codec), from_ranges=ranges(an, places, codec))
                for it, places in _calls.outgoing(an, nid)]


def serve(log_file: str | None = None) -> None:
    """Run the server on stdin/stdout until the client says exit."""
    logging.basicConfig(filename=log_file, level=logging.INFO if log_file else logging.WARNING,
                        format="%(asctime)s %(name)s %(levelname)s %(message)s")
    TRACEBACKS["on"] = log_file is not None
    server = create_server()
    server.start_io()
    server.indexer.stop()
    # exit now, even when an analysis of a large file is still running in the worker thread;
    # exit code 0 after a `shutdown` request, else 1 (the LSP rule)
    code = 0 if getattr(server.protocol, "_shutdown", False) else 1
    logging.shutdown()
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):
        pass
    os._exit(code)
