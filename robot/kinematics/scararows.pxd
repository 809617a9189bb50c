# The C types of robot/kinematics/scararows.py for its Cython build (robot/build.py ``PURE``;
# scararows.py stays plain Python, the fallback without a compiler). libm's functions replace the
# names scararows.py takes from `math` (the same C functions); the registers are C arrays.
cimport cython
from libc.math cimport sin, cos, atan2, acos, sqrt, fmod, fabs

cdef extern from *:
    """
    #ifndef PURE_SOURCE_SHA
    #define PURE_SOURCE_SHA ""
    #endif
    static const char* pure_source_sha(void) { return PURE_SOURCE_SHA; }
    """
    const char* pure_source_sha() noexcept

cdef double PI, DEG_TO_RAD, RAD_TO_DEG, ACOS_TOL, OVERHEAD_SINGULAR_MM, STRETCHED

@cython.locals(x=double, mod=double)
cdef double _wrap(double v) noexcept

@cython.final
cdef class ScaraRows:
    cdef double o0[3]
    cdef double a[3]
    cdef double b[3]
    cdef double f[3]
    cdef double rf[9]
    cdef double s[4]
    cdef double l1, l2, alpha, beta

    @cython.locals(acc=double)
    cdef double _m(self, const double[:, :] T, int i, int j) noexcept

    @cython.locals(theta=double, c=double, s=double, w0=double, w1=double, w2=double, a3=double, l1=double,
                   l2=double, r2=double, cd=double, delta=double, n=int, k=int, dl=double, phi1=double,
                   th1=double, th2=double, th4=double, out=list)
    cpdef list rows(self, const double[:, :] T, ref)
