# The C types of robot/cartpath.py for its Cython build (robot/build.py ``PURE``; cartpath.py stays
# plain Python, the fallback without a compiler). libm's functions replace the names cartpath.py
# takes from `math` (the same C functions); numpy's BLAS is called through the addresses given, as
# the C function pointer types of robot/capi.pxd; the inverse is fastpath's OPWCore and the piece
# search robot/lawtable.py's, both called as C.
cimport cython
from libc.math cimport sin, cos, atan2, sqrt, copysign, INFINITY as inf, M_PI as pi
from robot.kinematics.fastpath cimport OPWCore
from robot cimport lawtable
from robot.capi cimport dgemm_t, ddot_t, capi_libm_pow

# the sha256 robot/build.py passes (its own name: lawtable.pxd, cimported here, declares pure_source_sha)
cdef extern from *:
    """
    #ifndef PURE_SOURCE_SHA
    #define PURE_SOURCE_SHA ""
    #endif
    static const char* cartpath_source_sha(void) { return PURE_SOURCE_SHA; }
    """
    const char* cartpath_source_sha() noexcept

cdef bint _COMPILED
cdef double DEG_TO_RAD, RAD_TO_DEG
cdef int _ROW, _NOTRANS, _TRANS, _PRE, _POST, _T, _F
cdef const double[:, ::1] _EYE3V


cdef class CartPath:
    cdef OPWCore opw
    cdef int n
    cdef object keep
    cdef readonly const double[::1] ub
    cdef readonly const int[::1] kinds
    cdef const int[::1] mid_ok
    cdef readonly const double[::1] length
    cdef const double[::1] r
    cdef const double[::1] angle
    cdef const double[:, ::1] a
    cdef const double[:, ::1] b
    cdef const double[:, ::1] c
    cdef const double[:, :, :, ::1] rots
    cdef dgemm_t gemm
    cdef int has_pre, has_post
    cdef double[:, ::1] frames      # (4, 16): pre ($BASE), post (INV_POS($TOOL)), the pose T, a product F
    cdef double[:, ::1] poses       # (4, 12): scratch poses (3x4)
    cdef double[::1] ref            # (6,): scratch reference
    cdef double[::1] v3             # (3,): scratch vector
    cdef double step
    cdef size_t tgemm               # use_turns: the slerps' cblas_dgemm (0: none)
    cdef object keep_turns
    cdef const double[:, ::1] rv    # (n, 3): each piece's rotation vector (rad)
    cdef const int[::1] turn_ok     # (n,): 1 where the slerp within the piece is computed here
    cdef double[:, :, ::1] turns    # (2, 3, 3): scratch

    cpdef use_turns(self, size_t gemm, const double[:, ::1] rv, const int[::1] turn_ok)

    @cython.locals(x=double, y=double, z=double, th=double, sn=double, cs=double, C=double, i=int, j=int,
                   t="double[:, :, ::1]")
    cpdef void _turned(self, int k, double f, double[:, ::1] M, int m) noexcept

    @cython.locals(n=int, k=int, i=int, j=int, w=int, kind=int, f=double, du=double, s=double, ph=double,
                   cs=double, sn=double)
    cdef int _pose(self, double u, double[:, ::1] M, int m) noexcept

    @cython.locals(M="double[:, ::1]", pv="double[::1]", Rv="double[:, ::1]", i=int, j=int)
    cpdef pose_u(self, double u)

    @cython.locals(opw=OPWCore, i=int, has_status=int, src=int)
    cdef int _solve(self, const double[:, ::1] M, int m, int st, const double[::1] ref, int r0, double[::1] out,
                    int o) except -1

    @cython.locals(ref="double[::1]", i=int)
    cdef object _axes(self, const double[:, ::1] M, int m, int st, const double[:] ref6)

    cpdef axes_u(self, double u, status, const double[:] ref6)

    @cython.locals(n=Py_ssize_t, j=Py_ssize_t, i=int, st=int, out="double[::1]", ref="double[::1]")
    cpdef chain_u(self, const double[:] us, status, const double[:] ref6)

    @cython.locals(N=int, step=double, h=double, Aax=double, i=int, B="double[:, ::1]", Q="double[::1]",
                   D1="double[::1]", D2="double[::1]", R="double[:, ::1]")
    cpdef walk(self, double u0, double u1, int nk, status, const double[:] start6, int chain_from, double budget,
               bint plain, const double[:] v_ax, const double[:] a_ax, double vmax_k, double max_jump,
               double step_deg, int max_samples)

    @cython.locals(M="double[:, ::1]", step=double, x=double, biggest=double, j=int, i=int)
    cdef int _chain_samples(self, double u0, double u1, int nk, int st, const double[:] start6, int chain_from,
                            double max_jump, double step_deg, int max_samples, double[::1] Q) except -2

    @cython.locals(M="double[:, ::1]", d="double[::1]", i=int)
    cpdef dist_to(self, double u, const double[:] end, size_t ddot)

    @cython.locals(M="double[:, ::1]", b="double[:, :, ::1]", i=int, j=int)
    cpdef superposed(self, CartPath prev, double u_prev, double u, double u_start, status, ref6, size_t gemm)

    cpdef use_frames(self, size_t gemm, pre, post)

    @cython.locals(fr="double[:, ::1]", i=int, src=int, dst=int)
    cdef int _flange(self, const double[:, ::1] M, int m) noexcept

    @cython.locals(fr="double[:, ::1]")
    cdef void _mul4(self, int a, int b, int out) noexcept

    @cython.locals(M="double[:, ::1]", i=int, j=int)
    cdef int _pose_rp(self, const double[:, :] R, const double[:] p) except -1

    @cython.locals(rv="double[:, ::1]", i=int, j=int, src=int)
    cpdef flange_rp(self, const double[:, :] R, const double[:] p)

    cpdef solve_rp(self, const double[:, :] R, const double[:] p, status, const double[:] ref6)


cdef int _st(status) except? -2

@cython.locals(g=dgemm_t)
cdef void _superpose(size_t gemm, double[:, :, ::1] b) noexcept

@cython.locals(b="double[:, :, ::1]", i=int, j=int)
@cython.locals(rots="double[:, :, :, ::1]", z1=object, M=object)
cpdef turn_products(size_t gemm, const double[:, ::1] R0, const double[::1] rv, double f)

cpdef superpose_products(size_t gemm, const double[:, ::1] A, const double[:, ::1] B, const double[:, ::1] C)

@cython.locals(r=int, i=int, c2h=double, a0=double, a1=double, a2=double, b0=double, b1=double, b2=double)
cdef void _gradient_rows(const double[::1] f, double[::1] out, int n, double h) noexcept

@cython.locals(i=int, j=int, bad=int, x=double)
cdef int _rate_maxima(const double[::1] D1, const double[::1] D2, int N, double[::1] d1a, double[::1] d1b,
                      double[::1] qd, double[::1] qdd) noexcept

@cython.locals(V=double, W=double, t=double, x=double, y=double, i=int)
cdef double _piece_speed(const double[::1] qd, const double[::1] qdd, const double[:] v_ax, const double[:] a_ax,
                         double budget, bint plain, double vmax_k) noexcept

cdef double _pow2(double x) noexcept

@cython.locals(Aax=double, vk2=double, x=double, i=int)
cdef double _piece_acc(const double[::1] qd, const double[::1] qdd, const double[:] a_ax, double budget,
                       double vmax_k) noexcept

@cython.locals(s=double)
cdef double _dot3(size_t ddot, const double[::1] v) noexcept

cdef void _tmul(size_t gemm, const double[:, ::1] A, const double[:, ::1] B, double[:, ::1] out) noexcept

cdef void _mul3(size_t gemm, const double[:, ::1] A, const double[:, ::1] B, double[:, ::1] out) noexcept

cpdef line_products(size_t gemm, size_t ddot, const double[:, ::1] A, const double[:, ::1] B, const double[::1] v)

@cython.locals(L=double, th=double, w=double, wt=double, W=double, u1=double, vprog=double, vmax=double,
               amax=double, Aax=double, nk=cython.longlong, cp=CartPath)
cpdef plan_line(OPWCore opw, size_t gemm, size_t ddot, const double[:, :] start_T, double x, double y,
                double z, double a, double b, double c, double v_cp, double v_ori, double a_cp,
                double a_ori, status, q0, int chain_from, bint plain, v_ax, a_ax, double max_jump, double step_deg,
                int max_samples, pre, post)

@cython.locals(r0="double[:, ::1]", r1="double[:, ::1]", pp0="double[::1]", pp1="double[::1]", ra=double,
               rb=double, rc=double, ca=double, sa=double, cb=double, sb=double, cc=double, sc=double, i=int, j=int)
cdef tuple _line_ends(const double[:, :] start_T, double x, double y, double z, double a, double b, double c)

@cython.locals(dv="double[::1]", m="double[:, ::1]", dr="double[::1]", rvv="double[::1]", L=double, s=double,
               th=double, k=double, w0=double, w1=double, w2=double, i=int)
cdef object _line_geometry(size_t gemm, size_t ddot, const double[:, ::1] R0, const double[:, ::1] R1,
                           const double[::1] p0, const double[::1] p1)

@cython.locals(lk=double, ok=double, v=double, v2=double, vprog=double, vc=double, acc=double, a2=double,
               q=double, nk=cython.longlong)
cdef tuple _line_limits(double L, double th, double w, double W, double v_cp, double v_ori, double a_cp,
                        double a_ori)

@cython.locals(rt="double[:, :, :, ::1]", dmv="double[:, ::1]", pmv="double[:, ::1]", ubv="double[::1]",
               lmv="double[::1]", i=int, j=int, cp=CartPath)
cdef CartPath _line_path(OPWCore opw, size_t gemm, pre, post, const double[::1] dirv, const double[::1] p0,
                         const double[:, ::1] R0, const double[:, ::1] still, const double[:, ::1] R1, double L,
                         double W, double u1)

@cython.locals(vk2=double, vv="double[::1]", av="double[::1]", i=int)
cdef tuple _line_peaks(const double[::1] qd, const double[::1] qdd, double vmax, double amax)
