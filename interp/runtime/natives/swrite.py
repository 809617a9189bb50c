"""Formatted text (reference 4.7): SWRITE and SREAD, and their printf/scanf-style format
engine, written here (no eval).

A format is ``%[flags][width][.precision]conv`` with flags ``-+ 0#``, conversions
``d i x X o f F e E g G c s`` and ``%%``. Width and precision are ASCII digits no larger than
the length of the CHAR buffer written or read. A bad specification (unknown conversion, width
or precision past the buffer, a non-ASCII digit) is a format error, as on the controller: the
text up to it is written, ``state.RET1`` = #FMT_ERR and ``state.HITS`` counts the values
converted before it; the program goes on (without a STATE_T variable it is a run-time error).
docs/security.md lists the limits.
"""

from __future__ import annotations

import math
from typing import Any

from ..convert import num, real_to_int, ref_text, trunc_int
from ..errors import KrlRuntimeError, value_invalid
from ..values import UNSET, Arr, EnumValue, Struct
from .args import char_array, int_arg, put_text
from .registry import Family

FORMATTED = Family("formatted text")


_FLAGS = "-+ 0#"
_DIGITS = "0123456789"     # ASCII only: str.isdigit() also takes '²', '٣', ...


class FormatError(Exception):
    """A format that SWRITE/SREAD cannot use: the state's RET1 becomes #FMT_ERR."""


def _ascii_digits(text: str, j: int) -> int:
    """The end of the run of ASCII digits starting at ``text[j]``."""
    n = len(text)
    while j < n and text[j] in _DIGITS:
        j += 1
    return j


def _bounded(digits: str, limit: int, what: str, fmt: str) -> int:
    """``digits`` as a width or precision no larger than ``limit`` (the buffer's length);
    compared as text first, so that a 20-digit number is never turned into an int."""
    significant = digits.lstrip("0") or "0"
    if len(significant) > len(str(limit)) or int(significant) > limit:
        raise FormatError(f"format error: {what} {digits[:12]}{'...' if len(digits) > 12 else ''} "
                          f"larger than the buffer ({limit} characters) in {fmt[:40]!r}")
    return int(significant)


def parse_format(fmt: str, limit: int) -> tuple[list, str | None]:
    """Split a format into literal strings and (flags, width, precision, conv) tuples.

    Returns (parts, error): ``parts`` the format up to the first bad specification,
    ``error`` its message (None when the whole format is good). Width and precision are
    ASCII digits and bounded by ``limit``, the length of the CHAR buffer written (SWRITE)
    or read (SREAD): a larger one is a format error, as is an unknown conversion."""
    out: list = []
    i, n = 0, len(fmt)
    lit = []
    try:
        while i < n:
            ch = fmt[i]
            if ch != "%":
                lit.append(ch)
                i += 1
                continue
            if i + 1 < n and fmt[i + 1] == "%":
                lit.append("%")
                i += 2
                continue
            if lit:
                out.append("".join(lit))
                lit = []
            j = i + 1
            flags = ""
            while j < n and fmt[j] in _FLAGS:
                flags += fmt[j]
                j += 1
            k = _ascii_digits(fmt, j)
            width = _bounded(fmt[j:k], limit, "width", fmt) if k > j else None
            j = k
            prec = None
            if j < n and fmt[j] == ".":
                k = _ascii_digits(fmt, j + 1)
                prec = _bounded(fmt[j + 1:k], limit, "precision", fmt) if k > j + 1 else 0
                j = k
            while j < n and fmt[j] in "lhL":
                j += 1
            if j >= n:
                raise FormatError(f"format error: incomplete specification at the end of {fmt[:40]!r}")
            conv = fmt[j]
            if conv not in "dixXofFeEgGcs":
                raise FormatError(f"format error: %{conv} in {fmt[:40]!r}")
            out.append((flags, width, prec, conv))
            i = j + 1
    except FormatError as exc:
        return out, str(exc)
    if lit:
        out.append("".join(lit))
    return out, None


def _pad(body: str, sign: str, flags: str, width: int | None, numeric: bool) -> str:
    s = sign + body
    if width is None or len(s) >= width:
        return s
    if "-" in flags:
        return s + " " * (width - len(s))
    if "0" in flags and numeric:
        return sign + "0" * (width - len(s)) + body
    return " " * (width - len(s)) + s


def format_one(spec, v) -> str:
    flags, width, prec, conv = spec
    if conv == "s":
        if isinstance(v, Arr):
            s = v.text()
        elif isinstance(v, str):
            s = v
        elif isinstance(v, bool):
            s = "TRUE" if v else "FALSE"
        elif isinstance(v, EnumValue):
            s = v.name
        else:
            s = str(v)
        if prec is not None:
            s = s[:prec]
        return _pad(s, "", flags, width, False)
    if conv == "c":
        if isinstance(v, str):
            s = v[:1]
        else:
            s = chr(trunc_int(v, "%c argument") & 0xFF)
        return _pad(s, "", flags, width, False)
    if isinstance(v, bool):
        v = 1 if v else 0
    x = num(v)
    if conv in "dixXo":
        x = x if x.__class__ is int else real_to_int(x)
        mag = abs(x)
        if conv in "di":
            body = str(mag)
        elif conv == "o":
            body = format(mag, "o")
        else:
            body = format(x & 0xFFFFFFFF if x < 0 else x, "x")
            if conv == "X":
                body = body.upper()
        if prec is not None and len(body) < prec:
            body = "0" * (prec - len(body)) + body
        sign = "-" if x < 0 and conv in "di" else ("+" if "+" in flags else (" " if " " in flags else ""))
        return _pad(body, sign, flags if prec is None else flags.replace("0", ""), width, True)
    x = float(x)
    p = 6 if prec is None else prec
    code = {"f": "f", "F": "f", "e": "e", "E": "E", "g": "g", "G": "G"}[conv]
    body = format(abs(x), f"{'#' if '#' in flags else ''}.{p}{code}")
    neg = x < 0 or (x == 0 and math.copysign(1, x) < 0 and body.strip("0.") != "")
    sign = "-" if neg else ("+" if "+" in flags else (" " if " " in flags else ""))
    return _pad(body, sign, flags, width, True)


def swrite_text(fmt: str, values: list, room: int, limit: int | None = None) -> tuple[str, int, str | None]:
    """(formatted text, number of converted values, format error or None): the text of
    ``fmt`` with ``values``, at most ``room`` characters (the rest of the destination;
    the values past it are still converted and counted); it stops at a bad specification
    (:func:`parse_format`; widths and precisions bounded by ``limit``, the destination's
    length, default ``room``)."""
    parts, error = parse_format(fmt, room if limit is None else limit)
    out = []
    size = 0
    k = 0
    for p in parts:
        if k >= len(values) and not isinstance(p, str):
            break
        if isinstance(p, str):
            piece = p
        else:
            if size >= room:        # converted but not shown: no width, no precision to build
                p = (p[0], None, None, p[3])
            piece = format_one(p, values[k])
            k += 1
        if size < room:
            out.append(piece[:room - size])
            size += len(out[-1])
    return "".join(out), k, error


def _state(ref, ok: bool, hits: int, length: int) -> None:
    if ref is None:
        return
    st = ref.peek()
    if isinstance(st, Struct):
        st.f["RET1"] = EnumValue("CMD_OK" if ok else "FMT_ERR")
        if "HITS" in st.f:
            st.f["HITS"] = hits
        if "LENGTH" in st.f:
            st.f["LENGTH"] = length
        if "MSG_NO" in st.f:
            st.f["MSG_NO"] = 0


def _format_error(state_ref, error: str) -> None:
    """A bad format with no STATE_T variable to report it in is a run-time error."""
    if state_ref is None or not isinstance(state_ref.peek(), Struct):
        raise KrlRuntimeError(error)


@FORMATTED.native("SWRITE(CHAR DEST[] :OUT, STATE_T STATE :OUT, INT OFFSET :OUT, CHAR FORMAT[] :IN, ...)", pure=True)
def _swrite(ctx, a):
    dest = char_array(a[0], "SWRITE destination")
    off_ref = a[2]
    off = int_arg(off_ref, "SWRITE offset") if off_ref is not None else 0
    fmt = ref_text(a[3], "SWRITE format")
    vals = [r.get() if r is not None else UNSET for r in a[4:]]
    if any(v is UNSET for v in vals):
        raise value_invalid("SWRITE argument")
    n = len(dest.data)
    cur = dest.text()
    off = min(max(off, 0), n)
    text, hits, error = swrite_text(fmt, vals, n - off, n)
    if error is not None:
        _format_error(a[1], error)
    base = (cur + "\0" * n)[:off].replace("\0", " ")
    new = (base + text)[:n]
    for i, ch in enumerate(new):
        dest.data[i] = ch
    for i in range(len(new), n):
        dest.data[i] = "\0"
    if off_ref is not None:
        off_ref.set(len(new))
    _state(a[1], error is None, hits, len(new) - off)


def _scan_int(text: str, base: int) -> int:
    """A scanned integer; more digits than any INT has is INT overflow (never a Python
    int of thousands of digits)."""
    digits = text.lstrip("+-").lstrip("0")
    if len(digits) > 40:
        raise KrlRuntimeError(f"INT overflow ({text[:12]}... outside -2147483648..2147483647)")
    return int(text, base)


def _scan_number(src: str, pos: int, lim: int, conv: str) -> tuple[Any, int] | None:
    """The number of conversion `conv` (d/i, x/X, o, else a REAL) read from src[pos:lim] (ASCII
    digits only): (value, position after it), or None where none stands there."""
    j = pos
    if conv in "di":
        if j < lim and src[j] in "+-":
            j += 1
        k = j
        while j < lim and src[j] in _DIGITS:
            j += 1
        if j == k:
            return None
        return _scan_int(src[pos:j], 10), j
    if conv in "xX":
        while j < lim and src[j] in "0123456789abcdefABCDEF":
            j += 1
        if j == pos:
            return None
        return _scan_int(src[pos:j], 16), j
    if conv == "o":
        while j < lim and src[j] in "01234567":
            j += 1
        if j == pos:
            return None
        return _scan_int(src[pos:j], 8), j
    if j < lim and src[j] in "+-":
        j += 1
    k = j
    while j < lim and (src[j] in _DIGITS or src[j] == "."):
        j += 1
    if j < lim and src[j] in "eE":
        m = j + 1
        if m < lim and src[m] in "+-":
            m += 1
        if m < lim and src[m] in _DIGITS:
            j = m
            while j < lim and src[j] in _DIGITS:
                j += 1
    if j == k:
        return None
    try:
        return float(src[pos:j]), j
    except ValueError:
        return None


def sread_values(src: str, fmt: str, start: int = 0, limit: int | None = None) -> tuple[list, int, str | None]:
    """scanf: (list of (spec, python value), position after the last match, format error
    or None). Widths are bounded by ``limit`` (the source buffer's length; default
    ``len(src)``); numbers are ASCII digits only."""
    parts, error = parse_format(fmt, len(src) if limit is None else limit)
    pos = start
    out = []
    n = len(src)
    for p in parts:
        if isinstance(p, str):
            for ch in p:
                if ch.isspace():
                    while pos < n and src[pos].isspace():
                        pos += 1
                elif pos < n and src[pos] == ch:
                    pos += 1
                else:
                    return out, pos, error
            continue
        flags, width, prec, conv = p
        if conv != "c":
            while pos < n and src[pos].isspace():
                pos += 1
        lim = n if width is None else min(n, pos + width)
        if conv == "c":
            if pos >= n:
                break
            out.append((p, src[pos]))
            pos += 1
            continue
        if conv == "s":
            j = pos
            while j < lim and not src[j].isspace():
                j += 1
            if j == pos:
                break
            out.append((p, src[pos:j]))
            pos = j
            continue
        got = _scan_number(src, pos, lim, conv)
        if got is None:
            break
        value, j = got
        out.append((p, value))
        pos = j
    return out, pos, error


@FORMATTED.native("SREAD(CHAR SRC[] :IN, STATE_T STATE :OUT, INT OFFSET :OUT, CHAR FORMAT[] :IN, ...)", pure=True)
def _sread(ctx, a):
    src = ref_text(a[0], "SREAD source")
    off_ref = a[2]
    off = int_arg(off_ref, "SREAD offset") if off_ref is not None else 0
    fmt = ref_text(a[3], "SREAD format")
    buf = a[0].peek()
    got, pos, error = sread_values(src, fmt, max(0, off), len(buf.data) if isinstance(buf, Arr) else len(src))
    if error is not None:
        _format_error(a[1], error)
    targets = a[4:]
    hits = 0
    for (spec, v), ref in zip(got, targets):
        if ref is None:
            continue
        if isinstance(ref.peek(), Arr):
            put_text(ref.peek(), str(v))
        else:
            ref.set(v)
        hits += 1
    if off_ref is not None:
        off_ref.set(pos)
    _state(a[1], error is None and hits == len([t for t in targets if t is not None]), hits, pos - off)


__all__ = ["FORMATTED", "parse_format", "sread_values", "swrite_text"]
