"""Slot-based access and operator entry points for interpreters that resolve names and
operators at compile time (the bytecode VM, interp/vm).

Nothing here has a meaning of its own. Each function is either a rule both interpreters
apply (array index, FOR limits and test, TRIGGER arguments, ANOUT limits: written once,
here), or a *fast path*: it handles the common case of a general runtime function directly
and hands every other case to that function, so the result, and every error message, is
the general function's. tests/vm/test_slots.py checks the fast paths against the general
functions. The VM's loop (interp/vm/vm.py) inlines the common case of some of them and
calls them for every other case.
"""

from __future__ import annotations

from krl.semantics import types as T

from .convert import INT_MAX, INT_MIN, assign_into, binary_op, convert_scalar, num, trunc_int
from .errors import KrlRuntimeError, value_invalid
from .memory import ComputedRef, LiveArray, Slot, field_ref, index_ref
from .values import UNSET, Arr, Struct, copy_value

INT, REAL, BOOL = T.INT, T.REAL, T.BOOL


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


def load(ref):
    """:func:`read_value` (fast path: an INT/REAL/BOOL value in a Slot)."""
    if ref.__class__ is Slot:
        v = ref.c[ref.k]
        c = v.__class__
        if c is int or c is float or c is bool:
            return v
    return read_value(ref)


def _store_fast(c, k, t, v) -> bool:
    """Store scalar ``v`` into ``c[k]`` of type ``t`` when no conversion is involved."""
    vc = v.__class__
    if t is INT:
        if vc is int and INT_MIN <= v <= INT_MAX:
            c[k] = v
            return True
    elif t is REAL:
        if vc is float:
            c[k] = v
            return True
    elif t is BOOL:
        if vc is bool:
            c[k] = v
            return True
    return False


def store(ref, v) -> None:
    """Runtime.assign (``ref.set``), fast path: a writable Slot without write hook, of type
    INT/REAL/BOOL and a value of that very type (INT: in range), or holding a structure (Slot.set's
    ``assign_into``, as a program's ``AX = INVERSE(...)`` into an E6AXIS)."""
    if ref.__class__ is Slot and not ref.readonly and ref.on_write is None:
        t = ref.type
        vc = v.__class__
        if (t is INT and vc is int and INT_MIN <= v <= INT_MAX) or (t is REAL and vc is float) \
                or (t is BOOL and vc is bool):
            ref.c[ref.k] = v
            return
        cur = ref.c[ref.k]
        if cur.__class__ is Struct:
            if cur is not v:
                assign_into(cur, v)
            return
    ref.set(v)


def move(src, dest) -> None:
    """``dest = src`` of two variables: :func:`store` of :func:`read_value` (fast path: a
    structure into a writable Slot without write hook holding a structure of the same type, as
    a program's ``TRY = P`` of two E6POS: Slot.set's ``assign_into`` from the source's value
    itself, without the copy :func:`read_value` makes for the expression; assign_into copies the
    components into the destination's own, and a structure of one type holds none of its own
    type, so neither holds the other; the same structure is left as it is, as Slot.set leaves it)."""
    if src.__class__ is Slot and dest.__class__ is Slot and not dest.readonly and dest.on_write is None:
        v = src.c[src.k]
        cur = dest.c[dest.k]
        if v.__class__ is Struct and cur.__class__ is Struct and v.type is cur.type and v.type is not None:
            if cur is not v:
                assign_into(cur, v)
            return
    store(dest, read_value(src))


def _flat(base, idx):
    """(array, flat position) for a plain Slot without write hook holding an array of scalars
    and INT indices in range, else None."""
    if base.__class__ is not Slot or base.on_write is not None:
        return None
    a = base.c[base.k]
    if a.__class__ is not Arr:
        return None
    dims = a.dims
    if len(idx) != len(dims):
        return None
    pos = 0
    for i, n in zip(idx, dims):
        if i.__class__ is not int or not 1 <= i <= n:
            return None
        pos = pos * n + (i - 1)
    return a, pos


def element(base, idx: list, name: str):
    """Value of ``base[idx]`` (``idx``: the evaluated index values, none omitted)."""
    got = _flat(base, idx)
    if got is not None:
        x = got[0].data[got[1]]
        c = x.__class__
        if c is int or c is float or c is bool:
            return x
    return read_value(index_ref(base, [array_index(i) for i in idx], name))


def element1(base, i, name: str):
    """:func:`element` with one index (no list built on the fast path; an element of a live
    array, ``$IN[i]``, read without its ProxyRef)."""
    if i.__class__ is int:
        if base.__class__ is Slot:
            a = base.c[base.k]
            if a.__class__ is Arr and len(a.dims) == 1 and 1 <= i <= a.dims[0]:
                x = a.data[i - 1]
                c = x.__class__
                if c is int or c is float or c is bool:
                    return x
        elif base.__class__ is ComputedRef:
            a = base.getter()
            if a.__class__ is LiveArray and 1 <= i <= a.size:
                x = a.getter(i)     # (once: a running $TIMER's read is a clock read)
                c = x.__class__
                if c is int or c is float or c is bool:
                    return x
                if x is UNSET:      # (as ProxyRef.get, then read_value)
                    raise value_invalid(f"{name}[{i}]")
                return copy_value(x) if isinstance(x, Struct) or hasattr(x, "dims") else x
    return element(base, [i], name)


def element2(base, i, j, name: str):
    """:func:`element` with two indices."""
    if base.__class__ is Slot and i.__class__ is int and j.__class__ is int:
        a = base.c[base.k]
        if a.__class__ is Arr and len(a.dims) == 2:
            n, m = a.dims
            if 1 <= i <= n and 1 <= j <= m:
                x = a.data[(i - 1) * m + j - 1]
                c = x.__class__
                if c is int or c is float or c is bool:
                    return x
    return element(base, [i, j], name)


def set_element1(base, i, v, name: str) -> None:
    """:func:`set_element` with one index (an element of a live array, ``$OUT[i] = v``, written
    without its ProxyRef)."""
    if i.__class__ is int:
        if base.__class__ is Slot and not base.readonly and base.on_write is None:
            a = base.c[base.k]
            if a.__class__ is Arr and len(a.dims) == 1 and 1 <= i <= a.dims[0] \
                    and _store_fast(a.data, i - 1, a.type.elem, v):
                return
        elif base.__class__ is ComputedRef:
            a = base.getter()
            if a.__class__ is LiveArray and a.setter is not None and 1 <= i <= a.size:
                a.setter(i, convert_scalar(v, a.type))
                return
    set_element(base, [i], v, name)


def set_element(base, idx: list, v, name: str) -> None:
    """``base[idx] = v`` (Runtime.index + Runtime.assign)."""
    got = _flat(base, idx)
    if got is not None and not base.readonly:
        a, pos = got
        if _store_fast(a.data, pos, a.type.elem, v):
            return
    index_ref(base, [array_index(i) for i in idx], name).set(v)


def component(base, comp: str, name: str, key: str):
    """Value of ``base.comp`` (Runtime.field, then read); `key`: the component's key (the
    resolver's Component)."""
    if base.__class__ is Slot:
        s = base.c[base.k]
        if s.__class__ is Struct:
            x = s.f.get(key)
            c = x.__class__
            if c is int or c is float or c is bool:
                return x
    return read_value(field_ref(base, comp, name, key))


def set_component(base, comp: str, v, name: str, key: str) -> None:
    """``base.comp = v`` (Runtime.field + Runtime.assign); `key` as for :func:`component`."""
    if base.__class__ is Slot and not base.readonly and base.on_write is None:
        s = base.c[base.k]
        if s.__class__ is Struct and s.type is not None:
            ft = s.type.fields.get(key)
            if ft is not None and key in s.f and _store_fast(s.f, key, ft[1], v):
                return
    field_ref(base, comp, name, key).set(v)


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


def for_next(ref, end, step, info=None) -> bool:
    """End of a FOR iteration: counter = counter + step (Runtime.assign, binary_op);
    True while the loop goes on. An error of the step (INT overflow past 2^31-1) is placed
    on the FOR statement (``info``: its StmtInfo), not on the body's last line."""
    try:
        store(ref, add(ref.get(), step))
    except KrlRuntimeError as exc:
        if info is not None:
            exc.at(info.file, info.line)
        raise
    return not for_done(ref.get(), end, step)


# ------------------------------------------------------------------ operators (fast paths of convert.binary_op)
# Numbers only (``__class__`` is int or float: BOOL, CHAR, ENUM and UNSET take the general
# path). INT op INT stays INT unless it leaves the 32-bit range; with a REAL operand the
# result is REAL, as in binary_op.
def add(a, b):
    ca = a.__class__
    cb = b.__class__
    if ca is int and cb is int:
        r = a + b
        if INT_MIN <= r <= INT_MAX:
            return r
    elif (ca is float or ca is int) and (cb is float or cb is int):
        return float(a + b)
    return binary_op("+", a, b)


def sub(a, b):
    ca = a.__class__
    cb = b.__class__
    if ca is int and cb is int:
        r = a - b
        if INT_MIN <= r <= INT_MAX:
            return r
    elif (ca is float or ca is int) and (cb is float or cb is int):
        return float(a - b)
    return binary_op("-", a, b)


def mul(a, b):
    ca = a.__class__
    cb = b.__class__
    if ca is int and cb is int:
        r = a * b
        if INT_MIN <= r <= INT_MAX:
            return r
    elif (ca is float or ca is int) and (cb is float or cb is int):
        return float(a * b)
    return binary_op("*", a, b)


def _numbers(a, b) -> bool:
    ca = a.__class__
    cb = b.__class__
    return (ca is int or ca is float) and (cb is int or cb is float)


def lt(a, b):
    return a < b if _numbers(a, b) else binary_op("<", a, b)


def le(a, b):
    return a <= b if _numbers(a, b) else binary_op("<=", a, b)


def gt(a, b):
    return a > b if _numbers(a, b) else binary_op(">", a, b)


def ge(a, b):
    return a >= b if _numbers(a, b) else binary_op(">=", a, b)


def eq(a, b):
    return a == b if _numbers(a, b) else binary_op("==", a, b)


def ne(a, b):
    return a != b if _numbers(a, b) else binary_op("<>", a, b)


# ------------------------------------------------------------------ TRIGGER arguments
def trigger_args(kind: str, at, delay, prio, onstart: bool = False) -> dict:
    """Keyword arguments of MotionStatements.trigger from the evaluated TRIGGER operands."""
    at = num(at)
    delay = num(delay)
    p = trunc_int(prio, "TRIGGER PRIO") if prio is not None else None
    if kind == "PATH":
        return {"path": float(at), "onstart": onstart, "delay_ms": delay, "prio": p}
    return {"distance": trunc_int(at, "TRIGGER DISTANCE"), "delay_ms": delay, "prio": p}


# ------------------------------------------------------------------ ANOUT ON (reference §5.14)
def anout_limits(lo, hi) -> tuple:
    """(minimum, maximum) of ANOUT ON: the given values as REAL, default -1.0 and 1.0."""
    return (float(num(lo)) if lo is not None else -1.0, float(num(hi)) if hi is not None else 1.0)


def anout_value(v, lo: float, hi: float) -> float:
    """The analog output value: REAL, clamped to [minimum, maximum]."""
    return min(hi, max(lo, float(num(v))))


# ------------------------------------------------------------------ calls and jumps (the tree interpreter's messages)
def function_result(name: str, v):
    """The value of a function call in an expression; a procedure has none."""
    if v is None:
        raise KrlRuntimeError(f"{name} does not return a value")
    return v


def ended_without_return(routine, line) -> KrlRuntimeError:
    """Reaching ENDFCT without RETURN is a run-time error at ENDFCT (reference 2.3, table 8)."""
    return KrlRuntimeError(f"function {routine.name} ended without RETURN", None, routine.span.file,
                           routine.end_line or line or routine.span.line)


def return_without_value(routine, line) -> KrlRuntimeError:
    return KrlRuntimeError(f"RETURN without a value in function {routine.name}", None, routine.span.file, line)


def label_not_found(label: str, routine, line) -> KrlRuntimeError:
    return KrlRuntimeError(f"GOTO {label}: label not found", None, routine.span.file, line)
