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

Routines are compiled on their first call (the compiler needs the module's data list and
the runtime's resolver) and kept per routine.
"""

from __future__ import annotations

import ast
import copy
import heapq
import inspect
import itertools
import math
import operator

from interp.runtime.builtins import ValueRef
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
from .assembler import Code, Region, encode
from .compiler import compile_routine


# runtime functions the loop calls as ``_name`` (closure variables: no global lookup, no
# per-call binding)
HELPERS = ("load", "store", "element", "element1", "element2", "set_element", "set_element1", "component",
           "set_component", "add", "sub", "mul", "lt", "le", "gt", "ge", "eq", "ne", "for_next", "for_limits",
           "read_value", "array_index")


def _specialize(fn):
    """Compile the dispatch loop ``fn`` for speed, from its own source, with line numbers
    kept (tracebacks and coverage point into this file):

    * the :data:`HELPERS` become closure variables ``_name``;
    * the chain ``if op == <opcode>: ... elif op == <opcode>: ...``, hottest first, becomes
      a binary search, ``if op < k:``, shaped as a Huffman tree over the opcodes with
      Zipf weights by rank in the chain (weight 1/rank): the hottest opcode is found after
      two tests, the tenth after six, the 100th after nine (at most ten), where the chain
      needs one test per opcode ahead of it. The loop therefore dispatches on its own
      numbering of the opcodes, the leaves of that tree from left to right;
      ``fn.dispatch[opcode number]`` is that number (:func:`decode` writes it), and every
      ``OP.NAME`` in ``fn`` becomes it.
    """
    path = inspect.getsourcefile(fn)
    with open(path, encoding="utf-8") as f:
        module = ast.parse(f.read(), path)
    func = next(n for n in ast.walk(module) if isinstance(n, ast.FunctionDef) and n.name == fn.__name__
                and any(isinstance(d, ast.Name) and d.id == "_specialize" for d in n.decorator_list))
    func.decorator_list = []
    chain = next(n for n in ast.walk(func) if isinstance(n, ast.If) and _chain_ops(n.test))
    branches = []
    node = chain
    while True:
        branches.append((_chain_ops(node.test), node.body))
        if len(node.orelse) == 1 and isinstance(node.orelse[0], ast.If) and _chain_ops(node.orelse[0].test):
            node = node.orelse[0]
            continue
        break
    body_of, weight = {}, {}
    for rank, (names, body) in enumerate(branches, 1):
        for name in names:
            body_of.setdefault(name, body)
            weight.setdefault(name, 1.0 / rank / len(names))
    missing = set(OP.BY_NAME) - set(body_of)
    if missing:
        raise AssertionError(f"opcodes without a branch in the dispatch loop: {sorted(missing)}")
    root = _huffman(weight)
    order: list = []
    _leaves(root, order)
    number = {name: i for i, name in enumerate(order)}
    search = _search(root, body_of, number, set())
    _replace(func, chain, search if isinstance(search, ast.If) else search[0])
    func = _OpNumbers(number).visit(func)
    factory = ast.FunctionDef(
        "_factory", ast.arguments([], [], None, [], [], None, []),
        [ast.Assign([ast.Name(f"_{n}", ast.Store())], ast.Name(n, ast.Load())) for n in HELPERS]
        + [func, ast.Return(ast.Name(fn.__name__, ast.Load()))], [], None)
    mod = ast.Module([factory], [])
    _locate(mod, chain)
    ns: dict = {}
    exec(compile(mod, inspect.getsourcefile(fn), "exec"), fn.__globals__, ns)  # noqa: S102
    out = ns["_factory"]()
    out.dispatch = [number[o.name] for o in OP.OPS]
    return out


class _OpNumbers(ast.NodeTransformer):
    """``OP.NAME`` -> the loop's number of the opcode."""

    def __init__(self, number: dict) -> None:
        self.number = number

    def visit_Attribute(self, node):
        if isinstance(node.value, ast.Name) and node.value.id == "OP" and node.attr in self.number:
            return ast.copy_location(ast.Constant(self.number[node.attr]), node)
        return self.generic_visit(node)


def _chain_ops(test) -> list | None:
    """The opcode names of a dispatch test ``op == <opcode> [or op == <opcode> ...]``, else None."""
    parts = test.values if isinstance(test, ast.BoolOp) and isinstance(test.op, ast.Or) else [test]
    out = []
    for p in parts:
        if not (isinstance(p, ast.Compare) and isinstance(p.left, ast.Name) and p.left.id == "op"
                and len(p.ops) == 1 and isinstance(p.ops[0], ast.Eq)):
            return None
        c = p.comparators[0]
        if not (isinstance(c, ast.Attribute) and isinstance(c.value, ast.Name) and c.value.id == "OP"):
            return None
        out.append(c.attr)
    return out


def _huffman(weight: dict):
    """A Huffman tree over the opcode names: a name (leaf) or a pair (left, right)."""
    tie = itertools.count()
    heap = [(w, next(tie), name) for name, w in sorted(weight.items())]
    heapq.heapify(heap)
    while len(heap) > 1:
        wa, _, a = heapq.heappop(heap)
        wb, _, b = heapq.heappop(heap)
        heapq.heappush(heap, (wa + wb, next(tie), (a, b)))
    return heap[0][2]


def _leaves(node, out: list) -> None:
    if isinstance(node, tuple):
        _leaves(node[0], out)
        _leaves(node[1], out)
    else:
        out.append(node)


def _search(node, body_of: dict, number: dict, used: set):
    """The statements that dispatch ``op`` within the subtree ``node`` (``used``: the
    branch bodies already placed)."""
    if not isinstance(node, tuple):
        body = body_of[node]
        if id(body) in used:           # a branch of several opcodes: one copy per leaf
            return copy.deepcopy(body)
        used.add(id(body))
        return body
    right = []
    _leaves(node[1], right)
    lo = _search(node[0], body_of, number, used)
    hi = _search(node[1], body_of, number, used)
    test = ast.Compare(ast.Name("op", ast.Load()), [ast.Lt()], [ast.Constant(number[right[0]])])
    return [ast.If(test, lo, hi)]


def _replace(tree, old, new) -> None:
    for parent in ast.walk(tree):
        for _, value in ast.iter_fields(parent):
            if isinstance(value, list) and old in value:
                value[value.index(old)] = new
                return
    raise AssertionError("dispatch chain not found")


def _locate(tree, where) -> None:
    """Give the new dispatch tests the line of the chain's first test."""
    for node in ast.walk(tree):
        if isinstance(node, (ast.stmt, ast.expr)) and not hasattr(node, "lineno"):
            ast.copy_location(node, where)
    ast.fix_missing_locations(tree)


# the VM's forms of operand kinds y and o (opcodes.py)
_VALUE_CLASS = {"I": int, "R": float, "B": bool}
_COMPARE = {"<": (operator.lt, lt), "<=": (operator.le, le), ">": (operator.gt, gt), ">=": (operator.ge, ge),
            "==": (operator.eq, eq), "<>": (operator.ne, ne)}


def decode(code: Code) -> tuple[list, list]:
    """The VM's form of assembled code: one tuple ``(opcode, operand, ...)`` per
    instruction, with constants, names and statement infos resolved and jump targets as
    instruction numbers; and the error region of each instruction."""
    dispatch = VM.run.dispatch
    words = code.words
    starts = OP.instruction_starts(words)
    index = {a: i for i, a in enumerate(starts)}
    index[len(words)] = len(starts)
    prog = []
    regions = []
    moved: dict = {}     # guarded regions with their end as an instruction number
    for a in starts:
        info = OP.OPS[words[a]]
        ins = [dispatch[info.number]]
        for j, k in enumerate(info.operands):
            w = words[a + 1 + j]
            if k in "cnf":
                w = code.consts[w]
            elif k == "x":
                w = code.infos[w]
            elif k == "l":
                w = index[w]
            elif k == "s" or k == "v":
                w = code.lkeys[w]
            elif k == "y":
                w = _VALUE_CLASS.get(code.consts[w])
            elif k == "o":
                w = _COMPARE[code.consts[w]]
            elif k == "k":
                w = code.consts[w]
                w = (w, w.upper())
            ins.append(w)
        prog.append(tuple(ins))
        r = code.regions[a]
        if r is not None and r.kind == "G":
            got = moved.get(id(r))
            if got is None:
                got = moved[id(r)] = Region("G", r.line, index[r.end])
            r = got
        regions.append(r)
    return prog, regions


class VM:
    def __init__(self, rt) -> None:
        self.rt = rt
        self.codes: dict = {}          # id(routine) -> Code
        # the runtime's statement hooks, bound once (the loop takes them at each call)
        self.hooks = (rt.before_statement, rt.loop_tick, rt.take_error_proceed, rt.quiet_limit)

    # ------------------------------------------------------------------ entry points
    def run_program(self, module_name: str | None = None) -> None:
        """Body of the robot (or a submit) task: call the main routine of the module."""
        self.invoke(self.rt.main_routine(module_name), [], None)

    def code_for(self, module, routine, frame=None) -> Code:
        code = self.codes.get(id(routine))
        if code is None:
            lst = compile_routine(self.rt, module, routine, frame)
            code = encode(lst)   # no text on the way
            code.routine = routine
            code.module = module
            rt = self.rt
            # the storage the front end resolved: module slots bound now (the data lists are
            # loaded), global slots on first use (Runtime.storage_ref), frame slots by number
            code.mrefs = [rt.storage_ref(lst.storages[n.upper()], None) for n in code.mnames]
            code.gstorage = [lst.storages[n.upper()] for n in code.gnames]
            code.grefs = [None] * len(code.gnames)
            code.lkeys = list(range(len(code.lnames)))
            code.callees = lst.callees
            code.types = lst.types
            code.prog, code.iregions = decode(code)
            self.codes[id(routine)] = code
        return code

    # ------------------------------------------------------------------ calls
    def invoke(self, target, args: list, caller, catch_resume: bool = True):
        """Run routine ``target`` = (module, Routine) with reference ``args`` (the
        runtime's call protocol, Runtime.run_routine)."""
        return self.rt.run_routine(target, args, caller, self.exec_routine, catch_resume)

    def exec_routine(self, frame):
        """Run the code of the routine of ``frame`` (compiled on its first call); the value
        of its RETURN (None for a DEF)."""
        routine = frame.routine
        code = self.codes.get(id(routine)) or self.code_for(frame.module, routine, frame)
        return self.run(code, frame, [None] * code.ntemps, 0, [])

    def call(self, code: Code, ip: int, name: str, args: list, frame, flags: str):
        """A CALL whose routine is not known yet (the loop calls a known one itself):
        a built-in, a stub, or a routine found now and kept for this call site."""
        rt = self.rt
        target = rt.callee(code.callees[name.upper()])
        if target is None:
            if rt.is_native(name):
                return rt.call_builtin(name, args)
            return rt.stub_call(name, flags == "E")
        code.callsites[ip] = target
        return self.invoke(target, args, frame, "N" not in flags)

    def thunk(self, code: Code, frame, temps: list, ip: int, stack: list | None = None):
        """A callable that runs the thunk at ``ip`` of ``code`` in the activation (``frame``,
        ``temps``) that declared it."""
        return lambda: self.run(code, frame, temps, ip, list(stack) if stack else [], True)

    # ------------------------------------------------------------------ the loop
    @_specialize
    def run(self, code: Code, frame, temps: list, ip: int, stack: list, thunk: bool = False):
        """Run ``code`` from ``ip`` in the activation of ``frame`` (its runtime Frame) with
        the temporaries ``temps``; returns the value of RETURN,
        or of the thunk at END_THUNK. The ``_name`` helpers are the runtime functions of
        :data:`HELPERS`, closure variables of the loop (see :func:`_specialize`)."""
        rt = self.rt
        prog = code.prog
        mrefs = code.mrefs
        grefs = code.grefs
        store = frame.store          # store variables (operand kind v): Frame.store keys
        fvars = frame.vars
        push = stack.append
        pop = stack.pop
        before, tick, take_error_proceed, quiet_limit = self.hooks
        task = rt.current_task
        proceed = False
        while True:
            try:
                while True:
                    ins = prog[ip]
                    op = ins[0]
                    # hottest first (measured on the benchmark): the rank weights the search
                    # tree _specialize makes of this chain
                    if op == OP.STMT_G:
                        info = ins[1]
                        frame.line = info.line
                        n = rt.steps
                        if n < task.quiet and not info.stops:     # a quiet step (Runtime.quiet_limit)
                            rt.steps = n + 1
                            task.at = info
                            proceed = False
                        else:
                            before(info)
                            proceed = take_error_proceed()
                            task.quiet = quiet_limit(task)
                        ip += 1
                    elif op == OP.LOAD_ELEM1_V:
                        a = store[ins[1]]
                        i = store[ins[2]]
                        if i.__class__ is int and 0 < i <= a.dims[0] and (v := a.data[i - 1]) is not UNSET:
                            push(v)
                        else:
                            push(_element1(fvars[ins[1]], _load(fvars[ins[2]]), ins[3]))
                        ip += 1
                    elif op == OP.LOAD_FAST:
                        v = store[ins[1]]
                        push(v if v is not UNSET else _load(fvars[ins[1]]))
                        ip += 1
                    elif op == OP.JUMP_TICK:
                        n = rt.steps
                        if n < task.quiet and not ins[1].cond_stops:
                            rt.steps = n + 1
                        else:
                            tick(ins[1])
                            task.quiet = quiet_limit(task)
                        ip = ins[2]
                    elif op == OP.CONST:
                        push(ins[1])
                        ip += 1
                    elif op == OP.FOR_NEXT_FAST:
                        t = ins[2]
                        c = store[ins[1]]
                        if c.__class__ is int and (c := c + temps[t + 2]) <= temps[t + 3]:
                            store[ins[1]] = c
                            go = True
                        else:
                            go = _for_next(temps[t], temps[t + 1], temps[t + 2], ins[3])
                        if go:
                            n = rt.steps
                            if n < task.quiet:
                                rt.steps = n + 1
                            else:
                                tick(ins[3])
                                task.quiet = quiet_limit(task)
                            ip = ins[4]
                        else:
                            ip += 1
                    elif op == OP.LOAD_FAST2:
                        v = store[ins[1]]
                        push(v if v is not UNSET else _load(fvars[ins[1]]))
                        v = store[ins[2]]
                        push(v if v is not UNSET else _load(fvars[ins[2]]))
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
                        if v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                            store[ins[1]] = v
                        else:
                            _store(fvars[ins[1]], v)
                        ip += 1
                    elif op == OP.STORE_ELEM1:
                        i = pop()
                        v = pop()
                        a = store[ins[1]]
                        t = ins[3]
                        if i.__class__ is int and 0 < i <= a.dims[0] and v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                            a.data[i - 1] = v
                        else:
                            _set_element1(fvars[ins[1]], i, v, ins[2])
                        ip += 1
                    elif op == OP.SUBC_FAST:
                        a = store[ins[1]]
                        b = ins[2]
                        t = ins[4]
                        ca = a.__class__
                        if ca is b.__class__ and ca is t and (ca is float or (ca is int and INT_MIN <= (v := a - b) <= INT_MAX)):
                            store[ins[3]] = a - b if ca is float else v
                        else:
                            _store(fvars[ins[3]], _sub(a if a is not UNSET else _load(fvars[ins[1]]), b))
                        ip += 1
                    elif op == OP.IF_NOT_VC:
                        a = store[ins[1]]
                        b = ins[2]
                        ca = a.__class__
                        cb = b.__class__
                        f = ins[3]
                        if (f[0](a, b) if (ca is int or ca is float) and (cb is int or cb is float)
                                else f[1](a if a is not UNSET else _load(fvars[ins[1]]), b)):
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
                        a = store[ins[1]]
                        i = store[ins[2]]
                        v = pop()
                        t = ins[4]
                        if i.__class__ is int and 0 < i <= a.dims[0] and v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                            a.data[i - 1] = v
                        else:
                            _set_element1(fvars[ins[1]], _load(fvars[ins[2]]), v, ins[3])
                        ip += 1
                    elif op == OP.FAST_ADD_CONST:
                        a = store[ins[1]]
                        b = ins[2]
                        if a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a + b) <= INT_MAX:
                            push(v)
                        elif a.__class__ is float and b.__class__ is float:
                            push(a + b)
                        else:
                            push(_add(a if a is not UNSET else _load(fvars[ins[1]]), b))
                        ip += 1
                    elif op == OP.REF_LOCAL:
                        push(fvars[ins[1]])
                        ip += 1
                    elif op == OP.IF_NOT_VV:
                        a = store[ins[1]]
                        b = store[ins[2]]
                        ca = a.__class__
                        cb = b.__class__
                        f = ins[3]
                        if (f[0](a, b) if (ca is int or ca is float) and (cb is int or cb is float)
                                else f[1](a if a is not UNSET else _load(fvars[ins[1]]), b if b is not UNSET else _load(fvars[ins[2]]))):
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
                        base = fvars[ins[1]]
                        if base.__class__ is Slot and (x := base.c[base.k]).__class__ is Struct and (
                                (x := x.f.get(ins[2][1])).__class__ is float or x.__class__ is int
                                or x.__class__ is bool):
                            push(x)
                        else:
                            push(_component(base, ins[2][0], ins[3]))
                        ip += 1
                    elif op == OP.STORE_FIELD_L:
                        _set_component(fvars[ins[1]], ins[2][0], pop(), ins[3])
                        ip += 1
                    elif op == OP.UNOP:
                        stack[-1] = rt.unary_op(ins[1], stack[-1])
                        ip += 1
                    elif op == OP.JUMP_IF_FALSE:
                        if rt.to_bool(pop()):
                            ip += 1
                        else:
                            ip = ins[1]
                    elif op == OP.LOAD_ELEM2:
                        j = pop()
                        i = stack[-1]
                        a = store[ins[1]]
                        n, m = a.dims
                        if i.__class__ is int and j.__class__ is int and 0 < i <= n and 0 < j <= m \
                                and (v := a.data[(i - 1) * m + j - 1]) is not UNSET:
                            stack[-1] = v
                        else:
                            stack[-1] = _element2(fvars[ins[1]], i, j, ins[2])
                        ip += 1
                    elif op == OP.LOAD_ELEM2_VV:
                        a = store[ins[1]]
                        i = store[ins[2]]
                        j = store[ins[3]]
                        n, m = a.dims
                        if i.__class__ is int and j.__class__ is int and 0 < i <= n and 0 < j <= m \
                                and (v := a.data[(i - 1) * m + j - 1]) is not UNSET:
                            push(v)
                        else:
                            push(_element2(fvars[ins[1]], _load(fvars[ins[2]]), _load(fvars[ins[3]]), ins[4]))
                        ip += 1
                    elif op == OP.STMT:
                        info = ins[1]
                        if not thunk:
                            frame.line = info.line
                        n = rt.steps
                        if n < task.quiet and not info.stops:
                            rt.steps = n + 1
                            task.at = info
                        else:
                            before(info)
                            task.quiet = quiet_limit(task)
                        ip += 1
                    elif op == OP.STORE_FIELD:
                        base = pop()
                        _set_component(base, ins[1][0], pop(), ins[2])
                        ip += 1
                    elif op == OP.TICK:
                        n = rt.steps
                        if n < task.quiet and not ins[1].cond_stops:
                            rt.steps = n + 1
                        else:
                            tick(ins[1])
                            task.quiet = quiet_limit(task)
                        ip += 1
                    elif op == OP.MUL_CONST:
                        b = ins[1]
                        a = stack[-1]
                        if a.__class__ is float and b.__class__ is float:
                            stack[-1] = a * b
                        elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a * b) <= INT_MAX:
                            stack[-1] = v
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
                        if target is not None:
                            v = self.invoke(target, args, frame, "N" not in flags)
                        else:
                            v = self.call(code, ip, ins[1], args, frame, flags)
                        if flags == "E":
                            push(v if v is not None else function_result(ins[1], v))
                        ip += 1
                    elif op == OP.STORE_ELEM2:
                        j = pop()
                        i = pop()
                        v = pop()
                        a = store[ins[1]]
                        n, m = a.dims
                        t = ins[3]
                        if i.__class__ is int and j.__class__ is int and 0 < i <= n and 0 < j <= m and v.__class__ is t and (t is not int or INT_MIN <= v <= INT_MAX):
                            a.data[(i - 1) * m + j - 1] = v
                        else:
                            _set_element(fvars[ins[1]], [i, j], v, ins[2])
                        ip += 1
                    elif op == OP.ADDC_FAST:
                        a = store[ins[1]]
                        b = ins[2]
                        t = ins[4]
                        ca = a.__class__
                        if ca is b.__class__ and ca is t and (ca is float or (ca is int and INT_MIN <= (v := a + b) <= INT_MAX)):
                            store[ins[3]] = a + b if ca is float else v
                        else:
                            _store(fvars[ins[3]], _add(a if a is not UNSET else _load(fvars[ins[1]]), b))
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
                        return v if code.kind == "DEFFCT" else None
                    elif op == OP.END:
                        if code.kind == "DEFFCT":
                            raise ended_without_return(code.routine, frame.line)
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
                        push(_load(fvars[ins[1]]))
                        ip += 1
                    elif op == OP.STORE_LOCAL:
                        _store(fvars[ins[1]], pop())
                        ip += 1
                    elif op == OP.FAST_SUB_CONST:
                        a = store[ins[1]]
                        b = ins[2]
                        if a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a - b) <= INT_MAX:
                            push(v)
                        elif a.__class__ is float and b.__class__ is float:
                            push(a - b)
                        else:
                            push(_sub(a if a is not UNSET else _load(fvars[ins[1]]), b))
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
                        if code.kind == "DEFFCT":
                            raise return_without_value(code.routine, frame.line)
                        return None
                    elif op == OP.LOAD_ELEM1:
                        a = store[ins[1]]
                        i = stack[-1]
                        if i.__class__ is int and 0 < i <= a.dims[0] and (v := a.data[i - 1]) is not UNSET:
                            stack[-1] = v
                        else:
                            stack[-1] = _element1(fvars[ins[1]], i, ins[2])
                        ip += 1
                    elif op == OP.LOAD_ELEM_LL:
                        push(_element1(fvars[ins[1]], _load(fvars[ins[2]]), ins[3]))
                        ip += 1
                    elif op == OP.LOAD_LOCAL2:
                        push(_load(fvars[ins[1]]))
                        push(_load(fvars[ins[2]]))
                        ip += 1
                    elif op == OP.FOR_NEXT:
                        t = ins[1]
                        if _for_next(temps[t], temps[t + 1], temps[t + 2], ins[2]):
                            n = rt.steps
                            if n < task.quiet and not ins[2].cond_stops:
                                rt.steps = n + 1
                            else:
                                tick(ins[2])
                                task.quiet = quiet_limit(task)
                            ip = ins[3]
                        else:
                            ip += 1
                    elif op == OP.LOCAL_ADD_CONST:
                        push(_add(_load(fvars[ins[1]]), ins[2]))
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
                        _set_element1(fvars[ins[1]], _load(fvars[ins[2]]), pop(), ins[3])
                        ip += 1
                    elif op == OP.LOCAL_SUB_CONST:
                        push(_sub(_load(fvars[ins[1]]), ins[2]))
                        ip += 1
                    elif op == OP.LOAD_ELEM2_LLL:
                        push(_element2(fvars[ins[1]], _load(fvars[ins[2]]), _load(fvars[ins[3]]),
                                      ins[4]))
                        ip += 1
                    elif op == OP.FOR_TEST:
                        t = ins[1]
                        if for_done(temps[t].get(), temps[t + 1], temps[t + 2]):
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
                        stack[-1] = rt.binary_op(ins[1], stack[-1], b)
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
                        return stack[-1] if stack else None
                    elif op == OP.LOAD_TEMP:
                        push(temps[ins[1]])
                        ip += 1
                    elif op == OP.STORE_TEMP:
                        temps[ins[1]] = pop()
                        ip += 1
                    elif op == OP.JUMP_IF_TRUE:
                        if rt.to_bool(pop()):
                            ip = ins[1]
                        else:
                            ip += 1
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
                        temps[t + 1], temps[t + 2] = end, step = _for_limits(end, step)
                        temps[t + 3] = min(end, INT_MAX) if step.__class__ is int and step > 0 else -math.inf
                        push(start)
                        ip += 1
                    elif op == OP.FOR_INIT:
                        _store(temps[ins[1]], pop())
                        ip += 1
                    elif op == OP.AGG:
                        names = ins[2]
                        keys = names.split(",") if names else []
                        k = len(keys)
                        vals = stack[len(stack) - k:]
                        del stack[len(stack) - k:]
                        push(rt.aggregate(code.types.get(ins[1].upper()) if ins[1] else None,
                                          list(zip(keys, vals))))
                        ip += 1
                    elif op == OP.JUMP_IF_NONE:
                        if stack[-1] is None:
                            pop()
                            ip = ins[1]
                        else:
                            ip += 1
                    elif op == OP.HALT:
                        rt.halt()
                        ip += 1
                    elif op == OP.WAIT_FOR:
                        rt.wait_for(self.thunk(code, frame, temps, ins[1]))
                        ip += 1
                    elif op == OP.WAIT_SEC:
                        rt.wait_sec(pop())
                        ip += 1
                    elif op == OP.CONTINUE:
                        rt.set_continue(ins[1])
                        ip += 1
                    elif op == OP.ON_ERROR_PROCEED:
                        rt.on_error_proceed()
                        ip += 1
                    elif op == OP.EXIT_SIGNAL:
                        raise ExitSignal()
                    elif op == OP.GOTO_FAIL:
                        raise label_not_found(ins[1], code.routine, frame.line)
                    elif op == OP.RAISE:
                        line = ins[2]
                        raise KrlRuntimeError(ins[1], None, code.file if line else None, line or None)
                    elif op == OP.INT_DECL:
                        cond = self.thunk(code, frame, temps, ins[1])
                        rt.interrupt_decl(pop(), lambda c=cond: rt.to_bool(c(), "interrupt condition"),
                                          self.thunk(code, frame, temps, ins[2]), ins[3], frame,
                                          ins[4] == "G", ins[5])
                        ip += 1
                    elif op == OP.INT_CTL:
                        n = pop() if ins[2] == "P" else None
                        rt.interrupt_ctl(ins[1], n)
                        ip += 1
                    elif op == OP.BRAKE:
                        rt.brake(ins[1] == "F")
                        ip += 1
                    elif op == OP.STUB:
                        rt.stub_statement(ins[1])
                        ip += 1
                    elif op == OP.CYCFLAG:
                        ref = pop()
                        _store(ref, pop())
                        value = self.thunk(code, frame, temps, ins[1])
                        rt.cyclic_on(("CYCFLAG", ref.name), lambda r=ref, f=value: rt.assign(r, f()))
                        ip += 1
                    elif op == OP.ANOUT_ON:
                        flags = ins[2]
                        hi = pop() if "H" in flags else None
                        lo = pop() if "L" in flags else None
                        ref = pop()
                        lo, hi = anout_limits(lo, hi)
                        value = self.thunk(code, frame, temps, ins[3])

                        def anout(ref=ref, value=value, lo=lo, hi=hi):
                            ref.set(anout_value(value(), lo, hi))
                        anout()
                        rt.cyclic_on(("ANOUT", ins[1]), anout)
                        ip += 1
                    elif op == OP.ANIN_ON:
                        ref = pop()
                        value = self.thunk(code, frame, temps, ins[2])

                        def anin(ref=ref, value=value):
                            rt.assign(ref, value())
                        anin()
                        key = ins[1]
                        if key is not None:
                            rt.cyclic_on(("ANIN", key), anin)
                        ip += 1
                    elif op == OP.CYCLIC_OFF:
                        rt.cyclic_off((ins[1], ins[2]))
                        ip += 1
                    elif op == OP.RESUME:
                        rt.resume()
                        ip += 1
                    elif op == OP.TRIG_FIND:
                        target = rt.callee(code.callees[ins[1].upper()])
                        push(target)
                        ip = ins[2] if target is None else ip + 1
                    elif op == OP.TRIG_PACK:
                        argc = ins[1]
                        args = stack[len(stack) - argc:]
                        del stack[len(stack) - argc:]
                        stack[-1] = (stack[-1], args)
                        ip += 1
                    elif op == OP.TRIGGER:
                        flags = ins[2]
                        prio = pop() if "P" in flags else None
                        delay = pop()
                        at = pop()
                        action = self.thunk(code, frame, temps, ins[4], [pop()])
                        rt.trigger(action, line=ins[3],
                                   **trigger_args(ins[1], at, delay, prio, "O" in flags))
                        ip += 1
                    elif op == OP.TRIG_INVOKE:
                        target, args = pop()
                        self.invoke(target, args, frame)
                        ip += 1
                    elif op == OP.MOTION:
                        nwith = ins[5]
                        pairs = self.pairs(stack, nwith)
                        flags = ins[4]
                        ca = pop() if "C" in flags else None
                        aux = pop() if "A" in flags else None
                        approx = ins[2]
                        rt.motion(ins[1], pop(), approx.split(",") if approx else [], aux, ca,
                                  ins[3], pairs, code.file, ins[6])
                        ip += 1
                    elif op == OP.SPL_BEGIN:
                        temps[ins[1]] = [[], [], None]     # segments, pending triggers, saved
                        ip += 1
                    elif op == OP.SPL_TRIG_BEGIN:
                        sp = temps[ins[1]]
                        task = rt.current_task
                        sp[2] = task.next_triggers
                        task.next_triggers = []
                        ip += 1
                    elif op == OP.SPL_TRIG_END:
                        sp = temps[ins[1]]
                        task = rt.current_task
                        sp[1] += task.next_triggers
                        task.next_triggers = sp[2]
                        ip += 1
                    elif op == OP.SPL_SEG:
                        pairs = self.pairs(stack, ins[3])
                        flags = ins[2]
                        ca = float(num(pop())) if "C" in flags else None
                        aux = pop() if "A" in flags else None
                        sp = temps[ins[5]]
                        sp[0].append({"kind": ins[1], "target": pop(), "aux": aux, "ca": ca,
                                      "with_": pairs, "triggers": sp[1], "line": ins[4]})
                        sp[1] = []
                        ip += 1
                    elif op == OP.SPLINE:
                        pairs = self.pairs(stack, ins[3])
                        rt.spline(ins[1], temps[ins[5]][0], ins[2], pairs,
                                  code.file, ins[4])
                        ip += 1
                    else:
                        raise RuntimeError(f"bad opcode {op} at {ip} in {code.name}")
            except KrlRuntimeError as e:
                reg = code.iregions[ip]
                if reg is None:
                    raise
                e.at(code.file, reg.line)
                if reg.kind != "G" or thunk or not proceed:
                    raise
                proceed = False
                rt.record_error(e, frame)
                del stack[:]
                ip = reg.end

    @staticmethod
    def pairs(stack: list, n: int) -> list:
        """Pop ``n`` WITH (reference, value) pairs."""
        if not n:
            return []
        items = stack[len(stack) - 2 * n:]
        del stack[len(stack) - 2 * n:]
        return [(items[2 * i], items[2 * i + 1]) for i in range(n)]
