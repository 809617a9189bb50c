"""Results kept across processes in the user cache folder, so that a command started again on
the same files (``krl debug``'s launch, ``krl run``) does not parse and check them again.

:func:`stored` returns ``make()``'s result, kept in ``cache_dir()/stored/KIND/`` under the
SHA-256 of its key (what it was made of: the files' paths, sizes and modification times) and of
the code that made it (the sizes and modification times of the packages' sources, so any
change of the code makes it anew). A kept result is a pickle (Python objects: a checked
workspace's ASTs and scopes, a robot model), written by this user for this user:

* the folder is created with mode 0700, each file with 0600, written atomically;
* a file is read only when it and its folder belong to the current user and no one else may
  write them (POSIX), when it starts with this module's header and the whole key's digest,
  and when it is at most :data:`krl.limits.MAX_STORED_BYTES`; anything else is a miss (the
  result is made anew and replaces the file);
* at most :data:`krl.limits.MAX_STORE_BYTES` are kept in all; past it the results used least
  recently are removed.

Objects a result shares with the process (the type singletons ``INT``, ``UNKNOWN``, the system
scopes and tables built once per process: what the packages of `code` hold in module globals and
in their cached zero-argument functions) are not copied: they are stored as their place
(module, name, the keys and attributes down to them) and found there again on load, so that
identity (``t is T.INT``) holds as in a result made in the process. A place that does not
lead to an object of the same type is a miss.

A result that holds ``id()``-keyed tables (a dict whose keys, or a set whose members, are the
``id()`` of objects it holds: the front end keys routines and diagnostics that way) is stored
with ``fix_ids``: the objects behind those ids are stored with it and the tables re-keyed on
load (ids are addresses, different in every process).

Nothing here ever fails a command: a folder that cannot be written means results are not
kept. ``KRL_STORE=0`` turns keeping off. See docs/security.md, "The cache".
"""

from __future__ import annotations

import contextlib
import functools
import gc
import hashlib
import importlib
import importlib.util
import io
import os
import pickle
import sys
import types
from collections.abc import Callable, Iterable
from pathlib import Path

from krl.limits import MAX_STORE_BYTES, MAX_STORED_BYTES

HEADER = b"krl-tools stored result 1\n"
#: pickling a deep AST recurses once per level; KRL's nesting limits (krl/limits.py) bound it
RECURSION = 20_000


def cache_dir() -> Path:
    """The user cache folder (``$KRL_CACHE_DIR``, else the platform's user cache folder of
    krl-tools; never inside the repository), created here. Raises OSError when it cannot be
    created."""
    import platformdirs  # noqa: PLC0415

    d = Path(os.environ.get("KRL_CACHE_DIR") or platformdirs.user_cache_dir("krl-tools"))
    d.mkdir(parents=True, exist_ok=True)
    return d


def file_key(paths: Iterable) -> tuple:
    """(path, size, mtime ns) of each file (-1, -1 when it cannot be read): a key part that
    changes when a file does."""
    out = []
    for p in paths:
        try:
            st = os.stat(p, follow_symlinks=False)
            out.append((str(p), st.st_size, st.st_mtime_ns))
        except OSError:
            out.append((str(p), -1, -1))
    return tuple(out)


@functools.lru_cache(maxsize=None)
def code_version(packages: tuple[str, ...]) -> str:
    """The digest of the sources of `packages` (their files' relative paths, sizes and
    modification times; the grammar with ``krl``), the Python version and this module's
    header: results made by other code are never read."""
    h = hashlib.sha256(HEADER + sys.version.encode())
    for name in packages:
        spec = importlib.util.find_spec(name)
        if spec is None or not spec.submodule_search_locations:
            continue
        root = Path(next(iter(spec.submodule_search_locations)))
        for dirpath, dirnames, filenames in os.walk(root):
            dirnames[:] = sorted(d for d in dirnames if d != "__pycache__")
            for f in sorted(filenames):
                if f.endswith((".pyc", ".pyo")):
                    continue
                p = Path(dirpath) / f
                h.update(repr(file_key([p.relative_to(root)]) + file_key([p])).encode())
    grammar = Path(__file__).resolve().parents[1] / "grammar" / "KRL.g4"
    h.update(repr(file_key([grammar])).encode())
    return h.hexdigest()


def stored(kind: str, key, make: Callable[[], object], *, code: tuple[str, ...] = ("krl",),
           fix_ids: bool = False):
    """``make()``, or the result kept for (`kind`, `key`, the code of `code`). `key`: any value
    with a stable ``repr`` (tuples of strings and numbers). The result is kept when ``make``
    returns (exceptions pass through, nothing kept)."""
    if os.environ.get("KRL_STORE", "1") == "0":
        return make()
    try:
        folder = _folder(kind)
    except OSError:
        return make()
    digest = hashlib.sha256(repr((kind, key, code_version(code))).encode()).hexdigest()
    path = folder / f"{digest[:40]}.pickle"
    got = _read(path, digest)
    if got is not None:
        return got[0]
    value = make()
    _write(path, digest, value, fix_ids, code)
    return value


def _folder(kind: str) -> Path:
    root = cache_dir() / "stored"
    root.mkdir(mode=0o700, exist_ok=True)
    folder = root / kind
    folder.mkdir(mode=0o700, exist_ok=True)
    return folder


def _trusted(st) -> bool:
    """Owned by this user, writable by no one else (POSIX; elsewhere the user's own folder)."""
    if not hasattr(os, "getuid"):
        return True
    return st.st_uid == os.getuid() and not st.st_mode & 0o022


def _read(path: Path, digest: str) -> tuple | None:
    """(value,) of a kept result, or None (a miss)."""
    try:
        st = os.stat(path, follow_symlinks=False)
        if not (_trusted(st) and _trusted(os.stat(path.parent)) and _trusted(os.stat(path.parent.parent))):
            return None
        if st.st_size > MAX_STORED_BYTES or not path.is_file():
            return None
        with open(path, "rb") as fh:
            head = fh.readline(len(HEADER) + 1)
            if head != HEADER or fh.readline(80).strip() != digest.encode():
                return None
            data = fh.read()
        old = sys.getrecursionlimit()
        enabled = gc.isenabled()
        gc.disable()            # millions of new objects and no garbage: the collector only costs
        sys.setrecursionlimit(max(old, RECURSION))
        try:
            value, fixups = _Unpickler(io.BytesIO(data)).load()
        finally:
            sys.setrecursionlimit(old)
            if enabled:
                gc.enable()
        for table, pairs in fixups:
            table.clear()
            if isinstance(table, dict):
                table.update((id(obj), v) for obj, v in pairs)
            else:
                table.update(id(obj) for obj in pairs)
        os.utime(path)          # used now: the last to be removed
        return (value,)
    except Exception:  # noqa: BLE001 - a result that cannot be read is made anew
        return None


def _write(path: Path, digest: str, value, fix_ids: bool, code: tuple) -> None:
    """Keep `value` (in a detached grandchild process where the platform can fork one: the
    command goes on at once, and no child is left for it to reap)."""
    if hasattr(os, "fork") and sys.platform != "darwin":
        import dataclasses, inspect, tempfile  # noqa: E401, F401, PLC0415 - imported before the fork
        try:
            pid = os.fork()
        except OSError:
            pid = -1
        if pid == 0:                 # the child: fork the writer and leave at once
            status = 0
            try:
                if os.fork() == 0:   # the writer: write, then leave without any clean-up
                    null = os.open(os.devnull, os.O_RDWR)
                    for fd in (0, 1, 2):     # the parent's pipes are not held open by the writer
                        os.dup2(null, fd)
                    _write_now(path, digest, value, fix_ids, code)
            except BaseException:  # noqa: BLE001
                status = 1
            os._exit(status)
        if pid > 0:
            with contextlib.suppress(ChildProcessError):
                os.waitpid(pid, 0)   # the child ends at once; the writer is init's to reap
            return
    try:
        _write_now(path, digest, value, fix_ids, code)
    except Exception:  # noqa: BLE001 - not kept
        pass


def _write_now(path: Path, digest: str, value, fix_ids: bool, code: tuple) -> None:
    old = sys.getrecursionlimit()
    sys.setrecursionlimit(max(old, RECURSION))
    try:
        buf = io.BytesIO()
        _Pickler(buf, _anchors(code)).dump((value, _id_tables(value) if fix_ids else []))
        data = buf.getvalue()
    finally:
        sys.setrecursionlimit(old)
    if len(data) + 200 > MAX_STORED_BYTES:
        return
    _replace(path, HEADER + digest.encode() + b"\n" + data)
    _trim(path.parent.parent)


def _replace(path: Path, data: bytes) -> None:
    """Write a new file (mode 0600) beside `path` and rename it over `path`: a reader sees the
    old result or the new one, never half a file."""
    import tempfile  # noqa: PLC0415

    fd, tmp = tempfile.mkstemp(prefix=".", suffix=".tmp", dir=path.parent)   # mode 0600
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _trim(root: Path) -> None:
    """Remove the results used least recently while all together exceed MAX_STORE_BYTES."""
    files = []
    for f in root.glob("*/*.pickle"):
        try:
            st = f.stat()
        except OSError:
            continue
        files.append((st.st_mtime_ns, st.st_size, f))
    total = sum(s for _t, s, _f in files)
    for _t, size, f in sorted(files):
        if total <= MAX_STORE_BYTES:
            break
        try:
            f.unlink()
            total -= size
        except OSError:
            pass


_OPAQUE = (type, types.ModuleType, types.FunctionType, types.BuiltinFunctionType, types.MethodType,
           types.CodeType, types.FrameType)


def _id_tables(root) -> list:
    """(table, [(object, value)] or [object]) for every dict (set) reachable from `root` whose
    int keys (members) are all ``id()`` of objects reachable from `root`."""
    objs: dict[int, object] = {}
    tables = []
    stack = [root]
    while stack:
        o = stack.pop()
        if id(o) in objs or isinstance(o, _OPAQUE):
            continue
        objs[id(o)] = o
        t = type(o)
        if t is dict or t is set:
            if any(type(k) is int for k in o):
                tables.append(o)
        stack.extend(gc.get_referents(o))
    out = []
    for table in tables:
        ints = [k for k in table if type(k) is int]
        if not ints or not all(k in objs for k in ints):
            continue
        if len(ints) != len(table):
            continue            # a table of ids and other keys: not ours to guess
        if isinstance(table, dict):
            out.append((table, [(objs[k], v) for k, v in table.items()]))
        else:
            out.append((table, [objs[k] for k in table]))
    return out


# ----------------------------------------------------------------------- shared objects

#: objects visited when the process's shared objects are listed (module globals and below)
ANCHOR_BUDGET = 400_000
_PRIMITIVE = (str, int, float, bool, bytes, complex, type(None))

def _own(obj, packages: tuple) -> bool:
    return type(obj).__module__.split(".")[0] in packages


def _anchors(packages: tuple) -> dict[int, tuple]:
    """id -> (place, type name) of the objects the process shares: module globals of
    `packages` and the results of their cached zero-argument functions, and what is reachable
    from them through dict keys (str, int), list and tuple indices and the attributes of their
    own classes (breadth first, so each object gets its shortest place)."""
    import inspect  # noqa: PLC0415

    roots = []
    for modname, mod in sorted(sys.modules.items()):
        if mod is None or modname.split(".")[0] not in packages:
            continue
        for name, v in sorted(vars(mod).items()):
            if isinstance(v, _PRIMITIVE):
                continue
            if hasattr(v, "cache_info") and callable(v):
                try:
                    if v.cache_info().currsize and not inspect.signature(v).parameters:
                        roots.append((("c", modname, name), v()))
                except (TypeError, ValueError):
                    pass
                continue
            if isinstance(v, _OPAQUE):
                continue
            roots.append((("g", modname, name), v))
    out: dict[int, tuple] = {}
    queue = list(roots)
    head = 0
    while head < len(queue) and len(out) < ANCHOR_BUDGET:
        place, obj = queue[head]
        head += 1
        if id(obj) in out or isinstance(obj, _PRIMITIVE) or isinstance(obj, _OPAQUE):
            continue
        out[id(obj)] = (place, type(obj).__qualname__)
        t = type(obj)
        if t is dict:
            queue.extend((place + (("k", k),), v) for k, v in obj.items() if type(k) in (str, int))
        elif t is list or t is tuple:
            queue.extend((place + (("i", i),), v) for i, v in enumerate(obj))
        elif _own(obj, packages):
            names = list(getattr(obj, "__dict__", {}))
            for klass in t.__mro__:
                names.extend(n for n in getattr(klass, "__slots__", ()) if n not in ("__dict__", "__weakref__"))
            for n in names:
                try:
                    queue.append((place + (("a", n),), getattr(obj, n)))
                except AttributeError:
                    pass
    return out


class _Pickler(pickle.Pickler):
    """Stores the process's shared objects as their place (:func:`_anchors`), and the
    instances of slotted dataclasses by their slots' values (set again by :func:`_set_slots`
    on load: the dataclass's own ``__setstate__`` looks its fields up for every object, most
    of the time of loading an AST)."""

    def __init__(self, file, anchors: dict) -> None:
        super().__init__(file, protocol=pickle.HIGHEST_PROTOCOL)
        self.anchors = anchors
        self.slotted: dict = {}

    def persistent_id(self, obj):
        return self.anchors.get(id(obj))

    def reducer_override(self, obj):
        t = type(obj)
        names = self.slotted.get(t)
        if names is None:
            names = self.slotted[t] = _slot_names(t)
        if not names:
            return NotImplemented
        return (object.__new__, (t,), tuple(getattr(obj, n, _UNSET) for n in names), None, None, _set_slots)


class _Unset:
    """A slot without a value."""


_UNSET = _Unset()
_SLOTS: dict = {}


def _slot_names(t: type) -> tuple:
    """The slots of a dataclass with slots whose state is the dataclass's own (else ())."""
    import dataclasses  # noqa: PLC0415

    setstate = getattr(t, "__setstate__", None)
    if not (dataclasses.is_dataclass(t) and "__slots__" in t.__dict__
            and getattr(setstate, "__qualname__", "") == "_dataclass_setstate"):
        return ()
    names = []
    for klass in reversed(t.__mro__):
        names.extend(n for n in klass.__dict__.get("__slots__", ()) if n not in ("__dict__", "__weakref__"))
    return tuple(names)


def _set_slots(obj, values: tuple) -> None:
    t = type(obj)
    names = _SLOTS.get(t)
    if names is None:
        names = _SLOTS[t] = _slot_names(t)
    setattr_ = object.__setattr__
    for n, v in zip(names, values):
        if v is not _UNSET:
            setattr_(obj, n, v)


class _Unpickler(pickle.Unpickler):
    """Finds the shared objects at their place in this process."""

    def __init__(self, file) -> None:
        super().__init__(file)
        self.found: dict = {}

    def persistent_load(self, pid):
        got = self.found.get(pid)
        if got is None:
            got = self.found[pid] = _place(*pid)
        return got


def _place(place: tuple, type_name: str):
    kind, modname, name, *steps = place
    obj = getattr(importlib.import_module(modname), name)
    if kind == "c":
        obj = obj()
    for how, key in steps:
        obj = obj[key] if how in ("k", "i") else getattr(obj, key)
    if type(obj).__qualname__ != type_name:
        raise pickle.UnpicklingError(f"{place}: a {type(obj).__qualname__}, not a {type_name}")
    return obj
