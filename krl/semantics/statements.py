"""The statement kinds of KRL, declared once: what each statement evaluates, in which order,
under which error guard, and which runtime entry it calls (issue 76, "statements defined
once"; docs/architecture.md, "Statements: where to add one").

:data:`KINDS` maps every statement class of krl/ast/nodes.py to one :class:`StatementKind`.
A kind is either *control flow* (IF, LOOP, WHILE, REPEAT, FOR, SWITCH, GOTO, EXIT, HALT,
RETURN, a routine call, a label): its stepping is written in each back end (the tree
interpreter, interp/tree/interpreter.py, and the compiler, interp/vm/compiler.py), because
stepping is what the two back ends do differently. Every other kind is *planned*: its
:func:`plan` is a tuple of operands in evaluation order, and both back ends handle it with
one generic routine: the tree interpreter evaluates the operands in order and calls the
runtime entry; the compiler emits them in order and one ``STATEMENT`` instruction that calls
the same entry (interp/runtime/statements.py ``ENTRIES``; the plan names it by string, the
front end importing no interpreter).

An operand is ``(kind, payload)``; its kinds (:data:`OPERANDS`):

* ``value`` an expression evaluated now; ``const`` a static value (a literal: a string, a
  number, a bool or None; what the statement's text fixes);
* ``ref`` the reference of a variable (an lvalue expression, evaluated now: its indices);
* ``place_ref`` the reference of a place the resolver found (a ``Storage``: an analog
  channel); ``place`` the place itself (the key of what ANIN/ANOUT switch on and off);
* ``thunk`` an expression evaluated later, a callable without arguments (a cyclic value, a
  condition the controller polls), its errors not placed on the statement; ``thunk_at`` the
  same, evaluated while the statement runs (WAIT FOR), its errors placed on the statement's
  line; ``call`` a call statement run later (an interrupt's handler; a RESUME in it is not
  caught in the handler, §5.17); ``action`` a TRIGGER's action statement (its arguments
  evaluated now, by value, §5.18), a callable;
* ``pairs`` the WITH list: the (reference, value) pairs, each reference then its value;
* ``watch`` the watch class of an INTERRUPT DECL's condition (interp/runtime/watch.py
  ``watch_of_decl``: which changes can change its value), a string;
* ``segments`` a SPLINE block's body (its motions' operands and the TRIGGERs and
  conditional stops between them, each run as a planned statement of its own).

The *guard* of a kind (§5.19, ON_ERROR_PROCEED): ``GUARDED`` the statement's evaluation is
covered (an error is recorded in $ERR and the next statement runs), ``PLAIN`` it is not but
the statement takes the flag all the same (the flag is for the next statement only), ``BARE``
no statement prologue at all (a statement that cannot run raises at its line).

tests/interp/test_statement_table.py checks the table against the AST's statement classes, the
runtime's entries and both back ends.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from krl.ast import nodes as N
from krl.semantics.facts import (BESIDE, CLOCK, EXPRESSIONS, REPEAT, ROBOT, SIGNALS, TARGET, TASKS, WORLD, Facts,
                                 facts)

#: the guards (§5.19)
GUARDED, PLAIN, BARE = "guarded", "plain", "bare"

#: the operand kinds of a plan (the module docstring says what each is)
OPERANDS = ("value", "const", "ref", "place_ref", "place", "thunk", "thunk_at", "call", "action",
            "pairs", "segments", "watch")


@dataclass(frozen=True, slots=True)
class StatementKind:
    """One statement kind: ``control`` (stepping written in each back end; then the other
    fields are empty), ``guard`` (GUARDED, PLAIN or BARE), ``entries`` the runtime entries
    its plans call (interp/runtime/statements.py ENTRIES; more than one when the statement's
    facts choose: a cyclic flag's assignment), ``operands`` the node -> (entry, operands)
    function (:func:`plan` calls it), ``doc`` the reference section it follows; ``facts``
    what it reads and writes, whether it stops the advance run and how the fast-forward may
    treat it (krl/semantics/facts.py :class:`~krl.semantics.facts.Facts`; every kind has them)."""
    control: bool
    guard: str = ""
    entries: tuple = ()
    operands: Callable | None = None
    doc: str = ""
    facts: Facts | None = None


def _value_or_none(e) -> tuple:
    return ("value", e) if e is not None else ("const", None)


def _assign(st):
    if st.ann.cyclic:       # a cyclic flag: re-evaluated every IPO cycle until assigned again (§5.15)
        return "cyclic_assign", (("value", st.value), ("ref", st.target), ("thunk", st.value))
    return "assign", (("value", st.value), ("ref", st.target))


def _stub(st):
    words = getattr(st, "words", None)
    return "stub", (("const", " ".join(words) if words else type(st).__name__.upper()),)


def _interrupt_decl(st):
    brake = st.brake
    handler = ("const", None) if brake is not None else ("call", st.call)
    return "interrupt_decl", (("value", st.prio), ("thunk", st.when), handler,
                              ("const", brake.fast if brake is not None else None), ("const", st.call.name),
                              ("const", st.is_global), ("watch", st))


def _trigger(st):
    return "trigger", (("action", st.action), ("value", st.at), ("value", st.delay), _value_or_none(st.prio),
                       ("const", st.kind), ("const", st.onstart))


def _motion(st):
    return "motion", (("value", st.target), _value_or_none(st.aux), _value_or_none(st.ca), ("pairs", st.with_),
                      ("const", st.kind), ("const", ",".join(st.approx)), ("const", st.frame))


def _spline(st):
    return "spline", (("segments", st.body), ("pairs", st.with_), ("const", st.kind), ("const", st.approx))


def _anout_on(st):
    ch = st.ann.channel
    return "anout_on", (("place_ref", ch), _value_or_none(st.minimum), _value_or_none(st.maximum),
                        ("thunk", st.value), ("place", ch))


def _row(guard, entries, operands, doc, fx: Facts) -> StatementKind:
    return StatementKind(False, guard, entries, operands, doc, fx)


def _control(fx: Facts) -> StatementKind:
    return StatementKind(True, facts=fx)


#: the facts the table shares: a step of a pass that reads its expressions (and writes its
#: target), its stand-in calls once at its step or not
_READS = facts((EXPRESSIONS,), fast_forward=REPEAT)
_JUMPS = facts(fast_forward=REPEAT)
_ANALOG = "analog I/O"

#: every statement kind: node class -> StatementKind (checked complete by
#: tests/interp/test_statement_table.py and tests/interp/test_facts.py). Its facts: the
#: advance-run stops of reference §5.8-§5.14 and §6.10 (INTERRUPT ON/OFF/ENABLE/DISABLE stop it
#: too, [U]: otherwise the ``INTERRUPT OFF`` after the interruptible motion of §5.17 would run
#: before the motion); the statements a parked pass may run (``REPEAT``: their only effects are
#: writes the spin watch checks, a WAIT FOR that holds; interp/runtime/spin.py), and a motion,
#: which another task may run beside a parked period (``BESIDE``: interp/runtime/period.py);
#: the kinds that write ROBOT are the motion statements a submit program may not hold (§9, E406)
KINDS: dict = {
    N.Assign: _row(GUARDED, ("assign", "cyclic_assign"), _assign, "§5.1, §5.15",
                   facts((EXPRESSIONS,), (TARGET,), fast_forward=REPEAT, stub_once=True)),
    N.CallStmt: _control(facts((EXPRESSIONS,), (TARGET,), fast_forward=REPEAT, stub_once=True)),
    N.If: _control(facts((EXPRESSIONS,), fast_forward=REPEAT, stub_once=True)),
    N.Switch: _control(_READS), N.For: _control(facts((EXPRESSIONS,), (TARGET,), fast_forward=REPEAT)),
    N.While: _control(_READS), N.Repeat: _control(_READS), N.Loop: _control(_JUMPS), N.Exit: _control(_JUMPS),
    N.Goto: _control(_JUMPS), N.Label: _control(_JUMPS), N.Return: _control(_READS),
    N.Halt: _control(facts(writes=(TASKS,), stops="HALT")),
    N.WaitFor: _row(GUARDED, ("wait_for",), lambda st: ("wait_for", (("thunk_at", st.cond),)), "§5.8",
                    facts((EXPRESSIONS, CLOCK), stops="WAIT FOR", fast_forward=REPEAT)),
    N.WaitSec: _row(GUARDED, ("wait_sec",), lambda st: ("wait_sec", (("value", st.time),)), "§5.8",
                    facts((EXPRESSIONS, CLOCK), stops="WAIT SEC")),
    N.Continue: _row(PLAIN, ("set_continue",), lambda st: ("set_continue", ()), "§5.9",
                     facts(writes=(TASKS,), fast_forward=REPEAT)),
    N.OnErrorProceed: _row(PLAIN, ("on_error_proceed",), lambda st: ("on_error_proceed", ()), "§5.19",
                           facts(writes=(TASKS,))),
    N.InterruptDecl: _row(GUARDED, ("interrupt_decl",), _interrupt_decl, "§5.16",
                          facts((EXPRESSIONS,), (TASKS,))),
    N.InterruptCtl: _row(GUARDED, ("interrupt_ctl",),
                         lambda st: ("interrupt_ctl", (("const", st.action), _value_or_none(st.prio))), "§5.16",
                         facts((EXPRESSIONS,), (TASKS,), stops="INTERRUPT ON/OFF")),
    N.Brake: _row(PLAIN, ("brake",), lambda st: ("brake", (("const", st.fast),)), "§5.17",
                  facts(writes=(ROBOT, TASKS), name="BRAKE")),
    N.Resume: _row(PLAIN, ("resume",), lambda st: ("resume", ()), "§5.17",
                   facts(writes=(ROBOT, TASKS), name="RESUME")),
    N.Trigger: _row(GUARDED, ("trigger",), _trigger, "§5.18", facts((EXPRESSIONS,), (ROBOT,), name="TRIGGER")),
    N.ConditionalStop: _row(GUARDED, ("conditional_stop",), lambda st: (
        "conditional_stop", (("value", st.path), ("thunk", st.cond), ("const", st.onstart))), "KSS 8.3 STOP WHEN PATH",
        facts((EXPRESSIONS,), (ROBOT,), name="STOP WHEN PATH")),
    N.AninOn: _row(GUARDED, ("anin_on",), lambda st: (
        "anin_on", (("ref", st.target), ("thunk", st.value), ("place", st.ann.channel))), "§5.14",
        facts((EXPRESSIONS, SIGNALS), (TARGET,), stops=_ANALOG)),
    N.AninOff: _row(PLAIN, ("anin_off",), lambda st: ("anin_off", (("place", st.ann.channel),)), "§5.14",
                    facts(writes=(SIGNALS,), stops=_ANALOG)),
    N.AnoutOn: _row(GUARDED, ("anout_on",), _anout_on, "§5.14", facts((EXPRESSIONS,), (SIGNALS,), stops=_ANALOG)),
    N.AnoutOff: _row(PLAIN, ("anout_off",), lambda st: ("anout_off", (("place", st.ann.channel),)), "§5.14",
                     facts(writes=(SIGNALS,), stops=_ANALOG)),
    N.Motion: _row(GUARDED, ("motion",), _motion, "§6.1", facts((EXPRESSIONS,), (ROBOT,), fast_forward=BESIDE)),
    N.SplineBlock: _row(GUARDED, ("spline",), _spline, "§6.2", facts((EXPRESSIONS,), (ROBOT,))),
    N.KeywordStmt: _row(PLAIN, ("stub",), _stub, "§5.20", facts(writes=(WORLD,))),
    N.MoveEmi: _row(PLAIN, ("stub",), _stub, "§5.20", facts(writes=(WORLD,))),
    N.DeclStmt: _row(BARE, ("declaration",), lambda st: ("declaration", ()), "§2.2", facts(writes=(TASKS,))),
    N.Unparsed: _row(BARE, ("not_understood",),
                     lambda st: ("not_understood", (("const", st.text), ("const", st.error))), "§8",
                     facts(writes=(TASKS,))),
    N.Unsupported: _row(BARE, ("unsupported",), lambda st: ("unsupported", (("const", st.text),)), "§8",
                        facts(writes=(TASKS,))),
}


def facts_of(cls: type) -> Facts:
    """The facts of statement class `cls` (KeyError for a class that is no statement kind)."""
    return KINDS[cls].facts


def kinds_where(test) -> tuple:
    """The statement classes whose facts pass `test` (a Facts -> bool), in table order."""
    return tuple(cls for cls, kind in KINDS.items() if test(kind.facts))


@dataclass(frozen=True, slots=True)
class Plan:
    """A planned statement's plan: the runtime ``entry`` (a name of interp/runtime/statements.py
    ENTRIES), its ``guard`` and its ``operands`` in evaluation order."""
    entry: str
    guard: str
    operands: tuple


def plan(st) -> Plan:
    """The plan of statement ``st`` (a node of a planned kind; its annotations the resolver's).
    Raises KeyError for a control-flow kind (it has no plan)."""
    kind = KINDS[st.__class__]
    if kind.control:
        raise KeyError(f"{type(st).__name__} is control flow: it has no plan")
    entry, operands = kind.operands(st)
    return Plan(entry, kind.guard, operands)


def segments(body: list) -> list:
    """A SPLINE block's body as its ``segments`` operand evaluates it, in order: ``("motion",
    operands)`` for a motion (its segment's operands: target, auxiliary point, CA, the WITH
    pairs, the motion kind, the line) and ``("statement", s)`` for a TRIGGER or conditional
    stop (a planned statement of its own, whose trigger entry waits for the next segment);
    other statements of the block are not run (§6.2)."""
    out = []
    for s in body:
        if isinstance(s, (N.Trigger, N.ConditionalStop)):
            out.append(("statement", s))
        elif isinstance(s, N.Motion):
            out.append(("motion", (("value", s.target), _value_or_none(s.aux), _value_or_none(s.ca),
                                   ("pairs", s.with_), ("const", s.kind), ("const", s.span.line))))
    return out


def is_planned(cls: type) -> bool:
    """True when statement class ``cls`` is handled from its plan (not control flow)."""
    return not KINDS[cls].control


__all__ = ["BARE", "GUARDED", "KINDS", "OPERANDS", "PLAIN", "Plan", "StatementKind", "facts_of", "is_planned", "kinds_where",
           "plan", "segments"]
