# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False, auto_pickle=False
"""The simulator's hot path in C that is not kinematics of its own (issue 39, "Simulator";
issue 47), built by robot/build.py. The kinematics' hot path is robot/kinematics/fastpath.py,
compiled from that very Python file; this module calls its C methods (``OPWCore``):

* :class:`Forward`: the joints' forward kinematics (robot/kinematics/joints.py
  ``JointChain.forward``: scipy's rotation matrices, numpy's own BLAS through its address);
* :class:`CartPath`: the poses of a CP segment's lines and arcs (robot/planner.py
  ``CartSegment.pose_u``) and their axes (fastpath's ``OPWCore``), through the motion's ``$BASE``
  and ``$TOOL`` where it has them (``RobotModel.ik``'s two products, numpy's BLAS at its address),
  the planning walk of a piece (robot/planner.py ``_plan_cart``), the distance to the path's end
  (``CartSegment.tcp_dist_to_end``) and a Cartesian blend's setpoint (robot/blending.py
  ``blend_setpoint``);
* :func:`plan_line`: the plan of a single LIN (robot/planner.py ``_plan_cart`` of one line, for
  ``_planned_line``, which makes the segment);
* :func:`blend_args`: the plan of a blend between two CP motions from its braking on
  (robot/blending.py ``plan_blend``): robot/lawtable.py's checks and ramp (compiled from that
  Python file, its C functions called here) with the distance to the path's end of ``CartPath``;
* :class:`ArmCycle`: the IPO cycle's MuJoCo playback (``mj_kinematics`` through its address)
  with its TCP product (robot/controller.py ``Controller.step``);
* :func:`pose_line`: the trace's pose line (robot/trace.py).

Each is bit for bit the pure-Python code it mirrors (hand mirrors, until each becomes a
pure-Python-mode module of robot/build.py ``PURE`` as robot/lawtable.py and
robot/kinematics/pal4rows.py did; issue 76 item 5), which stays the fallback and the reference:
tests/robot/test_simcore.py compares the two wherever this module is built, and fails where it
is expected and missing. The same operations in the same order on C doubles, libm's functions
(what Python's ``math`` calls), ``degrees`` and ``radians`` as CPython's multiplications by 180/pi
and pi/180, and no fused multiply-add (compiled with ``-ffp-contract=off``). ``SOURCE_SHA`` is the
sha256 of the simcore.pyx it was built from (robot/build.py passes it): a stale build is not used.
Its objects live in one process and are never pickled: ``auto_pickle=False`` (Cython's generated
unpickling of a C array attribute copied past the array's end, seen with the 4-axis palletizer's rows,
robot/kinematics/pal4rows.py, which says the same).
"""

from libc.math cimport sin, cos, atan2, sqrt, fabs, copysign, M_PI, INFINITY
from cpython.mem cimport PyMem_Malloc, PyMem_Free
import numpy as np

from robot.kinematics.fastpath cimport OPWCore
from robot cimport lawtable

cdef extern from *:
    """
    #ifndef SIMCORE_SOURCE_SHA
    #define SIMCORE_SOURCE_SHA ""
    #endif
    """
    const char* SIMCORE_SOURCE_SHA

cdef extern from *:
    """
    #include <math.h>
    /* libm's pow called as CPython's float ** calls it: through a pointer the compiler cannot
       see through, so that pow(x, 2.0) is not folded into x * x (glibc's pow is not
       correctly rounded everywhere: the two may differ in the last bit) */
    static double (* volatile simcore_libm_pow)(double, double) = pow;
    """
    double simcore_libm_pow(double x, double y) noexcept nogil

#: The sha256 of the simcore.pyx this module was compiled from (robot/build.py; robot/kinematics
#: compares it with the file's: a stale build is not used)
SOURCE_SHA = SIMCORE_SOURCE_SHA.decode("ascii")

cdef double DEG_TO_RAD = M_PI / 180.0
cdef double RAD_TO_DEG = 180.0 / M_PI

# ----------------------------------------------------------------------------- CP paths
#: cblas_dgemm of an ILP64 BLAS (numpy's own: the product numpy's ``@`` computes for two
#: C-contiguous float64 4x4 matrices is this call, row-major, no transposes, alpha 1, beta 0)
ctypedef void (*_dgemm_t)(int order, int ta, int tb, long long m, long long n, long long k,
                          double alpha, const double* a, long long lda, const double* b,
                          long long ldb, double beta, double* c, long long ldc) noexcept nogil

ctypedef double (*_ddot_t)(long long n, const double* x, long long incx, const double* y,
                           long long incy) noexcept nogil


cdef double _dot3(_ddot_t ddot, const double* v) noexcept:
    """``v.dot(v)`` of a float64 (3,) as numpy computes it: ``0. + cblas_ddot(3, v, 1, v, 1)``."""
    cdef double s = 0.
    s += ddot(3, v, 1, v, 1)
    return s


cdef class CartPath:
    """The poses of a CP segment's lines and arcs, and their axes (``opw``: robot/kinematics/fastpath.py's
    ``OPWCore``; None: the poses only) (robot/planner.py ``CartSegment.pose_u`` and ``CartSegment.ik``
    with the compiled inverse, the same numbers):
    for path parameter u the piece k and fraction f of ``CartSegment._locate``, the position
    ``LinePiece.pos``/``ArcPiece.pos`` at ``s = f * length`` (libm's cos and sin, as ``math``)
    and the rotation the segment keeps for that piece (at its start, within it and at its end:
    the matrices the Python code holds; a rotation it would compute, such as a slerp between
    two orientations, is not mirrored). A pose not mirrored (such a rotation, a spline piece)
    gives None: the caller runs the Python code.

    ``kinds`` per piece: 0 line (``a`` = p0, ``b`` = dir), 1 arc (``a`` = centre, ``b`` = e1,
    ``c`` = e2, ``r``, ``angle``), -1 not mirrored; ``rots`` (n, 3, 3, 3): the rotation at
    f <= 0, within, at f >= 1; ``mid_ok`` 0 where the rotation within is not mirrored."""

    cdef OPWCore opw
    cdef int n
    cdef object keep
    cdef const double[::1] ub
    cdef const int[::1] kinds
    cdef const int[::1] mid_ok
    cdef const double[::1] length
    cdef const double[::1] r
    cdef const double[::1] angle
    cdef const double[:, ::1] a
    cdef const double[:, ::1] b
    cdef const double[:, ::1] c
    cdef const double[:, :, :, ::1] rots
    cdef _dgemm_t gemm
    cdef int has_pre, has_post
    cdef double[:, ::1] frames     # (12, 4): pre (base), post (tool), scratch T, F; numpy-allocated

    def __init__(self, OPWCore opw, ub, kinds, mid_ok, length, r, angle, a, b, c, rots):
        self.opw = opw
        self.keep = (ub, kinds, mid_ok, length, r, angle, a, b, c, rots)
        self.ub, self.kinds, self.mid_ok = ub, kinds, mid_ok
        self.length, self.r, self.angle = length, r, angle
        self.a, self.b, self.c, self.rots = a, b, c, rots
        self.n = self.kinds.shape[0]
        if (self.n < 1 or self.ub.shape[0] != self.n + 1 or self.mid_ok.shape[0] != self.n
                or self.length.shape[0] != self.n or self.r.shape[0] != self.n
                or self.angle.shape[0] != self.n or self.a.shape[0] != self.n or self.b.shape[0] != self.n
                or self.c.shape[0] != self.n or self.rots.shape[0] != self.n or self.a.shape[1] != 3
                or self.b.shape[1] != 3 or self.c.shape[1] != 3 or self.rots.shape[1] != 3
                or self.rots.shape[2] != 3 or self.rots.shape[3] != 3):
            raise ValueError("CartPath: inconsistent piece tables")

    cdef int _pose(self, double u, double* M) noexcept:
        """The pose at u into M (3x4, row-major); 0: not mirrored."""
        cdef int n = self.n, k, lo, hi, mid, i, j, w
        cdef double f, du, s, ph, cs, sn
        if u <= 0.0:
            k, f = 0, 0.0
        elif u >= 1.0:
            k, f = n - 1, 1.0
        else:
            k = lawtable.piece_of(self.ub, n, u)
            du = self.ub[k + 1] - self.ub[k]
            f = (u - self.ub[k]) / du if du > 0 else 1.0
        if self.kinds[k] < 0:
            return 0
        if f <= 0.0:
            w = 0
        elif f >= 1.0:
            w = 2
        else:
            if not self.mid_ok[k]:
                return 0
            w = 1
        s = f * self.length[k]
        if self.kinds[k] == 0:
            for i in range(3):
                M[4 * i + 3] = self.a[k, i] + self.b[k, i] * s
        else:
            ph = copysign(s / self.r[k], self.angle[k]) if self.r[k] > 0 else 0.0
            cs = cos(ph)
            sn = sin(ph)
            for i in range(3):
                M[4 * i + 3] = self.a[k, i] + self.r[k] * (cs * self.b[k, i] + sn * self.c[k, i])
        for i in range(3):
            for j in range(3):
                M[4 * i + j] = self.rots[k, w, i, j]
        return 1

    def pose_u(self, double u):
        """(p (3,), R (3, 3)) at u, or None (not mirrored)."""
        cdef double M[12]
        cdef int i, j
        if not self._pose(u, M):
            return None
        p = np.empty(3)
        R = np.empty((3, 3))
        cdef double[::1] pv = p
        cdef double[:, ::1] Rv = R
        for i in range(3):
            pv[i] = M[4 * i + 3]
            for j in range(3):
                Rv[i, j] = M[4 * i + j]
        return p, R

    cdef int _solve(self, const double* M, status, const double* ref, double* out) except -1:
        """fastpath's ``OPWCore.solve`` of the pose M (3x4, row-major) for the reference `ref`
        (turn None) into out (6); 0 where ``CartSegment.ik`` raises."""
        cdef OPWCore opw = self.opw
        cdef int i, st = 0, has_status = 0
        if status is not None:
            st = <int>status
            has_status = 1
        if self.has_pre or self.has_post:
            self._flange(M, &opw.M[0])
        else:
            for i in range(12):
                opw.M[i] = M[i]
        for i in range(6):
            opw.ref[i] = ref[i]
        if not opw.solve(has_status, st, 0, 0):
            return 0
        for i in range(6):
            out[i] = opw.q[i]
        return 1

    cdef object _axes(self, const double* M, status, const double[:] ref6):
        """The axes (6,) of the pose M (3x4) for the reference ref6 (a new array), or None."""
        cdef double ref[6]
        cdef int i
        for i in range(6):
            ref[i] = ref6[i]
        res = np.empty(6)
        cdef double[::1] rv = res
        if not self._solve(M, status, ref, &rv[0]):
            return None
        return res

    def axes_u(self, double u, status, const double[:] ref6):
        """The axes (6,) at u for the reference ref6 (``CartSegment.ik`` of ``pose_u(u)``), or
        None (not mirrored, or the Python inverse decides)."""
        cdef double M[12]
        if self.opw is None or ref6.shape[0] != 6 or not self._pose(u, M):
            return None
        return self._axes(M, status, ref6)

    def chain_u(self, const double[:] us, status, const double[:] ref6):
        """:meth:`axes_u` at each u of us in turn, each solution the next one's reference (the
        first one's: ref6): (n, 6), or None as soon as one would be None."""
        cdef Py_ssize_t n = us.shape[0], j
        cdef double M[12]
        cdef double ref[6]
        cdef int i
        if self.opw is None or ref6.shape[0] != 6:
            return None
        res = np.empty((n, 6))
        cdef double[:, ::1] out = res
        for i in range(6):
            ref[i] = ref6[i]
        for j in range(n):
            if not self._pose(us[j], M):
                return None
            if not self._solve(M, status, ref, &out[j, 0]):
                return None
            for i in range(6):
                ref[i] = out[j, i]
        return res


    def walk(self, double u0, double u1, int nk, status, const double[:] start6, int chain_from,
             double budget, bint plain, const double[:] v_ax, const double[:] a_ax, double vmax_k,
             double max_jump, double step_deg, int max_samples):
        """robot/planner.py ``_plan_cart``'s walk of a piece from u0 to u1 whose axes :meth:`chain_u`
        solves (the same numbers, the same operations in the same order): ``np.linspace(u0, u1,
        nk + 1)``'s samples solved in a chain from start6, more samples while an axis turns more
        than `step_deg` between two (up to `max_samples`), ``gradient_rows`` twice, the largest
        |q'| and |q''| of each axis and the piece's speed and acceleration limits from `v_ax` and
        `a_ax` (deg/s, deg/s^2, (6,)), `budget` and `vmax_k` (Python's ``min``, ``float ** 2`` as
        libm's pow). Returns (end axes (6,), q' at the start (6,), q' at the end (6,), |q'| max
        (6,), |q''| max (6,), the piece's speed limit, its axis acceleration limit or None when
        `plain`), or None where the Python code decides: a pose :meth:`chain_u` does not solve, an
        axis turning more than `max_jump` between samples (the Python code raises), `nk` reaching
        `chain_from` (the Python code solves in numpy), a step of 0, a NaN."""
        cdef double ref[6]
        cdef double qd[6]
        cdef double qdd[6]
        cdef double d1a[6]
        cdef double d1b[6]
        cdef double* Q
        cdef double* D1
        cdef double* D2
        cdef double step, h, Aax
        cdef int N
        if (self.opw is None or start6.shape[0] != 6 or v_ax.shape[0] != 6 or a_ax.shape[0] != 6
                or nk < 2 or max_samples < nk):
            return None
        Q = <double*>PyMem_Malloc(3 * (max_samples + 1) * 6 * sizeof(double))
        if Q == NULL:
            raise MemoryError()
        D1 = Q + (max_samples + 1) * 6
        D2 = D1 + (max_samples + 1) * 6
        try:
            N = self._chain_samples(u0, u1, nk, status, start6, chain_from, max_jump, step_deg, max_samples,
                                    Q, ref, &step)
            if N < 0:
                return None
            h = ((<double>1) * step + u0) - u0
            if not h > 0:
                return None
            _gradient_rows(Q, D1, N, h)
            _gradient_rows(D1, D2, N, h)
            if _rate_maxima(D1, D2, N, d1a, d1b, qd, qdd):
                return None
            vmax_k = _piece_speed(qd, qdd, v_ax, a_ax, budget, plain, vmax_k)
            Aax = INFINITY if plain else _piece_acc(qd, qdd, a_ax, budget, vmax_k)
            return (_array6(ref), _array6(d1a), _array6(d1b), _array6(qd), _array6(qdd), vmax_k,
                    None if plain else Aax)
        finally:
            PyMem_Free(Q)

    cdef int _chain_samples(self, double u0, double u1, int nk, status, const double[:] start6, int chain_from,
                            double max_jump, double step_deg, int max_samples, double* Q, double* ref,
                            double* step_out) except -2:
        """:meth:`walk`'s samples: ``np.linspace(u0, u1, nk + 1)`` solved in a chain from start6 into
        the rows of Q (the last into ref), more samples while an axis turns more than `step_deg`
        between two (up to `max_samples`); the row count N, the step in step_out, or -1 where the
        Python code decides (``nk`` reaching `chain_from`, a step of 0, an unsolved pose, a turn
        over `max_jump` or NaN)."""
        cdef double M[12]
        cdef double step, x, biggest
        cdef int j, i
        while True:
            if nk >= chain_from:
                return -1
            step = (u1 - u0) / <double>nk           # np.linspace: i * step + start, stop last
            if step == 0:
                return -1
            for i in range(6):
                Q[i] = start6[i]
                ref[i] = start6[i]
            for j in range(1, nk + 1):
                if not self._pose((<double>j) * step + u0 if j < nk else u1, M):
                    return -1
                if not self._solve(M, status, ref, &Q[6 * j]):
                    return -1
                for i in range(6):
                    ref[i] = Q[6 * j + i]
            biggest = 0.0
            for j in range(nk):
                for i in range(6):
                    x = fabs(Q[6 * (j + 1) + i] - Q[6 * j + i])
                    if x != x or x > max_jump:
                        return -1
                    if x > biggest:
                        biggest = x
            if biggest <= step_deg or nk >= max_samples:
                step_out[0] = step
                return nk + 1
            nk = <int>(<double>nk * biggest / step_deg) + 1
            if nk > max_samples:
                nk = max_samples


    def dist_to(self, double u, const double[:] end, size_t ddot):
        """robot/planner.py ``CartSegment.tcp_dist_to_end``: ``norm3(pose_u(u)[0] - end)`` (numpy's
        dot product through its ``cblas_ddot`` at address `ddot`), or None (a pose not mirrored)."""
        cdef double M[12]
        cdef double d[3]
        cdef int i
        if ddot == 0 or end.shape[0] != 3 or not self._pose(u, M):
            return None
        for i in range(3):
            d[i] = M[4 * i + 3] - end[i]
        return sqrt(_dot3(<_ddot_t>ddot, d))

    def superposed(self, CartPath prev, double u_prev, double u, double u_start, status, ref6, size_t gemm):
        """robot/blending.py ``blend_setpoint`` in Cartesian space with this path the next motion's:
        the poses of `prev` at `u_prev` and of this path at `u` and at `u_start` (:meth:`pose_u`),
        overlapped as ``superpose_pose`` does (``p0 + (p1 - pc)``, ``(R1 @ Rc.T) @ R0``: numpy's
        two products through its ``cblas_dgemm`` at address `gemm`, as numpy calls it, into
        numpy-allocated 3x3s) and solved as ``CartSegment.ik`` solves (:meth:`solve_rp`) for the
        reference ref6 (6,): the axes (6,), or None (a pose not mirrored, no inverse here, or the
        Python code decides)."""
        cdef double M0[12]
        cdef double M1[12]
        cdef double Mc[12]
        cdef double M[12]
        cdef int i, j
        if self.opw is None or gemm == 0 or len(ref6) != 6:
            return None
        if not prev._pose(u_prev, M0) or not self._pose(u, M1) or not self._pose(u_start, Mc):
            return None
        buf = np.empty((4, 3, 3))
        cdef double[:, :, ::1] b = buf
        for i in range(3):
            for j in range(3):
                b[0, i, j] = M1[4 * i + j]
                b[1, i, j] = Mc[4 * i + j]
                b[2, i, j] = M0[4 * i + j]
        (<_dgemm_t>gemm)(101, 111, 112, 3, 3, 3, 1.0, &b[0, 0, 0], 3, &b[1, 0, 0], 3, 0.0, &b[3, 0, 0], 3)
        (<_dgemm_t>gemm)(101, 111, 111, 3, 3, 3, 1.0, &b[3, 0, 0], 3, &b[2, 0, 0], 3, 0.0, &b[0, 0, 0], 3)
        for i in range(3):
            for j in range(3):
                M[4 * i + j] = b[0, i, j]
            M[4 * i + 3] = M0[4 * i + 3] + (M1[4 * i + 3] - Mc[4 * i + 3])
        return self._axes(M, status, ref6)

    @staticmethod
    def superpose_products(size_t gemm, const double[:, ::1] A, const double[:, ::1] B, const double[:, ::1] C):
        """``(A @ B.T) @ C`` of three 3x3s as :meth:`superposed` computes it, for robot/blending.py's
        check at set-up that it is numpy's bit for bit."""
        if gemm == 0 or A.shape[0] != 3 or A.shape[1] != 3 or B.shape[0] != 3 or B.shape[1] != 3 \
                or C.shape[0] != 3 or C.shape[1] != 3:
            raise ValueError("superpose_products: a BLAS address, three (3, 3)")
        buf = np.empty((4, 3, 3))
        cdef double[:, :, ::1] b = buf
        b[0, :, :] = A
        b[1, :, :] = B
        b[2, :, :] = C
        (<_dgemm_t>gemm)(101, 111, 112, 3, 3, 3, 1.0, &b[0, 0, 0], 3, &b[1, 0, 0], 3, 0.0, &b[3, 0, 0], 3)
        (<_dgemm_t>gemm)(101, 111, 111, 3, 3, 3, 1.0, &b[3, 0, 0], 3, &b[2, 0, 0], 3, 0.0, &b[0, 0, 0], 3)
        return buf[0].copy()

    def use_frames(self, size_t gemm, pre, post):
        """Solve ``(pre @ T) @ post`` instead of the pose T (4x4 of the pose's R and p) as it
        stands: robot/planner.py ``RobotModel.ik``'s ``$BASE @ T @ INV_POS($TOOL)``, each
        product numpy's ``@`` through the BLAS ``cblas_dgemm`` at address `gemm` (numpy's own,
        robot/blas.py; row-major, no transposes, alpha 1, beta 0, into numpy-allocated 4x4s);
        `pre` or `post` None: that product is skipped, as there for a null frame."""
        if gemm == 0:
            raise ValueError("CartPath.use_frames: no BLAS")
        frames = np.zeros((16, 4))
        if pre is not None:
            frames[0:4] = np.asarray(pre, dtype=float).reshape(4, 4)
        if post is not None:
            frames[4:8] = np.asarray(post, dtype=float).reshape(4, 4)
        self.gemm = <_dgemm_t>gemm
        self.frames = frames
        self.has_pre = 0 if pre is None else 1
        self.has_post = 0 if post is None else 1

    cdef void _flange(self, const double* M, double* out) noexcept:
        """The flange pose (3x4 into out) the solver is given for the pose M (3x4, row-major)."""
        cdef double* T = &self.frames[8, 0]
        cdef double* F = &self.frames[12, 0]
        cdef double* src
        cdef int i
        for i in range(12):
            T[i] = M[i]
        T[12] = 0.0
        T[13] = 0.0
        T[14] = 0.0
        T[15] = 1.0
        src = T
        if self.has_pre:
            self.gemm(101, 111, 111, 4, 4, 4, 1.0, &self.frames[0, 0], 4, T, 4, 0.0, F, 4)
            src = F
        if self.has_post:
            self.gemm(101, 111, 111, 4, 4, 4, 1.0, src, 4, &self.frames[4, 0], 4, 0.0,
                      T if src == F else F, 4)
            src = T if src == F else F
        for i in range(12):
            out[i] = src[i]

    @staticmethod
    cdef int _pose_rp(const double[:, :] R, const double[:] p, double* M) except -1:
        """The pose (R (3, 3), p (3,)) into M (3x4, row-major); ValueError for other shapes."""
        cdef int i, j
        if R.shape[0] != 3 or R.shape[1] != 3 or p.shape[0] != 3:
            raise ValueError("CartPath: R (3, 3), p (3,)")
        for i in range(3):
            for j in range(3):
                M[4 * i + j] = R[i, j]
            M[4 * i + 3] = p[i]
        return 0

    def flange_rp(self, const double[:, :] R, const double[:] p):
        """The flange pose (4x4) :meth:`solve_rp` solves for the pose (R (3, 3), p (3,))."""
        cdef double M[12]
        cdef double out[12]
        cdef int i, j
        CartPath._pose_rp(R, p, M)
        if self.has_pre or self.has_post:
            self._flange(M, out)
        else:
            for i in range(12):
                out[i] = M[i]
        res = np.zeros((4, 4))
        cdef double[:, ::1] rv = res
        for i in range(3):
            for j in range(4):
                rv[i, j] = out[4 * i + j]
        rv[3, 3] = 1.0
        return res

    def solve_rp(self, const double[:, :] R, const double[:] p, status, const double[:] ref6):
        """The axes (6,) of the pose (R (3, 3), p (3,)) for the reference ref6 (``CartSegment.ik``;
        turn None), or None (no inverse here, or the Python inverse decides)."""
        cdef double M[12]
        if self.opw is None or ref6.shape[0] != 6:
            return None
        CartPath._pose_rp(R, p, M)
        return self._axes(M, status, ref6)


# ----------------------------------------------------------------------------- a single LIN's plan

#: the identity numpy's ``R @ _EYE3`` multiplies with (robot/planner.py), numpy-allocated
_EYE3 = np.eye(3)
#: a line's entries of ``CartPath``'s tables that do not depend on the line (read-only)
_LINE_KIND, _LINE_MID, _LINE_R, _LINE_ANGLE, _LINE_C = (
    np.zeros(1, dtype=np.intc), np.ones(1, dtype=np.intc), np.ones(1), np.zeros(1), np.zeros((1, 3)))
for _a in (_LINE_KIND, _LINE_MID, _LINE_R, _LINE_ANGLE, _LINE_C):
    _a.setflags(write=False)


cdef void _tmul(_dgemm_t gemm, const double* A, const double* B, double* out) noexcept:
    """numpy's ``A.T @ B`` of two C-contiguous float64 3x3s (its cblas_dgemm call: A transposed)."""
    gemm(101, 112, 111, 3, 3, 3, 1.0, A, 3, B, 3, 0.0, out, 3)


cdef void _mul3(_dgemm_t gemm, const double* A, const double* B, double* out) noexcept:
    """numpy's ``A @ B`` of two C-contiguous float64 3x3s (its cblas_dgemm call)."""
    gemm(101, 111, 111, 3, 3, 3, 1.0, A, 3, B, 3, 0.0, out, 3)


def line_products(size_t gemm, size_t ddot, const double[:, ::1] A, const double[:, ::1] B, const double[::1] v):
    """(``A.T @ B``, ``A @ eye(3)``, ``v.dot(v)``) as :func:`plan_line` computes them (numpy's BLAS
    at the addresses `gemm` and `ddot`), for robot/planner.py's check at set-up that they are
    numpy's bit for bit."""
    if gemm == 0 or ddot == 0 or A.shape[0] != 3 or A.shape[1] != 3 or B.shape[0] != 3 or B.shape[1] != 3 \
            or v.shape[0] != 3:
        raise ValueError("line_products: BLAS addresses, A and B (3, 3), v (3,)")
    cdef const double[:, ::1] eye = _EYE3
    P = np.empty((3, 3))
    Q = np.empty((3, 3))
    cdef double[:, ::1] pv = P
    cdef double[:, ::1] qv = Q
    _tmul(<_dgemm_t>gemm, &A[0, 0], &B[0, 0], &pv[0, 0])
    _mul3(<_dgemm_t>gemm, &A[0, 0], &eye[0, 0], &qv[0, 0])
    return P, Q, _dot3(<_ddot_t>ddot, &v[0])


def plan_line(OPWCore opw, size_t gemm, size_t ddot, const double[:, :] start_T, double x, double y,
              double z, double a, double b, double c, double v_cp, double v_ori, double a_cp,
              double a_ori, status, q0, int chain_from, bint plain, v_ax, a_ax, double max_jump, double step_deg,
              int max_samples, pre, post):
    """robot/planner.py ``_plan_cart`` of a single LIN to a complete Cartesian target (x .. c, mm
    and deg: ``frame_to_matrix``'s rotation) from the TCP pose `start_T` (4x4 in $BASE) and the
    axes q0 (6,), ``$ORI_TYPE #VAR``, outside T1, solved through the compiled inverse `opw`
    (through $BASE `pre` and INV_POS($TOOL) `post` by ``CartPath.use_frames`` where not None):
    the same operations in the same order, numpy's products and dot products through its BLAS
    at the addresses `gemm` and `ddot` (robot/planner.py checks them once a process). `v_cp`,
    `v_ori`, `a_cp`, `a_ori`: ``_cp_speeds``'s; `chain_from`, `plain`, `v_ax`, `a_ax`,
    `max_jump`, `step_deg`, `max_samples`: :meth:`CartPath.walk`'s.

    Returns (p0, p1, dir, L, R0, R1, theta, rotvec, R_still, weight, u1, CartPath, q1, q' at
    the start, q' at the end, vel_peak, acc_peak, v_prog, vmax, amax): the line's ends,
    direction and length (mm), the two orientations, the turn between them (deg) and its
    rotation vector, the orientation kept along the line, the piece's time weight, its end's
    path parameter, its compiled path, the end axes, the axes' rates and peaks, the programmed
    normalised speed and the speed and acceleration the profile is planned with. None where
    the Python code decides: a turn of the orientation along the line (a slerp), a speed or
    acceleration not positive, a line of (nearly) zero length, a NaN, and wherever
    :meth:`CartPath.walk` gives None."""
    cdef double L, th, w, W, u1, vprog, vmax, amax, Aax
    cdef long long nk
    if opw is None or gemm == 0 or ddot == 0 or start_T.shape[0] != 4 or start_T.shape[1] != 4:
        return None
    if not (v_cp > 0 and v_ori > 0 and a_cp > 0 and a_ori > 0):
        return None
    R0, R1, p0, p1 = _line_ends(start_T, x, y, z, a, b, c)
    geo = _line_geometry(<_dgemm_t>gemm, <_ddot_t>ddot, R0, R1, p0, p1)
    if geo is None:
        return None
    dirv, L, th, rv, still = geo
    # the piece's weight max(L, th * c), W = sum([w]), u_bounds = [0, w] / W
    wt = th * (v_cp / v_ori)
    w = wt if wt > L else L
    W = 0.0
    W += w
    if not W > 1e-6:
        return None
    u1 = w / W
    vprog, vmax, amax, nk = _line_limits(L, th, w, W, v_cp, v_ori, a_cp, a_ori)
    if nk < 0:
        return None
    cp = _line_path(opw, gemm, pre, post, dirv, p0, R0, still, R1, L, W, u1)
    walked = cp.walk(0.0 / W, u1, <int>nk, status, q0, chain_from, 1.0, plain, v_ax, a_ax, vmax,
                     max_jump, step_deg, max_samples)
    if walked is None:
        return None
    q1, d1a, d1b, qd, qdd, vmax, a_walk = walked
    if not plain:
        Aax = a_walk
        if 1e-9 > Aax:
            Aax = 1e-9
        if Aax < amax:
            amax = Aax
    vel, accp = _line_peaks(qd, qdd, vmax, amax)
    return (p0, p1, dirv, L, R0, R1, th, rv, still, w, u1, cp, q1, d1a, d1b, vel, accp, vprog, vmax,
            amax)


cdef tuple _line_ends(const double[:, :] start_T, double x, double y, double z, double a, double b, double c):
    """:func:`plan_line`'s ends: (R0, R1, p0, p1), the start's rotation and position from `start_T`,
    the target's from ``frame_to_matrix(x, y, z, a, b, c)`` (math.radians, cos and sin, the
    products in its order)."""
    cdef double ra, rb, rc, ca, sa, cb, sb, cc, sc
    cdef int i, j
    R0 = np.empty((3, 3))
    R1 = np.empty((3, 3))
    p0 = np.empty(3)
    p1 = np.empty(3)
    cdef double[:, ::1] r0 = R0
    cdef double[:, ::1] r1 = R1
    cdef double[::1] pp0 = p0
    cdef double[::1] pp1 = p1
    for i in range(3):
        pp0[i] = start_T[i, 3]
        for j in range(3):
            r0[i, j] = start_T[i, j]
    ra, rb, rc = a * DEG_TO_RAD, b * DEG_TO_RAD, c * DEG_TO_RAD
    ca, sa, cb, sb, cc, sc = cos(ra), sin(ra), cos(rb), sin(rb), cos(rc), sin(rc)
    r1[0, 0], r1[0, 1], r1[0, 2] = ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc
    r1[1, 0], r1[1, 1], r1[1, 2] = sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc
    r1[2, 0], r1[2, 1], r1[2, 2] = -sb, cb * sc, cb * cc
    pp1[0], pp1[1], pp1[2] = x, y, z
    return R0, R1, p0, p1


cdef object _line_geometry(_dgemm_t mm, _ddot_t dd, R0, R1, p0, p1):
    """:func:`plan_line`'s line: (dir, L, theta (deg), rotvec, R_still) of the ends (LinePiece: d =
    p1 - p0, its norm3, dir = d / L; rotation_angle_deg(R0, R1) and rotvec_of(R0.T @ R1),
    robot/frames.py ``_angle``), or None for an orientation that turns along the line (a slerp:
    the Python code) or a turn near 180 deg."""
    cdef double[:, ::1] r0 = R0
    cdef double[::1] pp0 = p0
    cdef double[::1] pp1 = p1
    cdef double[:, ::1] r1 = R1
    cdef double L, s, th, k, w0, w1, w2
    cdef int i
    cdef const double[:, ::1] eye = _EYE3
    d = np.empty(3)                     # numpy's buffers, as numpy's own products use them
    M = np.empty((3, 3))
    cdef double[::1] dv = d
    cdef double[:, ::1] m = M
    for i in range(3):
        dv[i] = pp1[i] - pp0[i]
    L = sqrt(_dot3(dd, &dv[0]))
    dirv = np.zeros(3)
    cdef double[::1] dr = dirv
    if L > 0:
        for i in range(3):
            dr[i] = dv[i] / L
    _tmul(mm, &r0[0, 0], &r1[0, 0], &m[0, 0])
    w0, w1, w2 = m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]
    s = sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    th = atan2(0.5 * s, 0.5 * (m[0, 0] + m[1, 1] + m[2, 2] - 1.0))
    if th < 1e-6:
        k = 0.5 * (1.0 + th * th / 6.0)
    elif th < M_PI - 1e-3:
        k = th / s
    else:
        return None
    rv = np.empty(3)
    cdef double[::1] rvv = rv
    rvv[0], rvv[1], rvv[2] = w0 * k, w1 * k, w2 * k
    if not sqrt(_dot3(dd, &rvv[0])) < 1e-12:
        return None                     # the orientation turns along the line: a slerp (Python)
    still = np.empty((3, 3))
    cdef double[:, ::1] st = still
    _mul3(mm, &r0[0, 0], &eye[0, 0], &st[0, 0])
    return dirv, L, th * RAD_TO_DEG, rv, still


cdef tuple _line_limits(double L, double th, double w, double W, double v_cp, double v_ori, double a_cp,
                        double a_ori):
    """:func:`plan_line`'s speed and acceleration limits of the line (no curvature limit) and its
    sample count: (v_prog, vmax, amax, nk), nk -1 for a length past 1e9 mm or a NaN."""
    cdef double lk, ok, v, v2, vprog, vc, acc, a2, q
    cdef long long nk
    lk = L * W / w if w > 0 else 0.0
    ok = th * W / w if w > 0 else 0.0
    v = v_cp / lk if lk > 0 else INFINITY
    v2 = v_ori / ok if ok > 0 else INFINITY
    if v2 < v:
        v = v2
    vprog = v
    vc = sqrt(a_cp * INFINITY) if L > 0 else INFINITY
    vc = vc / lk if lk > 0 else INFINITY
    if vc < v:
        v = vc
    acc = a_cp / lk if lk > 0 else INFINITY
    a2 = a_ori / ok if ok > 0 else INFINITY
    if a2 < acc:
        acc = a2
    q = L / 50.0
    if not q < 1e9:
        return vprog, 0.0, 0.0, -1
    nk = <long long>q + <long long>(th / 10.0) + 4
    if nk > 48:
        nk = 48
    if nk < 4:
        nk = 4
    return vprog, (v if v < INFINITY else 1e12), (acc if acc < INFINITY else 1e12), nk


cdef CartPath _line_path(OPWCore opw, size_t gemm, pre, post, dirv, p0, R0, still, R1, double L, double W,
                         double u1):
    """:func:`plan_line`'s compiled path of the line (robot/planner.py ``_cart_path``), through
    $BASE `pre` and INV_POS($TOOL) `post` where not None."""
    cdef int i, j
    cdef double[::1] dr = dirv
    cdef double[::1] pp0 = p0
    cdef double[:, ::1] r0 = R0
    cdef double[:, ::1] st = still
    cdef double[:, ::1] r1 = R1
    rots = np.empty((1, 3, 3, 3))
    dm = np.empty((1, 3))
    pm = np.empty((1, 3))
    ub = np.empty(2)
    lm = np.empty(1)
    cdef double[:, :, :, ::1] rt = rots
    cdef double[:, ::1] dmv = dm
    cdef double[:, ::1] pmv = pm
    cdef double[::1] ubv = ub
    cdef double[::1] lmv = lm
    for i in range(3):
        dmv[0, i] = dr[i]
        pmv[0, i] = pp0[i]
        for j in range(3):
            rt[0, 0, i, j] = r0[i, j]
            rt[0, 1, i, j] = st[i, j]
            rt[0, 2, i, j] = r1[i, j]
    ubv[0], ubv[1] = 0.0 / W, u1
    lmv[0] = L
    cp = CartPath(opw, ub, _LINE_KIND, _LINE_MID, lm, _LINE_R, _LINE_ANGLE, pm, dm, _LINE_C, rots)
    if pre is not None or post is not None:
        cp.use_frames(gemm, pre, post)
    return cp


cdef tuple _line_peaks(qd, qdd, double vmax, double amax):
    """:func:`plan_line`'s axis speed and acceleration peaks (6,) from the largest |q'| `qd` and
    |q''| `qdd` at the speed `vmax` and the acceleration `amax` (``vmax ** 2`` as libm's pow)."""
    cdef const double[::1] qdv = qd
    cdef const double[::1] qddv = qdd
    cdef double vk2 = simcore_libm_pow(vmax, 2.0)
    cdef int i
    vel = np.empty(6)
    accp = np.empty(6)
    cdef double[::1] vv = vel
    cdef double[::1] av = accp
    for i in range(6):
        vv[i] = qdv[i] * vmax           # np.maximum(0, x) of x >= +0: x
        av[i] = qddv[i] * vk2 + qdv[i] * amax
    return vel, accp


# ----------------------------------------------------------------------------- the IPO cycle
ctypedef void (*_mj_kinematics_t)(const void* m, void* d) noexcept nogil


ctypedef void (*_dgemv_t)(int order, int ta, long long m, long long n, double alpha, const double* a,
                          long long lda, const double* x, long long incx, double beta, double* y,
                          long long incy) noexcept nogil


cdef class Forward:
    """``JointChain.forward`` (robot/kinematics/joints.py) in one call, the same numbers: the joint
    rotations of scipy's ``Rotation.from_rotvec(axis * q).as_matrix()`` (its quaternion, then
    its matrix, the same operations in the same order), and every product ``@`` of the Python
    code through numpy's own BLAS as numpy calls it (``cblas_dgemm`` for a 3x3 by 3x3 product,
    ``cblas_dgemv`` for a 3x3 by vector one, at the addresses given). Its users check it against
    the Python code at set-up (robot/kinematics/joints.py ``JointChain._compiled``)."""

    cdef _dgemm_t gemm
    cdef _dgemv_t gemv
    cdef double orig[6][3]
    cdef double axis[6][3]
    cdef double sign[6]
    cdef double[:, ::1] rorig      # (6 * 3, 3): R_origin, numpy-allocated
    cdef int origin_rot
    cdef double[:, ::1] rfl        # (3, 3)
    cdef double pfl[3]
    cdef double[:, ::1] buf        # scratch matrices, numpy-allocated: R, R', Rj (6), y

    def __init__(self, size_t gemm, size_t gemv, origins, axes, sign, R_origin, origin_rot,
                 R_flange, p_flange):
        cdef int i, j
        if gemm == 0 or gemv == 0:
            raise ValueError("Forward: no BLAS")
        self.gemm = <_dgemm_t>gemm
        self.gemv = <_dgemv_t>gemv
        for i in range(6):
            self.sign[i] = sign[i]
            for j in range(3):
                self.orig[i][j] = origins[i][j]
                self.axis[i][j] = axes[i][j]
        self.rorig = np.ascontiguousarray(R_origin, dtype=float).reshape(18, 3)
        self.origin_rot = 1 if origin_rot else 0
        self.rfl = np.ascontiguousarray(R_flange, dtype=float)
        for j in range(3):
            self.pfl[j] = p_flange[j]
        self.buf = np.zeros((3 * 9, 3))

    def forward(self, const double[:] a, double[:, ::1] T):
        """The flange frame (4x4, mm) of the axes a (A1..A6, deg; further values ignored) into T."""
        cdef double rv[3]
        cdef double p[3]
        cdef double angle, a2, scale, x, y, z, w, x2, y2, z2, w2, xy, zw, xz, yw, yz, xw, qi
        cdef double* R = &self.buf[0, 0]
        cdef double* R2 = &self.buf[3, 0]
        cdef double* Rj
        cdef double* yv = &self.buf[24, 0]
        cdef double* tmp
        cdef int i, j
        if a.shape[0] < 6 or T.shape[0] != 4 or T.shape[1] != 4:
            raise ValueError("Forward.forward: a (>= 6,), T (4, 4)")
        for i in range(6):
            # q = sign * radians(a); rotvec = axis * q; scipy's from_rotvec(...).as_matrix()
            qi = self.sign[i] * (a[i] * DEG_TO_RAD)
            for j in range(3):
                rv[j] = self.axis[i][j] * qi
            angle = sqrt(rv[0] * rv[0] + rv[1] * rv[1] + rv[2] * rv[2])
            if angle <= 1e-3:
                a2 = angle * angle
                scale = 0.5 - a2 / 48 + a2 * a2 / 3840
            else:
                scale = sin(angle / 2) / angle
            x, y, z, w = scale * rv[0], scale * rv[1], scale * rv[2], cos(angle / 2)
            x2 = x * x
            y2 = y * y
            z2 = z * z
            w2 = w * w
            xy = x * y
            zw = z * w
            xz = x * z
            yw = y * w
            yz = y * z
            xw = x * w
            Rj = &self.buf[6 + 3 * i, 0]
            Rj[0], Rj[1], Rj[2] = x2 - y2 - z2 + w2, 2 * (xy - zw), 2 * (xz + yw)
            Rj[3], Rj[4], Rj[5] = 2 * (xy + zw), - x2 + y2 - z2 + w2, 2 * (yz - xw)
            Rj[6], Rj[7], Rj[8] = 2 * (xz - yw), 2 * (yz + xw), - x2 - y2 + z2 + w2
        for j in range(9):
            R[j] = 0.0
        R[0] = R[4] = R[8] = 1.0
        p[0] = p[1] = p[2] = 0.0
        for i in range(6):
            # p = p + R @ origins[i]; R = R @ R_origin[i]; R = R @ Rj[i]
            self.gemv(102, 112, 3, 3, 1.0, R, 3, &self.orig[i][0], 1, 0.0, yv, 1)
            for j in range(3):
                p[j] = p[j] + yv[j]
            if self.origin_rot:
                self.gemm(101, 111, 111, 3, 3, 3, 1.0, R, 3, &self.rorig[3 * i, 0], 3, 0.0, R2, 3)
                tmp = R
                R = R2
                R2 = tmp
            self.gemm(101, 111, 111, 3, 3, 3, 1.0, R, 3, &self.buf[6 + 3 * i, 0], 3, 0.0, R2, 3)
            tmp = R
            R = R2
            R2 = tmp
        # T[:3, :3] = R @ R_flange; T[:3, 3] = p + R @ p_flange
        self.gemm(101, 111, 111, 3, 3, 3, 1.0, R, 3, &self.rfl[0, 0], 3, 0.0, R2, 3)
        self.gemv(102, 112, 3, 3, 1.0, R, 3, self.pfl, 1, 0.0, yv, 1)
        for i in range(3):
            for j in range(3):
                T[i, j] = R2[3 * i + j]
            T[i, 3] = p[i] + yv[i]
            T[3, i] = 0.0
        T[3, 3] = 1.0


cdef class ArmCycle:
    """The kinematic playback of one IPO cycle on a MuJoCo arm (robot/mjcf.py ``ArmModel``
    without external axes): ``set_axes`` (``qpos = sign * radians(A)``, ``mj_kinematics``),
    ``axes_deg`` (``degrees(sign * qpos)``) and ``flange_pose_world`` (the ``tool0`` site,
    position in mm) in one call, the same numbers (numpy's ``radians``/``degrees`` are one
    multiplication by pi/180 and 180/pi). ``mj_kinematics`` is MuJoCo's own, called through
    its address in the library the ``mujoco`` package loaded, on the model and data
    addresses the package gives (``_address``); the arrays are views into that data, so the
    caller keeps the ``ArmModel`` alive while this object is used."""

    cdef _mj_kinematics_t fn
    cdef _dgemm_t gemm
    cdef size_t m, d
    cdef object keep
    cdef double[:, ::1] tmp
    cdef double[:, ::1] flange
    cdef double* qpos
    cdef const double* xmat
    cdef const double* xpos
    cdef int qidx[6]
    cdef double sign[6]

    def __init__(self, size_t fn, size_t m, size_t d, qpos, qidx, sign, site_xmat, site_xpos):
        cdef double[::1] qp = qpos
        cdef const double[::1] xm = site_xmat
        cdef const double[::1] xp = site_xpos
        cdef int i
        if fn == 0 or m == 0 or d == 0 or len(qidx) != 6 or len(sign) != 6:
            raise ValueError("ArmCycle: no mj_kinematics, model or data")
        if xm.shape[0] != 9 or xp.shape[0] != 3:
            raise ValueError("ArmCycle: the site's xmat is 9 values and its xpos 3")
        for i in range(6):
            if not 0 <= qidx[i] < qp.shape[0]:
                raise ValueError("ArmCycle: a qpos index out of range")
            self.qidx[i] = qidx[i]
            self.sign[i] = sign[i]
        self.fn = <_mj_kinematics_t>fn
        self.gemm = NULL
        self.tmp = np.empty((4, 4))
        self.flange = np.empty((4, 4))
        self.m, self.d = m, d
        self.keep = (qpos, site_xmat, site_xpos)
        self.qpos = &qp[0]
        self.xmat = &xm[0]
        self.xpos = &xp[0]

    cdef void _play(self, const double[:] q, double* qa, double* F) noexcept:
        """Set the axes q (its first 6), run mj_kinematics, read back qa (6) and F (4x4, row-major)."""
        cdef int i, j
        for i in range(6):
            self.qpos[self.qidx[i]] = self.sign[i] * (q[i] * DEG_TO_RAD)
        self.fn(<const void*>self.m, <void*>self.d)
        for i in range(6):
            qa[i] = (self.sign[i] * self.qpos[self.qidx[i]]) * RAD_TO_DEG
        for i in range(3):
            for j in range(3):
                F[4 * i + j] = self.xmat[3 * i + j]
            F[4 * i + 3] = 1000.0 * self.xpos[i]
        F[12] = 0.0
        F[13] = 0.0
        F[14] = 0.0
        F[15] = 1.0

    def cycle(self, const double[:] q, double[::1] qa, double[:, ::1] F):
        """Set the axes q (A1..A6, deg; further values ignored), run ``mj_kinematics``, and
        write the axes read back (deg) into qa (6,) and the flange in WORLD (4x4, mm) into F."""
        if q.shape[0] < 6 or qa.shape[0] != 6 or F.shape[0] != 4 or F.shape[1] != 4:
            raise ValueError("ArmCycle.cycle: q (>= 6,), qa (6,), F (4, 4)")
        self._play(q, &qa[0], &F[0, 0])

    def cycle_tcp(self, const double[:] q, double[::1] qa, const double[:, ::1] base_inv,
                  const double[:, ::1] tool, double[:, ::1] T):
        """:meth:`cycle` (the flange into a buffer of this object) and ``T = (base_inv @ flange)
        @ tool`` by :meth:`product`; False without :meth:`use_gemm`, before anything is set (the
        caller then runs :meth:`cycle` and multiplies with numpy)."""
        if self.gemm == NULL:
            return False
        if (q.shape[0] < 6 or qa.shape[0] != 6 or base_inv.shape[0] != 4 or base_inv.shape[1] != 4
                or tool.shape[0] != 4 or tool.shape[1] != 4 or T.shape[0] != 4 or T.shape[1] != 4):
            raise ValueError("ArmCycle.cycle_tcp: q (>= 6,), qa (6,), 4x4 frames")
        self._play(q, &qa[0], &self.flange[0, 0])
        self._product(&base_inv[0, 0], &self.flange[0, 0], &tool[0, 0], &T[0, 0])
        return True

    def use_gemm(self, size_t gemm):
        """Compute :meth:`product` with the BLAS ``cblas_dgemm`` at address `gemm` (the one
        numpy calls; 0: none)."""
        self.gemm = <_dgemm_t>gemm

    def product(self, const double[:, ::1] A, const double[:, ::1] B, const double[:, ::1] C,
                double[:, ::1] out):
        """``out = (A @ B) @ C`` for C-contiguous 4x4 float64 matrices, as numpy's ``@`` computes
        it (two ``cblas_dgemm`` calls with numpy's arguments, the first into a numpy-allocated
        4x4); False without :meth:`use_gemm` (the caller multiplies with numpy)."""
        if self.gemm == NULL:
            return False
        if (A.shape[0] != 4 or A.shape[1] != 4 or B.shape[0] != 4 or B.shape[1] != 4
                or C.shape[0] != 4 or C.shape[1] != 4 or out.shape[0] != 4 or out.shape[1] != 4):
            raise ValueError("ArmCycle.product: 4x4 matrices")
        self._product(&A[0, 0], &B[0, 0], &C[0, 0], &out[0, 0])
        return True

    cdef void _product(self, const double* A, const double* B, const double* C, double* out) noexcept:
        """out = (A @ B) @ C: numpy's two cblas_dgemm calls (row-major, no transposes, leading
        dimension 4, alpha 1, beta 0), the first into a numpy-allocated 4x4."""
        self.gemm(101, 111, 111, 4, 4, 4, 1.0, A, 4, B, 4, 0.0, &self.tmp[0, 0], 4)
        self.gemm(101, 111, 111, 4, 4, 4, 1.0, &self.tmp[0, 0], 4, C, 4, 0.0, out, 4)


# ----------------------------------------------------------------------------- trace lines
cdef extern from "Python.h":
    char* PyOS_double_to_string(double val, char format_code, int precision, int flags,
                                int* ptype) except NULL
    double PyOS_string_to_double(const char* s, char** endptr, object overflow_exception) except? -1.0
    void PyMem_Free(void* p)
    int Py_DTSF_ADD_DOT_0

from libc.string cimport memcpy, strlen
from libc.math cimport isfinite, floor

#: |x| from which pose_line leaves a number to the Python path (its 'f' text would be long)
cdef double _BIG = 1e15


cdef Py_ssize_t _put_r6(double x, char* out) except -1:
    """``repr(robot.trace._round6(x))`` into out (see :func:`_put_r6_dtoa`). Fast path: the
    correctly rounded integer n = round(x · 10^6) is that of the computed product whenever the
    product is farther from a half-integer than its rounding error; the rounded double is then
    n / 10^6 (a correctly rounded quotient of exact integers: the double nearest to the decimal
    n · 10^-6, as strtod gives), and its repr is that decimal with the trailing zeros cut
    (fewer than 16 significant digits round-trip uniquely; repr writes fixed notation from
    1e-4 on). Anything else (near a tie, below 1e-4, huge) takes the dtoa path."""
    cdef double y = x * 1e6
    cdef double fl, fr, d
    cdef long long n, a, ip, fp
    cdef Py_ssize_t k = 0, m, j
    cdef char digits[24]
    if fabs(y) < 1e14:
        fl = floor(y)
        fr = y - fl
        d = fabs(fr - 0.5)
        if d > fabs(y) * 1e-15 + 1e-12:
            n = <long long>fl + (1 if fr > 0.5 else 0)
            if n == 0:
                memcpy(out, b"0.0", 3)
                return 3
            if n >= 100 or n <= -100:
                if n < 0:
                    out[k] = b'-'
                    k += 1
                    a = -n
                else:
                    a = n
                ip = a // 1000000
                fp = a % 1000000
                m = 0
                while True:
                    digits[m] = <char>(48 + ip % 10)
                    m += 1
                    ip //= 10
                    if ip == 0:
                        break
                for j in range(m):
                    out[k] = digits[m - 1 - j]
                    k += 1
                out[k] = b'.'
                k += 1
                if fp == 0:
                    out[k] = b'0'
                    return k + 1
                m = 6
                while fp % 10 == 0:
                    fp //= 10
                    m -= 1
                for j in range(m):
                    digits[m - 1 - j] = <char>(48 + fp % 10)
                    fp //= 10
                for j in range(m):
                    out[k] = digits[j]
                    k += 1
                return k
    return _put_r6_dtoa(x, out)


cdef Py_ssize_t _put_r6_dtoa(double x, char* out) except -1:
    """``repr(robot.trace._round6(x))`` into out: CPython's round(x, 6) is the double nearest
    to x's correctly rounded 6-decimal text (Objects/floatobject.c double_round: _Py_dg_dtoa
    mode 3, then strtod), which is what ``'%.6f'`` formatting (the same dtoa call) read back
    gives; -0.0 becomes 0.0; ``repr`` is the shortest text (format 'r', '.0' added)."""
    cdef char* s = PyOS_double_to_string(x, b'f', 6, 0, NULL)
    cdef double r
    try:
        r = PyOS_string_to_double(s, NULL, None)
    finally:
        PyMem_Free(s)
    if r == 0.0:
        r = 0.0
    s = PyOS_double_to_string(r, b'r', 0, Py_DTSF_ADD_DOT_0, NULL)
    cdef Py_ssize_t n = strlen(s)
    memcpy(out, s, n)
    PyMem_Free(s)
    return n


cdef inline Py_ssize_t _put(const char* s, char* out) noexcept:
    cdef Py_ssize_t n = strlen(s)
    memcpy(out, s, n)
    return n


def pose_line(double t, axes, tcp):
    """The JSON line of a pose event (robot/trace.py ``TraceWriter.flush``): time t (s), the
    axes and the TCP frame (sequences of numbers) each rounded by ``_round6``, written as
    ``repr``; None when a number is not finite or very large (the Python path writes it)."""
    cdef char buf[2048]
    cdef Py_ssize_t n = 0, i, k
    cdef double x
    cdef list ax = [float(v) for v in axes]
    cdef list tc = [float(v) for v in tcp]
    if len(ax) > 32 or len(tc) > 32:
        return None
    if not isfinite(t) or t >= _BIG or t <= -_BIG:
        return None
    for seq in (ax, tc):
        for v in seq:
            x = v
            if not isfinite(x) or x >= _BIG or x <= -_BIG:
                return None
    n += _put(b'{"t":', buf + n)
    n += _put_r6(t, buf + n)
    n += _put(b',"kind":"pose","axes":[', buf + n)
    for k in range(2):
        seq = ax if k == 0 else tc
        if k == 1:
            n += _put(b'],"tcp":[', buf + n)
        for i in range(len(seq)):
            if i:
                buf[n] = b','
                n += 1
            n += _put_r6(seq[i], buf + n)
    n += _put(b']}', buf + n)
    return buf[:n].decode('ascii')


cdef void _gradient_rows(const double* f, double* out, int n, double h) noexcept:
    """robot/planner.py ``gradient_rows`` of the n rows (n >= 3) of 6 in f into out."""
    cdef int r, i
    cdef double c2h = 2. * h
    cdef double a0 = -1.5 / h, a1 = 2. / h, a2 = -0.5 / h
    cdef double b0 = 0.5 / h, b1 = -2. / h, b2 = 1.5 / h
    for r in range(1, n - 1):
        for i in range(6):
            out[6 * r + i] = (f[6 * (r + 1) + i] - f[6 * (r - 1) + i]) / c2h
    for i in range(6):
        out[i] = a0 * f[i] + a1 * f[6 + i] + a2 * f[12 + i]
        out[6 * (n - 1) + i] = b0 * f[6 * (n - 3) + i] + b1 * f[6 * (n - 2) + i] + b2 * f[6 * (n - 1) + i]


cdef object _array6(const double* v):
    """A new float64 array (6,) of v."""
    res = np.empty(6)
    cdef double[::1] rv = res
    cdef int i
    for i in range(6):
        rv[i] = v[i]
    return res


cdef int _rate_maxima(const double* D1, const double* D2, int N, double* d1a, double* d1b, double* qd,
                      double* qdd) noexcept:
    """:meth:`CartPath.walk`'s q' at the start and the end (d1a, d1b) and the largest |q'| and |q''|
    of each axis (qd, qdd) over the N rows of D1 and D2; 1 where one is NaN, else 0."""
    cdef int i, j, bad = 0
    cdef double x
    for i in range(6):
        d1a[i] = D1[i]
        d1b[i] = D1[6 * (N - 1) + i]
        qd[i] = fabs(D1[i])
        qdd[i] = fabs(D2[i])
        for j in range(1, N):
            x = fabs(D1[6 * j + i])
            if x > qd[i]:
                qd[i] = x
            bad |= x != x
            x = fabs(D2[6 * j + i])
            if x > qdd[i]:
                qdd[i] = x
            bad |= x != x
        bad |= (qd[i] != qd[i]) | (qdd[i] != qdd[i])
    return bad


cdef double _piece_speed(const double* qd, const double* qdd, const double[:] v_ax, const double[:] a_ax,
                         double budget, bint plain, double vmax_k) noexcept:
    """:meth:`CartPath.walk`'s speed limit of the piece: `vmax_k`, no more than each axis's speed
    over its largest |q'| and (unless `plain`) sqrt(budget/2 x its acceleration over its largest |q''|)."""
    cdef double V = INFINITY, W, t, x
    cdef int i
    for i in range(6):
        if qd[i] > 1e-9:
            x = v_ax[i] / qd[i]
            if x < V:
                V = x
    if not plain:
        W = INFINITY
        t = 0.5 * budget
        for i in range(6):
            if qdd[i] > 1e-9:
                x = sqrt(t * a_ax[i] / qdd[i])
                if x < W:
                    W = x
        if W < V:
            V = W
    return V if V < vmax_k else vmax_k


cdef double _piece_acc(const double* qd, const double* qdd, const double[:] a_ax, double budget,
                       double vmax_k) noexcept:
    """:meth:`CartPath.walk`'s axis acceleration limit of the piece at the speed `vmax_k`
    (``vmax_k ** 2`` as libm's pow)."""
    cdef double Aax = INFINITY, x
    cdef double vk2 = simcore_libm_pow(vmax_k, 2.0)
    cdef int i
    for i in range(6):
        if qd[i] > 1e-9:
            x = (budget * a_ax[i] - qdd[i] * vk2) / qd[i]
            if x < Aax:
                Aax = x
    return Aax


def blend_args(const double[::1] prev_table, prev_bounds, double v_a, double a_b, double u_a, double tau_p,
               CartPath prev_path, const double[:] prev_end, size_t ddot, CartPath next_path,
               const double[::1] next_table, next_bounds, double t_brake):
    """robot/blending.py ``plan_blend`` of a blend between two CP motions from its braking
    (``BrakeProfile``'s ``v_a``, ``a_b``, ``u_a`` on the approximated motion's time law
    `prev_table`, robot/lawtable.py's table; the window ``tau_p``) on: robot/lawtable.py ``below``
    of the braking, the distance from ``u_a`` to `prev_end` on `prev_path`
    (:meth:`CartPath.dist_to`) and robot/lawtable.py ``blend_end_ramp`` on `next_path`'s pieces
    and its time law `next_table` (with `t_brake`, the next law's ``t_brake``). Returns (u_e,
    delay) of the next motion's ``RampProfile``, False where the braking exceeds the planned speed
    (no blend before the point), or None where the path does not hold its pieces' lengths (the
    Python code decides)."""
    cdef int k
    if not lawtable.below(lawtable._BRAKE, v_a, a_b, u_a, prev_table, prev_bounds, u_a, 1.0):
        return False
    got = prev_path.dist_to(u_a, prev_end, ddot)
    if got is None:
        return None
    for k in range(next_path.n):
        if next_path.kinds[k] < 0:
            return None                 # a piece whose length the path does not hold
    return lawtable.blend_end_ramp(next_table, next_bounds, next_path.length, next_path.ub, got, u_a, t_brake,
                                   tau_p)
