# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The simulator's hot path in C (issue 39, "Simulator"), built by robot/build.py:

* :class:`OPW`: the OPW inverse kinematics of one pose (and along a chain of poses), the
  compiled form of robot/kinematics.py ``Kinematics._opw_core`` + ``_status_row`` + the
  selection of ``Kinematics._select`` for the six-axis arm with a spherical wrist;
* :class:`CartPath`: the poses of a CP segment's lines and arcs (robot/planner.py
  ``CartSegment.pose_u``) and their axes;
* :class:`ArmCycle` and :func:`speed_ok`: the IPO cycle's MuJoCo playback with its TCP product,
  and its axis step check (robot/controller.py ``Controller.step``);
* :func:`pose_line`: the trace's pose line (robot/trace.py).

Bit for bit the pure-Python code it mirrors, which stays the fallback (and the reference:
tests/robot/test_simcore.py compares the two on random poses): the same operations in the same
order on C doubles, libm's sin/cos/atan2/acos/sqrt (what Python's ``math`` calls), ``degrees``
and ``radians`` as CPython's multiplications by 180/pi and pi/180, Python's float ``%`` as
CPython's ``float_rem``, and no fused multiply-add (compiled with ``-ffp-contract=off``).

:meth:`OPW.inverse` answers the selected axes, or None whenever the Python code would raise or
takes a path not mirrored here (no solution, no solution with the status, none within the
limits): the caller then runs the Python code, which gives the error with its message.
"""

from libc.math cimport sin, cos, atan2, acos, sqrt, fmod, copysign, fabs, M_PI, INFINITY
import numpy as np

#: Bumped whenever the mirrored Python code changes (robot/kinematics.py checks it: a stale
#: build is not used).
ABI = 4

cdef double DEG_TO_RAD = M_PI / 180.0
cdef double RAD_TO_DEG = 180.0 / M_PI
cdef double BOUNDARY_EPS = 1e-9
cdef double WRIST_SINGULAR_DEG = 1e-6
cdef double OVERHEAD_SINGULAR_MM = 1e-6
cdef double ACOS_TOL = 1e-9


cdef inline double _pymod(double vx, double wx) noexcept nogil:
    """CPython's float ``vx % wx`` (Objects/floatobject.c float_rem), wx != 0."""
    cdef double mod = fmod(vx, wx)
    if mod != 0.0:
        if (wx < 0) != (mod < 0):
            mod += wx
    else:
        mod = copysign(0.0, wx)
    return mod


cdef inline double _wrapdeg(double th, double off, double sg) noexcept nogil:
    # -((-degrees((th + off) * sg) + 180.0) % 360.0) + 180.0
    return -_pymod(-((th + off) * sg * RAD_TO_DEG) + 180.0, 360.0) + 180.0


cdef class OPW:
    """The constants of one robot's OPW solution and soft limits (see robot/kinematics.py)."""

    cdef double a1, a2, b, c1, c2, c3, c4, kappa_2, c2_2, k, at23, phi
    cdef double sgn[6]
    cdef double offs[6]
    cdef double lo[6]
    cdef double hi[6]
    cdef double ks[5]
    cdef int s_free, t_free

    def __init__(self, o, double kappa_2, double c2_2, double k, double at23, double phi,
                 sgn, offs, lo, hi, ks, int s_free, int t_free):
        cdef int i
        self.a1, self.a2, self.b = o.a1, o.a2, o.b
        self.c1, self.c2, self.c3, self.c4 = o.c1, o.c2, o.c3, o.c4
        self.kappa_2, self.c2_2, self.k, self.at23, self.phi = kappa_2, c2_2, k, at23, phi
        for i in range(6):
            self.sgn[i] = sgn[i]
            self.offs[i] = offs[i]
            self.lo[i] = lo[i]
            self.hi[i] = hi[i]
        for i in range(5):
            self.ks[i] = ks[i]
        self.s_free, self.t_free = s_free, t_free

    cdef inline void _status_row(self, const double* q, int* s, int* amb) noexcept nogil:
        cdef double t2 = (self.sgn[1] * q[1]) * DEG_TO_RAD - self.offs[1]
        cdef double t23 = t2 + (self.sgn[2] * q[2]) * DEG_TO_RAD - self.offs[2]
        cdef double xw = self.a1 + self.c2 * sin(t2) + self.c3 * sin(t23) + self.a2 * cos(t23)
        cdef double phi = self.phi
        s[0] = (<int>(xw < -BOUNDARY_EPS)) | ((<int>(q[2] >= phi - BOUNDARY_EPS)) << 1) \
            | ((<int>(q[4] < -BOUNDARY_EPS)) << 2)
        amb[0] = (<int>(fabs(xw) < OVERHEAD_SINGULAR_MM)) | ((<int>(fabs(q[2] - phi) < 1e-7)) << 1) \
            | ((<int>(fabs(q[4]) < WRIST_SINGULAR_DEG)) << 2) | self.s_free

    cdef int _core(self, const double* M, const double* ref, double* out) noexcept nogil:
        """``Kinematics._opw_core(T, ref)`` of the pose M (the first three rows of T, 12
        values): the solutions into out (8 x 6), their number."""
        cdef double r00 = M[0], r01 = M[1], r02 = M[2], px = M[3]
        cdef double r10 = M[4], r11 = M[5], r12 = M[6], py = M[7]
        cdef double r20 = M[8], r21 = M[9], r22 = M[10], pz = M[11]
        cdef double cx = px - self.c4 * r02
        cdef double cy = py - self.c4 * r12
        cdef double cz = pz - self.c4 * r22
        cdef double rho2 = cx * cx + cy * cy - self.b * self.b
        cdef double nx1, tmp1, tmp2, th1_i, th1_ii, tmp3, s1_2, tmp4, s2_2, s1, s2
        cdef double th1, s_, s_2, base2, arg2, arg3, a2c, a3c, v
        cdef double arm[4][3]
        cdef int narm = 0, n = 0, j, i
        cdef double th2, th3, sn1, cs1, s23, c23, mm, th4, th5, th6, total
        cdef double sol[6]
        if rho2 < 0.0:
            return 0
        nx1 = sqrt(rho2) - self.a1
        if sqrt(cx * cx + cy * cy) < OVERHEAD_SINGULAR_MM:
            tmp1 = (self.sgn[0] * ref[0]) * DEG_TO_RAD - self.offs[0]
        else:
            tmp1 = atan2(cy, cx)
        tmp2 = atan2(self.b, nx1 + self.a1)
        th1_i = tmp1 - tmp2
        th1_ii = tmp1 + tmp2 - M_PI
        tmp3 = cz - self.c1
        s1_2 = nx1 * nx1 + tmp3 * tmp3
        tmp4 = nx1 + 2.0 * self.a1
        s2_2 = tmp4 * tmp4 + tmp3 * tmp3
        s1 = sqrt(s1_2)
        s2 = sqrt(s2_2)
        for j in range(2):
            if j == 0:
                th1, s_, s_2, base2 = th1_i, s1, s1_2, atan2(nx1, tmp3)
            else:
                th1, s_, s_2, base2 = th1_ii, s2, s2_2, -atan2(tmp4, tmp3)
            if s_ < 1e-12:
                continue
            arg2 = (s_2 + self.c2_2 - self.kappa_2) / (2.0 * s_ * self.c2)
            arg3 = (s_2 - self.c2_2 - self.kappa_2) / (2.0 * self.c2 * self.k)
            if fabs(arg2) > 1.0 + ACOS_TOL or fabs(arg3) > 1.0 + ACOS_TOL:
                continue
            # math.acos(min(1.0, max(-1.0, arg)))
            v = arg2 if arg2 > -1.0 else -1.0
            a2c = acos(v if v < 1.0 else 1.0)
            v = arg3 if arg3 > -1.0 else -1.0
            a3c = acos(v if v < 1.0 else 1.0)
            arm[narm][0], arm[narm][1], arm[narm][2] = th1, -a2c + base2, a3c - self.at23
            narm += 1
            arm[narm][0], arm[narm][1], arm[narm][2] = th1, a2c + base2, -a3c - self.at23
            narm += 1
        for j in range(narm):
            th1, th2, th3 = arm[j][0], arm[j][1], arm[j][2]
            sn1, cs1 = sin(th1), cos(th1)
            s23, c23 = sin(th2 + th3), cos(th2 + th3)
            mm = r02 * s23 * cs1 + r12 * s23 * sn1 + r22 * c23
            v = 1.0 - mm * mm
            th5 = atan2(sqrt(v if v > 0.0 else 0.0), mm)
            th4 = atan2(r12 * cs1 - r02 * sn1,
                        r02 * c23 * cs1 + r12 * c23 * sn1 - r22 * s23)
            th6 = atan2(r01 * s23 * cs1 + r11 * s23 * sn1 + r21 * c23,
                        -r00 * s23 * cs1 - r10 * s23 * sn1 - r20 * c23)
            if fabs(th5 * RAD_TO_DEG) < WRIST_SINGULAR_DEG:
                total = th4 + th6
                th4 = (self.sgn[3] * ref[3]) * DEG_TO_RAD - self.offs[3]
                th6 = total - th4
            sol[0], sol[1], sol[2], sol[3], sol[4], sol[5] = th1, th2, th3, th4, th5, th6
            for i in range(6):
                out[6 * n + i] = _wrapdeg(sol[i], self.offs[i], self.sgn[i])
            n += 1
            sol[3], sol[4], sol[5] = th4 + M_PI, -th5, th6 - M_PI
            for i in range(6):
                out[6 * n + i] = _wrapdeg(sol[i], self.offs[i], self.sgn[i])
            n += 1
        return n

    def inverse(self, const double[:, :] T, status, turn, const double[:] ref6):
        """``Kinematics.inverse`` of the flange pose T (4x4, mm, the OPW arm's own frame) for
        the reference ref6 (6 axes, deg): the axes (6,) as a numpy array, or None where the
        Python code raises (the caller runs it for the error)."""
        cdef double M[12]
        cdef int i, j
        for i in range(3):
            for j in range(4):
                M[4 * i + j] = T[i, j]
        return self._inverse(M, status, turn, ref6)

    def inverse_rp(self, const double[:, :] R, const double[:] p, status, turn, const double[:] ref6):
        """:meth:`inverse` of the pose with rotation R (3x3) and position p (3,, mm)."""
        cdef double M[12]
        cdef int i, j
        for i in range(3):
            for j in range(3):
                M[4 * i + j] = R[i, j]
            M[4 * i + 3] = p[i]
        return self._inverse(M, status, turn, ref6)

    def inverse_chain_rp(self, const double[:, :, :] R, const double[:, :] p, status, turn,
                         const double[:] ref6):
        """:meth:`inverse_rp` of each pose (R[j] (3x3), p[j] (3,)) in turn, each solution the
        next one's reference (the first one's: ref6): the axes (n, 6), the rows those of n
        calls of :meth:`inverse_rp` bit for bit, or None as soon as one of them would be None
        (the caller then solves pose by pose for the error). Issue 39: the planner's samples
        of a CP segment."""
        cdef Py_ssize_t n = R.shape[0], j
        cdef double M[12]
        cdef double ref[6]
        cdef int i, k
        if p.shape[0] != n:
            raise ValueError("R and p hold different numbers of poses")
        res = np.empty((n, 6))
        cdef double[:, :] out = res
        for i in range(6):
            ref[i] = ref6[i]
        for j in range(n):
            for i in range(3):
                for k in range(3):
                    M[4 * i + k] = R[j, i, k]
                M[4 * i + 3] = p[j, i]
            if not self._solve(M, status, turn, ref, &out[j, 0]):
                return None
            for i in range(6):
                ref[i] = out[j, i]
        return res

    cdef object _inverse(self, const double* M, status, turn, const double[:] ref6):
        cdef double ref[6]
        cdef double[:] rv
        cdef int i
        for i in range(6):
            ref[i] = ref6[i]
        res = np.empty(6)
        rv = res
        if not self._solve(M, status, turn, ref, &rv[0]):
            return None
        return res

    cdef int _solve(self, const double* M, status, turn, const double* ref, double* best_q) except -1:
        """The selected axes of pose M (3x4, row-major) for the reference `ref` into best_q;
        0 where the Python code raises or takes a path not mirrored here."""
        cdef double rows[48]
        cdef double q[6]
        cdef int i, j, kk, n, s_target, free, keep, s_r, amb, tmask = 0, use_turn = 0
        cdef int nmatch = 0, have_best = 0, ok
        cdef double c, d, best_c, best_d, cost, best_cost = 0.0
        cdef int found
        cdef const double* b
        n = self._core(M, ref, rows)
        if n == 0:
            return 0
        if status is not None:
            s_target = (<int>status) & 7
            free = 0
        else:
            self._status_row(ref, &s_target, &free)
        keep = ~free
        if turn is not None:
            tmask = (<int>turn) & ~self.t_free
            use_turn = 1
        for j in range(n):
            b = &rows[6 * j]
            self._status_row(b, &s_r, &amb)
            if ((s_r ^ s_target) & ~amb & keep & 7) != 0:
                continue
            nmatch += 1
            ok = 1
            for i in range(6):
                found = 0
                best_c = 0.0
                best_d = INFINITY
                for kk in range(5):
                    c = b[i] + self.ks[kk]
                    if c < self.lo[i] or c > self.hi[i]:
                        continue
                    if use_turn and not (((c < 0) == (((tmask >> i) & 1) == 1)) or fabs(c) < 1e-6
                                         or ((self.t_free >> i) & 1) == 1):
                        continue
                    d = fabs(c - ref[i])
                    if d < best_d:
                        best_c, best_d = c, d
                        found = 1
                if not found:
                    ok = 0
                    break
                q[i] = best_c
            if ok:
                cost = 0.0
                for i in range(6):
                    cost += fabs(q[i] - ref[i])
                if not have_best or cost < best_cost:
                    have_best = 1
                    best_cost = cost
                    for i in range(6):
                        best_q[i] = q[i]
        return have_best




# ----------------------------------------------------------------------------- CP paths
cdef class CartPath:
    """The poses of a CP segment's lines and arcs, and their axes (``opw`` None: the poses only) (robot/planner.py
    ``CartSegment.pose_u`` and ``CartSegment.ik`` with the compiled inverse, the same numbers):
    for path parameter u the piece k and fraction f of ``CartSegment._locate``, the position
    ``LinePiece.pos``/``ArcPiece.pos`` at ``s = f * length`` (libm's cos and sin, as ``math``)
    and the rotation the segment keeps for that piece (at its start, within it and at its end:
    the matrices the Python code holds; a rotation it would compute, such as a slerp between
    two orientations, is not mirrored). A pose not mirrored (such a rotation, a spline piece)
    gives None: the caller runs the Python code.

    ``kinds`` per piece: 0 line (``a`` = p0, ``b`` = dir), 1 arc (``a`` = centre, ``b`` = e1,
    ``c`` = e2, ``r``, ``angle``), -1 not mirrored; ``rots`` (n, 3, 3, 3): the rotation at
    f <= 0, within, at f >= 1; ``mid_ok`` 0 where the rotation within is not mirrored."""

    cdef OPW opw
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

    def __init__(self, OPW opw, ub, kinds, mid_ok, length, r, angle, a, b, c, rots):
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
            # bisect_right(ub, u) - 1
            lo, hi = 0, n + 1
            while lo < hi:
                mid = (lo + hi) // 2
                if u < self.ub[mid]:
                    hi = mid
                else:
                    lo = mid + 1
            k = lo - 1
            if k < 0:
                k = 0
            if k > n - 1:
                k = n - 1
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

    def axes_u(self, double u, status, const double[:] ref6):
        """The axes (6,) at u for the reference ref6 (``CartSegment.ik`` of ``pose_u(u)``), or
        None (not mirrored, or the Python inverse decides)."""
        cdef double M[12]
        cdef double ref[6]
        cdef int i
        if self.opw is None or ref6.shape[0] != 6 or not self._pose(u, M):
            return None
        for i in range(6):
            ref[i] = ref6[i]
        res = np.empty(6)
        cdef double[::1] rv = res
        if not self.opw._solve(M, status, None, ref, &rv[0]):
            return None
        return res

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
            if not self.opw._solve(M, status, None, ref, &out[j, 0]):
                return None
            for i in range(6):
                ref[i] = out[j, i]
        return res


# ----------------------------------------------------------------------------- the IPO cycle
def speed_ok(const double[:] q, const double[:] q_prev, const double[:] lim):
    """True when no axis moves more than its limit in one cycle: ``abs(q[i] - q_prev[i]) <=
    lim[i]`` over the shortest of the three (robot/controller.py ``_check_speed``, which gives
    the error on False; a NaN step passes, as there)."""
    cdef Py_ssize_t n = min(q.shape[0], q_prev.shape[0], lim.shape[0]), i
    for i in range(n):
        if fabs(q[i] - q_prev[i]) > lim[i]:
            return False
    return True


ctypedef void (*_mj_kinematics_t)(const void* m, void* d) noexcept nogil
#: cblas_dgemm of an ILP64 BLAS (numpy's own: the product numpy's ``@`` computes for two
#: C-contiguous float64 4x4 matrices is this call, row-major, no transposes, alpha 1, beta 0)
ctypedef void (*_dgemm_t)(int order, int ta, int tb, long long m, long long n, long long k,
                          double alpha, const double* a, long long lda, const double* b,
                          long long ldb, double beta, double* c, long long ldc) noexcept nogil


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
