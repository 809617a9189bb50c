"""Every instruction of the KRL VM, defined once (as CPython's ``Python/bytecodes.c``).

An instruction is a function decorated ``@inst``: its name is the opcode's, its parameters are
the operands (annotated with their kind, :data:`interp.vm.declarations.KINDS`), its docstring the one line `krl asm`
readers and docs/architecture.md go by, and its body the handler. The decorator gives the
*stack effect* in CPython's notation, ``"a, b -- res"`` (inputs bottom to top, then outputs;
``args[argc]`` is ``argc`` items, ``prio if "P" in flags`` an item only when the condition on
the operands holds), the instruction's measured frequency (``freq``: executions per 10 000 on
the compute benchmark, interp/bench/bench.src; it weights the dispatch) or ``cold=True``.
A *superinstruction* is ``NAME = macro(PART, PART, ...)``: the instructions it replaces, in order;
its operands are theirs, concatenated, and its handler is their handlers in a row, with the
values that pass from one part to the next kept in locals (the compiler's peephole pass,
interp/vm/compiler.py, fuses exactly these sequences).

interp/vm/gen_loop.py reads this file's text (it is never imported to run) and writes, checked
in and never made at import:

* interp/vm/loop.py: the dispatch loop, :func:`run` below with ``DISPATCH()`` replaced by a
  binary search over the hot instructions' handlers, and one function per cold instruction
  (``COLD``, called through the one branch ``COLD_DISPATCH``);
* interp/vm/opcodes.py: the opcode table (number, operands, stack effect, doc, parts) that the
  compiler, the assembler, `krl asm`, the VM's linker and the tests read;
* interp/vm/loop.pxd: the C types of the loop's locals (:data:`C_LOCALS`) for the Cython build.

What a handler body may use: its operands (an operand of kind ``s v t i m g`` is a C integer in
the compiled loop; ``stmt.line`` of a kind with linked fields is read from the executed tuple,
:data:`KINDS`), its inputs, the loop's locals (:func:`run`), the names imported below, and the
``@inline`` helpers (a helper whose body is one ``return`` is an expression). It assigns its
outputs once on each path. A body that assigns ``ip`` chooses the next instruction on every
path; any other goes on at ``ip + 1``. Only the last part of a macro may jump.

Meaning stays the runtime's (docs/architecture.md, "One meaning"): a hot handler inlines the
common case of a runtime function (a number in a store variable, an in-range index, INT/REAL
arithmetic, a quiet step) and calls that function for every other case, so values and error
messages are the general function's.
"""

from __future__ import annotations

import math

from interp.runtime.natives import ValueRef
from interp.runtime.convert import INT_MAX, INT_MIN
from interp.runtime.errors import ExitSignal, KrlRuntimeError
from interp.runtime.memory import Slot
from interp.runtime.slots import (add as _add, array_index as _array_index,
                                  component as _component, element as _element, element1 as _element1,
                                  element2 as _element2, ended_without_return, for_done, for_limits as _for_limits,
                                  for_next as _for_next, function_result, label_not_found, load as _load, move as _move, mul as _mul,
                                  read_value as _read_value, return_without_value, set_component as _set_component,
                                  set_element as _set_element, set_element1 as _set_element1, store as _store,
                                  sub as _sub)
from interp.runtime.statements import ENTRIES as STATEMENT_ENTRIES, Segments
from interp.runtime.values import UNSET, Struct
from krl.semantics.types import BOOL as T_BOOL, INT as T_INT, REAL as T_REAL

from interp.vm.declarations import inline, inst, macro


# ---------------------------------------------------------------------------- the loop
def run(self, code, frame, temps=None, ip=0, stack=None, thunk=False):
    """Run ``code`` from ``ip`` in the activation of ``frame`` (its runtime Frame) with the
    temporaries ``temps``; returns the value of RETURN, or of the thunk at END_THUNK. ``code``
    None: the body of a call (``VM.body``), the code of the frame's routine from its start."""
    if code is None:
        routine = frame.routine
        code = self.codes.get(id(routine)) or self.code_for(routine)
        temps = [None] * code.ntemps
        stack = [None, None, None, None, None, None, None, None]      # STACK_BASE (vm.py)
    rt = self.rt
    prog = code.prog
    ops = code.ops               # prog's opcodes, one byte each (a C integer when compiled)
    mrefs = code.mrefs
    grefs = code.grefs
    store = frame.store          # store variables (operand kind v): Frame.store
    # the data list of each store array, read from the store when first used: an array's data
    # list is never replaced (values.Arr; convert.assign_into fills it in place)
    adata = [None] * len(store)
    agrid = [None] * len(store)
    fvars = frame.vars
    before, tick, take_error_proceed, quiet_limit, run_routine, exec_routine, call_native = self.hooks
    cold = COLD
    task = rt.clock.current_task
    # Quiet steps (Runtime.quiet_limit) are counted here, in two locals: ``left``, how many
    # more steps may be quiet, and ``unsaved``, the quiet steps taken and not yet added to
    # rt.clock.steps (SYNC_STEPS adds them before anything reads or changes rt.clock.steps or task.quiet:
    # the full statement hooks, a call, a cold instruction, an error's $ERR, leaving the loop).
    # (No task: a cyclic flag's or analog output's expression the controller evaluates.)
    # ``calm``: the task's advance-run stops are no-ops (Runtime.quiet_limit, ``Task.calm``), so
    # a statement that stops the advance run may be a quiet step too; read with task.quiet.
    left = task.quiet - rt.clock.steps if task is not None else 0
    calm = task is not None and task.calm
    unsaved = 0
    proceed = False
    # ``dirty``: a quiet STMT_G ran and its line (frame.line) and StmtInfo (task.at) are not
    # written yet; FLUSH writes them before anything that may read them.
    dirty = False
    try:
        while True:
            try:
                while True:
                    ins = prog[ip]
                    op = ops[ip]
                    DISPATCH()
            except KrlRuntimeError as e:
                FLUSH()
                reg = code.iregions[ip]
                if reg is None:
                    raise
                e.at(code.file, reg.line)
                if reg.kind != "G" or thunk or not proceed:
                    raise
                proceed = False
                SYNC_STEPS()
                rt.errstate.record_error(e, frame)
                left = task.quiet - rt.clock.steps if task is not None else 0
                calm = task is not None and task.calm
                del stack[8:]         # STACK_BASE
                ip = reg.end
    except BaseException:
        FLUSH()
        raise
    finally:
        rt.clock.count(unsaved)


# ---------------------------------------------------------------------------- helpers
@inline
def FLUSH():
    """The last quiet statement's line and StmtInfo (frame.line, task.at), written before
    anything reads them."""
    if dirty:
        frame.line = info.line
        task.at = info
        dirty = False


@inline
def SYNC_STEPS():
    """The quiet steps taken, counted on rt.clock (RunClock.count)."""
    rt.clock.count(unsaved)
    unsaved = 0


@inline
def LOOP_TICK(stmt, stops):
    """One loop iteration: a quiet step while one is allowed, else Runtime.loop_tick."""
    if left > 0 and (calm or not stops):
        left -= 1
        unsaved += 1
    else:
        FLUSH()
        SYNC_STEPS()
        tick(stmt)
        task.quiet = n = quiet_limit(task)
        left = n - rt.clock.steps
        calm = task.calm


@inline
def COLD_DISPATCH():
    """The cold instructions (motion, interrupts, triggers, analog I/O, waits, ...): one
    function each in the generated loop (``COLD``), called through this one branch, so that
    the loop is the hot path."""
    FLUSH()
    SYNC_STEPS()
    ip = cold[op](self, ins, code, frame, temps, stack, ip)
    left = task.quiet - rt.clock.steps if task is not None else 0
    calm = task is not None and task.calm


@inline
def REF(slot):
    """The reference of frame slot ``slot`` (made on first use: Frame.var)."""
    return fvars[slot] or frame.var(slot)


@inline
def FITS(value, vtype):
    """``value`` goes into a store variable of value class ``vtype`` (operand kind y) as it is."""
    return value.__class__ is vtype and (vtype is not int or INT_MIN <= value <= INT_MAX)


@inline
def SCALAR(x):
    """``x`` is an INT, REAL or BOOL value."""
    return x.__class__ is float or x.__class__ is int or x.__class__ is bool


@inline
def ARRAY_DATA(array, d):
    """``d``: the data list of 1-D store array ``array`` (len(d) is its size: values.Arr)."""
    d = adata[array]
    if d is None:
        d = adata[array] = store[array].data


@inline
def GRID(array, grid):
    """``grid``: (data, rows, columns) of 2-D store array ``array`` (they never change)."""
    grid = agrid[array]
    if grid is None:
        a = store[array]
        grid = agrid[array] = (a.data, a.dims[0], a.dims[1])


@inline
def GLOBAL_REF(slot, ref):
    """``ref``: the reference of global slot ``slot``, taken from its place on first use."""
    ref = grefs[slot]
    if ref is None:
        ref = grefs[slot] = rt.names.storage_ref(code.gstorage[slot], frame)


@inline
def COMPONENT(s, base, comp, name, value):
    """``value``: component ``comp`` of the structure ``s`` when it holds an INT, REAL or BOOL
    there, else the general read through the reference ``base`` (slots.component)."""
    x = s.f.get(comp.key) if s.__class__ is Struct else None
    if SCALAR(x):
        value = x
    else:
        value = _component(base, comp.name, name, comp.key)


# ---------------------------------------------------------------------------- statements
@inst(freq=3144)
def STMT_G(stmt: "x"):
    """statement boundary in a routine: Runtime.before_statement, then take the ON_ERROR_PROCEED flag (every statement takes it)"""
    info = stmt
    if left > 0 and (calm or not stmt.stops):      # a quiet step (Runtime.quiet_limit)
        left -= 1
        unsaved += 1
        dirty = True                        # frame.line, task.at: written by FLUSH
        proceed = False
    else:
        frame.line = stmt.line
        dirty = False
        SYNC_STEPS()
        before(stmt)
        proceed = take_error_proceed()
        task.quiet = n = quiet_limit(task)
        left = n - rt.clock.steps
        calm = task.calm


@inst()
def STMT(stmt: "x"):
    """statement boundary in a thunk (a TRIGGER action): Runtime.before_statement (trace, limits, interrupts, advance-run stop)"""
    info = stmt
    dirty = False                           # this statement's own line and info follow
    if not thunk:
        frame.line = stmt.line
    if left > 0 and (calm or not stmt.stops):
        left -= 1
        unsaved += 1
        task.at = stmt
    else:
        SYNC_STEPS()
        before(stmt)
        task.quiet = n = quiet_limit(task)
        left = n - rt.clock.steps
        calm = task.calm


@inst(freq=57)
def TICK(stmt: "x"):
    """one loop iteration: Runtime.loop_tick"""
    LOOP_TICK(stmt, stmt.cond_stops)


# ---------------------------------------------------------------------------- values
@inst("-- value", freq=113)
def CONST(const: "c"):
    """push a constant"""
    value = const


@inst("-- value")
def NONE():
    """push None (an omitted index or argument)"""
    value = None


@inst("value --")
def POP():
    """drop the top of the stack"""


@inst("-- value")
def LOAD_LOCAL(var: "s"):
    """push the value of a frame slot (aggregates are copied)"""
    value = _load(REF(var))


@inst("-- value", freq=1)
def LOAD_MOD(slot: "m"):
    """push the value of a module slot"""
    value = _load(mrefs[slot])


@inst("-- value")
def LOAD_GLOBAL(slot: "g"):
    """push the value of a global slot (resolved on first use)"""
    GLOBAL_REF(slot, ref)
    value = _load(ref)


@inst("-- ref", freq=86)
def REF_LOCAL(var: "s"):
    """push the reference of a frame slot"""
    ref = REF(var)


@inst("-- ref")
def REF_MOD(slot: "m"):
    """push the reference of a module slot"""
    ref = mrefs[slot]


@inst("-- ref")
def REF_GLOBAL(slot: "g"):
    """push the reference of a global slot"""
    GLOBAL_REF(slot, ref)


@inst("base, idx[count] -- ref")
def INDEX(count: "i", name: "n"):
    """the element reference of base[idx] (an index may be omitted: None); name: the array's, for messages"""
    ref = rt.names.index(base, [None if x is None else _array_index(x) for x in idx], name)


@inst("base -- ref")
def FIELD(comp: "k", name: "n"):
    """the component reference base.comp; name: the structure's, for messages"""
    ref = rt.names.field(base, comp.name, name, comp.key)


@inst("base, idx[count] -- value")
def LOAD_INDEX(count: "i", name: "n"):
    """the value of base[idx] (no index omitted)"""
    value = _element(base, idx, name)


@inst("base, index -- value")
def LOAD_INDEX1(name: "n"):
    """the value of base[index]"""
    value = _element1(base, index, name)


@inst("base, i, j -- value")
def LOAD_INDEX2(name: "n"):
    """the value of base[i, j]"""
    value = _element2(base, i, j, name)


@inst("value, base, idx[count] --")
def STORE_INDEX(count: "i", name: "n"):
    """base[idx] = value"""
    _set_element(base, idx, value, name)


@inst("value, base, index --")
def STORE_INDEX1(name: "n"):
    """base[index] = value"""
    _set_element1(base, index, value, name)


@inst("base -- value")
def LOAD_FIELD(comp: "k", name: "n"):
    """the value of base.comp"""
    s = base.c[base.k] if base.__class__ is Slot else None
    COMPONENT(s, base, comp, name, value)


@inst("value, base --")
def STORE_FIELD(comp: "k", name: "n"):
    """base.comp = value"""
    _set_component(base, comp.name, value, name, comp.key)


@inst("ref -- value")
def DEREF():
    """the value of a reference"""
    value = _read_value(ref)


@inst("value, ref --")
def ASSIGN():
    """Runtime.assign"""
    _store(ref, value)


@inst("value --")
def STORE_LOCAL(var: "s"):
    """pop a value into a frame slot (Runtime.assign)"""
    _store(REF(var), value)


@inst("value --", freq=1)
def STORE_MOD(slot: "m"):
    """pop a value into a module slot"""
    _store(mrefs[slot], value)


@inst("value --")
def STORE_GLOBAL(slot: "g"):
    """pop a value into a global slot"""
    GLOBAL_REF(slot, ref)
    _store(ref, value)


@inst("-- value")
def LOAD_TEMP(slot: "t"):
    """push a temporary"""
    value = temps[slot]


@inst("value --")
def STORE_TEMP(slot: "t"):
    """pop into a temporary"""
    temps[slot] = value


@inst("value -- arg", freq=18)
def VALARG():
    """wrap a value as an :IN argument (ValueRef)"""
    arg = ValueRef(value)


@inst("values[count] -- value", cold=True)
def AGG(struc: "a", count: "i", keys: "n"):
    """an aggregate of count values; struc: its STRUC or -, keys: the components' keys (the resolver's), comma-separated"""
    value = rt.names.aggregate(struc, list(zip(keys.split(",") if keys else [], values)))


# ---------------------------------------------------------------------------- store variables
# A routine's own scalar variables and arrays of scalars (operand kind v), read and written in
# Frame.store directly. The compiler emits these only for variables declared INT, REAL, BOOL,
# CHAR or ENUM (arrays: of INT, REAL, BOOL, CHAR), not CONST.
@inst("-- value", freq=248)
def LOAD_FAST(var: "v"):
    """push a store variable (LOAD_LOCAL)"""
    value = store[var]
    if value is UNSET:
        value = _load(REF(var))


@inst("value --", freq=221)
def STORE_FAST(var: "v", vtype: "y"):
    """pop a value into a store variable (STORE_LOCAL); vtype: its value class"""
    if FITS(value, vtype):
        store[var] = value
    else:
        _store(REF(var), value)


@inst("index -- value", freq=2)
def LOAD_ELEM1(array: "v", name: "n"):
    """the element of 1-D store array at index (LOAD_INDEX1); name: the array's, for messages"""
    ARRAY_DATA(array, d)
    if index.__class__ is int and 0 < index <= INT_MAX and (c1 := index) <= len(d) and (v := d[c1 - 1]) is not UNSET:
        value = v
    else:
        value = _element1(REF(array), index, name)


@inst("i, j -- value")
def LOAD_ELEM2(array: "v", name: "n"):
    """the element of 2-D store array at [i, j] (LOAD_INDEX2)"""
    GRID(array, grid)
    n = grid[1]
    m = grid[2]
    if i.__class__ is int and j.__class__ is int and 0 < i <= n and 0 < j <= m \
            and (v := grid[0][((c1 := i) - 1) * (c2 := m) + (c3 := j) - 1]) is not UNSET:
        value = v
    else:
        value = _element2(REF(array), i, j, name)


@inst("value, index --", freq=28)
def STORE_ELEM1(array: "v", name: "n", etype: "y"):
    """1-D store array [index] = value (STORE_INDEX1); etype: the element's value class"""
    ARRAY_DATA(array, d)
    if index.__class__ is int and 0 < index <= INT_MAX and (c1 := index) <= len(d) and FITS(value, etype):
        d[c1 - 1] = value
    else:
        _set_element1(REF(array), index, value, name)


@inst("value, i, j --", freq=35)
def STORE_ELEM2(array: "v", name: "n", etype: "y"):
    """2-D store array [i, j] = value (STORE_INDEX 2)"""
    GRID(array, grid)
    n = grid[1]
    m = grid[2]
    if i.__class__ is int and j.__class__ is int and 0 < i <= n and 0 < j <= m and FITS(value, etype):
        c1 = i
        c2 = m
        c3 = j
        grid[0][(c1 - 1) * c2 + c3 - 1] = value
    else:
        _set_element(REF(array), [i, j], value, name)


@inst("-- value", freq=248, replaces=("REF_LOCAL", "LOAD_FIELD"))
def LOAD_FIELD_L(var: "s", comp: "k", name: "n"):
    """push local var . comp (REF_LOCAL, LOAD_FIELD): a structure the frame holds itself (a local, an :IN copy) is read in its store, a reference parameter's through its Slot"""
    s = store[var]
    if s.__class__ is not Struct:
        base = REF(var)
        s = base.c[base.k] if base.__class__ is Slot else None
    COMPONENT(s, REF(var), comp, name, value)


@inst("value --", freq=71, replaces=("REF_LOCAL", "STORE_FIELD"))
def STORE_FIELD_L(var: "s", comp: "k", name: "n"):
    """local var . comp = value (REF_LOCAL, STORE_FIELD), set_component's fast path (slots.py): a writable Slot holding a typed Struct, a component of type INT/REAL/BOOL, a value of that very type; a variable the frame holds itself and has no Slot of yet is writable (Frame.var: not a CONST, no write hook)"""
    base = fvars[var]
    k = comp.key
    if base is None:
        s = store[var]
    elif base.__class__ is Slot and not base.readonly:
        s = base.c[base.k]
    else:
        s = None
    if s.__class__ is Struct and s.type is not None \
            and (ft := s.type.fields.get(k)) is not None and k in s.f \
            and (((t := ft[1]) is T_REAL and value.__class__ is float)
                 or (t is T_INT and value.__class__ is int and INT_MIN <= value <= INT_MAX)
                 or (t is T_BOOL and value.__class__ is bool)):
        s.f[k] = value
    else:
        _set_component(base or frame.var(var), comp.name, value, name, k)


@inst(replaces=("LOAD_LOCAL", "STORE_LOCAL"))
def MOVE_LOCAL(src: "s", dst: "s"):
    """local dst = local src (LOAD_LOCAL, STORE_LOCAL), slots.move: a structure assigned into the destination's in place without the copy LOAD_LOCAL makes of it (a status/turn search's TRY = P)"""
    _move(REF(src), REF(dst))


# ---------------------------------------------------------------------------- operators
@inst("a, b -- res", freq=16)
def BINOP(operator: "n"):
    """Runtime.binary_op; "/" inline (krl.semantics.values.binary_op: INT / INT truncates toward zero, REAL / REAL divides; a zero divisor and every other case take the runtime's call: its error, its INT range check)"""
    if operator == "/" and b.__class__ is a.__class__ and b != 0:
        if a.__class__ is float:
            res = a / b
        elif a.__class__ is int and INT_MIN <= (v := (abs(a) // abs(b) if (a >= 0) == (b >= 0)
                                                     else -(abs(a) // abs(b)))) <= INT_MAX:
            res = v
        else:
            res = rt.binary_op(operator, a, b)
    else:
        res = rt.binary_op(operator, a, b)


@inst("a -- res", freq=177)
def UNOP(operator: "n"):
    """Runtime.unary_op"""
    if (a is True or a is False) and operator == "NOT":
        res = a is False
    elif a.__class__ is float and operator == "-":
        res = -a
    else:
        res = rt.unary_op(operator, a)


@inst("a, b -- res", freq=239)
def ADD():
    """binary + (slots.add: the same meaning as BINOP +)"""
    if a.__class__ is float and b.__class__ is float:
        res = a + b
    elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a + b) <= INT_MAX:
        res = v
    else:
        res = _add(a, b)


@inst("a, b -- res", freq=43)
def SUB():
    """binary - (slots.sub)"""
    if a.__class__ is float and b.__class__ is float:
        res = a - b
    elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a - b) <= INT_MAX:
        res = v
    else:
        res = _sub(a, b)


@inst("a, b -- res", freq=269)
def MUL():
    """binary * (slots.mul)"""
    if a.__class__ is float and b.__class__ is float:
        res = a * b
    elif a.__class__ is int and b.__class__ is int and INT_MIN <= (v := a * b) <= INT_MAX:
        res = v
    elif (a.__class__ is int and b.__class__ is float) or (a.__class__ is float and b.__class__ is int):
        res = a * b                         # INT * REAL: REAL (mul)
    else:
        res = _mul(a, b)


@inst("a, b -- res")
def COMPARE(cmp: "o"):
    """a cmp b (<, <=, >, >=, ==, <>: slots.lt ... slots.ne); two INTs are compared by the comparison's mask (vm.Comparison: in C when compiled)"""
    ca = a.__class__
    cb = b.__class__
    if ca is int and cb is int:
        c1 = a
        c2 = b
        c3 = cmp.mask
        res = ((c3 >> ((c1 > c2) - (c1 < c2) + 1)) & 1) == 1
    elif (ca is int or ca is float) and (cb is int or cb is float):
        res = cmp.op(a, b)
    else:
        res = cmp.fn(a, b)


# ---------------------------------------------------------------------------- jumps
@inst(freq=15)
def JUMP(target: "l"):
    """jump"""
    ip = target


@inst("cond --", freq=176)
def JUMP_IF_FALSE(target: "l"):
    """jump if the condition is FALSE (Runtime.to_bool)"""
    if cond is True:
        ip += 1
    elif cond is False or not rt.to_bool(cond):
        ip = target
    else:
        ip += 1


@inst("cond --")
def JUMP_IF_TRUE(target: "l"):
    """jump if the condition is TRUE"""
    if cond is True:
        ip = target
    elif cond is False or not rt.to_bool(cond):
        ip += 1
    else:
        ip = target


@inst("ref, start, end, step -- start", freq=15)
def FOR_PREP(state: "t"):
    """the counter reference, end and step into temps state..state+2 (for_limits); state+3: the last counter value FOR_NEXT_FAST may reach without a test (min(end, INT max) for an INT step > 0, else -inf)"""
    temps[state] = ref
    if not (end.__class__ is int and step.__class__ is int and step != 0):
        end, step = _for_limits(end, step)      # (two INTs: for_limits' result)
    temps[state + 1] = end
    temps[state + 2] = step
    temps[state + 3] = min(end, INT_MAX) if step.__class__ is int and step > 0 else -math.inf


@inst("start --", freq=15)
def FOR_INIT(state: "t"):
    """assign start to the counter (slots.store's fast path for an INT counter)"""
    ref = temps[state]
    if (ref.__class__ is Slot and ref.type is T_INT and start.__class__ is int and not ref.readonly
            and ref.on_write is None and INT_MIN <= start <= INT_MAX):
        ref.c[ref.k] = start
    else:
        _store(ref, start)


@inst(freq=15)
def FOR_TEST(state: "t", target: "l"):
    """jump to target when the counter is past the end (for_done)"""
    ref = temps[state]
    end = temps[state + 1]
    step = temps[state + 2]
    if ref.__class__ is Slot and (c := ref.c[ref.k]).__class__ is int and end.__class__ is int \
            and step.__class__ is int:
        go = c > end if step > 0 else c < end       # for_done, INTs (STEP is not 0)
    else:
        go = for_done(ref.get(), end, step)
    if go:
        ip = target
    else:
        ip += 1


@inst()
def FOR_NEXT(state: "t", stmt: "x", target: "l"):
    """counter = counter + step (for_next); unless it is past the end: TICK stmt and jump to target"""
    if _for_next(temps[state], temps[state + 1], temps[state + 2], stmt):
        LOOP_TICK(stmt, stmt.cond_stops)
        ip = target
    else:
        ip += 1


@inst(freq=545)
def FOR_NEXT_FAST(var: "v", state: "t", stmt: "x", target: "l"):
    """FOR_NEXT with an INT store variable as the counter (the compiler's choice when the loop condition does not stop the advance run)"""
    c = store[var]
    if c.__class__ is int and (c := c + temps[state + 2]) <= temps[state + 3]:
        store[var] = c
        go = True
    elif (c.__class__ is int and (step := temps[state + 2]).__class__ is int
          and (end := temps[state + 1]).__class__ is int and INT_MIN <= c <= INT_MAX):
        # the last step (or a negative STEP): for_next's INT case inline
        store[var] = c
        go = c <= end if step > 0 else c >= end
    else:
        go = _for_next(temps[state], temps[state + 1], temps[state + 2], stmt)
    if go:
        LOOP_TICK(stmt, stmt.cond_stops)
        ip = target
    else:
        ip += 1


# ---------------------------------------------------------------------------- calls
@inst('args[argc] -- result if flags == "E"', freq=36)
def CALL(callee: "r", argc: "i", flags: "f"):
    """call callee (a routine of the program: linked per run, vm.Bound; else Calls.call_native: the implementation the resolver linked, Callee.native, or the stand-in policy); flags: S statement, E expression (pushes the result), N no RESUME catch"""
    target = code.callsites.get(ip)
    FLUSH()
    SYNC_STEPS()
    if target is not None:                  # VM.invoke, without its Python frame
        result = run_routine(target, args, frame, exec_routine, "N" not in flags)
    else:
        result = call_native(callee, args, flags == "E")
    left = task.quiet - rt.clock.steps if task is not None else 0
    calm = task is not None and task.calm
    if result is None and flags == "E":
        result = function_result(callee.name, result)


@inst()
def RETURN():
    """return from the routine (no value)"""
    FLUSH()
    if code.is_function:
        raise return_without_value(code.routine, frame.line)
    return None


@inst("value --", freq=18)
def RETURN_VAL():
    """return the value"""
    FLUSH()
    return value if code.is_function else None


@inst(freq=18)
def END():
    """end of the routine body"""
    FLUSH()
    if code.is_function:
        raise ended_without_return(code.routine, frame.line)
    return None


@inst()
def END_THUNK():
    """end of a thunk (a condition, a handler, a trigger action): its value, the top of the stack, or None"""
    return stack[-1] if len(stack) > 8 else None     # STACK_BASE


# ---------------------------------------------------------------------------- cold: statements with runtime calls
@inst(cold=True)
def HALT():
    """Runtime.halt"""
    rt.halt()


@inst(cold=True)
def EXIT_SIGNAL():
    """EXIT outside a loop: raise ExitSignal"""
    raise ExitSignal()


@inst(cold=True)
def GOTO_FAIL(label: "n"):
    """GOTO to a label that is not in an enclosing block"""
    raise label_not_found(label, code.routine, frame.line)


@inst(cold=True)
def RAISE(message: "n", line: "i"):
    """raise the run-time error message at line (0: the runtime places it)"""
    raise KrlRuntimeError(message, None, code.file if line else None, line or None)


# ---------------------------------------------------------------------------- cold: planned statements
# A statement that is not control flow is its plan's operands (krl/semantics/statements.py) and
# one STATEMENT, which calls the runtime entry the tree interpreter calls too.
@inst("args[argc] --", cold=True)
def STATEMENT(entry: "n", argc: "i", stmt: "x"):
    """a statement that is not control flow: its runtime entry (interp/runtime/statements.py ENTRIES) with the argc operands its plan pushed"""
    STATEMENT_ENTRIES[entry](rt, frame, stmt, *args)


@inst("values[nargs] -- fn", cold=True)
def THUNK(body: "h", nargs: "i"):
    """push the callable that runs the thunk at body (a deferred operand: a condition, a handler, a cyclic value, a trigger action), its stack starting with the nargs values"""
    fn = self.thunk(code, frame, temps, body, values)


@inst("-- value", cold=True)
def PLACE(place: "p"):
    """push the place itself (an analog channel's Storage: the key of what ANIN/ANOUT switch on and off)"""
    value = place


@inst("items[2 * count] -- pairs", cold=True)
def PAIRS(count: "i"):
    """the WITH (reference, value) pairs of the popped items [ref, value, ref, value, ...]"""
    pairs = self.pairs(items)


@inst("-- target", cold=True)
def TRIG_FIND(callee: "r", skip: "l"):
    """push the routine target of a TRIGGER action's call (Calls.callee), or None and jump to skip"""
    target = rt.calls.callee(callee)
    ip = skip if target is None else ip + 1


@inst("target, args[argc] -- call", cold=True)
def TRIG_PACK(argc: "i"):
    """the packed call (target, args) of a TRIGGER action"""
    call = (target, args)


@inst("call --", cold=True)
def TRIG_INVOKE(slow: "l"):
    """in an action thunk: invoke the packed call; None (no routine target): go on at slow"""
    if call is None:
        ip = slow
    else:
        self.invoke(call[0], call[1], frame)
        ip += 1


@inst(cold=True)
def SPL_BEGIN(spline: "t"):
    """start collecting a SPLINE block's segments in temp spline (statements.Segments)"""
    temps[spline] = Segments(rt)


@inst(cold=True)
def SPL_TRIG_BEGIN(spline: "t"):
    """a TRIGGER inside a SPLINE block: set the trigger list aside"""
    temps[spline].begin_statement()


@inst(cold=True)
def SPL_TRIG_END(spline: "t"):
    """collect the TRIGGER's entry for the next segment"""
    temps[spline].end_statement()


@inst("values[argc] --", cold=True)
def SPL_SEG(argc: "i", spline: "t"):
    """a segment into temp spline: its argc operands (krl/semantics/statements.py segments)"""
    temps[spline].motion(*values)


# ---------------------------------------------------------------------------- superinstructions
# The commonest statement shapes of KRL (docs/architecture.md, "Superinstructions"). Each is its
# parts in a row; the compiler's peephole pass fuses exactly these sequences (interp/vm/opcodes.py
# MACROS), never across a label, and within one error region (errors_from: see macro()).
LOAD_FAST2 = macro(LOAD_FAST, LOAD_FAST, freq=131)
LOAD_LOCAL2 = macro(LOAD_LOCAL, LOAD_LOCAL)
ADD_CONST = macro(CONST, ADD, freq=40)
SUB_CONST = macro(CONST, SUB)
MUL_CONST = macro(CONST, MUL, freq=52)
FAST_ADD_CONST = macro(LOAD_FAST, ADD_CONST)
FAST_SUB_CONST = macro(LOAD_FAST, SUB_CONST)
LOCAL_ADD_CONST = macro(LOAD_LOCAL, ADD_CONST)
LOCAL_SUB_CONST = macro(LOAD_LOCAL, SUB_CONST)
ADDC_FAST = macro(FAST_ADD_CONST, STORE_FAST, freq=28, doc="v2 = v1 + c")
SUBC_FAST = macro(FAST_SUB_CONST, STORE_FAST, freq=445, doc="v2 = v1 - c")
ADD_FAST = macro(LOAD_FAST2, ADD, STORE_FAST, freq=259, doc="v3 = v1 + v2")
JUMP_TICK = macro(TICK, JUMP, freq=690, doc="the back edge of WHILE and LOOP")
IF_NOT = macro(COMPARE, JUMP_IF_FALSE, freq=18, errors_from=0, doc="jump unless a cmp b (a COMPARE's result is a BOOL)")
IF_NOT_VV = macro(LOAD_FAST2, IF_NOT, freq=287, doc="jump unless v1 cmp v2")
IF_NOT_VC = macro(LOAD_FAST, CONST, IF_NOT, freq=445, doc="jump unless v cmp c")
LOAD_ELEM1_V = macro(LOAD_FAST, LOAD_ELEM1, freq=190, doc="store array [store variable]")
STORE_ELEM1_V = macro(LOAD_FAST, STORE_ELEM1, doc="store array [store variable] = value")
STORE_ELEM1_VC = macro(CONST, STORE_ELEM1_V, freq=435, doc="store array [store variable] = c")
LOAD_ELEM2_VV = macro(LOAD_FAST2, LOAD_ELEM2, freq=236, doc="store array [v1, v2]")
LOAD_ELEM_LL = macro(REF_LOCAL, LOAD_LOCAL, LOAD_INDEX1, doc="local array [local]")
STORE_ELEM_LL = macro(REF_LOCAL, LOAD_LOCAL, STORE_INDEX1, doc="local array [local] = value")
LOAD_ELEM2_LLL = macro(REF_LOCAL, LOAD_LOCAL2, LOAD_INDEX2, doc="local array [local, local]")
# chosen by counting the executed instructions and their pairs on the compute benchmark
IF_NOT_EV = macro(LOAD_ELEM1_V, LOAD_FAST, IF_NOT, freq=444, doc="IF a[i] <= k")
MOVE_ELEM1 = macro(LOAD_ELEM1_V, FAST_ADD_CONST, STORE_ELEM1, freq=431, doc="a[j + 1] = a[i]")
