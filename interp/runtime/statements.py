"""The runtime entries of the planned statements: what a statement that is not control flow
does once its operands are evaluated, written once for both interpreters.

krl/semantics/statements.py declares each statement kind (its operands in evaluation order,
its ON_ERROR_PROCEED guard and the name of its entry here); the tree interpreter
(interp/tree/interpreter.py ``s_planned``) evaluates the operands and calls the entry, the VM's
``STATEMENT`` instruction (interp/vm/instructions.py) calls it with the operands the compiled
code pushed. An entry is ``entry(rt, frame, info, *operands)``: the Runtime, the activation
(interp/runtime/contexts.py ``Frame``), the statement's StmtInfo (its file and line, where
errors and motions are placed) and the operands in the plan's order. A deferred operand
(``thunk``, ``thunk_at``, ``call``, ``action``) arrives as a callable without arguments.

:data:`ENTRIES` maps each name the table uses to its entry; tests/interp/test_statement_table.py
checks that each name of the table has an entry, and that each entry takes as many operands as
each plan gives it.
"""

from __future__ import annotations

from .convert import num
from .errors import KrlRuntimeError, not_understood_text
from .slots import anout_limits, anout_value, trigger_args


# ------------------------------------------------------------------ assignment (§5.1, §5.15)
def assign(rt, frame, info, value, ref) -> None:
    """``target = value`` (the VM inlines this as its store instructions, interp/vm/compiler.py
    ``store``: the fast paths of Names.assign)."""
    rt.names.assign(ref, value)


def cyclic_assign(rt, frame, info, value, ref, value_of) -> None:
    """The assignment of a cyclic flag: assigned now, then ``value_of()`` every IPO cycle
    until assigned again (§5.15)."""
    names = rt.names
    names.assign(ref, value)
    rt.cyclic.on(("cyclic flag", ref.name), lambda: names.assign(ref, value_of()))


# ------------------------------------------------------------------ waiting and the advance run (§5.8, §5.9, §5.19)
def wait_for(rt, frame, info, cond) -> None:
    """WAIT FOR: Runtime.wait_for with the condition's callable."""
    rt.wait_for(cond)


def wait_sec(rt, frame, info, time) -> None:
    """WAIT SEC: Runtime.wait_sec (seconds)."""
    rt.wait_sec(time)


def set_continue(rt, frame, info) -> None:
    """CONTINUE: the next line does not stop the advance run (Runtime.set_continue)."""
    rt.set_continue(info)


def on_error_proceed(rt, frame, info) -> None:
    """ON_ERROR_PROCEED: the next statement's errors are recorded in $ERR (ErrorState)."""
    rt.errstate.on_error_proceed()


# ------------------------------------------------------------------ interrupts (§5.16, §5.17)
def interrupt_decl(rt, frame, info, prio, cond, handler, brake_fast, name, is_global, watch) -> None:
    """INTERRUPT DECL prio WHEN cond DO handler: Interrupts.declare. ``handler`` None: the
    declaration's DO BRAKE (``brake_fast``: BRAKE F); ``watch``: the condition's watch class
    (interp/runtime/watch.py)."""
    if handler is None:
        def handler():
            rt.interrupts.brake(brake_fast)
    rt.interrupts.declare(prio, lambda: rt.to_bool(cond(), "interrupt condition"), handler, name, frame,
                          is_global, info.line, watch)


def interrupt_ctl(rt, frame, info, action, prio) -> None:
    """INTERRUPT ON/OFF/ENABLE/DISABLE [prio]: Interrupts.control."""
    rt.interrupts.control(action, prio)


def brake(rt, frame, info, fast) -> None:
    """BRAKE [F]: Interrupts.brake."""
    rt.interrupts.brake(fast)


def resume(rt, frame, info) -> None:
    """RESUME: Interrupts.resume."""
    rt.interrupts.resume()


# ---------------------------------------------------- triggers, conditional stops, motion (§5.18, §6.1, §6.2)
def trigger(rt, frame, info, action, at, delay, prio, kind, onstart) -> None:
    """TRIGGER WHEN DISTANCE/PATH ... DO action: MotionStatements.trigger (the action a
    callable that runs the action statement)."""
    rt.motions.trigger(action, line=info.line, **trigger_args(kind, at, delay, prio, onstart))


def conditional_stop(rt, frame, info, path, cond, onstart) -> None:
    """STOP WHEN PATH = path [ONSTART] IF cond: MotionStatements.conditional_stop."""
    rt.motions.conditional_stop(path, onstart, lambda: rt.to_bool(cond(), "conditional stop"), info.line)


def motion(rt, frame, info, target, aux, ca, pairs, kind, approx, frame_kind) -> None:
    """PTP/LIN/CIRC/SPL/... target: MotionStatements.motion. ``approx``: the approximation
    keywords joined by commas ("" none)."""
    rt.motions.motion(kind, target, approx.split(",") if approx else [], aux, ca, frame_kind, pairs,
                      info.file, info.line)


class Segments:
    """The segments of a SPLINE block as its body runs: each motion's segment, with the
    triggers and conditional stops declared since the previous one (a TRIGGER in the block
    runs as a statement of its own, its entry set aside for the next segment)."""

    __slots__ = ("task", "segs", "pending", "saved")

    def __init__(self, rt) -> None:
        self.task = rt.clock.current_task
        self.segs: list = []
        self.pending: list = []
        self.saved = None

    def begin_statement(self) -> None:
        """Before a TRIGGER or conditional stop of the block: set the task's list aside."""
        self.saved = self.task.next_triggers
        self.task.next_triggers = []

    def end_statement(self) -> None:
        """After it: its entries wait for the next segment."""
        self.pending += self.task.next_triggers
        self.task.next_triggers = self.saved

    def motion(self, target, aux, ca, pairs, kind, line) -> None:
        """A segment of the block (CA as REAL)."""
        self.segs.append({"kind": kind, "target": target, "aux": aux, "ca": float(num(ca)) if ca is not None else None,
                          "with_": pairs, "triggers": self.pending, "line": line})
        self.pending = []


def spline(rt, frame, info, segments, pairs, kind, approx) -> None:
    """SPLINE ... ENDSPLINE (PTP_SPLINE): MotionStatements.spline with the block's segments."""
    rt.motions.spline(kind, segments.segs, approx, pairs, info.file, info.line)


# ------------------------------------------------------------------ analog I/O (§5.14)
def anin_on(rt, frame, info, ref, value_of, channel) -> None:
    """ANIN ON target = value: assigned now and every IPO cycle (``channel``: the input SIGNAL
    the value reads, None when the checker found none: assigned once)."""
    names = rt.names

    def tick():
        names.assign(ref, value_of())
    tick()
    if channel is not None:
        rt.cyclic.on(("analog input", channel.key), tick)


def anin_off(rt, frame, info, channel) -> None:
    """ANIN OFF: Cyclic.off."""
    rt.cyclic.off(("analog input", channel.key))


def anout_on(rt, frame, info, ref, lo, hi, value_of, channel) -> None:
    """ANOUT ON channel = value [MINIMUM lo] [MAXIMUM hi]: the value, clamped, every IPO cycle."""
    lo, hi = anout_limits(lo, hi)

    def tick():
        ref.set(anout_value(value_of(), lo, hi))
    tick()
    rt.cyclic.on(("analog output", channel.key), tick)


def anout_off(rt, frame, info, channel) -> None:
    """ANOUT OFF: Cyclic.off."""
    rt.cyclic.off(("analog output", channel.key))


# ------------------------------------------------------------------ recognised, not simulated; not runnable
def stub(rt, frame, info, words) -> None:
    """CONFIRM, ASYPTP, MOVE_EMI, ... (§5.20): Runtime.stub_statement."""
    rt.stub_statement(words)


def declaration(rt, frame, info) -> None:
    """A declaration after the first statement: the run stops with an error at its line."""
    raise KrlRuntimeError("declaration after the first statement", None, info.file, info.line)


def unsupported(rt, frame, info, text) -> None:
    """A statement the simulator does not support: the run stops with an error at its line."""
    raise KrlRuntimeError(f"unsupported statement: {text.strip()[:60]}", None, info.file, info.line)


def not_understood(rt, frame, info, text, error) -> None:
    """A line the grammar does not accept (errors.not_understood): the run stops there."""
    raise KrlRuntimeError(not_understood_text(text, error), None, info.file, info.line)


#: every entry by the name krl/semantics/statements.py gives it
ENTRIES: dict = {fn.__name__: fn for fn in (
    assign, cyclic_assign, wait_for, wait_sec, set_continue, on_error_proceed, interrupt_decl, interrupt_ctl,
    brake, resume, trigger, conditional_stop, motion, spline, anin_on, anin_off, anout_on, anout_off, stub,
    declaration, unsupported, not_understood)}
