"""The language server's persistent parse and check cache (docs/editors.md, "Speed").

Two kinds of entries, in one SQLite database per version of the front end
(``$KRL_CACHE_DIR`` or the user cache folder, ``lsp/<version>.sqlite``; :func:`front_end_version`
hashes the grammar, every source and data file of the ``krl`` package, so any change of the
parser, the AST, the checker or this codec starts a new database):

* **parse**: one per (file content SHA-256, .dat or not): what ``krl check`` makes of the file
  (krl/workspace.py ``LoadedFile``: the AST, its input, syntax and build diagnostics, the
  template folds, the words of a file that does not parse), path-free;
* **check**: one per workspace (the SHA-256 of every file's path and content and of the
  entries not read): the workspace's diagnostics after a full check, so that a workspace opened
  again has its diagnostics at once while its analysis is made from the parse entries.

Entries are encoded with msgpack by a schema (:func:`encode_loaded`): an AST node is its class's
number in :data:`krl.ast.nodes` and its fields in declaration order, a diagnostic its fields.
Decoding builds only those classes, checks every node's field count and every diagnostic's
field types, and an entry carries the SHA-256 of its bytes: anything else is a corrupt entry,
ignored (and parsed again). Nothing is ever unpickled or evaluated. The database is trimmed to
:data:`krl.limits.MAX_LSP_CACHE_BYTES` (the least recently used entries go). A cache that
cannot be opened or written means a server without cache, said once in its log.
"""

from __future__ import annotations

import dataclasses
import hashlib
import logging
import os
import sqlite3
import threading
import time
from pathlib import Path

import msgpack
import platformdirs

from krl.ast import nodes as N
from krl.diagnostics import Diagnostic, Note
from krl.limits import MAX_LSP_CACHE_BYTES
from krl.syntax.engines import grammar_text
from krl.syntax.parse import default_bundle
from krl.workspace import LoadedFile

log = logging.getLogger("krl.lsp")
CODEC = "krl-lsp-cache 1"
LOCK_WAIT_S = 5.0

_CLASSES = sorted((c for c in vars(N).values() if isinstance(c, type) and dataclasses.is_dataclass(c)
                   and issubclass(c, N.Node)), key=lambda c: c.__name__)
_INDEX = {c: i for i, c in enumerate(_CLASSES)}
_POS = [tuple(f.name for f in dataclasses.fields(c) if f.name not in ("span", "ann") and not f.kw_only)
        for c in _CLASSES]
_KW = [tuple(f.name for f in dataclasses.fields(c) if f.name not in ("span", "ann") and f.kw_only)
       for c in _CLASSES]
_FIELDS = [p + k for p, k in zip(_POS, _KW)]
_LIST, _TUPLE = -1, -2


class CorruptEntry(ValueError):
    """An entry that does not decode to what this codec writes."""


# ---------------------------------------------------------------------- the codec

# An AST in an entry: a node is [class number, line, column, *fields], a list [_LIST, *items], a
# tuple [_TUPLE, *items], anything else a scalar (None, bool, int, float, str). msgpack's C code
# walks the structure both ways. Encoding: it packs lists and scalars itself and asks
# :func:`_pack_default` for nodes and tuples (strict_types: a tuple, or a subclass of a type it
# packs, is never packed as something else; any other type is refused, the file not cached).
# Decoding: it hands each array of the module's subtree, bottom-up, to the hook that builds its
# node, list or tuple; bins, maps and extension types are refused. (Measured on the 596 corpus
# files, CPU: encoding 0.71 -> 0.28 s, decoding 1.19 -> 0.86 s against the recursive Python
# codec of the same bytes, 2026-11-24.)

def _tagged_list(x: list) -> list:
    return [_LIST, *(x if list not in map(type, x) else map(_wrap, x))]


def _wrap(x):
    return _tagged_list(x) if type(x) is list else x


def _pack_default(v):
    t = type(v)
    i = _INDEX.get(t)
    if i is not None:
        out = [i, v.span.line, v.span.column]
        for f in _FIELDS[i]:
            x = getattr(v, f)
            out.append(_tagged_list(x) if type(x) is list else x)
        return out
    if t is tuple:
        return [_TUPLE, *(v if list not in map(type, v) else map(_wrap, v))]
    raise TypeError(f"no cache encoding for {t.__name__}")


def _refuse(*_args):
    raise CorruptEntry("a map or an extension type in an entry")


def _node_hook(path: str, on: list[bool]):
    """The list hook of an entry of `path`: builds nodes while ``on[0]`` (the module's
    subtree), else leaves arrays as they are."""
    classes, pos, kw, span = _CLASSES, _POS, _KW, N.Span
    count = len(classes)

    def hook(v: list):
        if not on[0]:
            return v
        tag = v[0] if v else None
        if type(tag) is not int:
            raise CorruptEntry("not a node")
        if bytes in map(type, v):
            raise CorruptEntry("unexpected bytes")
        if tag == _LIST:
            return v[1:]
        if tag == _TUPLE:
            return tuple(v[1:])
        if not 0 <= tag < count:
            raise CorruptEntry("not a node")
        p, k = pos[tag], kw[tag]
        n = 3 + len(p)
        if len(v) != n + len(k) or type(v[1]) is not int or type(v[2]) is not int:
            raise CorruptEntry("a node of another shape")
        if k:
            return classes[tag](*v[3:n], span=span(path, v[1], v[2]), **dict(zip(k, v[n:])))
        return classes[tag](*v[3:n], span=span(path, v[1], v[2]))
    return hook


_DIAG = (int, int, str, str, str, int, int, str, list)


def _enc_diag(d: Diagnostic) -> list:
    return [d.line, d.column, d.code, d.message, d.severity, d.end_line, d.end_column, d.help,
            [[n.path, n.line, n.column, n.message] for n in d.notes]]


def _dec_diag(x, path: str) -> Diagnostic:
    if type(x) is not list or len(x) != len(_DIAG) or not all(type(a) is t for a, t in zip(x, _DIAG)):
        raise CorruptEntry("not a diagnostic")
    notes = []
    for n in x[8]:
        if type(n) is not list or len(n) != 4 or [type(a) for a in n] != [str, int, int, str]:
            raise CorruptEntry("not a note")
        notes.append(Note(*n))
    return Diagnostic(path, x[0], x[1], x[2], x[3], x[4], x[5], x[6], notes, x[7])


def encode_loaded(lf: LoadedFile) -> bytes | None:
    """The entry of one file, None when it cannot be cached (a diagnostic of another file)."""
    if any(d.path != lf.path or any(n.path != lf.path for n in d.notes) for d in lf.diagnostics):
        return None
    try:
        body = [lf.module, lf.ok, lf.status, [_enc_diag(d) for d in lf.diagnostics], lf.unreadable,
                sorted(lf.failed_words), sorted(lf.template[0]), sorted(lf.template[1])]
        return msgpack.packb(body, use_bin_type=True, strict_types=True, default=_pack_default)
    except (TypeError, ValueError, OverflowError):
        return None


def decode_loaded(data: bytes, path: str) -> LoadedFile:
    """The LoadedFile of an entry for the file `path`. Raises CorruptEntry."""
    try:
        on = [False]
        up = msgpack.Unpacker(None, raw=False, use_list=True, strict_map_key=True, max_buffer_size=max(1, len(data)),
                              object_pairs_hook=_refuse, ext_hook=_refuse, list_hook=_node_hook(path, on))
        up.feed(data)
        if up.read_array_header() != 8:
            raise CorruptEntry("not an entry")
        on[0] = True
        module = up.unpack()            # the module's subtree, built by the hook
        on[0] = False
        ok, status, diags, unreadable, words, ini, inline = [up.unpack() for _ in range(7)]
        if up.tell() != len(data):
            raise CorruptEntry("extra data")
        if not isinstance(module, N.Module) or type(ok) is not bool or type(status) is not str \
                or type(unreadable) is not bool or not all(type(w) is str for w in words) \
                or not all(type(x) is int for x in (*ini, *inline)):
            raise CorruptEntry("not an entry")
        module.path = path
        return LoadedFile(path, module, ok, status, 0.0, 0.0, [_dec_diag(d, path) for d in diags], unreadable,
                          set(words), (frozenset(ini), frozenset(inline)))
    except CorruptEntry:
        raise
    except (ValueError, TypeError, RecursionError, msgpack.exceptions.UnpackException) as exc:
        raise CorruptEntry(str(exc) or type(exc).__name__) from None


def encode_diagnostics(diags: list[Diagnostic]) -> bytes:
    return msgpack.packb([[d.path, *_enc_diag(d)] for d in diags], use_bin_type=True)


def decode_diagnostics(data: bytes) -> list[Diagnostic]:
    """Raises CorruptEntry."""
    try:
        rows = msgpack.unpackb(data, raw=False, use_list=True)
        if type(rows) is not list:
            raise CorruptEntry("not a list")
        out = []
        for r in rows:
            if type(r) is not list or not r or type(r[0]) is not str:
                raise CorruptEntry("not a diagnostic")
            out.append(_dec_diag(r[1:], r[0]))
        return out
    except CorruptEntry:
        raise
    except (ValueError, TypeError, msgpack.exceptions.ExtraData) as exc:
        raise CorruptEntry(str(exc)) from None


# ---------------------------------------------------------------------- versions and keys

_VERSION: list[str] = []


def front_end_version() -> str:
    """A hash of everything a cached entry depends on: the grammar the parser was generated
    from and every .py/.yaml/.java file of the ``krl`` package (computed once per process)."""
    if not _VERSION:
        h = hashlib.sha256(CODEC.encode())
        h.update(grammar_text(default_bundle()).encode("utf-8"))
        root = Path(N.__file__).resolve().parents[1]
        for p in sorted(root.rglob("*")):
            if p.suffix in (".py", ".yaml", ".java") and "generated" not in p.parts and p.is_file():
                h.update(str(p.relative_to(root)).encode())
                h.update(p.read_bytes())
        _VERSION.append(h.hexdigest())
    return _VERSION[0]


def parse_key(sha: str, path: str) -> str:
    """The key of a file's parse: its content hash and whether it is a data list (the only
    thing of its name the parse depends on)."""
    return f"{sha}:{'dat' if path.lower().endswith('.dat') else 'src'}"


def check_key(files: list[tuple[str, str]], skipped: list[tuple[str, str]]) -> str:
    """The key of a workspace's check: (path, content hash) of its files in order, and the
    (path, reason) of the entries not read."""
    h = hashlib.sha256()
    for path, sha in files:
        h.update(f"f\t{path}\t{sha}\n".encode("utf-8", "surrogatepass"))
    for path, why in skipped:
        h.update(f"s\t{path}\t{why}\n".encode("utf-8", "surrogatepass"))
    return h.hexdigest()


def cache_dir() -> Path:
    """``$KRL_CACHE_DIR`` or the user cache folder (platformdirs), never the repository."""
    return Path(os.environ.get("KRL_CACHE_DIR") or platformdirs.user_cache_dir("krl-tools"))


# ---------------------------------------------------------------------- the store

class Store:
    """The cache database (see the module docstring); thread-safe; never raises."""

    def __init__(self, folder: Path | None = None, enabled: bool = True) -> None:
        self.db: sqlite3.Connection | None = None
        self.lock = threading.Lock()
        self.path: Path | None = None
        self.hits = self.misses = self.corrupt = 0
        if not enabled or os.environ.get("KRL_LSP_NO_CACHE"):
            return
        try:
            folder = (folder or cache_dir()) / "lsp"
            folder.mkdir(parents=True, exist_ok=True, mode=0o700)
            self.path = folder / f"{front_end_version()[:24]}.sqlite"
            db = sqlite3.connect(self.path, timeout=LOCK_WAIT_S, check_same_thread=False)
            db.execute("CREATE TABLE IF NOT EXISTS entries (kind TEXT, key TEXT, digest BLOB, data BLOB, "
                       "used REAL, PRIMARY KEY (kind, key))")
            db.commit()
            self.db = db
        except (OSError, sqlite3.Error) as exc:
            self._off(f"the parse cache is not used: {exc}")

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
        """The verified data of the entries of `kind` among `keys`."""
        out: dict[str, bytes] = {}
        if self.db is None or not keys:
            return out
        with self.lock:
            try:
                for i in range(0, len(keys), 500):
                    part = keys[i:i + 500]
                    rows = self.db.execute(
                        f"SELECT key, digest, data FROM entries WHERE kind = ? AND key IN ({','.join('?' * len(part))})",
                        (kind, *part)).fetchall()
                    for key, digest, data in rows:
                        if isinstance(data, bytes) and hashlib.sha256(data).digest() == digest:
                            out[key] = data
                        else:
                            self.corrupt += 1
                if out:
                    now = time.time()
                    self.db.executemany("UPDATE entries SET used = ? WHERE kind = ? AND key = ?",
                                        [(now, kind, k) for k in out])
                    self.db.commit()
            except sqlite3.Error as exc:
                self._off(f"the parse cache is not used: {exc}")
        self.hits += len(out)
        self.misses += len(keys) - len(out)
        return out

    def put(self, kind: str, items: dict[str, bytes]) -> None:
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
                self._off(f"the parse cache is not written: {exc}")

    def _trim(self) -> None:
        """Keep the database within MAX_LSP_CACHE_BYTES: the least recently used quarter goes
        while it is larger."""
        size = self.db.execute("SELECT COALESCE(SUM(LENGTH(data)), 0), COUNT(*) FROM entries").fetchone()
        if size[0] <= MAX_LSP_CACHE_BYTES:
            return
        self.db.execute("DELETE FROM entries WHERE rowid IN (SELECT rowid FROM entries ORDER BY used LIMIT ?)",
                        (max(1, size[1] // 4),))
        self.db.commit()
        self.db.execute("VACUUM")

    def close(self) -> None:
        with self.lock:
            self._close()
