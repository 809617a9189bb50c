"""What a name denotes while a program runs: :class:`Names` (``Runtime.names``), for both
interpreters (docs/architecture.md, "One program model").

It holds now: the run's program (its data lists' slots and the system-variable slots,
``Program.sysrefs``), its module table, its system variables (interp/runtime/sysvars.py) and the
stand-ins for KUKA's software (interp/runtime/kss.py). A name the resolver placed
(krl/semantics/resolve.py ``Storage``) becomes a reference (interp/runtime/memory.py ``Ref``) by
:meth:`Names.storage_ref`; one nothing declares by :meth:`Names.lookup`, VARSTATE's text by
:meth:`Names.ref_from_text`; the references of an element, a component, an assignment and an
aggregate's value (reference §5.1, §3.9) are :meth:`index`, :meth:`field`, :meth:`assign`,
:meth:`aggregate`. Errors raised: KrlRuntimeError ("unknown name", an index out of range, ...).
"""

from __future__ import annotations

from krl.ast import nodes as N
from krl.semantics import expression as X
from krl.semantics import types as T
from krl.semantics.resolve import Storage

from .errors import KrlRuntimeError
from .memory import Frame, Ref, field_ref, index_ref
from .natives import RSI_CONSTANTS, ValueRef
from .values import Struct


class Names:
    """The run-time names of one run (module docstring), or of a program model's load
    (interp/runtime/model.py): built once the `program`, its system variables (`sysvars`) and
    the system-software stand-ins (`kss`) exist; `clock` (scheduler.RunClock, None while loading
    and for a tool's copy) says whose running task VARSTATE's text is read in
    (:meth:`ref_from_text`)."""

    __slots__ = ("clock", "program", "modules", "sysvars", "kss")

    def __init__(self, program, sysvars, kss, clock=None) -> None:
        self.clock = clock
        self.program = program
        self.modules = program.modules      # by Storage.owner
        self.sysvars = sysvars
        self.kss = kss

    def sysref(self, st: Storage) -> Ref:
        """The reference of a system variable the tables declare (storage class SYSTEM; its
        storage is allocated on first use and kept). A slot past the program's list is a name the
        resolver placed while the program runs (VARSTATE's text, ``ref_from_text``)."""
        refs = self.program.sysrefs
        if st.slot >= len(refs):
            refs.extend([None] * (st.slot + 1 - len(refs)))
        ref = refs[st.slot]
        if ref is None:
            ref = self.sysvars.lookup(st.name)
            if ref is None:
                ref = self.lookup(st.name)
            refs[st.slot] = ref
        return ref

    def storage_ref(self, st: Storage, frame: Frame | None) -> Ref:
        """The reference a resolved name denotes (krl/semantics/resolve.py): a frame slot, a
        data-list slot, a system variable, or the fallback for what nothing declares."""
        k = st.kind
        if k == 0:                   # LOCAL
            return frame.vars[st.slot] or frame.var(st.slot)
        if k <= 2:                   # MODULE, GLOBAL
            return self.modules[st.owner].refs[st.slot] or self.program.data_ref(st)
        if k == 3:                   # SYSTEM
            refs = self.program.sysrefs
            return (refs[st.slot] if st.slot < len(refs) else None) or self.sysref(st)
        return self.lookup(st.name)

    def lookup(self, name: str) -> Ref:
        """The one run-time name lookup, for a name nothing declares (storage class
        UNRESOLVED; docs/architecture.md, "One program model"): a ``$`` name is a system
        variable the simulator knows, or one that a system data list or KSS's system files
        declare (``SysVars.lookup``); in a backup, a variable of KUKA's software the backup
        lacks stands in (interp/runtime/kss.py: the names the checker classifies outside the
        program, one note each); any other name is the run-time error "unknown name", as on
        the controller."""
        key = name.upper()
        if key[:1] == "$":
            r = self.sysvars.lookup(key)
            if r is not None:
                return r
        elif key in RSI_CONSTANTS:      # RSI's constants (RSIOK, ...): the option declares them
            return ValueRef(RSI_CONSTANTS[key], key)
        r = self.kss.name_ref(name)     # a variable of KUKA's software (interp/runtime/kss.py)
        if r is not None:
            return r
        raise KrlRuntimeError(f"unknown name {name}", name=name)

    def index(self, base: Ref, idx: list, name: str) -> Ref:
        return index_ref(base, idx, name)

    def field(self, base: Ref, comp: str, name: str, key: str | None = None) -> Ref:
        """``base.comp`` (memory.field_ref: `key`, the component's key, the resolver's)."""
        return field_ref(base, comp, name, key)

    def assign(self, ref: Ref, value) -> None:
        """``target = value`` (§5.1, conversions §3.9)."""
        ref.set(value)

    def read(self, ref: Ref):
        return ref.get()

    @staticmethod
    def aggregate(struc, items: list) -> Struct:
        """Value of ``{[TYPE:] NAME value, ...}``: a partial Struct; ``struc``: the resolved
        STRUC of the TYPE prefix (the resolver's, ``Aggregate.ann.struc``), else None."""
        return Struct(struc if isinstance(struc, T.Struc) else None, dict(items))

    def ref_from_text(self, text: str):
        """The reference named by a string such as ``"P[2].X"`` (VARSTATE), or None. The text
        is read by the front end's expression API (krl/semantics/expression.py): a name with
        constant indices and components, placed by the resolver's rules in the scopes the
        front end built for the running routine (``Layout.scope``, the checker's). The text
        is a run-time value, so this is the one name lookup that happens while the program
        runs, besides the ``$``-name fallback."""
        task = self.clock.current_task if self.clock is not None else None
        frame = getattr(task, "frame", None)
        if frame is None or frame.layout is None:
            return None
        try:
            expr = X.parse(text)
        except X.ExpressionError:
            return None
        chain = []
        e = expr
        while isinstance(e, (N.Index, N.Field)):
            chain.append(e)
            e = e.base
        if not isinstance(e, N.Name):
            return None
        layout = frame.layout
        resolver = self.program.ws.resolver
        sym = layout.scope.lookup(e.name) if layout.scope is not None else None
        try:
            ref = self.storage_ref(resolver.storage(e.name, sym, resolver.locals_of(layout), layout.owner), frame)
        except KrlRuntimeError:
            return None
        for part in reversed(chain):
            if isinstance(part, N.Field):
                ref = field_ref(ref, part.name, e.name)
                continue
            idx = []
            for i in part.indices:
                if i is None or isinstance(i, N.IntLit):
                    idx.append(None if i is None else i.value)
                elif isinstance(i, N.Unary) and i.op == "-" and isinstance(i.operand, N.IntLit):
                    idx.append(-i.operand.value)
                else:
                    return None     # an index that is not an INT literal
            ref = index_ref(ref, idx, e.name)
        return ref
