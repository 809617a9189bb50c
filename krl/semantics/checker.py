"""The static type checker (reference 2-6, 8.1 "compile errors").

Two jobs:

* :class:`Declarer` enters declarations into scopes (types first, then structure components,
  then variables, signals, external and routine signatures), reporting duplicates (E102),
  over-long identifiers (E103) and unknown types (E105).
* :class:`Checker` walks every routine and data list, gives every expression a type
  (``expr.ann.type``), resolves every name and call (``node.ann.symbol``) and reports the
  rules of the issue: assignment compatibility (3.9, E201/W202), aggregates field by field
  (E206), calls (arity E301, :OUT needs a variable E302, argument types E303), ENUM literals
  (E205), declarations before statements (E104), GOTO targets (E401/E402), EXIT outside
  loops (E403), RETURN (E404), undeclared names (E101/E106), write-protected system
  variables and constants (E501/E502), conditions (E204), SWITCH (E207), FOR (E208),
  motion targets (E209), operators (E203).

A name that is not found is recorded, not reported at once: krl/semantics/outside.py decides,
for the whole backup, whether installed software the backup lacks declares it (one warning
W101/W105/W106/W107 per name) or it is the program's error (E101/E105/E106 at each use).
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.ast import nodes as N
from krl.ast.visit import EXPRESSIONS, STATEMENTS, handlers
from krl.ast.printer import expr as printed
from krl.semantics import types as T
from krl.semantics.outside import KINDS, ext_evidence, line_evidence
from krl.semantics.facts import ROBOT
from krl.semantics.statements import KINDS as STATEMENT_KINDS
from krl.diagnostics import DiagnosticSink
from krl.diagnostics.codes import (E101, E102, E103, E104, E108, E109, E110, E201, E203, E204, E205, E206, E207, E208,
                                   E209, E211, E212, E301, E302, E303, E304, E401, E402, E403, E404, E405, E406, E408,
                                   E409, E501, E502, E503, E901, W108, W201, W202, W205, W206, W210, W501)
from krl.semantics.symbols import ParamSig, RoutineSig, Scope, Symbol, make_array

MAX_IDENT = 24
ARITH = {"+", "-", "*", "/"}
LOGIC = {"AND", "OR", "EXOR"}
BITS = {"B_AND", "B_OR", "B_EXOR"}
EQUALITY = {"==", "<>"}
ORDER = {"<", ">", "<=", ">="}

#: the statement kinds that move the robot (their facts write ROBOT: the statement table), which a
#: submit program may not hold (E406)
MOVES_ROBOT = frozenset(cls for cls, kind in STATEMENT_KINDS.items() if ROBOT in kind.facts.writes)


def _is_system_datalist(name: str) -> bool:
    return name.startswith("$")


@dataclass(frozen=True, slots=True)
class DeclaredTwice:
    """A declaration of a name that its scope already holds (the fact behind E102): ``name`` as
    the second declaration writes it, ``kind`` 'value' (a variable, constant, signal or IMPORT,
    also one data list's GLOBAL and non-GLOBAL declarations of a name), 'routine', 'type' or
    'component' (of the STRUC ``struc``), ``span`` the second declaration and ``first`` the
    first one's place (None when nothing of the program declares it: a table's name). The
    workspace keeps these per owner as it keeps findings (``Workspace.declared_twice``); the
    language server and the diff read them, never the message."""
    name: str
    kind: str
    span: N.Span
    first: N.Span | None = None
    struc: str = ""

    def worded(self, place=str) -> tuple[str, str]:
        """(code, message) of its E102; `place(span)` shows the first declaration's place
        (default ``path:line:col``)."""
        if self.kind == "component":
            return E102("component", name=self.name, struc=self.struc)
        where = f" (first declared at {place(self.first)})" if self.first is not None else ""
        return E102(name=self.name, where=where)


class Declarer:
    """Enters declarations into scopes. One instance per workspace."""

    def __init__(self, sink: DiagnosticSink, incomplete: bool = False, maybe_declared=None):
        self.sink = sink
        self.incomplete = incomplete
        # maybe_declared(name) -> True when an unreadable part of the workspace may declare it
        self.maybe_declared = maybe_declared or (lambda _name: incomplete)
        # unknown types are only warnings in system data lists: they use types of
        # $operate.dat, which lives on the controller and is not part of a backup
        self.soft_types = False
        # set while declaring the types of an EXT/EXTFCT declaration
        self.in_ext = False
        # the workspace's record of the current owner's name facts (krl/workspace.py ``_Uses``):
        # unresolved names (krl/semantics/outside.py decides on them) and declarations made
        # twice (DeclaredTwice); None: report at once, keep no facts
        self.unresolved = None
        # evidence(path, line, kind, kuka) -> why installed software declares a name used there,
        # or "" (krl/semantics/outside.py line_evidence; kuka: the file is KUKA's)
        self.evidence = lambda path, line, kind, kuka=False: line_evidence(None, line, kind, kuka)
        # (id(scope), UPPER name) of the types a system data list declared first (they may repeat)
        self._system_types: set[tuple[int, str]] = set()

    def unknown(self, kind: str, name: str, span: N.Span, evidence: str = "", kuka: bool | None = None,
                declared: str = "") -> None:
        """An unresolved name of `kind` ('name', 'type', 'routine', 'sysvar') used at `span`
        (or a routine an EXT at `declared`, FILE:LINE, names and nothing defines): recorded for
        the workspace's decision (krl/semantics/outside.py), or reported at once when the
        declarer works without a workspace. `kuka`: the file is KUKA's (default: the
        declarer's ``soft_types``); the line decides with it (outside.py ``line_evidence``)."""
        if not evidence:
            evidence = self.evidence(span.file, span.line, kind, self.soft_types if kuka is None else kuka)
        if self.unresolved is not None:
            self.unresolved.use(kind, name, span.file, span.line, span.column, evidence, declared)
            return
        err, warn, _noun = KINDS[kind]
        soft = evidence or kind == "sysvar" or self.maybe_declared(name)
        self.sink.at(span, *(warn("soft", name=name) if soft else err(name=name)))

    def ident(self, name: str, span: N.Span) -> None:
        if len(name) > MAX_IDENT:
            self.sink.at(span, *E103(name=name, length=len(name), limit=MAX_IDENT))

    def duplicate(self, name: str, span: N.Span, old: Symbol | T.KrlType | None, kind: str = "value") -> None:
        """E102 for a second declaration of `name` (of `kind`, DeclaredTwice) at `span`;
        `old` the first one (a Symbol or a declaration holder), when the program declares it."""
        decl = getattr(old, "decl", None)
        first = decl.span if decl is not None and getattr(decl, "span", None) is not None and decl.span.line else None
        fact = DeclaredTwice(name, kind, span, first)
        self.sink.at(span, *fact.worded())
        if self.unresolved is not None:
            self.unresolved.declared_twice(fact)

    def resolve_type(self, scope: Scope, tref: N.TypeRef | str, span: N.Span, dims=()) -> T.KrlType:
        """A type by name (E105/W105 and UNKNOWN when it does not exist), with array dims."""
        name = tref.name if isinstance(tref, N.TypeRef) else tref
        typ = scope.lookup_type(name)
        if typ is None:
            self.unknown("type", name, span, "an EXT declaration names it: the software that provides "
                         "the external routine declares its types" if self.in_ext else "")
            typ = T.UNKNOWN
        if isinstance(tref, N.TypeRef) and tref.size is not None:
            typ = T.Array(typ, (tref.size,))
        return make_array(typ, dims)

    # -- phase 1: type names
    def declare_types(self, scope: Scope, items: list[N.Decl], system: bool = False, path: str = "",
                      module: str = "") -> None:
        """Enter STRUC and ENUM names. A second declaration of a name in the same scope is
        E102, except between system data lists ($config.dat, $machine.dat, ...), which may
        repeat each other's declarations (the first one wins).

        Where each type is declared is recorded here, once: ``scope.type_symbols[NAME]`` is a
        Symbol of kind 'type' with the type, the scope kind it was entered in ('routine' for a
        routine's local type, 'module' for one of the module's data list, 'global' for a
        GLOBAL one of a data list or one of $config.dat and the other system data lists), the
        declaring StrucDecl/EnumDecl (the first one), the file `path` and the `module` (the
        data list's or the module's name). The language server reads it (go to definition,
        hover)."""
        for d in items:
            if isinstance(d, N.StrucDecl):
                typ: T.KrlType = T.Struc(d.name)
            elif isinstance(d, N.EnumDecl):
                typ = T.Enum(d.name, frozenset(v.upper() for v in d.values))
                for v in d.values:
                    self.ident(v, d.span)
            else:
                continue
            self.ident(d.name, d.span)
            key = d.name.upper()
            if scope.define_type(d.name, typ) is None:
                scope.type_symbols[key] = Symbol(d.name, "type", typ, scope.kind, d, "RO", module=module, path=path)
                if system:
                    self._system_types.add((id(scope), key))
                continue
            first = scope.type_symbols.get(key)
            first_system = first is None or (id(scope), key) in self._system_types
            if not (system and first_system) and (first is None or first.decl is not d):
                self.duplicate(d.name, d.span, first, "type")

    # -- phase 2: structure components
    def fill_types(self, scope: Scope, items: list[N.Decl]) -> None:
        for d in items:
            if isinstance(d, N.StrucDecl):
                st = scope.types.get(d.name.upper())
                if not isinstance(st, T.Struc) or st.fields:
                    continue
                for c in d.components:
                    self.ident(c.name, c.span)
                    ct = self.resolve_type(scope, c.type_name, c.span, c.dims)
                    if c.name.upper() in st.fields:
                        first = next(x.span for x in d.components if x.name.upper() == c.name.upper())
                        fact = DeclaredTwice(c.name, "component", c.span, first, d.name)
                        self.sink.at(c.span, *fact.worded())
                        if self.unresolved is not None:
                            self.unresolved.declared_twice(fact)
                    st.fields[c.name.upper()] = (c.name, ct)

    # -- phase 3: values and routines
    def declare_values(self, scope: Scope, items: list[N.Decl], module: str, path: str,
                       kind: str = "var") -> None:
        for d in items:
            if isinstance(d, N.VarDecl):
                for v in d.names:
                    self.ident(v.name, v.span)
                    typ = self.resolve_type(scope, d.type, d.type.span, v.dims)
                    sym = Symbol(v.name, "const" if d.is_const else kind, typ, scope.kind, d,
                                 "RO" if d.is_const else "RW", module=module, path=path)
                    ann = v.annotate()
                    ann.symbol, ann.type = sym, typ
                    self._define(scope, sym, v.span)
            elif isinstance(d, N.SignalDecl):
                self.ident(d.name, d.span)
                src = d.start.sysvar.upper() if d.start is not None else "$FALSE"
                if src in ("$ANIN", "$ANOUT"):
                    typ = T.REAL
                elif d.end is not None:
                    typ = T.INT
                else:
                    typ = T.BOOL
                access = "RO" if src in ("$IN", "$ANIN") else "RW"
                sym = Symbol(d.name, "signal", typ, scope.kind, d, access, module=module, path=path,
                             stop_read=src in ("$IN", "$ANIN"), stop_write=src in ("$OUT", "$ANOUT"))
                self._define(scope, sym, d.span)
            elif isinstance(d, N.ImportDecl):
                self.ident(d.name, d.span)
                typ = self.resolve_type(scope, d.type_name, d.span)
                self._define(scope, Symbol(d.name, "var", typ, scope.kind, d, module=module, path=path), d.span)
            elif isinstance(d, N.ExtDecl):
                self.ident(d.name, d.span)
                sig = self.ext_signature(scope, d)
                sym = Symbol(d.name, "routine", sig.returns or T.VOID, scope.kind, d, "RO",
                             signature=sig, module=module, path=path)
                # an EXT declaration may repeat a routine's signature: not a duplicate
                scope.routines.setdefault(d.name.upper(), sym)

    def _define(self, scope: Scope, sym: Symbol, span: N.Span) -> None:
        old = scope.define("values", sym)
        if old is not None:
            # in one scope, or the same global from two data lists (a link error, 2.7)
            self.duplicate(sym.name, span, old)

    def ext_signature(self, scope: Scope, d: N.ExtDecl) -> RoutineSig:
        self.in_ext = True
        try:
            ret = self.resolve_type(scope, d.return_type, d.span) if d.return_type is not None else None
            params = []
            for i, p in enumerate(d.params):
                size = p.name_size if p.name_size is not None else p.type_size
                typ = self.resolve_type(scope, p.type_name, p.span, (size,) if size is not None else ())
                params.append(ParamSig(p.name or f"P{i + 1}", typ, p.mode))
        finally:
            self.in_ext = False
        return RoutineSig(d.name, ret, params)

    def routine_symbol(self, r: N.Routine, module: str, path: str, scope: Scope) -> Symbol:
        """A routine's symbol; its signature is completed by :meth:`complete_signature`."""
        ret = None
        if r.kind == "DEFFCT":
            ret = self.resolve_type(scope, r.return_type, r.span) if r.return_type else T.UNKNOWN
        sig = RoutineSig(r.name, ret, [ParamSig(p.name, T.UNKNOWN, p.mode) for p in r.params])
        return Symbol(r.name, "routine", ret or T.VOID, scope.kind, r, "RO", signature=sig,
                      module=module, path=path)

    def complete_signature(self, sym: Symbol, local: Scope) -> None:
        """Fill parameter types from the routine's local declarations."""
        sig = sym.signature
        for p in sig.params:
            s = local.values.get(p.name.upper())
            if s is not None:
                p.type = s.type


class _Ctx:
    """Per-routine state of the checker."""

    def __init__(self, routine: N.Routine | None, scope: Scope):
        self.routine = routine
        self.scope = scope
        self.loops = 0
        self.labels: dict[str, tuple[N.Label, tuple[int, ...]]] = {}
        self.gotos: list[tuple[N.Goto, tuple[int, ...]]] = []
        self.block_path: list[int] = []
        self.next_block = 0


class Checker:
    """Types and checks statements and expressions. Never raises out of :meth:`check_routine`
    or :meth:`check_datalist` (an internal failure becomes E901)."""

    def __init__(self, sink: DiagnosticSink, declarer: Declarer, incomplete: bool = False):
        self.sink = sink
        self.decl = declarer
        self.incomplete = incomplete
        # one method per statement and expression kind (krl/ast/visit.py)
        self.stmt_dispatch = handlers(self, "s_", STATEMENTS)
        self.expr_dispatch = handlers(self, "e_", EXPRESSIONS)
        # set while checking KUKA system files (R1/System, TP, Mada, STEU): they use
        # declarations of $operate.dat, which is not part of a backup
        self.system_file = False
        # set while checking a .sub file: the submit interpreter has no motion (9, 8.2)
        self.submit = False

    # ---------------------------------------------------------------- entry points

    def check_datalist(self, dl: N.DataList, scope: Scope) -> None:
        """Check the initial values of a data list against the declared types (2.5, 3.9)."""
        try:
            for d in dl.items:
                if isinstance(d, N.VarDecl) and d.init is not None:
                    sym = scope.lookup(d.names[0].name)
                    target = sym.type if sym is not None else T.UNKNOWN
                    self.check_value(target, d.init, scope, d.init.span)
                elif isinstance(d, N.ArrayInit):
                    self.check_array_init(d, scope)
        except Exception as exc:  # noqa: BLE001
            self.sink.at(dl.span, *E901("datalist", error=f"{type(exc).__name__}: {exc}"))

    def check_array_init(self, d: N.ArrayInit, scope: Scope) -> None:
        sym = scope.lookup(d.name)
        if sym is None:
            self.not_found(d.span, d.name, scope)
            return
        t = sym.type
        if not isinstance(t, T.Array):
            if t is not T.UNKNOWN:
                self.sink.at(d.span, *E109(name=d.name))
            return
        if len(d.indices) != len(t.dims):
            self.sink.at(d.span, *E109("dims", name=d.name, have=len(t.dims), given=len(d.indices)))
            return
        for i, (idx, size) in enumerate(zip(d.indices, t.dims)):
            if idx is not None and size and not 1 <= idx <= size:
                self.sink.at(d.span, *E110("named", index=idx, name=d.name, size=size))
        if d.indices and d.indices[-1] is None:
            elem: T.KrlType = T.Array(t.elem, (t.dims[-1],))
        else:
            elem = t.elem
        self.check_value(elem, d.value, scope, d.span)

    def check_routine(self, r: N.Routine, local: Scope, module_path: str) -> None:
        """Check and annotate one routine whose scope `local` holds its parameters and locals."""
        try:
            ctx = _Ctx(r, local)
            self._routine(r, ctx)
        except RecursionError:
            self.sink.at(r.span, *E901("too_deep"))
        except Exception as exc:  # noqa: BLE001
            self.sink.at(r.span, *E901(error=f"{type(exc).__name__}: {exc}"))

    def _routine(self, r: N.Routine, ctx: _Ctx) -> None:
        local = ctx.scope
        declared = {k for k in local.values}
        for d in r.decls:
            if isinstance(d, N.VarDecl) and d.init is not None:   # DECL CONST ... = value
                sym = local.values.get(d.names[0].name.upper())
                self.check_value(sym.type if sym is not None else T.UNKNOWN, d.init, local, d.init.span)
        for p in r.params:
            self.decl.ident(p.name, p.span)
            if p.name.upper() not in declared:
                self.sink.at(p.span, *E101("parameter", name=p.name, routine=r.name))
            else:
                sym = local.values[p.name.upper()]
                sym.kind = "param"
                sym.mode = p.mode
        self.block(r.body, ctx)
        for g, path in ctx.gotos:
            got = ctx.labels.get(g.label.upper())
            if got is None:
                self.sink.at(g.span, *E401(label=g.label, routine=r.name))
                continue
            _label, lpath = got
            if tuple(path[:len(lpath)]) != lpath:
                self.sink.at(g.span, *E402(label=g.label))

    # ---------------------------------------------------------------- statements

    def block(self, stmts: list[N.Stmt], ctx: _Ctx, new_block: bool = False) -> None:
        if new_block:
            ctx.next_block += 1
            ctx.block_path.append(ctx.next_block)
        try:
            for s in stmts:
                self.stmt(s, ctx)
        finally:
            if new_block:
                ctx.block_path.pop()

    def stmt(self, s: N.Stmt, ctx: _Ctx) -> None:
        if self.submit and s.__class__ in MOVES_ROBOT:
            self.no_motion_in_submit(s)
        self.stmt_dispatch[s.__class__](s, ctx)

    def s_Assign(self, s: N.Assign, ctx: _Ctx) -> None:
        self.assign(s.target, s.value, ctx.scope, s.span)

    def s_CallStmt(self, s: N.CallStmt, ctx: _Ctx) -> None:
        self.call(s.call, ctx.scope, statement=True)

    def s_If(self, s: N.If, ctx: _Ctx) -> None:
        self.cond(s.cond, ctx.scope, "IF")
        self.block(s.then, ctx, True)
        if s.orelse is not None:
            self.block(s.orelse, ctx, True)

    def s_Switch(self, s: N.Switch, ctx: _Ctx) -> None:
        self.switch(s, ctx)

    def s_For(self, s: N.For, ctx: _Ctx) -> None:
        self.for_(s, ctx)

    def s_While(self, s: N.While, ctx: _Ctx) -> None:
        self.cond(s.cond, ctx.scope, "WHILE")
        self.loop_body(s.body, ctx)

    def s_Repeat(self, s: N.Repeat, ctx: _Ctx) -> None:
        self.loop_body(s.body, ctx)
        self.cond(s.cond, ctx.scope, "UNTIL")

    def s_Loop(self, s: N.Loop, ctx: _Ctx) -> None:
        self.loop_body(s.body, ctx)

    def s_Exit(self, s: N.Exit, ctx: _Ctx) -> None:
        if ctx.loops == 0:
            self.sink.at(s.span, *E403())

    def s_Goto(self, s: N.Goto, ctx: _Ctx) -> None:
        ctx.gotos.append((s, tuple(ctx.block_path)))

    def s_Label(self, s: N.Label, ctx: _Ctx) -> None:
        self.decl.ident(s.name, s.span)
        key = s.name.upper()
        if key in ctx.labels:
            self.sink.at(s.span, *E405(label=s.name))
        else:
            ctx.labels[key] = (s, tuple(ctx.block_path))

    def s_WaitFor(self, s: N.WaitFor, ctx: _Ctx) -> None:
        self.cond(s.cond, ctx.scope, "WAIT FOR")

    def s_WaitSec(self, s: N.WaitSec, ctx: _Ctx) -> None:
        self.numeric(s.time, ctx.scope, "WAIT SEC")

    def s_Return(self, s: N.Return, ctx: _Ctx) -> None:
        self.return_(s, ctx)

    def s_InterruptDecl(self, s: N.InterruptDecl, ctx: _Ctx) -> None:
        sc = ctx.scope
        self.int_expr(s.prio, sc, "interrupt number")
        if isinstance(s.prio, N.IntLit) and not 1 <= s.prio.value <= 128:
            self.sink.at(s.prio.span, *E408(prio=s.prio.value))
        self.cond(s.when, sc, "WHEN")
        if s.brake is None:
            self.call(s.call, sc, statement=True)
        else:
            self.set_type(s.call, T.VOID)

    def s_InterruptCtl(self, s: N.InterruptCtl, ctx: _Ctx) -> None:
        if s.prio is not None:
            self.int_expr(s.prio, ctx.scope, "interrupt number")

    def s_Trigger(self, s: N.Trigger, ctx: _Ctx) -> None:
        sc = ctx.scope
        self.numeric(s.at, sc, s.kind)
        self.numeric(s.delay, sc, "DELAY")
        if s.prio is not None:
            self.int_expr(s.prio, sc, "PRIO")
        elif isinstance(s.action, N.CallStmt) and s.action.call.name.upper() != "PULSE":
            # PULSE is a statement of its own, not a subprogram call (5.12, 5.18)
            self.sink.at(s.span, *E409())
        self.stmt(s.action, ctx)

    def s_ConditionalStop(self, s: N.ConditionalStop, ctx: _Ctx) -> None:
        self.numeric(s.path, ctx.scope, "PATH")
        self.cond(s.cond, ctx.scope, "STOP WHEN")

    def s_Motion(self, s: N.Motion, ctx: _Ctx) -> None:
        self.motion(s, ctx.scope)

    def s_SplineBlock(self, s: N.SplineBlock, ctx: _Ctx) -> None:
        for w in s.with_:
            self.with_assign(w, ctx.scope)
        for inner in s.body:
            self.stmt(inner, ctx)

    def s_AninOn(self, s: N.AninOn, ctx: _Ctx) -> None:
        self.assign_target(s.target, ctx.scope, s.span)
        self.expr(s.value, ctx.scope)

    def s_AnoutOn(self, s: N.AnoutOn, ctx: _Ctx) -> None:
        sc = ctx.scope
        self.signal_name(s.name, s.span, sc)
        self.numeric(s.value, sc, "ANOUT")
        for e in (s.delay, s.minimum, s.maximum):
            if e is not None:
                self.numeric(e, sc, "ANOUT")

    def s_AninOff(self, s: N.AninOff | N.AnoutOff, ctx: _Ctx) -> None:
        self.signal_name(s.name, s.span, ctx.scope)

    s_AnoutOff = s_AninOff

    def s_KeywordStmt(self, s: N.KeywordStmt, ctx: _Ctx) -> None:
        for a in s.args:
            if isinstance(a, N.Aggregate):
                self.aggregate(a, ctx.scope, T.UNKNOWN)
            else:
                self.expr(a, ctx.scope)

    def s_MoveEmi(self, s: N.MoveEmi, ctx: _Ctx) -> None:
        self.expr(s.target, ctx.scope)
        if s.value is not None:
            self.expr(s.value, ctx.scope)

    def s_DeclStmt(self, s: N.DeclStmt, ctx: _Ctx) -> None:
        self.sink.at(s.span, *E104())

    def s_nothing(self, s: N.Stmt, ctx: _Ctx) -> None:
        """HALT, CONTINUE, ON_ERROR_PROCEED, an unsupported construct: nothing to check."""

    s_Halt = s_Continue = s_OnErrorProceed = s_Unsupported = s_Unparsed = s_Brake = s_Resume = s_nothing

    def no_motion_in_submit(self, s: N.Stmt) -> None:
        """A statement that moves the robot (its facts write ROBOT: krl/semantics/statements.py) in
        a submit program (reference §9, §8.2: the submit interpreter has no motion)."""
        self.sink.at(s.span, *E406(what=STATEMENT_KINDS[s.__class__].facts.name or s.kind))

    def loop_body(self, body: list[N.Stmt], ctx: _Ctx) -> None:
        ctx.loops += 1
        try:
            self.block(body, ctx, True)
        finally:
            ctx.loops -= 1

    def signal_name(self, name: str, span: N.Span, sc: Scope) -> None:
        if sc.lookup(name) is None:
            self.not_found(span, name, sc)

    def switch(self, s: N.Switch, ctx: _Ctx) -> None:
        sc = ctx.scope
        st = self.expr(s.selector, sc)
        if not (st in (T.INT, T.CHAR) or isinstance(st, T.Enum) or st is T.UNKNOWN):
            self.sink.at(s.selector.span, *E207(type=st))
            st = T.UNKNOWN
        for c in s.cases:
            for v in c.values:
                vt = self.expr(v, sc, expected=st)
                if st is T.UNKNOWN or vt is T.UNKNOWN:
                    continue
                if isinstance(st, T.Enum):
                    if not isinstance(vt, (T.EnumLitType, T.Enum)) or isinstance(vt, T.Enum) and vt != st:
                        self.sink.at(v.span, *E207("case", type=vt, selector=st))
                elif not T.assignable(st, vt).ok or isinstance(vt, T.EnumLitType):
                    self.sink.at(v.span, *E207("case", type=vt, selector=st))
            self.block(c.body, ctx, True)
        if s.default is not None:
            self.block(s.default, ctx, True)

    def for_(self, s: N.For, ctx: _Ctx) -> None:
        sc = ctx.scope
        sym = sc.lookup(s.var.name)
        if sym is None:
            self.not_found(s.var.span, s.var.name, sc)
            self.set_type(s.var, T.UNKNOWN)
        else:
            s.var.annotate().symbol = sym
            s.var.ann.type = sym.type
            if sym.type not in (T.INT, T.UNKNOWN):
                self.sink.at(s.var.span, *E208(name=s.var.name, type=sym.type))
            elif sym.kind in ("const", "routine"):
                self.sink.at(s.var.span, *E208("not_variable", name=s.var.name))
        for e in (s.start, s.end, s.step):
            if e is not None:
                self.int_expr(e, sc, "FOR bound", lossy_ok=True)
        if s.step is not None:
            self.for_step(s.step)
        self.loop_body(s.body, ctx)

    def for_step(self, step: N.Expr) -> None:
        """5.4: the increment is an INT constant (literal or CONST), not 0."""
        e, value = step, None
        if isinstance(e, N.Unary) and e.op in ("-", "+") and isinstance(e.operand, N.IntLit):
            value = -e.operand.value if e.op == "-" else e.operand.value
        elif isinstance(e, N.IntLit):
            value = e.value
        elif isinstance(e, N.Name) and isinstance(N.symbol_of(e), Symbol) and N.symbol_of(e).kind == "const":
            return
        if value is None:
            if N.type_of(e) is not T.UNKNOWN:
                self.sink.at(e.span, *E212())
        elif value == 0:
            self.sink.at(e.span, *E212("zero"))

    def return_(self, s: N.Return, ctx: _Ctx) -> None:
        r = ctx.routine
        sc = ctx.scope
        if r is None:
            return
        if r.kind == "DEFFCT":
            if s.value is None:
                self.sink.at(s.span, *E404(routine=r.name))
                return
            sym = sc.lookup_routine(r.name)
            rt = sym.signature.returns if sym is not None and sym.signature else T.UNKNOWN
            self.check_value(rt or T.UNKNOWN, s.value, sc, s.value.span, what="RETURN value")
        elif s.value is not None:
            self.expr(s.value, sc)
            self.sink.at(s.span, *E404("procedure", routine=r.name))

    def motion(self, m: N.Motion, sc: Scope) -> None:
        for e in (m.aux, m.target):
            if e is not None:
                self.motion_target(e, sc, relative=m.kind.endswith("_REL"))
        if m.ca is not None:
            self.numeric(m.ca, sc, "CA")
        for w in m.with_:
            self.with_assign(w, sc)

    def motion_target(self, e: N.Expr, sc: Scope, relative: bool) -> None:
        if isinstance(e, N.Aggregate) and e.type_name is None:
            names = {i.name.upper() for i in e.items}
            cart = sc.lookup_type("E6POS")
            axes = sc.lookup_type("E6AXIS")
            if isinstance(cart, T.Struc) and isinstance(axes, T.Struc):
                if names <= set(cart.fields):
                    target: T.KrlType = cart
                elif names <= set(axes.fields):
                    target = axes
                else:
                    self.sink.at(e.span, *E209("mixed"))
                    target = T.UNKNOWN
                self.check_value(target, e, sc, e.span)
                return
        t = self.expr(e, sc)
        if t is T.UNKNOWN:
            return
        if T.geometric_family(t) is None:
            self.sink.at(e.span, *E209(type=t))

    def with_assign(self, w: N.WithAssign, sc: Scope) -> None:
        self.assign(w.target, w.value, sc, w.span)

    # ---------------------------------------------------------------- assignments

    def assign(self, target: N.Expr, value: N.Expr, sc: Scope, span: N.Span) -> None:
        tt = self.assign_target(target, sc, span)
        self.check_value(tt, value, sc, value.span)

    def assign_target(self, target: N.Expr, sc: Scope, span: N.Span) -> T.KrlType:
        tt = self.expr(target, sc)
        root = N.root_name(target)
        if root is None:
            self.sink.at(target.span, *E503())
            return T.UNKNOWN
        sym = N.symbol_of(root)
        if isinstance(sym, Symbol):
            if sym.kind == "const":
                self.sink.at(target.span, *E502(name=sym.name))
            elif sym.kind == "routine":
                self.sink.at(target.span, *E503("routine", name=sym.name))
            elif sym.access == "RO" and sym.name.upper() in ("$IN", "$ANIN"):
                self.sink.at(target.span, *E501("input", name=sym.name))
            elif sym.access == "RO" and sym.kind == "signal":
                # KUKA's own technology packages write SIGNAL names of inputs (simulated I/O): a warning
                self.sink.at(target.span, *W501(name=sym.name))
            elif sym.access == "RO":
                self.sink.at(target.span, *E501(name=sym.name))
        return tt

    def check_value(self, target: T.KrlType, value: N.Expr, sc: Scope, span: N.Span,
                    what: str = "assignment") -> None:
        """Type `value` against `target` (3.9), aggregates component by component."""
        if isinstance(value, N.Aggregate):
            self.aggregate(value, sc, target)
            return
        vt = self.expr(value, sc, expected=target)
        if vt is T.VOID:
            return
        got = T.assignable(target, vt)
        if not got.ok:
            code = E205 if isinstance(vt, T.EnumLitType) else E201
            if code == E205 and getattr(target, "soft", False):
                code = W205
            self.sink.at(span, *code("assign", what=what, reason=got.reason))
        elif got.lossy:
            code = W210 if isinstance(vt, T.StrType) else W202
            self.sink.at(span, *code(what=what, reason=got.reason))
            value.annotate().extra["conversion"] = f"{vt}->{target}"
        elif vt != target and vt is not T.UNKNOWN and target is not T.UNKNOWN:
            value.annotate().extra["conversion"] = f"{vt}->{target}"

    def aggregate(self, agg: N.Aggregate, sc: Scope, expected: T.KrlType) -> T.KrlType:
        """Check an aggregate against a structure type, component by component (1.5, 3.9)."""
        target = expected
        if agg.type_name is not None:
            named = sc.lookup_type(agg.type_name)
            if named is None:
                self.not_found_type(agg.span, agg.type_name, sc)
                named = T.UNKNOWN
            if expected is not T.UNKNOWN and named is not T.UNKNOWN:
                got = T.assignable(expected, named)
                if not got.ok:
                    self.sink.at(agg.span, *E201(reason=got.reason))
            target = named
        agg.annotate().type = target
        seen: set[str] = set()
        for item in agg.items:
            key = item.name.upper()
            if key in seen:
                self.sink.at(item.span, *E206("twice", name=item.name))
            seen.add(key)
            if isinstance(target, T.Struc) and target.fields:
                ft = target.field_type(item.name)
                if ft is None:
                    self.sink.at(item.span, *(W206 if target.soft else E206)(struc=target.name, name=item.name))
                    self.loose(item.value, sc)
                    continue
                self.check_value(ft, item.value, sc, item.value.span, what=f"component {item.name}")
            elif target is T.UNKNOWN:
                self.loose(item.value, sc)
            else:
                soft = getattr(target, "soft", False)
                self.sink.at(agg.span, *(W201(type=target) if soft else E201("aggregate", type=target)))
                for rest in agg.items:   # still type every component value
                    self.loose(rest.value, sc)
                return target
        return target

    def loose(self, value: N.Expr, sc: Scope) -> None:
        """Type a value without an expected type (after an error), aggregates included."""
        if isinstance(value, N.Aggregate):
            self.aggregate(value, sc, T.UNKNOWN)
        else:
            self.expr(value, sc)

    # ---------------------------------------------------------------- expressions

    def cond(self, e: N.Expr, sc: Scope, what: str) -> None:
        t = self.expr(e, sc, expected=T.BOOL)
        if t not in (T.BOOL, T.UNKNOWN):
            self.sink.at(e.span, *E204(what=what, type=t))

    def numeric(self, e: N.Expr, sc: Scope, what: str) -> None:
        t = self.expr(e, sc)
        if not T.is_numeric(t):
            self.sink.at(e.span, *E203("number", what=what, type=t))

    def int_expr(self, e: N.Expr, sc: Scope, what: str, lossy_ok: bool = False) -> None:
        t = self.expr(e, sc)
        if t in (T.INT, T.UNKNOWN, T.CHAR) or lossy_ok and t == T.REAL:
            return
        self.sink.at(e.span, *E203("integer", what=what, type=t))

    def set_type(self, e: N.Expr, t: T.KrlType) -> T.KrlType:
        (e.ann or e.annotate()).type = t
        return t

    def expr(self, e: N.Expr, sc: Scope, expected: T.KrlType | None = None) -> T.KrlType:
        """Type `e` (annotating it) and report errors; never raises for a valid AST.
        `expected`: the type the value is for (an enum literal or aggregate takes it)."""
        return self.expr_dispatch[e.__class__](e, sc, expected)

    def e_IntLit(self, e: N.IntLit, sc: Scope, expected) -> T.KrlType:
        return self.set_type(e, T.INT)

    def e_RealLit(self, e: N.RealLit, sc: Scope, expected) -> T.KrlType:
        return self.set_type(e, T.REAL)

    def e_BoolLit(self, e: N.BoolLit, sc: Scope, expected) -> T.KrlType:
        return self.set_type(e, T.BOOL)

    def e_StrLit(self, e: N.StrLit, sc: Scope, expected) -> T.KrlType:
        return self.set_type(e, T.StrType(len(e.value)))

    def e_ChannelName(self, e: N.ChannelName, sc: Scope, expected) -> T.KrlType:
        # a channel (COPEN(:SER_3, HANDLE)) is an argument of a channel routine, no typed value
        return T.UNKNOWN

    def e_EnumLit(self, e: N.EnumLit, sc: Scope, expected) -> T.KrlType:
        if isinstance(expected, T.Enum):
            if expected.values and e.name.upper() not in expected.values:
                self.sink.at(e.span, *(W205 if expected.soft else E205)(name=e.name, enum=expected.name))
                return self.set_type(e, T.UNKNOWN)
            return self.set_type(e, expected)
        return self.set_type(e, T.EnumLitType(e.name))

    def e_Name(self, e: N.Name, sc: Scope, expected) -> T.KrlType:
        return self.name(e, sc)

    def e_Index(self, e: N.Index, sc: Scope, expected) -> T.KrlType:
        return self.index(e, sc)

    def e_Field(self, e: N.Field, sc: Scope, expected) -> T.KrlType:
        bt = self.expr(e.base, sc)
        if bt is T.UNKNOWN:
            return self.set_type(e, T.UNKNOWN)
        if isinstance(bt, T.Struc):
            ft = bt.field_type(e.name)
            if ft is None:
                if bt.fields:
                    self.sink.at(e.span, *(W108 if bt.soft else E108)(struc=bt.name, name=e.name))
                return self.set_type(e, T.UNKNOWN)
            return self.set_type(e, ft)
        self.sink.at(e.span, *E108("not_struc", name=e.name, type=bt))
        return self.set_type(e, T.UNKNOWN)

    def e_Call(self, e: N.Call, sc: Scope, expected) -> T.KrlType:
        return self.call(e, sc, statement=False)

    def e_Aggregate(self, e: N.Aggregate, sc: Scope, expected) -> T.KrlType:
        return self.set_type(e, self.aggregate(e, sc, expected or T.UNKNOWN))

    def e_Unary(self, e: N.Unary, sc: Scope, expected) -> T.KrlType:
        return self.set_type(e, self.unary(e, sc))

    def e_Binary(self, e: N.Binary, sc: Scope, expected) -> T.KrlType:
        return self.set_type(e, self.binary(e, sc))

    def name(self, e: N.Name, sc: Scope) -> T.KrlType:
        sym = sc.lookup(e.name)
        if sym is None:
            rsym = sc.lookup_routine(e.name)
            if rsym is not None:
                # a parameterless function called without parentheses
                e.annotate().symbol = rsym
                return self.set_type(e, rsym.type if rsym.type is not T.VOID else T.UNKNOWN)
            self.not_found(e.span, e.name, sc)
            return self.set_type(e, T.UNKNOWN)
        e.annotate().symbol = sym
        return self.set_type(e, sym.type)

    def index(self, e: N.Index, sc: Scope) -> T.KrlType:
        bt = self.expr(e.base, sc)
        for i in e.indices:
            if i is None:
                continue
            it = self.expr(i, sc)
            if it is T.UNKNOWN or it in (T.INT, T.CHAR):
                continue
            if it == T.REAL:
                continue  # converted like an assignment to INT
            self.sink.at(i.span, *E211(type=it))
        if bt is T.UNKNOWN:
            return self.set_type(e, T.UNKNOWN)
        if not isinstance(bt, T.Array):
            self.sink.at(e.span, *E109("not_array_type", name=_show(e.base), type=bt))
            return self.set_type(e, T.UNKNOWN)
        n = len(bt.dims)
        if all(i is None for i in e.indices) and (len(e.indices) == n or e.indices == [None]):
            e.annotate().extra["whole_array"] = True
            return self.set_type(e, bt)
        if len(e.indices) != n:
            self.sink.at(e.span, *E109("dims", name=_show(e.base), have=n, given=len(e.indices)))
            return self.set_type(e, T.UNKNOWN)
        for i, size in zip(e.indices, bt.dims):
            if isinstance(i, N.IntLit) and size and not 1 <= i.value <= size:
                self.sink.at(i.span, *E110(index=i.value, size=size))
        if e.indices[-1] is None and all(i is not None for i in e.indices[:-1]):
            e.annotate().extra["row"] = True
            return self.set_type(e, T.Array(bt.elem, (bt.dims[-1],)))
        if any(i is None for i in e.indices):
            self.sink.at(e.span, *E109("last_only"))
            return self.set_type(e, T.UNKNOWN)
        return self.set_type(e, bt.elem)

    def unary(self, e: N.Unary, sc: Scope) -> T.KrlType:
        t = self.expr(e.operand, sc)
        if t is T.UNKNOWN:
            return T.UNKNOWN
        if e.op in ("-", "+"):
            if t in (T.INT, T.REAL):
                return t
            if t == T.CHAR:
                return T.INT
        elif e.op == "NOT":
            if t == T.BOOL:
                return T.BOOL
        elif e.op == "B_NOT":
            if t in (T.INT, T.CHAR):
                return T.INT
        self.sink.at(e.span, *E203("unary", op=e.op, type=t))
        return T.UNKNOWN

    def binary(self, e: N.Binary, sc: Scope) -> T.KrlType:
        """Type a binary operator and the left-nested chain below it (``1 + 1 + ... + 1``, up
        to krl.limits.MAX_EXPRESSION_TERMS terms) in a loop, innermost first: left before
        right, as the operators associate; only brackets and prefix operators recurse."""
        leftmost, chain = N.left_chain(e)
        lt = self.geo_operand(leftmost, sc) if chain[0].op == ":" else self.expr(leftmost, sc)
        for b in chain:
            lt = self.set_type(b, self._binary(b, lt, sc))
        return lt

    def _binary(self, e: N.Binary, lt: T.KrlType, sc: Scope) -> T.KrlType:
        """The type of `e` whose left operand has been typed `lt`."""
        op = e.op
        if op == ":":
            rt = self.geo_operand(e.right, sc)
            for side, t in ((e.left, lt), (e.right, rt)):
                if t is not T.UNKNOWN and T.geometric_family(t) != "cartesian":
                    self.sink.at(side.span, *E203("geometric", type=t))
                    return T.UNKNOWN
            return rt
        if op in EQUALITY:
            rt = self.expr(e.right, sc, expected=lt if isinstance(lt, T.Enum) else None)
            if isinstance(rt, T.Enum) and isinstance(e.left, N.EnumLit):
                lt = self.expr(e.left, sc, expected=rt)
        else:
            rt = self.expr(e.right, sc)
        if lt is T.UNKNOWN or rt is T.UNKNOWN:
            return T.BOOL if op in EQUALITY | ORDER else T.UNKNOWN
        num = (T.INT, T.REAL, T.CHAR)
        if op in ARITH:
            if lt in num and rt in num:
                return T.REAL if T.REAL in (lt, rt) else T.INT
        elif op in LOGIC:
            if lt == T.BOOL and rt == T.BOOL:
                return T.BOOL
        elif op in BITS:
            if lt in (T.INT, T.CHAR) and rt in (T.INT, T.CHAR):
                return T.INT
        elif op in EQUALITY:
            if self.comparable(lt, rt):
                return T.BOOL
        elif op in ORDER:
            if lt in num and rt in num or _char_like(lt) and _char_like(rt):
                return T.BOOL
        self.sink.at(e.span, *E203(op=op, left=lt, right=rt))
        return T.BOOL if op in EQUALITY | ORDER else T.UNKNOWN

    def comparable(self, a: T.KrlType, b: T.KrlType) -> bool:
        num = (T.INT, T.REAL, T.CHAR)
        if a in num and b in num:
            return True
        if _char_like(a) and _char_like(b):
            return True
        if a == T.BOOL and b == T.BOOL:
            return True
        if isinstance(a, T.Enum) and isinstance(b, T.Enum):
            return a == b
        if isinstance(a, (T.Enum, T.EnumLitType)) and isinstance(b, (T.Enum, T.EnumLitType)):
            return True
        return False

    def geo_operand(self, e: N.Expr, sc: Scope) -> T.KrlType:
        if isinstance(e, N.Aggregate) and e.type_name is None:
            frame = sc.lookup_type("E6POS")
            return self.aggregate(e, sc, frame if frame is not None else T.UNKNOWN)
        return self.expr(e, sc)

    # ---------------------------------------------------------------- calls

    def call(self, c: N.Call, sc: Scope, statement: bool) -> T.KrlType:
        """Check a call; returns (and records in c.ann.type) its result type, VOID for a
        procedure, UNKNOWN for an unknown routine."""
        return self.set_type(c, self._call(c, sc, statement))

    def _call(self, c: N.Call, sc: Scope, statement: bool) -> T.KrlType:
        sym = sc.lookup_routine(c.name)
        if sym is None:
            for a in c.args:
                if a is not None:
                    self.expr(a, sc)
            self.unknown("routine", c.name, c.span)
            return T.UNKNOWN
        c.annotate().symbol = sym
        if isinstance(sym.decl, N.ExtDecl):
            self._undefined_ext(c, sym, sc)
        sig = sym.signature
        if sig is None:
            return T.UNKNOWN
        if not statement and not sig.is_function:
            self.sink.at(c.span, *E304(name=c.name))
        elif (statement and sig.is_function and sig.returns is not T.UNKNOWN
              and isinstance(sym.decl, (N.Routine, N.ExtDecl))):
            # 2.4: a function is called only inside an expression. Only for functions the
            # program declares: KUKA documents built-ins such as CAST_TO as statements, which
            # the tables give a BOOL value
            self.sink.at(c.span, *E304("statement", name=c.name))
        if len(c.args) > len(sig.params) and not sig.varargs:
            self.sink.at(c.span, *E301(name=c.name, params=len(sig.params), given=len(c.args)))
        for i, a in enumerate(c.args):
            if a is None:
                continue
            p = sig.params[i] if i < len(sig.params) else None
            if p is None:
                self.expr(a, sc)
                continue
            if p.mode == "OUT":
                if not N.is_lvalue(a):
                    self.expr(a, sc, expected=p.type)
                    self.sink.at(a.span, *E302(n=i + 1, name=c.name))
                    continue
            if isinstance(a, N.Aggregate):
                self.aggregate(a, sc, p.type)
                continue
            at = self.expr(a, sc, expected=p.type)
            got = T.param_compatible(p.type, at, p.mode or "IN")
            if not got.ok:
                self.sink.at(a.span, *E303(n=i + 1, name=c.name, reason=got.reason))
        return sig.returns if sig.returns is not None else T.VOID

    # ---------------------------------------------------------------- helpers

    def unknown(self, kind: str, name: str, span: N.Span) -> None:
        """Record an unresolved name (krl/semantics/outside.py decides error or warning)."""
        self.decl.unknown(kind, name, span, kuka=self.system_file)

    def _undefined_ext(self, c: N.Call, sym: Symbol, sc: Scope) -> None:
        """Record a call of a routine that an EXT/EXTFCT declaration names and no module of the
        program defines (the link binds a call to the module main or GLOBAL routine of that name,
        reference 2.6; krl/semantics/resolve.py): the declaration resolves the name, its body is
        installed software's (krl/semantics/outside.py ``ext_evidence``). A routine of the
        platform tables behind an EXT is the controller's own: not recorded."""
        if self.decl.unresolved is None:
            return
        key = c.name.upper()
        s = sc
        while s is not None:
            if s.kind in ("global", "basis", "system"):
                got = s.routines.get(key)
                if got is not None and not isinstance(got.decl, N.ExtDecl):
                    return          # a module main or GLOBAL routine, or a built-in
            s = s.parent
        span = sym.decl.span
        place = f"{_file_name(span.file)}:{span.line}" if span is not None else "an EXT declaration"
        evidence = self.decl.evidence(c.span.file, c.span.line, "routine", self.system_file) or ext_evidence(place)
        self.decl.unknown("routine", c.name, c.span, evidence, declared=place)

    def not_found(self, span: N.Span, name: str, sc: Scope) -> None:
        self.unknown("sysvar" if name.startswith("$") else "name", name, span)

    def not_found_type(self, span: N.Span, name: str, sc: Scope) -> None:
        self.unknown("type", name, span)


def _file_name(path: str) -> str:
    return path.replace("\\", "/").rsplit("/", 1)[-1]


def _char_like(t: T.KrlType) -> bool:
    return t == T.CHAR or isinstance(t, T.StrType) and t.length == 1


def _show(e: N.Expr) -> str:
    try:
        return printed(e)
    except Exception:  # noqa: BLE001
        return "?"
