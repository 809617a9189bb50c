"""The arguments of a native (interp/runtime/natives/registry.py): reading and writing them.

A native gets its arguments as references: a variable by reference, an expression as a
:class:`ValueRef` (both interpreters wrap it the same way), an omitted argument as None.
The readers here raise the controller's errors: an omitted or unset value is 1422 "value
invalid" (interp/runtime/errors.py ``value_invalid``), a value of the wrong kind a
:class:`~interp.runtime.errors.KrlRuntimeError` that names the argument.
"""

from __future__ import annotations

from ..convert import num, real_to_int
from ..errors import KrlRuntimeError, value_invalid
from ..memory import Ref
from ..values import Arr, EnumValue, is_char_array


class ValueRef(Ref):
    """An rvalue passed where a reference is expected (an :IN expression argument)."""

    __slots__ = ("v", "type", "name")

    def __init__(self, v, name: str = "argument") -> None:
        self.v = v
        self.type = None
        self.name = name

    def peek(self):
        return self.v

    def set(self, v) -> None:
        self.v = v


def real_arg(ref, what="argument") -> float:
    """The value of a REAL (or INT) argument as a float; 1422 when omitted or unset."""
    if ref is None:
        raise value_invalid(what)
    return float(num(ref.get(), what))


def int_arg(ref, what="argument") -> int:
    """The value of an INT argument (a REAL rounds, reference 3.9); 1422 when omitted or unset."""
    if ref is None:
        raise value_invalid(what)
    v = num(ref.get(), what)
    return v if v.__class__ is int else real_to_int(v)


def char_array(ref, what) -> Arr:
    """The CHAR array an argument refers to (to be written in place); 1422 when omitted."""
    if ref is None:
        raise value_invalid(what)
    v = ref.peek()
    if not is_char_array(v):
        raise KrlRuntimeError(f"{what} is not a CHAR array")
    return v


def put_text(arr: Arr, text: str) -> int:
    """Write `text` into the CHAR array `arr`, cut to its length, the rest NUL; returns the
    number of characters written."""
    n = len(arr.data)
    text = text[:n]
    for i, ch in enumerate(text):
        arr.data[i] = ch
    for i in range(len(text), n):
        arr.data[i] = "\0"
    return len(text)


def case_sensitive(ref) -> bool:
    """A CASE_SENSE_T argument: False for #NOT_CASE_SENS, True otherwise (also omitted)."""
    if ref is None:
        return True
    v = ref.get()
    return not (isinstance(v, EnumValue) and v.name == "NOT_CASE_SENS")


__all__ = ["ValueRef", "case_sensitive", "char_array", "int_arg", "put_text", "real_arg"]
