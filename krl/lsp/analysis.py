"""A checked workspace and the look-ups every editor feature shares.

An :class:`Analysis` is a :class:`krl.workspace.Workspace` after ``check()`` plus, per file, its
text and lines. The scopes are the front end's (krl/semantics/symbols.py): a position's scope is
the routine scope of the routine around it (``Workspace.routine_scope``), else the module scope
of its file, else the global scope. A file with syntax errors is checked from what parsed, as
``krl check`` checks it (issue 63), so that names in a partial tree resolve. After an edit,
:func:`updated` hands the new parse to the workspace, which re-checks what the edit can affect
(``Workspace.replace``); the language server holds no phase of the check itself.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.diagnostics import Diagnostic
from krl.diagnostics.codes import W111
from krl.diagnostics.render import split_lines
from krl.lsp.parsing import Parsed
from krl.lsp.paths import is_uri
from krl.semantics import types as T
from krl.semantics.config import config_for
from krl.semantics.symbols import Scope, Symbol
from krl.workspace import SourceFile, Workspace


@dataclass
class FileInfo:
    """One file of an analysis: the parse, the workspace's SourceFile, the lines of its text."""
    path: str
    parsed: Parsed
    source: SourceFile
    lines: list[str]
    _by_line: dict[int, list[N.Node]] | None = None

    def nodes_on(self, line: int) -> list[N.Node]:
        """AST nodes whose first token is on `line` (1-based)."""
        if self._by_line is None:
            idx: dict[int, list[N.Node]] = {}
            for n in self.source.module.walk():
                idx.setdefault(n.span.line, []).append(n)
            self._by_line = idx
        return self._by_line.get(line, [])


@dataclass
class Analysis:
    """A checked workspace (see the module docstring); `files` by path."""
    root: str
    ws: Workspace
    files: dict[str, FileInfo] = field(default_factory=dict)
    how: str = "workspace"      # what the check that made it checked: Workspace.replace's answer
    # per AST node, what editor features derived from its annotations (krl/lsp/unused.py); handed
    # on while the workspace's symbols stay the same (a re-check of some routines or values)
    memo: dict = field(default_factory=dict, repr=False)
    _types: dict[int, Symbol] | None = None
    _type_of_decl: dict[int, Symbol] | None = None
    _routine_path: dict[int, str] | None = None

    # ------------------------------------------------------------------ places

    def routine_at(self, path: str, line: int) -> N.Routine | None:
        """The routine whose DEF..END lines hold `line`, else None."""
        fi = self.files.get(path)
        if fi is None:
            return None
        routines = fi.source.module.routines
        for i, r in enumerate(routines):
            end = r.end_line or (routines[i + 1].span.line - 1 if i + 1 < len(routines) else len(fi.lines))
            if r.span.line <= line <= end:
                return r
        return None

    def scope_at(self, path: str, line: int) -> Scope | None:
        """The innermost scope at a line: routine, module or global."""
        r = self.routine_at(path, line)
        if r is not None:
            sc = self.ws.routine_scope(r)
            if sc is not None:
                return sc
        fi = self.files.get(path)
        if fi is not None and fi.source.scope is not None:
            return fi.source.scope
        return self.ws.global_scope

    def routine_path(self, routine: N.Routine) -> str:
        if self._routine_path is None:
            self._routine_path = {id(r): f.path for f in self.ws.files for r in f.module.routines}
        return self._routine_path.get(id(routine), "")

    def type_symbol(self, typ: T.KrlType) -> Symbol | None:
        """Where the checker's Declarer entered a user STRUC/ENUM type (krl/semantics/checker.py
        ``Declarer.declare_types``: the Symbol of kind 'type' in its scope's ``type_symbols``,
        with the declaration, file and scope kind), else None (a built-in type)."""
        if self._types is None:
            self._index_types()
        return self._types.get(id(typ))

    def type_decl(self, typ: T.KrlType) -> tuple[N.Decl, str] | None:
        """The STRUC/ENUM declaration (and its file) of a user type, else None (built-in)."""
        sym = self.type_symbol(typ)
        return (sym.decl, sym.path) if sym is not None else None

    def declared_type(self, decl: N.Decl) -> T.KrlType | None:
        """The type a STRUC/ENUM declaration entered, None when it entered none (a duplicate)."""
        if self._type_of_decl is None:
            self._index_types()
        sym = self._type_of_decl.get(id(decl))
        return sym.type if sym is not None else None

    def _index_types(self) -> None:
        self._types, self._type_of_decl = {}, {}
        scopes = [self.ws.global_scope, *(u.scope for u in self.ws.units), *self.ws.routine_scopes.values()]
        for sc in scopes:
            if sc is None:
                continue
            for sym in sc.type_symbols.values():
                self._types.setdefault(id(sym.type), sym)
                self._type_of_decl.setdefault(id(sym.decl), sym)

    def diagnostics_for(self, path: str) -> list[Diagnostic]:
        """The workspace's diagnostics of one file, with the root's krl.toml applied."""
        diags = self.ws.diagnostics_of(path)
        if is_uri(path):        # an unsaved new buffer has no file name to match its main routine
            diags = [d for d in diags if d.code != W111]
        try:
            return config_for(self.root).apply(diags)     # the workspace root only, as krl check
        except Exception:  # noqa: BLE001 - a bad krl.toml: `krl check` says why; here all are shown
            return diags


def build_analysis(root: str, parsed: list[Parsed], skipped=()) -> Analysis:
    """Link and check parsed files as one workspace (krl/workspace.py ``Workspace.check``, files
    that do not parse checked from what parsed); `skipped`: the krl.files entries not read
    (links, FIFOs, ...), W002 as in ``krl check``."""
    ws = Workspace(root)
    an = Analysis(root, ws)
    for p in parsed:
        sf = ws.add_loaded(p.loaded, notify=False)
        an.files[p.path] = FileInfo(p.path, p, sf, split_lines(p.text))
    ws.add_unread(skipped)
    ws.check(resolve=False)
    return an


def updated(prev: Analysis, parsed: Parsed) -> Analysis:
    """A new analysis of `prev`'s workspace with one file's new parse in place: the workspace
    re-checks what the change can affect (``Workspace.replace``); ``how`` says what that was."""
    fi = prev.files[parsed.path]
    how = prev.ws.replace(parsed.loaded)
    an = Analysis(prev.root, prev.ws, dict(prev.files), how=how, memo=prev.memo if how != "workspace" else {})
    an.files[parsed.path] = FileInfo(parsed.path, parsed, fi.source, split_lines(parsed.text))
    return an
