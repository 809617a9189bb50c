"""CAST_TO / CAST_FROM: raw byte copies between variables and a CHAR buffer (reference §4.8).

    CAST_TO(buffer[], offset, var1, var2, ...)     ; writes the bytes of var1.. at offset
    CAST_FROM(buffer[], offset, var1, var2, ...)   ; reads var1.. back from offset

``offset`` (INT, in/out) counts the bytes before the first one written or read and advances
past them. The byte layout: little-endian, INT 4 bytes two's complement, REAL 4 bytes IEEE
single (so a REAL round trip rounds to single precision), BOOL 1 byte 0/1, CHAR 1 byte. Source:
KUKA's EthernetKRL 2.2 manual, 6.2.4 (p. 33), whose example writes
``CAST_TO(Bytes[],OFFSET,91984754,913434.2,TRUE,"X")`` into ``CHAR Bytes[10]`` and sends
``"r?{ ? _I X"``: 4 + 4 + 1 + 1 bytes, the INT's low byte ``r`` (0x72) first; the CREAD/CWRITE
manual that page refers to is quoted nowhere public in full (docs/network.md, "Binary
records"). Until issue 59 BOOL took 4 bytes: the manual's own record came out 13 bytes long.
Arrays element by element in row-major order, structures component by component in
declaration order. ENUM values have no documented code and are refused. Errors: an offset
outside 0..the buffer's length (a negative offset never reads from the end of the buffer), a
buffer too small, an unset value (1422).
"""

from __future__ import annotations

import struct

from krl.semantics import types as T

from ..convert import num, real_to_int
from ..errors import KrlRuntimeError, value_invalid
from ..values import UNSET, Arr, Struct
from .registry import Family

CAST = Family("cast")

_SCALAR = {"INT": "<i", "REAL": "<f", "BOOL": "<?"}


def _type_of(ref, value):
    t = getattr(ref, "type", None)
    if t is not None:
        return t
    if isinstance(value, (Arr, Struct)):
        return value.type
    if isinstance(value, bool):
        return T.BOOL
    if isinstance(value, int):
        return T.INT
    if isinstance(value, float):
        return T.REAL
    if isinstance(value, str) and len(value) == 1:
        return T.CHAR
    raise KrlRuntimeError("CAST: a variable of this type cannot be copied")


def encode(value, type_) -> bytes:
    """The bytes of one KRL value of type ``type_``."""
    if value is UNSET:
        raise value_invalid("CAST_TO argument")
    if isinstance(type_, T.Array):
        return b"".join(encode(v, type_.elem) for v in value.data)
    if isinstance(type_, T.Struc):
        return b"".join(encode(value.f.get(key, UNSET), ftype) for key, (_, ftype) in type_.fields.items())
    name = getattr(type_, "name", "")
    if name == "CHAR":
        return bytes([ord(value) & 0xFF])
    if name in _SCALAR:
        return struct.pack(_SCALAR[name], float(value) if name == "REAL" else bool(value) if name == "BOOL"
                           else int(value))
    raise KrlRuntimeError(f"CAST: values of type {type_} cannot be copied")


def decode(data: bytes, pos: int, type_, old=None):
    """(value, next position) of one value of ``type_`` read at ``pos``."""
    if isinstance(type_, T.Array):
        items = []
        for k in range(len(old.data)):
            v, pos = decode(data, pos, type_.elem, old.data[k])
            items.append(v)
        old.data[:] = items
        return old, pos
    if isinstance(type_, T.Struc):
        out = old if isinstance(old, Struct) else Struct(type_)
        for key, (_, ftype) in type_.fields.items():
            out.f[key], pos = decode(data, pos, ftype, out.f.get(key))
        return out, pos
    name = getattr(type_, "name", "")
    if name == "CHAR":
        _need(data, pos, 1)
        return chr(data[pos]), pos + 1
    if name in _SCALAR:
        fmt = _SCALAR[name]
        size = struct.calcsize(fmt)
        _need(data, pos, size)
        (v,) = struct.unpack_from(fmt, data, pos)
        if name == "BOOL":
            v = data[pos] != 0              # any byte other than 0 reads TRUE
        return v, pos + size
    raise KrlRuntimeError(f"CAST: values of type {type_} cannot be copied")


def _need(data: bytes, pos: int, n: int) -> None:
    if pos < 0 or pos + n > len(data):
        raise KrlRuntimeError("CAST_FROM: the buffer ends before the variable")


def _buffer(ref, what: str) -> Arr:
    v = ref.peek() if ref is not None else UNSET
    if not (isinstance(v, Arr) and v.type.elem == T.CHAR):
        raise KrlRuntimeError(f"{what}: the buffer is not a CHAR array")
    return v


def _offset(ref, what: str, buf: Arr) -> int:
    """The offset argument: an INT from 0 to the buffer's length (a REAL is rounded as on
    assignment); anything else is a run-time error, never a Python index from the end."""
    if ref is None:
        return 0
    v = num(ref.get(), f"{what} offset")
    off = v if v.__class__ is int else real_to_int(v)
    if not 0 <= off <= len(buf.data):
        raise KrlRuntimeError(f"{what}: offset {off} outside 0..{len(buf.data)} (the buffer's length)")
    return off


@CAST.native("BOOL CAST_TO(CHAR BUFFER[] :OUT, INT OFFSET :OUT, ...)", pure=True)
def cast_to(ctx, a) -> None:  # noqa: ARG001 - the built-ins' calling convention
    buf = _buffer(a[0], "CAST_TO")
    off = _offset(a[1], "CAST_TO", buf)
    data = b"".join(encode(r.get() if r is not None else UNSET, _type_of(r, r.peek() if r else UNSET))
                    for r in a[2:])
    if off + len(data) > len(buf.data):
        raise KrlRuntimeError("CAST_TO: the buffer is too small")
    for k, byte in enumerate(data):
        buf.data[off + k] = chr(byte)
    if a[1] is not None:
        a[1].set(off + len(data))


@CAST.native("BOOL CAST_FROM(CHAR BUFFER[] :IN, INT OFFSET :OUT, ...)", pure=True)
def cast_from(ctx, a) -> None:  # noqa: ARG001
    buf = _buffer(a[0], "CAST_FROM")
    pos = _offset(a[1], "CAST_FROM", buf)
    raw = bytes(0 if c is UNSET else ord(c) & 0xFF for c in buf.data)
    for r in a[2:]:
        if r is None:
            continue
        old = r.peek()
        value, pos = decode(raw, pos, _type_of(r, old), old)
        r.set(value)
    if a[1] is not None:
        a[1].set(pos)
