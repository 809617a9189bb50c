"""The geometric operator's fast paths (interp/runtime/convert.py ``geo_compose``: the left
operand's matrix kept while its six values are the very same floats; ``frame_tuple`` of six floats
without conversions) give the bytes of the general computation (``frame_values``: each operand's
components through ``num`` and ``float``; both matrices made afresh), on drawn sequences of operands: a pool of left
operands that repeat (equal values as other objects, -0.0 for 0.0, INT components, NaN, a missing
or unset component) and right ones drawn each time."""

from __future__ import annotations

import random
import struct

import pytest

from interp.runtime import convert
from interp.runtime.convert import FRAME_KEYS, frame_values, geo_compose, struct_from_frame
from interp.runtime.errors import KrlRuntimeError
from interp.runtime.sysvars import struct_of
from interp.runtime.values import UNSET
from robot.frames import frame_to_matrix, matrix_to_frame


def _general(a, b):
    Ta = frame_to_matrix(*frame_values(a, "left operand of ':'"))
    Tb = frame_to_matrix(*frame_values(b, "right operand of ':'"))
    return struct_from_frame(matrix_to_frame(Ta @ Tb), b)


def _image(s):
    return tuple((k, struct.pack("<d", x) if isinstance(x, float) else (type(x).__name__, x)) for k, x in s.f.items())


def _value(rng):
    return rng.choice([0.0, -0.0, 1.5, 90.0, -180.0, rng.uniform(-500, 500), rng.uniform(-180, 180), 7, 0,
                       float("nan")])


def _frame(rng, kind="FRAME"):
    vals = {k: _value(rng) for k in FRAME_KEYS}
    if kind != "FRAME":
        vals.update(S=rng.choice([2, 6]), T=rng.choice([0, 35]))
    s = struct_of(kind, vals)
    if rng.random() < 0.05:
        s.f[rng.choice(FRAME_KEYS)] = UNSET
    if rng.random() < 0.05:
        s.f.pop(rng.choice(FRAME_KEYS))
    return s


def test_the_composition_fast_paths_are_the_general_computation_bit_for_bit():
    rng = random.Random(62)
    pool = [_frame(rng, rng.choice(["FRAME", "POS", "E6POS"])) for _ in range(6)]
    for a in list(pool):                    # the same values as other objects, 0.0 as -0.0
        twin = struct_of(a.type.name, {k: (float(repr(x)) if isinstance(x, float) else x) for k, x in a.f.items()})
        pool.append(twin)
        pool.append(struct_of(a.type.name, {k: (-x if x == 0.0 and isinstance(x, float) else x)
                                            for k, x in a.f.items()}))
    hits = 0
    a = pool[0]
    for _ in range(1500):
        if rng.random() < 0.15:             # a run of points composed with one base, then another
            a = rng.choice(pool) if rng.random() < 0.9 else _frame(rng)
        b = _frame(rng, rng.choice(["FRAME", "E6POS"]))
        before = convert._last_left[1]
        try:
            want = _image(_general(a, b))
        except KrlRuntimeError as exc:
            with pytest.raises(KrlRuntimeError) as got:
                geo_compose(a, b)
            assert str(got.value) == str(exc)
            continue
        assert _image(geo_compose(a, b)) == want
        hits += convert._last_left[1] is before
    assert hits > 300, hits
