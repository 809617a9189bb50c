# The C types of robot/steplimit.py for its Cython build (robot/build.py ``PURE``; steplimit.py
# stays plain Python, the fallback without a compiler).
cimport cython

cdef extern from *:
    """
    #ifndef PURE_SOURCE_SHA
    #define PURE_SOURCE_SHA ""
    #endif
    static const char* pure_source_sha(void) { return PURE_SOURCE_SHA; }
    """
    const char* pure_source_sha() noexcept

@cython.locals(n=Py_ssize_t, i=Py_ssize_t, a=cython.double, b=cython.double, m=cython.double)
cpdef bint speed_ok(list q, list q_prev, list lim) except -1
