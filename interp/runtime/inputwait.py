"""Whether a robot program's WAIT FOR is one only the cell can release: its condition reads
inputs and constants alone (issue 89, a cell of several robots: interp/robotcell.py).

No KRL task writes an input: assigning ``$IN[...]`` (or a SIGNAL over it) is a compile error
(docs/krl-reference.md §3.9, "Assigning read-only system variables (``$POS_ACT``, ``$IN[...]``,
...) is a compile error [C]"; the table of system variables: ``$IN`` RO). So a submit program
still running beside the robot program cannot end such a wait: only what drives the inputs
can (a cell's rule, a stimulus, a partner robot's wire). A condition that reads an output, a
variable, a timer or calls a function may be changed by the submit program and is not one.
"""

from __future__ import annotations

from krl.ast import nodes as N
from krl.semantics.advance import reads
from krl.semantics.resolve import SYSTEM

from .sysvars import CONSTANT_NAMES

#: the read-only input arrays (reference §3: ``$IN`` digital, ``$ANIN`` analog inputs)
INPUT_ARRAYS = frozenset({"$IN", "$ANIN"})


def _input_or_constant(node) -> bool:
    place = getattr(node.ann, "place", None) if getattr(node, "ann", None) is not None else None
    if place is None:
        return False
    if place.kind == SYSTEM:
        key = place.name.upper()
        return key in INPUT_ARRAYS or key in CONSTANT_NAMES
    sym = place.symbol
    if sym is None or sym.kind != "signal":
        return False
    start = getattr(sym.decl, "start", None)
    return isinstance(sym.decl, N.SignalDecl) and start is not None and start.sysvar.upper() in INPUT_ARRAYS


def reads_inputs_only(expr) -> bool:
    """True when the resolved condition `expr` reads only inputs (``$IN``, ``$ANIN``, a SIGNAL
    over one of them) and constants (literals, the constant system variables): no task of its
    own controller can change its value (module docstring)."""
    return all(mode == "r" and _input_or_constant(node) for mode, node in reads(expr))


def wait_on_inputs(statements) -> bool:
    """True when the WAIT FOR among `statements` (the statements at the robot program's place,
    interp/runtime/spin.py ``SpinWatch.statements``) reads only inputs and constants; False
    when there is none."""
    node = next((n for n in statements or () if isinstance(n, N.WaitFor)), None)
    if node is None:
        return False
    ann = node.annotate()
    got = ann.extra.get("inputs_only")
    if got is None:
        got = ann.extra["inputs_only"] = reads_inputs_only(node.cond)
    return got
