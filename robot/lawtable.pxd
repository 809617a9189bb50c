# The C types of robot/lawtable.py for its Cython build (robot/build.py ``PURE``; lawtable.py stays
# plain Python, the fallback without a compiler). libm's sqrt replaces the name lawtable.py takes
# from `math` (the same C function); a table is a buffer of doubles (an array('d') or an ndarray).
# lawtable.py's first line: C's division (as robot/cartpath.py has it; its docstring), no negative indices.
cimport cython
from libc.math cimport sqrt, INFINITY as inf

cdef extern from *:
    """
    #ifndef PURE_SOURCE_SHA
    #define PURE_SOURCE_SHA ""
    #endif
    static const char* pure_source_sha(void) { return PURE_SOURCE_SHA; }
    """
    const char* pure_source_sha() noexcept

cdef int _FIELDS, _BRAKE, _RAMP

@cython.locals(r=double)
cpdef double trapezoid_u(double T, double ta, double a, double v, double t) noexcept

cpdef double trapezoid_du(double T, double ta, double a, double v, double t) noexcept

@cython.locals(u_acc=double)
cpdef double trapezoid_t_of_u(double T, double ta, double a, double v, double x) noexcept

@cython.locals(kind=double, d=double, r=double, den=double)
cpdef double t_of_u(const double[::1] tab, int i, double x) except? -1.0

@cython.locals(kind=double, r=double)
cpdef double du(const double[::1] tab, int i, double t) except? -1.0

@cython.locals(kind=double)
cpdef double t_total(const double[::1] tab, int i) except? -1.0

@cython.locals(kind=double, r=double, s=double)
cpdef double u(const double[::1] tab, int i, double t) except? -1.0

@cython.locals(va2=double, step=double, nb=Py_ssize_t, k=Py_ssize_t, x=double, vb=double, r=double, v=double)
cpdef bint below(int law, double p0, double p1, double p2, const double[::1] tab, object bounds, double u0,
                 double u1) except -1

@cython.locals(v=double)
cpdef double ramp_time(const double[::1] tab, double x) except? -1.0

@cython.locals(t_b=double, v_b=double)
cpdef double ramp_tau(const double[::1] tab, double u_e) except? -1.0

@cython.locals(t_b=double, v_b=double, tau=double)
cpdef double ramp_rate(const double[::1] tab, double u_e) except? -1.0

@cython.locals(u_e=double, delay=double, rt=double, lo=double, hi=double, mid=double, d=double, it=int)
cpdef tuple ramp_args(const double[::1] tab, object bounds, double u_max, double tau_p)

@cython.locals(m=Py_ssize_t, k=int, L=double, t_end=double, s=double, Lk=double, f=double, u_max=double,
               t2=double, u2=double, s_bounds=double[::1])
cpdef tuple blend_end_ramp(const double[::1] tab, object bounds, const double[::1] lengths,
                           const double[::1] u_bounds, double d_start, double u_a, double t_brake, double tau_p)

@cython.locals(lo=int, hi=int, mid=int)
cpdef int piece_of(const double[::1] bounds, int n, double x) except -1
