# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False, auto_pickle=False
"""The trace's pose line in C (issue 39, "Simulator"; issue 76 item 5), one of robot/simcore's
modules (robot/build.py ``SIMCORE``): :func:`pose_line`, the bytes robot/trace.py
``TraceWriter.flush`` writes for a pose event (``repr`` of each number rounded by ``_round6``),
without Python's float objects. robot/trace.py's own formatting stays the fallback and the
reference (tests/robot/test_simcore.py compares the two). ``SOURCE_SHA``: the sha256 of the
sources it was built from (robot/build.py ``simcore_sha``).
"""

from libc.math cimport fabs, isfinite, floor
from libc.string cimport memcpy, strlen

from robot.simcore.capi cimport SIMCORE_SOURCE_SHA

#: The sha256 of the sources this module was compiled from (robot/build.py ``simcore_sha``)
SOURCE_SHA = SIMCORE_SOURCE_SHA.decode("ascii")

cdef extern from "Python.h":
    char* PyOS_double_to_string(double val, char format_code, int precision, int flags,
                                int* ptype) except NULL
    double PyOS_string_to_double(const char* s, char** endptr, object overflow_exception) except? -1.0
    void PyMem_Free(void* p)
    int Py_DTSF_ADD_DOT_0

#: |x| from which pose_line leaves a number to the Python path (its 'f' text would be long)
cdef double _BIG = 1e15


cdef Py_ssize_t _put_r6(double x, char* out) except -1:
    """``repr(robot.trace._round6(x))`` into out (see :func:`_put_r6_dtoa`). Fast path: the
    correctly rounded integer n = round(x · 10^6) is that of the computed product whenever the
    product is farther from a half-integer than its rounding error; the rounded double is then
    n / 10^6 (a correctly rounded quotient of exact integers: the double nearest to the decimal
    n · 10^-6, as strtod gives), and its repr is that decimal with the trailing zeros cut
    (fewer than 16 significant digits round-trip uniquely; repr writes fixed notation from
    1e-4 on). Anything else (near a tie, below 1e-4, huge) takes the dtoa path."""
    cdef double y = x * 1e6
    cdef double fl, fr, d
    cdef long long n, a, ip, fp
    cdef Py_ssize_t k = 0, m, j
    cdef char digits[24]
    if fabs(y) < 1e14:
        fl = floor(y)
        fr = y - fl
        d = fabs(fr - 0.5)
        if d > fabs(y) * 1e-15 + 1e-12:
            n = <long long>fl + (1 if fr > 0.5 else 0)
            if n == 0:
                memcpy(out, b"0.0", 3)
                return 3
            if n >= 100 or n <= -100:
                if n < 0:
                    out[k] = b'-'
                    k += 1
                    a = -n
                else:
                    a = n
                ip = a // 1000000
                fp = a % 1000000
                m = 0
                while True:
                    digits[m] = <char>(48 + ip % 10)
                    m += 1
                    ip //= 10
                    if ip == 0:
                        break
                for j in range(m):
                    out[k] = digits[m - 1 - j]
                    k += 1
                out[k] = b'.'
                k += 1
                if fp == 0:
                    out[k] = b'0'
                    return k + 1
                m = 6
                while fp % 10 == 0:
                    fp //= 10
                    m -= 1
                for j in range(m):
                    digits[m - 1 - j] = <char>(48 + fp % 10)
                    fp //= 10
                for j in range(m):
                    out[k] = digits[j]
                    k += 1
                return k
    return _put_r6_dtoa(x, out)


cdef Py_ssize_t _put_r6_dtoa(double x, char* out) except -1:
    """``repr(robot.trace._round6(x))`` into out: CPython's round(x, 6) is the double nearest
    to x's correctly rounded 6-decimal text (Objects/floatobject.c double_round: _Py_dg_dtoa
    mode 3, then strtod), which is what ``'%.6f'`` formatting (the same dtoa call) read back
    gives; -0.0 becomes 0.0; ``repr`` is the shortest text (format 'r', '.0' added)."""
    cdef char* s = PyOS_double_to_string(x, b'f', 6, 0, NULL)
    cdef double r
    try:
        r = PyOS_string_to_double(s, NULL, None)
    finally:
        PyMem_Free(s)
    if r == 0.0:
        r = 0.0
    s = PyOS_double_to_string(r, b'r', 0, Py_DTSF_ADD_DOT_0, NULL)
    cdef Py_ssize_t n = strlen(s)
    memcpy(out, s, n)
    PyMem_Free(s)
    return n


cdef inline Py_ssize_t _put(const char* s, char* out) noexcept:
    cdef Py_ssize_t n = strlen(s)
    memcpy(out, s, n)
    return n


def pose_line(double t, axes, tcp):
    """The JSON line of a pose event (robot/trace.py ``TraceWriter.flush``): time t (s), the
    axes and the TCP frame (sequences of numbers) each rounded by ``_round6``, written as
    ``repr``; None when a number is not finite or very large (the Python path writes it)."""
    cdef char buf[2048]
    cdef Py_ssize_t n = 0, i, k
    cdef double x
    cdef list ax = [float(v) for v in axes]
    cdef list tc = [float(v) for v in tcp]
    if len(ax) > 32 or len(tc) > 32:
        return None
    if not isfinite(t) or t >= _BIG or t <= -_BIG:
        return None
    for seq in (ax, tc):
        for v in seq:
            x = v
            if not isfinite(x) or x >= _BIG or x <= -_BIG:
                return None
    n += _put(b'{"t":', buf + n)
    n += _put_r6(t, buf + n)
    n += _put(b',"kind":"pose","axes":[', buf + n)
    for k in range(2):
        seq = ax if k == 0 else tc
        if k == 1:
            n += _put(b'],"tcp":[', buf + n)
        for i in range(len(seq)):
            if i:
                buf[n] = b','
                n += 1
            n += _put_r6(seq[i], buf + n)
    n += _put(b']}', buf + n)
    return buf[:n].decode('ascii')
