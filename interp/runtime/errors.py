"""Run-time errors of KRL programs (reference §8).

:class:`KrlRuntimeError` (the front end's, krl/semantics/values.py: the operators raise it
too) carries the KRL message, the KSS message number where the reference gives one (1422
"value invalid", 1430 "interrupt not declared") and the place (file, line) — filled in by
:meth:`KrlRuntimeError.at` when the error crosses a statement. :class:`ResourceError` is the
error of a resource limit.

The control-flow signals (:class:`GotoSignal`, :class:`ExitSignal`, :class:`ReturnSignal`,
:class:`ResumeSignal`, :class:`HaltSignal`, :class:`StopRun`, :class:`ProgramSelected`) are
exceptions too: the tree
interpreter unwinds with them, as the paper describes; the VM uses the last three.
"""

from __future__ import annotations

from krl.ast import nodes as N
from krl.semantics.values import INTERRUPT_NOT_DECLARED, VALUE_INVALID, KrlRuntimeError, value_invalid


class ResourceError(KrlRuntimeError):
    """A run-time error for a resource limit of krl/limits.py (data memory, type nesting):
    loading a data list never skips it as it skips a bad initial value; it stops the run."""


class ControlSignal(Exception):
    """Base of the unwinding signals (never shown to users)."""


class GotoSignal(ControlSignal):
    """GOTO: unwinds to the statement list that holds ``target`` (the Label the front end
    resolved, krl/semantics/resolve.py; None: no enclosing block has it); ``label`` the
    GOTO's label name, for the error "label not found"."""

    def __init__(self, label: str, target=None) -> None:
        super().__init__(label)
        self.label = label.upper()
        self.target = target


class ExitSignal(ControlSignal):
    pass


class ReturnSignal(ControlSignal):
    def __init__(self, value=None) -> None:
        super().__init__()
        self.value = value


class ResumeSignal(ControlSignal):
    """RESUME: unwinds to the call in progress in ``frame`` (the declaring routine)."""

    def __init__(self, frame) -> None:
        super().__init__()
        self.frame = frame


class HaltSignal(ControlSignal):
    """HALT in a program: the run stops here (the simulation has no operator to restart it)."""


class ProgramSelected(ControlSignal):
    """The robot interpreter's program was stopped, deselected and another one selected by
    ``$CMD`` (interp/runtime/cmdchannel.py), and Automatic External's PLC starts it: raised in
    the robot task at its next resume (``Runtime.service``) to unwind the old program; the task
    then runs the main routine of ``module`` from its start. ``text`` says what selected it."""

    def __init__(self, module: str, text: str) -> None:
        super().__init__(module)
        self.module = module
        self.text = text


class StopRun(ControlSignal):
    """The scheduler ends the run (limit, deadlock, end of the robot program); raised inside
    a task to unwind it. ``reason`` as in the ``end`` trace event."""

    def __init__(self, reason: str, text: str = "") -> None:
        super().__init__(reason)
        self.reason = reason
        self.text = text


#: the words every stop on a line the grammar does not accept begins with: the simulator's
#: gap, not the program's error (interp/realprograms.py GAP_MESSAGES)
NOT_UNDERSTOOD = "line not understood by krl-tools"


def not_understood(st: N.Unparsed) -> str:
    """The message of a run that reaches a line the grammar does not accept (an ``Unparsed``
    statement, issue 63), in both interpreters alike. A line whose form KRL rejects (its
    ``error``: krl/diagnostics ``PROGRAM_SYNTAX_CODES``, a compile error of the reference, 8.1)
    is the program's error, in the checker's words: ``syntax error E012: ...``. Any other line
    may be a construct the recovered grammar lacks: the controller runs it, the simulator
    cannot say what it does, so the run stops there as the simulator's gap."""
    return not_understood_text(st.text, st.error)


def not_understood_text(text: str, error: str) -> str:
    """:func:`not_understood` of a line of source ``text`` with the checker's ``error`` ("" if none)."""
    if error:
        return f"syntax error {error}"
    return f"{NOT_UNDERSTOOD} (the controller runs it; the simulation stops here): {' '.join(text.split())[:60]}"


def not_entered(routine: N.Routine) -> str:
    """The message of a call of a routine whose blocks the parser could not close
    (``Routine.broken``: the line not understood from which its statements may belong
    elsewhere): the run stops at the call rather than run statements out of their blocks."""
    return (f"{NOT_UNDERSTOOD}: routine {routine.name} is not entered, its blocks are in doubt from "
            f"line {routine.broken} on")


def lvalue_name(e) -> str:
    """The name of an lvalue expression (krl.ast nodes) as run-time messages show it:
    ``p``, ``a[..]``, ``p.X``."""
    if isinstance(e, N.Name):
        return e.name
    if isinstance(e, N.Index):
        return lvalue_name(e.base) + "[..]"
    if isinstance(e, N.Field):
        return lvalue_name(e.base) + "." + e.name
    return "?"
