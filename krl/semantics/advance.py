"""The advance-run rules (reference §5.8-§5.13, §6.10): which statements stop the advance run.

A statement *stops the advance run* (the interpreter waits until the main run has executed
every planned motion and the robot stands still, then executes it) when it is
one of a kind whose facts in the statement table (krl/semantics/statements.py ``KINDS``) say it
``stops``, calls one of :data:`STOP_ROUTINES`, or reads/writes a variable
whose symbol says so (``Symbol.stop_read`` / ``stop_write``: a system variable whose
data-table entry, krl/semantics/data/sysvars.yaml ``stop: [read, write]``, says so, or a
SIGNAL on ``$IN``/``$OUT``/``$ANIN``/``$ANOUT``). Only the statement's own expressions count
(an IF's condition, not its branches; a FOR's start, end and STEP; a motion's target,
auxiliary point, CA and WITH values); a WHILE/REPEAT condition stops on each evaluation
(``cond_stops``). ``CONTINUE`` on the line just before suppresses the stop for that one
line. The stop applies in the robot interpreter's main and interrupt contexts; a TRIGGER
action and the submit interpreter never wait for it.

:func:`analyse` runs once per statement, in the front end (the resolver,
krl/semantics/resolve.py, after the checker), and the result is stored on the AST
(``stmt.ann.info``, a :class:`StmtInfo`; ``stmt.ann.extra["advance_stop"]`` says why, and
``extra["continued"]`` marks a statement right after CONTINUE). Both interpreters read it.
"""

from __future__ import annotations

from dataclasses import dataclass

from krl.ast import nodes as N
from krl.semantics.builtins import load_builtins
from krl.semantics.statements import KINDS
#: the routines whose call stops the advance run: declared so in the natives registry
#: (``stops``, interp/runtime/natives/registry.py), read from the table generated from it
STOP_ROUTINES = load_builtins().advance_stop


@dataclass(slots=True)
class StmtInfo:
    """Static facts of one statement: place (file, 1-based line), whether it stops the
    advance run before it executes (``stops``), whether its loop condition stops on each
    evaluation (``cond_stops``), and why (``reason``, e.g. "reads $IN"; None when neither)."""
    file: str
    line: int
    stops: bool = False
    cond_stops: bool = False
    reason: str | None = None


def _reads(expr, acc: list) -> None:
    if expr is None:
        return
    if isinstance(expr, N.Name):
        acc.append(("r", expr))
    elif isinstance(expr, N.Call):
        acc.append(("call", expr))
        for a in expr.args:
            _reads(a, acc)
    else:
        for c in expr.children():
            _reads(c, acc)


def reads(expr) -> list:
    """The accesses of expression `expr` (None: none), in source order: ``("r", Name)`` for
    each name it reads (index expressions included) and ``("call", Call)`` for each call
    (whose arguments' reads follow). What a name denotes is its ``ann.place`` (a Storage:
    krl/semantics/resolve.py) once the resolver has run. The runtime decides from it when an
    interrupt condition must be evaluated again (interp/runtime/watch.py)."""
    acc: list = []
    _reads(expr, acc)
    return acc


def _target(expr, acc: list) -> None:
    """An assignment target: its root is written, index expressions are read."""
    if isinstance(expr, N.Name):
        acc.append(("w", expr))
    elif isinstance(expr, N.Index):
        _target(expr.base, acc)
        for i in expr.indices:
            _reads(i, acc)
    elif isinstance(expr, N.Field):
        _target(expr.base, acc)


def accesses(stmt) -> tuple[list, list]:
    """(accesses of the statement itself, accesses of its loop condition): ``(mode, node)``
    with mode 'r' (a Name read), 'w' (a Name written) or 'call' (a Call)."""
    acc: list = []
    cond: list = []
    if isinstance(stmt, N.Assign):
        _target(stmt.target, acc)
        _reads(stmt.value, acc)
    elif isinstance(stmt, N.CallStmt):
        acc.append(("call", stmt.call))
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


def _why(items, symbol_of) -> str | None:
    for mode, node in items:
        if mode == "call":
            if node.name.upper() in STOP_ROUTINES:
                return node.name.upper()
            continue
        sym = symbol_of(node)
        if sym is None:
            continue
        if mode == "r" and sym.stop_read:
            return f"reads {sym.name}"
        if mode == "w" and sym.stop_write:
            return f"writes {sym.name}"
    return None


def analyse(stmt, symbol_of) -> StmtInfo:
    """The StmtInfo of ``stmt``; ``symbol_of(name_node)`` is the Symbol a Name resolved to
    (None when nothing declares it: it stops nothing)."""
    sp = stmt.span
    info = StmtInfo(sp.file, sp.line)
    acc, cond = accesses(stmt)
    why = KINDS[stmt.__class__].facts.stops or _why(acc, symbol_of)
    cond_why = _why(cond, symbol_of)
    info.stops = why is not None
    info.cond_stops = cond_why is not None
    info.reason = why or cond_why
    return info
