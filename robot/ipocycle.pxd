# The C types of robot/ipocycle.py for its Cython build (robot/build.py ``PURE``; ipocycle.py stays
# plain Python, the fallback without a compiler). libm's functions replace the names ipocycle.py
# takes from `math` (the same C functions); numpy's BLAS and MuJoCo's mj_kinematics are called
# through the addresses given, as the C function pointer types of robot/capi.pxd.
cimport cython
from libc.math cimport sin, cos, sqrt, M_PI as pi
from robot.capi cimport dgemm_t, dgemv_t, mj_kinematics_t

cdef extern from *:
    """
    #ifndef PURE_SOURCE_SHA
    #define PURE_SOURCE_SHA ""
    #endif
    static const char* pure_source_sha(void) { return PURE_SOURCE_SHA; }
    """
    const char* pure_source_sha() noexcept

cdef bint _COMPILED
cdef double DEG_TO_RAD, RAD_TO_DEG
cdef int _ROW, _NOTRANS, _COL, _TRANS, _R, _R2, _RJ


cdef class Forward:
    cdef dgemm_t gemm
    cdef dgemv_t gemv
    cdef int n, yv
    cdef const double[:, ::1] orig
    cdef const double[:, ::1] axis
    cdef const double[::1] sign
    cdef const double[:, ::1] rorig
    cdef bint origin_rot
    cdef const double[:, ::1] rfl
    cdef const double[:, ::1] pfl
    cdef double[:, ::1] buf        # (yv + 1, 3): R, R', Rj (n), the product's vector
    cdef int[::1] lin
    cdef double[::1] qa            # tcp_points' axes (n,) and frames (4, 4, 4)
    cdef double[:, :, ::1] fr

    @cython.locals(m=Py_ssize_t, k=Py_ssize_t, i=int, f=int, u=double, qa="double[::1]", fr="double[:, :, ::1]")
    cpdef tcp_points(self, const double[:] q0, const double[:] dq, const double[:] us,
                     const double[:, ::1] robroot, bint has_robroot, const double[:, ::1] base_inv,
                     const double[:, ::1] tool, double[:, :] out)
    cdef void _mm4(self, const double[:, ::1] A, const double[:, ::1] B, double[:, ::1] C) noexcept

    @cython.locals(i=int, j=int, k=int, r=int, r2=int, yv=int, p0=double, p1=double, p2=double, d=double)
    cpdef forward(self, const double[:] a, double[:, ::1] T)
    @cython.locals(x=double, y=double, z=double, w=double, angle=double, a2=double, scale=double,
                   x2=double, y2=double, z2=double, w2=double, xy=double, zw=double, xz=double,
                   yw=double, yz=double, xw=double, r=int, R="double[:, ::1]")
    cdef void _joint(self, int i, double qi) noexcept
    cdef void _mm(self, int r, const double[:, ::1] B, int rb, int out) noexcept
    cdef void _mv(self, int r, const double[:, ::1] V, int i) noexcept


cdef class ExternalChain:
    cdef dgemm_t gemm
    cdef int m
    cdef public int need
    cdef const double[:, :, ::1] frames
    cdef int[::1] lin
    cdef const double[::1] dirs
    cdef int[::1] idx
    cdef double[:, :, ::1] buf      # the chain so far, its product with the link, the axis' frame

    @cython.locals(k=int, v=double, buf="double[:, :, ::1]", fr="const double[:, :, ::1]")
    cpdef chain(self, const double[:] e, double[:, ::1] out)
    @cython.locals(i=int, j=int, ra=double, rb=double, rc=double, ca=double, sa=double, cb=double, sb=double,
                   cc=double, sc=double)
    cdef void _axis(self, int lin, double v, double[:, ::1] A) noexcept
    cdef void _mm4(self, const double[:, ::1] A, const double[:, ::1] B, double[:, ::1] C) noexcept


cdef class ArmCycle:
    cdef mj_kinematics_t fn
    cdef dgemm_t gemm
    cdef bint has_gemm
    cdef int n
    cdef size_t m, d
    cdef object keep
    cdef const int[::1] qidx
    cdef const double[::1] sign
    cdef double[::1] qpos
    cdef const double[::1] xmat
    cdef const double[::1] xpos
    cdef double[:, ::1] tmp
    cdef double[:, ::1] rows
    cdef bint keeping
    cdef public int row
    cdef int rows_n, at, width

    @cython.locals(i=int, j=int)
    cdef void _play(self, const double[:] q, double[::1] qa, double[:, ::1] F) noexcept
    cpdef cycle(self, const double[:] q, double[::1] qa, double[:, ::1] F)
    cpdef keep_rows(self, object rows, int at)
    cpdef use_gemm(self, size_t gemm)
    cpdef product(self, const double[:, ::1] A, const double[:, ::1] B, const double[:, ::1] C,
                  double[:, ::1] out)
    cdef void _product(self, const double[:, ::1] A, const double[:, ::1] B, const double[:, ::1] C,
                       double[:, ::1] out) noexcept
