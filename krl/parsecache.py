"""Parse entries of the one store (krl/store.py): a file's parse (krl/workspace.py
``LoadedFile``) as bytes and back, and a program's files loaded from the store by content hash
(:func:`load_project`), so that ``krl run``, ``krl debug``, ``krl check`` and the language server
parse a file once and share what they parsed.

The codec is msgpack by a schema (:func:`encode_loaded`): an AST node is its class's number in
:data:`krl.ast.nodes` (sorted by name) and its fields in declaration order, a diagnostic its
fields (msgpack's C code walks the AST both ways, the hooks below build the nodes); the entry is
path-free (the path is given when it is decoded). Decoding builds only
those classes, checks every node's field count and every diagnostic's field types: anything
else raises :class:`CorruptEntry` and the caller parses the file again. Nothing is ever
unpickled or evaluated (docs/security.md, "The cache").
"""

from __future__ import annotations

import dataclasses
from contextlib import contextmanager
from pathlib import Path

import msgpack

from krl.ast import nodes as N
from krl.diagnostics import Diagnostic, Note
from krl.source import read_source
from krl.store import Store, parse_key, shared_store
from krl import collector, limits, workspace
from krl.workspace import LoadedFile, Workspace, failed_load, load_batch, load_here, loading_files_by


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


def _enc_diag(d: Diagnostic, note_paths: bool) -> list:
    """A diagnostic's fields; its notes' paths only when `note_paths` (a check entry: notes
    may point at other files). A parse entry's notes are all in its own file (encode_loaded)
    and are stored without a path: the entry is keyed by content, and the same content at
    another path must get notes at that path."""
    return [d.line, d.column, d.code, d.message, d.severity, d.end_line, d.end_column, d.help,
            [[n.path, n.line, n.column, n.message] if note_paths else [n.line, n.column, n.message]
             for n in d.notes]]


_NOTE = [str, int, int, str]


def _dec_diag(x, path: str, note_path: str | None = None) -> Diagnostic:
    """The diagnostic of `path` encoded by :func:`_enc_diag`; `note_path`: the path of its
    notes when they were stored without one (a parse entry), None when each note has its own."""
    if type(x) is not list or len(x) != len(_DIAG) or not all(type(a) is t for a, t in zip(x, _DIAG)):
        raise CorruptEntry("not a diagnostic")
    notes = []
    shape = _NOTE if note_path is None else _NOTE[1:]
    for n in x[8]:
        if type(n) is not list or [type(a) for a in n] != shape:
            raise CorruptEntry("not a note")
        notes.append(Note(*n) if note_path is None else Note(note_path, *n))
    return Diagnostic(path, x[0], x[1], x[2], x[3], x[4], x[5], x[6], notes, x[7])


def encode_loaded(lf: LoadedFile) -> bytes | None:
    """The entry of one file, None when it cannot be cached (a diagnostic of another file)."""
    if any(d.path != lf.path or any(n.path != lf.path for n in d.notes) for d in lf.diagnostics):
        return None
    try:
        body = [lf.module, lf.ok, lf.status, [_enc_diag(d, False) for d in lf.diagnostics], lf.unreadable,
                sorted(lf.failed_words), *(sorted(map(list, lines.items())) for lines in lf.template)]
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
        if up.read_array_header() != 9:
            raise CorruptEntry("not an entry")
        on[0] = True
        module = up.unpack()            # the module's subtree, built by the hook
        on[0] = False
        ok, status, diags, unreadable, words, ini, inline, user = [up.unpack() for _ in range(8)]
        if up.tell() != len(data):
            raise CorruptEntry("extra data")
        if not isinstance(module, N.Module) or type(ok) is not bool or type(status) is not str \
                or type(unreadable) is not bool or not all(type(w) is str for w in words) \
                or not all(type(x) is list and len(x) == 2 and type(x[0]) is int and type(x[1]) is str
                           for x in (*ini, *inline, *user)):
            raise CorruptEntry("not an entry")
        module.path = path
        return LoadedFile(path, module, ok, status, 0.0, 0.0, [_dec_diag(d, path, path) for d in diags], unreadable,
                          set(words), (dict(map(tuple, ini)), dict(map(tuple, inline)), dict(map(tuple, user))))
    except CorruptEntry:
        raise
    except (ValueError, TypeError, RecursionError, msgpack.exceptions.UnpackException) as exc:
        raise CorruptEntry(str(exc) or type(exc).__name__) from None


def encode_diagnostics(diags: list[Diagnostic]) -> bytes:
    return msgpack.packb([[d.path, *_enc_diag(d, True)] for d in diags], use_bin_type=True)


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


# ---------------------------------------------------------------------- loading through the store

def read_parses(store: Store, wanted: dict) -> dict:
    """The stored parses of `wanted` (any id -> (parse key, path)): id -> LoadedFile decoded
    at that path, for the ids whose entry is in `store` and decodes; an entry that does not
    decode is counted in ``store.corrupt`` and left out (the caller parses the file again).
    The one lookup of parses for :func:`load_files` and the language server (krl/lsp/project.py)."""
    out: dict = {}
    if not wanted or store.db is None:
        return out
    data = store.get("parse", sorted({key for key, _path in wanted.values()}))
    with collector.paused():        # as krl.workspace.load_batch: new ASTs, next to no garbage
        for i, (key, path) in wanted.items():
            got = data.get(key)
            if got is not None:
                try:
                    out[i] = decode_loaded(got, path)
                except CorruptEntry:
                    store.corrupt += 1
    return out


def keep_parses(store: Store, made) -> None:
    """Put the parses `made` ((parse key, LoadedFile, outcome status) triples) in `store`:
    only those whose parse ended (status "done", krl.pool.Outcome); a parse stopped past its
    timeout (E005) or lost with its worker (E001) is never kept, so that one slow moment never
    becomes a lasting error for that content in every command (docs/security.md, "The store").
    A parse that cannot be encoded (:func:`encode_loaded`) is not kept either, nor one whose
    file no longer holds the content of its key: the worker processes read a file again by its
    path, so a file changed between the hash and the parse would otherwise be kept under the
    old content's hash."""
    if store.db is None:
        return
    store.put("parse", parse_entries(made))


def parse_entries(made) -> dict[str, bytes]:
    """The entries :func:`keep_parses` puts in the store for `made`: parse key -> entry."""
    return {key: e for key, lf, status in made
            if status == "done" and _on_disk(key, lf.path) and (e := encode_loaded(lf)) is not None}


def _on_disk(key: str, path: str) -> bool:
    """True when the file at `path` holds now the content whose hash begins parse key `key`."""
    src = read_source(path)
    return src.status == "ok" and bool(src.sha) and key.startswith(src.sha + ":")


def load_files(paths: list, timeout: float | None = None, store: Store | None = None,
               jobs: int | None = None) -> list[LoadedFile]:
    """The LoadedFile of each of `paths`, in order: from the store (`store`, default the
    process's :func:`krl.store.shared_store`) by content hash, the others parsed (in worker
    processes with `timeout` seconds per file and `jobs` workers, as
    :meth:`krl.workspace.Workspace.add_files`, else here: :func:`krl.workspace.load_here`) and put in the
    store (:func:`keep_parses`: not those stopped). Never raises for bad content."""
    store = shared_store() if store is None else store
    sources = [read_source(p) for p in paths]
    keys = {i: parse_key(s.sha, s.path) for i, s in enumerate(sources) if s.status == "ok" and s.sha}
    out: list = [None] * len(sources)
    for i, lf in read_parses(store, {i: (key, sources[i].path) for i, key in keys.items()}).items():
        out[i] = lf
    missing = [i for i, lf in enumerate(out) if lf is None]
    if not missing:
        return out
    status = {}
    if timeout is None:
        for i, lf in zip(missing, load_here([sources[i] for i in missing], limits.PARSE_TIMEOUT_S)):
            out[i], status[i] = lf, "done"
    else:
        for i, o in zip(missing, load_batch([sources[i].path for i in missing], timeout, jobs)):
            out[i] = o.value if o.status == "done" else failed_load(sources[i].path, o, timeout)
            status[i] = o.status
    keep_parses(store, [(keys[i], out[i], status[i]) for i in missing if i in keys])
    return out


def load_file(path) -> LoadedFile:
    """One file's LoadedFile through the store (:func:`load_files`)."""
    return load_files([path])[0]


def load_project(project, root: str = "", timeout: float | None = None, extra: list[Path] = (),
                 store: Store | None = None, jobs: int | None = None) -> Workspace:
    """:func:`krl.workspace.load_project` (the same arguments, and `store`) with the files'
    parses from the store (:func:`through_store`): the same workspace, not checked yet."""
    with through_store(store):
        return workspace.load_project(project, root, timeout, jobs, extra)


@contextmanager
def through_store(store: Store | None = None):
    """``with through_store():`` every workspace loaded in the block (krl.workspace
    ``load_workspace``, ``workspaces_for``: ``krl check``) takes its files' parses from the
    store (:func:`load_files`)."""
    with loading_files_by(lambda paths, timeout, jobs: load_files(paths, timeout, store, jobs)):
        yield
