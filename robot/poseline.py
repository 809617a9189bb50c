# cython: cdivision=True
"""The trace's pose line (robot/trace.py ``TraceWriter.flush``), written once in Python and compiled
by Cython from this very file (the C types in poseline.pxd beside it; robot/build.py ``PURE``):
without a compiler it runs as it stands (robot/kinematics/compiled.py ``pure_module`` picks the one
in use). Issue 76 item 5: this was a hand mirror in C (robot/simcore.pyx ``pose_line``) of
trace.py's own formatting; it is now the one formatter both use.

:func:`pose_line`: the JSON line of a pose event, ``{"t":T,"kind":"pose","axes":[...],"tcp":[...]}``,
each number written as ``repr`` of its value rounded to 6 decimals with -0.0 as 0.0 (robot/trace.py
``_round6``: the bytes ``json.dumps`` writes for that event, without its generic encoder), or None
when a number is not finite or its magnitude is 1e15 or more, or a list is longer than 32 (the
caller writes those through ``json.dumps``).

Each number (:func:`_put_r6`) takes a fast path where it can: the correctly rounded integer
n = round(x * 10^6) is that of the computed product whenever the product is farther from a
half-integer than its rounding error; the rounded double is then n / 10^6 (a correctly rounded
quotient of exact integers: the double nearest to the decimal n * 10^-6, as strtod gives, which
is CPython's ``round(x, 6)``: Objects/floatobject.c double_round, dtoa mode 3 then strtod), and its
repr is that decimal with the trailing zeros cut (fewer than 16 significant digits round-trip
uniquely; repr writes fixed notation from 1e-4 on). Anything else (near a tie, below 1e-4 in
magnitude, 1e8 or more) is Python's ``repr(round(x, 6))`` itself. The fast path's operations are
IEEE doubles' and exact integers' (below 2^53), the same compiled and as Python (its first line:
C's integer division, the same as Python's for the non-negative integers it divides).
"""

from math import *  # noqa: F403  (fabs, floor, isfinite: libm's compiled, poseline.pxd declares them as C's)

try:
    import cython
    COMPILED = cython.compiled
except ImportError:     # an install without Cython (a need of the build only): this file as Python
    COMPILED = False

#: the magnitude from which :func:`pose_line` leaves a line to the caller (its fixed text would be long)
_BIG = 1e15
#: the most numbers a list of :func:`pose_line` holds (its buffer's size)
_MAX_VALUES = 32


def built_from() -> str:
    """The sha256 of poseline.py and poseline.pxd the compiled module was built from
    (robot/build.py embeds it); "" as Python."""
    if COMPILED:
        return pure_source_sha().decode("ascii")  # noqa: F821  (poseline.pxd's C constant)
    return ""


def _put(text, out, k):
    """The ASCII bytes `text` into `out` from index k; the index after them."""
    for i in range(len(text)):
        out[k + i] = text[i]
    return k + len(text)


def _put_int(v, width, out, k):
    """The decimal digits of the integer v >= 0 into `out` from index k, `width` of them (leading
    zeros kept; 0: as many as v has); the index after them."""
    if width == 0:
        rest = v
        width = 1
        while rest >= 10:
            rest //= 10
            width += 1
    for j in range(width):
        out[k + width - 1 - j] = 48 + v % 10
        v //= 10
    return k + width


def _put_r6(x, out, k):
    """``repr`` of x rounded to 6 decimals (-0.0 as 0.0) into `out` from index k (module
    docstring); the index after it."""
    y = x * 1e6
    if fabs(y) < 1e14:  # noqa: F405
        fl = floor(y)  # noqa: F405
        fr = y - fl
        if fabs(fr - 0.5) > fabs(y) * 1e-15 + 1e-12:  # noqa: F405
            n = int(fl)
            if fr > 0.5:
                n += 1
            if n == 0:
                return _put(b"0.0", out, k)
            if n >= 100 or n <= -100:
                if n < 0:
                    out[k] = 45                         # '-'
                    k += 1
                    n = -n
                fp = n % 1000000
                k = _put_int(n // 1000000, 0, out, k)
                out[k] = 46                             # '.'
                k += 1
                if fp == 0:
                    out[k] = 48                         # '0'
                    return k + 1
                width = 6
                while fp % 10 == 0:
                    fp //= 10
                    width -= 1
                return _put_int(fp, width, out, k)
    r = round(x, 6)
    return _put(repr(0.0 if r == 0.0 else r).encode("ascii"), out, k)


def _plain(x):
    """True when x is finite and below 1e15 in magnitude (:func:`pose_line` writes it)."""
    return isfinite(x) and -_BIG < x < _BIG  # noqa: F405


def pose_line(t, axes, tcp):
    """The JSON line of a pose event (module docstring): time t (s), the axes (deg or mm) and the
    TCP frame (X, Y, Z mm, A, B, C deg), sequences of numbers; None where the caller writes it."""
    t = float(t)
    ax = [float(v) for v in axes]
    tc = [float(v) for v in tcp]
    if len(ax) > _MAX_VALUES or len(tc) > _MAX_VALUES or not _plain(t):
        return None
    for x in ax:
        if not _plain(x):
            return None
    for x in tc:
        if not _plain(x):
            return None
    buf = bytearray(32 * (2 * _MAX_VALUES + 2))    # a number's text: at most 25 bytes and its comma
    out = buf
    k = _put(b'{"t":', out, 0)
    k = _put_r6(t, out, k)
    k = _put(b',"kind":"pose","axes":[', out, k)
    for i in range(len(ax)):
        if i:
            out[k] = 44                                 # ','
            k += 1
        k = _put_r6(ax[i], out, k)
    k = _put(b'],"tcp":[', out, k)
    for i in range(len(tc)):
        if i:
            out[k] = 44
            k += 1
        k = _put_r6(tc[i], out, k)
    k = _put(b"]}", out, k)
    return out[:k].decode("ascii")
