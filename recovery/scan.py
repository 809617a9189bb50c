"""Scanning a corpus: parse every KRL file with one grammar version, in a process pool.

A scan never dies on one file: each file gets a classified row (ok, syntax_error, empty,
binary, too_large, timeout, unreadable, internal_error). Results are cached per
(grammar sha, file sha) in the user cache directory, so a repeated scan with an unchanged
grammar only hashes files.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

import platformdirs

from krl.syntax.source import is_krl_file, read_source

PARSE_TIMEOUT_S = 30
CACHE_VERSION = "1"


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


@dataclass(slots=True)
class FileResult:
    path: str                 # relative to the corpus root, with '/' separators
    bytes: int
    sha: str
    encoding: str = ""
    status: str = "ok"
    ok: bool = False
    seconds: float = 0.0
    issues: list[IssueRecord] = field(default_factory=list)

    @property
    def first_error(self) -> IssueRecord | None:
        return self.issues[0] if self.issues else None

    def to_json(self) -> dict:
        return asdict(self)

    @classmethod
    def from_json(cls, obj: dict) -> "FileResult":
        obj = dict(obj)
        obj["issues"] = [IssueRecord(**i) for i in obj.get("issues", [])]
        return cls(**obj)


def discover(corpus: Path) -> list[Path]:
    """All .src/.dat/.sub files under corpus (any letter case), sorted; symlinks not followed."""
    found = []
    for root, dirs, files in os.walk(corpus):
        dirs.sort()
        for name in sorted(files):
            p = Path(root) / name
            if is_krl_file(p) and not p.is_symlink():
                found.append(p)
    return found


def file_sha(path: Path) -> str:
    h = hashlib.sha256()
    try:
        h.update(path.read_bytes())
    except OSError:
        return "unreadable"
    return h.hexdigest()


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


def _init_worker(parser_dir: str | None) -> None:
    global _BUNDLE
    from krl.syntax.parse import ParserBundle, default_bundle  # noqa: PLC0415

    _BUNDLE = ParserBundle.from_directory(parser_dir, tag="scan") if parser_dir else default_bundle()


class _Timeout(BaseException):
    """The parse timeout (SIGALRM). A BaseException, so that no ``except Exception`` on the
    way (a handler in the parser, its error listener) can swallow it."""


def _on_alarm(signum, frame):  # noqa: ARG001
    raise _Timeout()


def scan_one(args: tuple[str, str, str, int]) -> FileResult:
    """Parse one file in a worker. Never raises: failures become classified rows."""
    import time  # noqa: PLC0415

    from krl.syntax.engines import parse_source  # noqa: PLC0415  (KRL_ENGINE: python, java, auto)

    abs_path, rel_path, sha, timeout = args
    start = time.perf_counter()
    source = read_source(abs_path)
    row = FileResult(rel_path, source.size, sha, source.encoding, source.status)
    if source.status != "ok":
        return row
    old = signal.signal(signal.SIGALRM, _on_alarm) if timeout else None
    if timeout:
        signal.alarm(timeout)
    try:
        result = parse_source(source, _BUNDLE, keep_tree=False)
        row.ok = result.ok
        row.status = result.status
        row.issues = [IssueRecord(i.line, i.column, i.kind, i.message, i.offending, i.offending_type,
                                  i.expected, i.rule_stack, i.line_shape, i.line_text[:300], i.cascade)
                      for i in result.errors]
    except _Timeout:
        row.status = "timeout"
    except Exception as exc:  # noqa: BLE001 - one bad file never stops a scan
        row.status = "internal_error"
        row.issues = [IssueRecord(0, 0, "internal", f"{type(exc).__name__}: {exc}", "", "", [], [],
                                  ["internal"], "", False)]
    finally:
        if timeout:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, old)
    row.seconds = round(time.perf_counter() - start, 4)
    return row


# ----------------------------------------------------------------------- cache

def cache_dir() -> Path:
    """The user cache directory (never inside the repository)."""
    d = Path(os.environ.get("KRL_CACHE_DIR") or platformdirs.user_cache_dir("krl-tools"))
    d.mkdir(parents=True, exist_ok=True)
    return d


class ResultCache:
    """Per-file results keyed by (grammar sha, file sha), one JSON file per grammar."""

    def __init__(self, gsha: str, enabled: bool = True):
        self.enabled = enabled
        self.path = cache_dir() / "results" / f"{front_end_sha()[:12]}-{gsha[:32]}.json"
        self.data: dict[str, dict] = {}
        if enabled and self.path.exists():
            try:
                self.data = json.loads(self.path.read_text())
            except (OSError, ValueError):
                self.data = {}
        self.dirty = False

    def get(self, sha: str, rel_path: str) -> FileResult | None:
        if not self.enabled:
            return None
        obj = self.data.get(sha)
        if obj is None:
            return None
        res = FileResult.from_json(obj)
        res.path = rel_path
        return res

    def put(self, res: FileResult) -> None:
        if res.status in ("timeout", "internal_error", "unreadable"):
            return  # not a property of (grammar, file): retry next time
        self.data[res.sha] = res.to_json()
        self.dirty = True

    def save(self) -> None:
        if self.enabled and self.dirty:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            tmp = self.path.with_suffix(".tmp")
            tmp.write_text(json.dumps(self.data))
            tmp.replace(self.path)


def scan(corpus: Path, gsha: str, parser_dir: str | None = None, jobs: int | None = None,
         use_cache: bool = True, progress: bool = True,
         timeout: int = PARSE_TIMEOUT_S) -> list[FileResult]:
    """Parse every KRL file under corpus; returns one FileResult per file, in path order.

    parser_dir: a directory of generated parser code (None: the working tree's parser).
    """
    corpus = Path(corpus)
    paths = discover(corpus)
    cache = ResultCache(gsha, enabled=use_cache)
    results: dict[int, FileResult] = {}
    todo: list[tuple[int, tuple[str, str, str, int]]] = []
    for idx, p in enumerate(paths):
        rel = p.relative_to(corpus).as_posix()
        sha = file_sha(p)
        hit = cache.get(sha, rel)
        if hit is not None:
            results[idx] = hit
        else:
            todo.append((idx, (str(p), rel, sha, timeout)))
    if todo:
        jobs = jobs or os.cpu_count() or 1
        # Big files first, so that the pool's tail is short.
        todo.sort(key=lambda item: -_size(item[1][0]))
        if jobs == 1:
            _init_worker(parser_dir)
            iterator = ((idx, scan_one(args)) for idx, args in todo)
            _collect(iterator, results, cache, len(todo), progress)
        else:
            with ProcessPoolExecutor(max_workers=jobs, initializer=_init_worker,
                                     initargs=(parser_dir,)) as pool:
                futures = pool.map(scan_one, [a for _, a in todo], chunksize=4)
                _collect(zip((i for i, _ in todo), futures), results, cache, len(todo), progress)
        cache.save()
    return [results[i] for i in range(len(paths))]


def _size(path: str) -> int:
    try:
        return os.path.getsize(path)
    except OSError:
        return 0


def _collect(pairs, results, cache, total, progress) -> None:
    from rich.progress import Progress  # noqa: PLC0415

    with Progress(transient=True, disable=not progress or total < 50) as bar:
        task = bar.add_task("parsing", total=total)
        for idx, res in pairs:
            results[idx] = res
            cache.put(res)
            bar.advance(task)
