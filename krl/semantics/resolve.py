"""The resolver: after checking, every use of a name gets its storage, as clox's resolver does.

The checker (krl/semantics/checker.py) gives each Name and Call its :class:`Symbol`. This pass
(:func:`resolve_workspace`, run by ``Workspace.check``) turns symbols into places, once, ahead
of any run; the interpreters (interp/) allocate storage for them and never look a name up:

* every Routine gets a :class:`Layout` (``routine.ann.layout``): its frame slots — the
  parameters in order, then its local variables, SIGNALs and IMPORTs in declaration order;
* every DataList gets a :class:`Layout` of its data-list slots (variables and SIGNALs);
* every Name (an expression, an assignment target, a FOR variable, a WITH target) gets its
  *place*, a :class:`Storage` (``name.ann.place``): its *storage class* and *slot*:

  ========== ============================================================================
  class      where the variable lives
  ========== ============================================================================
  LOCAL      a slot of the routine's frame: a local, or a parameter (an :IN copy, or the
             caller's reference for :OUT); ``slot`` is the frame slot
  MODULE     a slot of the data list of the routine's own module (``owner``: the module's
             index in ``Workspace.units``, ``slot`` its data-list slot)
  GLOBAL     a slot of another data list: ``$config.dat``, a system data list
             (``$machine.dat``, ...), a GLOBAL declaration of a PUBLIC data list
  SYSTEM     a system variable of the tables (krl/semantics/data), ``slot`` its index in
             ``Workspace.system_names``; machine data a backup declares for it (Mada)
             initialises it
  UNRESOLVED nothing declares the name: a ``$`` name goes to the runtime's documented
             fallback (``Names.lookup``: the simulated system variables, and in a backup
             an undeclared one that reads 0); any other name is the run-time error
             "unknown name" where it is evaluated
  ========== ============================================================================

  An IMPORT name stands for the imported data-list variable (its storage). A name inside a
  routine whose file does not parse (the checker does not check such bodies) is resolved
  with the same scopes (``Scope.lookup``).
* every Call gets a :class:`Callee` (``call.ann.callee``): a ROUTINE of the program (the
  module and Routine it runs), a NATIVE built-in of the tables (``native``: its implementation
  from ``Workspace.natives``, linked once here), or a STUB (nothing implements it: the
  run-time stand-in policy);
* every Aggregate with a TYPE prefix gets the STRUC it names (``aggregate.ann.struc``);
* every GOTO gets its ``target``, the Label it jumps to: the label of that name in the nearest
  block around the GOTO that holds one (the last one in that block), else None (the run-time
  error "label not found");
* an assignment to an element of a *cyclic* system variable (``cyclic: true`` in the tables:
  ``$CYCFLAG``, reference §5.15) gets ``assign.ann.cyclic``;
* every Field and every item of an aggregate gets the structure :class:`Component` it names
  (``ann.component``): its key (the STRUC declaration's: names are case-insensitive, the key is
  upper case) and its declared type when the structure's type is known;
* ANIN ON/OFF and ANOUT ON/OFF get their analog signal's place (``ann.channel``): the name
  the statement switches, and for ANIN ON the SIGNAL its value ``factor * signal`` reads
  (reference §5.14: the signal is declared with SIGNAL), None when it reads no SIGNAL or more
  than one (its value is then written once, not cyclically: nothing for ANIN OFF to name);
* every statement gets its :class:`krl.semantics.advance.StmtInfo` (``stmt.ann.info``).

The back ends read these facts and never a name's spelling.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.semantics import types as T
from krl.semantics.advance import analyse
from krl.semantics.builtins import load_builtins
from krl.semantics.symbols import Scope, Symbol, system_scopes

LOCAL, MODULE, GLOBAL, SYSTEM, UNRESOLVED = range(5)
CLASS_NAMES = ("local", "module", "global", "system", "unresolved")
ROUTINE, NATIVE, STUB = range(3)
CALLEE_NAMES = ("routine", "native", "stub")


@dataclass(slots=True, eq=False)
class Storage:
    """Where a name's variable lives: ``kind`` (LOCAL, MODULE, GLOBAL, SYSTEM, UNRESOLVED),
    ``slot`` (frame slot, data-list slot, or index in ``Workspace.system_names``), ``owner``
    (the data list's module index in ``Workspace.units``; -1 otherwise), ``name`` (the
    declared spelling; the upper-case key for SYSTEM; the use's spelling for UNRESOLVED,
    for its run-time error) and ``symbol``."""
    kind: int
    slot: int = -1
    owner: int = -1
    name: str = ""
    symbol: Symbol | None = None

    def __repr__(self) -> str:
        where = f"{self.owner}:{self.slot}" if self.owner >= 0 else str(self.slot)
        return f"Storage({CLASS_NAMES[self.kind]} {self.name} @{where})"

    @property
    def key(self) -> tuple:
        """Equal for two uses of the same variable (a frame slot, a data-list slot, a system
        variable; an unresolved name by its upper-case spelling)."""
        if self.kind == UNRESOLVED:
            return (UNRESOLVED, self.name.upper())
        return (self.kind, self.owner, self.slot)


@dataclass(slots=True, eq=False)
class Callee:
    """What a call runs. ``kind`` ROUTINE: ``routine`` (a Routine of the program) in module
    ``owner`` (index in ``Workspace.units``); NATIVE: a built-in routine of the tables, and
    ``native`` its implementation ``fn(rt, args)``, linked here once from the workspace's
    ``natives`` (the runtime's registry, interp/runtime/natives, gives it for a run; None when
    the simulator has none, or for a check alone); STUB: nothing implements it (a technology
    package absent from the backup). A call whose ``native`` is None goes to the run-time
    stand-in policy. ``name`` as called (for messages and traces)."""
    name: str
    kind: int = STUB
    owner: int = -1
    routine: N.Routine | None = None
    native: Callable | None = None

    def __repr__(self) -> str:
        return f"Callee({CALLEE_NAMES[self.kind]} {self.name})"


@dataclass(slots=True, frozen=True)
class Component:
    """A structure component a Field or an aggregate item names: ``key``, its key in the
    structure's values (the STRUC declaration's, ``types.Struc.fields``: upper case); ``name``
    as written (for messages and `krl asm`); ``type`` its declared type when the structure's
    STRUC is known (None otherwise: the run-time value decides, and the run-time error names a
    component the value does not have)."""
    name: str
    key: str
    type: T.KrlType | None = None


@dataclass(slots=True, eq=False)
class LayoutSlot:
    """What the front end knows of one slot of a Layout (a *slot* is a numbered place of a
    frame or a data list: ``Storage.slot``): the declared spelling, the symbol, its declaration
    node (VarDecl, SignalDecl or Param), the VarName for a variable, its type and the
    parameter mode. At run time the value of a slot is reached through a reference
    (interp/runtime/memory.py ``Slot``)."""
    name: str
    symbol: Symbol | None
    decl: object
    var: N.VarName | None = None
    type: T.KrlType | None = None
    mode: str | None = None


@dataclass(slots=True, eq=False)
class Layout:
    """The slots of a routine's frame (parameters first: ``nparams``) or of a data list,
    and the scope the names were resolved in (VARSTATE's text, typed expressions and tools
    use it)."""
    slots: list[LayoutSlot] = field(default_factory=list)
    nparams: int = 0
    scope: Scope | None = None
    owner: int = -1
    returns: T.KrlType | None = None       # a function's return type (None for a DEF)

    def index(self, name: str) -> int | None:
        """The slot of `name` (any case), else None: for tools (debugger, VARSTATE), not for
        the interpreters, which read each use's Storage."""
        key = name.upper()
        for i, s in enumerate(self.slots):
            if s.name.upper() == key:
                return i
        return None


def _data_layout(dl: N.DataList, owner: int) -> Layout:
    lay = Layout(owner=owner)
    seen: set = set()
    for d in dl.items:
        if isinstance(d, N.VarDecl):
            for v in d.names:
                if v.name.upper() in seen:
                    continue
                seen.add(v.name.upper())
                lay.slots.append(LayoutSlot(v.name, N.symbol_of(v), d, v, N.type_of(v)))
        elif isinstance(d, N.SignalDecl) and d.name.upper() not in seen:
            seen.add(d.name.upper())
            lay.slots.append(LayoutSlot(d.name, None, d))
    return lay


def _routine_layout(r: N.Routine, scope: Scope | None, owner: int) -> Layout:
    lay = Layout(scope=scope, owner=owner)
    values = scope.values if scope is not None else {}
    seen: set = set()
    modes = {}
    for p in r.params:
        key = p.name.upper()
        modes[key] = p.mode
        if key in seen:
            continue
        seen.add(key)
        sym = values.get(key)
        lay.slots.append(LayoutSlot(p.name, sym, p, type=sym.type if sym is not None else None, mode=p.mode))
    lay.nparams = len(lay.slots)
    for d in r.decls:
        if isinstance(d, N.VarDecl):
            for v in d.names:
                key = v.name.upper()
                if key in seen:
                    if key in modes:     # the declaration of a parameter: its type and VarName
                        i = next(i for i, s in enumerate(lay.slots) if s.name.upper() == key)
                        lay.slots[i].var = v
                        lay.slots[i].decl = d
                        lay.slots[i].type = N.type_of(v)
                    continue
                seen.add(key)
                lay.slots.append(LayoutSlot(v.name, values.get(key), d, v, N.type_of(v)))
        elif isinstance(d, N.SignalDecl) and d.name.upper() not in seen:
            seen.add(d.name.upper())
            lay.slots.append(LayoutSlot(d.name, values.get(d.name.upper()), d))
    return lay


class Resolver:
    """One pass over a checked workspace (see the module docstring)."""

    def __init__(self, ws) -> None:
        self.ws = ws
        self.system, _ = system_scopes()
        self.places: dict[int, tuple[int, int, int]] = {}   # id(Symbol) -> (kind, owner, slot)
        self.system_index: dict[str, int] = {}
        self.unit_of: dict[int, int] = {}                    # id(Routine) -> unit index
        self.native_names = set(self.system.routines)
        self.natives = ws.natives or {}     # upper-case name -> implementation (a run's workspace)
        tables = load_builtins()
        self.cyclic = frozenset(k for k, info in tables.sysvars.items() if info.cyclic)

    # ------------------------------------------------------------------ layouts
    def run(self) -> None:
        ws = self.ws
        ws.system_names = []
        ws.resolver = self
        start = self.on_layer(getattr(ws, "layer", None))
        returns: dict[int, T.KrlType | None] = {}
        for scope in [ws.global_scope] + [u.scope for u in ws.units]:
            for sym in (scope.routines.values() if scope is not None else ()):
                if isinstance(sym.decl, N.Routine) and sym.signature is not None:
                    returns.setdefault(id(sym.decl), sym.signature.returns)
        for i, u in enumerate(ws.units):
            if i < start:
                continue
            if u.src is not None:
                for r in u.src.module.routines:
                    self.unit_of[id(r)] = i
            if u.dat is not None and u.dat.module.data is not None:
                lay = _data_layout(u.dat.module.data, i)
                u.dat.module.data.annotate().layout = lay
                for k, s in enumerate(lay.slots):
                    sym = s.symbol if s.symbol is not None else (u.scope.values.get(s.name.upper())
                                                                 if u.scope is not None else None)
                    if sym is None and ws.global_scope is not None:
                        sym = ws.global_scope.values.get(s.name.upper())
                        if sym is not None and sym.decl is not s.decl:
                            sym = None
                    if sym is not None:
                        s.symbol = sym
                        self.places.setdefault(id(sym), (MODULE, i, k))
        for i, u in enumerate(ws.units):
            if i < start:
                continue
            if u.dat is not None and u.dat.module.data is not None:
                dl = u.dat.module.data
                scope = u.scope if u.scope is not None else ws.global_scope
                for d in dl.items:
                    if isinstance(d, N.VarDecl) and d.init is not None:
                        self.expr(d.init, scope, None, i)
                    elif isinstance(d, N.ArrayInit):
                        # `NAME[i] = value`: an element of this data list's own variable
                        k = u.dat.module.data.ann.layout.index(d.name)
                        d.annotate().place = Storage(MODULE, k, i, d.name) if k is not None else None
                        for e in (*d.indices, d.value):
                            self.expr(e, scope, None, i)
            if u.src is None:
                continue
            for r in u.src.module.routines:
                scope = ws.routine_scope(r) or u.scope
                lay = _routine_layout(r, ws.routine_scope(r), i)
                lay.returns = returns.get(id(r)) if r.kind == "DEFFCT" else None
                r.annotate().layout = lay
                local = self.locals_of(lay)
                for d in r.decls:
                    if isinstance(d, N.VarDecl) and d.init is not None:
                        self.expr(d.init, scope, local, i)
                self.block(r.body, scope, local, i)

    def on_layer(self, layer) -> int:
        """Take the places a shared BASIS layer's resolver gave (krl/basislayer.py: its units
        are the workspace's first, its system variables the first slots) and return how many
        units it holds (0 without a layer): those are not resolved again."""
        if layer is None:
            return 0
        done = layer.resolver
        self.places.update(done.places)
        self.system_index.update(done.system_index)
        self.unit_of.update(done.unit_of)
        self.ws.system_names.extend(layer.system_names)
        return len(layer.units)

    # ------------------------------------------------------------------ names
    @staticmethod
    def locals_of(layout: Layout) -> dict:
        """The frame slots of a routine's `layout` by symbol (``id``), or by upper-case name
        for a parameter without a declaration: what :meth:`storage` takes as ``local``."""
        return {id(s.symbol) if s.symbol is not None else s.name.upper(): k for k, s in enumerate(layout.slots)}

    def import_target(self, d: N.ImportDecl) -> Symbol | None:
        """The data-list variable ``IMPORT type name IS /R1/module..var`` names (2.5): the
        module's own or exported declaration of that name (as Workspace._link_imports links
        the data lists' IMPORTs; this also serves a routine's)."""
        path = [p for p in d.path if p]
        if len(path) < 2:
            return None
        mod, var = path[-2].upper(), path[-1].upper()
        for u in self.ws.units:
            names = {u.name.upper()}
            if u.dat is not None and u.dat.module.data is not None:
                names.add(u.dat.module.data.name.upper())
            if mod not in names:
                continue
            got = u.scope.values.get(var) if u.scope is not None else None
            if got is None and self.ws.global_scope is not None:
                g = self.ws.global_scope.values.get(var)
                got = g if g is not None and g.module.upper() in names else None
            if got is not None:
                return got
        return None

    def storage(self, name: str, sym: Symbol | None, local: dict | None, unit: int) -> Storage:
        hops = 0
        while sym is not None and (sym.alias is not None or isinstance(sym.decl, N.ImportDecl)):
            # IMPORT: the imported variable (an IMPORT of an IMPORT is followed a few times)
            hops += 1
            sym = (sym.alias if sym.alias is not None else self.import_target(sym.decl)) if hops < 8 else None
        if sym is None and local is not None and name.upper() in local:
            # a parameter without a declaration (E101): the caller's argument all the same
            return Storage(LOCAL, local[name.upper()], -1, name)
        if sym is None or sym.kind in ("routine", "type", "label"):
            return Storage(UNRESOLVED, name=name)
        if local is not None:
            k = local.get(id(sym))
            if k is not None:
                return Storage(LOCAL, k, -1, sym.name, sym)
        place = self.places.get(id(sym))
        if place is not None:
            key = name.upper()
            if key[:1] == "$" and key in self.system.values and sym.scope != "routine" and \
                    sym.module[:1] == "$":
                # machine data (a system data list) for a system variable of the tables: the
                # variable is the system's; the data list only initialises it
                return self.system_storage(self.system.values[key])
            _, owner, slot = place
            return Storage(MODULE if owner == unit else GLOBAL, slot, owner, sym.name, sym)
        if sym.scope in ("system", "basis") or sym.kind == "sysvar":
            if name[:1] == "$":
                return self.system_storage(sym)
            return Storage(UNRESOLVED, name=name, symbol=sym)
        return Storage(UNRESOLVED, name=name, symbol=sym)

    def system_storage(self, sym: Symbol) -> Storage:
        key = sym.name.upper()
        k = self.system_index.get(key)
        if k is None:
            k = self.system_index[key] = len(self.ws.system_names)
            self.ws.system_names.append(key)
        return Storage(SYSTEM, k, -1, key, sym)

    def name(self, e: N.Name, scope: Scope | None, local, unit: int) -> None:
        sym = N.symbol_of(e)
        if not isinstance(sym, Symbol) and scope is not None:
            sym = scope.lookup(e.name)
        e.annotate().place = self.storage(e.name, sym, local, unit)

    def call(self, c: N.Call, scope: Scope | None, unit: int) -> None:
        sym = N.symbol_of(c)
        if not isinstance(sym, Symbol) and scope is not None:
            sym = scope.lookup_routine(c.name)
        callee = Callee(c.name)
        if isinstance(sym, Symbol):
            decl = sym.decl
            if isinstance(decl, N.ExtDecl) and self.ws.global_scope is not None:
                # EXT/EXTFCT names a routine of another module (reference 2.6): the link binds
                # the call to the module main or GLOBAL routine that the global scope holds
                # (krl/workspace.py: a routine replaces an EXT signature there); a technology
                # package absent from the backup leaves it unbound
                linked = self.ws.global_scope.routines.get(c.name.upper())
                if linked is not None and isinstance(linked.decl, N.Routine):
                    decl = linked.decl
            if isinstance(decl, N.Routine):
                callee.kind = ROUTINE
                callee.routine = decl
                callee.owner = self.unit_of.get(id(decl), -1)
        if callee.kind != ROUTINE and c.name.upper() in self.native_names:
            # a built-in of the tables (also behind an EXT declaration nothing implements:
            # the controller's own routine runs), linked to its implementation
            callee.kind = NATIVE
            callee.native = self.natives.get(c.name.upper())
        c.annotate().callee = callee

    def expr(self, e, scope, local, unit: int) -> None:
        """Resolve every Name and Call of expression `e` (iteratively: a 500-term chain costs
        no stack)."""
        stack = [e]
        while stack:
            n = stack.pop()
            if not isinstance(n, N.Node):
                continue
            if isinstance(n, N.Name):
                self.name(n, scope, local, unit)
                continue
            if isinstance(n, N.Call):
                self.call(n, scope, unit)
            elif isinstance(n, N.Field):
                n.annotate().component = _component(n.name, N.type_of(n.base))
            elif isinstance(n, N.Aggregate):
                t = N.type_of(n)
                if n.type_name and scope is not None:
                    if not isinstance(t, T.Struc):
                        t = scope.lookup_type(n.type_name)
                    n.annotate().struc = t if isinstance(t, T.Struc) else None
                for it in n.items:
                    it.annotate().component = _component(it.name, t)
            stack.extend(n.children())

    # ------------------------------------------------------------------ statements
    def block(self, stmts, scope, local, unit: int) -> None:
        """Resolve a statement list and the blocks nested in it, with a work list (nesting costs
        no stack: the deepest legal file checks within krl.limits.MAX_CHECK_FRAMES). Each
        block's labels (the last of a name wins) are chained to the enclosing blocks', for
        the GOTO targets."""
        work = [(stmts, None)]
        while work:
            stmts, outer = work.pop()
            labels = ({s.name.upper(): s for s in stmts if isinstance(s, N.Label)}, outer)
            after_continue = False
            for s in stmts:
                work.extend((b, labels) for b in self.stmt(s, scope, local, unit))
                if isinstance(s, N.Goto):
                    s.annotate().target = _label_target(s.label.upper(), labels)
                info = s.annotate().info = analyse(s, _symbol_of)
                if info.reason is not None:
                    s.ann.extra["advance_stop"] = info.reason
                    if after_continue:
                        s.ann.extra["continued"] = True
                after_continue = isinstance(s, N.Continue)

    def stmt(self, s, scope, local, unit: int) -> list:
        """Resolve the statement's own expressions (a TRIGGER's action, an interrupt's BRAKE
        included); returns the statement lists nested in it."""
        blocks = []
        for f in s.__dataclass_fields__:
            v = getattr(s, f)
            if isinstance(v, list):
                if v and isinstance(v[0], N.Stmt):
                    blocks.append(v)
                else:
                    for x in v:
                        if isinstance(x, N.Case):
                            self.exprs(x.values, scope, local, unit)
                            blocks.append(x.body)
                        elif isinstance(x, N.Node):
                            self.expr(x, scope, local, unit)
            elif isinstance(v, N.Stmt):
                blocks += self.stmt(v, scope, local, unit)          # a TRIGGER's action
                v.annotate().info = analyse(v, _symbol_of)
            elif isinstance(v, N.Node):
                self.expr(v, scope, local, unit)
        if isinstance(s, (N.AnoutOn, N.AnoutOff, N.AninOff)) and scope is not None:
            # the analog channel is named by a plain word in these statements
            s.annotate().channel = self.storage(s.name, scope.lookup(s.name), local, unit)
        elif isinstance(s, N.AninOn):
            # the analog input is the SIGNAL the value reads (`ANIN ON v = factor * SIG`)
            signals = {id(_symbol_of(n)): n for n in s.value.walk()
                       if isinstance(n, N.Name) and getattr(_symbol_of(n), "kind", None) == "signal"}
            s.annotate().channel = next(iter(signals.values())).ann.place if len(signals) == 1 else None
        elif isinstance(s, N.Assign):
            t = s.target
            place = t.base.ann.place if isinstance(t, N.Index) and isinstance(t.base, N.Name) else None
            if place is not None and place.kind == SYSTEM and place.name in self.cyclic:
                s.annotate().cyclic = True        # a cyclic flag (reference §5.15)
        return blocks

    def exprs(self, es, scope, local, unit) -> None:
        for e in es:
            self.expr(e, scope, local, unit)


def _component(name: str, struc) -> Component:
    """The Component `name` names in a structure of type `struc` (a types.Struc, or None or
    another type when the checker does not know the structure's STRUC)."""
    if isinstance(struc, T.Struc):
        got = struc.fields.get(name.upper())
        if got is not None:
            return Component(name, name.upper(), got[1])
    return Component(name, name.upper())


def _label_target(key: str, labels: tuple | None) -> N.Label | None:
    """The Label `key` names in the nearest block of the chain `labels` ((table, outer))."""
    while labels is not None:
        got = labels[0].get(key)
        if got is not None:
            return got
        labels = labels[1]
    return None


def _symbol_of(node) -> Symbol | None:
    st = getattr(node.ann, "place", None)
    sym = st.symbol if isinstance(st, Storage) else None
    return sym if sym is not None else N.symbol_of(node)


def resolve_workspace(ws) -> None:
    """Give every routine and data list of the checked workspace `ws` its Layout, every Name
    its place, every Call its Callee, every statement its facts and StmtInfo (module
    docstring)."""
    Resolver(ws).run()
