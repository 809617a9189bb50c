"""The tree interpreter (paper §VI): a visitor over the AST.

It decides only *how to step*: statement by statement, expressions recursively. Every
semantic decision (values, conversions, operators, memory, calls, built-ins, system
variables, advance run, motion, interrupts, triggers, time) is a call into
:class:`interp.runtime.core.Runtime`. GOTO, EXIT and RETURN unwind with Python exceptions
(:mod:`interp.runtime.errors`); a block that holds the GOTO's label catches it and
continues there.

Meaning comes from the front end's typed facts (krl/semantics/resolve.py), never from a
name's spelling: each Name carries its place (a frame slot, a data-list slot, a system
variable), each Call its Callee (a routine, a built-in, a stub), each Field and aggregate item
its structure Component (the key of the component in the structure's values), a GOTO its
target Label, an assignment whether it sets a cyclic flag, an analog statement its channel, an
interrupt declaration its BRAKE, each statement its StmtInfo (advance-run stops). A name's
spelling is used only in messages. Dispatch is the one
node-dispatch helper (krl/ast/visit.py): one method per statement (``s_Kind``) and expression
kind (``e_Kind``).
"""

from __future__ import annotations

from krl.ast import nodes as N
from krl.ast.visit import EXPRESSIONS, STATEMENTS, handlers
from krl.semantics.resolve import LOCAL, ROUTINE, SYSTEM

from interp.runtime.natives import ValueRef
from interp.runtime.convert import num
from interp.runtime.errors import ExitSignal, GotoSignal, KrlRuntimeError, ReturnSignal, lvalue_name, not_understood
from interp.runtime.slots import (anout_limits, anout_value, array_index, ended_without_return, for_done,
                                 for_limits, for_next, label_not_found, return_without_value, trigger_args)
from interp.runtime.values import Channel, EnumValue, Struct, copy_value
from interp.runtime.watch import watch_of_decl

#: classes of the values a variable read returns as they are (immutable: no copy)
_IMMUTABLE = frozenset((int, float, bool, str, EnumValue, type(None)))


class TreeInterpreter:
    def __init__(self, rt) -> None:
        self.rt = rt
        self.names = rt.names           # what a name denotes (interp/runtime/names.py)
        self.calls = rt.calls           # the call protocol (interp/runtime/calls.py)
        self.errstate = rt.errstate     # $ERR, ON_ERROR_PROCEED (interp/runtime/errstate.py)
        self._labels: dict = {}
        self.stmt_dispatch = handlers(self, "s_", STATEMENTS)
        self.expr_dispatch = handlers(self, "e_", EXPRESSIONS)

    # ------------------------------------------------------------------ entry points
    def run_program(self, module_name: str | None = None) -> None:
        """Body of the robot (or a submit) task: call the main routine of the module."""
        self.invoke(self.calls.main_routine(module_name), [], None)

    # ------------------------------------------------------------------ statements
    def exec_block(self, stmts: list, frame) -> None:
        i = 0
        n = len(stmts)
        dispatch = self.stmt_dispatch
        while i < n:
            st = stmts[i]
            try:
                dispatch[st.__class__](st, frame)
                i += 1
            except GotoSignal as g:
                pos = self._label_pos(stmts, g.target)
                if pos is None:
                    raise
                i = pos

    def _label_pos(self, stmts: list, target):
        """The position of Label `target` in the statement list `stmts`, or None."""
        key = id(stmts)
        table = self._labels.get(key)
        if table is None:
            table = {id(s): i for i, s in enumerate(stmts) if isinstance(s, N.Label)}
            self._labels[key] = (table, stmts)
        else:
            table = table[0]
        return table.get(id(target))

    def begin(self, st, frame):
        """Common statement prologue: runtime bookkeeping; returns the StmtInfo."""
        info = st.ann.info
        frame.line = info.line
        self.rt.before_statement(info)
        return info

    def plain(self, st, frame):
        """Prologue of a statement that ON_ERROR_PROCEED does not cover: it takes the flag
        all the same (§5.19: the flag is for the next statement only)."""
        info = self.begin(st, frame)
        self.errstate.take_error_proceed()
        return info

    def guarded(self, fn, st, frame, proceed: bool | None = None) -> bool:
        """Run a statement body under ON_ERROR_PROCEED semantics and place errors; False
        if it failed and the error was recorded (``proceed``: the flag, if the statement
        took it already)."""
        if proceed is None:
            proceed = self.errstate.take_error_proceed()
        try:
            fn()
        except KrlRuntimeError as e:
            e.at(st.span.file, st.span.line)
            if not proceed:
                raise
            self.errstate.record_error(e, frame)
            return False
        return True

    def s_Assign(self, st, frame) -> None:
        self.begin(st, frame)

        def do():
            value = self.eval(st.value, frame)
            ref = self.ref(st.target, frame)
            self.names.assign(ref, value)
            if st.ann.cyclic:
                # a cyclic flag: re-evaluated every IPO cycle until assigned again (§5.15)
                self.rt.cyclic.on(("cyclic flag", ref.name), lambda: self.names.assign(ref, self.eval(st.value, frame)))
        self.guarded(do, st, frame)

    def s_CallStmt(self, st, frame) -> None:
        self.begin(st, frame)
        self.guarded(lambda: self.call(st.call, frame, statement=True), st, frame)

    def s_If(self, st, frame) -> None:
        self.begin(st, frame)
        cond = []
        self.guarded(lambda: cond.append(self.rt.to_bool(self.eval(st.cond, frame))), st, frame)
        if not cond:
            return
        if cond[0]:
            self.exec_block(st.then, frame)
        elif st.orelse:
            self.exec_block(st.orelse, frame)

    def s_Switch(self, st, frame) -> None:
        self.begin(st, frame)
        sel = []
        self.guarded(lambda: sel.append(self.eval(st.selector, frame)), st, frame)
        if not sel:
            return
        v = sel[0]
        for case in st.cases:
            for ce in case.values:
                if self.rt.binary_op("==", v, self.eval(ce, frame)):
                    self.exec_block(case.body, frame)
                    return
        if st.default is not None:
            self.exec_block(st.default, frame)

    def s_For(self, st, frame) -> None:
        info = self.begin(st, frame)
        rt = self.rt
        head = []

        def header():        # ON_ERROR_PROCEED covers it: an error skips the whole loop
            ref = self.ref(st.var, frame)
            start = self.eval(st.start, frame)
            end, step = for_limits(self.eval(st.end, frame),
                                   self.eval(st.step, frame) if st.step is not None else 1)
            self.names.assign(ref, start)
            head.extend((ref, end, step))
        if not self.guarded(header, st, frame):
            return
        ref, end, step = head
        if for_done(ref.get(), end, step):
            return
        try:
            while True:
                rt.loop_tick(info)
                self.exec_block(st.body, frame)
                if not for_next(ref, end, step, info):
                    break
        except ExitSignal:
            pass

    def s_While(self, st, frame) -> None:
        info = self.begin(st, frame)
        rt = self.rt
        proceed = self.errstate.take_error_proceed()
        first = []
        rt.loop_tick(info)
        # ON_ERROR_PROCEED covers the first evaluation of the condition: an error skips the loop
        if not self.guarded(lambda: first.append(rt.to_bool(self.eval(st.cond, frame))), st, frame, proceed) \
                or not first[0]:
            return
        try:
            while True:
                self.exec_block(st.body, frame)
                rt.loop_tick(info)
                if not rt.to_bool(self.eval_at(st.cond, frame, st)):
                    break
        except ExitSignal:
            pass

    def s_Repeat(self, st, frame) -> None:
        info = self.plain(st, frame)
        rt = self.rt
        try:
            while True:
                self.exec_block(st.body, frame)
                rt.loop_tick(info)
                if rt.to_bool(self.eval_at(st.cond, frame, st)):
                    break
        except ExitSignal:
            pass

    def s_Loop(self, st, frame) -> None:
        info = self.plain(st, frame)
        rt = self.rt
        try:
            while True:
                rt.loop_tick(info)
                self.exec_block(st.body, frame)
        except ExitSignal:
            pass

    def s_Exit(self, st, frame) -> None:
        self.plain(st, frame)
        raise ExitSignal()

    def s_Goto(self, st, frame) -> None:
        self.plain(st, frame)
        raise GotoSignal(st.label, st.ann.target)

    def s_Label(self, st, frame) -> None:
        pass

    def s_Halt(self, st, frame) -> None:
        self.plain(st, frame)
        self.rt.halt()

    def s_WaitFor(self, st, frame) -> None:
        self.begin(st, frame)
        self.guarded(lambda: self.rt.wait_for(lambda: self.eval(st.cond, frame)), st, frame)

    def s_WaitSec(self, st, frame) -> None:
        self.begin(st, frame)
        self.guarded(lambda: self.rt.wait_sec(self.eval(st.time, frame)), st, frame)

    def s_Continue(self, st, frame) -> None:
        info = self.plain(st, frame)
        self.rt.set_continue(info)

    def s_Return(self, st, frame) -> None:
        self.begin(st, frame)
        value = []
        # ON_ERROR_PROCEED covers the value: after an error the next statement runs
        if self.guarded(lambda: value.append(self.eval(st.value, frame) if st.value is not None else None),
                        st, frame):
            raise ReturnSignal(value[0])

    def s_OnErrorProceed(self, st, frame) -> None:
        self.plain(st, frame)
        self.errstate.on_error_proceed()

    def s_DeclStmt(self, st, frame) -> None:
        raise KrlRuntimeError("declaration after the first statement", None, st.span.file, st.span.line)

    def s_stub(self, st, frame) -> None:
        """CONFIRM, ASYPTP, MOVE_EMI, ... (§5.20): recognised, not simulated."""
        self.plain(st, frame)
        words = getattr(st, "words", None)
        self.rt.stub_statement(" ".join(words) if words else type(st).__name__.upper())

    s_KeywordStmt = s_MoveEmi = s_stub

    # analog I/O (§5.14) --------------------------------------------------------------
    def s_AnoutOn(self, st, frame) -> None:
        self.begin(st, frame)
        rt = self.rt

        def do():
            ref = rt.names.storage_ref(st.ann.channel, frame)
            lo, hi = anout_limits(self.eval(st.minimum, frame) if st.minimum is not None else None,
                                  self.eval(st.maximum, frame) if st.maximum is not None else None)

            def tick():
                ref.set(anout_value(self.eval(st.value, frame), lo, hi))
            tick()
            rt.cyclic.on(("analog output", st.ann.channel.key), tick)
        self.guarded(do, st, frame)

    def s_AnoutOff(self, st, frame) -> None:
        self.plain(st, frame)
        self.rt.cyclic.off(("analog output", st.ann.channel.key))

    def s_AninOn(self, st, frame) -> None:
        self.begin(st, frame)
        rt = self.rt
        channel = st.ann.channel

        def do():
            ref = self.ref(st.target, frame)

            def tick():
                rt.names.assign(ref, self.eval(st.value, frame))
            tick()
            if channel is not None:
                rt.cyclic.on(("analog input", channel.key), tick)
        self.guarded(do, st, frame)

    def s_AninOff(self, st, frame) -> None:
        self.plain(st, frame)
        self.rt.cyclic.off(("analog input", st.ann.channel.key))

    def s_Unsupported(self, st, frame) -> None:
        raise KrlRuntimeError(f"unsupported statement: {st.text.strip()[:60]}", None,
                              st.span.file, st.span.line)

    def s_Unparsed(self, st, frame) -> None:
        raise KrlRuntimeError(not_understood(st), None, st.span.file, st.span.line)

    # interrupts, triggers, brake ------------------------------------------------------
    def s_InterruptDecl(self, st, frame) -> None:
        self.begin(st, frame)
        rt = self.rt
        call = st.call
        cond_expr = st.when

        def cond():
            return rt.to_bool(self.eval(cond_expr, frame), "interrupt condition")

        if st.brake is not None:                 # DO BRAKE / DO BRAKE F (§5.16)
            fast = st.brake.fast

            def handler():
                rt.interrupts.brake(fast)
        else:
            def handler():
                self.call(call, frame, statement=True, catch_resume=False)

        watch = watch_of_decl(st)

        def do():
            rt.interrupts.declare(self.eval(st.prio, frame), cond, handler, call.name, frame,
                              st.is_global, st.span.line, watch)
        self.guarded(do, st, frame)

    def s_InterruptCtl(self, st, frame) -> None:
        self.begin(st, frame)
        self.guarded(lambda: self.rt.interrupts.control(
            st.action, self.eval(st.prio, frame) if st.prio is not None else None), st, frame)

    def s_Brake(self, st, frame) -> None:
        self.plain(st, frame)
        self.rt.interrupts.brake(st.fast)

    def s_Resume(self, st, frame) -> None:
        self.plain(st, frame)
        self.rt.interrupts.resume()

    def s_Trigger(self, st, frame) -> None:
        self.begin(st, frame)
        rt = self.rt
        act = st.action

        def do():
            if isinstance(act, N.CallStmt):
                call = act.call
                target = rt.calls.callee(call.ann.callee)
                if target is not None:
                    # the arguments are evaluated now, in the advance run (§5.18)
                    args = [None if a is None else ValueRef(copy_value(self.eval(a, frame)))
                            for a in call.args]

                    def action():
                        self.exec_trigger_stmt(act, frame, lambda: self.invoke(target, args, frame))
                else:
                    def action():
                        self.exec_trigger_stmt(act, frame, lambda: self.call(call, frame, statement=True))
            else:
                def action():
                    self.exec_trigger_stmt(act, frame, lambda: rt.names.assign(
                        self.ref(act.target, frame), self.eval(act.value, frame)))
            at = self.eval(st.at, frame)
            delay = self.eval(st.delay, frame)
            prio = self.eval(st.prio, frame) if st.prio is not None else None
            rt.motions.trigger(action, line=st.span.line, **trigger_args(st.kind, at, delay, prio, st.onstart))
        self.guarded(do, st, frame)

    def s_ConditionalStop(self, st, frame) -> None:
        self.begin(st, frame)
        rt = self.rt
        cond = st.cond

        def do():
            rt.motions.conditional_stop(self.eval(st.path, frame), st.onstart,
                                lambda: rt.to_bool(self.eval(cond, frame), "conditional stop"), st.span.line)
        self.guarded(do, st, frame)

    def exec_trigger_stmt(self, act, frame, fn) -> None:
        self.rt.before_statement(act.ann.info)
        try:
            fn()
        except KrlRuntimeError as e:
            raise e.at(act.span.file, act.span.line)

    # motion ---------------------------------------------------------------------------
    def with_pairs(self, with_, frame) -> list:
        return [(self.ref(w.target, frame), self.eval(w.value, frame)) for w in with_]

    def s_Motion(self, st, frame) -> None:
        self.begin(st, frame)
        rt = self.rt

        def do():
            target = self.eval(st.target, frame)
            aux = self.eval(st.aux, frame) if st.aux is not None else None
            ca = self.eval(st.ca, frame) if st.ca is not None else None
            rt.motions.motion(st.kind, target, st.approx, aux, ca, st.frame, self.with_pairs(st.with_, frame),
                      st.span.file, st.span.line)
        self.guarded(do, st, frame)

    def s_SplineBlock(self, st, frame) -> None:
        self.begin(st, frame)
        rt = self.rt
        task = rt.clock.current_task

        def do():
            segs = []
            pending = []
            for s in st.body:
                if isinstance(s, (N.Trigger, N.ConditionalStop)):
                    saved = task.next_triggers
                    task.next_triggers = []
                    (self.s_Trigger if isinstance(s, N.Trigger) else self.s_ConditionalStop)(s, frame)
                    pending += task.next_triggers
                    task.next_triggers = saved
                elif isinstance(s, N.Motion):
                    segs.append({"kind": s.kind, "target": self.eval(s.target, frame),
                                 "aux": self.eval(s.aux, frame) if s.aux is not None else None,
                                 "ca": float(num(self.eval(s.ca, frame))) if s.ca is not None else None,
                                 "with_": self.with_pairs(s.with_, frame), "triggers": pending,
                                 "line": s.span.line})
                    pending = []
            rt.motions.spline(st.kind, segs, st.approx, self.with_pairs(st.with_, frame), st.span.file, st.span.line)
        self.guarded(do, st, frame)

    # ------------------------------------------------------------------ calls
    def args_for(self, call: N.Call, frame) -> list:
        """Arguments as references: lvalues by reference, expressions as values, omitted None."""
        out = []
        for a in call.args:
            if a is None:
                out.append(None)
            elif isinstance(a, (N.Name, N.Index, N.Field)):
                out.append(self.ref(a, frame))
            else:
                out.append(ValueRef(self.eval(a, frame)))
        return out

    def call(self, call: N.Call, frame, statement: bool = False, catch_resume: bool = True):
        calls = self.calls
        callee = call.ann.callee
        if callee.kind == ROUTINE:
            return self.invoke(calls.callee(callee), self.args_for(call, frame), frame, catch_resume)
        # the arguments are evaluated before a stand-in too, as the VM does
        return calls.call_native(callee, self.args_for(call, frame), not statement)

    def invoke(self, target, args: list, caller, catch_resume: bool = True):
        """Run routine ``target`` = (module, Routine) with reference ``args`` (the
        runtime's call protocol, interp/runtime/calls.py ``Calls.run_routine``)."""
        return self.calls.run_routine(target, args, caller, self.exec_routine, catch_resume)

    def exec_routine(self, frame):
        """The body of the routine of ``frame``; the value of its RETURN (None for a DEF).
        RETURN and GOTO unwind as exceptions to here."""
        routine = frame.routine
        try:
            self.exec_block(routine.body, frame)
        except ReturnSignal as r:
            if routine.is_function and r.value is None:
                raise return_without_value(routine, frame.line) from None
            return r.value if routine.is_function else None
        except GotoSignal as g:
            raise label_not_found(g.label, routine, frame.line) from None
        if routine.is_function:
            raise ended_without_return(routine, frame.line)
        return None

    # ------------------------------------------------------------------ expressions
    def eval(self, e, frame):
        return self.expr_dispatch[e.__class__](e, frame)

    def eval_at(self, e, frame, st):
        try:
            return self.eval(e, frame)
        except KrlRuntimeError as exc:
            raise exc.at(st.span.file, st.span.line)

    def e_lit(self, e, frame):
        return e.value

    e_IntLit = e_RealLit = e_BoolLit = e_StrLit = e_lit

    def e_EnumLit(self, e, frame):
        return EnumValue(e.name)

    def e_ChannelName(self, e, frame):
        return Channel(e.name)

    def e_Aggregate(self, e, frame):
        items = []
        for it in e.items:
            items.append((it.ann.component.key, self.eval(it.value, frame)))
        return self.names.aggregate(e.ann.struc if e.type_name else None, items)

    def e_var(self, e, frame):
        v = self.ref(e, frame).get()
        if v.__class__ in _IMMUTABLE:
            return v                # a scalar is its own copy
        if isinstance(v, Struct) or hasattr(v, "dims"):
            return copy_value(v)
        return v

    e_Name = e_Index = e_Field = e_var

    def e_Call(self, e, frame):
        v = self.call(e, frame)
        if v is None:
            raise KrlRuntimeError(f"{e.name} does not return a value")
        return v

    def e_Unary(self, e, frame):
        return self.rt.unary_op(e.op, self.eval(e.operand, frame))

    def e_Binary(self, e, frame):
        left = e.left
        if not isinstance(left, N.Binary):       # one operator: no chain to walk
            return self.rt.binary_op(e.op, self.eval(left, frame), self.eval(e.right, frame))
        # a left-nested chain (up to MAX_EXPRESSION_TERMS terms) in a loop: left before right
        left, chain = N.left_chain(e)
        a = self.eval(left, frame)
        for b in chain:
            a = self.rt.binary_op(b.op, a, self.eval(b.right, frame))
        return a

    def ref(self, e, frame):
        """The reference of an lvalue expression (Name / Index / Field chain)."""
        names = self.names
        if e.__class__ is N.Name:
            st = e.ann.place
            k = st.kind
            if k == LOCAL:
                return frame.vars[st.slot] or frame.var(st.slot)
            if k < SYSTEM:
                return names.modules[st.owner].refs[st.slot] or names.storage_ref(st, frame)
            return names.storage_ref(st, frame)
        if isinstance(e, N.Index):
            base = self.ref(e.base, frame)
            idx = []
            for i in e.indices:
                if i is None:
                    idx.append(None)
                else:
                    idx.append(array_index(self.eval(i, frame)))
            return names.index(base, idx, lvalue_name(e.base))
        if isinstance(e, N.Field):
            base = self.ref(e.base, frame)
            return names.field(base, e.name, lvalue_name(e.base), e.ann.component.key)
        raise KrlRuntimeError("not a variable")

