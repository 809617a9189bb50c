"""Conversions and operator semantics (reference §3.9, §4.1, §4.3).

* INT is 32-bit: a result outside -2^31..2^31-1 is the run-time error "INT overflow"
  (the reference leaves wrap vs. error open and recommends the error).
* ``INT / INT`` truncates toward zero (7/2 = 3, -7/2 = -3); division by zero is an error.
* REAL -> INT rounds to the nearest integer, ties away from zero (5 + 10.6 -> 16,
  2.5 -> 3, -2.5 -> -3); ``ROUNDING`` can be switched to "trunc".
* CHAR <-> INT use the character code; CHAR takes part in arithmetic and comparisons as
  its code.
* No short circuit: the interpreter evaluates both operands, then calls :func:`binary_op`.
* ``:`` composes frames (``T(A:B) = T(A)·T(B)``); the result has the right operand's type
  and its S, T and external axes.
* REAL is a Python float (double); results are not rounded to binary32.
"""

from __future__ import annotations

import math

from krl.semantics import types as T

from .errors import KrlRuntimeError, value_invalid
from .values import UNSET, Arr, EnumValue, Struct, copy_value, make_value

INT_MIN = -(2 ** 31)
INT_MAX = 2 ** 31 - 1
ROUNDING = "half_away"   # or "trunc" (reference §3.9 [U])


def check_int(v: int) -> int:
    if v < INT_MIN or v > INT_MAX:
        shown = v if v.bit_length() <= 128 else ("a huge negative number" if v < 0 else "a huge number")
        raise KrlRuntimeError(f"INT overflow ({shown} outside -2147483648..2147483647)")
    return v


def real_to_int(x: float) -> int:
    """REAL -> INT: nearest integer, ties away from zero (or truncation, see ROUNDING)."""
    if math.isnan(x) or math.isinf(x):
        raise KrlRuntimeError("REAL value cannot be converted to INT")
    if ROUNDING == "trunc":
        return check_int(int(x))
    r = math.floor(abs(x) + 0.5)
    return check_int(int(r if x >= 0 else -r))


def trunc_int(v, what: str = "operand") -> int:
    """``int(num(v))``: a REAL truncated toward zero, as interrupt numbers, S/T, TRIGGER
    DISTANCE/PRIO and SWRITE's %c take it; a NaN or infinite REAL is the run-time error
    "REAL value cannot be converted to INT", a REAL past the INT range "INT overflow", never a
    Python exception or a huge Python int."""
    x = num(v, what)
    if x.__class__ is float and not math.isfinite(x):
        raise KrlRuntimeError(f"{what}: REAL value cannot be converted to INT")
    return check_int(int(x))


def num(v, what: str = "operand"):
    """A numeric operand: INT, REAL, or a CHAR as its code."""
    if v.__class__ is int or v.__class__ is float:
        return v
    if isinstance(v, str) and len(v) == 1:
        return ord(v)
    if v is UNSET:
        raise value_invalid()
    if isinstance(v, bool):
        raise KrlRuntimeError(f"BOOL {what} where a number is needed")
    raise KrlRuntimeError(f"{what} is not a number: {v!r}")


def to_bool(v, what: str = "condition") -> bool:
    if v is True or v is False:
        return v
    if v is UNSET:
        raise value_invalid()
    raise KrlRuntimeError(f"{what} is not BOOL: {v!r}")


def convert_scalar(v, t):
    """Convert ``v`` for storage in a leaf of simple/enum type ``t`` (assignment, §3.9)."""
    if v is UNSET:
        raise value_invalid()
    if t is T.INT:
        c = v.__class__
        if c is int:
            return check_int(v)
        if c is float:
            return real_to_int(v)
        if c is str and len(v) == 1:
            return ord(v)
        raise KrlRuntimeError(f"cannot assign {v!r} to INT")
    if t is T.REAL:
        c = v.__class__
        if c is float:
            return v
        if c is int:
            return float(v)
        if c is str and len(v) == 1:
            return float(ord(v))
        raise KrlRuntimeError(f"cannot assign {v!r} to REAL")
    if t is T.BOOL:
        if v is True or v is False:
            return v
        raise KrlRuntimeError(f"cannot assign {v!r} to BOOL")
    if t is T.CHAR:
        if isinstance(v, str) and len(v) == 1:
            return v
        if v.__class__ is int:
            if not 0 <= v <= 255:
                raise KrlRuntimeError(f"CHAR code {v} outside 0..255")
            return chr(v)
        if isinstance(v, Arr) and v.type.elem == T.CHAR and v.data:
            return v.data[0]
        raise KrlRuntimeError(f"cannot assign {v!r} to CHAR")
    if isinstance(t, T.Enum):
        if isinstance(v, EnumValue):
            if t.values and v.name not in t.values:
                raise KrlRuntimeError(f"#{v.name} is not a value of {t.name}")
            return EnumValue(v.name, t)
        raise KrlRuntimeError(f"cannot assign {v!r} to {t.name}")
    if isinstance(t, T.Struc):
        dest = make_value(t)
        assign_into(dest, v)
        return dest
    if isinstance(t, T.Array):
        dest = make_value(t)
        assign_into(dest, v)
        return dest
    return copy_value(v)  # unknown type: store a copy as is


def assign_chars(dest: Arr, v) -> None:
    """``s[] = "text"`` / ``dst[] = src[]``: copy characters, clear the rest (§3.4)."""
    if isinstance(v, Arr):
        text = v.text()
    elif isinstance(v, str):
        text = v
    else:
        raise KrlRuntimeError(f"cannot assign {v!r} to a CHAR array")
    n = len(dest.data)
    text = text[:n]
    for i, ch in enumerate(text):
        dest.data[i] = ch
    for i in range(len(text), n):
        dest.data[i] = "\0"


def assign_into(dest, v) -> None:
    """Assign ``v`` into the existing Struct/Arr ``dest`` in place (so that :OUT
    references and component views stay valid). Structures copy the components present
    in ``v`` that exist in ``dest`` (partial aggregates, geometric relatives, §3.9)."""
    if isinstance(dest, Struct):
        if not isinstance(v, Struct):
            if v is UNSET:
                raise value_invalid()
            raise KrlRuntimeError(f"cannot assign {v!r} to {dest.type.name if dest.type else 'a structure'}")
        ftypes = dest.type.fields if dest.type is not None else {}
        for k, x in v.f.items():
            if k not in dest.f:
                if dest.type is None:
                    dest.f[k] = copy_value(x)
                    continue
                if v.type is None:
                    raise KrlRuntimeError(f"{dest.type.name} has no component {k}")
                continue  # geometric relatives: only components with equal names
            cur = dest.f[k]
            if isinstance(cur, (Struct, Arr)):
                assign_into(cur, x)
            elif x is UNSET:
                dest.f[k] = UNSET
            else:
                ft = ftypes.get(k)
                dest.f[k] = convert_scalar(x, ft[1]) if ft is not None else x
        return
    if isinstance(dest, Arr):
        if dest.type.elem == T.CHAR and len(dest.dims) == 1 and (isinstance(v, str) or (
                isinstance(v, Arr) and v.type.elem == T.CHAR)):
            assign_chars(dest, v)
            return
        if isinstance(v, Arr) and len(v.data) == len(dest.data):
            for i, x in enumerate(v.data):
                cur = dest.data[i]
                if isinstance(cur, (Struct, Arr)):
                    assign_into(cur, x)
                else:
                    dest.data[i] = x if x is UNSET else convert_scalar(x, dest.type.elem)
            return
        raise KrlRuntimeError(f"cannot assign {v!r} to {dest.type}")
    raise KrlRuntimeError("assignment to a non-aggregate")


# ------------------------------------------------------------------ operators (§4.1)

_ARITH = {"+", "-", "*", "/"}
_CMP = {"==", "<>", "<", ">", "<=", ">="}


def _wrap32(v: int) -> int:
    v &= 0xFFFFFFFF
    return v - (1 << 32) if v & 0x80000000 else v


def binary_op(op: str, a, b):
    """Apply binary operator ``op`` (upper-case, as in the AST) to two values."""
    if op in _ARITH:
        x = num(a)
        y = num(b)
        if x.__class__ is int and y.__class__ is int:
            if op == "+":
                return check_int(x + y)
            if op == "-":
                return check_int(x - y)
            if op == "*":
                return check_int(x * y)
            if y == 0:
                raise KrlRuntimeError("division by zero")
            q = abs(x) // abs(y)
            return check_int(q if (x >= 0) == (y >= 0) else -q)
        if op == "+":
            return float(x + y)
        if op == "-":
            return float(x - y)
        if op == "*":
            return float(x * y)
        if y == 0:
            raise KrlRuntimeError("division by zero")
        return x / y
    if op in _CMP:
        return compare(op, a, b)
    if op in ("AND", "OR", "EXOR"):
        if (a is True or a is False) and (b is True or b is False):
            if op == "AND":
                return a and b
            if op == "OR":
                return a or b
            return a != b
        op = "B_" + op  # INT operands: the bitwise meaning (lenient)
    if op in ("B_AND", "B_OR", "B_EXOR"):
        x, y = num(a), num(b)
        if x.__class__ is not int or y.__class__ is not int:
            raise KrlRuntimeError(f"{op} needs INT operands")
        if op == "B_AND":
            return _wrap32(x & y)
        if op == "B_OR":
            return _wrap32(x | y)
        return _wrap32(x ^ y)
    if op == ":":
        return geo_compose(a, b)
    raise KrlRuntimeError(f"unknown operator {op}")


def compare(op: str, a, b) -> bool:
    if a is UNSET or b is UNSET:
        raise value_invalid()
    if isinstance(a, EnumValue) or isinstance(b, EnumValue):
        if op == "==":
            return a == b
        if op == "<>":
            return a != b
        raise KrlRuntimeError("enum values have no order")
    if (a is True or a is False) or (b is True or b is False):
        if (a is True or a is False) and (b is True or b is False):
            if op == "==":
                return a == b
            if op == "<>":
                return a != b
        raise KrlRuntimeError(f"cannot compare {a!r} {op} {b!r}")
    x, y = num(a), num(b)
    if op == "==":
        return x == y
    if op == "<>":
        return x != y
    if op == "<":
        return x < y
    if op == ">":
        return x > y
    if op == "<=":
        return x <= y
    return x >= y


def unary_op(op: str, a):
    if op == "-":
        x = num(a)
        return check_int(-x) if x.__class__ is int else -x
    if op == "+":
        return num(a)
    if op == "NOT":
        if a is True or a is False:
            return not a
        if a.__class__ is int:
            return _wrap32(~a)
        raise KrlRuntimeError("NOT needs a BOOL operand")
    if op == "B_NOT":
        x = num(a)
        if x.__class__ is not int:
            raise KrlRuntimeError("B_NOT needs an INT operand")
        return _wrap32(~x)
    raise KrlRuntimeError(f"unknown operator {op}")


# ------------------------------------------------------------------ geometry (§4.3)

FRAME_KEYS = ("X", "Y", "Z", "A", "B", "C")


def frame_tuple(v, what: str = "frame") -> tuple:
    """(X, Y, Z, A, B, C) of a FRAME/POS/E6POS value (missing components 0; set ones only)."""
    if not isinstance(v, Struct):
        raise KrlRuntimeError(f"{what} is not a FRAME/POS: {v!r}")
    out = []
    for k in FRAME_KEYS:
        x = v.f.get(k, 0.0)
        if x is UNSET:
            raise value_invalid(f"{what}.{k}")
        out.append(float(num(x)))
    return tuple(out)


def struct_from_frame(fr, like: Struct | None, type_=None) -> Struct:
    """A Struct with X..C from ``fr`` and the other components (S, T, E1..) of ``like``."""
    t = type_ if type_ is not None else (like.type if like is not None else None)
    out = make_value(t) if t is not None else Struct(None, {})
    if like is not None:
        for k, x in like.f.items():
            if k not in FRAME_KEYS and k in out.f or t is None:
                out.f[k] = copy_value(x)
    for k, x in zip(FRAME_KEYS, fr):
        out.f[k] = float(x)
    return out


def geo_compose(a, b) -> Struct:
    from robot.frames import frame_to_matrix, matrix_to_frame  # noqa: PLC0415

    Ta = frame_to_matrix(*frame_tuple(a, "left operand of ':'"))
    Tb = frame_to_matrix(*frame_tuple(b, "right operand of ':'"))
    fr = matrix_to_frame(Ta @ Tb)
    return struct_from_frame(fr, b)


def inv_pos(a) -> Struct:
    from robot.frames import frame_to_matrix, inv_pos as _inv, matrix_to_frame  # noqa: PLC0415

    fr = matrix_to_frame(_inv(frame_to_matrix(*frame_tuple(a, "INV_POS argument"))))
    return struct_from_frame(fr, a)
