# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False, auto_pickle=False
"""The compiled paths of CP motions (issue 39, "Simulator"; issue 47; issue 76 item 5), one of
robot/simcore's modules (robot/build.py ``SIMCORE``):

* :class:`CartPath`: the poses of a CP segment's lines and arcs (robot/segments.py
  ``CartSegment.pose_u``) and their axes (robot/kinematics/fastpath.py's ``OPWCore``, compiled
  from that Python file), through the motion's ``$BASE`` and ``$TOOL`` where it has them
  (``RobotModel.ik``'s two products, numpy's BLAS at its address), the planning walk of a piece
  (robot/cartlaw.py ``_CartWalk``), the distance to the path's end
  (``CartSegment.tcp_dist_to_end``) and a Cartesian blend's setpoint (robot/blending.py
  ``blend_setpoint``); its pieces' lengths, path parameters and kinds are read-only attributes
  (robot/blending.py ``_cart_blend`` gives them to robot/lawtable.py ``blend_end_ramp``).

Each is bit for bit the Python code it stands for, which stays the fallback and the reference
(tests/robot/test_simcore.py compares the two): the same operations in the same order on C
doubles, libm's functions (what Python's ``math`` calls), numpy's products through the BLAS
routine numpy itself calls (robot/blas.py), ``float ** 2`` as libm's pow, and no fused
multiply-add (compiled with ``-ffp-contract=off``). ``SOURCE_SHA``: the sha256 of the sources it
was built from (robot/build.py ``simcore_sha``): a stale build is not used. Its objects live in
one process and are never pickled (``auto_pickle=False``: Cython's generated unpickling of a C
array attribute copied past the array's end, robot/kinematics/pal4rows.py says the same).
"""

from libc.math cimport sin, cos, sqrt, fabs, copysign, INFINITY
from cpython.mem cimport PyMem_Malloc, PyMem_Free
import numpy as np

from robot.kinematics.fastpath cimport OPWCore
from robot cimport lawtable
from robot.simcore.capi cimport SIMCORE_SOURCE_SHA, simcore_libm_pow, dgemm_t, ddot_t, dot3

#: The sha256 of the sources this module was compiled from (robot/build.py ``simcore_sha``;
#: robot/simcore/__init__.py compares it with the files': a stale build is not used)
SOURCE_SHA = SIMCORE_SOURCE_SHA.decode("ascii")


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

    # its attributes: robot/simcore/cartpath.pxd

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
        return sqrt(dot3(<ddot_t>ddot, d))

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
        (<dgemm_t>gemm)(101, 111, 112, 3, 3, 3, 1.0, &b[0, 0, 0], 3, &b[1, 0, 0], 3, 0.0, &b[3, 0, 0], 3)
        (<dgemm_t>gemm)(101, 111, 111, 3, 3, 3, 1.0, &b[3, 0, 0], 3, &b[2, 0, 0], 3, 0.0, &b[0, 0, 0], 3)
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
        (<dgemm_t>gemm)(101, 111, 112, 3, 3, 3, 1.0, &b[0, 0, 0], 3, &b[1, 0, 0], 3, 0.0, &b[3, 0, 0], 3)
        (<dgemm_t>gemm)(101, 111, 111, 3, 3, 3, 1.0, &b[3, 0, 0], 3, &b[2, 0, 0], 3, 0.0, &b[0, 0, 0], 3)
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
        self.gemm = <dgemm_t>gemm
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
