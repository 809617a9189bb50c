"""Loading a program: storage for what the front end resolved (reference §2.1-§2.7).

:class:`Program` is the run-time side of one program model:

* the program's files are those of :func:`krl.project.project_of` (one rule for every
  command): the KRC backup holding the program (its whole root, ``R1`` and ``STEU``), else
  every KRL file below the program's folder (or ``--workspace``); outside a backup the
  project's BASIS (interp/basis: ``$config.dat``, ``bas.src``, ``ir_stopm.src``) is added as
  the System folder (:func:`basis_files`, krl/project.py rule 4: its ``$config.dat`` merges
  with a folder's own), inside one the backup's own System folder is used;
* they are loaded, checked and resolved together by the front end
  (:func:`krl.workspace.load_project`, ``Workspace.check``; krl/semantics/resolve.py gives
  every use its storage class and slot, every call its routine or its native's implementation
  (interp/runtime/natives ``LINKS``), every statement its advance-run facts), once per process
  for the same files (:func:`checked_workspace`); outside a backup the BASIS is checked once per
  process and the program's own files on it (:func:`shared_layer`, krl/basislayer.py), unless
  the program could change what the BASIS means (then all are checked together);
* this module only *allocates* storage for those symbols: one :class:`ModuleRT` per module of
  the workspace (``Workspace.units``, same order: a Storage's ``owner`` is its index) holds
  its data list's references by slot (``refs``), initialised from the DECL values when the
  program is loaded and kept for the whole run; the machine data lists of a backup
  (``Mada``) initialise the system variables they declare. Nothing here looks a name up:
  a data-list initialiser's names carry their Storage like any other use.

``Module.data`` (upper-case name -> reference) is kept for tools and tests that read a data
list by name (the benchmark's result, a debugger); the interpreters use ``refs``.
"""

from __future__ import annotations

import hashlib
import os
import threading
from collections import Counter
from pathlib import Path

from krl.ast import nodes as N
from krl.basislayer import BasisLayer, basis_layer
from krl.diagnostics import SYNTAX_CODES
from krl.diagnostics.codes import E001, E003, E005, E018, E019
from krl.files import spelled, spelled_within
from krl.limits import (MODEL_BASE_BYTES, MODEL_BYTES_PER_SOURCE_BYTE, MODEL_CACHE_BYTES, PARSE_TIMEOUT_S,
                        WORKSPACE_BASE_BYTES)
from krl.project import project_of, with_basis   # which files make the program: one rule
from krl.semantics import types as T
from krl.semantics.expression import Env, evaluate
from krl.semantics.resolve import GLOBAL, LOCAL, MODULE, SYSTEM, Storage
from krl.parsecache import load_file, load_project

from .convert import assign_into, convert_scalar
from .errors import KrlRuntimeError, ResourceError
from .inputwait import reads_inputs_only
from .kss import kuka_names, standard_files
from .memory import Slot, SignalRef, index_ref
from .natives import LINKS
from .sizedcache import SizedCache
from .values import UNSET, Struct, data_size, make_value
from .watch import timer_watch, watch_of, watch_of_decl

BASIS_DIR = Path(__file__).resolve().parent.parent / "basis"

# the problems of a file reported to the tools as its syntax errors (parse_module)
_START_CODES = SYNTAX_CODES | {E001, E003, E005}
# the problems that keep a module from starting: a file not read (E001, E005), not parsed (past a
# nesting or expression limit: E018, E019) or not built (E003). A line the grammar does not
# accept does not: the module runs from what parsed, and a run that reaches the line stops
# there (issue 63; interp/runtime/errors.py ``not_understood``)
_BLOCKING = frozenset({E001, E003, E005, E018, E019})
# files above this size in total are parsed in worker processes (the Java engine when present)
_BATCH_BYTES = 256 * 1024
#: the checked workspaces of this process, kept within MODEL_CACHE_BYTES of their estimated memory
#: (krl/limits.py; a segmented LRU: interp/runtime/sizedcache.py)
_CACHE = SizedCache(MODEL_CACHE_BYTES)
#: the checked workspaces this process loaded, by folder: how often each backup's files were
#: loaded and checked (tests/cpu_profile.py reports it per worker beside the models' LOADS)
WS_LOADS: Counter = Counter()
#: the checked BASIS layers of this process by the BASIS files' paths and contents
#: (krl/basislayer.py; at most a few: the project's BASIS, a test's own)
_LAYERS: dict = {}
#: how many checked workspaces this process made on a shared BASIS layer and how many whole
#: (tests and tools/trace_identity.py read it; a workspace taken from the cache is neither)
LAYER_USES: Counter = Counter()


class SyntaxProblem(str):
    """A syntax error of a file as text (``file:line:col: message``) that keeps its place
    (``file``, ``line``) for the run-time error that stops the program from starting."""

    def __new__(cls, text: str, file: str | None = None, line: int | None = None) -> "SyntaxProblem":
        self = super().__new__(cls, text)
        self.file = file
        self.line = line
        return self


def basis_files(project) -> list[Path]:
    """The files of the project's BASIS (:data:`BASIS_DIR`) that the program of `project`
    (krl.project.ProgramFiles) runs on: krl/project.py rule 4 (none in a backup; the BASIS
    ``$config.dat`` merges with the program's own; another BASIS module only when the program
    has none of its name)."""
    return with_basis(project, sorted(p for p in BASIS_DIR.iterdir() if p.is_file()))


def parse_module(path: str):
    """(Module AST, syntax error strings) of one file on its own (tools and tests; a run
    loads its files through :func:`checked_workspace`); the parse from the one store
    (krl/store.py) when it holds the file's content."""
    lf = load_file(path)
    errs = [SyntaxProblem(f"{d.path}:{d.line}:{d.column}: {d.message}", d.path, d.line)
            for d in lf.diagnostics if d.is_error and d.code in _START_CODES]
    return lf.module, errs


def program_files(main_path, workspace, submits) -> tuple:
    """``(main path, project, extra files)`` of the program `main_path` run with the `submits`
    in `workspace` (None: krl.project's rule finds it): the main path in the user's spelling,
    the project (krl.project.ProgramFiles) and the files a run adds to it (its BASIS, KUKA's
    P00 when a backup lacks it, a submit program outside the project): what
    :func:`checked_workspace` loads."""
    main_path = spelled_within(main_path, workspace)
    project = project_of(main_path, spelled(workspace) if workspace else None)
    extra = basis_files(project)
    extra += standard_files(project)     # KUKA's P00 when the backup lacks it
    # (a submit program of the project's, its name among the project's modules, needs no path
    # resolved: the links of every project file were resolved at each run, 0.1 s of a backup's)
    own = {_stem(f).lower() for f in project.files} if submits else ()
    others = [s for s in submits if Path(s).stem.lower() not in own]
    if others:
        real = {os.path.realpath(f) for f in project.files}
        extra += [spelled(s) for s in others if os.path.realpath(s) not in real]
    return main_path, project, extra


def _stem(path) -> str:
    """The stem of `path` (a str or Path) by string operations: a run lists its project's files
    at every start (pathlib's parse of each was half of program_files)."""
    return os.path.splitext(os.path.basename(path))[0]


def checked_workspace(project, extra: list[Path] = ()):
    """The loaded, checked and resolved workspace of `project` and the `extra` files (a run's
    BASIS, a submit program outside the project): cached per process for the same files
    (path, size, modification time), so the two interpreters of a conformance run, or the
    programs of one backup, load and check their files once (a workspace whose folder no longer
    exists is dropped; the cache holds at most krl/limits.py ``MODEL_CACHE_BYTES`` of their
    estimated memory, a workspace asked for again kept before one loaded once:
    interp/runtime/sizedcache.py; a workspace is charged :func:`workspace_cost`, and its models
    :func:`charge_models`); each file's parse comes from the one store in the user cache folder
    (krl/store.py, shared with the language server) when a file of the same content was parsed
    before. Never raises for bad input."""
    paths = [*project.files, *extra]
    key = [str(project.root), project.backup]
    sizes = []
    for p in paths:
        try:
            st = os.stat(p, follow_symlinks=False)
            key.append((str(p), st.st_size, st.st_mtime_ns))
            sizes.append(st.st_size)
        except OSError:
            key.append((str(p), -1, -1))
            sizes.append(0)
    size = sum(sizes)
    key.extend(e.kind + str(e.path) for e in project.entries if e.kind != "file")
    key = tuple(key)
    # a workspace whose folder is gone (a variant's or an extracted archive's temporary folder)
    # is never asked for again: dropped, so that it is not carried through every collection
    for gone in [k for k in _CACHE.keys() if not os.path.isdir(k[0])]:
        _CACHE.drop(gone)
    ws = _CACHE.get(key)
    if ws is not None:
        return ws
    timeout = PARSE_TIMEOUT_S if size > _BATCH_BYTES else None
    ws = None
    layer = shared_layer(extra) if not project.backup else None
    if layer is not None:
        ws = load_project(project, str(project.root), timeout)
        if layer.admits(ws):
            layer.attach(ws)
        else:
            ws = None
    LAYER_USES["layer" if ws is not None else "whole"] += 1
    if ws is None:
        # each file's parse from the one store (krl/store.py, krl/parsecache.py) by content hash
        ws = load_project(project, str(project.root), timeout, extra=list(extra))
    ws.natives = LINKS      # the resolver links each built-in call to its implementation
    ws.check()
    ws.run_facts = {}       # Program.derived: what runs derive from the checked files, made once
    WS_LOADS[str(project.root)] += 1
    cost = workspace_cost(sizes, len(project.files), ws.layer is not None)
    ws.cache_entry = (key, cost)        # charge_models: its models' charge added
    _CACHE.put(key, ws, cost)
    return ws


def workspace_cost(sizes: list[int], own: int, on_layer: bool) -> int:
    """The estimated bytes a checked workspace holds (krl/limits.py, measured there), before
    any model is built on it: ``MODEL_BYTES_PER_SOURCE_BYTE`` times the bytes of its files
    (`sizes`, the project's `own` first, then the extra ones), only the project's own when it
    was checked `on_layer` (the BASIS files' checked parse is the shared layer's, held once per
    process: :func:`shared_layer`), plus ``WORKSPACE_BASE_BYTES``."""
    files = sum(sizes[:own]) if on_layer else sum(sizes)
    return files * MODEL_BYTES_PER_SOURCE_BYTE + WORKSPACE_BASE_BYTES


def charge_models(ws, count: int) -> None:
    """Charge the cache's entry of `ws` (made by :func:`checked_workspace`) for the `count`
    program models now built on it (interp/runtime/model.py ``load_model``), krl/limits.py
    ``MODEL_BASE_BYTES`` each, beside its own charge (:func:`workspace_cost`); nothing when the
    cache no longer holds it. The caller holds model.py's lock."""
    key, cost = ws.cache_entry
    _CACHE.recost(key, cost + count * MODEL_BASE_BYTES)


def all_basis_files() -> list[Path]:
    """Every file of the project's BASIS (:data:`BASIS_DIR`), in the order a run adds them."""
    return sorted(p for p in BASIS_DIR.iterdir() if p.is_file())


def shared_layer(extra) -> BasisLayer | None:
    """The BASIS layer (krl/basislayer.py) checked once per process for the `extra` files of a
    program (:func:`program_files`) when they are the whole BASIS and nothing more, else None
    (a program with its own module of a BASIS module's name, a submit program outside it,
    KUKA's P00: checked whole). Keyed by the files' paths and contents; None when one cannot
    be read."""
    extra = list(extra)
    if extra != all_basis_files():
        return None
    digest = hashlib.sha256()
    try:
        for p in extra:
            digest.update(str(p).encode() + b"\0" + p.read_bytes() + b"\0")
    except OSError:
        return None
    key = digest.hexdigest()
    layer = _LAYERS.get(key)
    if layer is None:
        layer = basis_layer(extra, LINKS)
        _fill_run_memos(layer)
        _LAYERS[key] = layer
    return layer


def _fill_run_memos(layer: BasisLayer) -> None:
    """The memos a run notes on a statement's annotation (``ann.extra``: a WAIT FOR's watch
    class, its timer comparisons and whether it reads only inputs, interp/runtime/core.py
    ``_wait_key`` and inputwait.py; an INTERRUPT DECL's watch class, watch.py
    ``watch_of_decl``), filled once on the layer's statements: each depends on its statement
    and the layer's annotations alone, and the runs on the layer then only read them."""
    stack = [f.module for f in layer.files]
    while stack:
        node = stack.pop()
        stack.extend(node.children())
        if isinstance(node, N.WaitFor):
            extra = node.annotate().extra
            extra.setdefault("watch", watch_of(node.cond))
            extra.setdefault("timer_watch", timer_watch(node.cond))
            extra.setdefault("inputs_only", reads_inputs_only(node.cond))
        elif isinstance(node, N.InterruptDecl):
            watch_of_decl(node)


def forget_below(folder) -> int:
    """Drop the checked workspaces (with the models built on them) of the projects at or below
    `folder` (a str or Path): for a caller that knows they are not asked for again, so that they
    do not push out of the cache the workspaces that are (a test's own temporary folder at its
    end: tests/conftest.py; in a whole make test about 1,000 of the 1,500 workspaces the workers
    loaded were such folders, 2 MB of budget each, and the corpus backups asked for again by
    later tests were evicted by them). Returns how many were dropped."""
    root = os.path.abspath(folder)
    below = root.rstrip(os.sep) + os.sep
    gone = [k for k in _CACHE.keys() if os.path.abspath(k[0]) == root or os.path.abspath(k[0]).startswith(below)]
    for k in gone:
        _CACHE.drop(k)
    return len(gone)


class ModuleRT:
    """A module at run time: its routines, and the storage of its data list by slot (a run's
    copy of a model's module makes that storage its own when first read: :meth:`copy`)."""

    def __init__(self, program: "Program", index: int, unit) -> None:
        self.program = program
        self.index = index
        self.unit = unit
        self.name = unit.name.upper()
        self.files: dict[str, Path] = {}
        for f, kind in ((unit.src, None), (unit.dat, "dat")):
            if f is not None:
                self.files[kind or Path(f.path).suffix.lower().lstrip(".")] = Path(f.path)
        routines = unit.routines
        self.routines: dict[str, N.Routine] = {}
        for r in routines:
            self.routines.setdefault(r.name.upper(), r)
        self.main: N.Routine | None = routines[0] if routines else None
        self.path = unit.src.path if unit.src is not None else (unit.dat.path if unit.dat is not None else "")
        dl = unit.dat.module.data if unit.dat is not None else None
        self.datalist: N.DataList | None = dl
        self.layout = dl.ann.layout if dl is not None and dl.ann is not None else None
        n = len(self.layout.slots) if self.layout is not None else 0
        self.refs: list = [None] * n       # slot -> reference (the interpreters' storage)
        self.store: list = [UNSET] * n     # slot -> value of a variable
        self.data: dict = {}               # UPPER name -> reference (tools and tests)
        self.errors: list[str] = []        # data-list initialisation problems
        self.syntax_errors: list[str] = []  # problems of its files that keep it from starting (_BLOCKING)
        self.loaded = False
        self.loading = False

    def copy(self, program: "Program") -> "ModuleRT":
        """This module of a model (interp/runtime/model.py, frozen: :meth:`Program.freeze_modules`)
        as `program`'s (a run's copy: :meth:`Program.copy`): its code shared; its data list's
        values (``store``, ``refs``, ``data``) and its ``errors`` and ``syntax_errors`` its own,
        copied from this module when the run first asks for them (:meth:`__getattr__`: a run
        of a backup reads a few of its data lists)."""
        m = ModuleRT.__new__(ModuleRT)
        d = m.__dict__
        d.update(self.shared)
        d["program"] = program
        d["model"] = self
        return m

    def __getattr__(self, name: str):
        # (called for an attribute the object lacks: a copy's own values before it has them)
        model = self.__dict__.get("model")
        if model is None or name not in _OWN:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        with _OWN_LOCK:         # (a run's network partner may read it from its own thread)
            d = self.__dict__
            if name not in d:
                if name in ("errors", "syntax_errors"):
                    d[name] = list(getattr(model, name))
                else:
                    self._own_data(model)
            return d[name]

    def slot_values(self):
        """The values of this module's data list by slot as they are now (the idle watch's image,
        interp/runtime/idle.py): its store, or, while a run's copy has not made its data list
        its own (:meth:`copy`), its model's frozen one, which the copy's equals until the run
        reads it. Not for writing."""
        d = self.__dict__
        store = d.get("store")
        if store is None:
            model = d.get("model")
            return model.store if model is not None else self.store
        return store

    def _own_data(self, model: "ModuleRT") -> None:
        """This copy's data list (:meth:`copy`): `model`'s values copied (frozen.py
        ``StoreImage.copy``), each reference its own (a SIGNAL's on the run's system
        variables)."""
        old = model.store
        store = model.image.copy()
        sysvars = self.program.sysvars
        refs: dict = {}
        new_refs = []
        for r in model.refs:         # _ref_copy, its common case (a slot of this store) written out
            got = refs.get(id(r))
            if got is None and r is not None:
                if r.__class__ is Slot and r.c is old:
                    got = refs[id(r)] = Slot(store, r.k, r.type, r.name, readonly=r.readonly, on_write=r.on_write)
                else:
                    got = _ref_copy(r, old, store, sysvars, refs)
            new_refs.append(got)
        d = self.__dict__
        d["data"] = {k: refs.get(id(r)) or _ref_copy(r, old, store, sysvars, refs) for k, r in model.data.items()}
        d["refs"], d["store"] = new_refs, store


#: a run's copy of a module: what it shares with its model's module, and what it makes its own
#: when first asked (ModuleRT.copy)
_SHARED = ("index", "unit", "name", "files", "routines", "main", "path", "datalist", "layout", "loaded")
_OWN = frozenset({"store", "refs", "data", "errors", "syntax_errors"})
_OWN_LOCK = threading.Lock()


def _ref_copy(ref, store: list, new_store: list, sysvars, refs: dict):
    """A data list's reference `ref` on `store` as the copy's on `new_store` (a SIGNAL's on
    `sysvars`' live array; a constant signal's with a container of its own), recorded in
    `refs` by id. Raises TypeError for a reference of another kind (none is made by loading)."""
    if ref is None:
        return None
    got = refs.get(id(ref))
    if got is not None:
        return got
    if isinstance(ref, Slot):
        c = new_store if ref.c is store else dict(ref.c) if hasattr(ref.c, "keys") else list(ref.c)
        got = Slot(c, ref.k, ref.type, ref.name, readonly=ref.readonly, on_write=ref.on_write)
    elif isinstance(ref, SignalRef):
        got = SignalRef(sysvars.lookup(ref.proxy.name.upper()).peek(), ref.a, ref.b, ref.name)
    else:
        raise TypeError(f"a data list's reference of kind {type(ref).__name__} cannot be copied")
    refs[id(ref)] = got
    return got


class Program:
    """The program of one run, or of a program model's load (module docstring). ``modules``: one
    ModuleRT per unit of the workspace, by index; ``errors``: the checker's errors in the
    program's own module (its .src/.dat), which keep it from starting unless the run was asked
    not to check. Its collaborators, given when it is made: `sysvars` (sysvars.SysVars: the
    variables the machine data lists set, the ones a system data list declares), `memory`
    (memory.DataMemory: what its data lists take), `message` (``message(text)``: a note) and
    `system_ref` (``system_ref(Storage)``: the reference of a system variable an initialiser
    names: names.Names ``sysref``). A model loads it once (interp/runtime/model.py); each run
    reads its own :meth:`copy`."""

    def __init__(self, main_path: str | Path, workspace: str | Path | None, submits: list, check: bool,
                 sysvars, memory, message, system_ref, files: tuple | None = None) -> None:
        self.sysvars, self.memory, self.message, self.system_ref = sysvars, memory, message, system_ref
        # the user's spelling (links kept, krl/files.py spelled): every path the run shows or
        # traces is the one the user or the editor gave; identity compares resolved paths;
        # `files`: (main path, project, extra files, checked workspace) a model's load found already
        # (interp/runtime/model.py load_model: asked for once, the cache's count of uses is right)
        if files is None:
            files = program_files(main_path, workspace, submits)
            files += (checked_workspace(files[1], files[2]),)
        self.main_path, self.project, extra, ws = files
        self.backup = self.project.backup
        self.workspace = self.project.root
        self.system_dir = self.project.system if self.backup and self.project.system else BASIS_DIR
        self.ws = ws
        self.check = check
        self.modules: list[ModuleRT] = [ModuleRT(self, i, u) for i, u in enumerate(ws.units)]
        self._index()
        self.sysrefs: list = [None] * len(ws.system_names)
        self.stubs: set[str] = set()
        self._outside_types: set[str] | None = None     # the checker's W105 types (declared_type)
        self.fatal: ResourceError | None = None   # a data list past a limit: the program cannot start
        self._initialiser_env = _InitialiserEnv(self)
        self._syntax_errors()
        self._load_all()

    def _index(self) -> None:
        self.by_name: dict[str, ModuleRT] = {}
        self.by_path: dict[str, ModuleRT] = {}
        self._by_real: dict[str, ModuleRT] | None = None     # by resolved path (module_of), made when asked
        for m in self.modules:
            self.by_name.setdefault(m.name, m)
            for p in m.files.values():
                self.by_path[str(p)] = m

    def copy(self, sysvars, memory, message, system_ref, main_path=None, check=None) -> "Program":
        """This loaded program of a model (interp/runtime/model.py: frozen,
        :meth:`freeze_modules`) as a run's own: the code, the checked workspace and the
        modules' routines shared, each data list's values copied (values.copy_value) with
        references of its own when the run first reads them (:meth:`ModuleRT.copy`), on the
        run's collaborators (see the class docstring); the run's program is `main_path`
        (another program of the same files: a data list's values do not depend on which
        program runs; None: this one's), checked when `check` (None: as this one). This object
        is only read."""
        p = Program.__new__(Program)
        p.sysvars, p.memory, p.message, p.system_ref = sysvars, memory, message, system_ref
        for name in ("project", "backup", "workspace", "system_dir", "ws", "fatal", "_outside_types", "_places"):
            setattr(p, name, getattr(self, name))
        p.main_path = self.main_path if main_path is None else main_path
        p.check = self.check if check is None else check
        p.modules = [m.copy(p) for m in self.modules]
        p._index()
        p.sysrefs = [None] * len(self.sysrefs)
        p.stubs = set(self.stubs)
        p._initialiser_env = _InitialiserEnv(p)
        return p

    def freeze_modules(self) -> None:
        """A model's program, its modules' stores frozen (interp/runtime/model.py, each with its
        ``image``): what a run's copy of each module shares (``shared``) and where each data-list
        reference lies (``_places``: id(reference) -> (module index, slot), :meth:`own_ref`)."""
        self._places = {}
        for m in self.modules:
            m.shared = {name: getattr(m, name) for name in _SHARED}
            m.shared["loading"] = False
            for k, r in enumerate(m.refs):
                if r is not None:
                    self._places.setdefault(id(r), (m.index, k))

    def own_ref(self, model_ref):
        """The run's reference of its model's data-list reference `model_ref` (a system data
        list's declaration: sysvars.SysVars ``declared_as``). Raises KeyError for another."""
        index, slot = self._places[id(model_ref)]
        return self.modules[index].refs[slot]

    def derived(self, name: str, make):
        """``make(self)``, computed once per checked workspace (:func:`checked_workspace`) and
        given again to every run of the same files: a fact of the program's ASTs and the
        checker's annotations alone (interp/runtime/idle.py ``routine_writes``,
        interp/runtime/autocell.py ``program_numbers``: walks over every statement, 0.13-0.16 s
        each on the palletizer backup, paid by each of its 23 entry points in an audit)."""
        facts = self.ws.run_facts
        if name not in facts:
            facts[name] = make(self)
        return facts[name]

    # ------------------------------------------------------------------ modules
    def module(self, name: str) -> ModuleRT | None:
        """The first module named `name` (any case), in the order of the program's files
        (tools and tests; the interpreters use each call's resolved module)."""
        return self.by_name.get(name.upper())

    def module_of(self, path: str | Path) -> ModuleRT | None:
        """The module of the file `path` (the program's main file, a submit program), in any
        spelling of its path (links resolved to compare)."""
        m = self.by_path.get(str(path)) or self.by_path.get(str(spelled(path)))
        if m is not None:
            return m
        if self._by_real is None:
            self._by_real = {}
            for p, mod in self.by_path.items():
                self._by_real.setdefault(os.path.realpath(p), mod)
        return self._by_real.get(os.path.realpath(path))

    def errors_of(self, m: ModuleRT | None) -> list:
        """The checker's errors in module `m`'s files (none when the run does not check); input
        and syntax errors are not among them: a file not read or not parsed keeps any run from
        starting, --no-check or not, and the run says so itself ("the program has syntax errors
        and cannot start"); a line not understood stops the run when it is reached."""
        if m is None or not self.check or m.syntax_errors:
            return []
        paths = {str(p) for p in m.files.values()}
        return [d for d in self.ws.sink.sorted() if d.is_error and d.path in paths and d.code not in _START_CODES]

    def _syntax_errors(self) -> None:
        by_path: dict[str, list] = {}
        for d in self.ws.sink.sorted():
            if d.is_error and d.code in _BLOCKING:
                by_path.setdefault(d.path, []).append(
                    SyntaxProblem(f"{d.path}:{d.line}:{d.column}: {d.message}", d.path, d.line))
        for f in self.ws.files:
            if f.status not in ("ok", "syntax_error") and f.path not in by_path:
                by_path[f.path] = [SyntaxProblem(f"{f.path}: file not read: {f.status}", f.path, 1)]
        for m in self.modules:
            for kind in ("dat", "src", "sub"):
                p = m.files.get(kind)
                if p is not None:
                    m.syntax_errors += by_path.get(str(p), [])

    def _load_all(self) -> None:
        """Initialise every data list (§2.5): the system data lists first ($config.dat, ...),
        then the machine data (Mada: the system variables it declares take its values), then
        the others in the order of the program's files; an initialiser that names another
        data list's variable loads that list first."""
        def rank(m: ModuleRT) -> int:
            if m.datalist is None:
                return 3
            if m.datalist.name[:1] != "$":
                return 2
            return 1 if _in_mada(m) else 0
        try:
            for m in sorted(self.modules, key=rank):
                self.ensure_loaded(m)
        except ResourceError as exc:     # the program cannot start (Calls.main_routine)
            self.fatal = self.fatal or exc
        self._robot_values()

    def _robot_values(self) -> None:
        """KRL code and the controller see one robot (issue 22): the system variables that
        name the robot (SysVars.ROBOT_SYSVARS: $TRAFONAME, soft limits, $ROBROOT, ...) hold
        the simulated robot's machine data, also where the backup's Mada declares other
        values (a run with --robot); the Mada data list's own variables follow."""
        sv = self.sysvars
        sv.robot_values()
        sv.start_workspaces()
        if not self.backup:
            return
        for m in self.modules:
            if not (m.loaded and _in_mada(m)):
                continue
            for key in sv.ROBOT_SYSVARS:
                ref = m.data.get(key)
                if ref is None or key not in sv.store:
                    continue
                try:
                    cur, v = ref.peek(), sv.store[key]
                    if isinstance(cur, Struct) or hasattr(cur, "dims"):
                        assign_into(cur, v)
                except KrlRuntimeError:
                    pass

    def ensure_loaded(self, m: ModuleRT) -> ModuleRT:
        if m.loaded or m.loading:
            return m
        m.loading = True
        try:
            if m.datalist is not None and m.layout is not None:
                self._load_data(m)
        finally:
            m.loading = False
            m.loaded = True
        return m

    def _load_data(self, m: ModuleRT) -> None:
        """Declare and initialise a data list's variables in ``m`` (§2.5). A declaration that
        fails (unknown type, bad initialiser) is recorded in ``m.errors`` and skipped."""
        slot_of = {id(s.decl) if s.var is None else id(s.var): k for k, s in enumerate(m.layout.slots)}
        mada = self.backup and _in_mada(m)
        for item in m.datalist.items:
            try:
                self._load_item(m, item, slot_of, mada)
            except ResourceError:
                raise
            except KrlRuntimeError as exc:
                m.errors.append(f"line {item.span.line}: {exc.message}")
        if mada:
            # arrays set element by element (`$SOFTP_END[3]=168.0`, `$TRAFONAME[]="..."`)
            # initialise their system variable whole, once the list is read
            for key, ref in m.data.items():
                self._machine_data(key, ref)

    @staticmethod
    def _decl_span(vn: N.VarName, decl) -> N.Span:
        return vn.span if vn.span.line else decl.span

    def data_elements(self, t, vn: N.VarName, decl) -> int:
        """The data elements of variable ``vn`` of type ``t`` declared by ``decl``
        (values.data_size); a STRUC that contains itself or nests too deep is a
        ResourceError at the DECL's file:line."""
        try:
            return data_size(t)
        except KrlRuntimeError as exc:
            span = self._decl_span(vn, decl)
            raise ResourceError(exc.message, None, span.file, span.line) from None

    def take_memory_n(self, n: int, vn: N.VarName, decl) -> int:
        """Reserve ``n`` elements of the run's data memory for ``vn``; returns ``n``.
        Raises ResourceError "data memory exhausted" at the DECL's file:line."""
        span = self._decl_span(vn, decl)
        return self.memory.take(n, vn.name, span.file, span.line)

    def take_memory(self, t, vn: N.VarName, decl) -> int:
        """Reserve the run's data memory for variable ``vn`` of type ``t`` (a data-list or
        routine DECL, ``decl``) before anything is allocated; returns the elements taken."""
        return self.take_memory_n(self.data_elements(t, vn, decl), vn, decl)

    def declared_type(self, t, tref) -> T.KrlType:
        """The type the checker gave a declaration; a type nothing declares is untyped and
        logged once when the checker calls it KUKA's (W105, ``Outside.kuka``: a type of the
        controller's system data lists the backup does not hold, e.g. ESYS of $operate.dat; a
        type of a package an EXT names; krl/semantics/outside.py, issue 46: one decision),
        else the run-time error "unknown type NAME" (the program's E105)."""
        if t is not None and t is not T.UNKNOWN and not _has_unknown(t):
            return t
        name = tref.name if isinstance(tref, N.TypeRef) else str(tref)
        if self._outside_types is None:
            self._outside_types = self.derived("outside_types", _outside_types)
        if name.upper() not in self._outside_types:
            raise KrlRuntimeError(f"unknown type {name}")
        if name.upper() not in self.stubs:
            self.stubs.add(name.upper())
            self.message(f"not simulated: type {name} (undeclared; values are untyped)")
        return T.UNKNOWN

    def _load_item(self, m: ModuleRT, item, slot_of: dict, mada: bool) -> None:
        # a KSS system data list ($OPERATE, $MACHINE, $OPTION, ...: DEFDAT $NAME) declares the
        # system variables the simulator does not model (SysVars.declare)
        system_list = m.datalist.name[:1] == "$"
        if isinstance(item, N.VarDecl):
            for vn in item.names:
                k = slot_of.get(id(vn))
                if k is None:
                    continue             # a repeated name (E102): the first declaration holds it
                t = self.declared_type(N.type_of(vn), item.type)
                self.take_memory(t, vn, item)
                m.store[k] = make_value(t)
                ref = Slot(m.store, k, t, vn.name, readonly=item.is_const)
                if item.init is not None:
                    try:
                        v = self.literal(item.init, t)
                        cur = m.store[k]
                        if isinstance(cur, Struct) or hasattr(cur, "dims"):
                            assign_into(cur, v)
                        else:
                            m.store[k] = convert_scalar(v, t)
                    except KrlRuntimeError as exc:
                        m.errors.append(f"{vn.name}: {exc.message}")
                m.refs[k] = ref
                m.data[vn.name.upper()] = ref
                if mada:
                    self._machine_data(vn.name.upper(), ref)
                if system_list and vn.name[:1] == "$":
                    self.sysvars.declare(vn.name.upper(), ref, self._decl_span(vn, item))
        elif isinstance(item, N.ArrayInit):
            st = item.ann.place if item.ann is not None else None
            ref = m.refs[st.slot] if st is not None else None
            if ref is None:
                return
            if isinstance(ref, Slot) and ref.readonly:
                # a CONST array initialised element by element in its data list (reference
                # §2.5 array_elem_init): the data list writes it; the program cannot
                ref = Slot(ref.c, ref.k, ref.type, ref.name)
            try:
                target = index_ref(ref, list(item.indices), item.name)
                value = self.literal(item.value, target.type)
                if isinstance(target.peek(), Struct):
                    assign_into(target.peek(), value)
                else:
                    target.set(value)
            except KrlRuntimeError as exc:
                m.errors.append(f"{item.name}: {exc.message}")
        elif isinstance(item, N.SignalDecl):
            k = slot_of.get(id(item))
            ref = self.signal_ref(item)
            if ref is not None and k is not None:
                m.refs[k] = ref
                m.data[item.name.upper()] = ref
                if system_list and item.name[:1] == "$":
                    self.sysvars.declare(item.name.upper(), ref, item.span)

    def _machine_data(self, key: str, ref) -> None:
        """A machine data list (Mada) declares a system variable of the tables: the system
        variable takes its value (the data list only initialises it).

        A SIGNAL of the machine data that wires a system signal to an input or output
        (``SIGNAL $I_O_ACT $IN[11]`` in ``STEU/Mada/$machine.dat``) is no value: the state of
        that I/O at load time (FALSE) is not the system variable's value, and the wiring is
        not simulated (docs/robot.md "Presets": ``$I_O_ACT``, ``$MOVE_ENABLE``, ``$USER_SAF``
        keep their boot values). ``SIGNAL $X FALSE`` (a signal permanently FALSE) is a value
        and is taken."""
        sv = self.sysvars
        if key not in sv.store or isinstance(ref, SignalRef):
            return
        try:
            v = ref.peek()
            cur = sv.store[key]
            if isinstance(cur, Struct) or hasattr(cur, "dims"):
                assign_into(cur, v)
            elif v is not UNSET:
                sv.store[key] = v
        except KrlRuntimeError:
            pass

    def signal_ref(self, item: N.SignalDecl):
        if item.start is None:   # `SIGNAL $NAME FALSE`: a signal permanently FALSE
            return Slot({"V": False}, "V", T.BOOL, item.name, readonly=True)
        sv = self.sysvars.lookup(item.start.sysvar.upper())
        if sv is None:
            return None
        arr = sv.peek()
        if not getattr(arr, "is_live_array", False):
            return None
        end = item.end.index if item.end is not None else None
        return SignalRef(arr, item.start.index, end, item.name)

    # ------------------------------------------------------------------ storage
    def data_ref(self, st: Storage):
        """The reference of a MODULE or GLOBAL storage (its data list loaded on demand, for an
        initialiser that names another list's variable)."""
        m = self.modules[st.owner]
        ref = m.refs[st.slot]
        if ref is None and not m.loaded:
            self.ensure_loaded(m)
            ref = m.refs[st.slot]
        if ref is None:
            raise KrlRuntimeError(f"unknown name {st.name}", name=st.name)
        return ref

    def literal(self, e, t=None):
        """Value of a data-list or CONST initialiser: literals, aggregates, a leading sign and
        constants (a name's resolved storage), by the front end's evaluator
        (krl/semantics/expression.py) reading this program's data lists. `t`: the declared
        type (the caller converts the value to it)."""
        return evaluate(e, self._initialiser_env)


def _outside_types(program: Program) -> frozenset:
    """The types among :func:`kuka_names` (W105): :meth:`Program.declared_type`'s decision."""
    return frozenset(k for kind, k in kuka_names(program) if kind == "type")


class _InitialiserEnv(Env):
    """What a data-list or CONST initialiser reads (krl.semantics.expression.Env): another
    data list's variable or a system variable, by the storage the resolver gave the name;
    an aggregate is a Struct of the STRUC its TYPE prefix names."""

    def __init__(self, program: Program) -> None:
        self.program = program

    def refuse(self, node, what: str):
        raise KrlRuntimeError("only literal values are allowed in a data list")

    def name(self, node: N.Name):
        st = node.ann.place if node.ann is not None else None
        program = self.program
        if isinstance(st, Storage) and st.kind in (MODULE, GLOBAL):
            return lambda: program.data_ref(st).get()
        if isinstance(st, Storage) and st.kind == SYSTEM:
            return lambda: program.system_ref(st).get()
        raise KrlRuntimeError(f"unknown name {node.name} in a data list initialisation")

    def aggregate(self, node: N.Aggregate, items: list):
        struc = node.ann.struc if node.ann is not None else None
        return lambda: Struct(struc, {k: r() for k, r in items})


def _has_unknown(t) -> bool:
    return isinstance(t, T.Array) and t.elem is T.UNKNOWN


def _in_mada(m: ModuleRT) -> bool:
    p = m.files.get("dat")
    return p is not None and p.parent.name.upper() == "MADA"


__all__ = ["BASIS_DIR", "LOCAL", "ModuleRT", "Program", "SyntaxProblem", "basis_files", "checked_workspace",
           "forget_below", "parse_module", "program_files", "workspace_cost", "charge_models"]
