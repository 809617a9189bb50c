"""Slot-based access and operator entry points for interpreters that resolve names and
operators at compile time (the bytecode VM, interp/vm).

Nothing here has a meaning of its own. Each function is either a statement of a rule the
tree interpreter applies inline (so that both interpreters can share it), or a *fast
path*: it handles the common case of a general runtime function directly and hands every
other case to that function, so the result, and every error message, is the general
function's. tests/vm/test_slots.py checks the fast paths against the general functions.
"""

from __future__ import annotations

from .convert import INT_MAX, INT_MIN, binary_op, num
from .errors import KrlRuntimeError
from .memory import Slot, index_ref
from .values import Arr, Struct, copy_value


# ------------------------------------------------------------------ reading
def read_value(ref):
    """The value of a variable used in an expression: aggregates are copied (the tree
    interpreter's ``e_var``)."""
    v = ref.get()
    if isinstance(v, Struct) or hasattr(v, "dims"):
        return copy_value(v)
    return v


def array_index(v) -> int:
    """An index expression's value as an array index."""
    v = num(v, "array index")
    if v.__class__ is not int:
        raise KrlRuntimeError("array index is not an INT")
    return v


def element(base, i, name: str):
    """Value of ``base[i]`` (one index). Fast path: a Slot holding a 1-D array of scalars
    and an index in range; everything else through memory.index_ref."""
    if base.__class__ is Slot and i.__class__ is int:
        v = base.c[base.k]
        if v.__class__ is Arr and len(v.dims) == 1 and 1 <= i <= v.dims[0]:
            x = v.data[i - 1]
            if x.__class__ is int or x.__class__ is float:
                return x
    return read_value(index_ref(base, [array_index(i)], name))


# ------------------------------------------------------------------ FOR (reference §5.4)
def for_limits(end, step):
    """(end, step) of a FOR statement as numbers; STEP 0 is an error."""
    end = num(end)
    step = num(step)
    if step == 0:
        raise KrlRuntimeError("FOR with STEP 0")
    return end, step


def for_done(c, end, step) -> bool:
    """The counter ``c`` is past ``end``: the loop ends."""
    return (step > 0 and c > end) or (step < 0 and c < end)


# ------------------------------------------------------------------ operators (fast paths of convert.binary_op)
def add(a, b):
    if a.__class__ is int and b.__class__ is int:
        r = a + b
        if INT_MIN <= r <= INT_MAX:
            return r
    elif a.__class__ is float and b.__class__ is float:
        return a + b
    return binary_op("+", a, b)


def sub(a, b):
    if a.__class__ is int and b.__class__ is int:
        r = a - b
        if INT_MIN <= r <= INT_MAX:
            return r
    elif a.__class__ is float and b.__class__ is float:
        return a - b
    return binary_op("-", a, b)


def mul(a, b):
    if a.__class__ is int and b.__class__ is int:
        r = a * b
        if INT_MIN <= r <= INT_MAX:
            return r
    elif a.__class__ is float and b.__class__ is float:
        return a * b
    return binary_op("*", a, b)


def lt(a, b):
    ca = a.__class__
    if (ca is int or ca is float) and (b.__class__ is int or b.__class__ is float):
        return a < b
    return binary_op("<", a, b)


def eq(a, b):
    ca = a.__class__
    if (ca is int or ca is float) and (b.__class__ is int or b.__class__ is float):
        return a == b
    return binary_op("==", a, b)


# ------------------------------------------------------------------ TRIGGER arguments
def trigger_args(kind: str, at, delay, prio, onstart: bool = False) -> dict:
    """Keyword arguments of Runtime.trigger from the evaluated TRIGGER operands."""
    at = num(at)
    delay = num(delay)
    p = int(num(prio)) if prio is not None else None
    if kind == "PATH":
        return {"path": float(at), "onstart": onstart, "delay_ms": delay, "prio": p}
    return {"distance": int(at), "delay_ms": delay, "prio": p}
