"""A KRL program as a set of files (reference 2.1, 2.5, 2.7).

A :class:`Workspace` holds parsed files (:class:`SourceFile`, each with its AST), the scope
hierarchy of :mod:`krl.semantics.symbols` and the diagnostics. Pairing and visibility:

* ``NAME.src`` (or ``.sub``) and ``NAME.dat`` in the same folder form one module: the data
  list is the module scope of the routines;
* ``$config.dat`` and the system data lists (any ``DEFDAT $NAME``: ``$machine.dat``,
  ``$custom.dat``, ``$option.dat``, ``$robcor.dat``, ``$operate.dat``) are global;
* ``DEFDAT X PUBLIC`` exports its ``GLOBAL`` declarations; the main routine (first routine)
  of every module and every ``GLOBAL DEF/DEFFCT`` are global routines;
* ``IMPORT`` declarations bring another module's data under a local name.

A KRC backup folder (``KRC/R1/Program``, ``R1/System`` with ``bas.src`` and ``$config.dat``,
``R1/Mada``, ``R1/TP``, ``STEU/Mada``; any letter case) loads as one workspace:
krl/project.py says which files form a program (:func:`krl.project.project_of`, one rule for
every command); :func:`load_project` and :func:`load_workspace` load them.
Files are read with krl.source.read_source and parsed with parse_source only.

Usage::

    ws = load_workspace([Path("KRC")])
    ws.check()                      # runs the checker, fills ws.diagnostics
    ws.modules["DEMO"].routines     # AST; expression types in node.ann.type
"""

from __future__ import annotations

import gc
import re
import time
from collections.abc import Callable
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path

from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.files import Entry
from krl.project import (ProgramFiles, collect_entries, folder_groups, is_submit_file, is_system_path, module_key,
                         modules_of, project_of)
from krl.project import module_files as project_module_files
from krl.semantics.builtins import load_builtins
from krl.semantics.checker import Checker, Declarer, _is_system_datalist
from krl.diagnostics import Diagnostic, DiagnosticSink
from krl.semantics.outside import Unresolved, template_lines
from krl.semantics.resolve import resolve_workspace
from krl.semantics.symbols import Scope, Symbol, system_scopes
from krl.syntax.folds import fold_diagnostics
from krl.syntax.messages import syntax_diagnostics
from krl.syntax.engines import EngineUnavailable, java_answers, parse_source, resolve, result_from_answer
from krl.syntax.parse import ParseResult, default_bundle, parse_text
from krl.source import SourceText, is_krl_file, read_source


@dataclass(slots=True)
class SourceFile:
    """One file of the workspace: its AST, whether it parsed, and its module scope."""
    path: str
    module: N.Module
    ok: bool
    status: str = "ok"
    scope: Scope | None = None
    parse_seconds: float = 0.0


@dataclass(slots=True)
class LoadedFile:
    """One file read, parsed and built, apart from any workspace (picklable: it may come from
    a worker process): its AST, its diagnostics (input, syntax, build) and what a failed
    parse leaves for name lookup."""
    path: str
    module: N.Module
    ok: bool
    status: str
    parse_seconds: float
    build_seconds: float
    diagnostics: list
    unreadable: bool = False
    failed_words: set = field(default_factory=set)
    # (INI-fold lines, inline-form lines) of KUKA's templates (krl/semantics/outside.py)
    template: tuple = (frozenset(), frozenset())


# Below this many bytes a batch of files is parsed by the Python engine: starting the Java
# engine's worker costs more than it saves. Measured (load_batch, 2 jobs, interleaved): 24 KB
# python 0.42-0.46 s, java 0.52-0.62 s; 54 KB even; 77 KB 0.66-1.08 s against 0.58-0.82 s;
# 234 KB 2.3-2.8 s against 1.8-1.9 s; 352 KB 3.9-4.1 s against 1.7-2.5 s.
JAVA_BATCH_BYTES = 64 * 1024


def load_file(path: str | Path) -> LoadedFile:
    """Read (krl.source.read_source), parse (the Python engine) and build one file;
    never raises for bad content."""
    t = time.perf_counter()
    src = read_source(path)
    return _loaded(src, parse_source(src, keep_tree=True, engine="python"), t)


def load_parsed(src: SourceText, raw: bytes | None = None) -> LoadedFile:
    """Build one read file from the Java engine's answer `raw` (its parse tree is rebuilt,
    krl/syntax/engines/tree.py), or parse it with the Python engine when raw is None;
    never raises for bad content."""
    t = time.perf_counter()
    if raw is None:
        return _loaded(src, parse_source(src, keep_tree=True, engine="python"), t)
    return _loaded(src, result_from_answer(src, raw, keep_tree=True), t)


def _loaded(src: SourceText, result: ParseResult, started: float) -> LoadedFile:
    elapsed = time.perf_counter() - started
    path_s = src.path
    sink = DiagnosticSink()
    if result.status not in ("ok", "syntax_error") and not result.errors:
        sink.add(path_s, 1, 1, "E001", f"file not checked: {result.status}"
                 + (f" ({src.detail})" if src.detail else ""))
    sink.extend(syntax_diagnostics(result, src.text))
    sink.extend(fold_diagnostics(path_s, src.text))
    t = time.perf_counter()
    unreadable, words = False, set()
    if not result.ok:
        if result.status in ("binary", "too_large", "unreadable", "not_regular"):
            unreadable = True
        elif src.text:
            words = {w.upper() for w in _WORD.findall(src.text)}
    module = build_module(result, sink)
    return LoadedFile(path_s, module, result.ok, result.status, elapsed, time.perf_counter() - t,
                      sink.items, unreadable, words, template_lines(src.text or ""))


def load_batch(paths: list, timeout: float, jobs: int | None = None) -> list:
    """Read `paths` here, parse and build them in `jobs` worker processes (krl/pool.py), each
    file stopped past `timeout` seconds; returns one krl.pool.Outcome per path, in order (value:
    a LoadedFile). A batch of at least JAVA_BATCH_BYTES is parsed by the Java engine
    (:func:`_parse_tasks`): the same trees. Progress: the :func:`on_each_file` callback, as
    files finish."""
    # on use: the worker pool (pebble) costs 0.42 s (python -X importtime, 2026-11-23, load average
    # 22 on the 2 cores), which single files, `krl run` and the language server, who never start a
    # pool, do not pay
    from krl.pool import run_tasks  # noqa: PLC0415

    default_bundle()    # imported once here, inherited by the forked workers
    hook = _ON_FILE.get()
    sources = [read_source(p) for p in paths]
    done: list = [None] * len(paths)
    # The ASTs arriving here are millions of new objects and next to no garbage: the cyclic
    # collector's passes over the growing heap cost more than the unpickling (main-process CPU
    # for the whole corpus 6.4 s with them, 2.7 s without); it runs once the batch is in.
    enabled = gc.isenabled()
    gc.disable()
    try:
        # (the workers, forked from here, collect as usual: their parse trees are cyclic garbage)
        for o in run_tasks(load_parsed, _parse_tasks(sources, jobs, timeout), jobs=jobs, timeout=timeout,
                           initializer=gc.enable):
            done[o.key] = o
            sources[o.key] = None
            if hook is not None:
                hook(str(paths[o.key]))      # progress as files finish, in any order
    finally:
        if enabled:
            gc.enable()
    return done


def _parse_tasks(sources: list[SourceText], jobs: int | None, stall: float):
    """(index, (source, raw)) for :func:`load_parsed` in worker processes: one Java worker
    with `jobs` threads parses a batch of at least JAVA_BATCH_BYTES here, with trees, while
    the workers rebuild and build what it has answered (raw None: the Python engine)."""
    from krl.pool import default_jobs  # noqa: PLC0415 - on use: the pool's 0.42 s (run_tasks above)

    try:
        engine = resolve()
    except EngineUnavailable:
        engine = "python"
    # big files first, so that the workers' tail is short
    order = sorted(range(len(sources)), key=lambda i: -sources[i].size)
    if engine != "java" or sum(s.size for s in sources) < JAVA_BATCH_BYTES:
        for i in order:
            yield i, (sources[i], None)
        return
    for i, src, raw in java_answers(((i, sources[i]) for i in order), threads=jobs or default_jobs(),
                                    trees=True, stall=stall, decode=False):
        yield i, (src, raw)


@dataclass(slots=True)
class ModuleUnit:
    """A module: its .src/.sub file and/or its .dat file, sharing one module scope."""
    name: str
    src: SourceFile | None = None
    dat: SourceFile | None = None
    scope: Scope | None = None

    @property
    def routines(self) -> list[N.Routine]:
        return self.src.module.routines if self.src is not None else []


@dataclass
class Workspace:
    """Files, scopes and diagnostics of one program (see the module docstring)."""
    root: str
    files: list[SourceFile] = field(default_factory=list)
    units: list[ModuleUnit] = field(default_factory=list)
    global_scope: Scope | None = None
    sink: DiagnosticSink = field(default_factory=DiagnosticSink)
    routine_scopes: dict[int, Scope] = field(default_factory=dict)
    parse_seconds: float = 0.0
    check_seconds: float = 0.0
    checked: bool = False
    # words of files that did not parse: a name among them may be declared there
    failed_words: set = field(default_factory=set)
    unreadable: bool = False
    # path -> (INI-fold lines, inline-form lines) of KUKA's templates (krl/semantics/outside.py)
    template: dict = field(default_factory=dict)
    # when set: only these paths' routine bodies and data-list values are checked (the other
    # files still declare their names); one file in the context of its backup
    check_only: set | None = None
    # the system variables the program uses, by Storage.slot, and the resolver that placed
    # every name (krl/semantics/resolve.py)
    system_names: list = field(default_factory=list)
    resolver: object = None
    # what an editor needs to re-check one module after a change (krl/lsp/incremental.py):
    # the declarer and checker of the last check, the ids of the diagnostics of its body phase
    # (routine scopes, data-list values, routine bodies) and of the unresolved-name report
    phases: dict = field(default_factory=dict)

    def maybe_declared(self, name: str) -> bool:
        """True when a file that could not be parsed (or read) may declare `name`."""
        return self.unreadable or name.upper() in self.failed_words

    def evidence(self, path: str, line: int, kind: str) -> str:
        """Why a use at path:line says installed software declares the name, or "" (the
        template's INI fold; a KUKA inline form, for routines and types)."""
        ini, inline = self.template.get(path, (frozenset(), frozenset()))
        if line in ini:
            return "the template's INI fold uses it (KUKA's template and technology packages write that fold)"
        if line in inline and kind in ("routine", "type"):
            return "a KUKA inline form (;FOLD ... ;%{PE}) uses it"
        return ""

    def _note_failed(self, result, text: str) -> None:
        if result.ok:
            return
        if result.status in ("binary", "too_large", "unreadable", "not_regular"):
            self.unreadable = True
        elif text:
            self.failed_words.update(w.upper() for w in _WORD.findall(text))

    @property
    def diagnostics(self) -> list[Diagnostic]:
        """All diagnostics so far, sorted by path, line, column; with :attr:`check_only`, those
        of the files checked."""
        out = self.sink.sorted()
        if self.check_only is not None:
            out = [d for d in out if d.path in self.check_only]
        return out

    @property
    def modules(self) -> dict[str, ModuleUnit]:
        """Module units by upper-case name."""
        return {u.name.upper(): u for u in self.units}

    @property
    def incomplete(self) -> bool:
        """True when a file of the workspace did not parse."""
        return any(not f.ok for f in self.files)

    def lookup_routine(self, name: str) -> Symbol | None:
        """A global routine (main routine of a module, GLOBAL routine or built-in) by name;
        ``sym.decl`` is its Routine node for routines of the workspace."""
        return self.global_scope.lookup_routine(name) if self.global_scope is not None else None

    def routine_scope(self, routine: N.Routine) -> Scope | None:
        """The scope of a routine's parameters and locals (after :meth:`check`)."""
        return self.routine_scopes.get(id(routine))

    def add_file(self, path: str | Path) -> SourceFile:
        """Read, parse and build one file (never raises for bad content)."""
        return self._add_loaded(load_file(path))

    def add_files(self, paths, timeout: float | None = None, jobs: int | None = None) -> None:
        """:meth:`add_file` for each of `paths`, in order. With `timeout` (seconds per file) the
        files are read here and parsed and built in worker processes (:func:`load_batch`)."""
        paths = list(paths)
        if timeout is None or not paths:
            for p in paths:
                self.add_file(p)
            return
        for p, outcome in zip(paths, load_batch(paths, timeout, jobs)):
            self.add_outcome(p, outcome, timeout)

    def add_outcome(self, path, o, timeout: float) -> None:
        """Add one file of :func:`load_batch`: its LoadedFile, or E005 (stopped past `timeout`
        seconds) or E001 (its worker died) and an empty module."""
        if o.status == "done":
            self._add_loaded(o.value, notify=False)
            return
        if o.status == "timeout":
            self.sink.add(str(path), 1, 1, "E005", f"file not checked: not parsed within {timeout:g} s "
                          "(--timeout; the parse was stopped)")
        else:
            self.sink.add(str(path), 1, 1, "E001", f"file not checked: {o.detail}")
        self.unreadable = True
        module = build_module(ParseResult(str(path), False, "", o.status), DiagnosticSink())
        self.files.append(SourceFile(str(path), module, False, o.status))

    def _add_loaded(self, lf: "LoadedFile", notify: bool = True) -> SourceFile:
        self.parse_seconds += lf.parse_seconds
        self.check_seconds += lf.build_seconds
        self.sink.extend(lf.diagnostics)
        self.unreadable |= lf.unreadable
        self.failed_words |= lf.failed_words
        hook = _ON_FILE.get() if notify else None
        if hook is not None:
            hook(lf.path)
        self.template[lf.path] = lf.template
        sf = SourceFile(lf.path, lf.module, lf.ok, lf.status, parse_seconds=lf.parse_seconds)
        self.files.append(sf)
        return sf

    def add_text(self, text: str, path: str = "<string>.src") -> SourceFile:
        """Parse and build KRL text as if it were the file `path` (tests, editors, REPLs)."""
        t = time.perf_counter()
        result = parse_text(text, path)
        self.parse_seconds += time.perf_counter() - t
        self.sink.extend(syntax_diagnostics(result, text))
        self.sink.extend(fold_diagnostics(path, text))
        self._note_failed(result, text)
        self.template[path] = template_lines(text)
        module = build_module(result, self.sink)
        sf = SourceFile(path, module, result.ok, result.status)
        self.files.append(sf)
        return sf

    # ------------------------------------------------------------------ linking

    def _link_imports(self, checker: Checker) -> None:
        """IMPORT type name IS /R1/module..var (2.5): point the local name at the module's
        data-list variable (Symbol.alias, Symbol.module); report a missing target."""
        by_name: dict[str, ModuleUnit] = {}
        for u in self.units:
            for n in _unit_names(u):
                by_name.setdefault(n, u)
        for u in self.units:
            if u.scope is None:
                continue
            for sym in u.scope.values.values():
                d = sym.decl
                if not isinstance(d, N.ImportDecl) or len(d.path) < 3:
                    continue
                target_unit = by_name.get(d.path[1].upper())
                target = target_unit.scope.values.get(d.path[2].upper()) if target_unit and target_unit.scope else None
                if target is None and target_unit is not None and self.global_scope is not None:
                    g = self.global_scope.values.get(d.path[2].upper())
                    target = g if g is not None and g.module.upper() in _unit_names(target_unit) else None
                if target is None:
                    checker.not_found(d.span, f"{d.path[1]}..{d.path[2]}", u.scope)
                    continue
                sym.alias, sym.module = target, target.module

    def _pair(self) -> None:
        """The modules of the files (krl/project.py rule 5, :func:`krl.project.modules_of`)."""
        for name, code, dat in modules_of(self.files, lambda f: f.module.kind == "dat"):
            self.units.append(ModuleUnit(name, src=code, dat=dat))

    def check(self) -> list[Diagnostic]:
        """Link the files into scopes and run the checker; returns the sorted diagnostics."""
        if self.checked:
            return self.diagnostics
        t = time.perf_counter()
        self.checked = True
        try:
            self._check()
        except Exception as exc:  # noqa: BLE001 - never a traceback for bad input
            self.sink.add(self.root, 1, 1, "E901", f"internal checker error: {type(exc).__name__}: {exc}")
        self.check_seconds += time.perf_counter() - t
        return self.diagnostics

    def _check(self) -> None:
        _system, basis = system_scopes()
        incomplete = self.incomplete
        sink = self.sink
        declarer = Declarer(sink, incomplete, self.maybe_declared)
        declarer.unresolved = Unresolved(load_builtins().packages, self.maybe_declared)
        declarer.evidence = self.evidence
        checker = Checker(sink, declarer, incomplete)
        glob = Scope("global", "$GLOBAL", basis)
        self.global_scope = glob
        self._pair()

        # which scope each data list's declarations go to
        def targets(unit: ModuleUnit) -> list[tuple[Scope, list[N.Decl], str]]:
            out = []
            if unit.dat is not None and unit.dat.module.data is not None:
                dl = unit.dat.module.data
                if _is_system_datalist(dl.name):
                    out.append((glob, dl.items, dl.name))
                else:
                    exported = [d for d in dl.items if getattr(d, "is_global", False)]
                    local = [d for d in dl.items if not getattr(d, "is_global", False)]
                    if exported:
                        out.append((glob, exported, dl.name))
                    out.append((unit.scope, local, dl.name))
            return out

        for unit in self.units:
            unit.scope = Scope("module", unit.name, glob)
            for f in (unit.src, unit.dat):
                if f is not None:
                    f.scope = unit.scope
        plan = [(u, targets(u)) for u in self.units]
        for u, tg in plan:
            for scope, items, name in tg:
                declarer.declare_types(scope, items, system=_is_system_datalist(name), path=u.dat.path, module=name)
        for u, tg in plan:
            for scope, items, name in tg:
                declarer.soft_types = _is_system_datalist(name) or is_kuka_file(u.dat.path)
                declarer.fill_types(scope, items)
        declarer.soft_types = False
        # system data lists first, so that user globals that repeat them are the duplicates
        order = sorted(plan, key=lambda p: 0 if any(_is_system_datalist(n) for _, _, n in p[1]) else 1)
        for u, tg in order:
            for scope, items, name in tg:
                path = u.dat.path if u.dat is not None else ""
                if scope is glob and _is_system_datalist(name):
                    # several system data lists may repeat a declaration: first one wins
                    tmp = Scope("global-sys", name, glob)
                    declarer.soft_types = True  # they refer to $operate.dat, never in a backup
                    try:
                        declarer.declare_values(tmp, items, name, path)
                    finally:
                        declarer.soft_types = False
                    for k, v in tmp.values.items():
                        glob.values.setdefault(k, v)
                    for k, v in tmp.routines.items():
                        glob.routines.setdefault(k, v)
                else:
                    declarer.soft_types = is_kuka_file(path)
                    declarer.declare_values(scope, items, name, path)
                    declarer.soft_types = False

        for u in self.units:
            if u.dat is not None and u.dat.module.data is not None and not _is_system_datalist(u.dat.module.data.name):
                _global_and_local_twice(u.dat.module.data, declarer)
        self._link_imports(checker)

        # routines: main routines and GLOBAL ones are global, others module-local
        routine_syms: list[tuple[N.Routine, Symbol, ModuleUnit]] = []
        for u in self.units:
            if u.src is None:
                continue
            declarer.soft_types = is_kuka_file(u.src.path)
            for i, r in enumerate(u.src.module.routines):
                declarer.ident(r.name, r.span)
                is_global = i == 0 or r.is_global
                scope = glob if is_global else u.scope
                sym = declarer.routine_symbol(r, u.name, u.src.path, u.scope)
                old = scope.routines.get(r.name.upper())
                if old is not None and isinstance(old.decl, N.Routine):
                    declarer.duplicate(r.name, r.span, old)
                else:
                    scope.routines[r.name.upper()] = sym  # a routine replaces its EXT signature
                if is_global and scope is glob:
                    u.scope.routines.setdefault(r.name.upper(), sym)
                routine_syms.append((r, sym, u))
            declarer.soft_types = False
            if u.src.module.routines:
                main = u.src.module.routines[0]
                if main.name.upper() != u.name.upper() and not is_submit_file(u.src.path):
                    sink.at(main.span, "W111", f"main routine '{main.name}' differs from the file name '{u.name}'")

        # routine scopes (parameters and locals), then signatures, then bodies
        body_mark = len(sink.items)
        for r, sym, u in routine_syms:
            declarer.soft_types = is_kuka_file(u.src.path)
            local = Scope("routine", r.name, u.scope)
            declarer.declare_types(local, r.decls, path=u.src.path, module=u.name)
            declarer.fill_types(local, r.decls)
            declarer.declare_values(local, r.decls, u.name, u.src.path if u.src else "")
            declarer.complete_signature(sym, local)
            self.routine_scopes[id(r)] = local
        declarer.soft_types = False
        for u in self.units:
            if u.dat is not None and u.dat.module.data is not None and u.dat.ok:
                if self.check_only is not None and u.dat.path not in self.check_only:
                    continue
                checker.system_file = declarer.soft_types = is_kuka_file(u.dat.path)
                checker.check_datalist(u.dat.module.data, u.scope)
        for r, _sym, u in routine_syms:
            if u.src is None or not u.src.ok:
                continue  # a file with syntax errors: its AST may miss tokens; E002 says why
            if self.check_only is not None and u.src.path not in self.check_only:
                continue
            checker.system_file = declarer.soft_types = is_kuka_file(u.src.path)
            checker.submit = is_submit_file(u.src.path)
            checker.check_routine(r, self.routine_scopes[id(r)], u.src.path)
        checker.system_file = declarer.soft_types = checker.submit = False
        finish_mark = len(sink.items)
        declarer.unresolved.finish(sink)
        self.phases = {"declarer": declarer, "checker": checker,
                       "body": {id(d) for d in sink.items[body_mark:finish_mark]},
                       "unresolved": {id(d) for d in sink.items[finish_mark:]},
                       "routine_symbols": {id(r): sym for r, sym, _u in routine_syms}}
        # advisory warnings are for code its maintainer can change: not for KUKA's own files
        kuka = {f.path for f in self.files if is_kuka_file(f.path)} | {
            u.dat.path for u in self.units
            if u.dat is not None and u.dat.module.data is not None and _is_system_datalist(u.dat.module.data.name)}
        sink.items = [d for d in sink.items if not (d.code in ADVISORY and d.path in kuka)]
        # every use gets its storage and every statement its advance-run facts, once, for the
        # interpreters (krl/semantics/resolve.py)
        resolve_workspace(self)


_ON_FILE: ContextVar[Callable[[str], None] | None] = ContextVar("krl_workspace_on_file", default=None)


@contextmanager
def on_each_file(callback: Callable[[str], None]):
    """``with on_each_file(cb):`` calls ``cb(path)`` after each file that a workspace reads and
    parses (progress display of `krl check`); the hook ends with the block."""
    token = _ON_FILE.set(callback)
    try:
        yield
    finally:
        _ON_FILE.reset(token)


# warnings that advise a change of the code (docs/diagnostics.md): not reported in KUKA's files
ADVISORY = frozenset({"W108", "W111", "W201", "W202", "W205", "W206", "W210", "W501"})
_WORD = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")


def _global_and_local_twice(dl: N.DataList, declarer: Declarer) -> None:
    """E102 for a name that one data list declares both GLOBAL and not (2.5, 2.7): the two go
    to different scopes (global and module), so the scopes alone do not see the repeat."""
    first: dict[str, tuple[object, bool]] = {}
    for d in dl.items:
        is_global = bool(getattr(d, "is_global", False))
        if isinstance(d, N.VarDecl):
            named = [(v.name, v.span, v) for v in d.names]
        elif isinstance(d, (N.SignalDecl, N.ImportDecl)):
            named = [(d.name, d.span, d)]
        else:
            continue
        for name, span, node in named:
            got = first.get(name.upper())
            if got is None:
                first[name.upper()] = (node, is_global)
            elif got[1] != is_global:
                declarer.duplicate(name, span, _Decl(got[0]))


class _Decl:
    def __init__(self, node):
        self.decl = node


def is_kuka_file(path: str) -> bool:
    """A file KUKA's software wrote: a system file (:func:`is_system_path`) or one of KUKA's
    hook programs under R1/Program (kss.yaml ``programs``: masref_user.src,
    CollDetect_UserAction.src; KUKA's system files call their routines)."""
    if is_system_path(path):
        return True
    p = Path(path)
    return (p.name.upper() in load_builtins().programs
            and "program" in [q.lower() for q in p.parts[:-1]])


def _unit_names(u: "ModuleUnit") -> set[str]:
    names = {u.name.upper()}
    if u.dat is not None and u.dat.module.data is not None:
        names.add(u.dat.module.data.name.upper())
    return names



def _add_entries(ws: "Workspace", entries, timeout: float | None = None, jobs: int | None = None) -> None:
    ws.add_files([e.path for e in entries if e.kind == "file"], timeout=timeout, jobs=jobs)
    _note_unread(ws, entries)


def load_workspaces(groups: list[tuple[str, list]], timeout: float | None = None,
                    jobs: int | None = None) -> list[Workspace]:
    """One workspace per (root, entries) group (entries: :func:`collect_entries`), the files of
    all groups loaded in one batch (:func:`load_batch`; with `timeout`, else here one by one)."""
    out = [Workspace(root) for root, _ in groups]
    files = [(k, e.path) for k, (_, entries) in enumerate(groups) for e in entries if e.kind == "file"]
    if timeout is None:
        for k, path in files:
            out[k].add_file(path)
    else:
        for (k, path), outcome in zip(files, load_batch([p for _, p in files], timeout, jobs)):
            out[k].add_outcome(path, outcome, timeout)
    for ws, (_, entries) in zip(out, groups):
        _note_unread(ws, entries)
    return out


def _note_unread(ws: "Workspace", entries) -> None:
    for e in entries:
        if e.kind != "file":
            ws.sink.add(str(e.path), 1, 1, "W002", f"not read: {e.message}")
            ws.unreadable = True   # it may declare what the other files use


def load_workspace(paths: list[str | Path], root: str = "", timeout: float | None = None,
                   jobs: int | None = None) -> Workspace:
    """One workspace from files and/or folders (all files of the folders). Never raises for
    bad content; a path that does not exist gives an E001 diagnostic; a link, FIFO, unreadable
    or too deep folder met in a folder gives a W002 warning and is not read. With `timeout`
    (seconds per file) files are parsed in worker processes (:meth:`Workspace.add_files`)."""
    ws = Workspace(root or (str(paths[0]) if paths else ""))
    entries = []
    for p in paths:
        p = Path(p)
        if not p.exists() and not p.is_symlink():
            ws.sink.add(str(p), 1, 1, "E001", "no such file or folder")
            continue
        entries += collect_entries(p)
    _add_entries(ws, entries, timeout, jobs)
    return ws


def check_texts(files: dict[str, str]) -> Workspace:
    """A checked workspace from {path: KRL text}; e.g. ``check_texts({"a.src": "DEF a()..."})``."""
    ws = Workspace(next(iter(files), ""))
    for path, text in files.items():
        ws.add_text(text, path)
    ws.check()
    return ws


def module_files(path: Path) -> list[Path]:
    """`path` and the other file of its module (krl/project.py rule 5): the .src/.sub and the
    .dat beside it with the same name (any case; links not followed)."""
    try:
        siblings = sorted(path.parent.iterdir()) if path.parent.is_dir() else []
    except OSError:
        siblings = []
    key = module_key(path)
    same = [sib for sib in siblings if module_key(sib) == key and is_krl_file(sib) and not sib.is_symlink()]
    if path not in same:
        same.append(path)
    return [Path(f) for f in project_module_files(path, same)]


def load_project(project: ProgramFiles, root: str = "", timeout: float | None = None, jobs: int | None = None,
                 extra: list[Path] = ()) -> Workspace:
    """The workspace of `project` (krl.project.project_of): its files in walk order, then
    `extra` files (a run's BASIS: krl.project.with_basis; a submit program outside the
    project); the entries not read are W002 warnings."""
    ws = Workspace(root or str(project.root))
    files = project.files
    more = [f for f in extra if f not in files]
    _add_entries(ws, project.entries + [Entry(f, f.name, "file") for f in more], timeout, jobs)
    return ws


def workspaces_for(path: str | Path, timeout: float | None = None, jobs: int | None = None,
                   groups: list | None = None) -> list[Workspace]:
    """The workspaces to check for a command-line PATH (krl/project.py): a file -> its program
    (the backup holding it, else every KRL file of its folder), checked and reported for the
    file's own module only (its .src/.dat); a folder holding backups -> one workspace per
    backup, plus one per top-level subfolder for the files outside the backups; another
    folder -> one workspace of all its files. A folder is walked once (:func:`folder_groups`;
    pass its result as `groups` when the caller has it already). `timeout`, `jobs`: see
    :func:`load_workspace`."""
    p = Path(path)
    if p.exists() and not p.is_dir():
        ws = load_project(project_of(p), str(p), timeout, jobs)
        ws.check_only = {str(f) for f in module_files(p)}
        return [ws]
    groups = folder_groups(p) if groups is None else groups
    if groups is not None and (len(groups) > 1 or groups[0][0] != str(p)):
        return load_workspaces(groups, timeout, jobs)
    if groups is not None:          # a folder without backups: one workspace of all its files
        ws = Workspace(str(p))
        _add_entries(ws, groups[0][1], timeout, jobs)
        return [ws]
    return [load_workspace([p], str(p), timeout, jobs)]
