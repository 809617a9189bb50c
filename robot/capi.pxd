# The C declarations the pure-Python-mode modules of robot/build.py ``PURE`` share where they call
# numpy's BLAS and MuJoCo through the addresses robot/blas.py and the mujoco package give (robot/ipocycle.py,
# robot/cartpath.py): their C function pointer types, and libm's pow as CPython's float ** calls it.

cdef extern from *:
    """
    #include <math.h>
    /* libm's pow called as CPython's float ** calls it: through a pointer the compiler cannot
       see through, so that pow(x, 2.0) is not folded into x * x (glibc's pow is not
       correctly rounded everywhere: the two may differ in the last bit) */
    static double (* volatile capi_libm_pow)(double, double) = pow;
    """
    double capi_libm_pow(double x, double y) noexcept nogil

#: cblas_dgemm of an ILP64 BLAS (numpy's own: the product numpy's ``@`` computes for two
#: C-contiguous float64 matrices is this call, row-major, no transposes, alpha 1, beta 0)
ctypedef void (*dgemm_t)(int order, int ta, int tb, long long m, long long n, long long k,
                         double alpha, const double* a, long long lda, const double* b,
                         long long ldb, double beta, double* c, long long ldc) noexcept nogil

#: cblas_ddot of the same BLAS
ctypedef double (*ddot_t)(long long n, const double* x, long long incx, const double* y,
                          long long incy) noexcept nogil

#: cblas_dgemv of the same BLAS (numpy's 3x3 by vector product)
ctypedef void (*dgemv_t)(int order, int ta, long long m, long long n, double alpha, const double* a,
                         long long lda, const double* x, long long incx, double beta, double* y,
                         long long incy) noexcept nogil

#: MuJoCo's mj_kinematics(const mjModel*, mjData*)
ctypedef void (*mj_kinematics_t)(const void* m, void* d) noexcept nogil
