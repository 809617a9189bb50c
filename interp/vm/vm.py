"""The VM: runs encoded code (interp/vm/assembler.py) on the shared runtime.

One dispatch loop (:meth:`VM.run`) with the instruction pointer, the operand stack and
the frame's store in locals, one dispatch point, and every semantic operation a call into
:class:`interp.runtime.core.Runtime` (or its fast paths in interp/runtime/slots.py), the
same calls the tree interpreter makes. Hot opcodes inline the common case of such a call
(a number in a store variable, an in-range index, int/float arithmetic, a quiet step:
docs/architecture.md, "Bytecode VM") and make the call for every other case, so values
and error messages stay the runtime's. A KRL call runs a nested :meth:`run` (one Python
level per KRL call, as the tree interpreter's ``invoke``), so interrupt handlers, TRIGGER
actions and WAIT FOR conditions, which the runtime calls back at a statement boundary or
an IPO cycle, run as *thunks* of the declaring routine's code on top of the interrupted
context.

Errors: the assembler's regions (``.at``) are the line table. A KrlRuntimeError raised by
an instruction is placed on its region's line; in a guarded region after ON_ERROR_PROCEED
it is recorded ($ERR) and execution goes on after the statement, as in the tree
interpreter.

Code: the compiler makes a routine's listing from its annotated AST alone (no runtime),
:func:`link` turns the listing into the executed form (one tuple per listing instruction:
`krl asm` prints exactly what runs; kept per checked workspace by :func:`linked_code`, not on
the AST), and :class:`Bound` binds it to a run's storage and links every call site from its
Callee (a routine of the program: the (module, Routine) to invoke) when the routine is first
called; a built-in or a stub is run through the runtime (``Runtime.call_native``, as the tree
interpreter does: the implementation the resolver linked, else the stand-in policy). Dispatch: :meth:`VM.run` is the source of
every opcode's handler, a chain in frequency order; interp/vm/loop.py, generated from it by
interp/vm/gen_loop.py and checked in, is the same loop with a Huffman-shaped binary search
for the dispatch, and is what runs by default (``VM(rt, loop="source")`` runs the source).
The cold opcodes (motion, interrupts, triggers, analog I/O, waits, ...) are methods
``_cold_NAME`` the loop calls, so that the loop is the hot path.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import math
import operator
import sys
import weakref
from pathlib import Path

from interp.runtime.natives import ValueRef
from interp.runtime.convert import INT_MAX, INT_MIN, num
from interp.runtime.errors import ExitSignal, KrlRuntimeError
from interp.runtime.memory import Slot
from interp.runtime.values import UNSET, Struct
from interp.runtime.slots import (add, anout_limits, anout_value, array_index, component, element,
                                  element1, element2, ended_without_return, eq, for_done, for_limits,
                                  for_next, function_result, ge, gt, label_not_found, le, load, lt, mul,
                                  ne, read_value, return_without_value, set_component, set_element,
                                  set_element1, store, sub, trigger_args)

from . import opcodes as OP
from krl.semantics.advance import StmtInfo
from krl.semantics.types import BOOL as T_BOOL, INT as T_INT, REAL as T_REAL
from krl.semantics.resolve import ROUTINE

from .assembler import Region
from .compiler import compile_routine


# runtime functions the loop calls as ``_name`` (closure variables: no global lookup, no
# per-call binding)
HELPERS = ("load", "store", "element", "element1", "element2", "set_element", "set_element1", "component",
           "set_component", "add", "sub", "mul", "lt", "le", "gt", "ge", "eq", "ne", "for_next", "for_limits",
           "read_value", "array_index")
(_load, _store, _element, _element1, _element2, _set_element, _set_element1, _component,
 _set_component, _add, _sub, _mul, _lt, _le, _gt, _ge, _eq, _ne, _for_next, _for_limits,
 _read_value, _array_index) = (load, store, element, element1, element2, set_element, set_element1,
                               component, set_component, add, sub, mul, lt, le, gt, ge, eq, ne, for_next,
                               for_limits, read_value, array_index)


# The operand stack starts with STACK_BASE placeholders that no instruction reads (the loop
# spells the number out: ``len(stack) > 8``, ``del stack[8:]``): a statement's pushes and pops then
# never take the list back to empty, which would free and reallocate its items at every statement.
STACK_BASE = 8

# the VM's forms of operand kinds y and o (opcodes.py)
_VALUE_CLASS = {"I": int, "R": float, "B": bool}
# (the comparison on two numbers, its runtime function, its mask): bit s + 1 of the mask is set when
# the comparison holds for two INTs whose order is s = (a > b) - (a < b) (-1, 0, 1), so the
# compiled loop compares two INTs in C without a call
_COMPARE = {"<": (operator.lt, lt, 0b001), "<=": (operator.le, le, 0b011), ">": (operator.gt, gt, 0b100),
            ">=": (operator.ge, ge, 0b110), "==": (operator.eq, eq, 0b010), "<>": (operator.ne, ne, 0b101)}


class Linked:
    """The VM's executed form of one routine, made from its listing (interp/vm/compiler.py)
    by :func:`link`: one tuple ``(opcode, operand, ...)`` per instruction of the listing
    (``STMT_G``/``STMT`` also carry their statement's line and ``stops`` after it), in
    the listing's order (so `krl asm`, which prints the listing, shows exactly what runs),
    constants and statement infos in place, jump targets as instruction numbers, frame slots
    as slot numbers, module and global slots as indexes into ``mstorage`` / ``gstorage``
    (the front end's Storage, bound per run by :class:`Bound`); and the error region of
    each instruction. It holds nothing of a run and is kept per routine and loop."""

    __slots__ = ("name", "kind", "file", "prog", "ops", "iregions", "lnames", "ntemps",
                 "mnames", "mstorage", "gnames", "gstorage", "calls", "is_function")


def link(lst, dispatch) -> Linked:
    """The executed form of listing `lst` (interp/vm/compiler.py) for the loop whose opcode
    numbering is `dispatch` (opcode number -> the loop's number). Module and global slots
    are numbered by the places the front end resolved (``Storage.key``), never by a name."""
    out = Linked()
    out.name, out.kind, out.file, out.ntemps = lst.name, lst.kind, lst.file, lst.ntemps
    out.is_function = lst.kind == "DEFFCT"
    out.lnames = list(lst.lnames)
    lix = {n.upper(): i for i, n in enumerate(out.lnames)}
    out.mnames, out.gnames, out.mstorage, out.gstorage = [], [], [], []
    out.calls = []       # the instructions that call a routine of the program (Bound links them)
    mix: dict = {}
    gix: dict = {}
    labels = lst.labels
    prog = []
    regions = []
    moved: dict = {}     # guarded regions with their end as an instruction number
    call_op = dispatch[OP.CALL]
    for name, ops, reg in lst.instrs:
        info = OP.BY_NAME[name]
        ins = [dispatch[info.number]]
        for k, v in zip(info.operands, ops):
            if k == "x":
                v = StmtInfo(lst.file, v[0], "S" in v[1], "C" in v[1])
            elif k == "l":
                v = labels[v]
            elif k == "s" or k == "v":
                v = lix[v.upper()]
            elif k == "m" or k == "g":
                index, names, places = (mix, out.mnames, out.mstorage) if k == "m" else (gix, out.gnames, out.gstorage)
                place = v
                v = index.setdefault(place.key, len(index))
                if v == len(places):
                    names.append(place.name)
                    places.append(place)
            elif k == "y":
                v = _VALUE_CLASS.get(v)
            elif k == "o":
                v = _COMPARE[v]
            elif k == "k":
                v = (v, v.upper())
            ins.append(v)
        if name == "STMT_G" or name == "STMT":
            ins += (ins[1].line, ins[1].stops)      # read by every statement: kept in the tuple
        elif name == "JUMP_TICK" or name == "TICK":
            ins.append(ins[1].cond_stops)           # read by every iteration: kept in the tuple
        elif ins[0] == call_op and ins[1].kind == ROUTINE:
            out.calls.append(len(prog))
        prog.append(tuple(ins))
        if reg is not None and reg.kind == "G":
            got = moved.get(id(reg))
            if got is None:
                got = moved[id(reg)] = Region("G", reg.line, labels[reg.end])
            reg = got
        elif reg is not None:
            reg = Region(reg.kind, reg.line, -1)
        regions.append(reg)
    out.prog, out.iregions = prog, regions
    out.ops = bytes(ins[0] for ins in prog)     # the opcodes alone: the loop dispatches on a C byte
    return out


class Bound:
    """One run's view of a routine's code: the Linked form (shared) and this run's bindings
    of its module slots (``mrefs``, bound when first called: the data lists are loaded),
    global slots (``grefs``, bound on first use) and of each call site that runs a routine
    of the program (``callsites``: instruction -> (module, Routine), from its Callee)."""

    __slots__ = ("name", "kind", "is_function", "file", "routine", "prog", "ops", "iregions", "ntemps", "gstorage",
                 "mrefs", "grefs", "callsites", "gnames")

    def __init__(self, linked: Linked, routine, rt) -> None:
        self.name, self.kind, self.file, self.routine = linked.name, linked.kind, linked.file, routine
        self.is_function = linked.is_function
        self.prog, self.ops, self.iregions, self.ntemps = linked.prog, linked.ops, linked.iregions, linked.ntemps
        self.gstorage, self.gnames = linked.gstorage, linked.gnames
        self.mrefs = [rt.storage_ref(st, None) for st in linked.mstorage]
        self.grefs = [None] * len(linked.gstorage)
        prog = linked.prog
        self.callsites = {ip: rt.callee(prog[ip][1]) for ip in linked.calls}


class VM:
    def __init__(self, rt, loop: str = "generated") -> None:
        """`loop`: "generated" (interp/vm/loop.py, the dispatch loop generated from
        :meth:`run`, compiled by Cython when built: :data:`COMPILED`; the default),
        "python" (loop.py as plain Python, also when the compiled one exists) or "source"
        (:meth:`run` itself, the handlers' source); all three are kept runnable and tested
        (tests/vm/test_generated_loop.py, tests/vm/test_compiled_loop.py)."""
        self.rt = rt
        if loop == "source":
            self.loop, self.dispatch = VM.run, SOURCE_DISPATCH
        elif loop == "python":
            self.loop, self.dispatch = _python_loop().run, GENERATED_DISPATCH
        else:
            self.loop, self.dispatch = _generated_run, GENERATED_DISPATCH
        self.codes: dict = {}          # id(routine) -> Bound
        # the cold opcodes' handlers by the loop's number of the opcode
        self.cold = [None] * len(OP.OPS)
        for o in OP.OPS:
            handler = getattr(self, "_cold_" + o.name, None)
            if handler is not None:
                self.cold[self.dispatch[o.number]] = handler
        # the body of a KRL call: the loop itself, which finds the routine's code when called
        # without one (no Python frame of its own per call)
        self.body = functools.partial(self.loop, self, None)
        # the runtime's statement hooks, bound once (the loop takes them at each call)
        self.hooks = (rt.before_statement, rt.loop_tick, rt.take_error_proceed, rt.quiet_limit, rt.run_routine,
                      self.body, rt.call_native)

    # ------------------------------------------------------------------ entry points
    def run_program(self, module_name: str | None = None) -> None:
        """Body of the robot (or a submit) task: call the main routine of the module."""
        self.invoke(self.rt.main_routine(module_name), [], None)

    def code_for(self, routine) -> Bound:
        """This run's code of `routine`: compiled from its annotated AST and linked for this
        VM's loop once per process (:func:`linked_code`), bound to this run's storage and call
        sites once per run."""
        code = self.codes.get(id(routine))
        if code is None:
            linked = linked_code(self.rt.program.ws, routine, self.dispatch)
            code = self.codes[id(routine)] = Bound(linked, routine, self.rt)
        return code

    # ------------------------------------------------------------------ calls
    def invoke(self, target, args: list, caller, catch_resume: bool = True):
        """Run routine ``target`` = (module, Routine) with reference ``args`` (the
        runtime's call protocol, Runtime.run_routine)."""
        return self.rt.run_routine(target, args, caller, self.body, catch_resume)

    def thunk(self, code, frame, temps: list, ip: int, stack: list | None = None):
        """A callable that runs the thunk at ``ip`` of ``code`` in the activation (``frame``,
        ``temps``) that declared it."""
        loop = self.loop
        return lambda: loop(self, code, frame, temps, ip, [None] * STACK_BASE + (stack or []), True)

    # ------------------------------------------------------------------ cold opcodes
    def _cold_AGG(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        push = stack.append
        names = ins[2]
        keys = names.split(",") if names else []
        k = len(keys)
        vals = stack[len(stack) - k:]
        del stack[len(stack) - k:]
        push(rt.aggregate(ins[1], list(zip(keys, vals))))
        return ip + 1

    def _cold_JUMP_IF_NONE(self, ins, code, frame, temps, stack, ip):
        pop = stack.pop
        if stack[-1] is None:
            pop()
            return ins[1]
        else:
            return ip + 1

    def _cold_HALT(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        rt.halt()
        return ip + 1

    def _cold_WAIT_FOR(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        rt.wait_for(self.thunk(code, frame, temps, ins[1]))
        return ip + 1

    def _cold_WAIT_SEC(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        pop = stack.pop
        rt.wait_sec(pop())
        return ip + 1

    def _cold_CONTINUE(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        rt.set_continue(ins[1])
        return ip + 1

    def _cold_ON_ERROR_PROCEED(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        rt.on_error_proceed()
        return ip + 1

    def _cold_EXIT_SIGNAL(self, ins, code, frame, temps, stack, ip):
        raise ExitSignal()

    def _cold_GOTO_FAIL(self, ins, code, frame, temps, stack, ip):
        raise label_not_found(ins[1], code.routine, frame.line)

    def _cold_RAISE(self, ins, code, frame, temps, stack, ip):
        line = ins[2]
        raise KrlRuntimeError(ins[1], None, code.file if line else None, line or None)

    def _cold_INT_DECL(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        pop = stack.pop
        cond = self.thunk(code, frame, temps, ins[1])
        flags = ins[4]                 # G (GLOBAL), then the watch (interp/runtime/watch.py)
        is_global = flags[:1] == "G"
        rt.interrupt_decl(pop(), lambda c=cond: rt.to_bool(c(), "interrupt condition"),
                          self.thunk(code, frame, temps, ins[2]), ins[3], frame,
                          is_global, ins[5], flags[1:] if is_global else flags)
        return ip + 1

    def _cold_INT_CTL(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        pop = stack.pop
        n = pop() if ins[2] == "P" else None
        rt.interrupt_ctl(ins[1], n)
        return ip + 1

    def _cold_BRAKE(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        rt.brake(ins[1] == "F")
        return ip + 1

    def _cold_STUB(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        rt.stub_statement(ins[1])
        return ip + 1

    def _cold_CYCLIC_ASSIGN(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        pop = stack.pop
        ref = pop()
        _store(ref, pop())
        value = self.thunk(code, frame, temps, ins[1])
        rt.cyclic_on(("cyclic flag", ref.name), lambda r=ref, f=value: rt.assign(r, f()))
        return ip + 1

    def _cold_ANOUT_ON(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        pop = stack.pop
        flags = ins[2]
        hi = pop() if "H" in flags else None
        lo = pop() if "L" in flags else None
        ref = pop()
        lo, hi = anout_limits(lo, hi)
        value = self.thunk(code, frame, temps, ins[3])

        def anout(ref=ref, value=value, lo=lo, hi=hi):
            ref.set(anout_value(value(), lo, hi))
        anout()
        rt.cyclic_on(("analog output", ins[1].key), anout)
        return ip + 1

    def _cold_ANIN_ON(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        pop = stack.pop
        ref = pop()
        value = self.thunk(code, frame, temps, ins[2])

        def anin(ref=ref, value=value):
            rt.assign(ref, value())
        anin()
        channel = ins[1]
        if channel is not None:
            rt.cyclic_on(("analog input", channel.key), anin)
        return ip + 1

    def _cold_CYCLIC_OFF(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        rt.cyclic_off((ins[1], ins[2].key))
        return ip + 1

    def _cold_RESUME(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        rt.resume()
        return ip + 1

    def _cold_TRIG_FIND(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        push = stack.append
        target = rt.callee(ins[1])
        push(target)
        return ins[2] if target is None else ip + 1

    def _cold_TRIG_PACK(self, ins, code, frame, temps, stack, ip):
        argc = ins[1]
        args = stack[len(stack) - argc:]
        del stack[len(stack) - argc:]
        stack[-1] = (stack[-1], args)
        return ip + 1

    def _cold_TRIGGER(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        pop = stack.pop
        flags = ins[2]
        prio = pop() if "P" in flags else None
        delay = pop()
        at = pop()
        action = self.thunk(code, frame, temps, ins[4], [pop()])
        rt.trigger(action, line=ins[3],
                   **trigger_args(ins[1], at, delay, prio, "O" in flags))
        return ip + 1

    def _cold_TRIG_INVOKE(self, ins, code, frame, temps, stack, ip):
        pop = stack.pop
        target, args = pop()
        self.invoke(target, args, frame)
        return ip + 1

    def _cold_MOTION(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        pop = stack.pop
        nwith = ins[5]
        pairs = self.pairs(stack, nwith)
        flags = ins[4]
        ca = pop() if "C" in flags else None
        aux = pop() if "A" in flags else None
        approx = ins[2]
        rt.motion(ins[1], pop(), approx.split(",") if approx else [], aux, ca,
                  ins[3], pairs, code.file, ins[6])
        return ip + 1

    def _cold_SPL_BEGIN(self, ins, code, frame, temps, stack, ip):
        temps[ins[1]] = [[], [], None]     # segments, pending triggers, saved
        return ip + 1

    def _cold_SPL_TRIG_BEGIN(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        sp = temps[ins[1]]
        task = rt.current_task
        sp[2] = task.next_triggers
        task.next_triggers = []
        return ip + 1

    def _cold_SPL_TRIG_END(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        sp = temps[ins[1]]
        task = rt.current_task
        sp[1] += task.next_triggers
        task.next_triggers = sp[2]
        return ip + 1

    def _cold_SPL_SEG(self, ins, code, frame, temps, stack, ip):
        pop = stack.pop
        pairs = self.pairs(stack, ins[3])
        flags = ins[2]
        ca = float(num(pop())) if "C" in flags else None
        aux = pop() if "A" in flags else None
        sp = temps[ins[5]]
        sp[0].append({"kind": ins[1], "target": pop(), "aux": aux, "ca": ca,
                      "with_": pairs, "triggers": sp[1], "line": ins[4]})
        sp[1] = []
        return ip + 1

    def _cold_SPLINE(self, ins, code, frame, temps, stack, ip):
        rt = self.rt
        pairs = self.pairs(stack, ins[3])
        rt.spline(ins[1], temps[ins[5]][0], ins[2], pairs,
                  code.file, ins[4])
        return ip + 1

    # ------------------------------------------------------------------ the loop
    def run(self, code, frame, temps: list | None = None, ip: int = 0, stack: list | None = None, thunk: bool = False):
        """Run ``code`` from ``ip`` in the activation of ``frame`` (its runtime Frame) with
        the temporaries ``temps``; returns the value of RETURN,
        or of the thunk at END_THUNK. ``code`` None: the body of a call
        (``VM.body``), the code of the frame's routine from its start. The ``_name`` helpers are
        the runtime functions of :data:`HELPERS` (module names of the generated loop:
        interp/vm/gen_loop.py)."""
        if code is None:
            routine = frame.routine
            code = self.codes.get(id(routine)) or self.code_for(routine)
            temps = [None] * code.ntemps
            stack = [None, None, None, None, None, None, None, None]      # STACK_BASE
        rt = self.rt
        prog = code.prog
        ops = code.ops               # prog's opcodes, one byte each (C integers when compiled)
        mrefs = code.mrefs
        grefs = code.grefs
        store = frame.store          # store variables (operand kind v): Frame.store keys
        # the data list of each store array, read from the store when first used: an array's data
        # list is never replaced (values.Arr; convert.assign_into fills it in place)
        adata = [None] * len(store)
        agrid = [None] * len(store)
        fvars = frame.vars
        push = stack.append
        pop = stack.pop
        before, tick, take_error_proceed, quiet_limit, run_routine, exec_routine, call_native = self.hooks
        cold = self.cold
        task = rt.current_task
        # Quiet steps (Runtime.quiet_limit) are counted here, in two locals: ``left``, how many
        # more steps may be quiet, and ``unsaved``, the quiet steps taken and not yet added to
        # rt.steps. Before anything that reads or changes rt.steps or task.quiet (the full
        # statement hooks, a call, a cold opcode, an error's $ERR, leaving the loop) the loop
        # adds ``unsaved`` to rt.steps; after it, it takes ``left`` from task.quiet again.
        # (No task: a cyclic flag's or analog output's expression the controller evaluates.)
        left = task.quiet - rt.steps if task is not None else 0
        unsaved = 0
        proceed = False
        # ``dirty``: a quiet STMT_G ran and its line (frame.line) and StmtInfo (task.at) are not
        # written yet. The loop writes them (the lines marked "flush") before anything that may
        # read them: a statement or loop hook, a call, a cold opcode, an error, leaving the loop.
        dirty = False
        try:
            while True:
                try:
                    while True:
                        ins = prog[ip]
                        op = ops[ip]
                        # hottest first (measured on the benchmark): the rank weights the search
                        # tree interp/vm/gen_loop.py makes of this chain
                        if op == OP.STMT_G:
                            info = ins[1]
                            if left > 0 and not ins[3]:         # a quiet step (Runtime.quiet_limit)
                                left -= 1
                                unsaved += 1
                                dirty = True                    # frame.line, task.at: flushed later
                                proceed = False
                            else:
                                frame.line = ins[2]             # info.line, info.stops: link()
                                dirty = False
                                rt.steps += unsaved
                                unsaved = 0
                                before(info)
                                proceed = take_error_proceed()
                                task.quiet = n = quiet_limit(task)
                                left = n - rt.steps
                            ip += 1
                        elif op == OP.LOAD_ELEM1_V:
                            x1 = ins[1]             # x1, x2, x3: C integers when compiled (loop.pxd)
                            x2 = ins[2]
                            i = store[x2]
                            d = adata[x1]  # 1-D: len(data) is dims[0] (values.Arr)
                            if d is None:
                                d = adata[x1] = store[x1].data
                            if i.__class__ is int and 0 < i <= INT_MAX and (x3 := i) <= len(d) and (v := d[x3 - 1]) is not UNSET:
                                push(v)
                            else:
                                push(_element1((fvars[x1] or frame.var(x1)), _load((fvars[x2] or frame.var(x2))), ins[3]))
                            ip += 1
                        elif op == OP.LOAD_FAST:
                            x1 = ins[1]
                            v = store[x1]
                            push(v if v is not UNSET else _load((fvars[x1] or frame.var(x1))))
                            ip += 1
                        elif op == OP.JUMP_TICK:
                            if left > 0 and not ins[3]:
                                left -= 1
                                unsaved += 1
                            else:
                                if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                    frame.line = info.line
                                    task.at = info
                                    dirty = False
                                rt.steps += unsaved
                                unsaved = 0
                                tick(ins[1])
                                task.quiet = n = quiet_limit(task)
                                left = n - rt.steps
                            ip = ins[2]
                        elif op == OP.CONST:
                            push(ins[1])
                            ip += 1
                        elif op == OP.FOR_NEXT_FAST:
                            x2 = ins[2]
                            x1 = ins[1]
                            c = store[x1]
                            if c.__class__ is int and (c := c + temps[x2 + 2]) <= temps[x2 + 3]:
                                store[x1] = c
                                go = True
                            elif (c.__class__ is int and (step := temps[x2 + 2]).__class__ is int
                                  and (end := temps[x2 + 1]).__class__ is int and INT_MIN <= c <= INT_MAX):
                                # the last step (or a negative STEP): for_next's INT case inline
                                store[x1] = c
                                go = c <= end if step > 0 else c >= end
                            else:
                                go = _for_next(temps[x2], temps[x2 + 1], temps[x2 + 2], ins[3])
                            if go:
                                if left > 0:
                                    left -= 1
                                    unsaved += 1
                                else:
                                    if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                        frame.line = info.line
                                        task.at = info
                                        dirty = False
                                    rt.steps += unsaved
                                    unsaved = 0
                                    tick(ins[3])
                                    task.quiet = n = quiet_limit(task)
                                    left = n - rt.steps
                                ip = ins[4]
                            else:
                                ip += 1
                        elif op == OP.LOAD_FAST2:
                            x1 = ins[1]
                            x2 = ins[2]
                            v = store[x1]
                            push(v if v is not UNSET else _load((fvars[x1] or frame.var(x1))))
                            v = store[x2]
                            push(v if v is not UNSET else _load((fvars[x2] or frame.var(x2))))
                            ip += 1
                        elif op == OP.ADD:
                            b = pop()
                            a = stack[-1]
                            if a.__class__ is float and b.__class__ is float:
                                stack[-1] = a + b
                            elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a + b) <= INT_MAX:
                                stack[-1] = v
                            else:
                                stack[-1] = _add(a, b)
                            ip += 1
                        elif op == OP.STORE_FAST:
                            v = pop()
                            t = ins[2]
                            x1 = ins[1]
                            if v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                                store[x1] = v
                            else:
                                _store((fvars[x1] or frame.var(x1)), v)
                            ip += 1
                        elif op == OP.STORE_ELEM1:
                            i = pop()
                            v = pop()
                            x1 = ins[1]
                            t = ins[3]
                            d = adata[x1]
                            if d is None:
                                d = adata[x1] = store[x1].data
                            if i.__class__ is int and 0 < i <= INT_MAX and (x3 := i) <= len(d) and v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                                d[x3 - 1] = v
                            else:
                                _set_element1((fvars[x1] or frame.var(x1)), i, v, ins[2])
                            ip += 1
                        elif op == OP.SUBC_FAST:
                            x1 = ins[1]
                            a = store[x1]
                            b = ins[2]
                            t = ins[4]
                            ca = a.__class__
                            if ca is b.__class__ and ca is t and (ca is float or (ca is int and INT_MIN <= (v := a - b) <= INT_MAX)):
                                x3 = ins[3]
                                store[x3] = a - b if ca is float else v
                            else:
                                _store((fvars[ins[3]] or frame.var(ins[3])), _sub(a if a is not UNSET else _load((fvars[x1] or frame.var(x1))), b))
                            ip += 1
                        elif op == OP.IF_NOT_VC:
                            x1 = ins[1]
                            a = store[x1]
                            b = ins[2]
                            ca = a.__class__
                            cb = b.__class__
                            f = ins[3]
                            if ca is int and cb is int:
                                y1 = a                  # two INTs: compared in C by the mask (_COMPARE)
                                y2 = b
                                x3 = f[2]
                                go = (x3 >> ((y1 > y2) - (y1 < y2) + 1)) & 1
                            elif (ca is int or ca is float) and (cb is int or cb is float):
                                go = f[0](a, b)
                            else:
                                go = f[1](a if a is not UNSET else _load((fvars[x1] or frame.var(x1))), b)
                            if go:
                                ip += 1
                            else:
                                ip = ins[4]
                        elif op == OP.IF_NOT_LE:
                            b = pop()
                            a = pop()
                            ca = a.__class__
                            cb = b.__class__
                            if (a <= b) if (ca is int or ca is float) and (cb is int or cb is float) else _le(a, b):
                                ip += 1
                            else:
                                ip = ins[1]
                        elif op == OP.STORE_ELEM1_V:
                            x1 = ins[1]
                            x2 = ins[2]
                            i = store[x2]
                            v = pop()
                            t = ins[4]
                            d = adata[x1]
                            if d is None:
                                d = adata[x1] = store[x1].data
                            if i.__class__ is int and 0 < i <= INT_MAX and (x3 := i) <= len(d) and v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                                d[x3 - 1] = v
                            else:
                                _set_element1((fvars[x1] or frame.var(x1)), _load((fvars[x2] or frame.var(x2))), v, ins[3])
                            ip += 1
                        elif op == OP.IF_NOT_EV:
                            # LOAD_ELEM1_V, LOAD_FAST, IF_NOT_<o>: their handlers in a row
                            x1 = ins[1]
                            x2 = ins[2]
                            i = store[x2]
                            d = adata[x1]
                            if d is None:
                                d = adata[x1] = store[x1].data
                            if not (i.__class__ is int and 0 < i <= INT_MAX and (x3 := i) <= len(d) and (v := d[x3 - 1]) is not UNSET):
                                v = _element1((fvars[x1] or frame.var(x1)), _load((fvars[x2] or frame.var(x2))), ins[3])
                            x1 = ins[4]
                            b = store[x1]
                            if b is UNSET:
                                b = _load((fvars[x1] or frame.var(x1)))
                            ca = v.__class__
                            cb = b.__class__
                            f = ins[5]
                            if ca is int and cb is int:
                                y1 = v
                                y2 = b
                                x3 = f[2]
                                go = (x3 >> ((y1 > y2) - (y1 < y2) + 1)) & 1
                            else:
                                go = f[0](v, b) if (ca is int or ca is float) and (cb is int or cb is float) else f[1](v, b)
                            if go:
                                ip += 1
                            else:
                                ip = ins[6]
                        elif op == OP.MOVE_ELEM1:
                            # LOAD_ELEM1_V, FAST_ADD_CONST, STORE_ELEM1: their handlers in a row
                            x1 = ins[1]
                            x2 = ins[2]
                            i = store[x2]
                            d = adata[x1]
                            if d is None:
                                d = adata[x1] = store[x1].data
                            if not (i.__class__ is int and 0 < i <= INT_MAX and (x3 := i) <= len(d) and (v := d[x3 - 1]) is not UNSET):
                                v = _element1((fvars[x1] or frame.var(x1)), _load((fvars[x2] or frame.var(x2))), ins[3])
                            x1 = ins[4]
                            a = store[x1]
                            b = ins[5]
                            if a.__class__ is int and b.__class__ is int and INT_MIN <= (i := a + b) <= INT_MAX:
                                pass
                            elif a.__class__ is float and b.__class__ is float:
                                i = a + b
                            else:
                                i = _add(a if a is not UNSET else _load((fvars[x1] or frame.var(x1))), b)
                            x1 = ins[6]
                            t = ins[8]
                            d = adata[x1]
                            if d is None:
                                d = adata[x1] = store[x1].data
                            if i.__class__ is int and 0 < i <= INT_MAX and (x3 := i) <= len(d) and v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                                d[x3 - 1] = v
                            else:
                                _set_element1((fvars[x1] or frame.var(x1)), i, v, ins[7])
                            ip += 1
                        elif op == OP.ADD_FAST:
                            # LOAD_FAST2, ADD, STORE_FAST: their handlers in a row
                            x1 = ins[1]
                            x2 = ins[2]
                            a = store[x1]
                            b = store[x2]
                            t = ins[4]
                            if a.__class__ is int and b.__class__ is int and t is int and INT_MIN <= (v := a + b) <= INT_MAX:
                                x3 = ins[3]
                                store[x3] = v
                            elif a.__class__ is float and b.__class__ is float and t is float:
                                x3 = ins[3]
                                store[x3] = a + b
                            else:
                                if a is UNSET:
                                    a = _load((fvars[x1] or frame.var(x1)))
                                if b is UNSET:
                                    b = _load((fvars[x2] or frame.var(x2)))
                                v = _add(a, b)          # (ADD's inline cases give add's result)
                                x3 = ins[3]
                                if v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                                    store[x3] = v
                                else:
                                    _store((fvars[x3] or frame.var(x3)), v)
                            ip += 1
                        elif op == OP.STORE_ELEM1_VC:
                            # CONST, STORE_ELEM1_V
                            x1 = ins[1]
                            x2 = ins[2]
                            i = store[x2]
                            v = ins[5]
                            t = ins[4]
                            d = adata[x1]
                            if d is None:
                                d = adata[x1] = store[x1].data
                            if i.__class__ is int and 0 < i <= INT_MAX and (x3 := i) <= len(d) and v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                                d[x3 - 1] = v
                            else:
                                _set_element1((fvars[x1] or frame.var(x1)), _load((fvars[x2] or frame.var(x2))), v, ins[3])
                            ip += 1
                        elif op == OP.FAST_ADD_CONST:
                            x1 = ins[1]
                            a = store[x1]
                            b = ins[2]
                            if a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a + b) <= INT_MAX:
                                push(v)
                            elif a.__class__ is float and b.__class__ is float:
                                push(a + b)
                            else:
                                push(_add(a if a is not UNSET else _load((fvars[x1] or frame.var(x1))), b))
                            ip += 1
                        elif op == OP.REF_LOCAL:
                            push((fvars[ins[1]] or frame.var(ins[1])))
                            ip += 1
                        elif op == OP.IF_NOT_VV:
                            x1 = ins[1]
                            x2 = ins[2]
                            a = store[x1]
                            b = store[x2]
                            ca = a.__class__
                            cb = b.__class__
                            f = ins[3]
                            if ca is int and cb is int:
                                y1 = a
                                y2 = b
                                x3 = f[2]
                                go = (x3 >> ((y1 > y2) - (y1 < y2) + 1)) & 1
                            elif (ca is int or ca is float) and (cb is int or cb is float):
                                go = f[0](a, b)
                            else:
                                go = f[1](a if a is not UNSET else _load((fvars[x1] or frame.var(x1))), b if b is not UNSET else _load((fvars[x2] or frame.var(x2))))
                            if go:
                                ip += 1
                            else:
                                ip = ins[4]
                        elif op == OP.MUL:
                            b = pop()
                            a = stack[-1]
                            if a.__class__ is float and b.__class__ is float:
                                stack[-1] = a * b
                            elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a * b) <= INT_MAX:
                                stack[-1] = v
                            elif (a.__class__ is int and b.__class__ is float) or (a.__class__ is float and b.__class__ is int):
                                stack[-1] = a * b                   # INT * REAL: REAL (mul)
                            else:
                                stack[-1] = _mul(a, b)
                            ip += 1
                        elif op == OP.LOAD_FIELD:
                            base = stack[-1]
                            if base.__class__ is Slot and (x := base.c[base.k]).__class__ is Struct and (
                                    (x := x.f.get(ins[1][1])).__class__ is float or x.__class__ is int
                                    or x.__class__ is bool):
                                stack[-1] = x
                            else:
                                stack[-1] = _component(base, ins[1][0], ins[2])
                            ip += 1
                        elif op == OP.LOAD_FIELD_L:
                            # a structure the frame holds itself (a local, an :IN copy) is read from
                            # its store; a reference parameter's through its Slot
                            x1 = ins[1]
                            x = store[x1]
                            if x.__class__ is Struct and (
                                    (x := x.f.get(ins[2][1])).__class__ is float or x.__class__ is int
                                    or x.__class__ is bool):
                                push(x)
                            else:
                                base = (fvars[x1] or frame.var(x1))
                                if base.__class__ is Slot and (x := base.c[base.k]).__class__ is Struct and (
                                        (x := x.f.get(ins[2][1])).__class__ is float or x.__class__ is int
                                        or x.__class__ is bool):
                                    push(x)
                                else:
                                    push(_component(base, ins[2][0], ins[3]))
                            ip += 1
                        elif op == OP.STORE_FIELD_L:
                            # set_component's fast path (slots.py): a writable Slot holding a typed
                            # Struct, a field of type INT/REAL/BOOL, a value of that very type; a
                            # variable the frame holds itself and has no Slot of yet is writable
                            # (Frame.var: not a CONST, no write hook)
                            x1 = ins[1]
                            base = fvars[x1]
                            v = pop()
                            k = ins[2][1]
                            if base is None:
                                s = store[x1]
                            elif base.__class__ is Slot and not base.readonly:
                                s = base.c[base.k]
                            else:
                                s = None
                            if s.__class__ is Struct and s.type is not None \
                                    and (ft := s.type.fields.get(k)) is not None and k in s.f \
                                    and (((t := ft[1]) is T_REAL and v.__class__ is float)
                                         or (t is T_INT and v.__class__ is int and INT_MIN <= v <= INT_MAX)
                                         or (t is T_BOOL and v.__class__ is bool)):
                                s.f[k] = v
                            else:
                                _set_component(base or frame.var(x1), ins[2][0], v, ins[3])
                            ip += 1
                        elif op == OP.UNOP:
                            a = stack[-1]
                            if (a is True or a is False) and ins[1] == "NOT":
                                stack[-1] = a is False
                            elif a.__class__ is float and ins[1] == "-":
                                stack[-1] = -a
                            else:
                                stack[-1] = rt.unary_op(ins[1], a)
                            ip += 1
                        elif op == OP.JUMP_IF_FALSE:
                            v = pop()
                            if v is True:
                                ip += 1
                            elif v is False or not rt.to_bool(v):
                                ip = ins[1]
                            else:
                                ip += 1
                        elif op == OP.LOAD_ELEM2:
                            j = pop()
                            i = stack[-1]
                            x1 = ins[1]
                            grid = agrid[x1]
                            if grid is None:               # (data, rows, columns) of a 2-D store array: they never change
                                a = store[x1]
                                grid = agrid[x1] = (a.data, a.dims[0], a.dims[1])
                            n = grid[1]
                            m = grid[2]
                            if i.__class__ is int and j.__class__ is int and 0 < i <= n and 0 < j <= m \
                                    and (v := grid[0][((y1 := i) - 1) * (y2 := m) + (y3 := j) - 1]) is not UNSET:
                                stack[-1] = v
                            else:
                                stack[-1] = _element2((fvars[ins[1]] or frame.var(ins[1])), i, j, ins[2])
                            ip += 1
                        elif op == OP.LOAD_ELEM2_VV:
                            x1 = ins[1]
                            x2 = ins[2]
                            x3 = ins[3]
                            i = store[x2]
                            j = store[x3]
                            grid = agrid[x1]
                            if grid is None:               # (data, rows, columns) of a 2-D store array: they never change
                                a = store[x1]
                                grid = agrid[x1] = (a.data, a.dims[0], a.dims[1])
                            n = grid[1]
                            m = grid[2]
                            if i.__class__ is int and j.__class__ is int and 0 < i <= n and 0 < j <= m \
                                    and (v := grid[0][((y1 := i) - 1) * (y2 := m) + (y3 := j) - 1]) is not UNSET:
                                push(v)
                            else:
                                push(_element2((fvars[x1] or frame.var(x1)), _load((fvars[x2] or frame.var(x2))), _load((fvars[x3] or frame.var(x3))), ins[4]))
                            ip += 1
                        elif op == OP.STMT:
                            info = ins[1]
                            dirty = False               # this statement's own line and info follow
                            if not thunk:
                                frame.line = ins[2]
                            if left > 0 and not ins[3]:
                                left -= 1
                                unsaved += 1
                                task.at = info
                            else:
                                rt.steps += unsaved
                                unsaved = 0
                                before(info)
                                task.quiet = n = quiet_limit(task)
                                left = n - rt.steps
                            ip += 1
                        elif op == OP.STORE_FIELD:
                            base = pop()
                            _set_component(base, ins[1][0], pop(), ins[2])
                            ip += 1
                        elif op == OP.TICK:
                            if left > 0 and not ins[2]:
                                left -= 1
                                unsaved += 1
                            else:
                                if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                    frame.line = info.line
                                    task.at = info
                                    dirty = False
                                rt.steps += unsaved
                                unsaved = 0
                                tick(ins[1])
                                task.quiet = n = quiet_limit(task)
                                left = n - rt.steps
                            ip += 1
                        elif op == OP.MUL_CONST:
                            b = ins[1]
                            a = stack[-1]
                            if a.__class__ is float and b.__class__ is float:
                                stack[-1] = a * b
                            elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a * b) <= INT_MAX:
                                stack[-1] = v
                            elif (a.__class__ is int and b.__class__ is float) or (a.__class__ is float and b.__class__ is int):
                                stack[-1] = a * b                   # INT * REAL: REAL (mul)
                            else:
                                stack[-1] = _mul(a, b)
                            ip += 1
                        elif op == OP.SUB:
                            b = pop()
                            a = stack[-1]
                            if a.__class__ is float and b.__class__ is float:
                                stack[-1] = a - b
                            elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a - b) <= INT_MAX:
                                stack[-1] = v
                            else:
                                stack[-1] = _sub(a, b)
                            ip += 1
                        elif op == OP.ADD_CONST:
                            b = ins[1]
                            a = stack[-1]
                            if a.__class__ is float and b.__class__ is float:
                                stack[-1] = a + b
                            elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a + b) <= INT_MAX:
                                stack[-1] = v
                            else:
                                stack[-1] = _add(a, b)
                            ip += 1
                        elif op == OP.CALL:
                            argc = ins[2]
                            if argc:
                                args = stack[-argc:]
                                del stack[-argc:]
                            else:
                                args = []
                            flags = ins[3]
                            target = code.callsites.get(ip)
                            if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                frame.line = info.line
                                task.at = info
                                dirty = False
                            rt.steps += unsaved
                            unsaved = 0
                            if target is not None:       # VM.invoke, without its Python frame
                                v = run_routine(target, args, frame, exec_routine, "N" not in flags)
                            else:                        # a built-in (linked: Callee.native) or the stand-in policy
                                v = call_native(ins[1], args, flags == "E")
                            left = task.quiet - rt.steps if task is not None else 0
                            if flags == "E":
                                push(v if v is not None else function_result(ins[1].name, v))
                            ip += 1
                        elif op == OP.STORE_ELEM2:
                            j = pop()
                            i = pop()
                            v = pop()
                            x1 = ins[1]
                            grid = agrid[x1]
                            if grid is None:               # (data, rows, columns) of a 2-D store array: they never change
                                a = store[x1]
                                grid = agrid[x1] = (a.data, a.dims[0], a.dims[1])
                            n = grid[1]
                            m = grid[2]
                            t = ins[3]
                            if i.__class__ is int and j.__class__ is int and 0 < i <= n and 0 < j <= m and v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                                y1 = i
                                y2 = m
                                y3 = j
                                grid[0][(y1 - 1) * y2 + y3 - 1] = v
                            else:
                                _set_element((fvars[ins[1]] or frame.var(ins[1])), [i, j], v, ins[2])
                            ip += 1
                        elif op == OP.ADDC_FAST:
                            x1 = ins[1]
                            a = store[x1]
                            b = ins[2]
                            t = ins[4]
                            ca = a.__class__
                            if ca is b.__class__ and ca is t and (ca is float or (ca is int and INT_MIN <= (v := a + b) <= INT_MAX)):
                                x3 = ins[3]
                                store[x3] = a + b if ca is float else v
                            else:
                                _store((fvars[ins[3]] or frame.var(ins[3])), _add(a if a is not UNSET else _load((fvars[x1] or frame.var(x1))), b))
                            ip += 1
                        elif op == OP.LOAD_MOD:
                            push(_load(mrefs[ins[1]]))
                            ip += 1
                        elif op == OP.STORE_MOD:
                            _store(mrefs[ins[1]], pop())
                            ip += 1
                        elif op == OP.VALARG:
                            stack[-1] = ValueRef(stack[-1])
                            ip += 1
                        elif op == OP.RETURN_VAL:
                            v = pop()
                            if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                frame.line = info.line
                                task.at = info
                                dirty = False
                            return v if code.is_function else None
                        elif op == OP.END:
                            if code.is_function:
                                if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                    frame.line = info.line
                                    task.at = info
                                    dirty = False
                                raise ended_without_return(code.routine, frame.line)
                            if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                frame.line = info.line
                                task.at = info
                                dirty = False
                            return None
                        elif op == OP.IF_NOT_LT:
                            b = pop()
                            a = pop()
                            ca = a.__class__
                            cb = b.__class__
                            if (a < b) if (ca is int or ca is float) and (cb is int or cb is float) else _lt(a, b):
                                ip += 1
                            else:
                                ip = ins[1]
                        elif op == OP.JUMP:
                            ip = ins[1]
                        elif op == OP.LOAD_LOCAL:
                            push(_load((fvars[ins[1]] or frame.var(ins[1]))))
                            ip += 1
                        elif op == OP.STORE_LOCAL:
                            _store((fvars[ins[1]] or frame.var(ins[1])), pop())
                            ip += 1
                        elif op == OP.FAST_SUB_CONST:
                            a = store[ins[1]]
                            b = ins[2]
                            if a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a - b) <= INT_MAX:
                                push(v)
                            elif a.__class__ is float and b.__class__ is float:
                                push(a - b)
                            else:
                                push(_sub(a if a is not UNSET else _load((fvars[ins[1]] or frame.var(ins[1]))), b))
                            ip += 1
                        elif op == OP.SUB_CONST:
                            b = ins[1]
                            a = stack[-1]
                            if a.__class__ is float and b.__class__ is float:
                                stack[-1] = a - b
                            elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a - b) <= INT_MAX:
                                stack[-1] = v
                            else:
                                stack[-1] = _sub(a, b)
                            ip += 1
                        elif op == OP.IF_NOT_GT:
                            b = pop()
                            a = pop()
                            ca = a.__class__
                            cb = b.__class__
                            if (a > b) if (ca is int or ca is float) and (cb is int or cb is float) else _gt(a, b):
                                ip += 1
                            else:
                                ip = ins[1]
                        elif op == OP.IF_NOT_GE:
                            b = pop()
                            a = pop()
                            ca = a.__class__
                            cb = b.__class__
                            if (a >= b) if (ca is int or ca is float) and (cb is int or cb is float) else _ge(a, b):
                                ip += 1
                            else:
                                ip = ins[1]
                        elif op == OP.IF_NOT_EQ:
                            b = pop()
                            a = pop()
                            ca = a.__class__
                            cb = b.__class__
                            if (a == b) if (ca is int or ca is float) and (cb is int or cb is float) else _eq(a, b):
                                ip += 1
                            else:
                                ip = ins[1]
                        elif op == OP.IF_NOT_NE:
                            b = pop()
                            a = pop()
                            ca = a.__class__
                            cb = b.__class__
                            if (a != b) if (ca is int or ca is float) and (cb is int or cb is float) else _ne(a, b):
                                ip += 1
                            else:
                                ip = ins[1]
                        elif op == OP.RETURN:
                            if code.is_function:
                                if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                    frame.line = info.line
                                    task.at = info
                                    dirty = False
                                raise return_without_value(code.routine, frame.line)
                            if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                frame.line = info.line
                                task.at = info
                                dirty = False
                            return None
                        elif op == OP.LOAD_ELEM1:
                            x1 = ins[1]
                            i = stack[-1]
                            d = adata[x1]
                            if d is None:
                                d = adata[x1] = store[x1].data
                            if i.__class__ is int and 0 < i <= INT_MAX and (x3 := i) <= len(d) and (v := d[x3 - 1]) is not UNSET:
                                stack[-1] = v
                            else:
                                stack[-1] = _element1((fvars[ins[1]] or frame.var(ins[1])), i, ins[2])
                            ip += 1
                        elif op == OP.LOAD_ELEM_LL:
                            push(_element1((fvars[ins[1]] or frame.var(ins[1])), _load((fvars[ins[2]] or frame.var(ins[2]))), ins[3]))
                            ip += 1
                        elif op == OP.LOAD_LOCAL2:
                            push(_load((fvars[ins[1]] or frame.var(ins[1]))))
                            push(_load((fvars[ins[2]] or frame.var(ins[2]))))
                            ip += 1
                        elif op == OP.FOR_NEXT:
                            t = ins[1]
                            if _for_next(temps[t], temps[t + 1], temps[t + 2], ins[2]):
                                if left > 0 and not ins[2].cond_stops:
                                    left -= 1
                                    unsaved += 1
                                else:
                                    if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                        frame.line = info.line
                                        task.at = info
                                        dirty = False
                                    rt.steps += unsaved
                                    unsaved = 0
                                    tick(ins[2])
                                    task.quiet = n = quiet_limit(task)
                                    left = n - rt.steps
                                ip = ins[3]
                            else:
                                ip += 1
                        elif op == OP.LOCAL_ADD_CONST:
                            push(_add(_load((fvars[ins[1]] or frame.var(ins[1]))), ins[2]))
                            ip += 1
                        elif op == OP.STORE_INDEX:
                            n = ins[1]
                            if n == 1:
                                i = pop()
                                base = pop()
                                _set_element1(base, i, pop(), ins[2])
                            else:
                                idx = stack[-n:]
                                del stack[-n:]
                                base = pop()
                                _set_element(base, idx, pop(), ins[2])
                            ip += 1
                        elif op == OP.STORE_ELEM_LL:
                            _set_element1((fvars[ins[1]] or frame.var(ins[1])), _load((fvars[ins[2]] or frame.var(ins[2]))), pop(), ins[3])
                            ip += 1
                        elif op == OP.LOCAL_SUB_CONST:
                            push(_sub(_load((fvars[ins[1]] or frame.var(ins[1]))), ins[2]))
                            ip += 1
                        elif op == OP.LOAD_ELEM2_LLL:
                            push(_element2((fvars[ins[1]] or frame.var(ins[1])), _load((fvars[ins[2]] or frame.var(ins[2]))), _load((fvars[ins[3]] or frame.var(ins[3]))),
                                          ins[4]))
                            ip += 1
                        elif op == OP.FOR_TEST:
                            t = ins[1]
                            ref = temps[t]
                            end = temps[t + 1]
                            step = temps[t + 2]
                            if ref.__class__ is Slot and (c := ref.c[ref.k]).__class__ is int and end.__class__ is int \
                                    and step.__class__ is int:
                                go = c > end if step > 0 else c < end       # for_done, INTs (STEP is not 0)
                            else:
                                go = for_done(temps[t].get(), end, step)
                            if go:
                                ip = ins[2]
                            else:
                                ip += 1
                        elif op == OP.LOAD_INDEX:
                            n = ins[1]
                            idx = stack[-n:]
                            del stack[-n:]
                            stack[-1] = _element(stack[-1], idx, ins[2])
                            ip += 1
                        elif op == OP.INDEX:
                            n = ins[1]
                            idx = [None if x is None else _array_index(x) for x in stack[-n:]]
                            del stack[-n:]
                            stack[-1] = rt.index(stack[-1], idx, ins[2])
                            ip += 1
                        elif op == OP.ASSIGN:
                            ref = pop()
                            _store(ref, pop())
                            ip += 1
                        elif op == OP.LT:
                            b = pop()
                            stack[-1] = _lt(stack[-1], b)
                            ip += 1
                        elif op == OP.LE:
                            b = pop()
                            stack[-1] = _le(stack[-1], b)
                            ip += 1
                        elif op == OP.GT:
                            b = pop()
                            stack[-1] = _gt(stack[-1], b)
                            ip += 1
                        elif op == OP.GE:
                            b = pop()
                            stack[-1] = _ge(stack[-1], b)
                            ip += 1
                        elif op == OP.EQ:
                            b = pop()
                            stack[-1] = _eq(stack[-1], b)
                            ip += 1
                        elif op == OP.NE:
                            b = pop()
                            stack[-1] = _ne(stack[-1], b)
                            ip += 1
                        elif op == OP.BINOP:
                            b = pop()
                            a = stack[-1]
                            # "/" inline (krl.semantics.values.binary_op): INT / INT truncates
                            # toward zero, REAL / REAL divides; zero divisors and every other
                            # case take the runtime's call (its error, its INT range check)
                            if ins[1] == "/" and b.__class__ is a.__class__ and b != 0:
                                if a.__class__ is float:
                                    stack[-1] = a / b
                                elif a.__class__ is int and INT_MIN <= (v := (abs(a) // abs(b) if (a >= 0) == (b >= 0)
                                                                        else -(abs(a) // abs(b)))) <= INT_MAX:
                                    stack[-1] = v
                                else:
                                    stack[-1] = rt.binary_op(ins[1], a, b)
                            else:
                                stack[-1] = rt.binary_op(ins[1], a, b)
                            ip += 1
                        elif op == OP.REF_MOD:
                            push(mrefs[ins[1]])
                            ip += 1
                        elif op == OP.LOAD_GLOBAL or op == OP.REF_GLOBAL or op == OP.STORE_GLOBAL:
                            g = ins[1]
                            ref = grefs[g]
                            if ref is None:
                                ref = rt.storage_ref(code.gstorage[g], frame)
                                grefs[g] = ref
                            if op == OP.LOAD_GLOBAL:
                                push(_load(ref))
                            elif op == OP.REF_GLOBAL:
                                push(ref)
                            else:
                                _store(ref, pop())
                            ip += 1
                        elif op == OP.FIELD:
                            stack[-1] = rt.field(stack[-1], ins[1], ins[2])
                            ip += 1
                        elif op == OP.END_THUNK:
                            return stack[-1] if len(stack) > 8 else None     # STACK_BASE
                        elif op == OP.LOAD_TEMP:
                            push(temps[ins[1]])
                            ip += 1
                        elif op == OP.STORE_TEMP:
                            temps[ins[1]] = pop()
                            ip += 1
                        elif op == OP.JUMP_IF_TRUE:
                            v = pop()
                            if v is True:
                                ip = ins[1]
                            elif v is False or not rt.to_bool(v):
                                ip += 1
                            else:
                                ip = ins[1]
                        elif op == OP.NONE:
                            push(None)
                            ip += 1
                        elif op == OP.POP:
                            pop()
                            ip += 1
                        elif op == OP.DEREF:
                            stack[-1] = _read_value(stack[-1])
                            ip += 1
                        elif op == OP.FOR_PREP:
                            t = ins[1]
                            step = pop()
                            end = pop()
                            start = pop()
                            temps[t] = pop()
                            if not (end.__class__ is int and step.__class__ is int and step != 0):
                                end, step = _for_limits(end, step)       # (two INTs: for_limits' result)
                            temps[t + 1] = end
                            temps[t + 2] = step
                            temps[t + 3] = min(end, INT_MAX) if step.__class__ is int and step > 0 else -math.inf
                            push(start)
                            ip += 1
                        elif op == OP.FOR_INIT:
                            ref = temps[ins[1]]
                            v = pop()
                            # store's fast path (slots.py) for an INT counter
                            if (ref.__class__ is Slot and ref.type is T_INT and v.__class__ is int and not ref.readonly
                                    and ref.on_write is None and INT_MIN <= v <= INT_MAX):
                                ref.c[ref.k] = v
                            else:
                                _store(ref, v)
                            ip += 1
                        elif (op == OP.AGG or op == OP.JUMP_IF_NONE or op == OP.HALT or op == OP.WAIT_FOR or
                              op == OP.WAIT_SEC or op == OP.CONTINUE or op == OP.ON_ERROR_PROCEED or
                              op == OP.EXIT_SIGNAL or op == OP.GOTO_FAIL or op == OP.RAISE or
                              op == OP.INT_DECL or op == OP.INT_CTL or op == OP.BRAKE or op == OP.STUB or
                              op == OP.CYCLIC_ASSIGN or op == OP.ANOUT_ON or op == OP.ANIN_ON or op == OP.CYCLIC_OFF or
                              op == OP.RESUME or op == OP.TRIG_FIND or op == OP.TRIG_PACK or op == OP.TRIGGER or
                              op == OP.TRIG_INVOKE or op == OP.MOTION or op == OP.SPL_BEGIN or
                              op == OP.SPL_TRIG_BEGIN or op == OP.SPL_TRIG_END or op == OP.SPL_SEG or
                              op == OP.SPLINE):
                            # the cold opcodes (statements of motion, interrupts, I/O, ...): one
                            # method each (VM._cold_NAME), so the loop stays the hot path
                            if dirty:                   # the quiet statement's frame.line and task.at (flush)
                                frame.line = info.line
                                task.at = info
                                dirty = False
                            rt.steps += unsaved
                            unsaved = 0
                            ip = cold[op](ins, code, frame, temps, stack, ip)
                            left = task.quiet - rt.steps if task is not None else 0
                        else:
                            raise RuntimeError(f"bad opcode {op} at {ip} in {code.name}")
                except KrlRuntimeError as e:
                    if dirty:                   # the quiet statement's frame.line and task.at (flush)
                        frame.line = info.line
                        task.at = info
                        dirty = False
                    reg = code.iregions[ip]
                    if reg is None:
                        raise
                    e.at(code.file, reg.line)
                    if reg.kind != "G" or thunk or not proceed:
                        raise
                    proceed = False
                    rt.steps += unsaved
                    unsaved = 0
                    rt.record_error(e, frame)
                    left = task.quiet - rt.steps if task is not None else 0
                    del stack[8:]         # STACK_BASE
                    ip = reg.end
        except BaseException:
            if dirty:                   # the quiet statement's frame.line and task.at (flush)
                frame.line = info.line
                task.at = info
                dirty = False
            raise
        finally:
            rt.steps += unsaved

    @staticmethod
    def pairs(stack: list, n: int) -> list:
        """Pop ``n`` WITH (reference, value) pairs."""
        if not n:
            return []
        items = stack[len(stack) - 2 * n:]
        del stack[len(stack) - 2 * n:]
        return [(items[2 * i], items[2 * i + 1]) for i in range(n)]


# The linked code of each routine, per checked workspace: a routine is compiled and linked once
# per process for each loop numbering (the two interpreters of a conformance case, the programs
# of one backup, the runs of a test share it), and dropped with its workspace. The VM's caches
# live here, not on the AST.
_LINKED: dict = {}       # id(workspace) -> (weak reference to it, {(id(routine), id(dispatch)): ...})


def linked_code(ws, routine, dispatch) -> Linked:
    """The Linked form of `routine` (a Routine of the checked workspace `ws`) for the loop
    numbering `dispatch`, compiled (interp/vm/compiler.py) and linked on first use."""
    entry = _LINKED.get(id(ws))
    if entry is None or entry[0]() is not ws:
        entry = _LINKED[id(ws)] = (weakref.ref(ws, lambda _ref, key=id(ws): _LINKED.pop(key, None)), {})
    per = entry[1]
    key = (id(routine), id(dispatch))
    got = per.get(key)
    if got is None or got[0] is not routine:
        got = per[key] = (routine, link(compile_routine(routine), dispatch))
    return got[1]


# The loops: VM.run above is the source of every handler (runnable: VM(rt, loop="source"),
# dispatching on the opcode numbers themselves); interp/vm/loop.py is generated from it
# (python -m interp.vm.gen_loop) and dispatches on its own numbering. `make` compiles loop.py
# with Cython (interp/vm/build.py) into an extension beside it, which Python imports in its
# place; it runs (loop="generated") only when it was built from this vm.py, else loop.py does.
SOURCE_DISPATCH = [o.number for o in OP.OPS]


def _python_loop():
    """interp/vm/loop.py itself, imported from its file (also when the extension exists)."""
    name = "interp.vm._loop_python"
    mod = sys.modules.get(name)
    if mod is None:
        spec = importlib.util.spec_from_file_location(name, Path(__file__).with_name("loop.py"))
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
    return mod


def _current(mod) -> bool:
    return mod.VM_SOURCE == hashlib.sha256(Path(__file__).read_bytes()).hexdigest()


from . import loop as _loop  # noqa: E402

COMPILED = not _loop.__file__.endswith(".py") and _current(_loop)
if not COMPILED:
    _loop = _python_loop()
GENERATED_DISPATCH, _generated_run = _loop.DISPATCH, _loop.run
