# The C types of robot/poseline.py for its Cython build (robot/build.py ``PURE``; poseline.py stays
# plain Python, the fallback without a compiler). libm's functions replace the names poseline.py
# takes from `math` (the same C functions); the line is written into a byte buffer (a bytearray's
# memory, a pointer compiled) by index.
cimport cython
from libc.math cimport fabs, floor, isfinite

cdef extern from *:
    """
    #ifndef PURE_SOURCE_SHA
    #define PURE_SOURCE_SHA ""
    #endif
    static const char* pure_source_sha(void) { return PURE_SOURCE_SHA; }
    """
    const char* pure_source_sha() noexcept

cdef double _BIG
cdef Py_ssize_t _MAX_VALUES

@cython.locals(i=Py_ssize_t)
cdef Py_ssize_t _put(bytes text, unsigned char* out, Py_ssize_t k) except -1

@cython.locals(rest=cython.longlong, j=Py_ssize_t)
cdef Py_ssize_t _put_int(long long v, Py_ssize_t width, unsigned char* out, Py_ssize_t k) except -1

@cython.locals(y=double, fl=double, fr=double, n=cython.longlong, fp=cython.longlong, width=Py_ssize_t,
               r=double)
cdef Py_ssize_t _put_r6(double x, unsigned char* out, Py_ssize_t k) except -1

cdef bint _plain(double x) noexcept

@cython.locals(ax=list, tc=list, x=double, i=Py_ssize_t, k=Py_ssize_t, buf=bytearray, out=cython.p_uchar)
cpdef object pose_line(double t, object axes, object tcp)
