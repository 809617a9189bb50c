"""The runtime's fast paths (interp/runtime/slots.py) agree with the general functions."""

from __future__ import annotations

import itertools

import pytest

from interp.runtime.convert import binary_op
from interp.runtime.errors import KrlRuntimeError
from interp.runtime.memory import ComputedRef, LiveArray, Slot, field_ref, index_ref
from interp.runtime.slots import (add, array_index, component, element, element1, element2, eq, ge, gt, le, load, lt,
                                  move, mul, ne, read_value, set_component, set_element, set_element1, store, sub)
from interp.runtime.values import UNSET, EnumValue, copy_value, make_value
from krl.semantics import types as T

VALUES = [0, 1, -7, 2147483647, -2147483648, 2.5, -0.0, 1e300, True, False, "A", EnumValue("X"), UNSET]
FAST = {"+": add, "-": sub, "*": mul, "<": lt, "<=": le, ">": gt, ">=": ge, "==": eq, "<>": ne}


def outcome(fn, *args):
    try:
        v = fn(*args)
        return ("ok", type(v), v)
    except KrlRuntimeError as e:
        return ("error", e.message, e.number)


@pytest.mark.parametrize("op", list(FAST))
def test_operators(op):
    for a, b in itertools.product(VALUES, VALUES):
        assert outcome(FAST[op], a, b) == outcome(binary_op, op, a, b), (op, a, b)


def _array(t, dims, values):
    a = make_value(T.Array(t, dims))
    for i, v in enumerate(values):
        a.data[i] = v
    return Slot({"A": a}, "A", a.type, "A")


def test_elements_and_stores():
    for t, vals, new in ((T.INT, [1, UNSET, 3, 4], [5, 2.6, True, 2 ** 40]),
                         (T.REAL, [1.0, UNSET, 3.0, 4.0], [5, 2.6, True]),
                         (T.BOOL, [True, UNSET, False, True], [False, 1])):
        for idx in ([1], [2], [4], [5], [0], [1.5], [True]):
            fast = _array(t, (4,), vals)
            slow = _array(t, (4,), vals)
            assert outcome(element, fast, idx, "A") == \
                outcome(lambda: read_value(index_ref(slow, [array_index(i) for i in idx], "A")))
            if len(idx) == 1:
                assert outcome(element1, fast, idx[0], "A") == outcome(element, slow, idx, "A")
                f1 = _array(t, (4,), vals)
                for v in new:
                    assert outcome(set_element1, f1, idx[0], v, "A") == outcome(set_element, fast, idx, v, "A")
                    assert f1.c["A"].data == fast.c["A"].data
            for v in new:
                r1 = outcome(set_element, fast, idx, v, "A")
                r2 = outcome(lambda: index_ref(slow, [array_index(i) for i in idx], "A").set(v))
                assert r1 == r2
                assert fast.c["A"].data == slow.c["A"].data
        m1 = _array(t, (2, 2), vals)
        for i, j in itertools.product([0, 1, 2, 3], repeat=2):
            assert outcome(element2, m1, i, j, "M") == outcome(lambda: read_value(index_ref(m1, [i, j], "M")))


def test_load_store_components():
    st = T.Struc("PAIR")
    st.fields["A"] = ("A", T.INT)
    st.fields["B"] = ("B", T.REAL)
    for v in (1, 2.5, True, 2 ** 40, "x"):
        for comp in ("A", "b", "C"):
            s1 = Slot({"P": make_value(st)}, "P", st, "P")
            s2 = Slot({"P": make_value(st)}, "P", st, "P")
            key = comp.upper()      # the resolver's key of the component (resolve.py Component)
            assert outcome(set_component, s1, comp, v, "P", key) == \
                outcome(lambda: field_ref(s2, comp, "P", key).set(v))
            assert s1.c["P"].f == s2.c["P"].f
            assert outcome(component, s1, comp, "P", key) == \
                outcome(lambda: read_value(field_ref(s2, comp, "P", key)))
    for t, v in ((T.INT, 3), (T.INT, 3.7), (T.REAL, 2), (T.BOOL, 1), (T.INT, 2 ** 33)):
        a = Slot({"X": UNSET}, "X", t, "X")
        b = Slot({"X": UNSET}, "X", t, "X")
        assert outcome(load, a) == outcome(read_value, b)
        assert outcome(store, a, v) == outcome(b.set, v)
        assert a.c == b.c
        assert outcome(load, a) == outcome(read_value, b)
    ro = Slot({"X": 1}, "X", T.INT, "X", readonly=True)
    assert outcome(store, ro, 2)[0] == "error"


def _pose_type():
    """A structure type of REAL, INT and nested structure components (an E6POS with a FRAME)."""
    inner = T.Struc("INNER")
    inner.fields["X"] = ("X", T.REAL)
    inner.fields["N"] = ("N", T.INT)
    st = T.Struc("POSE")
    st.fields["X"] = ("X", T.REAL)
    st.fields["S"] = ("S", T.INT)
    st.fields["IN"] = ("IN", inner)
    return st, inner


def _filled(st, x, s, ix):
    v = make_value(st)
    v.f["X"], v.f["S"] = x, s
    v.f["IN"].f["X"], v.f["IN"].f["N"] = ix, s + 1
    return v


def test_move_is_store_of_read_value():
    """``dest = src`` of two variables (the VM's MOVE_LOCAL): move gives the general path's
    values, errors and structures (``store(dest, read_value(src))``), the destination's own
    structure written in place and sharing nothing with the source; a structure into itself,
    other types, scalars, a read-only destination and an unset source as the general path."""
    st, inner = _pose_type()
    other = T.Struc("OTHER")
    other.fields["X"] = ("X", T.REAL)
    cases = [(_filled(st, 1.5, 3, -2.0), _filled(st, 0.0, 0, 0.0), st),
             (_filled(st, UNSET, 2, 7.0), make_value(st), st),       # an unset component
             (_filled(st, 4.0, 5, 1.0), make_value(other), other),   # another type: components by name
             (2.5, 1.0, T.REAL), (7, 1.0, T.REAL), (UNSET, 1, T.INT)]
    for src_v, dst_v, dt in cases:
        results = []
        for fn in (move, lambda a, b: store(b, read_value(a))):
            src = Slot({"S": make_copy(src_v)}, "S", None, "S")
            dst = Slot({"D": make_copy(dst_v)}, "D", dt, "D")
            before = dst.c["D"]
            got = outcome(fn, src, dst)
            d = dst.c["D"]
            results.append((got, repr(getattr(d, "f", d)), d is before))
            if hasattr(d, "f") and hasattr(src.c["S"], "f"):
                src.c["S"].f["X"] = 99.0
                src.c["S"].f.get("IN") and src.c["S"].f["IN"].f.update(X=99.0)
                assert d.f.get("X") != 99.0 and (d.f.get("IN") is None or d.f["IN"].f["X"] != 99.0)
        assert results[0] == results[1], (src_v, dst_v)
    same = Slot({"P": _filled(st, 1.5, 3, -2.0)}, "P", st, "P")
    kept = same.c["P"]
    move(same, same)
    assert same.c["P"] is kept and kept.f["X"] == 1.5 and kept.f["IN"].f["N"] == 4
    ro = Slot({"D": make_value(st)}, "D", st, "D", readonly=True)
    assert outcome(move, Slot({"S": _filled(st, 1.0, 1, 1.0)}, "S", st, "S"), ro) == \
        outcome(lambda: store(ro, read_value(Slot({"S": _filled(st, 1.0, 1, 1.0)}, "S", st, "S"))))
    assert outcome(move, Slot({"S": _filled(st, 1.0, 1, 1.0)}, "S", st, "S"), ro)[0] == "error"


def make_copy(v):
    return copy_value(v) if hasattr(v, "f") else v


def _live(t, values, writable: bool):
    """A live system array (``$IN``/``$OUT``-like: memory.py LiveArray) over a list of 4 values,
    the base a compiled ``$OUT[i]`` gets (a ComputedRef giving it), and the list."""
    store_ = list(values)

    def put(i, v):
        store_[i - 1] = v
    arr = LiveArray("$L", 4, t, lambda i: store_[i - 1], put if writable else None)
    return ComputedRef(lambda: arr, T.Array(t, (4,)), "$L"), store_


def test_live_array_elements_and_stores():
    """element1/set_element1 on a live array (``$IN[i]``, ``$OUT[i] = v``) give the value, the
    write and the error of the general path (index_ref's ProxyRef), reads counted once each."""
    for t, vals, new in ((T.BOOL, [True, UNSET, False, True], [False, 1, UNSET]),
                         (T.INT, [1, UNSET, 3, 4], [5, 2.6, True, 2 ** 40]),
                         (T.REAL, [1.0, UNSET, 3.0, 4.0], [5, 2.6, True])):
        for i in (1, 2, 4, 5, 0, 1.5, True):
            for writable in (True, False):
                fast, fs = _live(t, vals, writable)
                slow, ss = _live(t, vals, writable)
                assert outcome(element1, fast, i, "$L") == outcome(element, slow, [i], "$L")
                for v in new:
                    assert outcome(set_element1, fast, i, v, "$L") == \
                        outcome(lambda: index_ref(slow, [array_index(i)], "$L").set(v))
                    assert fs == ss
    reads = []
    arr = LiveArray("$T", 4, T.INT, lambda i: reads.append(i) or 7)
    assert element1(ComputedRef(lambda: arr, T.Array(T.INT, (4,)), "$T"), 3, "$T") == 7 and reads == [3]
