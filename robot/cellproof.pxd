# The C types of robot/cellproof.py for its Cython build (robot/build.py ``PURE``; cellproof.py stays
# plain Python, the fallback without a compiler). libm's sqrt replaces the name cellproof.py takes from
# `math` (the same C function); numpy's arrays as typed memoryviews.
cimport cython
from libc.math cimport sqrt

cdef extern from *:
    """
    #ifndef PURE_SOURCE_SHA
    #define PURE_SOURCE_SHA ""
    #endif
    static const char* pure_source_sha(void) { return PURE_SOURCE_SHA; }
    """
    const char* pure_source_sha() noexcept

cdef double POINT_M2, INF
cdef Py_ssize_t WINDOW

cdef double _clamp(double x) noexcept

@cython.locals(rx=double, ry=double, rz=double, a=double, e=double, f=double, s=double, t=double, c=double,
               b=double, denom=double, dx=double, dy=double, dz=double)
cpdef double segment_distance(double px, double py, double pz, double ux, double uy, double uz,
                              double qx, double qy, double qz, double vx, double vy, double vz) noexcept

@cython.locals(best=Py_ssize_t, depth=double, k=Py_ssize_t)
cpdef Py_ssize_t deepest(const double[::1] gaps, const unsigned char[::1] exact, Py_ssize_t start, Py_ssize_t stop,
                         double beyond) noexcept

@cython.locals(low=double, k=Py_ssize_t)
cpdef double least(const double[::1] values) noexcept

@cython.locals(c=Py_ssize_t, acc=double)
cdef double _moved(const double[:, ::1] levers, const double[::1] top, Py_ssize_t g, Py_ssize_t lo,
                   Py_ssize_t hi) noexcept


cdef class Prover:
    cdef const Py_ssize_t[::1] near, far, hflat, hjoint, hgeom, slide, lo, hi
    cdef const double[::1] half, reach
    cdef double slack
    cdef double[::1] top, moved
    cdef Py_ssize_t[::1] over

    @cython.locals(k=Py_ssize_t, g=Py_ssize_t, h=Py_ssize_t, i=Py_ssize_t, j=Py_ssize_t, hg=double, hh=double,
                   best=double, e=Py_ssize_t, hz=double, vx=double, vy=double, vz=double, along=double, r2=double,
                   near="const Py_ssize_t[::1]", far="const Py_ssize_t[::1]", half="const double[::1]")
    cpdef void measure(self, const double[:, ::1] xpos, const double[:, ::1] xmat, const double[:, ::1] anchor,
                       const double[:, ::1] axis, double[::1] gaps, double[::1] levers) noexcept

    @cython.locals(n=Py_ssize_t, r=Py_ssize_t, width=Py_ssize_t, stop=Py_ssize_t, i=Py_ssize_t, c=Py_ssize_t,
                   d=double, m=Py_ssize_t, k=Py_ssize_t, j=Py_ssize_t, g=Py_ssize_t, every=bint,
                   near="const Py_ssize_t[::1]", far="const Py_ssize_t[::1]", top="double[::1]",
                   moved="double[::1]", over="Py_ssize_t[::1]")
    cpdef Py_ssize_t first_unproved(self, const double[:, ::1] levers, const double[::1] pose,
                                    const double[:, ::1] poses, Py_ssize_t start, const double[::1] limits) noexcept
