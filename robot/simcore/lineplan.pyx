# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False, auto_pickle=False
"""A single LIN's plan in C (issue 39, "Simulator"; issue 76 item 5), one of robot/simcore's
modules (robot/build.py ``SIMCORE``): :func:`plan_line`, robot/cartplan.py ``plan_cart`` of one
line (for robot/cartline.py ``_planned_line``, which makes the segment), its path a
robot/simcore/cartpath.pyx ``CartPath`` walked there; :func:`line_products`, its BLAS products
for robot/segments.py's check at set-up that they are numpy's.

Bit for bit the Python code it stands for, which stays the fallback and the reference
(tests/robot/test_simcore.py compares the two): the same operations in the same order on C
doubles, libm's functions (what Python's ``math`` calls), ``degrees`` and ``radians`` as
CPython's multiplications by 180/pi and pi/180, numpy's products and dot products through the
BLAS routines numpy itself calls (robot/blas.py), and no fused multiply-add (``-ffp-contract=off``).
``SOURCE_SHA``: the sha256 of the sources it was built from (robot/build.py ``simcore_sha``).
"""

from libc.math cimport sin, cos, atan2, sqrt, M_PI, INFINITY
import numpy as np

from robot.kinematics.fastpath cimport OPWCore
from robot.simcore.capi cimport SIMCORE_SOURCE_SHA, simcore_libm_pow, dgemm_t, ddot_t, dot3
from robot.simcore.cartpath cimport CartPath

#: The sha256 of the sources this module was compiled from (robot/build.py ``simcore_sha``)
SOURCE_SHA = SIMCORE_SOURCE_SHA.decode("ascii")

cdef double DEG_TO_RAD = M_PI / 180.0
cdef double RAD_TO_DEG = 180.0 / M_PI

#: the identity numpy's ``R @ _EYE3`` multiplies with (robot/planner.py), numpy-allocated
_EYE3 = np.eye(3)
#: a line's entries of ``CartPath``'s tables that do not depend on the line (read-only)
_LINE_KIND, _LINE_MID, _LINE_R, _LINE_ANGLE, _LINE_C = (
    np.zeros(1, dtype=np.intc), np.ones(1, dtype=np.intc), np.ones(1), np.zeros(1), np.zeros((1, 3)))
for _a in (_LINE_KIND, _LINE_MID, _LINE_R, _LINE_ANGLE, _LINE_C):
    _a.setflags(write=False)


cdef void _tmul(dgemm_t gemm, const double* A, const double* B, double* out) noexcept:
    """numpy's ``A.T @ B`` of two C-contiguous float64 3x3s (its cblas_dgemm call: A transposed)."""
    gemm(101, 112, 111, 3, 3, 3, 1.0, A, 3, B, 3, 0.0, out, 3)


cdef void _mul3(dgemm_t gemm, const double* A, const double* B, double* out) noexcept:
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
    _tmul(<dgemm_t>gemm, &A[0, 0], &B[0, 0], &pv[0, 0])
    _mul3(<dgemm_t>gemm, &A[0, 0], &eye[0, 0], &qv[0, 0])
    return P, Q, dot3(<ddot_t>ddot, &v[0])


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
    geo = _line_geometry(<dgemm_t>gemm, <ddot_t>ddot, R0, R1, p0, p1)
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


cdef object _line_geometry(dgemm_t mm, ddot_t dd, R0, R1, p0, p1):
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
    L = sqrt(dot3(dd, &dv[0]))
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
    if not sqrt(dot3(dd, &rvv[0])) < 1e-12:
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
