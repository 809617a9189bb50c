"""What a program's checked workspace says, in terms that do not depend on where its modules and
system variables are numbered: a workspace checked on the shared BASIS layer
(krl/basislayer.py) and one checked whole must say the same (tests/interp/test_basis_layer.py).

:func:`facts` gives the sorted diagnostics, the unit names, the system variables, the global
scope's names and, for every file, every node's annotation (the checker's type and symbol,
the resolver's Storage, Callee, Layout, Component, StmtInfo ...) with a module index given as
its unit's name and a system slot as its variable's name. :func:`checked_whole` checks a
program's files and its BASIS together, as every run did before the layer.
"""

from __future__ import annotations

import dataclasses
import types

from krl.ast import nodes as N
from krl.parsecache import load_project
from krl.semantics import types as T
from krl.semantics.resolve import SYSTEM, Callee, Layout, Storage
from krl.semantics.symbols import Scope, Symbol
from interp.runtime.natives import LINKS


def checked_whole(project, extra):
    """The program's files and `extra` (its BASIS) loaded and checked together, no layer."""
    ws = load_project(project, str(project.root), None, extra=list(extra))
    ws.natives = LINKS
    ws.check()
    return ws


def _unit(ws, i: int):
    return ws.units[i].name.upper() if 0 <= i < len(ws.units) else i


def _node(n: N.Node) -> tuple:
    return (type(n).__name__, n.span.line if n.span else None, n.span.column if n.span else None,
            getattr(n, "name", None))


def _symbol(s: Symbol, ws) -> tuple:
    return ("Symbol", s.name, s.kind, str(s.type), s.scope, s.module, s.path, s.access, s.mode,
            s.stop_read, s.stop_write, _node(s.decl) if isinstance(s.decl, N.Node) else None,
            _value(s.alias, ws) if s.alias is not None else None,
            _value(s.signature, ws) if s.signature is not None else None)


_MEMO: dict = {}        # id -> (the object, its picture) within one :func:`facts`
_SHARED = (Symbol, T.KrlType, Layout, Scope)
_FIELDS: dict = {}      # a dataclass -> its fields' names


def _value(x, ws, depth: int = 0):
    """A comparable picture of one annotation value (module indices as unit names, system
    slots as names, nodes and symbols by what they are, never by identity)."""
    if x is None or isinstance(x, (bool, int, float, str)):
        return x
    if isinstance(x, _SHARED):
        got = _MEMO.get(id(x))
        if got is None:
            got = _MEMO[id(x)] = (x, _picture(x, ws, depth))
        return got[1]
    return _picture(x, ws, depth)


def _picture(x, ws, depth: int):
    if depth > 12:
        return "..."
    if isinstance(x, Storage):
        slot = ws.system_names[x.slot] if x.kind == SYSTEM else x.slot
        return ("Storage", x.kind, slot, _unit(ws, x.owner), x.name,
                _value(x.symbol, ws) if x.symbol is not None else None)
    if isinstance(x, Callee):
        return ("Callee", x.name, x.kind, _unit(ws, x.owner), _node(x.routine) if x.routine else None,
                getattr(x.native, "__qualname__", None))
    if isinstance(x, Layout):
        return ("Layout", _unit(ws, x.owner), x.nparams, str(x.returns),
                (x.scope.kind, x.scope.name) if x.scope is not None else None,
                tuple((s.name, _value(s.symbol, ws) if s.symbol is not None else None,
                       _node(s.decl) if s.decl is not None else None, str(s.type), s.mode) for s in x.slots))
    if isinstance(x, Symbol):
        return _symbol(x, ws)
    if isinstance(x, N.Node):
        return _node(x)
    if isinstance(x, Scope):
        return ("Scope", x.kind, x.name)
    if isinstance(x, T.KrlType):
        return ("Type", str(x))
    if isinstance(x, (types.FunctionType, types.BuiltinFunctionType, types.MethodType)):
        return getattr(x, "__qualname__", repr(x))
    if isinstance(x, dict):
        return tuple(sorted((str(k), _value(v, ws, depth + 1)) for k, v in x.items()))
    if isinstance(x, (list, tuple, set, frozenset)):
        items = [_value(v, ws, depth + 1) for v in x]
        return tuple(sorted(items, key=repr)) if isinstance(x, (set, frozenset)) else tuple(items)
    names = _FIELDS.get(type(x))
    if names is None and dataclasses.is_dataclass(x):
        names = _FIELDS[type(x)] = tuple(f.name for f in dataclasses.fields(x))
    if names is not None:
        return (type(x).__name__, *((n, _value(getattr(x, n), ws, depth + 1)) for n in names))
    return (type(x).__name__, repr(x))


def _nodes(node):
    stack = [node]
    while stack:
        x = stack.pop()
        if isinstance(x, (list, tuple)):
            stack.extend(reversed(x))
        elif isinstance(x, N.Node):
            yield x
            stack.extend(reversed([getattr(x, f.name) for f in dataclasses.fields(x)
                                   if f.name not in ("span", "ann")]))


#: what a run notes on a statement's annotation (interp/runtime/program.py ``_fill_run_memos``
#: fills them on the layer's statements): not the check's, left out
RUN_MEMOS = frozenset({"watch", "timer_watch", "inputs_only"})


def _checked(ann):
    if not RUN_MEMOS & set(ann.extra):
        return ann
    return dataclasses.replace(ann, extra={k: v for k, v in ann.extra.items() if k not in RUN_MEMOS})


def facts(ws) -> dict:
    """What `ws` (checked and resolved) says, independent of module and system-slot numbering."""
    _MEMO.clear()
    out = {
        "diagnostics": [(d.path, d.line, d.column, d.code, d.message) for d in ws.diagnostics],
        "units": sorted(u.name.upper() for u in ws.units),
        "system_names": sorted(ws.system_names),
        "global": {t: sorted(getattr(ws.global_scope, t)) for t in ("values", "routines", "types", "type_symbols")},
        "files": [f.path for f in ws.files],
    }
    for f in ws.files:
        out["ann " + f.path] = [(_node(n), _value(_checked(n.ann), ws)) for n in _nodes(f.module) if n.ann is not None]
    un = ws.unresolved()
    _MEMO.clear()
    out["unresolved"] = sorted((k, v[0], tuple(v[1])) for k, v in un.uses.items()) if un is not None else None
    return out
