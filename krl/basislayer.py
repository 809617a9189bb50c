"""The project's BASIS checked once and shared, only read, by the programs checked on it.

Outside a backup every program runs on the project's BASIS (interp/basis: ``$config.dat``,
``bas.src``, ``collmonlib.src``, ``ir_stopm.src``; krl/project.py rule 4), and checking those
four files was nearly all of a small program's load (docs/architecture.md, "One checked BASIS
per process"). A :class:`BasisLayer` is the workspace of the BASIS files alone, checked and
resolved once (:func:`basis_layer`); a program's workspace is then checked on it
(``Workspace.layer``): the layer's units are the workspace's first units (so a BASIS name's
``Storage.owner`` is the same in every workspace), its system variables the first slots of
``Workspace.system_names``, its global names entered in the program's ``$GLOBAL`` scope as the
layer's check left them, its findings and unresolved uses those of the layer's owners; only
the program's own files are checked and resolved. Nothing of the layer is written again.

The layer is used only where it cannot change a meaning (:meth:`BasisLayer.admits`): the
program's files all parse and are all read, none is a system data list (its own
``$config.dat`` merges with the BASIS's, rule 4), and no name the program enters in
``$GLOBAL`` (a name a GLOBAL declaration of a data list declares, a main or GLOBAL routine, a
module's or data list's name) is a word of the BASIS's ASTs (what the BASIS's names could resolve to, or a BASIS
global it would repeat). Everything else is checked whole, as before.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from krl.ast import nodes as N
from krl.semantics.checker import _is_system_datalist
from krl.semantics.symbols import Scope
from krl.parsecache import load_files
from krl.workspace import SourceFile, Workspace

__all__ = ["BasisLayer", "basis_layer", "words_of"]


class BasisLayer:
    """A checked and resolved workspace of the BASIS files alone, shared by the programs
    checked on it (module docstring). ``units``: its ModuleUnits (the first of every workspace
    on it); ``files``: its SourceFiles; ``words``: every string of its ASTs, upper case."""

    def __init__(self, ws: Workspace) -> None:
        if not ws.checked or ws.resolver is None or ws._state is None:
            raise ValueError("a BASIS layer is made of a checked and resolved workspace")
        self.workspace = ws
        self.units = tuple(ws.units)
        self.files = tuple(ws.files)
        self._ids = frozenset(id(f) for f in ws.files)
        self.global_scope: Scope = ws.global_scope
        self.resolver = ws.resolver
        self.system_names = tuple(ws.system_names)
        self.parts = tuple(ws.owner_parts())        # the four parts of its check's owners
        self.kuka = frozenset(ws._state.kuka)
        self.inputs = tuple(ws._inputs)
        self.words = frozenset(w for f in ws.files for w in words_of(f.module))

    def holds(self, f: SourceFile) -> bool:
        """True for one of the layer's own SourceFiles."""
        return id(f) in self._ids

    def enter(self, glob: Scope) -> None:
        """Enter the layer's global names (values, types, routines) in a program's `glob`."""
        g = self.global_scope
        for table in ("values", "types", "routines", "type_symbols"):
            getattr(glob, table).update(getattr(g, table))

    def admits(self, ws: Workspace) -> bool:
        """True when `ws`, a program's files loaded and not checked yet, checked on this layer
        gives what a check of its files and the BASIS's together gives (module docstring)."""
        return not self.refusal(ws)

    def refusal(self, ws: Workspace) -> str:
        """Why `ws` (loaded, not checked) is checked whole and not on this layer, "" when it
        may be checked on it: "checked", "not read", "not parsed", "system data list NAME",
        "global NAME" (the first in sorted order of the names that are BASIS words)."""
        if ws.checked or ws.layer is not None or ws.check_only is not None:
            return "checked"
        if ws.unreadable:
            return "not read"
        if ws.failed_words or any(not f.ok for f in ws.files):
            return "not parsed"
        names: set[str] = set()
        for f in ws.files:
            m = f.module
            names.add(_stem(f.path))
            if m.data is not None:
                if _is_system_datalist(m.data.name):
                    return f"system data list {m.data.name}"
                names.add(m.data.name.upper())
                for d in m.data.items:
                    if getattr(d, "is_global", False):
                        names |= _declared(d)
            for i, r in enumerate(m.routines):
                if i == 0 or r.is_global:
                    names.add(r.name.upper())
        clash = sorted(names & self.words)
        return f"global {clash[0]}" if clash else ""

    def attach(self, ws: Workspace) -> None:
        """Make `ws` (admitted: :meth:`admits`) a workspace on this layer: the layer's files
        after its own, as the BASIS files are added to a program's (krl/project.py rule 4)."""
        ws.layer = self
        ws.files.extend(self.files)
        for f in self.files:
            lf = self.workspace.loaded.get(f.path)
            if lf is not None:
                ws.loaded[f.path] = lf
            ws.template[f.path] = self.workspace.template.get(f.path)
        ws.routine_scopes.update(self.workspace.routine_scopes)
        ws.sink.extend(self.inputs)


def basis_layer(paths: list[Path], natives: dict | None = None) -> BasisLayer:
    """The layer of the BASIS files `paths` (in the order a run adds them): loaded alone, each
    parse from the one store (krl/parsecache.py), checked and resolved with `natives` (the
    run's built-in implementations: interp/runtime/natives ``LINKS``)."""
    ws = Workspace(str(Path(paths[0]).parent) if paths else "")
    for lf in load_files(list(paths)):
        ws.add_loaded(lf, notify=False)
    ws.natives = natives
    ws.check()
    return BasisLayer(ws)


def _stem(path: str) -> str:
    name = path.replace("\\", "/").rsplit("/", 1)[-1]
    return name.rsplit(".", 1)[0].upper()


def _declared(d: N.Decl) -> set[str]:
    """The names a data list's GLOBAL declaration `d` enters in ``$GLOBAL``, upper case."""
    if isinstance(d, N.VarDecl):
        return {v.name.upper() for v in d.names}
    name = getattr(d, "name", None)
    return {name.upper()} if isinstance(name, str) else set()


def words_of(node) -> set[str]:
    """Every string held by `node` and the nodes below it (names, type names, literals), upper
    case: a superset of the names the node declares or looks up."""
    out: set[str] = set()
    stack = [node]
    while stack:
        x = stack.pop()
        if isinstance(x, str):
            out.add(x.upper())
        elif isinstance(x, (list, tuple)):
            stack.extend(x)
        elif isinstance(x, N.Node):
            stack.extend(getattr(x, f.name) for f in dataclasses.fields(x) if f.name not in ("span", "ann"))
    return out
