"""The advance-run rules (reference §5.8-§5.13, §6.10).

A statement *stops the advance run* (the interpreter waits until the main run has executed
every planned motion and the robot stands still, then executes it) when it is one of
:data:`STOP_STATEMENTS`, calls one of :data:`STOP_ROUTINES`, or reads/writes a system
variable whose data-table entry (krl/semantics/data/sysvars.yaml: ``stop: [read, write]``)
says so — directly or through a SIGNAL on ``$IN``/``$OUT``/``$ANIN``/``$ANOUT``. Only the
statement's own expressions count (an IF's condition, not its branches; a loop's
condition, checked again on every evaluation). ``CONTINUE`` on the line just before
suppresses the stop for that one line. The stop applies in the robot interpreter's main
and interrupt contexts; a TRIGGER action and the submit interpreter never wait for it.

:func:`analyse` computes a :class:`StmtInfo` per statement once (the VM compiler calls
the same function and stores the flags in its code).
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.ast import nodes as N

# INTERRUPT ON/OFF/ENABLE/DISABLE stop it too (reference §6.10 [U]): otherwise the
# `INTERRUPT OFF` after the interruptible motion of §5.17 would run before the motion.
STOP_STATEMENTS = (N.WaitFor, N.WaitSec, N.Halt, N.AninOn, N.AninOff, N.AnoutOn, N.AnoutOff,
                   N.InterruptCtl)
STOP_ROUTINES = frozenset({"PULSE"})


@dataclass(slots=True)
class StmtInfo:
    """Static facts of one statement: place, advance-run stop, loop-condition stop."""
    file: str
    line: int
    stops: bool = False           # stops the advance run before it executes
    cond_stops: bool = False      # a loop condition that stops on each evaluation


def _reads(expr, acc: list) -> None:
    if expr is None:
        return
    if isinstance(expr, N.Name):
        acc.append(("r", expr.name))
    elif isinstance(expr, N.Call):
        acc.append(("call", expr.name))
        for a in expr.args:
            _reads(a, acc)
    else:
        for c in expr.children():
            _reads(c, acc)


def _target(expr, acc: list) -> None:
    """An assignment target: its root is written, index expressions are read."""
    if isinstance(expr, N.Name):
        acc.append(("w", expr.name))
    elif isinstance(expr, N.Index):
        _target(expr.base, acc)
        for i in expr.indices:
            _reads(i, acc)
    elif isinstance(expr, N.Field):
        _target(expr.base, acc)


def accesses(stmt) -> tuple[list, list]:
    """(accesses of the statement itself, accesses of its loop condition)."""
    acc: list = []
    cond: list = []
    if isinstance(stmt, N.Assign):
        _target(stmt.target, acc)
        _reads(stmt.value, acc)
    elif isinstance(stmt, N.CallStmt):
        acc.append(("call", stmt.call.name))
        for a in stmt.call.args:
            if isinstance(a, (N.Name, N.Index, N.Field)) and stmt.call.name.upper() in STOP_ROUTINES:
                _target(a, acc)
            else:
                _reads(a, acc)
    elif isinstance(stmt, N.If):
        _reads(stmt.cond, acc)
    elif isinstance(stmt, N.Switch):
        _reads(stmt.selector, acc)
    elif isinstance(stmt, N.For):
        for e in (stmt.start, stmt.end, stmt.step):
            _reads(e, acc)
    elif isinstance(stmt, (N.While, N.Repeat)):
        _reads(stmt.cond, cond)
    elif isinstance(stmt, N.Motion):
        for e in (stmt.target, stmt.aux, stmt.ca):
            _reads(e, acc)
        for w in stmt.with_:
            _reads(w.value, acc)
    elif isinstance(stmt, N.Return):
        _reads(stmt.value, acc)
    elif isinstance(stmt, N.WaitFor):
        _reads(stmt.cond, acc)
    elif isinstance(stmt, N.InterruptCtl):
        _reads(stmt.prio, acc)
    return acc, cond


def analyse(stmt, stop_of) -> StmtInfo:
    """StmtInfo of ``stmt``. ``stop_of(name, mode)`` answers whether reading (mode 'r') or
    writing ('w') the variable ``name`` stops the advance run (a resolver decision: it
    knows SIGNAL names and system variables)."""
    sp = stmt.span
    info = StmtInfo(sp.file, sp.line)
    if isinstance(stmt, STOP_STATEMENTS):
        info.stops = True
    acc, cond = accesses(stmt)

    def any_stop(items) -> bool:
        for mode, name in items:
            if mode == "call":
                if name.upper() in STOP_ROUTINES:
                    return True
            elif stop_of(name, mode):
                return True
        return False

    info.stops = info.stops or any_stop(acc)
    info.cond_stops = any_stop(cond)
    return info
