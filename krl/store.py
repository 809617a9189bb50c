"""The one store of parse and check results kept across processes, shared by every command
(``krl lsp``, ``krl run``, ``krl debug``, ``krl check``; docs/security.md, "The cache").

It is one SQLite database per version of the front end, ``cache_dir()/front-end/<version>.sqlite``
(:func:`front_end_version` hashes the grammar and every source and data file of the ``krl``
package, so any change of the parser, the AST, the checker or the codec starts a new database
and an old one is never read). A row is (kind, key, SHA-256 of the data, data, last use):

* kind ``parse``: one per file content, keyed by :func:`parse_key` (the SHA-256 of the file's
  bytes and whether it is a data list); the data is the file's parse encoded by
  krl/parsecache.py (msgpack by a schema: AST node classes by number, fields in order,
  diagnostics by their fields);
* kind ``check``: one per workspace, keyed by :func:`check_key` (every file's path and content
  hash); the data is the workspace's diagnostics (the language server shows them at once).

This module stores and returns bytes only; it never unpickles or evaluates anything it reads.
The data of a row is returned only when its SHA-256 matches; what a codec cannot decode is a
corrupt entry, and the caller makes the result anew (a silent recompute, counted in
:attr:`Store.corrupt`). A damaged database (a truncated file, garbage, a malformed page:
SQLite's SQLITE_CORRUPT or SQLITE_NOTADB, when it is opened or at any query) is removed and made
anew, once per process, with one warning on stderr (issue 74: before, it turned the cache off for
good). A database that cannot be opened, read or written otherwise (a full disk, a read-only
folder, or damaged again) turns the store off for the process (said once in the ``krl.store``
log): commands then parse and check as without a cache, and never fail for it.
The database is kept within :data:`krl.limits.MAX_CACHE_BYTES` (past it the least recently used
quarter of the rows goes), an entry larger than :data:`krl.limits.MAX_CACHE_ENTRY_BYTES` is not
kept (nor read: such a row is corrupt). The cache root (:func:`cache_dir`) and its
``front-end`` folder are created with mode 0700 (the database with the user's umask, in that
folder). When a store opens, :func:`tidy` removes, once per process, other versions'
databases unused for 7 days and the folders earlier versions left. ``KRL_STORE=0`` (or ``KRL_LSP_NO_CACHE``) turns the store off.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import shutil
import sqlite3
import sys
import threading
import time
from pathlib import Path

from krl.limits import MAX_CACHE_BYTES, MAX_CACHE_ENTRY_BYTES
import platformdirs

log = logging.getLogger("krl.store")
log.addHandler(logging.NullHandler())   # a command's standard error never gets it unless logging is set up
#: the codec's name and version: part of :func:`front_end_version`
CODEC = "krl-store 3 (msgpack by schema; parse entries' notes without a path)"
LOCK_WAIT_S = 5.0
#: s: an entry's last use is kept to this precision (Store.get writes it only when older)
USED_RESOLUTION_S = 3600.0
#: another front-end version's database not used for this long (by its mtime) is removed
UNUSED_DATABASE_S = 7 * 24 * 3600.0
#: folders of the cache root that earlier versions wrote (their serialized results) and nothing reads now
OBSOLETE_FOLDERS = ("lsp", "stored")
KRL_ROOT = Path(__file__).resolve().parent
GRAMMAR = KRL_ROOT.parent / "grammar" / "KRL.g4"


def cache_dir() -> Path:
    """The user cache folder (``$KRL_CACHE_DIR``, else the platform's user cache folder of
    krl-tools; never inside the repository), created here with mode 0700 (a folder that exists
    is left as it is). Raises OSError when it cannot be created."""

    d = Path(os.environ.get("KRL_CACHE_DIR") or platformdirs.user_cache_dir("krl-tools"))
    d.mkdir(parents=True, exist_ok=True, mode=0o700)
    return d


_TIDIED: set[str] = set()


def tidy(root: Path, current: str) -> list[Path]:
    """Remove from the cache root `root` what no process of this version reads: the databases
    of other front-end versions (``front-end/<v>.sqlite`` and its journal files, `current`
    being this version's file name) whose newest file was not modified for
    :data:`UNUSED_DATABASE_S` (7 days), and the folders :data:`OBSOLETE_FOLDERS` of earlier
    versions (their serialized results). Only regular files and folders inside `root` are removed; a
    symbolic link is never followed nor removed. Once per root and process; never raises (what
    cannot be removed stays). Returns what was removed."""
    key = str(root)
    if key in _TIDIED:
        return []
    _TIDIED.add(key)
    removed: list[Path] = []
    try:
        cutoff = time.time() - UNUSED_DATABASE_S
        groups: dict[str, list[os.DirEntry]] = {}
        for e in databases(root):
            stem = e.name.partition(".sqlite")[0]
            if stem != current.partition(".sqlite")[0]:
                groups.setdefault(stem, []).append(e)
        for files in groups.values():
            if max(e.stat(follow_symlinks=False).st_mtime for e in files) < cutoff:
                for e in files:
                    try:
                        os.unlink(e.path)
                        removed.append(Path(e.path))
                    except OSError:
                        pass
        removed += remove_obsolete(root)
    except OSError as exc:
        log.info("the cache folder was not tidied: %s", exc)
    if removed:
        log.info("removed from the cache folder: %s", ", ".join(map(str, removed)))
    return removed


def databases(root: Path) -> list[os.DirEntry]:
    """The databases of every front-end version in the cache root `root` with their journal
    files (``front-end/<v>.sqlite*``): regular files only, a symbolic link never followed (nor
    the folder, when it is one). Raises OSError when the folder cannot be listed."""
    front = root / "front-end"
    if not front.is_dir() or front.is_symlink():
        return []
    with os.scandir(front) as it:
        return [e for e in it if ".sqlite" in e.name and not e.name.startswith(".sqlite")
                and e.is_file(follow_symlinks=False)]


def remove_obsolete(root: Path) -> list[Path]:
    """Remove the folders :data:`OBSOLETE_FOLDERS` of the cache root `root` (a symbolic link is
    never followed nor removed); the ones removed."""
    removed = []
    for name in OBSOLETE_FOLDERS:
        d = root / name
        if d.is_dir() and not d.is_symlink():
            shutil.rmtree(d, ignore_errors=True)     # never follows a link inside (fd-based on POSIX)
            if not d.exists():
                removed.append(d)
    return removed


_VERSION: list[str] = []


def front_end_version() -> str:
    """A hash of everything a stored entry depends on: the codec, the grammar the parser was
    generated from (grammar/KRL.g4) and every .py/.yaml/.java file of the ``krl`` package but
    the generated parser (made from that grammar); computed once per process."""
    if not _VERSION:
        h = hashlib.sha256(CODEC.encode())
        try:
            h.update(GRAMMAR.read_bytes())
        except OSError:
            h.update(b"no grammar")
        for p in sorted(KRL_ROOT.rglob("*")):
            if p.suffix in (".py", ".yaml", ".java") and "generated" not in p.parts and p.is_file():
                h.update(str(p.relative_to(KRL_ROOT)).encode())
                h.update(p.read_bytes())
        _VERSION.append(h.hexdigest())
    return _VERSION[0]


def parse_key(sha: str, path: str) -> str:
    """The key of a file's parse: its content hash and whether it is a data list (the only
    thing of its name the parse depends on)."""
    return f"{sha}:{'dat' if str(path).lower().endswith('.dat') else 'src'}"


def check_key(files: list[tuple[str, str]], skipped: list[tuple[str, str]]) -> str:
    """The key of a workspace's check: (path, content hash) of its files in order, and the
    (path, reason) of the entries not read."""
    h = hashlib.sha256()
    for path, sha in files:
        h.update(f"f\t{path}\t{sha}\n".encode("utf-8", "surrogatepass"))
    for path, why in skipped:
        h.update(f"s\t{path}\t{why}\n".encode("utf-8", "surrogatepass"))
    return h.hexdigest()


def enabled() -> bool:
    """False when the user turned the store off (``KRL_STORE=0``, ``KRL_LSP_NO_CACHE``)."""
    return os.environ.get("KRL_STORE", "1") != "0" and not os.environ.get("KRL_LSP_NO_CACHE")


@contextlib.contextmanager
def turned_off():
    """The store off for the block (``KRL_STORE=0`` while it runs, so worker processes started in
    it inherit it): a command's ``--no-cache`` never touches the cache folder, not even for the
    data tables (krl/semantics/builtins.py reads them through the store)."""
    before = os.environ.get("KRL_STORE")
    os.environ["KRL_STORE"] = "0"
    try:
        yield
    finally:
        if before is None:
            os.environ.pop("KRL_STORE", None)
        else:
            os.environ["KRL_STORE"] = before


#: SQLite's result codes of a damaged database file: SQLITE_CORRUPT, SQLITE_NOTADB
_DAMAGED = (11, 26)
_WARNED: set[str] = set()


def damaged(exc: sqlite3.Error) -> bool:
    """True when `exc` says the database file is damaged (not a locked or full database)."""
    return (getattr(exc, "sqlite_errorcode", None) or 0) & 0xFF in _DAMAGED


def _warn_once(text: str) -> None:
    """Print `text` on stderr once per process (and to the ``krl.store`` log)."""
    log.warning("%s", text)
    if text not in _WARNED:
        _WARNED.add(text)
        print(text, file=sys.stderr)


class Store:
    """The database (see the module docstring): bytes by (kind, key); thread-safe; never
    raises. `folder`: the cache folder (default :func:`cache_dir`)."""

    def __init__(self, folder: Path | None = None, enabled: bool = True) -> None:
        self.db: sqlite3.Connection | None = None
        self.lock = threading.Lock()
        self.path: Path | None = None
        self.hits = self.misses = self.corrupt = 0
        self.rebuilt = False
        if not enabled or not globals()["enabled"]():
            return
        try:
            root = folder or cache_dir()
            root.mkdir(parents=True, exist_ok=True, mode=0o700)
            folder = root / "front-end"
            folder.mkdir(parents=True, exist_ok=True, mode=0o700)
            self.path = folder / f"{front_end_version()[:24]}.sqlite"
            tidy(root, self.path.name)
            try:
                self.db = self._open()
            except sqlite3.DatabaseError as exc:
                if not damaged(exc):
                    raise
                self._rebuild(exc)
        except (OSError, sqlite3.Error) as exc:
            self._off(f"the cache is not used: {exc}")

    def _open(self) -> sqlite3.Connection:
        db = sqlite3.connect(self.path, timeout=LOCK_WAIT_S, check_same_thread=False)
        try:
            db.execute("CREATE TABLE IF NOT EXISTS entries (kind TEXT, key TEXT, digest BLOB, data BLOB, "
                       "used REAL, PRIMARY KEY (kind, key))")
            db.execute("SELECT COUNT(*) FROM entries").fetchone()   # reads the table's pages: a cut file fails here
            db.commit()
        except sqlite3.Error:
            db.close()
            raise
        return db

    def _rebuild(self, exc: sqlite3.Error) -> None:
        """The database is damaged (truncated, garbage, malformed): it is removed and made anew,
        once per process, with one warning on stderr. A second failure turns the store off."""
        self._close()
        if self.rebuilt:
            self._off(f"the cache is not used: {exc}")
            return
        self.rebuilt = True
        _warn_once(f"krl: warning: the parse cache {self.path} was damaged ({exc}); it is rebuilt")
        for suffix in ("", "-journal", "-wal", "-shm"):
            with contextlib.suppress(FileNotFoundError):
                os.unlink(f"{self.path}{suffix}")
        self.db = self._open()

    def _failed(self, exc: sqlite3.Error, what: str) -> None:
        """A query failed: a damaged database is rebuilt (:meth:`_rebuild`), anything else (a
        full disk, a lock held too long) turns the store off for the process."""
        if damaged(exc):
            try:
                self._rebuild(exc)
                return
            except (OSError, sqlite3.Error) as again:
                exc = again
        self._off(f"{what}: {exc}")

    def _off(self, why: str) -> None:
        log.warning("%s", why)
        self._close()

    def _close(self) -> None:
        db, self.db = self.db, None
        if db is not None:
            try:
                db.close()
            except sqlite3.Error:
                pass

    def get(self, kind: str, keys: list[str]) -> dict[str, bytes]:
        """The verified data of the entries of `kind` among `keys` (a row whose data does not
        match its digest, or is larger than MAX_CACHE_ENTRY_BYTES, is counted corrupt and left
        out)."""
        out: dict[str, bytes] = {}
        if self.db is None or not keys:
            return out
        # the last use is written again only when it is older than USED_RESOLUTION_S: the
        # trim's order needs no finer time, and a lookup of entries used lately writes nothing
        now = time.time()
        stale = now - USED_RESOLUTION_S
        touch: list[str] = []
        with self.lock:
            try:
                for i in range(0, len(keys), 500):
                    part = keys[i:i + 500]
                    # data past the entry limit (never written so: planted) is not even read
                    rows = self.db.execute(
                        "SELECT key, digest, CASE WHEN LENGTH(data) <= ? THEN data END, used FROM entries "
                        f"WHERE kind = ? AND key IN ({','.join('?' * len(part))})",
                        (MAX_CACHE_ENTRY_BYTES, kind, *part)).fetchall()
                    for key, digest, data, used in rows:
                        if isinstance(data, bytes) and hashlib.sha256(data).digest() == digest:
                            out[key] = data
                            if not isinstance(used, (int, float)) or used < stale:
                                touch.append(key)
                        else:
                            self.corrupt += 1
                if touch:
                    self.db.executemany("UPDATE entries SET used = ? WHERE kind = ? AND key = ?",
                                        [(now, kind, k) for k in touch])
                    self.db.commit()
            except sqlite3.Error as exc:
                self._failed(exc, "the cache is not used")
        self.hits += len(out)
        self.misses += len(keys) - len(out)
        return out

    def put(self, kind: str, items: dict[str, bytes]) -> None:
        """Keep `items` (key -> data; an entry past MAX_CACHE_ENTRY_BYTES is not kept)."""
        items = {k: v for k, v in items.items() if len(v) <= MAX_CACHE_ENTRY_BYTES}
        if self.db is None or not items:
            return
        now = time.time()
        with self.lock:
            try:
                self.db.executemany("INSERT OR REPLACE INTO entries VALUES (?, ?, ?, ?, ?)",
                                    [(kind, k, hashlib.sha256(v).digest(), v, now) for k, v in items.items()])
                self.db.commit()
                self._trim()
            except sqlite3.Error as exc:
                self._failed(exc, "the cache is not written")

    def _trim(self) -> None:
        """Keep the database within MAX_CACHE_BYTES: the least recently used quarter goes
        while it is larger. The file's pages (two pragmas, no scan of the table) bound the
        entries' size from above; only past the limit are the entries summed."""
        pages = self.db.execute("PRAGMA page_count").fetchone()[0]
        if pages * self.db.execute("PRAGMA page_size").fetchone()[0] <= MAX_CACHE_BYTES:
            return
        size = self.db.execute("SELECT COALESCE(SUM(LENGTH(data)), 0), COUNT(*) FROM entries").fetchone()
        if size[0] <= MAX_CACHE_BYTES:
            return
        self.db.execute("DELETE FROM entries WHERE rowid IN (SELECT rowid FROM entries ORDER BY used LIMIT ?)",
                        (max(1, size[1] // 4),))
        self.db.commit()
        self.db.execute("VACUUM")

    def close(self) -> None:
        with self.lock:
            self._close()


_SHARED: dict[tuple, Store] = {}
_SHARED_LOCK = threading.Lock()


def shared_store() -> Store:
    """The process's store in the user cache folder (one per ``$KRL_CACHE_DIR``, opened on
    first use; the language server opens its own with :class:`Store`)."""
    key = (os.environ.get("KRL_CACHE_DIR"), enabled())
    with _SHARED_LOCK:
        got = _SHARED.get(key)
        if got is None:
            got = _SHARED[key] = Store()
        return got
