"""Scanning a corpus: parse every KRL file with one grammar version, in worker processes.

A scan never hangs, never dies on one file and never lies about one: every entry of the corpus
gets a classified row. A parsed file is ``ok`` or ``syntax_error`` (or ``too_deep``/``too_long``
past a limit of krl/limits.py); a file that is not parsed is ``empty``, ``binary``,
``too_large``, ``unreadable``, ``not_regular`` (a FIFO, socket or device: never opened),
``symlink`` (never followed), ``timeout`` (the worker was killed after ``--timeout``) or
``internal_error`` (the parser raised, or its worker died); a folder that cannot be listed is an
``unreadable_folder`` row and one past :data:`krl.limits.MAX_FOLDER_DEPTH` a ``too_deep`` row.

Each file is read once in the main process (:func:`krl.source.read_limited`, no FIFO is
ever opened); the SHA-256 of those bytes keys the result cache, and the same bytes are what a
worker decodes and parses (:func:`parse_row`, the scan's one call into the parser). Workers are
a killable pool (krl/pool.py, pebble): a timeout kills the worker, whatever the parser is doing.

Results are cached per (front end, grammar sha, file sha) in the user cache directory, so a
repeated scan with an unchanged grammar only reads and hashes files. Cache entries are validated
when read: a corrupt or foreign file is ignored (one warning) and rebuilt; a cache folder that
cannot be written means a scan without cache (one warning). With ``use_cache=False`` the cache
folder is never touched.
"""

from __future__ import annotations

import hashlib
import json
import os
import sqlite3
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path


from krl.files import display_path
from krl.project import folder_entries
from krl.limits import PARSE_TIMEOUT_S
from krl.pool import default_jobs, run_tasks
from krl.source import read_limited, source_from_bytes
from krl.terminal import printable
from krl.syntax.parse import ParserBundle, default_bundle
from krl.syntax.engines import parse_source
from rich.progress import Progress
from krl.cluster import run_batches

CACHE_VERSION = "3"
CACHE_SCHEMA = "krl-scan-results"

# Rows that say nothing about (grammar, file): never cached, retried next time.
NOT_CACHED = frozenset({"timeout", "internal_error", "unreadable", "not_regular", "symlink",
                        "unreadable_folder", "too_deep_folder"})
STATUSES = frozenset({"ok", "syntax_error", "too_deep", "too_long", "empty", "binary", "too_large"}) | NOT_CACHED


@dataclass(slots=True)
class IssueRecord:
    """The parts of a SyntaxIssue that clustering and reports need (picklable, JSON-able)."""

    line: int
    column: int
    kind: str
    message: str
    offending: str
    offending_type: str
    expected: list[str]
    rule_stack: list[str]
    shape: list[str]
    line_text: str
    cascade: bool


_ISSUE_TYPES = {"line": int, "column": int, "kind": str, "message": str, "offending": str,
                "offending_type": str, "expected": list, "rule_stack": list, "shape": list,
                "line_text": str, "cascade": bool}


@dataclass(slots=True)
class FileResult:
    path: str                 # relative to the corpus root, '/' separators, undecodable bytes as \xNN
    bytes: int
    sha: str
    encoding: str = ""
    status: str = "ok"
    ok: bool = False
    seconds: float = 0.0
    issues: list[IssueRecord] = field(default_factory=list)
    detail: str = ""          # why a file was not parsed ("a FIFO (never opened)", "killed after 30 s")

    def to_json(self) -> dict:
        return asdict(self)

    @classmethod
    def from_json(cls, obj: dict) -> "FileResult":
        obj = dict(obj)
        obj["issues"] = [IssueRecord(**i) for i in obj.get("issues", [])]
        return cls(**obj)


_ROW_TYPES = {"path": str, "bytes": int, "sha": str, "encoding": str, "status": str, "ok": bool,
              "seconds": (int, float), "issues": list, "detail": str}


def valid_row(obj: object, sha: str) -> bool:
    """True when `obj` is a cached row of this schema for the file hashed `sha`: exactly the
    fields of :class:`FileResult` (and of :class:`IssueRecord` for each issue), each of its type."""
    def fits(o: object, types: dict) -> bool:
        return (isinstance(o, dict) and set(o) == set(types)
                and all(isinstance(o[k], t) for k, t in types.items()))

    if not fits(obj, _ROW_TYPES) or obj["sha"] != sha or obj["status"] not in STATUSES:
        return False
    for issue in obj["issues"]:
        if not fits(issue, _ISSUE_TYPES):
            return False
        if not all(isinstance(x, str) for k in ("expected", "rule_stack", "shape") for x in issue[k]):
            return False
    return True


def discover(corpus: Path) -> list[Path]:
    """The regular .src/.dat/.sub files under corpus (any letter case), in walk order
    (krl/files.py: iterative, links never followed; krl/project.py ``folder_entries``: a
    controller archive's C and Log Files left out, as the scan leaves them)."""
    return [e.path for e in folder_entries(corpus) if e.kind == "file"]


def grammar_sha(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def front_end_sha() -> str:
    """Hash of the parse front end (krl/syntax/*.py except generated code).

    A cached result depends on the grammar, the file and how errors are recovered and
    recorded, so a change of the front end invalidates the cache too.
    """
    h = hashlib.sha256(CACHE_VERSION.encode())
    syntax_dir = Path(__file__).resolve().parents[1] / "krl" / "syntax"
    for p in sorted(syntax_dir.glob("*.py")):
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()


# ----------------------------------------------------------------------- worker side

_BUNDLE = None
_BUNDLE_DIR: tuple[str | None] | None = None


def _init_worker(parser_dir: str | None) -> None:
    """Load the parser of `parser_dir` (None: the working tree's). The scan calls it in the
    main process first, so that a missing parser is one clear error there and the forked
    workers inherit the loaded parser (then this is a no-op in them)."""
    global _BUNDLE, _BUNDLE_DIR
    if _BUNDLE_DIR == (parser_dir,):
        return

    _BUNDLE = ParserBundle.from_directory(parser_dir, tag="scan") if parser_dir else default_bundle()
    _BUNDLE_DIR = (parser_dir,)


def parse_row(rel_path: str, data: bytes, sha: str) -> FileResult:
    """Decode and parse the bytes of one file: the scan's one call into the parser."""

    source = source_from_bytes(rel_path, data, sha)
    row = FileResult(rel_path, source.size, sha, source.encoding, source.status, detail=source.detail)
    if source.status != "ok":
        return row
    result = parse_source(source, _BUNDLE, keep_tree=False)
    row.ok = result.ok
    row.status = result.status
    row.issues = [IssueRecord(i.line, i.column, i.kind, i.message, i.offending, i.offending_type,
                              i.expected, i.rule_stack, i.line_shape, i.line_text[:300], i.cascade)
                  for i in result.errors]
    return row


def scan_bytes(rel_path: str, data: bytes, sha: str) -> FileResult:
    """Parse one file in a worker. Never raises: an exception becomes an internal_error row."""
    start = time.perf_counter()
    try:
        row = parse_row(rel_path, data, sha)
    except Exception as exc:  # noqa: BLE001 - one bad file never stops a scan
        row = failed_row(rel_path, len(data), sha, "internal_error", f"{type(exc).__name__}: {exc}")
    row.seconds = round(time.perf_counter() - start, 4)
    return row


def failed_row(rel_path: str, size: int, sha: str, status: str, detail: str) -> FileResult:
    """The row of a file whose parse did not end normally (timeout, internal error): one issue
    of kind "internal", which reports list by file and never cluster."""
    return FileResult(rel_path, size, sha, "", status, False, 0.0,
                      [IssueRecord(0, 0, "internal", detail, "", "", [], [], ["internal"], "", False)],
                      detail)


# ----------------------------------------------------------------------- cache

from krl.store import cache_dir  # noqa: E402 - the one user cache folder (re-exported)


_WARNED: set[str] = set()


def warn(message: str) -> None:
    """A warning of the scan on stderr, once per message and process (never one per file)."""
    if message not in _WARNED:
        _WARNED.add(message)
        print(f"warning: {printable(message)}", file=sys.stderr)


class ResultCache:
    """Per-file results keyed by (grammar sha, file sha): one SQLite database per grammar and
    front end, ``results/<front end>-<grammar>.sqlite``, with a ``meta`` table (schema, version)
    and a ``results`` table (sha -> the row as JSON). Rows are read when a file is met and
    written in transactions, so the cache costs no memory per file whatever the corpus size
    (issue 17; it was one JSON document held whole).

    Never raises: a database of another schema or version, or one that is not a database, is
    ignored and rebuilt with one warning; entries that fail validation (:func:`valid_row`) are
    parsed again and counted in one warning; a cache folder or database that cannot be used
    means a scan without cache, with one warning. Several scans may share a cache (SQLite's
    locking; a writer waits up to LOCK_WAIT_S, and writes COMMIT_EVERY rows at a time in one
    short transaction)."""

    LOCK_WAIT_S = 30.0
    COMMIT_EVERY = 500

    def __init__(self, gsha: str, enabled: bool = True, warn: Callable[[str], None] = warn):
        self.enabled = enabled
        self.warn = warn
        self.db: sqlite3.Connection | None = None
        self.path: Path | None = None
        self.pending: dict[str, str] = {}     # sha -> row JSON, written COMMIT_EVERY at a time
        self.corrupt = 0
        self.lock = threading.Lock()
        if not enabled:
            return      # --no-cache: the cache folder is never touched
        try:
            self.path = cache_dir() / "results" / f"{front_end_sha()[:12]}-{gsha[:32]}.sqlite"
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            self._disable(f"cache folder not usable ({exc.strerror or exc}); running without a cache")
            return
        self._open()

    def _disable(self, why: str) -> None:
        self.enabled = False
        self._close()
        self.warn(why)

    def _close(self) -> None:
        if self.db is not None:
            try:
                self.db.close()
            except sqlite3.Error:
                pass
        self.db = None

    def _connect(self) -> sqlite3.Connection:
        assert self.path is not None
        db = sqlite3.connect(self.path, timeout=self.LOCK_WAIT_S, check_same_thread=False)
        db.execute("CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL)")
        db.execute("CREATE TABLE IF NOT EXISTS results (sha TEXT PRIMARY KEY, row TEXT NOT NULL)")
        db.execute("INSERT OR IGNORE INTO meta VALUES ('schema', ?), ('version', ?)", (CACHE_SCHEMA, CACHE_VERSION))
        db.commit()
        meta = dict(db.execute("SELECT key, value FROM meta").fetchall())
        if meta != {"schema": CACHE_SCHEMA, "version": CACHE_VERSION}:
            db.close()
            raise sqlite3.DatabaseError("of another schema or version")
        return db

    def _open(self) -> None:
        assert self.path is not None
        try:
            self.db = self._connect()
            return
        except sqlite3.OperationalError as exc:     # locked past LOCK_WAIT_S, cannot open, disk full
            self._disable(f"cache file {self.path} not usable ({exc}); running without a cache")
            return
        except sqlite3.DatabaseError:               # not a database, or another schema or version
            self.warn(f"cache file {self.path} is corrupt or of another version; ignored and rebuilt")
        except (sqlite3.Error, OSError) as exc:
            self._disable(f"cache file {self.path} not usable ({exc}); running without a cache")
            return
        try:
            self.path.unlink(missing_ok=True)
            self.db = self._connect()
        except (sqlite3.Error, OSError) as exc:
            self._disable(f"cache file {self.path} not usable ({exc}); running without a cache")

    def get(self, sha: str, rel_path: str) -> FileResult | None:
        if not self.enabled or self.db is None:
            return None
        with self.lock:
            found = self.pending.get(sha)
            if found is None:
                try:
                    row = self.db.execute("SELECT row FROM results WHERE sha = ?", (sha,)).fetchone()
                except sqlite3.Error as exc:
                    self._disable(f"cache file {self.path} not readable ({exc}); running without a cache")
                    return None
                found = row[0] if row is not None else None
        if found is None:
            return None
        try:
            obj = json.loads(found)
        except (ValueError, RecursionError, TypeError):
            obj = None
        if not valid_row(obj, sha):
            self.corrupt += 1
            return None     # parsed again; its new row replaces the entry
        res = FileResult.from_json(obj)
        res.path = rel_path
        return res

    def put(self, res: FileResult) -> None:
        if not self.enabled or self.db is None or res.status in NOT_CACHED or not res.sha:
            return  # not a property of (grammar, file): retry next time
        with self.lock:
            self.pending[res.sha] = json.dumps(res.to_json())
            if len(self.pending) >= self.COMMIT_EVERY:
                self._flush()

    def _flush(self) -> None:
        """Write the pending rows in one short transaction (the write lock is never held while
        files are parsed, so concurrent scans wait for each other only that long)."""
        if not self.pending or self.db is None:
            return
        try:
            with self.db:
                self.db.executemany("INSERT OR REPLACE INTO results VALUES (?, ?)", self.pending.items())
        except sqlite3.Error as exc:
            self._disable(f"cache file {self.path} not written ({exc}); the next scan parses again")
        self.pending = {}

    def save(self) -> None:
        """Commit and close; the one warning about corrupt entries met."""
        if self.corrupt:
            self.warn(f"{self.corrupt} corrupt entries in cache file {self.path}; "
                      "ignored, their files were parsed again")
            self.corrupt = 0
        if not self.enabled or self.db is None:
            return
        with self.lock:
            self._flush()
            self._close()


# ----------------------------------------------------------------------- the scan

def scan(corpus: Path, gsha: str, parser_dir: str | None = None, jobs: int | None = None,
         use_cache: bool = True, progress: bool = True, timeout: float | None = PARSE_TIMEOUT_S,
         in_process: bool = False, on_row: Callable[[int, FileResult], None] | None = None,
         keep: bool = True, warn: Callable[[str], None] = warn,
         scheduler: str | None = None) -> list[FileResult]:
    """Classify and parse every KRL entry under corpus; one FileResult per entry, in walk order.

    parser_dir: a directory of generated parser code (None: the working tree's parser).
    jobs: worker processes (default: the number of cores); timeout: seconds per file, after
    which its worker is killed (row ``timeout``); in_process: parse here, without workers and
    without a timeout (only for callers that already run in a worker). on_row: called with the
    walk index and the row of each entry as it is known (classified entries and cache hits
    first, parsed files as they finish, so in any order). keep=False: the rows are only given
    to on_row and the scan returns [] (memory stays flat whatever the corpus size; the cache,
    when used, still holds one entry per file). scheduler: the address of a Dask scheduler
    (``tcp://HOST:8786``): the files are parsed on its cluster, in batches, with the same rows
    (krl/cluster.py; raises SchedulerError when it cannot be reached). Never raises
    for what it finds in the corpus.
    """

    corpus = Path(corpus)
    _init_worker(parser_dir)      # here first: a missing parser fails once, with its own message
    entries = folder_entries(corpus)     # an archive's C and Log Files are no program (rule 8)
    rows: list[FileResult | None] = [None] * len(entries) if keep else []
    cache = ResultCache(gsha, enabled=use_cache, warn=warn)
    files = [idx for idx, e in enumerate(entries) if e.kind == "file"]
    # Big files first, so that the pool's tail is short.
    files.sort(key=lambda i: -entries[i].size)
    bar = Progress(transient=True, disable=not progress or len(files) < 50)
    bar_task = bar.add_task("parsing", total=len(files))

    def record(idx: int, row: FileResult) -> None:
        if keep:
            rows[idx] = row
        if entries[idx].kind == "file":
            bar.advance(bar_task)
        if on_row is not None:
            on_row(idx, row)

    for idx, e in enumerate(entries):
        if e.kind != "file":
            status = "too_deep_folder" if e.kind == "too_deep" else e.kind
            record(idx, FileResult(display_path(e.rel), e.size, "", "", status, detail=e.message))

    pending: dict[int, tuple[str, int, str]] = {}

    def tasks():
        for idx in files:
            e = entries[idx]
            rel = display_path(e.rel)
            data, status, detail, size = read_limited(e.path, follow_symlinks=False)
            if data is None:
                record(idx, FileResult(rel, size, "", "", status, detail=detail))
                continue
            sha = hashlib.sha256(data).hexdigest()
            hit = cache.get(sha, rel)
            if hit is not None:
                record(idx, hit)
                continue
            pending[idx] = (rel, len(data), sha)
            yield idx, (rel, data, sha)

    with bar:
        if scheduler is not None:

            outcomes = run_batches(scheduler, scan_bytes, tasks(), timeout=timeout,
                                   initializer=_init_worker, initargs=(parser_dir,), name="krl-scan")
        else:
            outcomes = run_tasks(scan_bytes, tasks(), jobs=jobs or default_jobs(), timeout=timeout,
                                 initializer=_init_worker, initargs=(parser_dir,), in_process=in_process)
        for out in outcomes:
            rel, size, sha = pending.pop(out.key)
            row = out.value if out.status == "done" else failed_row(rel, size, sha, out.status, out.detail)
            cache.put(row)
            record(out.key, row)
    cache.save()
    return [r for r in rows if r is not None]
