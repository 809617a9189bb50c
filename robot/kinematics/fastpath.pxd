# The C types of robot/kinematics/fastpath.py for its Cython build (robot/build.py; a .pxd beside a
# pure-Python module: fastpath.py itself stays plain Python, the fallback without a compiler).
# libm's functions replace the names fastpath.py takes from `math` (the same C functions); the
# registers (M, ref, rows, q, ...) are C arrays; the methods the hot path calls are C methods
# (cpdef: Python calls them too).
import cython
from libc.math cimport sin, cos, atan2, acos, sqrt, fmod, copysign, fabs, INFINITY as inf

cdef double PI, DEG_TO_RAD, RAD_TO_DEG, BOUNDARY_EPS, WRIST_SINGULAR_DEG, OVERHEAD_SINGULAR_MM, ACOS_TOL
cdef int MAX_ROWS, MAX_AXES

@cython.locals(mod=cython.double)
cdef double _pymod(double vx, double wx) noexcept

@cython.locals(x=cython.double)
cdef double _wrapdeg(double th, double off, double sg) noexcept


cdef class Chooser:
    cdef public int n
    cdef public int t_free
    cdef double lo[8]
    cdef double hi[8]
    cdef int lin[8]
    cdef double ks[5]
    cdef double ref[8]
    cdef double rows[512]
    cdef double q[8]
    cdef double cand[8]

    @cython.locals(n=cython.int, have_best=cython.int, best_cost=cython.double, j=cython.int,
                   base=cython.int, ok=cython.int, i=cython.int, found=cython.int, best_c=cython.double,
                   best_d=cython.double, kk=cython.int, c=cython.double, d=cython.double, cost=cython.double)
    cpdef int pick(self, int nrows, int use_turn, int tmask)

    @cython.locals(nrows=cython.Py_ssize_t, n=cython.int, i=cython.int, j=cython.int, tmask=cython.int,
                   use_turn=cython.int)
    cpdef object choose(self, list rows, object ref, object turn)

    @cython.locals(n=cython.int, tmask=cython.int, use_turn=cython.int, have=cython.int, best_cost=cython.double,
                   best_i=cython.int, best_v=cython.double, j=cython.int, base=cython.int, first_bad=cython.int,
                   i=cython.int, pick_c=cython.double, pick_d=cython.double, over_c=cython.double,
                   over_d=cython.double, inlim_any=cython.int, kk=cython.int, c=cython.double, ok=cython.int,
                   d=cython.double, o=cython.double, cost=cython.double)
    cpdef object limit_error(self, int nrows, object turn, list lo0, list hi0)


cdef class OPWCore(Chooser):
    cdef public double a1, a2, b, c1, c2, c3, c4, kappa_2, c2_2, k, at23, phi
    cdef public int s_free
    cdef double sgn[6]
    cdef double offs[6]
    cdef double M[12]
    cdef double sol[48]
    cdef double arm[12]
    cdef public int s_out, amb_out
    cdef public int n_rows, n_match
    cdef object src

    cpdef void use_rows(self, src)

    cpdef int core(self, int has_ref)

    @cython.locals(narm=cython.int, j=cython.int)
    cpdef int arm_rows(self, int has_ref)

    @cython.locals(r02=cython.double, px=cython.double, r12=cython.double, py=cython.double,
                   r22=cython.double, pz=cython.double,
                   cx=cython.double, cy=cython.double, cz=cython.double, rho2=cython.double,
                   nx1=cython.double, tmp1=cython.double, tmp2=cython.double, th1_i=cython.double,
                   th1_ii=cython.double, tmp3=cython.double, s1_2=cython.double, tmp4=cython.double,
                   s2_2=cython.double, s1=cython.double, s2=cython.double, narm=cython.int, j=cython.int,
                   th1=cython.double, s_=cython.double, s_2=cython.double, base2=cython.double,
                   arg2=cython.double, arg3=cython.double, v=cython.double, a2c=cython.double,
                   a3c=cython.double)
    cdef int _arms(self, int has_ref)

    @cython.locals(r00=cython.double, r01=cython.double, r02=cython.double,
                   r10=cython.double, r11=cython.double, r12=cython.double,
                   r20=cython.double, r21=cython.double, r22=cython.double, j=cython.int,
                   v=cython.double, n=cython.int, th1=cython.double, th2=cython.double, th3=cython.double,
                   sn1=cython.double, cs1=cython.double, s23=cython.double, c23=cython.double, mm=cython.double,
                   th4=cython.double, th5=cython.double, th6=cython.double, total=cython.double, b=cython.int)
    cdef int _wrists(self, int narm, int has_ref)

    @cython.locals(t2=cython.double, t23=cython.double, xw=cython.double, phi=cython.double, s=cython.int,
                   amb=cython.int)
    cpdef void status(self, double q0, double q1, double q2, double q3, double q4, double q5)

    @cython.locals(n=cython.int, s_target=cython.int, free=cython.int, keep=cython.int, nmatch=cython.int,
                   j=cython.int, b=cython.int, i=cython.int)
    cpdef int solve(self, int has_status, int status, int use_turn, int tmask)

    @cython.locals(i=cython.int, j=cython.int, has_ref=cython.int, n=cython.int)
    cpdef list rows_of(self, const double[:, :] T, const double[:] ref)

    @cython.locals(i=cython.int, j=cython.int)
    cpdef object inverse(self, const double[:, :] T, object status, object turn, const double[:] ref)

    @cython.locals(i=cython.int, j=cython.int)
    cpdef object inverse_rp(self, const double[:, :] R, const double[:] p, object status, object turn,
                            const double[:] ref)

    @cython.locals(i=cython.int, tmask=cython.int, use_turn=cython.int, out=cython.double[::1])
    cdef object _inverse(self, object status, object turn, const double[:] ref)

    @cython.locals(n=cython.Py_ssize_t, j=cython.Py_ssize_t, i=cython.int, k=cython.int, tmask=cython.int,
                   use_turn=cython.int, out=cython.double[:, ::1])
    cpdef object inverse_chain_rp(self, const double[:, :, :] R, const double[:, :] p, object status,
                                  object turn, const double[:] ref)
