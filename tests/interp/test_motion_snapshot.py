"""The motion parameter snapshot's memo (interp/runtime/motion.py ``params_from`` with a
``ParamsMemo``) answers what the snapshot made afresh answers, to the bit, on drawn stores: the
motion system variables written between motions as a program writes them (a new value object each
time: the same number, -0.0 for 0.0, an INT for a REAL, an unset value, another enum value),
sometimes none of them."""

from __future__ import annotations

import dataclasses
import random
import struct
from types import SimpleNamespace

from interp.runtime.motion import ParamsMemo, params_from
from interp.runtime.values import UNSET, Struct
from krl.semantics.values import EnumValue

FIELDS = {"$VEL": ("CP", "ORI1", "ORI2"), "$ACC": ("CP", "ORI1", "ORI2"),
          "$APO": ("CPTP", "CDIS", "CVEL", "CORI"), "$TOOL": tuple("XYZABC"), "$BASE": tuple("XYZABC")}
ENUMS = {"$ORI_TYPE": ("VAR", "CONSTANT", "JOINT"), "$CIRC_TYPE": ("BASE", "PATH"), "$IPO_MODE": ("BASE", "TCP")}


def _bits(v):
    """`v` with every float as its bytes (-0.0 and 0.0 differ; a NaN equals itself)."""
    if isinstance(v, float):
        return ("f", struct.pack("<d", v))
    if isinstance(v, tuple):
        return tuple(_bits(x) for x in v)
    return (type(v).__name__, v)


def _number(rng: random.Random):
    return rng.choice([0.0, -0.0, 1.5, -1.5, 100.0, 0.3, 2, 0, 7, float(rng.randint(-999, 999)) / 8,
                       rng.uniform(-500, 500), float("nan")])


def _store(rng: random.Random) -> dict:
    store = {k: Struct(None, {c: _number(rng) for c in comps}) for k, comps in FIELDS.items()}
    store["$VEL_AXIS"] = SimpleNamespace(data=[_number(rng) for _ in range(6)])
    store["$ACC_AXIS"] = SimpleNamespace(data=[_number(rng) for _ in range(6)])
    for k, names in ENUMS.items():
        store[k] = EnumValue(rng.choice(names))
    store["$OV_PRO"] = _number(rng)
    return store


def _write(rng: random.Random, store: dict) -> None:
    """One write a program may make between two motions."""
    what = rng.randrange(6)
    if what == 0:
        key = rng.choice(list(FIELDS))
        comp = rng.choice(FIELDS[key])
        cur = store[key].f.get(comp, 0.0)
        store[key].f[comp] = rng.choice([_number(rng), UNSET, float(cur) if cur is not UNSET else 0.0,
                                         -cur if isinstance(cur, (int, float)) else 1.0])
    elif what == 1:
        data = store[rng.choice(["$VEL_AXIS", "$ACC_AXIS"])].data
        data[rng.randrange(6)] = rng.choice([_number(rng), UNSET])
    elif what == 2:
        key = rng.choice(list(ENUMS))
        store[key] = rng.choice([EnumValue(rng.choice(ENUMS[key])), UNSET])
    elif what == 3:
        store["$OV_PRO"] = rng.choice([_number(rng), UNSET])
    elif what == 4:
        key = rng.choice(["$TOOL", "$BASE"])
        store[key].f.pop(rng.choice(FIELDS[key]), None)         # a component never assigned
    # what == 5: no write between the motions


def test_the_snapshot_memo_is_the_snapshot_bit_for_bit():
    rng = random.Random(62)
    hits = misses = 0
    for _ in range(40):
        store = _store(rng)
        memo = ParamsMemo()
        for _ in range(25):
            for _ in range(rng.choice([0, 0, 1, 1, 2])):
                _write(rng, store)
            last = memo.params
            try:
                fresh = params_from(store)
            except Exception as exc:  # noqa: BLE001 - the memo must raise the same error
                err = type(exc), str(exc)
                try:
                    params_from(store, None, memo)
                except Exception as exc2:  # noqa: BLE001
                    assert (type(exc2), str(exc2)) == err
                else:
                    raise AssertionError(f"the memo answered where the snapshot raised {err}")
                continue
            got = params_from(store, None, memo)
            assert _bits(dataclasses.astuple(got)) == _bits(dataclasses.astuple(fresh))
            if got is last:
                hits += 1
            else:
                misses += 1
    assert hits > 150 and misses > 150, (hits, misses)
