"""The bytecode compiler: a routine's AST -> its instruction listing (interp/vm/assembler.py).

The VM links the listing directly (interp/vm/vm.py ``link``); no text is produced or parsed on
the way to running code, so no KRL text (a comment, a string) can ever be read back as an
instruction. The readable assembly (assembler.format_listing) is written only for `krl asm`
and the assembler's round-trip tests.

Statements are declared once (krl/semantics/statements.py ``KINDS``; docs/architecture.md,
"Statements: where to add one"): a statement that is not control flow is compiled from its
plan by :meth:`Compiler.s_planned` (its operands in the plan's order, then one ``STATEMENT``
that calls the runtime entry the tree interpreter calls, interp/runtime/statements.py), so the
VM makes the same runtime calls in the same order by construction; control flow (IF, loops,
SWITCH, GOTO, EXIT, HALT, RETURN, calls) and expressions have one handler per kind here and in
the tree interpreter (interp/tree/interpreter.py), through the one node-dispatch helper
(krl/ast/visit.py), for only the stepping differs:

* meaning comes from the front end's typed facts (krl/semantics/resolve.py), never from a
  name's spelling: a LOCAL place is a *frame slot* (parameters and locals, in ``.locals``
  order, the routine's Layout: operands ``s``/``v`` are the slot numbers, ``Storage.slot``), a
  MODULE place a *module slot* (the data list of the routine's module), any other place a
  *global slot* (another data list, a system variable, the ``$``-name fallback; its reference
  is taken on first use, Names.storage_ref); the listing carries each place (operands
  ``m``/``g``), each call's Callee (``r``), each aggregate's STRUC (``a``), each structure
  component (``k``, its key the resolver's) and each analog channel (``p``) for the VM to link;
* structured statements become jumps; GOTO jumps to its target Label, in the nearest
  enclosing block that holds it (the tree interpreter's rule), EXIT to the end of the
  innermost loop;
* a superinstruction (interp/vm/instructions.py ``macro``) replaces the sequence of its parts
  (:func:`peephole`, from the table interp/vm/opcodes.py ``MACROS``);
* constant operands are folded with the front end's operators (krl/semantics/values.py, the
  runtime's); an expression whose folding raises is left for run time;
* operands that are evaluated later (WAIT FOR, interrupt conditions and handlers, cyclic
  values, TRIGGER actions) are compiled as *thunks* after the routine's END, pushed as
  callables by ``THUNK``;
* each statement's StmtInfo (advance-run stop flags) is the front end's (``stmt.ann.info``,
  krl/semantics/advance.py), the one the tree interpreter reads, and its error region
  (``.at``) places run-time errors on the line the tree interpreter would name.
"""

from __future__ import annotations

from krl.ast import nodes as N
from krl.ast.visit import EXPRESSIONS, STATEMENTS, handlers
from krl.semantics import types as T
from krl.semantics.resolve import LOCAL, MODULE
from krl.semantics.statements import BARE, KINDS, PLAIN, plan, segments as segment_plan
from krl.semantics.values import EnumValue, KrlRuntimeError, binary_op, unary_op

from interp.runtime.errors import lvalue_name
from interp.runtime.values import Channel
from interp.runtime.watch import watch_of_decl

from .assembler import Listing, Region, format_listing
from .opcodes import BY_NAME as OPS, MACROS


_FAST_BINOPS = {"+": "ADD", "-": "SUB", "*": "MUL"}
_COMPARISONS = frozenset(("<", "<=", ">", ">=", "==", "<>"))     # COMPARE (operand kind o)
_FOLDABLE = (int, float, bool, str, EnumValue)


def local_names(routine: N.Routine) -> list[str]:
    """Frame slots of a routine (its Layout, krl/semantics/resolve.py): its parameters, then
    its variables and SIGNALs (declaration order)."""
    return [s.name for s in routine.ann.layout.slots]


_LETTERS = {T.INT: "I", T.REAL: "R", T.BOOL: "B", T.CHAR: "C"}


def store_variables(routine: N.Routine) -> dict:
    """The routine's *store variables* (operand kind ``v``, interp/vm/opcodes.py): frame slot
    -> (type letter I/R/B/C, number of array dimensions, 0 for a scalar) for each variable
    the frame holds in its own store (Calls.enter_routine: a local, or an :IN parameter)
    whose type (the checker's, from the routine's Layout) is INT, REAL, BOOL or CHAR, scalar
    or an array of 1 or 2 fixed dimensions; not CONST, not an :OUT parameter (an alias of
    the caller's variable)."""
    layout = routine.ann.layout
    out: dict = {}
    for k, s in enumerate(layout.slots):
        d = s.decl
        if not isinstance(d, N.VarDecl) or d.is_const or d.init is not None:
            continue
        if k < layout.nparams and s.mode != "IN":
            continue
        t = s.type
        dims = 0
        if isinstance(t, T.Array):
            if len(t.dims) > 2 or 0 in t.dims:
                continue
            dims = len(t.dims)
            t = t.elem
        letter = _LETTERS.get(t)
        if letter is not None:
            out[k] = (letter, dims)
    return out


class Compiler:
    def __init__(self, routine: N.Routine) -> None:
        self.routine = routine
        self.locals = local_names(routine)
        self.fast = store_variables(routine)
        self.lst = Listing(routine.name, routine.kind, routine.span.file, self.locals, 0)
        self.region: Region | None = None
        self.nlabels = 0
        self.blocks: list[dict] = []      # label tables (id of a Label -> label) of the enclosing blocks
        self.loops: list[str] = []        # exit labels of the enclosing loops
        self.thunks: list = []            # (label, emitter) compiled after END
        self.in_thunk = False
        # control flow by its hand-written s_Kind, every other kind from its plan
        self.stmt_dispatch = handlers(self, "s_", [k for k in STATEMENTS if KINDS[k].control])
        self.stmt_dispatch.update((k, self.s_planned) for k in STATEMENTS if not KINDS[k].control)
        self.expr_dispatch = handlers(self, "e_", EXPRESSIONS)
        self.operand_emitters = self._operand_emitters()

    # ------------------------------------------------------------------ emitting
    def emit(self, name: str, *ops) -> None:
        assert len(ops) == len(OPS[name].operands), (name, ops)
        self.lst.instrs.append((name, list(ops), self.region))

    def new_label(self) -> str:
        self.nlabels += 1
        return f"_{self.nlabels}"

    def place(self, label: str) -> None:
        self.lst.labels[label] = len(self.lst.instrs)

    def temp(self) -> int:
        t = self.lst.ntemps
        self.lst.ntemps += 1
        return t

    def info(self, st) -> tuple:
        si = st.ann.info
        return (si.line, ("S" if si.stops else "") + ("C" if si.cond_stops else ""))

    def guarded(self, st) -> str:
        """STMT_G and a guarded region up to the returned end label."""
        assert not self.in_thunk, "STMT_G in a thunk (the VM sets frame.line for it)"
        self.region = None
        self.emit("STMT_G", self.info(st))
        end = self.new_label()
        self.region = Region("G", st.span.line, end)
        return end

    def stmt(self, st) -> None:
        """A statement ON_ERROR_PROCEED does not cover: STMT_G all the same, which takes the
        flag (it is for the next statement only; the tree interpreter's ``plain``)."""
        assert not self.in_thunk, "STMT_G in a thunk (the VM sets frame.line for it)"
        self.region = None
        self.emit("STMT_G", self.info(st))

    # ------------------------------------------------------------------ routine
    def compile(self) -> Listing:
        self.block(self.routine.body)
        self.region = None
        self.emit("END")
        self.in_thunk = True
        while self.thunks:
            label, fn = self.thunks.pop(0)
            self.place(label)
            fn()
            self.emit("END_THUNK")
        while peephole(self.lst):
            pass
        return self.lst

    def thunk(self, fn) -> str:
        label = self.new_label()
        self.thunks.append((label, fn))
        return label

    def block(self, stmts: list) -> None:
        labels = {id(s): self.new_label() for s in stmts if isinstance(s, N.Label)}
        self.blocks.append(labels)
        dispatch = self.stmt_dispatch
        try:
            for st in stmts:
                dispatch[st.__class__](st)
        finally:
            self.blocks.pop()

    # ------------------------------------------------------------------ statements
    def s_CallStmt(self, st) -> None:
        end = self.guarded(st)
        self.call(st.call, "S")
        self.place(end)

    def s_If(self, st) -> None:
        end = self.guarded(st)
        other = self.new_label()
        self.expr(st.cond)
        self.emit("JUMP_IF_FALSE", other)
        self.block(st.then)
        if st.orelse:
            self.region = None
            self.emit("JUMP", end)
            self.place(other)
            self.block(st.orelse)
        else:
            self.place(other)
        self.place(end)

    def s_Switch(self, st) -> None:
        end = self.guarded(st)
        t = self.temp()
        self.expr(st.selector)
        self.emit("STORE_TEMP", t)
        self.region = None
        bodies = []
        for case in st.cases:
            lab = self.new_label()
            bodies.append((lab, case.body))
            for ce in case.values:
                self.emit("LOAD_TEMP", t)
                self.expr(ce)
                self.emit("COMPARE", "==")
                self.emit("JUMP_IF_TRUE", lab)
        if st.default is not None:
            self.block(st.default)
        self.region = None
        self.emit("JUMP", end)
        for lab, body in bodies:
            self.place(lab)
            self.block(body)
            self.region = None
            self.emit("JUMP", end)
        self.place(end)

    def s_For(self, st) -> None:
        info = self.info(st)
        end = self.guarded(st)        # the header: an error under ON_ERROR_PROCEED skips the loop
        t = self.temp()
        self.temp()
        self.temp()
        self.temp()
        self.ref(st.var)
        self.expr(st.start)
        self.expr(st.end)
        if st.step is not None:
            self.expr(st.step)
        else:
            self.emit("CONST", 1)
        self.emit("FOR_PREP", t)
        self.emit("FOR_INIT", t)
        self.region = None
        body = self.new_label()
        self.emit("FOR_TEST", t, end)
        self.emit("TICK", info)
        self.place(body)
        self.loop_body(st.body, end)
        self.region = None
        if self.fast_scalar(st.var) == "I" and "C" not in info[1]:
            self.emit("FOR_NEXT_FAST", self.local(st.var), t, info, body)
        else:
            self.emit("FOR_NEXT", t, info, body)
        self.place(end)

    def loop_body(self, body, end) -> None:
        self.loops.append(end)
        try:
            self.block(body)
        finally:
            self.loops.pop()

    def s_While(self, st) -> None:
        info = self.info(st)
        end = self.guarded(st)
        region = self.region
        top, body = self.new_label(), self.new_label()
        self.region = None
        self.emit("TICK", info)
        # the first evaluation of the condition: ON_ERROR_PROCEED covers it (an error skips
        # the loop); the later ones are placed on the WHILE line only
        self.region = region
        self.expr(st.cond)
        self.emit("JUMP_IF_FALSE", end)
        self.region = None
        self.emit("JUMP", body)
        self.place(top)
        self.region = Region("A", st.span.line)
        self.expr(st.cond)
        self.region = None
        self.emit("JUMP_IF_FALSE", end)
        self.place(body)
        self.loop_body(st.body, end)
        self.region = None
        self.emit("JUMP_TICK", info, top)
        self.place(end)

    def s_Repeat(self, st) -> None:
        info = self.info(st)
        self.stmt(st)
        top, end = self.new_label(), self.new_label()
        self.place(top)
        self.loop_body(st.body, end)
        self.region = None
        self.emit("TICK", info)
        self.region = Region("A", st.span.line)
        self.expr(st.cond)
        self.region = None
        self.emit("JUMP_IF_FALSE", top)
        self.place(end)

    def s_Loop(self, st) -> None:
        info = self.info(st)
        self.stmt(st)
        top, end = self.new_label(), self.new_label()
        self.emit("TICK", info)
        self.place(top)
        self.loop_body(st.body, end)
        self.region = None
        self.emit("JUMP_TICK", info, top)
        self.place(end)

    def s_Exit(self, st) -> None:
        self.stmt(st)
        if self.loops:
            self.emit("JUMP", self.loops[-1])
        else:
            self.emit("EXIT_SIGNAL")

    def s_Goto(self, st) -> None:
        self.stmt(st)
        key = id(st.ann.target)
        for labels in reversed(self.blocks):
            if key in labels:
                self.emit("JUMP", labels[key])
                return
        self.emit("GOTO_FAIL", st.label.upper())

    def s_Label(self, st) -> None:
        self.place(self.blocks[-1][id(st)])

    def s_Halt(self, st) -> None:
        self.stmt(st)
        self.emit("HALT")

    def s_Return(self, st) -> None:
        if st.value is None:
            self.stmt(st)
            self.emit("RETURN")
            return
        end = self.guarded(st)        # the value: after an error under ON_ERROR_PROCEED, go on
        self.expr(st.value)
        self.region = None
        self.emit("RETURN_VAL")
        self.place(end)

    # ------------------------------------------------------------------ planned statements
    def s_planned(self, st) -> None:
        """A statement that is not control flow, from its plan (krl/semantics/statements.py):
        its prologue by its guard (STMT_G and, if GUARDED, a guarded region; none if BARE),
        then :meth:`planned_body`."""
        p = plan(st)
        end = None
        if p.guard is BARE:
            self.region = None
        elif p.guard is PLAIN:
            self.stmt(st)
        else:
            end = self.guarded(st)
        self.planned_body(st, p)
        if end is not None:
            self.place(end)

    def planned_body(self, st, p=None) -> None:
        """The operands of ``st``'s plan in order, then one STATEMENT that calls its runtime
        entry (interp/runtime/statements.py); an assignment's entry is the store instructions
        (:meth:`store`: the fast paths of Names.assign)."""
        p = p or plan(st)
        if p.entry == "assign":
            (_, value), (_, target) = p.operands
            self.expr(value)
            self.store(target)
            return
        for k, x in p.operands:
            self.operand_emitters[k](x, st)
        self.emit("STATEMENT", p.entry, len(p.operands), self.info(st))

    def _operand_emitters(self) -> dict:
        """operand kind (krl/semantics/statements.py OPERANDS) -> ``emit(payload, statement)``:
        the code that pushes the operand."""
        def thunk(body, region=None, nargs=0):
            def compile_body():
                self.region = region
                body()
            self.emit("THUNK", self.thunk(compile_body), nargs)

        return {
            "value": lambda e, st: self.expr(e),
            "const": lambda x, st: self.emit("CONST", x),
            "ref": lambda e, st: self.ref(e),
            "place_ref": lambda p, st: self.ref_place(p),
            "place": lambda p, st: self.emit("PLACE", p),
            "watch": lambda decl, st: self.emit("CONST", watch_of_decl(decl)),
            "thunk": lambda e, st: thunk(lambda: self.expr(e)),
            # evaluated while the statement runs: its errors placed on the statement (its region)
            "thunk_at": lambda e, st: thunk(lambda: self.expr(e), self.region),
            # an interrupt's handler: RESUME not caught in it
            "call": lambda c, st: thunk(lambda: self.call(c, "SN")),
            "action": self.trigger_action,
            "pairs": self.with_pairs,
            "segments": self.segments,
        }

    def trigger_action(self, act, st) -> None:
        """Push the callable that runs TRIGGER action statement ``act`` when the trigger
        fires: a thunk that starts with the packed call (TRIG_FIND, the arguments evaluated
        now, by value, §5.18, TRIG_PACK) or None (an assignment, run from its plan then)."""
        region = self.region
        if isinstance(act, N.CallStmt):
            nf = self.new_label()
            self.emit("TRIG_FIND", act.call.ann.callee, nf)
            for a in act.call.args:
                if a is None:
                    self.emit("NONE")
                else:
                    self.expr(a)
                    self.emit("VALARG")
            self.emit("TRIG_PACK", len(act.call.args))
            self.place(nf)
            self.region = region
        else:
            self.emit("NONE")
        info = self.info(act)

        def action():
            self.region = None
            self.emit("STMT", info)
            self.region = Region("A", act.span.line)
            if isinstance(act, N.CallStmt):
                slow, done = self.new_label(), self.new_label()
                self.emit("TRIG_INVOKE", slow)
                self.emit("JUMP", done)
                self.place(slow)
                self.call(act.call, "S")
                self.place(done)
            else:
                self.emit("POP")
                self.planned_body(act)
        self.emit("THUNK", self.thunk(action), 1)

    def segments(self, body, st) -> None:
        """Push a SPLINE block's segments (krl/semantics/statements.py ``segments``: the first
        operand of its plan, so that its TRIGGERs start at stack depth 0): collected in a
        temporary, each TRIGGER or conditional stop compiled as a statement of its own."""
        region = self.region
        t = self.temp()
        self.emit("SPL_BEGIN", t)
        for what, x in segment_plan(body):
            if what == "statement":
                self.emit("SPL_TRIG_BEGIN", t)
                self.s_planned(x)
                self.region = region
                self.emit("SPL_TRIG_END", t)
            else:
                for k, p in x:
                    self.operand_emitters[k](p, None)
                self.emit("SPL_SEG", len(x), t)
        self.emit("LOAD_TEMP", t)

    def with_pairs(self, with_, st=None) -> None:
        """Push the WITH list's (reference, value) pairs as one list (PAIRS)."""
        for w in with_:
            self.ref(w.target)
            self.expr(w.value)
        self.emit("PAIRS", len(with_))

    # ------------------------------------------------------------------ calls
    def args(self, call: N.Call) -> None:
        for a in call.args:
            if a is None:
                self.emit("NONE")
            elif isinstance(a, (N.Name, N.Index, N.Field)):
                self.ref(a)
            else:
                self.expr(a)
                self.emit("VALARG")

    def call(self, call: N.Call, flags: str) -> None:
        self.args(call)
        self.emit("CALL", call.ann.callee, len(call.args), flags)

    # ------------------------------------------------------------------ names
    @staticmethod
    def operand(place):
        """(class, operand) of a place (the front end's Storage): LOCAL and the frame slot,
        MOD or GLOBAL and the place itself (the VM numbers those by the place)."""
        if place.kind == LOCAL:
            return "LOCAL", place.slot
        return ("MOD" if place.kind == MODULE else "GLOBAL"), place

    def ref_place(self, place) -> None:
        kind, op = self.operand(place)
        self.emit("REF_" + kind, op)

    def fast_scalar(self, e) -> str | None:
        """The type letter of ``e`` if it is a scalar store variable, else None."""
        if e.__class__ is N.Name and e.ann.place.kind == LOCAL:
            got = self.fast.get(e.ann.place.slot)
            if got is not None and got[1] == 0:
                return got[0]
        return None

    def fast_array(self, e) -> str | None:
        """The element type letter of ``e`` if it is ``store array[i]`` or ``[i, j]`` with
        every index given and as many as the array's dimensions, else None."""
        if isinstance(e, N.Index) and isinstance(e.base, N.Name) and None not in e.indices \
                and e.base.ann.place.kind == LOCAL:
            got = self.fast.get(e.base.ann.place.slot)
            if got is not None and got[1] == len(e.indices):
                return got[0]
        return None

    @staticmethod
    def local(e: N.Name) -> int:
        """The frame slot of a LOCAL name (the ``s``/``v`` operand: the resolver's Storage.slot)."""
        return e.ann.place.slot

    def ref(self, e) -> None:
        if isinstance(e, N.Name):
            self.ref_place(e.ann.place)
        elif isinstance(e, N.Index):
            self.ref(e.base)
            self.indices(e)
            self.emit("INDEX", len(e.indices), lvalue_name(e.base))
        elif isinstance(e, N.Field):
            self.ref(e.base)
            self.emit("FIELD", e.ann.component, lvalue_name(e.base))
        else:
            self.emit("RAISE", "not a variable", 0)

    def indices(self, e: N.Index) -> None:
        for i in e.indices:
            if i is None:
                self.emit("NONE")
            else:
                self.expr(i)

    def store(self, target) -> None:
        letter = self.fast_scalar(target)
        if letter is not None and letter in "IRB":
            self.emit("STORE_FAST", self.local(target), letter)
            return
        letter = self.fast_array(target)
        if letter is not None:
            self.indices(target)
            self.emit(f"STORE_ELEM{len(target.indices)}", self.local(target.base), lvalue_name(target.base),
                      letter)
            return
        if isinstance(target, N.Name):
            kind, op = self.operand(target.ann.place)
            self.emit("STORE_" + kind, op)
        elif isinstance(target, N.Index) and None not in target.indices:
            self.ref(target.base)
            self.indices(target)
            if len(target.indices) == 1:
                self.emit("STORE_INDEX1", lvalue_name(target.base))
            else:
                self.emit("STORE_INDEX", len(target.indices), lvalue_name(target.base))
        elif isinstance(target, N.Field):
            self.ref(target.base)
            self.emit("STORE_FIELD", target.ann.component, lvalue_name(target.base))
        else:
            self.ref(target)
            self.emit("ASSIGN")

    # ------------------------------------------------------------------ expressions
    def fold(self, e):
        """(True, value) if ``e`` is a constant the operators (krl/semantics/values.py) can fold."""
        if isinstance(e, (N.IntLit, N.RealLit, N.BoolLit, N.StrLit)):
            return True, e.value
        if isinstance(e, N.EnumLit):
            return True, EnumValue(e.name)
        try:
            if isinstance(e, N.Unary):
                ok, a = self.fold(e.operand)
                if ok:
                    v = unary_op(e.op, a)
                    return isinstance(v, _FOLDABLE), v
            elif isinstance(e, N.Binary):
                left, chain = N.left_chain(e)
                n, v = self.fold_chain(left, chain)
                return n == len(chain), v
        except KrlRuntimeError:
            pass
        return False, None

    def fold_chain(self, left, chain):
        """How far a left-nested chain of binary operators (``chain`` innermost first, as
        krl.ast.nodes.left_chain gives it) folds, in a loop: (n, value) when ``left`` and the
        first n operators of the chain are constants (n = 0: ``left`` alone, if it folds);
        (0, None) when nothing folds. An operator folds when :meth:`fold` would fold it."""
        ok, a = self.fold(left)
        if not ok:
            return 0, None
        for n, b in enumerate(chain):
            if b.op == ":":
                return n, a
            try:
                ok, r = self.fold(b.right)
                if not ok:
                    return n, a
                v = binary_op(b.op, a, r)
            except KrlRuntimeError:
                return n, a
            if not isinstance(v, _FOLDABLE):
                return n, a
            a = v
        return len(chain), a

    def expr(self, e) -> None:
        self.expr_dispatch[e.__class__](e)

    def e_literal(self, e) -> None:
        self.emit("CONST", e.value)

    e_IntLit = e_RealLit = e_BoolLit = e_StrLit = e_literal

    def e_EnumLit(self, e) -> None:
        self.emit("CONST", EnumValue(e.name))

    def e_ChannelName(self, e) -> None:
        self.emit("CONST", Channel(e.name))

    def e_Name(self, e) -> None:
        if self.fast_scalar(e) is not None:
            self.emit("LOAD_FAST", self.local(e))
            return
        kind, op = self.operand(e.ann.place)
        self.emit("LOAD_" + kind, op)

    def e_Index(self, e) -> None:
        if self.fast_array(e) is not None:
            self.indices(e)
            self.emit(f"LOAD_ELEM{len(e.indices)}", self.local(e.base), lvalue_name(e.base))
            return
        self.ref(e.base)
        self.indices(e)
        if None in e.indices:
            self.emit("INDEX", len(e.indices), lvalue_name(e.base))
            self.emit("DEREF")
        elif len(e.indices) <= 2:
            self.emit(f"LOAD_INDEX{len(e.indices)}", lvalue_name(e.base))
        else:
            self.emit("LOAD_INDEX", len(e.indices), lvalue_name(e.base))

    def e_Field(self, e) -> None:
        self.ref(e.base)
        self.emit("LOAD_FIELD", e.ann.component, lvalue_name(e.base))

    def e_Call(self, e) -> None:
        self.call(e, "E")

    def e_Unary(self, e) -> None:
        ok, v = self.fold(e)
        if ok:
            self.emit("CONST", v)
            return
        self.expr(e.operand)
        self.emit("UNOP", e.op)

    def e_Binary(self, e) -> None:
        # a left-nested chain (up to MAX_EXPRESSION_TERMS terms) in a loop: the longest
        # constant start of the chain is one CONST, as recursing would fold it
        left, chain = N.left_chain(e)
        n, v = self.fold_chain(left, chain)
        if n == len(chain):                      # all of it is a constant
            self.emit("CONST", v)
            return
        if n:
            self.emit("CONST", v)
        else:
            self.expr(left)
        for b in chain[n:]:
            self.expr(b.right)
            fast = _FAST_BINOPS.get(b.op)
            if fast is not None:
                self.emit(fast)
            elif b.op in _COMPARISONS:
                self.emit("COMPARE", b.op)
            else:
                self.emit("BINOP", b.op)

    def e_Aggregate(self, e) -> None:
        for it in e.items:
            self.expr(it.value)
        struc = e.ann.struc if e.type_name else None
        self.emit("AGG", struc if struc is not None else e.type_name, len(e.items),
                  ",".join(it.ann.component.key for it in e.items))


def peephole(lst: Listing) -> bool:
    """Replace sequences of instructions by the superinstruction whose parts they are
    (opcodes.MACROS: ``macro`` in interp/vm/instructions.py; its operands are its parts',
    concatenated); True if it replaced any (a superinstruction may be the part of another one:
    the next pass fuses it). A sequence is fused only when no label points inside it and all of
    it lies in one error region, the fused instruction's; a superinstruction with ``errors_from``
    (only that part can raise) takes that part's region whatever the others'. Three-part
    sequences go first, and a pair is left alone when its second instruction starts a triple."""
    old = lst.instrs
    targets = set(lst.labels.values())
    new: list = []
    where: dict = {}

    def fusion(i: int, n: int):
        """(fused instruction, region) for old[i:i+n], or None."""
        group = old[i:i + n]
        if len(group) < n or any(i + k in targets for k in range(1, n)):
            return None
        name = MACROS.get(tuple(g[0] for g in group))
        if name is None:
            return None
        regions = [g[2] for g in group]
        only = OPS[name].errors_from
        if only is None and not all(r is regions[0] for r in regions):
            return None
        return (name, [v for g in group for v in g[1]]), regions[0 if only is None else only]

    i = 0
    while i < len(old):
        done = False
        for n in (3, 2):
            got = fusion(i, n)
            if got is None:
                continue
            if n == 2 and i + 1 not in targets and fusion(i + 1, 3) is not None:
                continue      # leave old[i + 1] to the longer sequence it starts
            fused, region = got
            where[i] = len(new)
            new.append((fused[0], fused[1], region))
            i += n
            done = True
            break
        if not done:
            where[i] = len(new)
            new.append(old[i])
            i += 1
    where[len(old)] = len(new)
    lst.instrs = new
    lst.labels = {k: where[v] for k, v in lst.labels.items()}
    return len(new) < len(old)


def compile_routine(routine: N.Routine) -> Listing:
    """The instruction listing of ``routine``, from its annotated AST alone (the front end's
    facts, krl/semantics/resolve.py; no runtime): for vm.link (the VM's executed form, kept
    per workspace by the VM, interp/vm/vm.py ``linked_code``) and assembler.format_listing
    (`krl asm`)."""
    return Compiler(routine).compile()


def compile_module(routines) -> str:
    """The readable assembly text of ``routines`` (a module's, main routine first): what
    the VM runs (`krl asm` and the round-trip tests; the VM never reads text)."""
    parts = []
    seen = set()
    for r in routines:
        if id(r) not in seen:
            seen.add(id(r))
            parts.append(format_listing(compile_routine(r)))
    return "\n".join(parts)
