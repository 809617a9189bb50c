# The C view of robot/simcore/cartpath.pyx's CartPath, for the modules that cimport it
# (robot/simcore/lineplan.pyx makes a line's path and walks it).
from robot.kinematics.fastpath cimport OPWCore
from robot.simcore.capi cimport dgemm_t


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
    cdef double[:, ::1] frames     # (16, 4): pre (base), post (tool), scratch T, F; numpy-allocated

    cdef int _pose(self, double u, double* M) noexcept
    cdef int _solve(self, const double* M, status, const double* ref, double* out) except -1
    cdef object _axes(self, const double* M, status, const double[:] ref6)
    cdef int _chain_samples(self, double u0, double u1, int nk, status, const double[:] start6, int chain_from,
                            double max_jump, double step_deg, int max_samples, double* Q, double* ref,
                            double* step_out) except -2
    cdef void _flange(self, const double* M, double* out) noexcept
    @staticmethod
    cdef int _pose_rp(const double[:, :] R, const double[:] p, double* M) except -1
