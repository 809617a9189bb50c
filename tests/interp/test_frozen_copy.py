"""A model's frozen values and the copies a run takes of them (interp/runtime/frozen.py): each
copier makes what values.copy_value makes of the value (the same classes, types, components in
order and elements), a value of its own at every level, and the frozen value refuses a write."""

from __future__ import annotations

import pytest

from interp.runtime.frozen import StoreImage, freeze
from interp.runtime.values import UNSET, Arr, Channel, EnumValue, Struct, copy_value, make_value
from krl.semantics import types as T

POINT = T.Struc("POINT", {"X": (0, T.REAL), "Y": (1, T.REAL), "ON": (2, T.BOOL)})
PAIR = T.Struc("PAIR", {"P": (0, POINT), "N": (1, T.INT), "V": (2, T.Array(T.INT, (2,)))})


def _values() -> list:
    """Values of every shape a data list or the system variables hold (built fresh each time)."""
    flat = Struct(POINT, {"X": 1.5, "Y": UNSET, "ON": True})
    nested = Struct(PAIR, {"P": Struct(POINT, {"X": 2.0, "Y": 3.0, "ON": False}), "N": 4,
                           "V": Arr(T.Array(T.INT, (2,)), (2,), [5, UNSET])})
    points = Arr(T.Array(POINT, (2,)), (2,), [Struct(POINT, {"X": float(i), "Y": 0.0, "ON": UNSET}) for i in (1, 2)])
    pairs = make_value(T.Array(PAIR, (2,)))
    mixed = Arr(T.Array(T.UNKNOWN, (3,)), (3,), [Struct(POINT, {"X": 1.0}), 7, Channel("SER_3")])
    first_scalar = Arr(T.Array(T.UNKNOWN, (2,)), (2,), [1, Struct(POINT, {"X": 1.0})])
    return [3, 2.5, True, "A", UNSET, EnumValue("GO"), flat, nested, points, pairs, mixed, first_scalar,
            Struct(None, {}), Arr(T.Array(T.INT, (0,)), (0,), [])]


def _shape(v):
    """The whole of a value, class and type at every level, to compare two values by."""
    if isinstance(v, Struct):
        return ("S", type(v.f) is dict, v.type, [(k, _shape(x)) for k, x in v.f.items()])
    if isinstance(v, Arr):
        return ("A", type(v.data) is list, v.type, v.dims, [_shape(x) for x in v.data])
    return (type(v), v)


def _compounds(v) -> list:
    """Every structure and array in `v`, itself included."""
    if isinstance(v, Struct):
        return [v] + [c for x in v.f.values() for c in _compounds(x)]
    if isinstance(v, Arr):
        return [v] + [c for x in v.data for c in _compounds(x)]
    return []


@pytest.mark.parametrize("k", range(len(_values())))
def test_a_copier_makes_what_copy_value_makes(k):
    """What a run's copy was before the copiers: copy_value of the frozen value (which shares
    what copy_value shares: the later elements of an array whose first is a scalar)."""
    v = _values()[k]
    make = freeze(v)
    expected = copy_value(v)
    if not isinstance(v, (Struct, Arr)):
        assert make is None
        return
    a, b = make(), make()
    assert _shape(a) == _shape(b) == _shape(expected)
    frozen = {id(c) for c in _compounds(v)}
    own = [c for c in _compounds(a) if id(c) not in frozen]
    assert len(own) == len([c for c in _compounds(expected) if id(c) not in frozen]) > 0
    assert not {id(c) for c in own} & {id(c) for c in _compounds(b)}


def test_a_frozen_value_refuses_a_write_and_its_copies_do_not_reach_it():
    v = _values()[7]
    make = freeze(v)
    with pytest.raises(TypeError):
        v.f["N"] = 1
    with pytest.raises(TypeError):
        v.f["V"].data[0] = 1
    with pytest.raises(TypeError):
        v.f["P"].f["X"] = 1.0
    c = make()
    c.f["N"], c.f["V"].data[0], c.f["P"].f["X"] = 9, 9, 9.0
    assert (v.f["N"], v.f["V"].data[0], v.f["P"].f["X"]) == (4, 5, 2.0)
    assert _shape(make()) == _shape(copy_value(_values()[7]))


@pytest.mark.parametrize("as_dict", [False, True])
def test_a_store_image_copies_the_store_in_one_step(as_dict):
    values = _values()
    store = {f"$V{i}": v for i, v in enumerate(values)} if as_dict else list(values)
    image = StoreImage(store)
    expected = {k: copy_value(v) for k, v in store.items()} if as_dict else [copy_value(v) for v in store]
    assert isinstance(image.values, tuple) != as_dict
    with pytest.raises(TypeError):
        image.values[next(iter(image.values)) if as_dict else 0] = 1
    got = image.copy()
    assert type(got) is (dict if as_dict else list)
    pairs = list(zip(got.values(), expected.values())) if as_dict else list(zip(got, expected))
    assert (list(got) == list(expected) if as_dict else len(got) == len(expected)) and all(_shape(a) == _shape(b) for a, b in pairs)
    assert got is not image.copy()
    got[next(iter(got)) if as_dict else 0] = "written"
    assert image.copy() != got and (image.values["$V0"] if as_dict else image.values[0]) == 3
