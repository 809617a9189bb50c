"""KRL scalar values and operators: the one meaning of an operator (reference §3.9, §4.1).

Both interpreters (through interp/runtime/convert.py), the compiler's constant folding, and the
front end's own evaluator (:mod:`krl.semantics.evaluate`: cell-rule conditions, data-list
initialisers, typed expressions) apply these functions, so an operator means one thing
everywhere.

Values: INT -> ``int``, REAL -> ``float``, BOOL -> ``bool``, CHAR -> a one-character ``str``
(arithmetic and comparisons use its code), ENUM -> :class:`EnumValue`, :data:`UNSET` a leaf
declared but never assigned (reading it is error 1422 "value invalid", reference §10.2).
Structures and arrays are the runtime's (interp/runtime/values.py); the geometric operator
``:`` (§4.3) composes frames and is the runtime's too (``interp.runtime.convert.binary_op``).

Decisions the reference leaves open (recorded in docs/architecture.md):

* INT is 32-bit: a result outside -2^31..2^31-1 is the run-time error "INT overflow"
  (the reference leaves wrap vs. error open and recommends the error);
* ``INT / INT`` truncates toward zero (7/2 = 3, -7/2 = -3); division by zero is an error;
* REAL -> INT rounds to the nearest integer, ties away from zero (2.5 -> 3, -2.5 -> -3);
* no short circuit: both operands are evaluated, then the operator applies;
* ``AND``/``OR``/``EXOR``/``NOT`` of INT operands are the bitwise operators (lenient);
* REAL is a Python float (double); results are not rounded to binary32.

Errors are :class:`KrlRuntimeError` (message, KSS number where the reference gives one).
"""

from __future__ import annotations

import math

VALUE_INVALID = 1422
INTERRUPT_NOT_DECLARED = 1430
#: KUKA's message for a name that is no function of the controller (CWRITE $FCT_CALL; CrossMeld 1309)
NOT_AVAILABLE = 1309

INT_MIN = -(2 ** 31)
INT_MAX = 2 ** 31 - 1


class KrlRuntimeError(Exception):
    """A KRL run-time error: ``message``, ``number`` (or None), ``file``, ``line``, and ``name``:
    the KRL name an error about one is about ("unknown name X", "routine X not found", "X is not
    an array"; None for the others), so that a reader of the error needs no parse of its text.

    Raised by the operators here, by the front end's evaluator and by the interpreters'
    runtime (interp/runtime/errors.py re-exports it with the unwinding signals)."""

    def __init__(self, message: str, number: int | None = None, file: str | None = None,
                 line: int | None = None, name: str | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.name = name
        self.number = number
        self.file = file
        self.line = line
        # True when the trace already holds this error's `error` event (a main-run fault,
        # written by the controller with its motion id): the run does not write it again
        self.traced = False
        self.debug_seen = False     # a debugger stopped at it already (Stepping.error_hook)

    def at(self, file: str | None, line: int | None) -> "KrlRuntimeError":
        """Set the place if it is not set yet (the innermost statement wins); returns self."""
        if self.line is None:
            self.file, self.line = file, line
        return self

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}: " if self.line is not None else ""
        num_ = f" ({self.number})" if self.number is not None else ""
        return f"{where}{self.message}{num_}"


def value_invalid(what: str = "") -> KrlRuntimeError:
    """Error 1422 "value invalid" (a leaf read before it was assigned, reference §10.2)."""
    return KrlRuntimeError(f"value invalid{': ' + what if what else ''}", VALUE_INVALID)


class _Unset:
    __slots__ = ()

    def __repr__(self) -> str:
        return "UNSET"

    def __bool__(self) -> bool:  # never used as a truth value by accident
        raise TypeError("UNSET has no truth value")


UNSET = _Unset()


class EnumValue:
    """``#NAME``: an enum value (name upper-case; ``type`` the Enum type if known)."""

    __slots__ = ("name", "type")

    def __init__(self, name: str, type_=None) -> None:
        self.name = name.upper()
        self.type = type_

    def __eq__(self, other: object) -> bool:
        return isinstance(other, EnumValue) and other.name == self.name

    def __hash__(self) -> int:
        return hash(("#", self.name))

    def __repr__(self) -> str:
        return f"#{self.name}"


# ------------------------------------------------------------------ conversions (§3.9)

def check_int(v: int) -> int:
    """`v` if it is in the INT range, else the run-time error "INT overflow"."""
    if v < INT_MIN or v > INT_MAX:
        shown = v if v.bit_length() <= 128 else ("a huge negative number" if v < 0 else "a huge number")
        raise KrlRuntimeError(f"INT overflow ({shown} outside -2147483648..2147483647)")
    return v


def real_to_int(x: float) -> int:
    """REAL -> INT: the nearest integer, ties away from zero (5 + 10.6 -> 16, 2.5 -> 3, -2.5 -> -3)."""
    if math.isnan(x) or math.isinf(x):
        raise KrlRuntimeError("REAL value cannot be converted to INT")
    r = math.floor(abs(x) + 0.5)
    return check_int(int(r if x >= 0 else -r))


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


def trunc_int(v, what: str = "operand") -> int:
    """``int(num(v))``: a REAL truncated toward zero, as interrupt numbers, S/T, TRIGGER
    DISTANCE/PRIO and SWRITE's %c take it; a NaN or infinite REAL is the run-time error
    "REAL value cannot be converted to INT", a REAL past the INT range "INT overflow", never a
    Python exception or a huge Python int."""
    x = num(v, what)
    if x.__class__ is float and not math.isfinite(x):
        raise KrlRuntimeError(f"{what}: REAL value cannot be converted to INT")
    return check_int(int(x))


def to_bool(v, what: str = "condition") -> bool:
    """A BOOL operand or condition."""
    if v is True or v is False:
        return v
    if v is UNSET:
        raise value_invalid()
    raise KrlRuntimeError(f"{what} is not BOOL: {v!r}")


# ------------------------------------------------------------------ operators (§4.1)

_ARITH = {"+", "-", "*", "/"}
_CMP = {"==", "<>", "<", ">", "<=", ">="}


def _wrap32(v: int) -> int:
    v &= 0xFFFFFFFF
    return v - (1 << 32) if v & 0x80000000 else v


def binary_op(op: str, a, b):
    """Apply binary operator ``op`` (upper-case, as in the AST) to two values; the geometric
    operator ``:`` is the runtime's (it composes frames: interp.runtime.convert.binary_op)."""
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
    raise KrlRuntimeError(f"unknown operator {op}")


def compare(op: str, a, b) -> bool:
    """A comparison (``==``, ``<>``, ``<``, ``>``, ``<=``, ``>=``): numbers and CHARs by value,
    BOOL and ENUM values only for (in)equality."""
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
    """Apply unary operator ``op`` (``-``, ``+``, ``NOT``, ``B_NOT``) to a value."""
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


__all__ = ["INTERRUPT_NOT_DECLARED", "INT_MAX", "INT_MIN", "UNSET", "VALUE_INVALID", "EnumValue",
           "KrlRuntimeError", "binary_op", "check_int", "compare", "num", "real_to_int", "to_bool",
           "trunc_int", "unary_op", "value_invalid"]
