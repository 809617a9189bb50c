"""A function's structure value of its own return type returns as one copy when its components are
already what the assignment stores (interp/runtime/calls.py ``typed_copy``): the same value as the
general conversion (a fresh value of the type and the value assigned into it), to the bit and in the
component order, on drawn structures of the system's types (REAL, INT, BOOL, enum, CHAR array and
nested components, unset ones, and components of another type than their field's)."""

from __future__ import annotations

import random
import struct

from interp.runtime.calls import typed_copy
from interp.runtime.convert import convert_scalar
from interp.runtime.sysvars import sys_type
from interp.runtime.values import UNSET, Arr, Struct, make_value
from krl.semantics import types as T
from krl.semantics.values import EnumValue


def _draw(rng: random.Random, t):
    if rng.random() < 0.15:
        return UNSET
    if isinstance(t, T.Struc):
        return _fill(rng, make_value(t))
    if isinstance(t, T.Array):
        a = make_value(t)
        for i in range(len(a.data)):
            a.data[i] = _draw(rng, t.elem)
        return a
    if isinstance(t, T.Enum):
        return EnumValue(rng.choice(sorted(t.values)), t) if t.values else UNSET
    if t in (T.REAL, T.INT, T.BOOL) and rng.random() < 0.03:     # of another type than its field's
        return rng.choice([2, 2.0, True, 0])
    if t is T.REAL:
        return rng.choice([0.0, -0.0, 1.5, rng.uniform(-1e3, 1e3), float("nan"), float("inf")])
    if t is T.INT:
        return rng.randint(-2**31, 2**31 - 1)
    if t is T.BOOL:
        return rng.random() < 0.5
    if t is T.CHAR:
        return chr(rng.randint(32, 126))
    return UNSET


def _fill(rng: random.Random, s: Struct) -> Struct:
    for k, (_, ft) in s.type.fields.items():
        v = _draw(rng, ft)
        if isinstance(s.f[k], (Struct, Arr)):      # (an aggregate component is never unset itself)
            if v is not UNSET:
                s.f[k] = v
        else:
            s.f[k] = v
    if rng.random() < 0.05:
        s.f.pop(next(iter(s.f)))                   # a component never made
    return s


def _image(v):
    if isinstance(v, Struct):
        return ("S", id(v.type), tuple((k, _image(x)) for k, x in v.f.items()))
    if isinstance(v, Arr):
        return ("A", tuple(_image(x) for x in v.data))
    if isinstance(v, float):
        return ("f", struct.pack("<d", v))
    if isinstance(v, EnumValue):
        return ("e", v.name, id(v.type))
    return (type(v).__name__, v)


def test_a_structure_of_the_return_type_returns_as_the_general_conversion():
    rng = random.Random(59)
    copied = general = 0
    for name in ("FRAME", "E6POS", "E6AXIS", "LDAT", "FDAT", "PDAT", "LOAD"):
        t = sys_type(name)
        for _ in range(60):
            v = _fill(rng, make_value(t))
            try:
                want = _image(convert_scalar(v, t))
            except Exception as exc:  # noqa: BLE001 - a value the conversion refuses: no copy either
                assert typed_copy(v, t) is None, (name, exc)
                continue
            got = typed_copy(v, t)
            if got is None:
                general += 1
                continue
            copied += 1
            assert _image(got) == want, name
            assert got is not v and got.f is not v.f
    assert copied > 100 and general > 50, (copied, general)
