"""Loading a program and its environment; name resolution (reference §2.1-§2.7).

:class:`Program` indexes the files of the workspace (module name = file stem), parses
them lazily (each file once) and builds the run-time module objects
(:class:`ModuleRT`): routines, data-list store (initialised from the DECL values, kept
for the whole run, so .dat state persists across calls), types (STRUC/ENUM).

Environment:

* the program's files are those of krl.project.project_of (one rule for every command): the
  KRC backup holding the program (its whole root, ``R1`` and ``STEU``), else every KRL file
  below the program's folder (or ``--workspace``);
* outside a KRC backup the project's BASIS (interp/basis: ``$config.dat``, ``bas.src``,
  ``ir_stopm.src``) is the system folder; inside a backup its own System folder is used, and
  the backup's ``Mada`` data lists (``$machine.dat``, ...) declare further system variables.
  Files are read in place, never copied.

Resolution order for a name (§2.7): locals/parameters -> the module's data list ->
globals (``$config.dat``, GLOBAL names of PUBLIC data lists, system data lists) ->
system variables. Routines: the module's own routines -> GLOBAL routines and module main
routines -> built-in natives -> the stub policy (see :meth:`Program.find_routine`).

This is the runtime's own small resolver; when the front end's checker has annotated a
node (``node.ann.symbol``), the interpreters may use that instead (docs/architecture.md).
"""

from __future__ import annotations

from pathlib import Path

from krl.ast import nodes as N
from krl.project import project_of   # which files make the program: one rule
from krl.semantics import types as T
from krl.semantics.symbols import Scope, fill_struc, make_array, system_scopes

from .convert import assign_into, convert_scalar
from .errors import KrlRuntimeError, ResourceError
from .memory import Slot, SignalRef
from .values import UNSET, EnumValue, Struct, data_size, make_value

BASIS_DIR = Path(__file__).resolve().parent.parent / "basis"
KRL_SUFFIXES = {".src": "src", ".dat": "dat", ".sub": "sub"}

_PARSE_CACHE: dict = {}


class SyntaxProblem(str):
    """A syntax error of a file as text (``file:line:col: message``) that keeps its place
    (``file``, ``line``) for the run-time error that stops the program from starting."""

    def __new__(cls, text: str, file: str | None = None, line: int | None = None) -> "SyntaxProblem":
        self = super().__new__(cls, text)
        self.file = file
        self.line = line
        return self


def parse_module(path: str):
    """(Module AST, list of syntax error strings) of one file, cached per process."""
    from krl.source import read_source  # noqa: PLC0415

    # read once (a FIFO or device is classified, never opened); the key is the hash of the
    # very bytes that are parsed
    src = read_source(path)
    key = (str(path), src.sha or src.status)
    got = _PARSE_CACHE.get(key)
    if got is not None:
        return got
    from krl.ast.build import build_module  # noqa: PLC0415
    from krl.diagnostics import DiagnosticSink  # noqa: PLC0415
    from krl.syntax.parse import parse_source  # noqa: PLC0415
    from krl.syntax.messages import syntax_diagnostics  # noqa: PLC0415

    res = parse_source(src)
    sink = DiagnosticSink()
    mod = build_module(res, sink)  # E003: a construct that cannot be built stops the start too
    errs = [SyntaxProblem(f"{d.path}:{d.line}:{d.column}: {d.message}", d.path, d.line)
            for d in syntax_diagnostics(res, src.text) + sink.errors]
    if not res.ok and not res.errors:
        errs.append(f"{path}: file not read: {res.status}" + (f" ({src.detail})" if src.detail else ""))
    got = (mod, errs)
    _PARSE_CACHE[key] = got
    return got


class ModuleRT:
    """A module at run time: routines, data list store and types."""

    def __init__(self, name: str, program: "Program") -> None:
        self.name = name
        self.program = program
        self.files: dict[str, Path] = {}
        self.routines: dict[str, N.Routine] = {}
        self.main: N.Routine | None = None
        self.data: dict = {}            # UPPER -> Ref (data-list variables, signals)
        self.store: dict = {}
        self.types = Scope("module", name, program.types)
        self.loaded = False
        self.errors: list[str] = []         # data-list initialisation problems
        self.syntax_errors: list[str] = []  # syntax errors of its files (cannot run)
        self.path = ""


class Program:
    def __init__(self, rt, main_path: str | Path, workspace: str | Path | None = None) -> None:
        self.rt = rt
        self.main_path = Path(main_path).resolve()
        self.project = project_of(self.main_path, Path(workspace).resolve() if workspace else None)
        self.backup = self.project.backup
        self.workspace = self.project.root
        self.system_dir = self.project.system if self.backup and self.project.system else BASIS_DIR
        system, basis = system_scopes()
        self.types = Scope("global", "$CONFIG", basis)
        self.globals: dict = {}
        self.global_routines: dict = {}
        self.modules: dict[str, ModuleRT] = {}
        self.index: dict[str, dict[str, Path]] = {}
        self.stubs: set[str] = set()
        self._scanned_all = False
        self.fatal: ResourceError | None = None   # a data list past a limit: the program cannot start
        self._index_files()
        self._load_system()

    # ------------------------------------------------------------------ files
    def _add_file(self, p: Path, system: bool = False) -> None:
        kind = KRL_SUFFIXES.get(p.suffix.lower())
        if kind is None:
            return
        name = p.stem.upper()
        entry = self.index.setdefault(name, {})
        if kind not in entry or system:
            entry[kind] = p

    def _index_files(self) -> None:
        """The program's files (krl.project.project_of, in walk order; the first file of a
        module name and kind counts), then, outside a backup, the project's BASIS."""
        for p in self.project.files:
            self._add_file(p)
        if not self.backup:
            for p in sorted(self.system_dir.iterdir()):
                if p.is_file() and p.stem.upper() not in self.index:
                    self._add_file(p, system=True)
        self._add_file(self.main_path)

    def _load_system(self) -> None:
        try:
            self._load_system_data()
        except ResourceError as exc:     # the program cannot start (Runtime.main_routine)
            self.fatal = self.fatal or exc

    def _load_system_data(self) -> None:
        cfg = self.index.get("$CONFIG", {}).get("dat")
        if cfg is None:
            cfg = next((p for p in self.system_dir.iterdir() if p.name.upper() == "$CONFIG.DAT"), None)
        if cfg is not None:
            m = self.module("$CONFIG")
            for k, ref in m.data.items():
                self.globals.setdefault(k, ref)
        if self.backup:
            # the machine data lists of the backup (R1/Mada, STEU/Mada): system variables
            mada = [p for p in self.project.files
                    if p.suffix.lower() == ".dat" and p.parent.name.upper() == "MADA"]
            for p in sorted(mada):
                try:
                    self._load_sysdata(p)
                except ResourceError:
                    raise
                except KrlRuntimeError:
                    continue

    def _load_sysdata(self, p: Path) -> None:
        mod, errs = parse_module(str(p))
        if mod.data is None:
            return
        m = ModuleRT(p.stem.upper(), self)
        m.types = self.types
        self._load_data(m, mod.data, all_global=False)
        sv = self.rt.sysvars
        for key, ref in m.data.items():
            if key in sv.store:
                # machine data for a system variable of the table: take the backup's value
                try:
                    v = ref.peek()
                    cur = sv.store[key]
                    if isinstance(cur, Struct) or hasattr(cur, "dims"):
                        assign_into(cur, v)
                    elif v is not UNSET:
                        sv.store[key] = v
                except KrlRuntimeError:
                    pass
            elif key not in sv.info:
                self.globals.setdefault(key, ref)

    # ------------------------------------------------------------------ modules
    def module(self, name: str) -> ModuleRT | None:
        key = name.upper()
        m = self.modules.get(key)
        if m is not None:
            return m
        files = self.index.get(key)
        if not files:
            return None
        m = ModuleRT(key, self)
        self.modules[key] = m
        m.files = files
        is_config = key == "$CONFIG"
        if is_config:
            m.types = self.types
        dat = files.get("dat")
        if dat is not None:
            mod, errs = parse_module(str(dat))
            m.syntax_errors += errs
            if mod.data is not None:
                try:
                    self._load_data(m, mod.data, all_global=is_config)
                except ResourceError as exc:
                    self.fatal = self.fatal or exc
                    raise
        src = files.get("src") or files.get("sub")
        if src is not None:
            mod, errs = parse_module(str(src))
            m.syntax_errors += errs
            m.path = str(src)
            for i, r in enumerate(mod.routines):
                m.routines.setdefault(r.name.upper(), r)
                if i == 0:
                    m.main = r
                if r.is_global or i == 0:
                    self.global_routines.setdefault(r.name.upper(), (m, r))
        m.loaded = True
        return m

    def _load_data(self, m: ModuleRT, data: N.DataList, all_global: bool) -> None:
        """Declare and initialise a data list's variables in ``m`` (§2.5). A declaration that
        fails (unknown type, bad initialiser) is recorded in ``m.errors`` and skipped."""
        for item in data.items:
            try:
                self._load_item(m, data, item, all_global)
            except ResourceError:
                raise
            except KrlRuntimeError as exc:
                m.errors.append(f"line {item.span.line}: {exc.message}")

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
        return self.rt.memory.take(n, vn.name, span.file, span.line)

    def take_memory(self, t, vn: N.VarName, decl) -> int:
        """Reserve the run's data memory for variable ``vn`` of type ``t`` (a data-list or
        routine DECL, ``decl``) before anything is allocated; returns the elements taken."""
        return self.take_memory_n(self.data_elements(t, vn, decl), vn, decl)

    def _load_item(self, m: ModuleRT, data: N.DataList, item, all_global: bool) -> None:
        if True:
            is_glob = all_global or (data.public and getattr(item, "is_global", False))
            if isinstance(item, N.StrucDecl):
                st = T.Struc(item.name)
                scope = self.types if (item.is_global or all_global) else m.types
                scope.types[item.name.upper()] = st
                fill_struc(scope, st, [(c.type_name, c.name, tuple(c.dims)) for c in item.components])
            elif isinstance(item, N.EnumDecl):
                en = T.Enum(item.name, frozenset(v.upper() for v in item.values))
                scope = self.types if (item.is_global or all_global) else m.types
                scope.types[item.name.upper()] = en
            elif isinstance(item, N.VarDecl):
                t0 = self.resolve_type(item.type, m.types)
                for vn in item.names:
                    t = make_array(t0, vn.dims) if vn.dims else t0
                    key = vn.name.upper()
                    self.take_memory(t, vn, item)
                    m.store[key] = make_value(t)
                    ref = Slot(m.store, key, t, vn.name, readonly=item.is_const)
                    if item.init is not None:
                        try:
                            v = self.literal(item.init, t, m)
                            cur = m.store[key]
                            if isinstance(cur, (Struct,)) or hasattr(cur, "dims"):
                                assign_into(cur, v)
                            else:
                                m.store[key] = convert_scalar(v, t)
                        except KrlRuntimeError as exc:
                            m.errors.append(f"{vn.name}: {exc.message}")
                    m.data[key] = ref
                    if is_glob:
                        self.globals[key] = ref
            elif isinstance(item, N.ArrayInit):
                ref = m.data.get(item.name.upper())
                if ref is None:
                    return
                try:
                    from .memory import index_ref  # noqa: PLC0415

                    target = index_ref(ref, list(item.indices), item.name)
                    target.set(self.literal(item.value, target.type, m)) if not isinstance(
                        target.peek(), Struct) else assign_into(target.peek(), self.literal(item.value, target.type, m))
                except KrlRuntimeError as exc:
                    m.errors.append(f"{item.name}: {exc.message}")
            elif isinstance(item, N.ImportDecl):
                ref = self.import_ref(item)
                m.data[item.name.upper()] = ref
            elif isinstance(item, N.SignalDecl):
                ref = self.signal_ref(item)
                if ref is not None:
                    m.data[item.name.upper()] = ref
                    if is_glob:
                        self.globals[item.name.upper()] = ref

    def import_ref(self, item: N.ImportDecl):
        """``IMPORT type name IS /R1/module..var``: the other data list's variable (§2.5)."""
        path = [p for p in item.path if p]
        if len(path) < 2:
            raise KrlRuntimeError(f"IMPORT {item.name}: bad path")
        mod = self.module(path[-2])
        ref = mod.data.get(path[-1].upper()) if mod is not None else None
        if ref is None:
            raise KrlRuntimeError(f"IMPORT {item.name}: {'/'.join(path)} not found")
        return ref

    def signal_ref(self, item: N.SignalDecl):
        if item.start is None:   # `SIGNAL $NAME FALSE`: a signal permanently FALSE
            return Slot({"V": False}, "V", T.BOOL, item.name, readonly=True)
        sv = self.rt.sysvars.lookup(item.start.sysvar.upper())
        if sv is None:
            return None
        arr = sv.peek()
        if not getattr(arr, "is_live_array", False):
            return None
        end = item.end.index if item.end is not None else None
        return SignalRef(arr, item.start.index, end, item.name)

    # ------------------------------------------------------------------ types and literals
    def scan_types(self) -> None:
        """Register the GLOBAL STRUC/ENUM types of every data list of the workspace (once):
        all types first, then the structure components (types may refer to each other)."""
        if getattr(self, "_types_scanned", False):
            return
        self._types_scanned = True
        pending = []
        for name, files in list(self.index.items()):
            dat = files.get("dat")
            if dat is None:
                continue
            mod, _ = parse_module(str(dat))
            if mod.data is None:
                continue
            for item in mod.data.items:
                if isinstance(item, N.StrucDecl) and item.is_global:
                    if item.name.upper() not in self.types.types:
                        st = T.Struc(item.name)
                        self.types.types[item.name.upper()] = st
                        pending.append((st, item))
                elif isinstance(item, N.EnumDecl) and item.is_global:
                    self.types.types.setdefault(item.name.upper(), T.Enum(
                        item.name, frozenset(v.upper() for v in item.values)))
        for st, item in pending:
            fill_struc(self.types, st, [(c.type_name, c.name, tuple(c.dims)) for c in item.components])

    def resolve_type(self, tref, scope: Scope):
        name = tref.name if isinstance(tref, N.TypeRef) else str(tref)
        t = scope.lookup_type(name)
        if t is None:
            self.scan_types()
            t = scope.lookup_type(name)
        if t is None:
            if not self.backup:
                raise KrlRuntimeError(f"unknown type {name}")
            # a type of the controller's system data lists that the backup does not hold
            # (e.g. ESYS of $operate.dat): untyped, logged once
            if name.upper() not in self.stubs:
                self.stubs.add(name.upper())
                self.rt.message(f"not simulated: type {name} (undeclared; values are untyped)")
            t = T.UNKNOWN
        size = tref.size if isinstance(tref, N.TypeRef) else None
        if size:
            t = T.Array(t, (size,))
        return t

    def literal(self, e, t, m: ModuleRT):
        """Value of a data-list initialiser (literals, aggregates, leading minus, constants)."""
        if isinstance(e, N.IntLit):
            return e.value
        if isinstance(e, N.RealLit):
            return e.value
        if isinstance(e, N.BoolLit):
            return e.value
        if isinstance(e, N.StrLit):
            return e.value
        if isinstance(e, N.EnumLit):
            return EnumValue(e.name)
        if isinstance(e, N.Unary) and e.op in ("-", "+"):
            v = self.literal(e.operand, t, m)
            return -v if e.op == "-" else v
        if isinstance(e, N.Aggregate):
            st = None
            if e.type_name:
                st = m.types.lookup_type(e.type_name)
            out = Struct(st if isinstance(st, T.Struc) else None, {})
            ft = t if isinstance(t, T.Struc) else st
            for it in e.items:
                sub_t = ft.fields.get(it.name.upper(), (None, None))[1] if isinstance(ft, T.Struc) else None
                out.f[it.name.upper()] = self.literal(it.value, sub_t, m)
            return out
        if isinstance(e, N.Name):
            ref = m.data.get(e.name.upper()) or self.globals.get(e.name.upper())
            if ref is not None:
                return ref.get()
            raise KrlRuntimeError(f"unknown name {e.name} in a data list initialisation")
        raise KrlRuntimeError("only literal values are allowed in a data list")

    # ------------------------------------------------------------------ resolution
    def scan_all(self) -> None:
        """Load every module of the workspace once (to find GLOBAL routines and data)."""
        if self._scanned_all:
            return
        self._scanned_all = True
        for name in list(self.index):
            try:
                self.module(name)
            except ResourceError:
                raise
            except KrlRuntimeError:
                continue
            except RecursionError:
                continue

    def lookup_global(self, name: str):
        key = name.upper()
        ref = self.globals.get(key)
        if ref is None and not self._scanned_all:
            self.scan_all()
            ref = self.globals.get(key)
        return ref

    def find_routine(self, name: str, module: ModuleRT | None):
        """(ModuleRT, Routine) for a call of ``name`` from ``module``, or None."""
        key = name.upper()
        if module is not None:
            r = module.routines.get(key)
            if r is not None:
                return module, r
        got = self.global_routines.get(key)
        if got is not None:
            return got
        m = self.module(key)
        if m is not None and m.main is not None and m.main.name.upper() == key:
            return m, m.main
        if not self._scanned_all:
            self.scan_all()
            return self.global_routines.get(key)
        return None


