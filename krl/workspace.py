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

The check records what each of its owners left (the declarations; each routine's scope and
body; each data-list value: findings and unresolved uses), so that :meth:`Workspace.replace`
puts a new version of one file in place (an editor's buffer) and runs the same phases again for
the routines or values whose AST changed, or the whole check when the file's interface changed;
the diagnostics are those of a full check either way.

Usage::

    ws = load_workspace([Path("KRC")])
    ws.check()                      # runs the checker, fills ws.diagnostics
    ws.modules["DEMO"].routines     # AST; expression types in node.ann.type
    ws.replace(load_text(new_text, path))   # an edit: "routines", "values" or "workspace"
"""

from __future__ import annotations

import functools
import gc
import re
import time
from collections.abc import Callable
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field, replace
from pathlib import Path

from krl import collector
from krl.ast import nodes as N
from krl.ast.build import build_module
from krl.ast.coverage import lines_not_understood
from krl.files import Entry
from krl.kssarchive import archive_root, read_info
from krl.project import (ProgramFiles, collect_entries, folder_groups, header_folder, is_submit_file, is_system_path, module_key,
                         modules_of, project_of)
from krl.project import module_files as project_module_files
from krl.semantics.builtins import load_builtins
from krl.semantics.checker import Checker, DeclaredTwice, Declarer, _is_system_datalist
from krl.diagnostics import SYNTAX_CODES, Diagnostic, DiagnosticSink
from krl.diagnostics.render import split_lines
from krl.diagnostics.codes import E001, E005, E901, W002, W108, W111, W201, W202, W205, W206, W210, W501
from krl.semantics.outside import Unresolved, line_evidence, package_installed, template_lines
from krl.semantics.resolve import resolve_workspace
from krl.semantics.symbols import Scope, Symbol, system_scopes
from krl.syntax.folds import fold_diagnostics
from krl.syntax.messages import syntax_diagnostics
from krl.syntax.engines import EngineUnavailable, java_answers, parse_source, resolve, result_from_answer
from krl.syntax.engines.tree import is_acyclic, stream_tokens
from krl.syntax.parse import ParseResult, default_bundle, parse_text
from krl.source import SourceText, is_krl_file, read_source
from krl.pool import default_jobs, run_tasks


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
    # (INI-fold lines, inline-form lines, USER-fold lines) of KUKA's templates and files
    # (krl/semantics/outside.py template_lines)
    template: tuple = ({}, {}, {})


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
        result = parse_source(src, keep_tree=True, engine="python")
    else:
        # without parent links: the builder and the messages never go up the tree, and a tree
        # without cycles is freed by reference counting when dropped, with no walk of
        # release_tree (400 files: 0.19 s of CPU, 2026-11-24)
        result = result_from_answer(src, raw, keep_tree=True, parents=False)
    try:
        return _loaded(src, result, t)
    finally:
        if not is_acyclic(result.tree):
            release_tree(result.tree)
        result.tree = None


def record_unparsed(module: N.Module, text: str, diagnostics) -> set[str]:
    """For a file with syntax errors: set ``module.unparsed`` and ``module.code_lines`` (the lines
    its AST lacks: the lines of its syntax diagnostics and the code lines on which no node starts,
    krl/ast/coverage.py), move a routine's ``broken`` line to the first syntax finding in it, and
    return the words of the lines not understood, upper-case: the names the file may
    declare or use where the checker cannot see them (``Workspace.maybe_declared``). One rule for
    ``krl check`` and the language server (krl/lsp/parsing.py)."""
    syntax = sorted({d.line for d in diagnostics if d.code in SYNTAX_CODES})
    module.unparsed, module.code_lines = lines_not_understood(module, text, syntax)
    for r in module.routines:
        if r.broken:        # the first syntax finding in it (E010 names the opener the parser closed late)
            r.broken = min((n for n in syntax if r.span.line <= n <= r.broken), default=r.broken)
    lines = split_lines(text)
    return {w.upper() for n in module.unparsed if 0 < n <= len(lines) for w in _WORD.findall(lines[n - 1])}


def release_tree(tree) -> None:
    """Break the cycles of a parse tree the AST was built from (each rule node's `children`
    cleared: a child points back through `parentCtx`), so that reference counting frees it at
    once. Without it a tree is cyclic garbage that only a full collection of the cyclic
    collector finds: a pass over the whole heap (the language server's first check of 400
    files: 1.9 M objects, 0.66 s of CPU against 0.31 s for this walk and the freeing,
    2026-11-24)."""
    stack = [tree] if tree is not None else []
    pop, push = stack.pop, stack.extend
    while stack:
        node = pop()
        children = getattr(node, "children", None)
        if children:
            node.children = None
            push(children)


def _loaded(src: SourceText, result: ParseResult, started: float) -> LoadedFile:
    elapsed = time.perf_counter() - started
    path_s = src.path
    sink = DiagnosticSink()
    if result.status not in ("ok", "syntax_error") and not result.errors:
        sink.add(path_s, 1, 1, *E001("not_checked", why=result.status + (f" ({src.detail})" if src.detail else "")))
    sink.extend(syntax_diagnostics(result, src.text, tokens=stream_tokens(result.tree) if result.errors else None))
    sink.extend(fold_diagnostics(path_s, src.text))
    t = time.perf_counter()
    unreadable = False
    if not result.ok and result.status in ("binary", "too_large", "unreadable", "not_regular"):
        unreadable = True
    module = build_module(result, sink)
    words = set()
    if not result.ok and not unreadable and src.text:
        words = record_unparsed(module, src.text, sink.items)
    return LoadedFile(path_s, module, result.ok, result.status, elapsed, time.perf_counter() - t,
                      sink.items, unreadable, words, template_lines(src.text or ""))


# What the workers of a fork server import before they fork (krl.pool.run_tasks `preload`).
WORKER_MODULES = ("krl.workspace", "krl.syntax.engines.tree", "krl.syntax.generated.KRLLexer",
                  "krl.syntax.generated.KRLParser")


def load_batch(paths: list, timeout: float, jobs: int | None = None, threaded: bool = False) -> list:
    """Read `paths` here, parse and build them in `jobs` worker processes (krl/pool.py), each
    file stopped past `timeout` seconds; returns one krl.pool.Outcome per path, in order (value:
    a LoadedFile). A batch of at least JAVA_BATCH_BYTES is parsed by the Java engine
    (:func:`_parse_tasks`): the same trees. Progress: the :func:`on_each_file` callback, as
    files finish. `threaded`: the caller runs other threads (the language server), so the
    workers come from a fork server (WORKER_MODULES loaded), not from a fork of this process."""

    default_bundle()    # imported once here, inherited by the forked workers
    hook = _ON_FILE.get()
    sources = [read_source(p) for p in paths]
    done: list = [None] * len(paths)
    # The ASTs arriving here are millions of new objects and next to no garbage: the cyclic
    # collector's passes over the growing heap cost more than the unpickling (main-process CPU
    # for the whole corpus 6.4 s with them, 2.7 s without); it runs once the batch is in.
    with collector.paused():
        # (the workers, forked from here, collect as usual: their parse trees are cyclic garbage)
        for o in run_tasks(load_parsed, _parse_tasks(sources, jobs, timeout), jobs=jobs, timeout=timeout,
                           initializer=gc.enable, preload=WORKER_MODULES if threaded else None):
            done[o.key] = o
            sources[o.key] = None
            if hook is not None:
                hook(str(paths[o.key]))      # progress as files finish, in any order
    return done


def load_here(sources: list[SourceText], stall: float) -> list[LoadedFile]:
    """Parse and build `sources` in this process, with no worker processes (krl/parsecache.py
    ``load_files`` without a timeout: ``krl audit``'s check of a unit in its worker, a run's
    small project; a Dask worker, which is daemonic, may not start them): a batch of at least
    JAVA_BATCH_BYTES is parsed by the Java engine's worker (a JVM this process starts once and
    keeps; a file it does not answer within `stall` seconds, and what it cannot parse, go to the
    Python engine), a smaller one by the Python engine, as :func:`load_batch` decides. The same LoadedFiles, in order; never raises for bad content.
    The cold store of ``krl audit``'s check, where each worker parsed its backups' files with
    the Python engine: 32 -> 16 s of CPU for the corpus, the JVMs included (2026-11-25)."""
    try:
        engine = resolve()
    except EngineUnavailable:
        engine = "python"
    if engine != "java" or sum(s.size for s in sources) < JAVA_BATCH_BYTES:
        return [load_parsed(s) for s in sources]
    out: list = [None] * len(sources)
    with collector.paused():       # as in load_batch: new ASTs, next to no garbage
        for i, src, raw in java_answers(enumerate(sources), trees=True, stall=stall):
            out[i] = load_parsed(src, raw)
    return out


def _parse_tasks(sources: list[SourceText], jobs: int | None, stall: float):
    """(index, (source, raw)) for :func:`load_parsed` in worker processes: one Java worker
    with `jobs` threads parses a batch of at least JAVA_BATCH_BYTES here, with trees, while
    the workers rebuild and build what it has answered (raw None: the Python engine)."""

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
    # path -> (INI-fold lines, inline-form lines, USER-fold lines) of KUKA's templates and files
    # (krl/semantics/outside.py template_lines)
    template: dict = field(default_factory=dict)
    # when set: only these paths' routine bodies and data-list values are checked (the other
    # files still declare their names); one file in the context of its backup
    check_only: set | None = None
    # the system variables the program uses, by Storage.slot, and the resolver that placed
    # every name (krl/semantics/resolve.py)
    system_names: list = field(default_factory=list)
    resolver: object = None
    # the implementations of the built-in routines, upper-case name -> fn(rt, args): given by
    # the runtime for a run (interp/runtime/natives LINKS); the resolver links each call to its
    # own (Callee.native). None for a check alone.
    natives: dict | None = None
    # the LoadedFile of each file added from one (path -> LoadedFile): what a full check is
    # made from again when :meth:`replace` cannot re-check a change on its own
    loaded: dict = field(default_factory=dict, repr=False)
    # what the last check left for :meth:`replace` (_CheckState), and the check's options
    _state: "_CheckState | None" = field(default=None, repr=False)
    _options: tuple = field(default=(True,), repr=False)      # (resolve,)
    _installed: tuple | None = field(default=None, repr=False)      # installed_packages, once read
    _unread: bool = field(default=False, repr=False)                # an entry not read (not a file's)
    _by_path: dict | None = field(default=None, repr=False)
    _inputs: list = field(default_factory=list, repr=False)         # the load's diagnostics, in order
    # the checked BASIS the program is checked on (krl/basislayer.py ``BasisLayer``: its units
    # first, only read), else None: the workspace's own files are all it checks
    layer: object = field(default=None, repr=False)

    @property
    def installed_packages(self) -> tuple[tuple[str, str], ...]:
        """The technology packages (name, version) that the controller archive holding this
        backup lists as installed (its am.ini ``[TechPacks]``, else ArchiveInfo.xml's
        ``OptionData``: krl/kssarchive.py); () outside an archive. Read once."""
        if self._installed is None:
            self._installed = ()
            if self.root and archive_root(self.root) is not None:
                try:
                    info = read_info(self.root)
                except (ValueError, OSError):
                    info = None
                self._installed = info.techpacks if info is not None else ()
        return self._installed

    def maybe_declared(self, name: str) -> bool:
        """True when a file that could not be parsed (or read) may declare `name`."""
        return self.unreadable or name.upper() in self.failed_words

    def evidence(self, path: str, line: int, kind: str, kuka: bool = False) -> str:
        """Why a use at path:line says installed software declares the name, or "" (a line of a
        KUKA file, `kuka`, outside its USER folds; the template's INI fold; a KUKA inline form, for
        routines and types): krl/semantics/outside.py ``line_evidence``."""
        return line_evidence(self.template.get(path), line, kind, kuka)

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
        return self.add_loaded(load_file(path))

    def add_files(self, paths, timeout: float | None = None, jobs: int | None = None) -> None:
        """:meth:`add_file` for each of `paths`, in order. With `timeout` (seconds per file) the
        files are read here and parsed and built in worker processes (:func:`load_batch`)."""
        paths = list(paths)
        loader = _LOADER.get()
        if loader is not None and paths:
            for lf in loader(paths, timeout, jobs):
                self.add_loaded(lf, notify=timeout is None)
            return
        if timeout is None or not paths:
            for p in paths:
                self.add_file(p)
            return
        for p, outcome in zip(paths, load_batch(paths, timeout, jobs)):
            self.add_outcome(p, outcome, timeout)

    def add_outcome(self, path, o, timeout: float) -> None:
        """Add one file of :func:`load_batch`: its LoadedFile, or E005 (stopped past `timeout`
        seconds) or E001 (its worker died) and an empty module (:func:`failed_load`)."""
        self.add_loaded(o.value if o.status == "done" else failed_load(path, o, timeout), notify=False)

    def add_loaded(self, lf: "LoadedFile", notify: bool = True) -> SourceFile:
        """Add one file read, parsed and built apart (:func:`load_file`, :func:`load_batch`, an
        editor's buffer): its AST and its input, syntax and build diagnostics."""
        self.parse_seconds += lf.parse_seconds
        self.check_seconds += lf.build_seconds
        self.sink.extend(lf.diagnostics)
        self.unreadable |= lf.unreadable
        if not lf.ok:
            self.failed_words |= lf.failed_words
        hook = _ON_FILE.get() if notify else None
        if hook is not None:
            hook(lf.path)
        self.template[lf.path] = lf.template
        self.loaded[lf.path] = lf
        sf = SourceFile(lf.path, lf.module, lf.ok, lf.status, parse_seconds=lf.parse_seconds)
        self.files.append(sf)
        return sf

    def add_unread(self, entries) -> None:
        """W002 for each walk entry that was not read (krl.files.Entry: a link, FIFO, folder too
        deep): it may declare what the other files use."""
        for e in entries:
            if e.kind != "file":
                self.sink.add(str(e.path), 1, 1, *W002(why=e.message))
                self.unreadable = self._unread = True

    def add_text(self, text: str, path: str = "<string>.src") -> SourceFile:
        """Parse and build KRL text as if it were the file `path` (tests, editors, REPLs)."""
        return self.add_loaded(load_text(text, path), notify=False)

    def unchecked_copy(self) -> "Workspace":
        """A new workspace of the same files as loaded (their LoadedFiles and ASTs, shared; the
        load's diagnostics; what the files that were not read or did not parse may declare),
        not checked: a second check of the same program whose :meth:`replace` calls leave this
        one as it is (krl/survey/mutants.py: each seeded error put in place and taken out
        again). The ASTs are shared: a check of the copy annotates them again, as a second
        check of this workspace would. Raises ValueError on a workspace checked on a BASIS
        layer (:attr:`layer`: not edited)."""
        if self.layer is not None:
            raise ValueError("a workspace checked on a shared BASIS layer is not copied")
        ws = Workspace(self.root)
        ws.sink.extend(self._inputs if self.checked else self.sink.items)
        ws.files = [SourceFile(f.path, lf.module, lf.ok, lf.status, parse_seconds=lf.parse_seconds)
                    for f in self.files for lf in (self.loaded[f.path],)]
        ws.loaded, ws.template = dict(self.loaded), dict(self.template)
        ws.failed_words, ws.unreadable, ws._unread = set(self.failed_words), self.unreadable, self._unread
        ws._installed, ws.natives = self._installed, self.natives
        return ws

    # ------------------------------------------------------------------ linking

    def _link_imports(self, checker: Checker, units: list[ModuleUnit]) -> None:
        """IMPORT type name IS /R1/module..var (2.5) in `units`: point the local name at the
        module's data-list variable (Symbol.alias, Symbol.module); report a missing target."""
        by_name: dict[str, ModuleUnit] = {}
        for u in self.units:
            for n in _unit_names(u):
                by_name.setdefault(n, u)
        for u in units:
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
        """The modules of the files (krl/project.py rule 5, :func:`krl.project.modules_of`); on a
        BASIS layer, the layer's units first and the modules of the other files after them."""
        files = self.files
        if self.layer is not None:
            self.units = list(self.layer.units)
            files = [f for f in files if not self.layer.holds(f)]
        for name, code, dat in modules_of(files, lambda f: f.module.kind == "dat"):
            self.units.append(ModuleUnit(name, src=code, dat=dat))

    def check(self, resolve: bool = True) -> list[Diagnostic]:
        """Link the files into scopes and run the checker; returns the sorted diagnostics.

        A file with syntax errors is checked from what parsed (issue 63): its declarations,
        routines and statements, each line not understood an ``Unparsed`` node (no finding of
        its own beyond the syntax error). `resolve` False: no storage places for the
        interpreters (krl/semantics/resolve.py; an editor needs only the checker's annotations;
        :meth:`resolve` places them later)."""
        if self.checked:
            if resolve and not self._options[0]:
                self.resolve()        # checked for the checker alone before; a run needs the places
                self._options = (True,)
            return self.diagnostics
        t = time.perf_counter()
        self.checked = True
        self._options = (resolve,)
        self._inputs = list(self.sink.items)
        try:
            self._check()
        except Exception as exc:  # noqa: BLE001 - never a traceback for bad input
            self._state = None
            self.sink.add(self.root, 1, 1, *E901(error=f"{type(exc).__name__}: {exc}"))
        self._by_path = None
        self.check_seconds += time.perf_counter() - t
        return self.diagnostics

    def resolve(self) -> None:
        """Place every name for the interpreters (krl/semantics/resolve.py) when the last check
        or re-check left it out."""
        if self.resolver is None and self.global_scope is not None:
            resolve_workspace(self)

    def diagnostics_of(self, path: str) -> list[Diagnostic]:
        """The diagnostics of one file, in the order of :attr:`diagnostics` (an index kept until
        the next check or re-check)."""
        if self._by_path is None:
            by: dict[str, list[Diagnostic]] = {}
            for d in self.sink.items:       # grouped as added; each file's sorted when asked
                by.setdefault(d.path, []).append(d)
            self._by_path = {p: (False, ds) for p, ds in by.items()}
        done, ds = self._by_path.get(path, (True, []))
        if not done:    # the stable sort of :attr:`diagnostics`, restricted to one path: the same order
            ds.sort(key=lambda d: (d.line, d.column, d.code))
            self._by_path[path] = (True, ds)
        return list(ds)

    def _check(self) -> None:
        """The phases of a check (reference 2.5-2.7), each finding and unresolved use recorded
        with its owner (the declarations, a routine's locals and body, a data-list value:
        :class:`_CheckState`) so that :meth:`replace` runs the same phases for one owner."""
        _system, basis = system_scopes()
        incomplete = self.incomplete
        st = self._state = _CheckState()
        declarer = st.declarer = Declarer(st.decl_sink, incomplete, self.maybe_declared)
        declarer.unresolved = st.decl_uses
        declarer.evidence = self.evidence
        checker = st.checker = Checker(st.decl_sink, declarer, incomplete)
        glob = Scope("global", "$GLOBAL", basis)
        self.global_scope = glob
        self._pair()
        layer = self.layer
        # on a BASIS layer (krl/basislayer.py) its global names are entered as its check left
        # them and only the other units are checked
        units = self.units if layer is None else self.units[len(layer.units):]
        if layer is not None:
            layer.enter(glob)
        sink = st.decl_sink

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

        for unit in units:
            unit.scope = Scope("module", unit.name, glob)
            for f in (unit.src, unit.dat):
                if f is not None:
                    f.scope = unit.scope
        plan = [(u, targets(u)) for u in units]
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

        for u in units:
            if u.dat is not None and u.dat.module.data is not None and not _is_system_datalist(u.dat.module.data.name):
                _global_and_local_twice(u.dat.module.data, declarer)
        self._link_imports(checker, units)

        # routines: main routines and GLOBAL ones are global, others module-local
        for u in units:
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
                    declarer.duplicate(r.name, r.span, old, "routine")
                else:
                    scope.routines[r.name.upper()] = sym  # a routine replaces its EXT signature
                if is_global and scope is glob:
                    u.scope.routines.setdefault(r.name.upper(), sym)
                st.add_routine(_RoutineCheck(r, u, sym, r.span, r.end_line))
            declarer.soft_types = False
            if u.src.module.routines:
                main = u.src.module.routines[0]
                if main.name.upper() != u.name.upper() and not is_submit_file(u.src.path):
                    sink.at(main.span, *W111(name=main.name, file=u.name))
        st.declarations_done(self)

        # routine scopes (parameters and locals), then data-list values, then bodies
        for rec in st.routines:
            self._declare_locals(rec)
        for u in units:
            if u.dat is not None and u.dat.module.data is not None:
                st.set_values(u, self._check_values(u, u.dat.module.data.items, {}))
        for rec in st.routines:
            if self._body_wanted(rec):
                self._check_body(rec)
        # advisory warnings are for code its maintainer can change: not for KUKA's own files
        st.kuka = {f.path for f in self.files if is_kuka_file(f.path)} | {
            u.dat.path for u in units
            if u.dat is not None and u.dat.module.data is not None and _is_system_datalist(u.dat.module.data.name)}
        if layer is not None:
            st.kuka |= layer.kuka
        self._report()
        self._assemble()
        # every use gets its storage and every statement its advance-run facts, once, for the
        # interpreters (krl/semantics/resolve.py)
        if self._options[0]:
            resolve_workspace(self)

    # ------------------------------------------------------------------ the phases of one owner

    def _declare_locals(self, rec: "_RoutineCheck") -> None:
        """A routine's scope: its parameters and local declarations, its signature completed."""
        st = self._state
        declarer, r, u = st.declarer, rec.routine, rec.unit
        rec.scope_diags, rec.scope_uses = declarer.sink, declarer.unresolved = DiagnosticSink(), _Uses()
        declarer.soft_types = is_kuka_file(u.src.path)
        try:
            local = Scope("routine", r.name, u.scope)
            declarer.declare_types(local, r.decls, path=u.src.path, module=u.name)
            declarer.fill_types(local, r.decls)
            declarer.declare_values(local, r.decls, u.name, u.src.path)
            declarer.complete_signature(rec.symbol, local)
            self.routine_scopes[id(r)] = local
        finally:
            declarer.soft_types = False

    def _body_wanted(self, rec: "_RoutineCheck") -> bool:
        """True when the routine's body is checked: always, but for a file outside
        :attr:`check_only` (a file with syntax errors is checked from what parsed)."""
        return self.check_only is None or rec.unit.src.path in self.check_only

    def _check_body(self, rec: "_RoutineCheck") -> None:
        st = self._state
        declarer, checker, path = st.declarer, st.checker, rec.unit.src.path
        sink, uses = DiagnosticSink(), _Uses()
        checker.sink = declarer.sink = sink
        declarer.unresolved = uses
        checker.system_file = declarer.soft_types = is_kuka_file(path)
        checker.submit = is_submit_file(path)
        try:
            checker.check_routine(rec.routine, self.routine_scopes[id(rec.routine)], path)
        finally:
            checker.system_file = declarer.soft_types = checker.submit = False
        rec.body_diags, rec.body_uses = sink, uses

    def _check_values(self, u: ModuleUnit, items: list, kept: dict) -> list:
        """The initial values of a data list's `items` against the declared types, one record
        per item (`kept`: id(item) -> a record still valid, not checked again)."""
        f = u.dat
        if not (self.check_only is None or f.path in self.check_only):
            return []
        st = self._state
        declarer, checker = st.declarer, st.checker
        dl = f.module.data
        out = []
        checker.system_file = declarer.soft_types = is_kuka_file(f.path)
        try:
            for item in items:
                if not (isinstance(item, N.ArrayInit) or isinstance(item, N.VarDecl) and item.init is not None):
                    continue
                rec = kept.get(id(item))
                if rec is None:
                    rec = _ValueCheck(item, item.span, DiagnosticSink(), _Uses())
                    checker.sink = declarer.sink = rec.diags
                    declarer.unresolved = rec.uses
                    checker.check_datalist(N.DataList(dl.name, [item], dl.public, span=dl.span), u.scope)
                out.append(rec)
        finally:
            checker.system_file = declarer.soft_types = False
        return out

    def _reported(self, f: SourceFile) -> bool:
        return self.check_only is None or f.path in self.check_only

    def _owners(self) -> list[tuple[DiagnosticSink, "_Uses"]]:
        """(findings, unresolved uses) of every owner that is reported, in the order of a check:
        the declarations, routine scopes, data-list values (of files that parse), routine bodies
        (of files that parse); on a BASIS layer each part's own owners, then the layer's
        (:meth:`owner_parts`: its units follow the program's in a check of them all)."""
        parts = self.owner_parts()
        if self.layer is not None:
            parts = [mine + theirs for mine, theirs in zip(parts, self.layer.parts)]
        return [o for part in parts for o in part]

    def owner_parts(self) -> list[list[tuple[DiagnosticSink, "_Uses"]]]:
        """The owners of this workspace's own check (:meth:`_owners`), in four parts: the
        declarations, the routine scopes, the data-list values, the routine bodies."""
        st = self._state
        values = []
        for u in self.units:
            if u.dat is not None and self._reported(u.dat):
                values += st.value_owners.get(id(u), ())
        return [[(st.decl_sink, st.decl_uses)], [(rec.scope_diags, rec.scope_uses) for rec in st.routines], values,
                [(rec.body_diags, rec.body_uses) for rec in st.routines
                 if rec.body_diags is not None and self._reported(rec.unit.src)]]

    def unresolved(self) -> Unresolved | None:
        """The names of the last check that the workspace does not declare
        (krl/semantics/outside.py ``Unresolved``: every recorded use, in the order a check
        records them, with the evidence that KUKA's software declares them); None before a
        check. The run's stand-ins for KUKA's system software read it (interp/runtime/kss.py)."""
        if self._state is None:
            return None
        tables, installed = load_builtins(), self.installed_packages
        packages, unlisted = tables.packages, {}
        if installed:       # a routine of a package the archive lists is installed software's
            listed = {k: v for k, v in tables.package_routines.items() if package_installed(v[0], installed)}
            unlisted = {k: v for k, v in tables.package_routines.items() if k not in listed}
            packages = {**listed, **packages}
        un = Unresolved(packages, self.maybe_declared, installed=installed, unlisted=unlisted)
        for _diags, uses in self._owners():
            for use in uses.items:
                un.use(*use)
        return un

    def declared_twice(self) -> list[DeclaredTwice]:
        """The declarations of the last check (or re-check) that repeat a name their scope
        already holds (krl/semantics/checker.py DeclaredTwice: the facts behind E102), in the
        order of a check; [] before a check. The language server's rename and the backup diff
        read these, never the diagnostics' words."""
        if self._state is None:
            return []
        return [f for _diags, uses in self._owners() for f in uses.twice]

    def _all_uses(self) -> list[list[tuple]]:
        """Every reported owner's unresolved uses, in the report's order (what :meth:`_report`
        reads; the report of 400 files took two thirds of an edit's re-check)."""
        return [list(uses.items) for _diags, uses in self._owners()]

    def _report(self) -> None:
        """The unresolved-name report (krl/semantics/outside.py) from every recorded use."""
        un = self.unresolved()
        self._state.report = DiagnosticSink()
        un.finish(self._state.report)

    def _assemble(self) -> None:
        """The workspace's diagnostics in the order a check adds them (the input's, each
        owner's, the report), a repeat dropped as one sink drops it, advisory warnings left out
        in KUKA's files."""
        st = self._state
        sink = DiagnosticSink()
        add = sink.add_diagnostic
        for d in self._inputs:
            add(d)
        for part in [diags for diags, _uses in self._owners()] + [st.report]:
            for d in part.items:
                add(d)
        kuka = st.kuka
        sink.items = [d for d in sink.items if not (d.code in ADVISORY and d.path in kuka)]
        self.sink = sink
        self._by_path = None

    # ------------------------------------------------------------------ re-check after a change

    def replace(self, lf: "LoadedFile") -> str:
        """Put `lf`, a new version of the file ``lf.path`` of this workspace, in the old one's
        place and, when the workspace was checked, check again what the change can affect; the
        diagnostics are then those of a full check of the same files (tests/lsp/test_edits.py
        replays real edits). Returns what was checked again:

        * "routines": a .src/.sub whose interface (routine kinds, names, GLOBAL marks,
          parameters and their declared types, return types) is the same: only its routines
          whose AST changed, against the kept module and global scopes; the other routines
          keep their findings (moved with their lines);
        * "values": a .dat whose declarations are the same but for initial values: only the
          values that changed are checked;
        * "workspace": any other change (an interface, a file that cannot be read, a file whose
          declarations other findings quote by line): every module that may depend on it, the
          whole workspace, from the parses it holds;
        * "none": not checked yet.

        The unresolved-name report (per backup) is made again when what it reads changed: the
        reported owners' unresolved uses, or what the files that do not parse may declare
        (``failed_words``, ``unreadable``: :meth:`maybe_declared`). Storage places
        (:meth:`resolve`) are left for later. Raises KeyError when no file is ``lf.path``, ValueError
        on a workspace checked on a shared BASIS layer (:attr:`layer`: its files are only read)."""
        if self.layer is not None:
            raise ValueError("a workspace checked on a shared BASIS layer is not edited")
        path = lf.path
        sf = next((f for f in self.files if f.path == path), None)
        old = self.loaded.get(path)
        if sf is None or old is None:
            raise KeyError(path)
        old_template = old.template
        may_declare = (frozenset(self.failed_words), self.unreadable)      # what maybe_declared reads
        self._set_loaded(lf)
        st = self._state
        if not self.checked or st is None:
            sf.module, sf.ok, sf.status = lf.module, lf.ok, lf.status
            return "none" if not self.checked else self._check_again()
        self._by_path = None
        self.resolver = None
        st.declarer.incomplete = st.checker.incomplete = self.incomplete
        try:
            uses = self._all_uses()
            if old.unreadable or lf.unreadable or self.check_only is not None:
                done = None
            elif sf.module.kind == "dat" or lf.module.kind == "dat":
                done = self._recheck_data(sf, lf, old_template)
            else:
                done = self._recheck_code(sf, lf, old_template)
            if done is None:
                return self._check_again()
            if self._all_uses() != uses or (frozenset(self.failed_words), self.unreadable) != may_declare:
                self._report()              # else the report, made from these alone, stays
            self._assemble()
            return done
        except Exception:  # noqa: BLE001 - the full check decides (and reports E901 itself)
            return self._check_again()

    def _set_loaded(self, lf: "LoadedFile") -> None:
        old = self.loaded[lf.path]
        self.loaded[lf.path] = lf
        self.template[lf.path] = lf.template
        gone = {id(d) for d in old.diagnostics}
        if self.checked:
            self._inputs = [d for d in self._inputs if id(d) not in gone] + list(lf.diagnostics)
        else:
            self.sink.remove(gone)
            self.sink.extend(lf.diagnostics)
        self.failed_words = set()
        for x in self.loaded.values():
            if not x.ok:
                self.failed_words |= x.failed_words
        self.unreadable = self._unread or any(x.unreadable for x in self.loaded.values())

    def _check_again(self) -> str:
        """The whole workspace checked again from the parses it holds."""
        self.sink = DiagnosticSink()
        self.sink.extend(self._inputs)
        self.global_scope, self.units, self.routine_scopes = None, [], {}
        self.system_names, self.resolver, self._state, self.checked = [], None, None, False
        for f in self.files:
            lf = self.loaded.get(f.path)
            if lf is not None:
                f.module, f.ok, f.status, f.scope = lf.module, lf.ok, lf.status, None
        self.check(*self._options)
        return "workspace"

    def _recheck_code(self, sf: SourceFile, lf: "LoadedFile", old_template) -> str | None:
        st = self._state
        old_mod, new_mod = sf.module, lf.module
        if old_mod.kind != "src" or new_mod.kind != "src" or old_mod.data is not None or new_mod.data is not None:
            return None
        if not _same_interface(old_mod, new_mod):
            return None
        recs = [st.by_routine.get(id(r)) for r in old_mod.routines]
        if any(rec is None for rec in recs):
            return None
        new_template = lf.template
        if sf.path in st.decl_paths and (old_template != new_template or any(
                rec.span != r.span for rec, r in zip(recs, new_mod.routines))):
            return None         # a finding of the declarations quotes this file's lines
        sf.module, sf.ok, sf.status = new_mod, lf.ok, lf.status
        redo = []
        for rec, r in zip(recs, new_mod.routines):
            if r is not rec.routine:
                st.rebind_routine(rec, r, self.routine_scopes)
                redo.append(rec)
            elif (r.span != rec.span or old_template != new_template) and not rec.move(r, old_template, new_template):
                redo.append(rec)
        for rec in redo:
            self._declare_locals(rec)
            rec.body_diags = rec.body_uses = None
        for rec in recs:
            if rec.body_diags is None and self._body_wanted(rec):
                self._check_body(rec)
        return "routines"

    def _recheck_data(self, sf: SourceFile, lf: "LoadedFile", old_template) -> str | None:
        st = self._state
        old_mod, new_mod = sf.module, lf.module
        if old_mod.kind != "dat" or new_mod.kind != "dat" or old_mod.data is None or new_mod.data is None \
                or old_mod.routines or new_mod.routines:
            return None
        odl, ndl = old_mod.data, new_mod.data
        if (odl.name, odl.public) != (ndl.name, ndl.public):
            return None
        old_decls = [d for d in odl.items if not isinstance(d, N.ArrayInit)]
        new_decls = [d for d in ndl.items if not isinstance(d, N.ArrayInit)]
        if len(old_decls) != len(new_decls) or any(
                a is not b and _declaration(a) != _declaration(b) for a, b in zip(old_decls, new_decls)):
            return None
        if sf.path in st.decl_paths and (old_template != lf.template
                                         or st.anchors.get(sf.path) != _anchors(new_decls)):
            return None         # a finding of the declarations quotes this file's lines
        unit = next((u for u in self.units if u.dat is sf), None)
        if unit is None:
            return None
        for a, b in zip(old_decls, new_decls):
            if a is not b:
                st.rebind_item(a, b)
        sf.module, sf.ok, sf.status = new_mod, lf.ok, lf.status
        kept = {}
        for rec in st.values.get(id(unit), ()):
            if rec.move(old_template, lf.template):
                kept[id(rec.item)] = rec
        st.set_values(unit, self._check_values(unit, ndl.items, kept))
        return "values"


# ---------------------------------------------------------------------- what a check leaves

class _Uses:
    """The name facts of one owner besides its findings: its unresolved-name uses
    (:class:`krl.semantics.outside.Unresolved.use`'s arguments, replayed into the report in the
    order of a check) and its declarations made twice (``twice``: DeclaredTwice)."""

    __slots__ = ("items", "twice")

    def __init__(self) -> None:
        self.items: list[tuple] = []
        self.twice: list[DeclaredTwice] = []

    def use(self, kind: str, name: str, path: str, line: int, column: int, evidence: str = "",
            declared: str = "") -> None:
        self.items.append((kind, name, path, line, column, evidence, declared))

    def declared_twice(self, fact: DeclaredTwice) -> None:
        self.twice.append(fact)


def _moved_diagnostics(sink: DiagnosticSink, delta: int) -> DiagnosticSink:
    out = DiagnosticSink()
    for d in sink.items:
        out.add_diagnostic(replace(d, line=d.line + delta, end_line=d.end_line + delta if d.end_line else 0,
                                   notes=[replace(n, line=n.line + delta) for n in d.notes]))
    return out


def _same_template(old, new, lines: range, delta: int) -> bool:
    """True when lines `lines` of the old text lie in the same template folds (INI, inline
    form: the evidence of an unresolved use) as those lines moved by `delta` in the new."""
    return all(all(a.get(n) == b.get(n + delta) for a, b in zip(old, new)) for n in lines)


@dataclass(slots=True, eq=False)
class _RoutineCheck:
    """What the check of one routine left: the routine, its module, its symbol, where it
    stood (span, END line), the findings and unresolved uses of its scope (parameters and
    locals) and of its body (None: the body was not checked)."""
    routine: N.Routine
    unit: ModuleUnit
    symbol: Symbol
    span: N.Span
    end_line: int
    scope_diags: DiagnosticSink | None = None
    scope_uses: _Uses | None = None
    body_diags: DiagnosticSink | None = None
    body_uses: _Uses | None = None

    def move(self, r: N.Routine, old_template, new_template) -> bool:
        """The routine kept its AST but stands elsewhere (lines inserted above it) or the
        template folds around it changed: move its findings with it. False when that is not
        exact: a finding quotes a line of the file, or a use now lies in another fold."""
        delta = r.span.line - self.span.line
        path = self.span.file
        parts = [p for p in (self.scope_diags, self.body_diags) if p is not None]
        if any(path in d.message for p in parts for d in p.items):
            return False
        if any(p is not None and p.twice for p in (self.scope_uses, self.body_uses)):
            return False       # a declaration made twice: its facts hold places (checked again)
        uses = [p for p in (self.scope_uses, self.body_uses) if p is not None and p.items]
        if uses and (self.end_line < self.span.line or not _same_template(
                old_template, new_template, range(self.span.line, self.end_line + 1), delta)):
            return False
        if delta:
            self.scope_diags = _moved_diagnostics(self.scope_diags, delta)
            if self.body_diags is not None:
                self.body_diags = _moved_diagnostics(self.body_diags, delta)
            for p in uses:
                p.items = [(k, n, f, line + delta, c, e, x) for k, n, f, line, c, e, x in p.items]
        self.span, self.end_line = r.span, r.end_line
        return True


@dataclass(slots=True, eq=False)
class _ValueCheck:
    """What the check of one data-list value (an initialised declaration or an array
    element's value) left: the item, where it stood, its findings and unresolved uses."""
    item: N.Decl
    span: N.Span
    diags: DiagnosticSink
    uses: _Uses

    def move(self, old_template, new_template) -> bool:
        """Like :meth:`_RoutineCheck.move` for an item that kept its AST (one line)."""
        delta = self.item.span.line - self.span.line
        if any(self.span.file in d.message for d in self.diags.items):
            return False
        if self.uses.items and not _same_template(old_template, new_template, range(self.span.line, self.span.line + 1),
                                                  delta):
            return False
        if delta:
            self.diags = _moved_diagnostics(self.diags, delta)
            self.uses.items = [(k, n, f, line + delta, c, e, x) for k, n, f, line, c, e, x in self.uses.items]
        self.span = self.item.span
        return True




class _CheckState:
    """The declarer and checker of the last check, and what each of its owners left: the
    declaration phases (types, values, imports, routine symbols: one owner, made again only
    by a full check), each routine (:class:`_RoutineCheck`, in check order) and each
    data-list value (:class:`_ValueCheck`, per module), the unresolved-name report."""

    def __init__(self) -> None:
        self.declarer: Declarer | None = None
        self.checker: Checker | None = None
        self.decl_sink = DiagnosticSink()
        self.decl_uses = _Uses()
        self.decl_paths: set[str] = set()       # files whose lines the declarations' findings quote
        self.anchors: dict[str, list] = {}      # such a .dat file: the spans of its declarations
        self.routines: list[_RoutineCheck] = []
        self.by_routine: dict[int, _RoutineCheck] = {}
        self.values: dict[int, list[_ValueCheck]] = {}     # id(unit) -> its values' records
        self.value_owners: dict[int, list[tuple]] = {}      # id(unit) -> (findings, uses) of the records with any
        self.symbols_of: dict[int, tuple] = {}  # id(declaration) -> (declaration, its symbols)
        self.report = DiagnosticSink()
        self.kuka: set[str] = set()

    def set_values(self, unit: ModuleUnit, recs: list[_ValueCheck]) -> None:
        """The records of `unit`'s data-list values; those without findings or unresolved
        uses are left out of what each edit's report and assembly walk (a data list can hold
        thousands of values)."""
        self.values[id(unit)] = recs
        self.value_owners[id(unit)] = [(r.diags, r.uses) for r in recs if r.diags.items or r.uses.items]

    def add_routine(self, rec: _RoutineCheck) -> None:
        self.routines.append(rec)
        self.by_routine[id(rec.routine)] = rec

    def declarations_done(self, ws: "Workspace") -> None:
        """Note which files the declarations' findings and uses name (their lines must stay
        put for a re-check of that file alone) and which symbols each declaration entered."""
        paths = self.decl_paths
        for d in self.decl_sink.items:
            paths.add(d.path)
        paths.update(f.first.file for f in self.decl_uses.twice if f.first is not None)
        paths.update(u[2] for u in self.decl_uses.items)
        for u in ws.units:
            if u.dat is not None and u.dat.path in paths and u.dat.module.data is not None:
                self.anchors[u.dat.path] = _anchors([d for d in u.dat.module.data.items if not isinstance(d, N.ArrayInit)])
        scopes = [ws.global_scope, *(u.scope for u in ws.units)]
        for sc in scopes:
            for table in (sc.values, sc.routines, sc.type_symbols):
                for sym in table.values():
                    if sym.decl is not None:
                        got = self.symbols_of.get(id(sym.decl))
                        if got is None:
                            got = self.symbols_of[id(sym.decl)] = (sym.decl, [])
                        if sym not in got[1]:
                            got[1].append(sym)

    def rebind_routine(self, rec: _RoutineCheck, r: N.Routine, routine_scopes: dict) -> None:
        """A routine's new AST takes the old one's place (same interface): the symbol points
        at it; its scope and findings are made again by the caller."""
        old = rec.routine
        del self.by_routine[id(old)]
        routine_scopes.pop(id(old), None)
        if rec.symbol.decl is old:
            rec.symbol.decl = r
        rec.routine, rec.span, rec.end_line = r, r.span, r.end_line
        self.by_routine[id(r)] = rec

    def rebind_item(self, a: N.Decl, b: N.Decl) -> None:
        """A data-list declaration's new AST `b` takes the old one's place (same declaration
        but for its value): the symbols it entered point at it, its names keep their
        annotations."""
        _node, syms = self.symbols_of.pop(id(a), (None, []))
        for sym in syms:
            if sym.decl is a:
                sym.decl = b
        if syms:
            self.symbols_of[id(b)] = (b, syms)
        if isinstance(a, N.VarDecl):
            for va, vb in zip(a.names, b.names):
                vb.ann = va.ann


def _type_key(t: N.TypeRef | None):
    return None if t is None else (t.name.upper(), t.size)


def routine_interface(r: N.Routine) -> tuple:
    """What other modules and the module's other routines can see of a routine: its kind,
    name, GLOBAL mark, return type and parameters (name, mode, open dimensions, declared type
    and dimensions)."""
    decl_of: dict[str, tuple] = {}
    names = {p.name.upper() for p in r.params}
    for d in r.decls:
        if isinstance(d, N.VarDecl):
            for v in d.names:
                if v.name.upper() in names:
                    decl_of.setdefault(v.name.upper(), (_type_key(d.type), tuple(v.dims), d.is_const))
    params = tuple((p.name.upper(), p.mode, p.dims, decl_of.get(p.name.upper())) for p in r.params)
    return r.kind, r.name.upper(), r.is_global, _type_key(r.return_type), params


def _same_interface(old: N.Module, new: N.Module) -> bool:
    """True when two versions of a .src file show the same routines to the rest (an
    unchanged routine, the same AST, is not looked at)."""
    return len(old.routines) == len(new.routines) and all(
        a is b or routine_interface(a) == routine_interface(b) for a, b in zip(old.routines, new.routines))


def _declaration(d: N.Decl):
    """A data-list declaration as the declaration phases see it: all but its initial value
    (AST equality leaves spans out)."""
    if isinstance(d, N.VarDecl):
        return ("var", d.type, tuple(d.names), d.is_global, d.is_const, d.decl_keyword)
    return d


def _anchors(decls: list) -> list:
    """The spans of a data list's declarations and of their parts (not their values)."""
    out = []
    for d in decls:
        stack = [d]
        while stack:
            n = stack.pop()
            out.append(n.span)
            stack.extend(c for c in n.children() if not (isinstance(n, N.VarDecl) and c is n.init))
    return out


def failed_load(path, o, timeout: float) -> LoadedFile:
    """The LoadedFile of a file whose load in :func:`load_batch` did not end (krl.pool.Outcome
    `o`): E005 (stopped past `timeout` seconds) or E001 (its worker died), an empty module; it
    may declare anything (unreadable)."""
    sink = DiagnosticSink()
    if o.status == "timeout":
        sink.add(str(path), 1, 1, *E005("not_checked", timeout=timeout))
    else:
        sink.add(str(path), 1, 1, *E001("not_checked", why=o.detail))
    module = build_module(ParseResult(str(path), False, "", o.status), DiagnosticSink())
    return LoadedFile(str(path), module, False, o.status, 0.0, 0.0, sink.items, unreadable=True)


def load_text(text: str, path: str = "<string>.src") -> LoadedFile:
    """Parse (the Python engine) and build KRL text as if it were the file `path`."""
    t = time.perf_counter()
    src = SourceText(path, text, "", len(text.encode("utf-8", "surrogatepass")))
    return _loaded(src, parse_text(text, path), t)


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


#: how the files of a workspace are loaded instead of parsing them all (:func:`loading_files_by`)
_LOADER: ContextVar[Callable[[list, float | None, int | None], list] | None] = ContextVar(
    "krl_workspace_loader", default=None)


@contextmanager
def loading_files_by(loader: Callable[[list, float | None, int | None], list]):
    """``with loading_files_by(f):`` the workspaces made in the block get their files from
    ``f(paths, timeout, jobs)`` (one LoadedFile per path, in order, as :meth:`Workspace.add_files`
    would make them): krl/parsecache.py takes them from the one store. Ends with the block."""
    token = _LOADER.set(loader)
    try:
        yield
    finally:
        _LOADER.reset(token)


# warnings that advise a change of the code (docs/diagnostics.md): not reported in KUKA's files
ADVISORY = frozenset({W108, W111, W201, W202, W205, W206, W210, W501})
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


@functools.lru_cache(maxsize=8192)
def is_kuka_file(path: str) -> bool:
    """A file KUKA's software wrote: a system file (:func:`is_system_path`), a file whose own
    header lines say it is KUKA's wherever it lies (krl.project.header_folder: a flat backup's
    bas.src), or one of KUKA's
    hook programs under R1/Program (kss.yaml ``programs``: masref_user.src,
    CollDetect_UserAction.src; KUKA's system files call their routines). Remembered per path
    (a check asks 6-7 times per file: 2,656 Path objects parsed for 400 files, 0.3 of 4.7 s
    profiled, 2026-11-24)."""
    if is_system_path(path) or header_folder(path) is not None:     # its folder, else its own header
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
    ws.add_unread(entries)


def load_workspaces(groups: list[tuple[str, list]], timeout: float | None = None,
                    jobs: int | None = None) -> list[Workspace]:
    """One workspace per (root, entries) group (entries: :func:`collect_entries`), the files of
    all groups loaded in one batch (:func:`load_batch`; with `timeout`, else here one by one)."""
    out = [Workspace(root) for root, _ in groups]
    files = [(k, e.path) for k, (_, entries) in enumerate(groups) for e in entries if e.kind == "file"]
    loader = _LOADER.get()
    if loader is not None and files:
        for (k, _path), lf in zip(files, loader([p for _, p in files], timeout, jobs)):
            out[k].add_loaded(lf, notify=timeout is None)
    elif timeout is None:
        for k, path in files:
            out[k].add_file(path)
    else:
        for (k, path), outcome in zip(files, load_batch([p for _, p in files], timeout, jobs)):
            out[k].add_outcome(path, outcome, timeout)
    for ws, (_, entries) in zip(out, groups):
        ws.add_unread(entries)
    return out


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
            ws.sink.add(str(p), 1, 1, *E001("missing"))
            continue
        entries += collect_entries(p)
    _add_entries(ws, entries, timeout, jobs)
    return ws


@dataclass(frozen=True)
class NotUnderstood:
    """The lines of one file that its AST does not hold (issue 63): ``lines`` as (line, the
    parser's message: the file's syntax diagnostic at that line, or for a follow-on line
    without one, the error it follows), the code lines understood and
    counted (krl/ast/coverage.py), and what they are (``noun``: declarations of a data list,
    statements of a module). Every tool names these once, at the top of what it prints."""
    path: str
    lines: tuple
    understood: int
    total: int
    noun: str

    def headline(self, verb: str, shown=str) -> str:
        """``$config.dat:915 not understood: 1,040 of 1,041 declarations compared`` (`verb`: what
        the tool did with the rest; `shown`: the file as the user names it)."""
        nums = [str(n) for n, _m in self.lines]
        where = ", ".join(nums[:8]) + (f" and {len(nums) - 8} more lines" if len(nums) > 8 else "")
        return (f"{shown(self.path)}:{where} not understood: {self.understood:,} of {self.total:,} "
                f"{self.noun} {verb}")

    def details(self, shown=str, limit: int = 8) -> list[str]:
        """One line ``FILE:LINE: message`` per line not understood (at most `limit`, then a count)."""
        out = [f"{shown(self.path)}:{n}: {m}" for n, m in self.lines[:limit]]
        if len(self.lines) > limit:
            out.append(f"... and {len(self.lines) - limit} more lines not understood in {shown(self.path)}")
        return out


def not_understood(ws: Workspace) -> list[NotUnderstood]:
    """The files of `ws` with lines not understood (a syntax error, or lines its error recovery
    passed over), in the workspace's file order (with :attr:`Workspace.check_only`, of those
    files only); [] when every file parsed. Files not read or
    not parsed at all (E001, E005, past a limit) are not among them: their diagnostics say so."""
    out = []
    for f in ws.files:
        m = f.module
        if f.ok or not m.unparsed or (ws.check_only is not None and f.path not in ws.check_only):
            continue
        msgs: dict[int, str] = {}
        lf = ws.loaded.get(f.path)
        for d in (lf.diagnostics if lf is not None else ()):
            if d.code in SYNTAX_CODES and d.line not in msgs:
                msgs[d.line] = d.message
        lines, last = [], None
        for n in m.unparsed:
            if n in msgs:
                last = n
                lines.append((n, msgs[n]))
            else:
                lines.append((n, f"follows the error at line {last}" if last is not None
                              else "not read by the parser"))
        noun = "declarations" if m.kind == "dat" and not m.routines else "statements"
        out.append(NotUnderstood(f.path, tuple(lines), max(0, m.code_lines - len(m.unparsed)), m.code_lines, noun))
    return out


_KSS = re.compile(r"KUKA\s*(\d+)(?:\.(\d+))?", re.IGNORECASE)
#: the controller a KSS major version runs on (KUKA's KSS release notes: KSS 8 on the KR C4,
#: KSS 5 and 4 on the KR C2)
_CONTROLLERS = {"8": "KR C4", "5": "KR C2", "4": "KR C2"}


#: a name of a KUKA robot model (``KR 10 R1440-2``, ``KR6 R900 sixx``, ``LBR iiwa 14 R820``), as
#: opposed to the user's own name of a machine (``MACHINE_DEF[1]={NAME[] "Robot",...}``)
_KUKA_MODEL = re.compile(r"^(KR\s*\d|LBR\s)", re.IGNORECASE)


def config_robot(files) -> tuple[str, str, int] | None:
    """``(name, path, line)`` of the robot that the ``$config.dat`` among `files`
    (:class:`SourceFile`, a backup's) names in ``MACHINE_DEF[1].NAME[]`` (KUKA's ``MACHINE_DEF_T``
    of a KR C4: the cell's first machine, its robot) when the name reads as a KUKA model
    (:data:`_KUKA_MODEL`: ``KR 10 R1440-2``; not the user's ``"Robot"``), else None. The
    robot's identity where no ``$machine.dat`` names it (issue 72)."""
    for f in files:
        dl = f.module.data if f.module is not None else None
        if dl is None or dl.name.upper() != "$CONFIG":
            continue
        for item in dl.items:
            if not (isinstance(item, N.ArrayInit) and item.name.upper() == "MACHINE_DEF" and item.indices == [1]
                    and isinstance(item.value, N.Aggregate)):
                continue
            for comp in item.value.items:
                if comp.name.upper() == "NAME" and isinstance(comp.value, N.StrLit):
                    name = comp.value.value.strip()
                    if _KUKA_MODEL.match(name):
                        return name, str(f.path), item.span.line
    return None


def machine_identity(files) -> dict[str, str]:
    """What the machine data among `files` (:class:`SourceFile`, a backup's) say of the robot
    and its controller, from what parsed of each ``$machine.dat``: ``robot`` (``$MODEL_NAME[]``,
    KSS 8.5 and later, else ``$TRAFONAME[]``, without KUKA's ``#``: ``KR30L16_3A C4 FLR ZH16_2``;
    where no ``$machine.dat`` names it, the model ``$config.dat`` names in ``MACHINE_DEF[1]``:
    :func:`config_robot`), ``robot_from`` (``$machine.dat``, ``$config.dat MACHINE_DEF[1]`` or
    ""), ``mada`` (``$V_R1MADA[]``: ``V8.3.190/KUKA8.3``), ``kss`` (``KSS 8.3``) and ``controller``
    (``KR C4``); "" for what they do not name (a backup without machine data names nothing else).
    The one rule of krl report's cover (krl/diff/ident.py) and krl audit's unit names."""
    files = list(files)
    values: dict[str, str] = {}
    for f in files:
        dl = f.module.data if f.module is not None else None
        if dl is None or dl.name.upper() != "$MACHINE":
            continue
        for item in dl.items:
            if isinstance(item, N.ArrayInit) and isinstance(item.value, N.StrLit) and item.indices == [None]:
                values.setdefault(item.name.upper(), item.value.value.strip())
    robot = (values.get("$MODEL_NAME") or values.get("$TRAFONAME") or "").lstrip("#").strip()
    robot_from = "$machine.dat" if robot else ""
    if not robot:
        named = config_robot(files)
        robot, robot_from = (named[0], "$config.dat MACHINE_DEF[1]") if named else ("", "")
    mada = values.get("$V_R1MADA", "")
    m = _KSS.search(mada)
    kss = (f"KSS {m.group(1)}.{m.group(2)}" if m.group(2) else f"KSS {m.group(1)}") if m else ""
    return {"robot": robot, "robot_from": robot_from, "mada": mada, "kss": kss,
            "controller": _CONTROLLERS.get(m.group(1), "") if m else ""}


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
