"""KRL's string functions (reference 4.6): STRLEN, STRDECLLEN, STRCLEAR, STRADD, STRCOPY,
STRCOMP, STRFIND and the StrTo* conversions.

A CHAR array is written in place, cut to its declared length, the rest NUL. StrToInt and
StrToReal accept KRL's literal syntax only (reference 1.5: :func:`_to_int`, :func:`_to_real`);
StrToFrame ... StrToE6Axis an aggregate ``{X 1.0, Y 2.0, ...}`` with numbers. A text that does
not convert leaves the :OUT variable as it was and returns FALSE.
"""

from __future__ import annotations

import math
import re

from ..convert import INT_MAX, INT_MIN, ref_text
from ..errors import KrlRuntimeError
from ..sysvars import sys_type
from ..values import UNSET, Arr, Struct
from .args import case_sensitive, char_array, int_arg, put_text
from .registry import Family

STRINGS = Family("strings")


@STRINGS.native("INT STRLEN(CHAR STRVAR[] :IN)", pure=True)
def _strlen(ctx, a):
    return len(ref_text(a[0], "STRLEN argument"))


@STRINGS.native("INT STRDECLLEN(CHAR STRVAR[] :OUT)", pure=True)
def _strdecllen(ctx, a):
    v = a[0].peek() if a[0] is not None else UNSET
    if isinstance(v, Arr):
        return len(v.data)
    if isinstance(v, str):
        return len(v)
    raise KrlRuntimeError("STRDECLLEN needs a CHAR array")


@STRINGS.native("BOOL STRCLEAR(CHAR STRVAR[] :OUT)", pure=True)
def _strclear(ctx, a):
    put_text(char_array(a[0], "STRCLEAR argument"), "")
    return True


@STRINGS.native("INT STRADD(CHAR STRDEST[] :OUT, CHAR STRTOADD[] :IN)", pure=True)
def _stradd(ctx, a):
    dest = char_array(a[0], "STRADD destination")
    return put_text(dest, dest.text() + ref_text(a[1], "STRADD argument"))


@STRINGS.native("BOOL STRCOPY(CHAR STRDEST[] :OUT, CHAR STRSOURCE[] :IN)", pure=True)
def _strcopy(ctx, a):
    dest = char_array(a[0], "STRCOPY destination")
    src = ref_text(a[1], "STRCOPY source")
    put_text(dest, src)
    return len(src) <= len(dest.data)


@STRINGS.native("BOOL STRCOMP(CHAR S1[] :IN, CHAR S2[] :IN, CASE_SENSE_T MODE :IN)", pure=True)
def _strcomp(ctx, a):
    s1, s2 = ref_text(a[0], "STRCOMP argument 1"), ref_text(a[1], "STRCOMP argument 2")
    if not case_sensitive(a[2] if len(a) > 2 else None):
        return s1.upper() == s2.upper()
    return s1 == s2


@STRINGS.native("INT STRFIND(INT STARTAT :IN, CHAR STRVAR[] :IN, CHAR STRFIND[] :IN, CASE_SENSE_T MODE :IN)", pure=True)
def _strfind(ctx, a):
    start = int_arg(a[0])
    s, sub = ref_text(a[1], "STRFIND string"), ref_text(a[2], "STRFIND pattern")
    if not case_sensitive(a[3] if len(a) > 3 else None):
        s, sub = s.upper(), sub.upper()
    if start < 1:
        start = 1
    pos = s.find(sub, start - 1)
    return pos + 1 if pos >= 0 and sub else 0


def _strto(conv):
    def fn(ctx, a):
        s = ref_text(a[0], "string")
        try:
            v = conv(s)
        except (ValueError, KrlRuntimeError):
            return False
        a[1].set(v)
        return True
    return fn


# The number syntax of StrToInt/StrToReal is KRL's literal syntax (reference §1.5,
# grammar/KRL.g4 INTLITERAL, HEXLITERAL, BINLITERAL, REALLITERAL) with the sign a data-list
# initial value may carry: ASCII digits only, no blanks, no '_', no 'nan'/'inf', no '0x'.
_INT_SYNTAX = re.compile(r"[+-]?[0-9]+")
_HEX_SYNTAX = re.compile(r"'[Hh]([0-9A-Fa-f]+)'")
_BIN_SYNTAX = re.compile(r"'[Bb]([01]+)'")
_REAL_SYNTAX = re.compile(r"[+-]?(?:[0-9]+\.[0-9]*(?:[Ee][+-]?[0-9]+)?|\.[0-9]+(?:[Ee][+-]?[0-9]+)?"
                          r"|[0-9]+(?:[Ee][+-]?[0-9]+)?)")


def _to_int(s: str) -> int:
    """A KRL INT literal (decimal with an optional sign, 'H..' or 'B..') in -2^31..2^31-1;
    raises ValueError otherwise."""
    if _INT_SYNTAX.fullmatch(s):
        if len(s.lstrip("+-").lstrip("0")) > 10:
            raise ValueError(s)
        v = int(s, 10)
    elif m := _HEX_SYNTAX.fullmatch(s):
        if len(m.group(1).lstrip("0")) > 8:
            raise ValueError(s)
        v = int(m.group(1), 16)
    elif m := _BIN_SYNTAX.fullmatch(s):
        if len(m.group(1).lstrip("0")) > 32:
            raise ValueError(s)
        v = int(m.group(1), 2)
    else:
        raise ValueError(s)
    if not INT_MIN <= v <= INT_MAX:
        raise ValueError(s)
    return v


def _to_real(s: str) -> float:
    """A KRL REAL or decimal INT literal with an optional sign; raises ValueError
    otherwise or when it is too large for any float (1E999)."""
    if not _REAL_SYNTAX.fullmatch(s):
        raise ValueError(s)
    v = float(s)
    if not math.isfinite(v):
        raise ValueError(s)
    return v


def _to_bool(s: str) -> bool:
    u = s.strip().upper()
    if u in ("TRUE", "1"):
        return True
    if u in ("FALSE", "0"):
        return False
    raise ValueError(s)


@STRINGS.native("BOOL STRTOSTRING(CHAR S[] :IN, CHAR RETVAL[] :OUT)", pure=True)
def _strtostring(ctx, a):
    dest = char_array(a[1], "STRTOSTRING destination")
    put_text(dest, ref_text(a[0], "string"))
    return True


def _strto_struct(tname):
    def fn(ctx, a):
        text = ref_text(a[0], "string").strip()
        if not (text.startswith("{") and text.endswith("}")):
            return False
        body = text[1:-1]
        if ":" in body.split(",")[0]:
            body = body.split(":", 1)[1]
        vals = {}
        for part in body.split(","):
            w = part.split()
            if len(w) != 2:
                return False
            try:
                vals[w[0].upper()] = _to_real(w[1]) if w[0].upper() not in ("S", "T") else _to_int(w[1])
            except ValueError:
                return False
        s = Struct(sys_type(tname), vals)
        a[1].set(s)
        return True
    return fn


STRINGS.add("BOOL STRTOINT(CHAR S[] :IN, INT RETVAL :OUT)", _strto(_to_int), pure=True)
STRINGS.add("BOOL STRTOREAL(CHAR S[] :IN, REAL RETVAL :OUT)", _strto(_to_real), pure=True)
STRINGS.add("BOOL STRTOBOOL(CHAR S[] :IN, BOOL RETVAL :OUT)", _strto(_to_bool), pure=True)
STRINGS.add("BOOL STRTOFRAME(CHAR S[] :IN, FRAME RETVAL :OUT)", _strto_struct("FRAME"), pure=True)
STRINGS.add("BOOL STRTOPOS(CHAR S[] :IN, POS RETVAL :OUT)", _strto_struct("POS"), pure=True)
STRINGS.add("BOOL STRTOE3POS(CHAR S[] :IN, E3POS RETVAL :OUT)", _strto_struct("E3POS"), pure=True)
STRINGS.add("BOOL STRTOE6POS(CHAR S[] :IN, E6POS RETVAL :OUT)", _strto_struct("E6POS"), pure=True)
STRINGS.add("BOOL STRTOAXIS(CHAR S[] :IN, AXIS RETVAL :OUT)", _strto_struct("AXIS"), pure=True)
STRINGS.add("BOOL STRTOE3AXIS(CHAR S[] :IN, E3AXIS RETVAL :OUT)", _strto_struct("E3AXIS"), pure=True)
STRINGS.add("BOOL STRTOE6AXIS(CHAR S[] :IN, E6AXIS RETVAL :OUT)", _strto_struct("E6AXIS"), pure=True)
