"""Routine calls of a run (reference §2.3, §2.4, §5.17): :class:`Calls`, the call protocol both
interpreters use (``Runtime.calls``).

It holds now: the frame plans of the routines called so far (:class:`FramePlan`, by
``id(routine)``), the checked return types of the functions returned from (by ``id(routine)``),
and the run's program, data memory, module table and system-software stand-ins it calls into.
A frame is made by :meth:`Calls.enter_routine`; :meth:`Calls.run_routine` runs one call (the
interpreter's body), converts a function's value and leaves the routine; the entry routine of a
task is :meth:`Calls.main_routine`; a call whose callee is not a routine of the program is
:meth:`Calls.call_native`. Errors raised: KrlRuntimeError (reference §2.3: stack overflow past
krl.limits.MAX_CALL_DEPTH nested calls, data memory exhausted, a routine that cannot be
entered), ResourceError (a type nested too deep).
"""

from __future__ import annotations

from pathlib import Path

from krl.ast import nodes as N
from krl.limits import MAX_CALL_DEPTH
from krl.semantics import types as T
from krl.semantics.resolve import ROUTINE, Callee

from .convert import INT_MAX, INT_MIN, assign_into, convert_scalar
from .errors import KrlRuntimeError, ResumeSignal, not_entered
from .memory import Frame, Slot
from .natives import ValueRef
from .values import LEAVES, UNSET, Arr, Struct, copy_value, make_value, maker, value_size


def _scalar(t) -> bool:
    """A type of single values: INT, REAL, BOOL, CHAR or an ENUM (not an array, a STRUC or
    an unresolved type)."""
    return isinstance(t, (T.Simple, T.Enum)) and t is not T.UNKNOWN


_INT, _REAL, _BOOL = T.INT, T.REAL, T.BOOL


def typed_copy(v: Struct, t) -> Struct | None:
    """The value :func:`~.convert.convert_scalar` makes of structure `v` for its own type `t` (a
    fresh value of `t` with `v` assigned into it), made as one copy of `v`'s components when each
    is already what the assignment would store: every component of `t` in its order, each unset,
    a REAL's float, an INT's int in range or a BOOL's bool; else None (the general conversion).
    A function's FRAME value returns so (getCircFrame of the CAM-like program, per point)."""
    fields = t.fields
    f = v.f
    if len(f) != len(fields):
        return None
    for (k, x), (fk, (_, ft)) in zip(f.items(), fields.items()):
        c = x.__class__
        if k != fk or not (x is UNSET or (c is float and ft is _REAL) or (c is bool and ft is _BOOL)
                           or (c is int and ft is _INT and INT_MIN <= x <= INT_MAX)):
            return None
    return Struct(t, f.copy())


class FramePlan:
    """A routine's Layout made ready for its calls (:meth:`Calls._frame_plan`, once per
    routine and run): ``layout``; ``n`` slots; ``made`` (slot -> (type, name) of the Slot
    ``Frame.var`` makes when first used, for a variable the frame holds itself: a plain
    local, a scalar or structure :IN copy; else None); ``fresh`` ((slot, function making the
    fresh value) for each local STRUC or array); ``decls`` ((slot, name, type, VarDecl) for
    each local with an initial value, (slot, name, None, SignalDecl) for each SIGNAL);
    ``params`` ((slot, name, mode, type or None, scalar?, data elements) for each parameter;
    *scalar*: a type whose fresh value is UNSET and whose values are converted by
    convert_scalar: INT, REAL, BOOL, CHAR, ENUM); ``elements``, the data elements of the
    locals; ``sizes`` ((data elements, VarName, VarDecl) for each local)."""

    __slots__ = ("layout", "n", "made", "fresh", "decls", "params", "elements", "sizes")


class Calls:
    """The routine calls of one run (module docstring): built by the Runtime once its program,
    system-software stand-ins, controller and run mode exist."""

    __slots__ = ("program", "memory", "modules", "kss", "clock", "controller", "tracing", "stepping",
                 "run_native", "_plans", "_return_types")

    def __init__(self, program, memory, modules, kss, clock, controller, tracing, stepping, run_native) -> None:
        """For the run of `program` (program.Program), `memory` (memory.DataMemory), `modules`
        (its modules by Callee.owner), `kss` (kss.SystemSoftware: the stand-ins), `clock`
        (scheduler.py RunClock: the running task), `controller` (its time, for the trace),
        `tracing` (tracing.py: the ``call``/``return`` events) and `stepping` (stepping.py: the
        debugger's error hook); `run_native(fn, args)` runs a native implementation on the run
        (core.py Runtime.run_native: natives take the runtime)."""
        self.program = program
        self.memory = memory
        self.modules = modules              # by Callee.owner
        self.kss = kss
        self.clock = clock
        self.controller = controller
        self.tracing = tracing
        self.stepping = stepping
        self.run_native = run_native
        self._plans: dict = {}              # id(routine) -> FramePlan
        self._return_types: dict = {}       # id(routine) -> the checker's return type, checked once

    def entered(self):
        """The routines the run has entered so far, as ids (``id(routine)``; interp/runtime/idle.py
        ``IdleWatch._constant``): one is added before the first statement of its first call."""
        return self._plans.keys()

    def main_routine(self, module_name: str | None = None):
        """(module, main routine) a robot or submit task starts with (the program's module, or
        the module of a submit program's file ``module_name``); raises KrlRuntimeError when the
        module's files have syntax errors, when the checker rejected them (unless the run does
        not check: ``krl run --no-check``) or when there is no main routine."""
        prog = self.program
        if module_name is None:
            m = prog.module_of(prog.main_path)
            name = prog.main_path.stem
        else:
            m = prog.module_of(module_name) or prog.module(str(module_name))
            name = module_name
        if m is not None and m.syntax_errors:
            first = m.syntax_errors[0]
            raise KrlRuntimeError("the program has syntax errors and cannot start: " + first, None,
                                  getattr(first, "file", None) or m.path, getattr(first, "line", None) or 0)
        errors = prog.errors_of(m)
        if errors:
            d = errors[0]
            more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
            raise KrlRuntimeError(f"the program has errors and cannot start: {d.path}:{d.line}:{d.column}: "
                                  f"error[{d.code}]: {d.message}{more}", None, d.path, d.line)
        if prog.fatal is not None:
            raise prog.fatal
        if m is None or m.main is None:
            raise KrlRuntimeError(f"no main routine in {Path(str(name)).stem}")
        return m, m.main

    def callee(self, c: Callee):
        """(module, Routine) of a call whose callee is a routine of the program, else None."""
        if c.kind != ROUTINE:
            return None
        return self.modules[c.owner], c.routine

    def call_native(self, c: Callee, args: list, is_function: bool):
        """A call whose callee is not a routine of the program, with reference ``args``
        (interp/runtime/natives/args.py), for both interpreters: the implementation the
        resolver linked (``c.native``, interp/runtime/natives) runs; with none (a routine of
        the tables the simulator does not implement, or one nothing declares) KUKA's system
        software stands in, in a backup (interp/runtime/kss.py: counted, one note), and
        anything else is the run-time error "routine NAME not found". ``is_function``: the
        call's value is used. Returns the call's value (None for a procedure)."""
        fn = c.native
        if fn is None:
            return self.kss.call(c.name, is_function)
        return self.run_native(fn, args)

    def enter_routine(self, module, routine: N.Routine, args: list, caller: Frame | None) -> Frame:
        """Create the frame of a call (§2.3): :IN parameters get converted copies, :OUT
        (and unmarked) parameters are bound to the caller's reference; omitted arguments
        stay declared-but-unset; locals are declared unset. The routine's slots are its
        Layout (krl/semantics/resolve.py), planned once (:class:`FramePlan`); the Slot of a
        variable the frame holds itself is made when first used (``Frame.var``)."""
        if routine.broken:
            raise KrlRuntimeError(not_entered(routine), None, routine.span.file, routine.broken)
        task = self.clock.current_task
        if self.kss.standard and id(routine) in self.kss.standard and (caller is None or caller.module is not module):
            self.kss.standard_call(routine)     # a call from outside the standard program
        if caller is not None and caller.depth >= MAX_CALL_DEPTH:
            raise KrlRuntimeError(f"stack overflow: more than {MAX_CALL_DEPTH} nested calls")
        plan = self._plans.get(id(routine))
        if plan is None:
            plan = self._plans[id(routine)] = self._frame_plan(module, routine)
        mem = self.memory
        n = plan.elements
        if mem.used + n > mem.limit:
            self._locals_do_not_fit(plan.sizes)
        mem.used += n
        k = plan.n
        store = [UNSET] * k
        frame = Frame(routine, module, caller, task, plan.layout, store, [None] * k, plan.made)
        frame.data = n
        try:
            for k, make in plan.fresh:
                store[k] = make()
            if plan.decls:
                self._declare(frame, plan.decls)
            nargs = len(args)
            for k, name, mode, t, scalar, size in plan.params:
                a = args[k] if k < nargs else None
                if a is None:
                    self._omitted(frame, k, name, t, size)
                elif mode == "IN" or a.__class__ is ValueRef:
                    c = a.__class__
                    v = a.c[a.k] if c is Slot else a.v if c is ValueRef else a.peek()   # (Ref.peek)
                    if scalar:          # (the scalar case of _param_copy and _slot_type)
                        if v is not UNSET:
                            c = v.__class__
                            store[k] = v if (c is float and t is _REAL) or (
                                c is int and t is _INT and INT_MIN <= v <= INT_MAX) else convert_scalar(v, t)
                    elif v.__class__ is Struct and v.type is t:
                        # a structure of the parameter's own type: its copy (the same components,
                        # already of their types: what make_value + assign_into give), its size
                        if mem.used + size > mem.limit:
                            mem.take(size, name, what="a copy of :IN parameter")
                        mem.used += size
                        frame.data += size
                        f = v.f
                        store[k] = Struct(t, f.copy()) if LEAVES.issuperset(map(type, f.values())) \
                            else copy_value(v)
                    else:
                        self._in_copy(frame, k, name, t, size, v)
                else:
                    frame.vars[k] = a
        except BaseException:
            mem.give(frame.data)
            raise
        trace = self.tracing.writer
        if trace is not None:
            trace.write("call", self.controller.time, name=routine.name,
                           line=caller.line if caller is not None else None)
        return frame

    def _locals_do_not_fit(self, local_sizes) -> None:
        """Raise "data memory exhausted" at the first local DECL that does not fit."""
        mem = self.memory
        used = mem.used
        try:
            for n, vn, d in local_sizes:
                self.program.take_memory_n(n, vn, d)
        finally:
            mem.used = used

    def _declare(self, frame: Frame, decls) -> None:
        """The locals of a new frame that are not plain variables: a DECL with an initial
        value (DECL CONST INT OFFS = 10, KSS 8) and a SIGNAL of the routine."""
        store = frame.store
        fvars = frame.vars
        for k, name, t, d in decls:
            if t is not None:
                ref = fvars[k] = Slot(store, k, t, name)
                v = self.program.literal(d.init, t)
                cur = store[k]
                if isinstance(cur, (Struct, Arr)):
                    assign_into(cur, v)
                else:
                    store[k] = convert_scalar(v, t)
                ref.readonly = d.is_const
            else:
                fvars[k] = self.program.signal_ref(d)

    def _omitted(self, frame: Frame, k: int, name: str, t, size: int) -> None:
        """Parameter ``k`` of a new frame whose argument is omitted: declared, unset."""
        store = frame.store
        if isinstance(t, T.Array) and t.elem == T.CHAR and t.dims == (0,):
            # an omitted string parameter: declared, no characters (KUKA's MsgLib calls
            # STRLEN on it without ON_ERROR_PROCEED); VARSTATE says #DECLARED
            store[k] = Arr(t, (0,), [])
            frame.vars[k] = Slot(store, k, t, name)
        elif t is None or (isinstance(t, T.Array) and 0 in t.dims):
            store[k] = UNSET
            frame.vars[k] = Slot(store, k, None, name)
        else:
            frame.data += self.memory.take(size, name, what="parameter")
            store[k] = make_value(t)
            frame.vars[k] = Slot(store, k, t, name)

    def _in_copy(self, frame: Frame, k: int, name: str, t, size: int, v) -> None:
        """An :IN parameter ``k`` of a new frame (or a value given for a reference
        parameter) that is not a scalar nor a structure of its own type: a converted copy of
        ``v``, with its data memory."""
        frame.data += self.memory.take(value_size(v) if isinstance(v, (Struct, Arr)) else size,
                                       name, what="a copy of :IN parameter")
        v = frame.store[k] = self._param_copy(v, t, name)
        frame.vars[k] = Slot(frame.store, k, self._slot_type(t, v), name)

    def _frame_plan(self, module, routine: N.Routine) -> FramePlan:
        """The routine's Layout made ready for :meth:`enter_routine` (:class:`FramePlan`).
        Types are the checker's; raises KrlRuntimeError for a type nothing declares (outside
        a backup), ResourceError for a type that nests too deep (values.data_size)."""
        layout = routine.ann.layout
        prog = self.program
        plan = FramePlan()
        plan.layout = layout
        plan.n = len(layout.slots)
        made = plan.made = [None] * plan.n
        fresh, decls, params, sizes = [], [], [], []
        for k, s in enumerate(layout.slots):
            if k < layout.nparams:
                if s.var is not None:            # the parameter's declaration (a VarDecl)
                    t = prog.declared_type(s.type, s.decl.type)
                    n = prog.data_elements(t, s.var, s.decl)
                else:                            # no declaration (E101): untyped
                    t, n = None, 1
                scalar = _scalar(t)
                params.append((k, s.name, s.mode, t, scalar, n))
                if scalar or isinstance(t, T.Struc):
                    made[k] = (t, s.name)        # the Slot of its copy, made when first used
            elif isinstance(s.decl, N.VarDecl):
                t = prog.declared_type(s.type, s.decl.type)
                n = prog.data_elements(t, s.var, s.decl)
                sizes.append((n, s.var, s.decl))
                if isinstance(t, (T.Struc, T.Array)):
                    fresh.append((k, maker(t)))
                if s.decl.init is not None:
                    decls.append((k, s.name, t, s.decl))
                else:
                    made[k] = (t, s.name)
            else:                                # a SIGNAL of the routine
                decls.append((k, s.name, None, s.decl))
        plan.fresh, plan.decls, plan.params, plan.sizes = tuple(fresh), tuple(decls), tuple(params), sizes
        plan.elements = sum(n for n, _, _ in sizes)
        return plan

    @staticmethod
    def _slot_type(t, v):
        if isinstance(t, T.Array) and 0 in t.dims and isinstance(v, Arr):
            return v.type
        return t

    def _param_copy(self, v, t, name: str):
        if v is UNSET:
            return make_value(t) if t is not None and not (isinstance(t, T.Array) and 0 in t.dims) else UNSET
        if t is None:
            return copy_value(v)
        if isinstance(t, T.Array):
            if 0 in t.dims:
                if isinstance(v, str):
                    arr = make_value(T.Array(T.CHAR, (max(len(v), 1),)))
                    assign_into(arr, v)
                    return arr
                return copy_value(v)
            dest = make_value(t)
            assign_into(dest, v)
            return dest
        if isinstance(t, T.Struc):
            dest = make_value(t)
            assign_into(dest, v)
            return dest
        return convert_scalar(v, t)

    def run_routine(self, target, args: list, caller: Frame | None, body, catch_resume: bool = True):
        """The call protocol of both interpreters (§2.3, §5.17): :meth:`enter_routine`,
        the task's innermost frame (VARSTATE), ``body(frame)`` — the interpreter runs the
        routine and returns the value of its RETURN (None for a DEF) —, the value converted
        to a function's return type (:meth:`return_value`), RESUME caught at the caller
        that declared the interrupt (unless ``catch_resume`` is False: an interrupt
        handler's own call), and leaving the routine: its data memory given back, its
        interrupts removed, a ``return`` event written unless it is abandoned by an error or
        RESUME (no event then). ``target``: (module, Routine)."""
        module, routine = target
        frame = self.enter_routine(module, routine, args, caller)
        task = self.clock.current_task
        prev = task.frame
        task.frame = frame
        returned = False
        try:
            value = body(frame)
            if routine.kind == "DEFFCT":       # (Routine.is_function)
                t = self._return_types.get(id(routine))
                c = value.__class__
                if not ((c is float and t is _REAL) or (c is int and t is _INT and INT_MIN <= value <= INT_MAX)):
                    value = self.return_value(routine, value, module)
            returned = True
            return value
        except ResumeSignal as r:
            if catch_resume and r.frame is caller and caller is not None:
                return None
            raise
        except KrlRuntimeError as e:
            hook = self.stepping.error_hook
            if hook is not None and not e.debug_seen:
                e.debug_seen = True     # the debugger stops once, in the innermost frame
                hook(task, frame, e)
            raise
        finally:
            task.frame = prev
            # leave_routine, inlined: once per call
            self.memory.used -= frame.data      # DataMemory.give
            frame.data = 0
            if frame.interrupts:
                self.clock.current_task.irqs.remove_frame(frame)
            if returned:
                trace = self.tracing.writer
                if trace is not None:
                    trace.write("return", self.controller.time, name=frame.name)

    def return_value(self, routine: N.Routine, value, module):
        """``RETURN expr`` of a function: converted to the return type (§2.4; the checker's,
        ``Layout.returns``)."""
        if routine.return_type is None:
            return value
        t = self._return_types.get(id(routine))
        if t is None:
            t = self._return_types[id(routine)] = self.program.declared_type(routine.ann.layout.returns,
                                                                              routine.return_type)
        if isinstance(t, T.Array) and isinstance(value, str):
            arr = make_value(t)
            assign_into(arr, value)
            return arr
        if value.__class__ is Struct and value.type is t:
            got = typed_copy(value, t)
            if got is not None:
                return got
        return convert_scalar(value, t)
