# cython: boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False, auto_pickle=False
"""The compiled paths of CP motions (issue 39, "Simulator"; issue 47; issue 76 item 5), written once
in Python and compiled by Cython from this very file (the C types in cartpath.pxd beside it;
robot/build.py ``PURE``); without a compiler it runs as it stands (robot/kinematics/compiled.py
``pure_module`` picks the one in use):

* :class:`CartPath`: the poses of a CP segment's lines and arcs (robot/segments.py
  ``CartSegment.pose_u``) and their axes (robot/kinematics/fastpath.py's ``OPWCore``), through the
  motion's ``$BASE`` and ``$TOOL`` where it has them (``RobotModel.ik``'s two products), the
  planning walk of a piece (robot/cartlaw.py ``_CartWalk``), the distance to the path's end
  (``CartSegment.tcp_dist_to_end``) and a Cartesian blend's setpoint (robot/blending.py
  ``blend_setpoint``); its pieces' lengths, path parameters and kinds are read-only attributes
  (robot/blending.py ``_cart_blend`` gives them to robot/lawtable.py ``blend_end_ramp``);
* :func:`plan_line`: robot/cartplan.py ``plan_cart`` of a single LIN (for robot/cartline.py
  ``_planned_line``, which makes the segment), its path a :class:`CartPath` walked there;
* :func:`line_products`, :func:`superpose_products`: their BLAS products, for the checks at set-up
  (robot/segments.py ``_line_blas``, robot/blending.py ``_superpose_gemm``) that they are numpy's.

Issue 76 item 5: these were hand mirrors in C (robot/simcore/cartpath.pyx and lineplan.pyx) of the
Python code named above, which stays the general code (splines, slerps, ``#JOINT``, external
axes) and the reference; this file is now the one source of both the compiled path and its Python
form. Where the compiled module calls C through an address the branches on ``_COMPILED`` say so:
numpy's products and dot products are numpy's own BLAS routines (``cblas_dgemm``, ``cblas_ddot``,
robot/blas.py gives their addresses) with the arguments numpy passes; as Python they are numpy's
``@`` and ``dot``. Every other operation is the same on IEEE doubles either way (no fused
multiply-add: robot/build.py ``-ffp-contract=off``; libm's sin, cos, atan2, copysign and sqrt both
ways; ``float ** 2`` as libm's pow; ``radians`` and ``degrees`` as CPython's multiplications by
pi/180 and 180/pi), so the two give the same bits (tests/robot/test_simcore.py compares both with
the Python code above). Its objects live in one process and are never pickled (``auto_pickle``:
Cython's generated unpickling of a C array attribute copied past the array's end,
robot/kinematics/pal4rows.py says the same).
"""

from math import *  # noqa: F403  (sin, cos, atan2, copysign, sqrt, inf, pi: cartpath.pxd declares libm's as C's)

import numpy as np

from robot import lawtable

try:
    import cython
    COMPILED = cython.compiled
except ImportError:     # an install without Cython (a need of the build only): this file as Python
    COMPILED = False
#: :data:`COMPILED` as the compiled branches test it (a C constant of cartpath.pxd when compiled)
_COMPILED = COMPILED

#: CPython's ``math.radians`` and ``math.degrees`` factors (Modules/mathmodule.c: pi / 180, 180 / pi)
DEG_TO_RAD = pi / 180.0  # noqa: F405
RAD_TO_DEG = 180.0 / pi  # noqa: F405
#: cblas's row-major, no-transpose and transpose (numpy's arguments)
_ROW, _NOTRANS, _TRANS = 101, 111, 112
#: :attr:`CartPath.frames`' rows, each a 4x4 row by row: $BASE (pre), INV_POS($TOOL) (post), the pose T, a product F
_PRE, _POST, _T, _F = 0, 1, 2, 3


def built_from() -> str:
    """The sha256 of cartpath.py and cartpath.pxd the compiled module was built from
    (robot/build.py embeds it); "" as Python."""
    if _COMPILED:
        return cartpath_source_sha().decode("ascii")  # noqa: F821  (cartpath.pxd's C constant)
    return ""


class CartPath:
    """The poses of a CP segment's lines and arcs, and their axes (``opw``: robot/kinematics/fastpath.py's
    ``OPWCore``, compiled with this module, as Python without; None: the poses only)
    (robot/segments.py ``CartSegment.pose_u`` and ``CartSegment.ik`` with that inverse, the same numbers):
    for path parameter u the piece k and fraction f of ``CartSegment._locate``, the position
    ``LinePiece.pos``/``ArcPiece.pos`` at ``s = f * length`` (libm's cos and sin, as ``math``)
    and the rotation the segment keeps for that piece (at its start, within it and at its end:
    the matrices the Python code holds; within a ``$ORI_TYPE #VAR`` piece whose orientation turns,
    the slerp ``CartSegment.pose_u`` computes, ``R0 @ rotvec_matrix(f * rotvec)``, where
    :meth:`use_turns` gave the rotation vectors: robot/pathpieces.py ``rotvec_matrix``'s
    operations on libm's sqrt, sin and cos, and numpy's product through its ``cblas_dgemm``).
    A pose not here (a rotation it does not hold, a spline piece) gives None: the caller runs
    the Python code.

    ``kinds`` per piece (int32): 0 line (``a`` = p0, ``b`` = dir), 1 arc (``a`` = centre, ``b`` = e1,
    ``c`` = e2, ``r``, ``angle``), -1 not here; ``rots`` (n, 3, 3, 3): the rotation at f <= 0, within,
    at f >= 1; ``mid_ok`` (int32) 0 where the rotation within is not here; ``ub`` (n + 1,) the
    pieces' path parameters, ``length`` (n,) mm. Raises ValueError for inconsistent tables."""

    def __init__(self, opw, ub, kinds, mid_ok, length, r, angle, a, b, c, rots):
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
        self.has_pre = self.has_post = 0
        self.poses = np.empty((4, 12))      # scratch poses (3x4 row by row): the pose, a blend's three
        self.ref = np.empty(6)              # scratch reference axes
        self.v3 = np.empty(3)               # scratch vector
        self.step = 0.0
        self.tgemm = 0                      # use_turns: the BLAS address of the slerps' products (0: none)
        self.turns = np.empty((2, 3, 3))    # scratch: a slerp's rotvec_matrix, then its product

    def use_turns(self, gemm, rv, turn_ok):
        """Compute the slerp within piece k where ``turn_ok[k]`` (int32 (n,)): ``rots[k, 0] @
        rotvec_matrix(f * rv[k])`` (``rv`` (n, 3), rad: the rotation vector from the piece's start
        orientation to its end's, robot/segments.py ``CartSegment._rv``), the product numpy's ``@``
        (compiled through the ``cblas_dgemm`` at address `gemm`, as numpy calls it for two C-contiguous
        3x3s). Raises ValueError without a BLAS address or for other shapes."""
        if gemm == 0 or rv.shape[0] != self.n or rv.shape[1] != 3 or turn_ok.shape[0] != self.n:
            raise ValueError("CartPath.use_turns: a BLAS address, rv (n, 3), turn_ok (n,)")
        self.keep_turns = (rv, turn_ok)
        self.rv, self.turn_ok = rv, turn_ok
        self.tgemm = gemm

    def _turned(self, k, f, M, m):
        """Row m of M's rotation: the slerp of piece k at fraction f (:meth:`use_turns`): robot/
        pathpieces.py ``rotvec_matrix(f * rv[k])`` operation by operation, then ``rots[k, 0] @`` it."""
        x = f * self.rv[k, 0]
        y = f * self.rv[k, 1]
        z = f * self.rv[k, 2]
        t = self.turns
        th = sqrt(x * x + y * y + z * z)  # noqa: F405
        if th < 1e-12:
            for i in range(3):
                for j in range(3):
                    t[0, i, j] = 1.0 if i == j else 0.0
        else:
            sn = sin(th)  # noqa: F405
            cs = cos(th)  # noqa: F405
            x, y, z = x / th, y / th, z / th
            C = 1.0 - cs
            t[0, 0, 0] = cs + x * x * C
            t[0, 0, 1] = x * y * C - z * sn
            t[0, 0, 2] = x * z * C + y * sn
            t[0, 1, 0] = y * x * C + z * sn
            t[0, 1, 1] = cs + y * y * C
            t[0, 1, 2] = y * z * C - x * sn
            t[0, 2, 0] = z * x * C - y * sn
            t[0, 2, 1] = z * y * C + x * sn
            t[0, 2, 2] = cs + z * z * C
        if _COMPILED:
            cython.cast(dgemm_t, self.tgemm)(_ROW, _NOTRANS, _NOTRANS, 3, 3, 3, 1.0,  # noqa: F821
                                             cython.address(self.rots[k, 0, 0, 0]), 3, cython.address(t[0, 0, 0]), 3,
                                             0.0, cython.address(t[1, 0, 0]), 3)
        else:
            tt = np.asarray(t)
            tt[1] = np.asarray(self.rots[k, 0]) @ tt[0]
        for i in range(3):
            for j in range(3):
                M[m, 4 * i + j] = t[1, i, j]

    def _pose(self, u, M, m):
        """The pose at u into row m of M (3x4, row by row); 0: not here."""
        n = self.n
        if u <= 0.0:
            k, f = 0, 0.0
        elif u >= 1.0:
            k, f = n - 1, 1.0
        else:
            k = lawtable.piece_of(self.ub, n, u)
            du = self.ub[k + 1] - self.ub[k]
            f = (u - self.ub[k]) / du if du > 0 else 1.0
        kind = self.kinds[k]
        if kind < 0:
            return 0
        if f <= 0.0:
            w = 0
        elif f >= 1.0:
            w = 2
        elif self.mid_ok[k]:
            w = 1
        elif self.tgemm != 0 and self.turn_ok[k]:
            w = -1                          # the slerp (_turned)
        else:
            return 0
        s = f * self.length[k]
        if kind == 0:
            for i in range(3):
                M[m, 4 * i + 3] = self.a[k, i] + self.b[k, i] * s
        else:
            ph = copysign(s / self.r[k], self.angle[k]) if self.r[k] > 0 else 0.0  # noqa: F405
            cs = cos(ph)  # noqa: F405
            sn = sin(ph)  # noqa: F405
            for i in range(3):
                M[m, 4 * i + 3] = self.a[k, i] + self.r[k] * (cs * self.b[k, i] + sn * self.c[k, i])
        if w < 0:
            self._turned(k, f, M, m)
            return 1
        for i in range(3):
            for j in range(3):
                M[m, 4 * i + j] = self.rots[k, w, i, j]
        return 1

    def pose_u(self, u):
        """(p (3,), R (3, 3)) at u, or None (not here)."""
        M = self.poses
        if not self._pose(u, M, 0):
            return None
        p = np.empty(3)
        pv = p
        R = np.empty((3, 3))
        Rv = R
        for i in range(3):
            pv[i] = M[0, 4 * i + 3]
            for j in range(3):
                Rv[i, j] = M[0, 4 * i + j]
        return p, R

    def _solve(self, M, m, st, ref, r0, out, o):
        """fastpath's ``OPWCore.solve`` of the pose in row m of M (3x4) with the status st (-1: none,
        :func:`_st`) for the reference ref[r0:r0 + 6] (turn None) into out[o:o + 6]; 0 where
        ``CartSegment.ik`` raises."""
        opw = self.opw
        has_status = 1 if st >= 0 else 0
        if st < 0:
            st = 0
        if self.has_pre or self.has_post:
            src = self._flange(M, m)
            for i in range(12):
                opw.M[i] = self.frames[src, i]
        else:
            for i in range(12):
                opw.M[i] = M[m, i]
        for i in range(6):
            opw.ref[i] = ref[r0 + i]
        if not opw.solve(has_status, st, 0, 0):
            return 0
        for i in range(6):
            out[o + i] = opw.q[i]
        return 1

    def _axes(self, M, m, st, ref6):
        """The axes (6,) of the pose in row m of M with the status st (:func:`_st`) for the reference
        ref6 (a new array), or None."""
        ref = self.ref
        for i in range(6):
            ref[i] = ref6[i]
        res = np.empty(6)
        if not self._solve(M, m, st, ref, 0, res, 0):
            return None
        return res

    def axes_u(self, u, status, ref6):
        """The axes (6,) at u for the reference ref6 (``CartSegment.ik`` of ``pose_u(u)``), or
        None (not here, or the Python inverse decides)."""
        if self.opw is None or ref6.shape[0] != 6 or not self._pose(u, self.poses, 0):
            return None
        return self._axes(self.poses, 0, _st(status), ref6)

    def chain_u(self, us, status, ref6):
        """:meth:`axes_u` at each u of us in turn, each solution the next one's reference (the
        first one's: ref6): (n, 6), or None as soon as one would be None."""
        n = us.shape[0]
        if self.opw is None or ref6.shape[0] != 6:
            return None
        res = np.empty((n, 6))
        out = res.reshape(6 * n)
        st = _st(status)
        ref = self.ref
        for i in range(6):
            ref[i] = ref6[i]
        for j in range(n):
            if not self._pose(us[j], self.poses, 0):
                return None
            if j == 0:
                if not self._solve(self.poses, 0, st, ref, 0, out, 0):
                    return None
            elif not self._solve(self.poses, 0, st, out, 6 * (j - 1), out, 6 * j):
                return None
        return res

    def walk(self, u0, u1, nk, status, start6, chain_from, budget, plain, v_ax, a_ax, vmax_k, max_jump, step_deg,
             max_samples):
        """robot/cartlaw.py's walk of a piece from u0 to u1 whose axes :meth:`chain_u`
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
        if (self.opw is None or start6.shape[0] != 6 or v_ax.shape[0] != 6 or a_ax.shape[0] != 6
                or nk < 2 or max_samples < nk):
            return None
        B = np.empty((3, (max_samples + 1) * 6))    # the samples' axes, q', q'' (rows of 6)
        Q = B[0]
        D1 = B[1]
        D2 = B[2]
        N = self._chain_samples(u0, u1, nk, _st(status), start6, chain_from, max_jump, step_deg, max_samples, Q)
        if N < 0:
            return None
        step = self.step
        h = (1.0 * step + u0) - u0
        if not h > 0:
            return None
        _gradient_rows(Q, D1, N, h)
        _gradient_rows(D1, D2, N, h)
        res = np.empty((5, 6))          # the end axes, q' at the start and the end, |q'| and |q''| max
        R = res
        if _rate_maxima(D1, D2, N, R[1], R[2], R[3], R[4]):
            return None
        for i in range(6):
            R[0, i] = Q[6 * (N - 1) + i]
        vmax_k = _piece_speed(R[3], R[4], v_ax, a_ax, budget, plain, vmax_k)
        Aax = inf if plain else _piece_acc(R[3], R[4], a_ax, budget, vmax_k)  # noqa: F405
        # float: Python's, not numpy's
        return res[0], res[1], res[2], res[3], res[4], float(vmax_k), None if plain else float(Aax)

    def _chain_samples(self, u0, u1, nk, st, start6, chain_from, max_jump, step_deg, max_samples, Q):
        """:meth:`walk`'s samples: ``np.linspace(u0, u1, nk + 1)`` solved in a chain from start6 into
        the rows of 6 of Q, more samples while an axis turns more than `step_deg` between two (up to
        `max_samples`); the row count N (the step in :attr:`step`), or -1 where the Python code
        decides (``nk`` reaching `chain_from`, a step of 0, an unsolved pose, a turn over `max_jump`
        or NaN)."""
        M = self.poses
        while True:
            if nk >= chain_from:
                return -1
            step = (u1 - u0) / nk           # np.linspace: i * step + start, stop last
            if step == 0:
                return -1
            for i in range(6):
                Q[i] = start6[i]
            for j in range(1, nk + 1):
                if not self._pose(j * step + u0 if j < nk else u1, M, 0):
                    return -1
                if not self._solve(M, 0, st, Q, 6 * (j - 1), Q, 6 * j):
                    return -1
            biggest = 0.0
            for j in range(nk):
                for i in range(6):
                    x = abs(Q[6 * (j + 1) + i] - Q[6 * j + i])
                    if x != x or x > max_jump:
                        return -1
                    if x > biggest:
                        biggest = x
            if biggest <= step_deg or nk >= max_samples:
                self.step = step
                return nk + 1
            if _COMPILED:
                nk = cython.cast(cython.int, nk * biggest / step_deg) + 1
            else:
                nk = int(nk * biggest / step_deg) + 1
            if nk > max_samples:
                nk = max_samples

    def dist_to(self, u, end, ddot):
        """robot/segments.py ``CartSegment.tcp_dist_to_end``: ``norm3(pose_u(u)[0] - end)`` (numpy's
        dot product, compiled through its ``cblas_ddot`` at address `ddot`), or None (a pose not here)."""
        M = self.poses
        d = self.v3
        if ddot == 0 or end.shape[0] != 3 or not self._pose(u, M, 0):
            return None
        for i in range(3):
            d[i] = M[0, 4 * i + 3] - end[i]
        return sqrt(_dot3(ddot, d))  # noqa: F405

    def superposed(self, prev, u_prev, u, u_start, status, ref6, gemm):
        """robot/blending.py ``blend_setpoint`` in Cartesian space with this path the next motion's:
        the poses of `prev` at `u_prev` and of this path at `u` and at `u_start` (:meth:`pose_u`),
        overlapped as ``superpose_pose`` does (``p0 + (p1 - pc)``, ``(R1 @ Rc.T) @ R0``: numpy's
        two products, compiled through its ``cblas_dgemm`` at address `gemm` as numpy calls it, into
        numpy-allocated 3x3s) and solved as ``CartSegment.ik`` solves (:meth:`solve_rp`) for the
        reference ref6 (6,): the axes (6,), or None (a pose not here, no inverse here, or the
        Python code decides)."""
        M = self.poses
        if self.opw is None or gemm == 0 or len(ref6) != 6:
            return None
        if not prev._pose(u_prev, M, 1) or not self._pose(u, M, 2) or not self._pose(u_start, M, 3):
            return None
        buf = np.empty((4, 3, 3))
        b = buf
        for i in range(3):
            for j in range(3):
                b[0, i, j] = M[2, 4 * i + j]
                b[1, i, j] = M[3, 4 * i + j]
                b[2, i, j] = M[1, 4 * i + j]
        _superpose(gemm, buf)
        for i in range(3):
            for j in range(3):
                M[0, 4 * i + j] = b[0, i, j]
            M[0, 4 * i + 3] = M[1, 4 * i + 3] + (M[2, 4 * i + 3] - M[3, 4 * i + 3])
        return self._axes(M, 0, _st(status), ref6)

    def use_frames(self, gemm, pre, post):
        """Solve ``(pre @ T) @ post`` instead of the pose T (4x4 of the pose's R and p) as it
        stands: robot/robotmodel.py ``RobotModel.ik``'s ``$BASE @ T @ INV_POS($TOOL)``, each
        product numpy's ``@`` (compiled through the BLAS ``cblas_dgemm`` at address `gemm`, numpy's own,
        robot/blas.py; row-major, no transposes, alpha 1, beta 0, into numpy-allocated 4x4s);
        `pre` or `post` None: that product is skipped, as there for a null frame. Raises
        ValueError without a BLAS address."""
        if gemm == 0:
            raise ValueError("CartPath.use_frames: no BLAS")
        frames = np.zeros((4, 16))
        if pre is not None:
            frames[_PRE] = np.asarray(pre, dtype=float).reshape(16)
        if post is not None:
            frames[_POST] = np.asarray(post, dtype=float).reshape(16)
        if _COMPILED:
            self.gemm = cython.cast(dgemm_t, gemm)  # noqa: F821  (cartpath.pxd's C types)
        self.frames = frames
        self.has_pre = 0 if pre is None else 1
        self.has_post = 0 if post is None else 1

    def _flange(self, M, m):
        """The flange pose the solver is given for the pose in row m of M (3x4): the row of
        :attr:`frames` that holds it (4x4)."""
        fr = self.frames
        for i in range(12):
            fr[_T, i] = M[m, i]
        fr[_T, 12] = 0.0
        fr[_T, 13] = 0.0
        fr[_T, 14] = 0.0
        fr[_T, 15] = 1.0
        src = _T
        if self.has_pre:
            self._mul4(_PRE, _T, _F)
            src = _F
        if self.has_post:
            dst = _T if src == _F else _F
            self._mul4(src, _POST, dst)
            src = dst
        return src

    def _mul4(self, a, b, out):
        """frames[out] = frames[a] @ frames[b] (4x4s, numpy's product)."""
        fr = self.frames
        if _COMPILED:
            self.gemm(_ROW, _NOTRANS, _NOTRANS, 4, 4, 4, 1.0, cython.address(fr[a, 0]), 4, cython.address(fr[b, 0]), 4,
                      0.0, cython.address(fr[out, 0]), 4)
        else:
            fa = np.asarray(fr)
            fa[out] = (fa[a].reshape(4, 4) @ fa[b].reshape(4, 4)).reshape(16)

    def _pose_rp(self, R, p):
        """The pose (R (3, 3), p (3,)) into row 0 of :attr:`poses`; ValueError for other shapes."""
        M = self.poses
        if R.shape[0] != 3 or R.shape[1] != 3 or p.shape[0] != 3:
            raise ValueError("CartPath: R (3, 3), p (3,)")
        for i in range(3):
            for j in range(3):
                M[0, 4 * i + j] = R[i, j]
            M[0, 4 * i + 3] = p[i]

    def flange_rp(self, R, p):
        """The flange pose (4x4) :meth:`solve_rp` solves for the pose (R (3, 3), p (3,))."""
        self._pose_rp(R, p)
        res = np.zeros((4, 4))
        rv = res
        if self.has_pre or self.has_post:
            src = self._flange(self.poses, 0)
            for i in range(3):
                for j in range(4):
                    rv[i, j] = self.frames[src, 4 * i + j]
        else:
            for i in range(3):
                for j in range(4):
                    rv[i, j] = self.poses[0, 4 * i + j]
        rv[3, 3] = 1.0
        return res

    def solve_rp(self, R, p, status, ref6):
        """The axes (6,) of the pose (R (3, 3), p (3,)) for the reference ref6 (``CartSegment.ik``;
        turn None), or None (no inverse here, or the Python inverse decides)."""
        if self.opw is None or ref6.shape[0] != 6:
            return None
        self._pose_rp(R, p)
        return self._axes(self.poses, 0, _st(status), ref6)


def _st(status):
    """The status an inverse is solved with as :meth:`CartPath._solve` takes it: -1 for None, else the int."""
    return -1 if status is None else int(status)


def _superpose(gemm, b):
    """b[0] = (b[0] @ b[1].T) @ b[2] of the 3x3s of b (4, 3, 3), b[3] the first product (numpy's)."""
    if _COMPILED:
        g = cython.cast(dgemm_t, gemm)  # noqa: F821  (cartpath.pxd's C types)
        g(_ROW, _NOTRANS, _TRANS, 3, 3, 3, 1.0, cython.address(b[0, 0, 0]), 3, cython.address(b[1, 0, 0]), 3, 0.0,
          cython.address(b[3, 0, 0]), 3)
        g(_ROW, _NOTRANS, _NOTRANS, 3, 3, 3, 1.0, cython.address(b[3, 0, 0]), 3, cython.address(b[2, 0, 0]), 3, 0.0,
          cython.address(b[0, 0, 0]), 3)
    else:
        bb = np.asarray(b)
        bb[3] = bb[0] @ bb[1].T
        bb[0] = bb[3] @ bb[2]


def superpose_products(gemm, A, B, C):
    """``(A @ B.T) @ C`` of three 3x3s as :meth:`CartPath.superposed` computes it, for robot/blending.py's
    check at set-up that it is numpy's bit for bit. Raises ValueError without a BLAS address or
    for other shapes."""
    if gemm == 0 or A.shape[0] != 3 or A.shape[1] != 3 or B.shape[0] != 3 or B.shape[1] != 3 \
            or C.shape[0] != 3 or C.shape[1] != 3:
        raise ValueError("superpose_products: a BLAS address, three (3, 3)")
    buf = np.empty((4, 3, 3))
    b = buf
    for i in range(3):
        for j in range(3):
            b[0, i, j] = A[i, j]
            b[1, i, j] = B[i, j]
            b[2, i, j] = C[i, j]
    _superpose(gemm, buf)
    return buf[0].copy()


def turn_products(gemm, R0, rv, f):
    """``R0 @ rotvec_matrix(f * rv)`` (3x3) as :meth:`CartPath._turned` computes it, for robot/segments.py's
    check at set-up that it is robot/pathpieces.py's with numpy's product bit for bit. Raises ValueError
    without a BLAS address or for other shapes."""
    if gemm == 0 or R0.shape[0] != 3 or R0.shape[1] != 3 or rv.shape[0] != 3:
        raise ValueError("turn_products: a BLAS address, R0 (3, 3), rv (3,)")
    rots = np.zeros((1, 3, 3, 3))
    rots[0, 0] = R0
    z1 = np.zeros(1)
    cp = CartPath(None, np.array([0.0, 1.0]), np.zeros(1, dtype=np.intc), np.zeros(1, dtype=np.intc), np.ones(1),
                  np.ones(1), z1, np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)), rots)
    cp.use_turns(gemm, np.array([rv], dtype=float), np.ones(1, dtype=np.intc))
    M = np.zeros((1, 12))
    cp._turned(0, f, M, 0)
    return M[0].reshape(3, 4)[:, :3].copy()


def _gradient_rows(f, out, n, h):
    """robot/cartlaw.py ``gradient_rows`` of the n rows (n >= 3) of 6 in f into out."""
    c2h = 2. * h
    a0, a1, a2 = -1.5 / h, 2. / h, -0.5 / h
    b0, b1, b2 = 0.5 / h, -2. / h, 1.5 / h
    for r in range(1, n - 1):
        for i in range(6):
            out[6 * r + i] = (f[6 * (r + 1) + i] - f[6 * (r - 1) + i]) / c2h
    for i in range(6):
        out[i] = a0 * f[i] + a1 * f[6 + i] + a2 * f[12 + i]
        out[6 * (n - 1) + i] = b0 * f[6 * (n - 3) + i] + b1 * f[6 * (n - 2) + i] + b2 * f[6 * (n - 1) + i]


def _rate_maxima(D1, D2, N, d1a, d1b, qd, qdd):
    """:meth:`CartPath.walk`'s q' at the start and the end (d1a, d1b) and the largest |q'| and |q''|
    of each axis (qd, qdd) over the N rows of D1 and D2; 1 where one is NaN, else 0."""
    bad = 0
    for i in range(6):
        d1a[i] = D1[i]
        d1b[i] = D1[6 * (N - 1) + i]
        qd[i] = abs(D1[i])
        qdd[i] = abs(D2[i])
        for j in range(1, N):
            x = abs(D1[6 * j + i])
            if x > qd[i]:
                qd[i] = x
            bad |= x != x
            x = abs(D2[6 * j + i])
            if x > qdd[i]:
                qdd[i] = x
            bad |= x != x
        bad |= (qd[i] != qd[i]) | (qdd[i] != qdd[i])
    return bad


def _piece_speed(qd, qdd, v_ax, a_ax, budget, plain, vmax_k):
    """:meth:`CartPath.walk`'s speed limit of the piece: `vmax_k`, no more than each axis's speed
    over its largest |q'| and (unless `plain`) sqrt(budget/2 x its acceleration over its largest |q''|)
    (a negative or NaN quotient, whose root is NaN, is no limit)."""
    V = inf  # noqa: F405
    for i in range(6):
        if qd[i] > 1e-9:
            x = v_ax[i] / qd[i]
            if x < V:
                V = x
    if not plain:
        W = inf  # noqa: F405
        t = 0.5 * budget
        for i in range(6):
            if qdd[i] > 1e-9:
                y = t * a_ax[i] / qdd[i]
                if y >= 0.0:
                    x = sqrt(y)  # noqa: F405
                    if x < W:
                        W = x
        if W < V:
            V = W
    return V if V < vmax_k else vmax_k


def _pow2(x):
    """``x ** 2`` as CPython's float computes it: libm's pow (compiled through a pointer gcc does not fold)."""
    if _COMPILED:
        return capi_libm_pow(x, 2.0)  # noqa: F821  (robot/capi.pxd's C function)
    return float(x) ** 2.0


def _piece_acc(qd, qdd, a_ax, budget, vmax_k):
    """:meth:`CartPath.walk`'s axis acceleration limit of the piece at the speed `vmax_k`
    (``vmax_k ** 2`` as libm's pow)."""
    Aax = inf  # noqa: F405
    vk2 = _pow2(vmax_k)
    for i in range(6):
        if qd[i] > 1e-9:
            x = (budget * a_ax[i] - qdd[i] * vk2) / qd[i]
            if x < Aax:
                Aax = x
    return Aax


def _dot3(ddot, v):
    """``v.dot(v)`` of a float64 (3,) as numpy computes it: ``0. + cblas_ddot(3, v, 1, v, 1)``."""
    s = 0.0
    if _COMPILED:
        s += cython.cast(ddot_t, ddot)(3, cython.address(v[0]), 1, cython.address(v[0]), 1)  # noqa: F821
    else:
        s += float(np.asarray(v).dot(np.asarray(v)))
    return s


def _tmul(gemm, A, B, out):
    """out = ``A.T @ B`` of two C-contiguous float64 3x3s (numpy's; compiled its cblas_dgemm call, A transposed)."""
    if _COMPILED:
        cython.cast(dgemm_t, gemm)(_ROW, _TRANS, _NOTRANS, 3, 3, 3, 1.0, cython.address(A[0, 0]), 3,  # noqa: F821
                                   cython.address(B[0, 0]), 3, 0.0, cython.address(out[0, 0]), 3)
    else:
        np.copyto(out, np.asarray(A).T @ np.asarray(B))


def _mul3(gemm, A, B, out):
    """out = ``A @ B`` of two C-contiguous float64 3x3s (numpy's; compiled its cblas_dgemm call)."""
    if _COMPILED:
        cython.cast(dgemm_t, gemm)(_ROW, _NOTRANS, _NOTRANS, 3, 3, 3, 1.0, cython.address(A[0, 0]), 3,  # noqa: F821
                                   cython.address(B[0, 0]), 3, 0.0, cython.address(out[0, 0]), 3)
    else:
        np.copyto(out, np.asarray(A) @ np.asarray(B))


#: the identity numpy's ``R @ _EYE3`` multiplies with (robot/cartplan.py), numpy-allocated
_EYE3 = np.eye(3)
#: the same as the compiled functions take it (a C view, made once)
_EYE3V = _EYE3
#: a line's entries of :class:`CartPath`'s tables that do not depend on the line (read-only)
_LINE_KIND, _LINE_MID, _LINE_R, _LINE_ANGLE, _LINE_C = (
    np.zeros(1, dtype=np.intc), np.ones(1, dtype=np.intc), np.ones(1), np.zeros(1), np.zeros((1, 3)))
for _a in (_LINE_KIND, _LINE_MID, _LINE_R, _LINE_ANGLE, _LINE_C):
    _a.setflags(write=False)


def line_products(gemm, ddot, A, B, v):
    """(``A.T @ B``, ``A @ eye(3)``, ``v.dot(v)``) as :func:`plan_line` computes them (compiled:
    numpy's BLAS at the addresses `gemm` and `ddot`), for robot/segments.py's check at set-up that
    they are numpy's bit for bit. Raises ValueError without the addresses or for other shapes."""
    if gemm == 0 or ddot == 0 or A.shape[0] != 3 or A.shape[1] != 3 or B.shape[0] != 3 or B.shape[1] != 3 \
            or v.shape[0] != 3:
        raise ValueError("line_products: BLAS addresses, A and B (3, 3), v (3,)")
    P, Q = np.empty((3, 3)), np.empty((3, 3))
    _tmul(gemm, A, B, P)
    _mul3(gemm, A, _EYE3V, Q)
    return P, Q, _dot3(ddot, v)


def plan_line(opw, gemm, ddot, start_T, x, y, z, a, b, c, v_cp, v_ori, a_cp, a_ori, status, q0, chain_from, plain,
              v_ax, a_ax, max_jump, step_deg, max_samples, pre, post):
    """robot/cartplan.py ``plan_cart`` of a single LIN to a complete Cartesian target (x .. c, mm
    and deg: ``frame_to_matrix``'s rotation) from the TCP pose `start_T` (4x4 in $BASE) and the
    axes q0 (6,), ``$ORI_TYPE #VAR``, outside T1, solved through the inverse `opw` (fastpath's
    ``OPWCore``; through $BASE `pre` and INV_POS($TOOL) `post` by ``CartPath.use_frames`` where not
    None): the same operations in the same order, numpy's products and dot products (compiled:
    through its BLAS at the addresses `gemm` and `ddot`; robot/segments.py checks them once a
    process). `v_cp`, `v_ori`, `a_cp`, `a_ori`: ``cp_speeds``'s; `chain_from`, `plain`, `v_ax`,
    `a_ax`, `max_jump`, `step_deg`, `max_samples`: :meth:`CartPath.walk`'s.

    Returns (p0, p1, dir, L, R0, R1, theta, rotvec, R_still, weight, u1, CartPath, q1, q' at
    the start, q' at the end, vel_peak, acc_peak, v_prog, vmax, amax): the line's ends,
    direction and length (mm), the two orientations, the turn between them (deg) and its
    rotation vector, the orientation kept along the line, the piece's time weight, its end's
    path parameter, its path, the end axes, the axes' rates and peaks, the programmed
    normalised speed and the speed and acceleration the profile is planned with. None where
    the Python code decides: a turn of the orientation along the line (a slerp), a speed or
    acceleration not positive, a line of (nearly) zero length, a NaN, and wherever
    :meth:`CartPath.walk` gives None."""
    if opw is None or gemm == 0 or ddot == 0 or start_T.shape[0] != 4 or start_T.shape[1] != 4:
        return None
    if not (v_cp > 0 and v_ori > 0 and a_cp > 0 and a_ori > 0):
        return None
    R0, R1, p0, p1 = _line_ends(start_T, x, y, z, a, b, c)
    geo = _line_geometry(gemm, ddot, R0, R1, p0, p1)
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
    walked = cp.walk(0.0 / W, u1, nk, status, q0, chain_from, 1.0, plain, v_ax, a_ax, vmax,
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
    return (p0, p1, dirv, float(L), R0, R1, float(th), rv, still, float(w), float(u1), cp, q1, d1a, d1b, vel, accp,
            float(vprog), float(vmax), float(amax))


def _line_ends(start_T, x, y, z, a, b, c):
    """:func:`plan_line`'s ends: (R0, R1, p0, p1), the start's rotation and position from `start_T`,
    the target's from ``frame_to_matrix(x, y, z, a, b, c)`` (math.radians, cos and sin, the
    products in its order)."""
    R0 = np.empty((3, 3))
    r0 = R0
    R1 = np.empty((3, 3))
    r1 = R1
    p0 = np.empty(3)
    pp0 = p0
    p1 = np.empty(3)
    pp1 = p1
    for i in range(3):
        pp0[i] = start_T[i, 3]
        for j in range(3):
            r0[i, j] = start_T[i, j]
    ra, rb, rc = a * DEG_TO_RAD, b * DEG_TO_RAD, c * DEG_TO_RAD
    ca, sa, cb, sb, cc, sc = cos(ra), sin(ra), cos(rb), sin(rb), cos(rc), sin(rc)  # noqa: F405
    r1[0, 0], r1[0, 1], r1[0, 2] = ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc
    r1[1, 0], r1[1, 1], r1[1, 2] = sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc
    r1[2, 0], r1[2, 1], r1[2, 2] = -sb, cb * sc, cb * cc
    pp1[0], pp1[1], pp1[2] = x, y, z
    return R0, R1, p0, p1


def _line_geometry(gemm, ddot, R0, R1, p0, p1):
    """:func:`plan_line`'s line: (dir, L, theta (deg), rotvec, R_still) of the ends (LinePiece: d =
    p1 - p0, its norm3, dir = d / L; rotation_angle_deg(R0, R1) and rotvec_of(R0.T @ R1),
    robot/frames.py ``_angle``), or None for an orientation that turns along the line (a slerp:
    the Python code) or a turn near 180 deg."""
    d = np.empty(3)                     # numpy's buffers, as numpy's own products use them
    dv = d
    M = np.empty((3, 3))
    m = M
    for i in range(3):
        dv[i] = p1[i] - p0[i]
    L = sqrt(_dot3(ddot, d))  # noqa: F405
    dirv = np.zeros(3)
    dr = dirv
    if L > 0:
        for i in range(3):
            dr[i] = dv[i] / L
    _tmul(gemm, R0, R1, M)
    w0, w1, w2 = m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]
    s = sqrt(w0 * w0 + w1 * w1 + w2 * w2)  # noqa: F405
    th = atan2(0.5 * s, 0.5 * (m[0, 0] + m[1, 1] + m[2, 2] - 1.0))  # noqa: F405
    if th < 1e-6:
        k = 0.5 * (1.0 + th * th / 6.0)
    elif th < pi - 1e-3:  # noqa: F405
        k = th / s
    else:
        return None
    rv = np.empty(3)
    rvv = rv
    rvv[0], rvv[1], rvv[2] = w0 * k, w1 * k, w2 * k
    if not sqrt(_dot3(ddot, rv)) < 1e-12:  # noqa: F405
        return None                     # the orientation turns along the line: a slerp (Python)
    still = np.empty((3, 3))
    _mul3(gemm, R0, _EYE3V, still)
    return dirv, L, th * RAD_TO_DEG, rv, still


def _line_limits(L, th, w, W, v_cp, v_ori, a_cp, a_ori):
    """:func:`plan_line`'s speed and acceleration limits of the line (no curvature limit) and its
    sample count: (v_prog, vmax, amax, nk), nk -1 for a length past 1e9 mm or a NaN."""
    lk = L * W / w if w > 0 else 0.0
    ok = th * W / w if w > 0 else 0.0
    v = v_cp / lk if lk > 0 else inf  # noqa: F405
    v2 = v_ori / ok if ok > 0 else inf  # noqa: F405
    if v2 < v:
        v = v2
    vprog = v
    vc = sqrt(a_cp * inf) if L > 0 else inf  # noqa: F405
    vc = vc / lk if lk > 0 else inf  # noqa: F405
    if vc < v:
        v = vc
    acc = a_cp / lk if lk > 0 else inf  # noqa: F405
    a2 = a_ori / ok if ok > 0 else inf  # noqa: F405
    if a2 < acc:
        acc = a2
    q = L / 50.0
    if not q < 1e9:
        return vprog, 0.0, 0.0, -1
    if _COMPILED:
        nk = cython.cast(cython.longlong, q) + cython.cast(cython.longlong, th / 10.0) + 4
    else:
        nk = int(q) + int(th / 10.0) + 4
    if nk > 48:
        nk = 48
    if nk < 4:
        nk = 4
    return vprog, (v if v < inf else 1e12), (acc if acc < inf else 1e12), nk  # noqa: F405


def _line_path(opw, gemm, pre, post, dirv, p0, R0, still, R1, L, W, u1):
    """:func:`plan_line`'s path of the line (robot/segments.py ``_cart_path``), through
    $BASE `pre` and INV_POS($TOOL) `post` where not None."""
    rots = np.empty((1, 3, 3, 3))
    rt = rots
    dm = np.empty((1, 3))
    dmv = dm
    pm = np.empty((1, 3))
    pmv = pm
    ub = np.empty(2)
    ubv = ub
    lm = np.empty(1)
    lmv = lm
    for i in range(3):
        dmv[0, i] = dirv[i]
        pmv[0, i] = p0[i]
        for j in range(3):
            rt[0, 0, i, j] = R0[i, j]
            rt[0, 1, i, j] = still[i, j]
            rt[0, 2, i, j] = R1[i, j]
    ubv[0], ubv[1] = 0.0 / W, u1
    lmv[0] = L
    cp = CartPath(opw, ub, _LINE_KIND, _LINE_MID, lm, _LINE_R, _LINE_ANGLE, pm, dm, _LINE_C, rots)
    if pre is not None or post is not None:
        cp.use_frames(gemm, pre, post)
    return cp


def _line_peaks(qd, qdd, vmax, amax):
    """:func:`plan_line`'s axis speed and acceleration peaks (6,) from the largest |q'| `qd` and
    |q''| `qdd` at the speed `vmax` and the acceleration `amax` (``vmax ** 2`` as libm's pow)."""
    vk2 = _pow2(vmax)
    vel = np.empty(6)
    vv = vel
    accp = np.empty(6)
    av = accp
    for i in range(6):
        vv[i] = qd[i] * vmax            # np.maximum(0, x) of x >= +0: x
        av[i] = qdd[i] * vk2 + qd[i] * amax
    return vel, accp
