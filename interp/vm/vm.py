"""The VM: links the compiler's listings and runs them on the shared runtime.

The dispatch loop is interp/vm/loop.py, generated from the instruction definitions
(interp/vm/instructions.py: every instruction's operands, stack effect and handler, defined once)
by interp/vm/gen_loop.py, and compiled by Cython when built (interp/vm/build.py). Every semantic
operation of a handler is a call into :class:`interp.runtime.core.Runtime` (or its fast paths in
interp/runtime/slots.py), the same calls the tree interpreter makes (docs/architecture.md,
"Bytecode VM"). A KRL call runs a nested loop (one Python level per KRL call, as the tree
interpreter's ``invoke``), so interrupt handlers, TRIGGER actions and WAIT FOR conditions, which
the runtime calls back at a statement boundary or an IPO cycle, run as *thunks* of the declaring
routine's code on top of the interrupted context.

Errors: the listing's regions (``.at``) are the line table. A KrlRuntimeError raised by an
instruction is placed on its region's line; in a guarded region after ON_ERROR_PROCEED it is
recorded ($ERR) and execution goes on after the statement, as in the tree interpreter.

Code: the compiler makes a routine's listing from its annotated AST alone (no runtime),
:func:`link` turns the listing into the executed form (one tuple per listing instruction: `krl
asm` prints exactly what runs; kept per checked workspace by :func:`linked_code`, not on the
AST), each operand as its kind's VM form (:data:`LINK`), and :class:`Bound` binds it to a run's
storage and links every call site from its Callee (a routine of the program: the (module,
Routine) to invoke) when the routine is first called; a built-in or a stub is run through the
runtime (``Calls.call_native``, as the tree interpreter does: the implementation the resolver
linked, else the stand-in policy).
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import operator
import sys
import weakref
from pathlib import Path

from interp.runtime.slots import eq, ge, gt, le, lt, ne

from . import opcodes as OP
from krl.semantics.advance import StmtInfo
from krl.semantics.resolve import ROUTINE

from .assembler import Region
from .compiler import compile_routine


# The operand stack starts with STACK_BASE placeholders that no instruction reads (the loop
# spells the number out: ``len(stack) > 8``, ``del stack[8:]``): a statement's pushes and pops then
# never take the list back to empty, which would free and reallocate its items at every statement.
STACK_BASE = 8


class Comparison:
    """The VM form of a comparison operand (kind o): the comparison on two numbers (``op``), its
    runtime function (``fn``: slots.lt, ...) and ``mask``, in which bit s + 1 is set when the
    comparison holds for two INTs whose order is s = (a > b) - (a < b) (-1, 0, 1), so that the
    compiled loop compares two INTs in C without a call."""

    __slots__ = ("symbol", "op", "fn", "mask")

    def __init__(self, symbol: str, op, fn, mask: int) -> None:
        self.symbol, self.op, self.fn, self.mask = symbol, op, fn, mask


COMPARISONS = {c.symbol: c for c in (
    Comparison("<", operator.lt, lt, 0b001), Comparison("<=", operator.le, le, 0b011),
    Comparison(">", operator.gt, gt, 0b100), Comparison(">=", operator.ge, ge, 0b110),
    Comparison("==", operator.eq, eq, 0b010), Comparison("<>", operator.ne, ne, 0b101))}

# the VM form of a value type (kind y): the Python class of its values (None for C: every CHAR
# store takes the general path)
_VALUE_CLASS = {"I": int, "R": float, "B": bool}


class Linked:
    """The VM's executed form of one routine, made from its listing (interp/vm/compiler.py)
    by :func:`link`: one tuple ``(opcode, operand, ...)`` per instruction of the listing, in
    the listing's order (so `krl asm`, which prints the listing, shows exactly what runs),
    each operand in its VM form followed by its linked fields (declarations.py ``KINDS``:
    ``stmt.line`` is one tuple read), jump targets as instruction numbers, module and global
    slots as indexes into ``mstorage`` / ``gstorage`` (the front end's Storage, bound per run by
    :class:`Bound`); and the error region of each instruction. It holds nothing of a run."""

    __slots__ = ("name", "kind", "file", "prog", "ops", "iregions", "lnames", "ntemps",
                 "mnames", "mstorage", "gnames", "gstorage", "calls", "is_function")


def _slot(index: dict, names: list, places: list, place) -> int:
    """The module or global slot of `place` (a Storage): numbered by the place the front end
    resolved (``Storage.key``), never by a name."""
    k = index.setdefault(place.key, len(index))
    if k == len(places):
        names.append(place.name)
        places.append(place)
    return k


def link(lst) -> Linked:
    """The executed form of listing `lst` (interp/vm/compiler.py)."""
    out = Linked()
    out.name, out.kind, out.file, out.ntemps = lst.name, lst.kind, lst.file, lst.ntemps
    out.is_function = lst.kind == "DEFFCT"
    out.lnames = list(lst.lnames)
    out.mnames, out.gnames, out.mstorage, out.gstorage = [], [], [], []
    out.calls = []       # the instructions that call a routine of the program (Bound links them)
    mix: dict = {}
    gix: dict = {}
    labels = lst.labels
    # an operand's VM form by kind (the others are the listing's value itself)
    forms = {
        "x": lambda v: StmtInfo(lst.file, v[0], "S" in v[1], "C" in v[1]),
        "l": labels.__getitem__, "h": labels.__getitem__,
        "m": lambda v: _slot(mix, out.mnames, out.mstorage, v),
        "g": lambda v: _slot(gix, out.gnames, out.gstorage, v),
        "y": _VALUE_CLASS.get,
        "o": COMPARISONS.__getitem__,
    }
    kinds = OP.KINDS
    prog = []
    regions = []
    moved: dict = {}     # guarded regions with their end as an instruction number
    for name, values, reg in lst.instrs:
        info = OP.BY_NAME[name]
        ins = [info.number]
        for k, v in zip(info.operands, values):
            form = forms.get(k)
            v = form(v) if form is not None else v
            ins.append(v)
            ins += [getattr(v, f) for f in kinds[k]]
        if info.number == OP.CALL and values[0].kind == ROUTINE:
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
        self.mrefs = [rt.names.storage_ref(st, None) for st in linked.mstorage]
        self.grefs = [None] * len(linked.gstorage)
        prog = linked.prog
        self.callsites = {ip: rt.calls.callee(prog[ip][1]) for ip in linked.calls}     # CALL's callee operand


class VM:
    def __init__(self, rt, loop: str = "generated") -> None:
        """`loop`: "generated" (interp/vm/loop.py, compiled by Cython when built and current:
        :data:`COMPILED`; the default) or "python" (loop.py as plain Python, also when the
        compiled one exists); both are tested (tests/vm/test_compiled_loop.py)."""
        self.rt = rt
        self.loop = _python_loop().run if loop == "python" else _generated_run
        self.codes: dict = {}          # id(routine) -> Bound
        # the body of a KRL call: the loop itself, which finds the routine's code when called
        # without one (no Python frame of its own per call)
        self.body = functools.partial(self.loop, self, None)
        # the runtime's statement hooks, bound once (the loop takes them at each call)
        self.hooks = (rt.before_statement, rt.loop_tick, rt.errstate.take_error_proceed, rt.quiet_limit, rt.calls.run_routine,
                      self.body, rt.calls.call_native)

    # ------------------------------------------------------------------ entry points
    def run_program(self, module_name: str | None = None) -> None:
        """Body of the robot (or a submit) task: call the main routine of the module."""
        self.invoke(self.rt.calls.main_routine(module_name), [], None)

    def code_for(self, routine) -> Bound:
        """This run's code of `routine`: compiled from its annotated AST and linked once per
        process (:func:`linked_code`), bound to this run's storage and call sites once per run."""
        code = self.codes.get(id(routine))
        if code is None:
            linked = linked_code(self.rt.program.ws, routine)
            code = self.codes[id(routine)] = Bound(linked, routine, self.rt)
        return code

    # ------------------------------------------------------------------ calls
    def invoke(self, target, args: list, caller, catch_resume: bool = True):
        """Run routine ``target`` = (module, Routine) with reference ``args`` (the
        runtime's call protocol, Calls.run_routine)."""
        return self.rt.calls.run_routine(target, args, caller, self.body, catch_resume)

    def thunk(self, code, frame, temps: list, ip: int, stack: list | None = None):
        """A callable that runs the thunk at ``ip`` of ``code`` in the activation (``frame``,
        ``temps``) that declared it."""
        loop = self.loop
        return lambda: loop(self, code, frame, temps, ip, [None] * STACK_BASE + (stack or []), True)

    @staticmethod
    def pairs(items: list) -> list:
        """The WITH (reference, value) pairs of the popped items ``[ref, value, ref, value, ...]``."""
        return [(items[2 * i], items[2 * i + 1]) for i in range(len(items) // 2)]


# The linked code of each routine, per checked workspace: a routine is compiled and linked once
# per process (the two interpreters of a conformance case, the programs of one backup, the runs
# of a test share it), and dropped with its workspace. The VM's caches live here, not on the AST.
_LINKED: dict = {}       # id(workspace) -> (weak reference to it, {id(routine): (routine, Linked)})


def linked_code(ws, routine) -> Linked:
    """The Linked form of `routine` (a Routine of the checked workspace `ws`), compiled
    (interp/vm/compiler.py) and linked on first use."""
    entry = _LINKED.get(id(ws))
    if entry is None or entry[0]() is not ws:
        entry = _LINKED[id(ws)] = (weakref.ref(ws, lambda _ref, key=id(ws): _LINKED.pop(key, None)), {})
    per = entry[1]
    got = per.get(id(routine))
    if got is None or got[0] is not routine:
        got = per[id(routine)] = (routine, link(compile_routine(routine)))
    return got[1]


# The loop: interp/vm/loop.py, generated from interp/vm/instructions.py (python -m
# interp.vm.gen_loop). `make` compiles loop.py with Cython (interp/vm/build.py) into an extension
# beside it, which Python imports in its place; it runs (loop="generated") only when it was built
# from the loop.py that is here (its SOURCE, the sha256 of loop.py's text above that line), else
# loop.py runs as plain Python.
LOOP_PY = Path(__file__).with_name("loop.py")


def _python_loop():
    """interp/vm/loop.py itself, imported from its file (also when the extension exists)."""
    name = "interp.vm._loop_python"
    mod = sys.modules.get(name)
    if mod is None:
        spec = importlib.util.spec_from_file_location(name, LOOP_PY)
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
    return mod


def _current(mod) -> bool:
    """`mod` (a loop module) was made from the loop.py that is here."""
    text = LOOP_PY.read_text(encoding="utf-8")
    return mod.SOURCE == hashlib.sha256(text[:text.rindex("SOURCE = ")].encode("utf-8")).hexdigest()


from . import loop as _loop  # noqa: E402

COMPILED = not _loop.__file__.endswith(".py") and _current(_loop)
if not COMPILED:
    _loop = _python_loop()
_generated_run = _loop.run
