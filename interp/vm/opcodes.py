"""THE opcode table of the KRL VM (one source of truth, like CPython's ``opcode`` module).

Each opcode is defined once, here: its name, number, stack effect and operand kinds. The
compiler writes instructions by name, the assembler encodes them from this table, the
disassembler decodes them with it, and the VM dispatches on the numbers bound below.

Operand kinds (how an operand is written in the assembly text / stored in the code):

====  ==========================================  =====================================
kind  text                                        code
====  ==========================================  =====================================
i     an integer                                  the integer
c     a literal: 12, -3, 2.5, "text", TRUE,       index into the constant pool
      #ENUM_VALUE, NONE
n     a name or word (``X``, ``$OV_PRO``, ``+``,  index into the constant pool (a str)
      ``C_DIS,C_PTP``; JSON-quoted if it is not
      a plain word)
l     a label ``L3``                              the instruction address
s     a local (frame slot) by name                the slot number (``.locals`` order);
                                                  the VM's form is the key of ``Frame.vars``
v     a *store variable* by name: a local or      the slot number; the VM's form is the
      :IN parameter the frame holds in its own    key of ``Frame.store``
      store (never an alias of the caller's)
m     a module (data list) variable by name       index into the code's module slots
g     a global / system variable by name          index into the code's global slots
t     a temporary slot number                     the number
f     a flag word (``-`` = none)                  index into the constant pool (a str)
y     a value type: I, R, B or C (INT, REAL,      index into the constant pool (a str);
      BOOL, CHAR)                                 the VM's form is the Python class of
                                                  that type's values (None for C: every
                                                  CHAR store takes the general path)
o     a comparison: ``<``, ``<=``, ``>``, ``>=``,   index into the constant pool (a str);
      ``==``, ``<>``                              the VM's form is (the comparison on two
                                                  numbers, its runtime function)
k     a structure component by name              index into the constant pool (a str);
                                                  the VM's form is (the name, its UPPER key)
x     a statement: ``LINE`` or ``LINE/FLAGS``      index into the code's statement table
      (S: stops the advance run, C: its loop      (advance.StmtInfo objects)
      condition stops it)
r     the routine a call runs, by name            index into the constant pool (a str);
                                                  the compiler's and the VM's form is the
                                                  call's Callee (krl/semantics/resolve.py),
                                                  linked when the routine is first called
a     the STRUC an aggregate names (``-``: none)  index into the constant pool (a str);
                                                  the compiler's and the VM's form is the
                                                  front end's Struc (or its name when
                                                  nothing declares it)
p     an analog channel by name                   index into the constant pool (a str);
                                                  the compiler's and the VM's form is the
                                                  channel's place (a Storage)
====  ==========================================  =====================================

Operands ``m`` and ``g`` are written as names; the compiler's and the VM's form of each is the
place (Storage) the front end resolved, so the VM never reads a name to decide a meaning.

Stack effect: the net change of the operand-stack depth; ``None`` where it depends on an
operand (documented per opcode).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class OpInfo:
    name: str
    number: int
    effect: int | None
    operands: str            # operand kinds, one letter each
    doc: str


_TABLE = [
    # name            effect operands doc
    # -- statements and lines
    ("STMT",          0,  "x", "statement boundary in a thunk (a TRIGGER action): Runtime.before_statement (trace, limits, interrupts, advance-run stop)"),
    ("STMT_G",        0,  "x",  "statement boundary in a routine: Runtime.before_statement, then take the ON_ERROR_PROCEED flag (every statement takes it)"),
    ("TICK",          0,  "x",  "one loop iteration: Runtime.loop_tick"),
    # -- values
    ("CONST",         1,  "c",  "push a constant"),
    ("NONE",          1,  "",   "push None (an omitted index or argument)"),
    ("POP",          -1,  "",   "drop the top of the stack"),
    ("LOAD_LOCAL",    1,  "s",  "push the value of a frame slot (aggregates are copied)"),
    ("LOAD_MOD",      1,  "m",  "push the value of a module slot"),
    ("LOAD_GLOBAL",   1,  "g",  "push the value of a global slot (resolved on first use)"),
    ("REF_LOCAL",     1,  "s",  "push the reference of a frame slot"),
    ("REF_MOD",       1,  "m",  "push the reference of a module slot"),
    ("REF_GLOBAL",    1,  "g",  "push the reference of a global slot"),
    ("INDEX",      None,  "in", "pop i indices and a reference, push the element reference (effect -i); n: name for messages"),
    ("FIELD",         0,  "nn", "replace a reference by its component reference; n: component, n: name for messages"),
    ("LOAD_INDEX", None,  "in", "pop i indices (none omitted) and a reference, push the element's value (effect -i)"),
    ("STORE_INDEX",None,  "in", "pop i indices, a reference and a value: element = value (effect -i-2)"),
    ("LOAD_FIELD",    0,  "kn", "FIELD, then the component's value"),
    ("STORE_FIELD",  -2,  "kn", "pop a reference and a value: component = value"),
    ("DEREF",         0,  "",   "replace a reference by its value"),
    ("ASSIGN",       -2,  "",   "pop a reference and a value: Runtime.assign"),
    ("STORE_LOCAL",  -1,  "s",  "pop a value into a frame slot (Runtime.assign)"),
    ("STORE_MOD",    -1,  "m",  "pop a value into a module slot"),
    ("STORE_GLOBAL", -1,  "g",  "pop a value into a global slot"),
    ("LOAD_TEMP",     1,  "t",  "push a temporary"),
    ("STORE_TEMP",   -1,  "t",  "pop into a temporary"),
    ("VALARG",        0,  "",   "wrap a value as an :IN argument (ValueRef)"),
    ("AGG",        None,  "an", "pop k values, push an aggregate; a: its STRUC or -, n: component names (effect 1-k)"),
    # -- operators
    ("BINOP",        -1,  "n",  "Runtime.binary_op"),
    ("UNOP",          0,  "n",  "Runtime.unary_op"),
    ("ADD",          -1,  "",   "binary +  (Runtime fast path, same meaning as BINOP +)"),
    ("SUB",          -1,  "",   "binary -"),
    ("MUL",          -1,  "",   "binary *"),
    ("LT",           -1,  "",   "binary <"),
    ("LE",           -1,  "",   "binary <="),
    ("GT",           -1,  "",   "binary >"),
    ("GE",           -1,  "",   "binary >="),
    ("EQ",           -1,  "",   "binary =="),
    ("NE",           -1,  "",   "binary <>"),
    # -- superinstructions (written by the compiler's peephole pass; same runtime calls)
    ("LOAD_ELEM_LL",  1,  "ssn", "push local array s1 [local s2] (REF_LOCAL, LOAD_LOCAL, LOAD_INDEX 1)"),
    ("STORE_ELEM_LL",-1,  "ssn", "pop a value into local array s1 [local s2] (REF_LOCAL, LOAD_LOCAL, STORE_INDEX 1)"),
    ("LOAD_ELEM2_LLL",1,  "sssn", "push local 2-D array s1 [local s2, local s3]"),
    ("LOAD_LOCAL2",   2,  "ss", "push two locals"),
    ("ADD_CONST",     0,  "c",  "CONST c, ADD"),
    ("LOCAL_ADD_CONST", 1, "sc", "LOAD_LOCAL s, ADD_CONST c"),
    ("LOCAL_SUB_CONST", 1, "sc", "LOAD_LOCAL s, SUB_CONST c"),
    ("JUMP_TICK",     0,  "xl", "TICK x, JUMP l (the back edge of WHILE and LOOP)"),
    ("SUB_CONST",     0,  "c",  "CONST c, SUB"),
    ("MUL_CONST",     0,  "c",  "CONST c, MUL"),
    ("IF_NOT_LT",    -2,  "l",  "LT, JUMP_IF_FALSE l"),
    ("IF_NOT_LE",    -2,  "l",  "LE, JUMP_IF_FALSE l"),
    ("IF_NOT_GT",    -2,  "l",  "GT, JUMP_IF_FALSE l"),
    ("IF_NOT_GE",    -2,  "l",  "GE, JUMP_IF_FALSE l"),
    ("IF_NOT_EQ",    -2,  "l",  "EQ, JUMP_IF_FALSE l"),
    ("IF_NOT_NE",    -2,  "l",  "NE, JUMP_IF_FALSE l"),
    # -- store variables (operand kind v): a routine's own scalar variables and arrays of
    #    scalars, read and written in ``Frame.store`` directly. Each has an inline fast path
    #    for the common case and hands every other case (UNSET, a conversion, an index out
    #    of range) to the same runtime function as the general opcode, so values and error
    #    messages are the general opcode's. The compiler emits them only for variables
    #    declared INT, REAL, BOOL, CHAR or ENUM (arrays: of INT, REAL, BOOL, CHAR), not CONST.
    ("LOAD_FAST",     1,  "v",  "push a store variable (LOAD_LOCAL)"),
    ("LOAD_FAST2",    2,  "vv", "push two store variables"),
    ("FAST_ADD_CONST", 1, "vc", "LOAD_FAST v, ADD_CONST c"),
    ("FAST_SUB_CONST", 1, "vc", "LOAD_FAST v, SUB_CONST c"),
    ("STORE_FAST",   -1,  "vy", "pop a value into a store variable (STORE_LOCAL); y: its type"),
    ("LOAD_ELEM1",    0,  "vn", "pop an index, push store array v [index] (LOAD_INDEX 1); n: name for messages"),
    ("LOAD_ELEM2",   -1,  "vn", "pop two indices, push store array v [i, j] (LOAD_INDEX 2)"),
    ("STORE_ELEM1",  -2,  "vny","pop an index and a value: store array v [index] = value (STORE_INDEX 1); n: name, y: element type"),
    ("STORE_ELEM2",  -3,  "vny","pop two indices and a value: store array v [i, j] = value (STORE_INDEX 2)"),
    ("LOAD_ELEM1_V",  1,  "vvn", "push store array v1 [store variable v2]"),
    ("STORE_ELEM1_V",-1,  "vvny", "pop a value into store array v1 [store variable v2]"),
    ("LOAD_ELEM2_VV", 1,  "vvvn", "push store array v1 [v2, v3]"),
    ("LOAD_FIELD_L",  1,  "skn", "push local s . component (REF_LOCAL, LOAD_FIELD)"),
    ("STORE_FIELD_L",-1,  "skn", "pop a value into local s . component (REF_LOCAL, STORE_FIELD)"),
    ("FOR_NEXT_FAST", 0,  "vtxl", "FOR_NEXT with an INT store variable v as the counter, a loop condition that does not stop the advance run"),
    ("ADDC_FAST",     0,  "vcvy", "v2 = v1 + c (FAST_ADD_CONST v1 c, STORE_FAST v2 y)"),
    ("SUBC_FAST",     0,  "vcvy", "v2 = v1 - c (FAST_SUB_CONST v1 c, STORE_FAST v2 y)"),
    ("IF_NOT_VV",     0,  "vvol", "jump to l unless v1 o v2 (LOAD_FAST2 v1 v2, IF_NOT_<o> l)"),
    ("IF_NOT_VC",     0,  "vcol", "jump to l unless v o c (LOAD_FAST v, CONST c, IF_NOT_<o> l)"),
    # chosen by measurement: the commonest triples of the compute benchmark (interp/bench)
    ("IF_NOT_EV",     0,  "vvnvol", "jump to l unless v1 [v2] o v3 (LOAD_ELEM1_V v1 v2 n, LOAD_FAST v3, IF_NOT_<o> l)"),
    ("MOVE_ELEM1",    0,  "vvnvcvny", "v4 [v3 + c] = v1 [v2] (LOAD_ELEM1_V v1 v2 n, FAST_ADD_CONST v3 c, STORE_ELEM1 v4 n y)"),
    ("ADD_FAST",      0,  "vvvy", "v3 = v1 + v2 (LOAD_FAST2 v1 v2, ADD, STORE_FAST v3 y)"),
    ("STORE_ELEM1_VC", 0, "vvnyc", "store array v1 [store variable v2] = c (CONST c, STORE_ELEM1_V v1 v2 n y)"),
    # -- jumps
    ("JUMP",          0,  "l",  "jump"),
    ("JUMP_IF_FALSE",-1,  "l",  "pop a condition (Runtime.to_bool); jump if FALSE"),
    ("JUMP_IF_TRUE", -1,  "l",  "pop a condition; jump if TRUE"),
    ("JUMP_IF_NONE",  0,  "l",  "if the top is None: pop it and jump"),
    ("FOR_PREP",     -3,  "t",  "pop step, end, start and the counter reference into temps t..t+2, push start; t+3: the last counter value FOR_NEXT_FAST may reach without a test (min(end, INT max) for an INT step > 0, else -inf)"),
    ("FOR_INIT",     -1,  "t",  "pop start: assign it to the counter"),
    ("FOR_TEST",      0,  "tl", "jump when the counter is past the end"),
    ("FOR_NEXT",      0,  "txl", "counter = counter + step; unless it is past the end: TICK x and jump to l"),
    # -- calls
    ("CALL",       None,  "rif","pop i arguments, call r (effect -i, +1 for a function call); f: S statement, E expression, N no RESUME catch"),
    ("RETURN",        0,  "",   "return from the routine (no value)"),
    ("RETURN_VAL",   -1,  "",   "return the top of the stack"),
    ("END",           0,  "",   "end of the routine body"),
    ("END_THUNK",     0,  "",   "end of a thunk (condition, handler, trigger action): return the top or None"),
    # -- statements with runtime calls
    ("HALT",          0,  "",   "Runtime.halt"),
    ("WAIT_FOR",      0,  "l",  "Runtime.wait_for with the condition thunk at l"),
    ("WAIT_SEC",     -1,  "",   "Runtime.wait_sec"),
    ("CONTINUE",      0,  "x",  "Runtime.set_continue"),
    ("ON_ERROR_PROCEED", 0, "", "Runtime.on_error_proceed"),
    ("EXIT_SIGNAL",   0,  "",   "EXIT outside a loop: raise ExitSignal"),
    ("GOTO_FAIL",     0,  "n",  "GOTO to a label that is not in an enclosing block"),
    ("RAISE",         0,  "ni", "raise a run-time error n at line i"),
    ("INT_DECL",     -1,  "llnfi", "pop the number: Runtime.interrupt_decl(cond thunk, handler thunk, name, GLOBAL?, line)"),
    ("INT_CTL",    None,  "nf", "Runtime.interrupt_ctl(action[, popped number]); f: P if a number is given"),
    ("BRAKE",         0,  "f",  "Runtime.brake (f: F for BRAKE F)"),
    ("STUB",          0,  "n",  "Runtime.stub_statement (CONFIRM, ASYPTP, MOVE_EMI, ...)"),
    ("CYCLIC_ASSIGN",-2,  "l",  "pop a reference and a value: assign, then Runtime.cyclic_on re-assigns the thunk's value every IPO cycle (a cyclic flag)"),
    ("ANOUT_ON",   None,  "pfl", "pop [max,] [min,] the output reference: ANOUT ON channel p (f: L min, H max), value thunk l, Runtime.cyclic_on"),
    ("ANIN_ON",      -1,  "pl", "pop the target reference: ANIN ON, value thunk l, Runtime.cyclic_on (p: the input channel or -)"),
    ("CYCLIC_OFF",    0,  "np", "Runtime.cyclic_off of what n switched on for channel p (ANOUT OFF, ANIN OFF)"),
    ("RESUME",        0,  "",   "Runtime.resume"),
    ("TRIG_FIND",     1,  "rl", "push the routine target of a TRIGGER action call r, or None and jump"),
    ("TRIG_PACK",  None,  "i",  "pop i arguments and the target, push the packed call (effect -i)"),
    ("TRIGGER",    None,  "nfil", "pop [prio,] delay, at and the packed call: Runtime.trigger; n: kind, f: O onstart / P prio; i: line; l: action thunk"),
    ("TRIG_INVOKE",  -1,  "",   "in an action thunk: invoke the packed call"),
    ("MOTION",     None,  "nnnfii", "pop [with pairs,] [ca,] [aux,] target: Runtime.motion; n kind, n approx, n frame, f A/C, i #with, i line"),
    ("SPL_BEGIN",     0,  "t",  "start collecting spline segments in temp t"),
    ("SPL_TRIG_BEGIN",0,  "t",  "a TRIGGER inside a SPLINE block: set the trigger list aside"),
    ("SPL_TRIG_END",  0,  "t",  "collect the TRIGGER's entry for the next segment"),
    ("SPL_SEG",    None,  "nfiit", "pop a segment (target, aux?, ca?, with pairs) into temp t; n kind, f A/C, i #with, i line"),
    ("SPLINE",     None,  "nniit", "pop the block's with pairs: Runtime.spline; n kind, n approx, i #with, i line"),
]

OPS: list[OpInfo] = [OpInfo(name, i, eff, ops, doc) for i, (name, eff, ops, doc) in enumerate(_TABLE)]
BY_NAME: dict[str, OpInfo] = {o.name: o for o in OPS}
OPERAND_KINDS = "icnlsmgtfxvyokrap"

# bind the numbers as module constants (STMT, CONST, ...) for the compiler and the VM
globals().update({o.name: o.number for o in OPS})


def size(op: int) -> int:
    """Length of an instruction in code words (the opcode and its operands)."""
    return 1 + len(OPS[op].operands)


def instruction_starts(words: list) -> list[int]:
    """The address of each instruction in the code words, in order."""
    starts = []
    pc = 0
    while pc < len(words):
        starts.append(pc)
        pc += size(words[pc])
    return starts
