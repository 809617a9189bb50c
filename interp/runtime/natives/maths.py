"""KRL's arithmetic functions (reference 4.5): ABS, SQRT, SIN, COS, TAN, ACOS, ATAN2, FRAND.

Angles are in degrees, as on the controller. Errors stop the program: SQRT of a negative
number, TAN at an odd multiple of 90 degrees, ACOS outside -1..1. ATAN2(0, 0) is 0.
FRAND draws from the run's seeded random generator (context.py ``NativeContext.uniform``).
"""

from __future__ import annotations

import math

from krl.semantics.facts import ARGS, CLOCK
from ..errors import KrlRuntimeError
from .args import real_arg
from .registry import Family

MATHS = Family("math")


@MATHS.native("REAL ABS(REAL X :IN)", pure=True)
def _abs(ctx, a):
    return abs(real_arg(a[0]))


@MATHS.native("REAL SQRT(REAL X :IN)", pure=True)
def _sqrt(ctx, a):
    x = real_arg(a[0])
    if x < 0:
        raise KrlRuntimeError(f"SQRT of a negative number ({x})")
    return math.sqrt(x)


def _trig(fn):
    return lambda ctx, a: fn(math.radians(real_arg(a[0])))


MATHS.add("REAL SIN(REAL X :IN)", _trig(math.sin), pure=True)
MATHS.add("REAL COS(REAL X :IN)", _trig(math.cos), pure=True)


@MATHS.native("REAL TAN(REAL X :IN)", pure=True)
def _tan(ctx, a):
    x = real_arg(a[0])
    if abs(math.cos(math.radians(x))) < 1e-12:
        raise KrlRuntimeError(f"TAN({x}) is undefined")
    return math.tan(math.radians(x))


@MATHS.native("REAL ACOS(REAL X :IN)", pure=True)
def _acos(ctx, a):
    x = real_arg(a[0])
    if not -1.0 <= x <= 1.0:
        raise KrlRuntimeError(f"ACOS argument {x} outside -1..1")
    return math.degrees(math.acos(x))


@MATHS.native("REAL ATAN2(REAL Y :IN, REAL X :IN)", pure=True)
def _atan2(ctx, a):
    y, x = real_arg(a[0]), real_arg(a[1])
    if x == 0 and y == 0:
        return 0.0
    return math.degrees(math.atan2(y, x))


@MATHS.native("REAL FRAND(REAL MIN_VAL :IN, REAL MAX_VAL :IN)", reads=(ARGS, CLOCK))
def _frand(ctx, a):
    lo, hi = real_arg(a[0]), real_arg(a[1])
    return ctx.uniform(lo, hi)      # a clock read too: not idle (interp/runtime/idle.py)
