"""Conversions and the geometric operator (reference §3.9, §4.3).

The scalar operators and conversions (INT range, INT division, REAL -> INT rounding, CHAR
codes, comparisons, BOOL and bitwise operators) are the front end's, krl/semantics/values.py,
one meaning for both interpreters, the compiler's folding and the front end's evaluator; this
module adds what needs the runtime's structures and arrays:

* :func:`convert_scalar`, :func:`assign_into`: assignment (§3.9; partial aggregates and
  geometric relatives copy the components present);
* :func:`binary_op`: the front end's operators, and ``:``, which composes frames
  (``T(A:B) = T(A)·T(B)``); the result has the right operand's type and its S, T and external
  axes.
"""

from __future__ import annotations

from operator import is_, itemgetter

from krl.semantics import types as T
from krl.semantics.values import INT_MAX, INT_MIN, KrlRuntimeError, UNSET, EnumValue, check_int, compare, num
from krl.semantics.values import binary_op as _binary_op
from krl.semantics.values import real_to_int, to_bool, trunc_int, unary_op, value_invalid

from .values import Arr, Struct, copy_value, make_value, value_text
from robot.frames import frame_to_matrix, inv_pos as _inv, matrix_to_frame

__all__ = ["INT_MAX", "INT_MIN", "assign_chars", "assign_into", "binary_op", "check_int", "compare",
           "convert_scalar", "frame_tuple", "frame_values", "geo_compose", "inv_pos", "num", "real_to_int",
           "ref_bytes", "ref_text", "struct_from_frame", "to_bool", "trunc_int", "unary_op"]

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
        raise KrlRuntimeError(f"cannot assign {value_text(v)} to INT")
    if t is T.REAL:
        c = v.__class__
        if c is float:
            return v
        if c is int:
            return float(v)
        if c is str and len(v) == 1:
            return float(ord(v))
        raise KrlRuntimeError(f"cannot assign {value_text(v)} to REAL")
    if t is T.BOOL:
        if v is True or v is False:
            return v
        raise KrlRuntimeError(f"cannot assign {value_text(v)} to BOOL")
    if t is T.CHAR:
        if isinstance(v, str) and len(v) == 1:
            return v
        if v.__class__ is int:
            if not 0 <= v <= 255:
                raise KrlRuntimeError(f"CHAR code {v} outside 0..255")
            return chr(v)
        if isinstance(v, Arr) and v.type.elem == T.CHAR and v.data:
            return v.data[0]
        raise KrlRuntimeError(f"cannot assign {value_text(v)} to CHAR")
    if isinstance(t, T.Enum):
        if isinstance(v, EnumValue):
            if t.values and v.name not in t.values:
                raise KrlRuntimeError(f"#{v.name} is not a value of {t.name}")
            return EnumValue(v.name, t)
        raise KrlRuntimeError(f"cannot assign {value_text(v)} to {t.name}")
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
        raise KrlRuntimeError(f"cannot assign {value_text(v)} to a CHAR array")
    data = dest.data
    n = len(data)
    text = text[:n]
    k = len(text)
    data[:k] = text                 # one character an element, in one slice
    data[k:] = "\0" * (n - k)


def assign_into(dest, v) -> None:
    """Assign ``v`` into the existing Struct/Arr ``dest`` in place (so that :OUT
    references and component views stay valid). Structures copy the components present
    in ``v`` that exist in ``dest`` (partial aggregates, geometric relatives, §3.9). A value of
    the structure's own type copies its REAL components' floats as they are (``convert_scalar``
    of a float to REAL is the float, and of an int in range to INT the int: a program's E6POS
    copies, e.g. a status/turn search's)."""
    if dest.__class__ is Struct and v.__class__ is Struct and v.type is dest.type and v.type is not None:
        reals, ints = _scalar_fields(v.type)
        df = dest.f
        for k, x in v.f.items():
            c = x.__class__
            if c is float and k in reals and k in df:
                df[k] = x
            elif c is int and k in ints and k in df and INT_MIN <= x <= INT_MAX:
                df[k] = x
            else:
                _assign_component(dest, v, k, x, v.type.fields)
        return
    if isinstance(dest, Struct):
        if not isinstance(v, Struct):
            if v is UNSET:
                raise value_invalid()
            raise KrlRuntimeError(f"cannot assign {value_text(v)} to {dest.type.name if dest.type else 'a structure'}")
        ftypes = dest.type.fields if dest.type is not None else {}
        for k, x in v.f.items():
            _assign_component(dest, v, k, x, ftypes)
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
        raise KrlRuntimeError(f"cannot assign {value_text(v)} to {dest.type}")
    raise KrlRuntimeError("assignment to a non-aggregate")


def _assign_component(dest, v, k: str, x, ftypes) -> None:
    """:func:`assign_into` of the component `k` (value `x` of the structure `v`) into `dest`."""
    if k not in dest.f:
        if dest.type is None:
            dest.f[k] = copy_value(x)
            return
        if v.type is None:
            raise KrlRuntimeError(f"{dest.type.name} has no component {k}")
        return  # geometric relatives: only components with equal names
    cur = dest.f[k]
    if isinstance(cur, (Struct, Arr)):
        assign_into(cur, x)
    elif x is UNSET:
        dest.f[k] = UNSET
    else:
        ft = ftypes.get(k)
        dest.f[k] = convert_scalar(x, ft[1]) if ft is not None else x


#: structure type -> the names of its REAL and of its INT components (by id, with the type and
#: its field count)
_REALS: dict[int, tuple] = {}


def _scalar_fields(t) -> tuple[frozenset, frozenset]:
    """(the names of the REAL components, those of the INT components) of the structure type `t`
    (kept)."""
    c = _REALS.get(id(t))
    if c is not None and c[0] is t and c[1] == len(t.fields):
        return c[2]
    got = (frozenset(k for k, (_, ft) in t.fields.items() if ft is T.REAL),
           frozenset(k for k, (_, ft) in t.fields.items() if ft is T.INT))
    _REALS[id(t)] = (t, len(t.fields), got)
    return got


def ref_text(ref, what: str) -> str:
    """The text of a STRING or CHAR-array argument (a memory.Ref, None when omitted) of a
    built-in; raises KrlRuntimeError ("value invalid" when omitted, "not a string" otherwise)."""
    if ref is None:
        raise value_invalid(what)
    v = ref.get()
    if isinstance(v, str):
        return v
    if isinstance(v, Arr) and v.type.elem == T.CHAR:
        return v.text()
    raise KrlRuntimeError(f"{what} is not a string")


def ref_bytes(ref, what: str) -> bytes:
    """The bytes of a CHAR-array argument of a built-in, every element of it (a NUL, an unset
    element: 0), or of a string literal (one byte a character): a binary record as
    ``EKI_Send`` sends it (docs/network.md "Binary records"). Raises as :func:`ref_text`."""
    if ref is None:
        raise value_invalid(what)
    v = ref.get()
    if isinstance(v, str):
        return v.encode("latin-1", "replace")
    if isinstance(v, Arr) and v.type.elem == T.CHAR:
        return bytes(0 if c is UNSET else ord(c) & 0xFF for c in v.data)
    raise KrlRuntimeError(f"{what} is not a string")


# ------------------------------------------------------------------ operators (§4.1, §4.3)

def binary_op(op: str, a, b):
    """Apply binary operator ``op`` (upper-case, as in the AST) to two values: ``:`` composes
    frames (:func:`geo_compose`), every other operator is the front end's
    (krl.semantics.values.binary_op)."""
    if op == ":":
        return geo_compose(a, b)
    return _binary_op(op, a, b)


# ------------------------------------------------------------------ geometry (§4.3)

FRAME_KEYS = ("X", "Y", "Z", "A", "B", "C")
_XYZABC = itemgetter(*FRAME_KEYS)


def frame_tuple(v, what: str = "frame") -> tuple:
    """(X, Y, Z, A, B, C) of a FRAME/POS/E6POS value (missing components 0; set ones only)."""
    if v.__class__ is Struct:
        f = v.f
        try:
            out = _XYZABC(f)    # a FRAME/POS/E6POS value has every component (UNSET or set)
        except KeyError:
            g = f.get
            out = (g("X", 0.0), g("Y", 0.0), g("Z", 0.0), g("A", 0.0), g("B", 0.0), g("C", 0.0))
        x, y, z, a, b, c = out
        if (x.__class__ is float and y.__class__ is float and z.__class__ is float and a.__class__ is float
                and b.__class__ is float and c.__class__ is float):
            return out          # (float(num(x)) of a float is x itself)
    return frame_values(v, what)


def frame_values(v, what: str = "frame") -> tuple:
    """:func:`frame_tuple` for any value: each component through ``num`` and ``float``; raises
    KrlRuntimeError for a value that is not a structure or an unset component."""
    if not isinstance(v, Struct):
        raise KrlRuntimeError(f"{what} is not a FRAME/POS: {value_text(v)}")
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


#: the left operand of the last ``:`` and its matrix (:func:`geo_compose`)
_last_left: tuple = ((), None)


def geo_compose(a, b) -> Struct:
    """``a : b`` (§4.3). The matrix of the left operand is the last one's when its six values
    are the very objects the last was made of (``is``: the same floats, -0.0 not 0.0; a read-only
    array held here): a program that composes one base frame with many points (the CAM-like
    program's ``lfStartPoint:lfPoint``) makes it once."""
    global _last_left
    fa = frame_tuple(a, "left operand of ':'")
    last, Ta = _last_left
    if len(last) != len(fa) or not all(map(is_, fa, last)):
        Ta = frame_to_matrix(*fa)
        Ta.flags.writeable = False
        _last_left = (fa, Ta)
    Tb = frame_to_matrix(*frame_tuple(b, "right operand of ':'"))
    fr = matrix_to_frame(Ta @ Tb)
    return struct_from_frame(fr, b)


def inv_pos(a) -> Struct:

    fr = matrix_to_frame(_inv(frame_to_matrix(*frame_tuple(a, "INV_POS argument"))))
    return struct_from_frame(fr, a)
