# cython: boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False, auto_pickle=False
"""The IPO cycle's kinematics (issue 39, "Simulator"; issue 47; issue 76 item 5), written once in
Python and compiled by Cython from this very file (the C types in ipocycle.pxd beside it;
robot/build.py ``PURE``); without a compiler it runs as it stands (robot/kinematics/compiled.py
``pure_module`` picks the one in use):

* :class:`Forward`: the forward kinematics of six rotary joints (robot/kinematics/joints.py
  ``JointChain.forward``): each joint's rotation as scipy's ``Rotation.from_rotvec(axis *
  q).as_matrix()`` computes it (its quaternion, then its matrix: the same operations in the same
  order), chained by numpy's products; ``Forward.tcp_points``, the TCP positions of many axis sets
  on one PTP line in one call (``RobotModel.tcp``'s products: a PTP motion's path-length table);
* :class:`ExternalChain`: an external kinematic's ``ETn(E)`` (robot/external.py ``ExternalAxes.chain``:
  ``frame_to_matrix``'s formulas for a rotary axis, numpy's products);
* :class:`ArmCycle`: the kinematic playback of one IPO cycle on a MuJoCo arm of six rotary axes
  without external axes (robot/readback.py ``ReadBack.cycle``): ``qpos = sign * radians(A)``,
  MuJoCo's ``mj_kinematics``, the axes read back (``degrees(sign * qpos)``), the ``tool0`` site
  as the flange in WORLD (mm) and the TCP product ``INV_POS($BASE) : FLANGE : $TOOL``.

Issue 76 item 5: these were hand mirrors in C (robot/simcore/ipocycle.pyx) of
``JointChain.forward_py``'s numpy/scipy code and of robot/mjcf.py ``ArmModel``'s playback; this
file is now the one source of both ways. Where the compiled module calls C through an address
the branches on ``COMPILED`` say so: numpy's products are numpy's own BLAS routines
(``cblas_dgemm`` for a 3x3 or 4x4 by matrix product, ``cblas_dgemv`` for a 3x3 by vector one,
robot/blas.py gives their addresses) with the arguments numpy passes, and ``mj_kinematics`` is
MuJoCo's own, at its address in the library the ``mujoco`` package loaded; as Python they are
``numpy.matmul`` and ``mujoco.mj_kinematics``. Every other operation is the same on IEEE doubles
either way (no fused multiply-add: robot/build.py ``-ffp-contract=off``; libm's sin, cos and sqrt
both ways; ``radians`` and ``degrees`` are numpy's multiplications by pi/180 and 180/pi), so the
two give the same bits (tests/robot/test_simcore.py compares them with numpy's and scipy's own
forward kinematics and with ``ArmModel``'s playback).
"""

from math import *  # noqa: F403  (sin, cos, sqrt, pi: ipocycle.pxd declares libm's as C's when compiled)

import numpy as np

try:
    import cython
    COMPILED = cython.compiled
except ImportError:     # an install without Cython (a need of the build only): this file as Python
    COMPILED = False
#: :data:`COMPILED` as the compiled branches test it (a C constant of ipocycle.pxd when compiled)
_COMPILED = COMPILED

#: numpy's ``radians`` and ``degrees`` factors (numpy/core/src/umath: NPY_PI / 180, 180 / NPY_PI)
DEG_TO_RAD = pi / 180.0  # noqa: F405
RAD_TO_DEG = 180.0 / pi  # noqa: F405
#: cblas's row-major, no-transpose (numpy's arguments)
_ROW, _NOTRANS = 101, 111
#: cblas_dgemv's order as numpy calls it for a C-contiguous 3x3 by vector product: the matrix's
#: transpose, column-major
_COL, _TRANS = 102, 112
#: :attr:`Forward.buf`'s rows: the chain's R and its next value (3 each), then the joints' rotations
#: (3 each), then the product's vector (:attr:`Forward.yv`)
_R, _R2, _RJ = 0, 3, 6


def built_from() -> str:
    """The sha256 of ipocycle.py and ipocycle.pxd the compiled module was built from
    (robot/build.py embeds it); "" as Python."""
    if _COMPILED:
        return pure_source_sha().decode("ascii")  # noqa: F821  (ipocycle.pxd's C constant)
    return ""


class Forward:
    """The flange frame of n joints (robot/kinematics/joints.py ``JointChain``'s origins (n, 3) mm,
    unit axes (n, 3), KUKA signs (n,), origin rotations (n, 3, 3) used when `origin_rot`, the last
    link to the flange R_flange (3, 3) and p_flange (3,) mm; `linear` (n flags, None: all rotary):
    a linear joint moves along its axis by its value in mm, a SCARA's A3), the products through
    numpy's ``cblas_dgemm`` and ``cblas_dgemv`` at the addresses `gemm` and `gemv` when compiled
    (robot/blas.py ``numpy_cblas``; unused as Python). Raises ValueError for a missing BLAS
    address when compiled, or arrays of other shapes."""

    def __init__(self, gemm, gemv, origins, axes, sign, R_origin, origin_rot, R_flange, p_flange, linear=None):
        if _COMPILED:
            if gemm == 0 or gemv == 0:
                raise ValueError("Forward: no BLAS")
            self.gemm = cython.cast(dgemm_t, cython.cast(cython.size_t, gemm))  # noqa: F821  (ipocycle.pxd's C types)
            self.gemv = cython.cast(dgemv_t, cython.cast(cython.size_t, gemv))  # noqa: F821
        n = self.n = len(origins)
        self.orig = np.array(origins, dtype=float).reshape(n, 3)
        self.axis = np.array(axes, dtype=float).reshape(n, 3)
        self.sign = np.array(sign, dtype=float).reshape(n)
        self.rorig = np.ascontiguousarray(R_origin, dtype=float).reshape(3 * n, 3)
        self.origin_rot = bool(origin_rot)
        self.rfl = np.ascontiguousarray(R_flange, dtype=float).reshape(3, 3)
        self.pfl = np.array(p_flange, dtype=float).reshape(1, 3)
        self.yv = _RJ + 3 * n
        self.buf = np.zeros((self.yv + 1, 3))
        self.lin = np.zeros(n, dtype=np.intc)
        self.qa = np.zeros(n)           # tcp_points' axes and its four frames
        self.fr = np.zeros((4, 4, 4))
        if linear is not None:
            for i in range(n):
                self.lin[i] = 1 if linear[i] else 0

    def forward(self, a, T):
        """The flange frame (4x4, mm) of the axes a (A1..An, deg; further values ignored) into T
        (a C-contiguous float64 4x4). Raises ValueError for other shapes."""
        if a.shape[0] < self.n or T.shape[0] != 4 or T.shape[1] != 4:
            raise ValueError("Forward.forward: a (>= n,), T (4, 4)")
        for i in range(self.n):
            # float(): C's doubles compiled, Python's floats (not numpy's scalars) as Python
            if not self.lin[i]:
                self._joint(i, float(self.sign[i]) * (float(a[i]) * DEG_TO_RAD))
        for k in range(9):
            self.buf[_R + k // 3, k % 3] = 1.0 if k % 4 == 0 else 0.0
        p0 = p1 = p2 = 0.0
        r, r2, yv = _R, _R2, self.yv
        for i in range(self.n):
            # p = p + R @ origins[i]; R = R @ R_origin[i]; R = R @ Rj[i]
            self._mv(r, self.orig, i)
            p0, p1, p2 = p0 + self.buf[yv, 0], p1 + self.buf[yv, 1], p2 + self.buf[yv, 2]
            if self.origin_rot:
                self._mm(r, self.rorig, 3 * i, r2)
                r, r2 = r2, r
            if self.lin[i]:
                # a linear joint: p = p + (R @ axes[i]) * (sign * A)
                self._mv(r, self.axis, i)
                d = float(self.sign[i]) * float(a[i])
                p0, p1, p2 = p0 + self.buf[yv, 0] * d, p1 + self.buf[yv, 1] * d, p2 + self.buf[yv, 2] * d
                continue
            self._mm(r, self.buf, _RJ + 3 * i, r2)
            r, r2 = r2, r
        # T[:3, :3] = R @ R_flange; T[:3, 3] = p + R @ p_flange
        self._mm(r, self.rfl, 0, r2)
        self._mv(r, self.pfl, 0)
        T[0, 3], T[1, 3], T[2, 3] = p0 + self.buf[yv, 0], p1 + self.buf[yv, 1], p2 + self.buf[yv, 2]
        for i in range(3):
            for j in range(3):
                T[i, j] = self.buf[r2 + i, j]
            T[3, i] = 0.0
        T[3, 3] = 1.0

    def tcp_points(self, q0, dq, us, robroot, has_robroot, base_inv, tool, out):
        """The TCP positions (mm) of the axes ``q0 + u * dq`` (A1..An, deg; further values
        ignored) for each u of `us` ((m,)) into the rows of `out` ((m, 3)): robot/robotmodel.py
        ``RobotModel.tcp``'s ``(base_inv @ F) @ tool`` of the flange F of :meth:`forward`, F first
        ``robroot @ F`` where `has_robroot`, its translation column; the products numpy's (compiled:
        its ``cblas_dgemm`` calls with numpy's arguments, as :meth:`ArmCycle.product`). One call for
        a PTP motion's path-length table (robot/segments.py ``JointSegment``: 65 points, each a
        Python forward kinematics before). Raises ValueError for other shapes (compiled: or frames
        not C-contiguous float64 4x4)."""
        m = us.shape[0]
        if (q0.shape[0] < self.n or dq.shape[0] < self.n or out.shape[0] < m or out.shape[1] != 3
                or robroot.shape[0] != 4 or robroot.shape[1] != 4 or base_inv.shape[0] != 4
                or base_inv.shape[1] != 4 or tool.shape[0] != 4 or tool.shape[1] != 4):
            raise ValueError("Forward.tcp_points: q0, dq (>= n,), out (m, 3), 4x4 frames")
        qa, fr = self.qa, self.fr
        for k in range(m):
            u = us[k]
            for i in range(self.n):
                qa[i] = q0[i] + u * dq[i]
            self.forward(qa, fr[0])
            f = 0
            if has_robroot:
                self._mm4(robroot, fr[0], fr[1])
                f = 1
            self._mm4(base_inv, fr[f], fr[2])
            self._mm4(fr[2], tool, fr[3])
            for i in range(3):
                out[k, i] = fr[3, i, 3]

    def _mm4(self, A, B, C):
        """C = A @ B of 4x4 float64 matrices: numpy's product (compiled: its ``cblas_dgemm``,
        row-major, no transposes, leading dimension 4, alpha 1, beta 0)."""
        if _COMPILED:
            self.gemm(_ROW, _NOTRANS, _NOTRANS, 4, 4, 4, 1.0, cython.address(A[0, 0]), 4, cython.address(B[0, 0]), 4,
                      0.0, cython.address(C[0, 0]), 4)
        else:
            np.matmul(A, B, out=C)

    def _joint(self, i, qi):
        """Joint i's rotation by qi (rad) about its axis into :attr:`buf`: scipy's
        ``Rotation.from_rotvec(axis * qi).as_matrix()`` (its quaternion, small angles by its
        series, then the matrix; scipy/spatial/transform/_rotation.pyx)."""
        x, y, z = float(self.axis[i, 0]) * qi, float(self.axis[i, 1]) * qi, float(self.axis[i, 2]) * qi
        angle = sqrt(x * x + y * y + z * z)  # noqa: F405
        if angle <= 1e-3:
            a2 = angle * angle
            scale = 0.5 - a2 / 48 + a2 * a2 / 3840
        else:
            scale = sin(angle / 2) / angle  # noqa: F405
        x, y, z, w = scale * x, scale * y, scale * z, cos(angle / 2)  # noqa: F405
        x2, y2, z2, w2 = x * x, y * y, z * z, w * w
        xy, zw, xz, yw, yz, xw = x * y, z * w, x * z, y * w, y * z, x * w
        r = _RJ + 3 * i
        R = self.buf
        R[r, 0], R[r, 1], R[r, 2] = x2 - y2 - z2 + w2, 2 * (xy - zw), 2 * (xz + yw)
        R[r + 1, 0], R[r + 1, 1], R[r + 1, 2] = 2 * (xy + zw), - x2 + y2 - z2 + w2, 2 * (yz - xw)
        R[r + 2, 0], R[r + 2, 1], R[r + 2, 2] = 2 * (xz - yw), 2 * (yz + xw), - x2 - y2 + z2 + w2

    def _mm(self, r, B, rb, out):
        """buf[out:out+3] = buf[r:r+3] @ B[rb:rb+3] (3x3 by 3x3, numpy's product)."""
        if _COMPILED:
            self.gemm(_ROW, _NOTRANS, _NOTRANS, 3, 3, 3, 1.0, cython.address(self.buf[r, 0]), 3,
                      cython.address(B[rb, 0]), 3, 0.0, cython.address(self.buf[out, 0]), 3)
        else:
            np.matmul(self.buf[r:r + 3], B[rb:rb + 3], out=self.buf[out:out + 3])

    def _mv(self, r, V, i):
        """buf[yv] = buf[r:r+3] @ V[i] (3x3 by vector, numpy's product)."""
        if _COMPILED:
            self.gemv(_COL, _TRANS, 3, 3, 1.0, cython.address(self.buf[r, 0]), 3, cython.address(V[i, 0]), 1,
                      0.0, cython.address(self.buf[self.yv, 0]), 1)
        else:
            np.matmul(self.buf[r:r + 3], V[i], out=self.buf[self.yv])


class ExternalChain:
    """``ETn(E)`` of one external kinematic (robot/external.py ``ExternalAxes.chain``: a track
    carrying the robot, a turntable): ``root : TA1KR : Ax(E_a) : TA2A1 : Ax(E_b) : ... : TFLA3``,
    each ``Ax(e)`` ``Tz(d * e)`` (mm, a linear axis) or robot/frames.py ``frame_to_matrix(0, 0, 0,
    d * e, 0, 0)`` (deg, a rotary one: its formulas, term by term), the products numpy's (compiled:
    its ``cblas_dgemm`` at the address `gemm`, robot/blas.py; unused as Python) in Python's order
    ``(T @ link) @ Ax``. `frames` ((m + 2) 4x4 matrices, mm): the root's, the m axes' links, TFLA3's;
    `linear`, `direction`, `index` (m each): an axis' kind, its ``$AXIS_DIR`` and its place in E.
    Raises ValueError for a missing BLAS address when compiled, or arrays of other shapes."""

    def __init__(self, gemm, frames, linear, direction, index):
        if _COMPILED:
            if gemm == 0:
                raise ValueError("ExternalChain: no BLAS")
            self.gemm = cython.cast(dgemm_t, cython.cast(cython.size_t, gemm))  # noqa: F821  (ipocycle.pxd's C types)
        m = self.m = len(linear)
        if len(direction) != m or len(index) != m or m > 3:
            raise ValueError("ExternalChain: up to 3 axes, each with a kind, a direction and an index")
        self.frames = np.ascontiguousarray(frames, dtype=float).reshape(m + 2, 4, 4)
        self.lin = np.array([1 if v else 0 for v in linear], dtype=np.intc)
        self.dirs = np.array(direction, dtype=float)
        self.idx = np.array(index, dtype=np.intc)
        self.need = 0
        for k in range(m):
            if self.idx[k] < 0:
                raise ValueError("ExternalChain: a negative axis index")
            if self.idx[k] + 1 > self.need:
                self.need = self.idx[k] + 1
        self.buf = np.zeros((4, 4, 4))      # the chain so far (two), the link's product, the axis' frame

    def chain(self, e, out):
        """``ETn(E)`` (4x4, mm) of the external axes `e` (at least :attr:`need` values, mm or deg)
        into `out` (C-contiguous float64 4x4). Raises ValueError for other shapes."""
        if e.shape[0] < self.need or out.shape[0] != 4 or out.shape[1] != 4:
            raise ValueError("ExternalChain.chain: e (>= need,), out (4, 4)")
        buf, fr = self.buf, self.frames
        for k in range(self.m):
            # T = (T @ link) @ Ax(d * e): T the root first, then buf[0]
            v = self.dirs[k] * e[self.idx[k]]
            if k == 0:
                self._mm4(fr[0], fr[1], buf[2])
            else:
                self._mm4(buf[0], fr[k + 1], buf[2])
            self._axis(self.lin[k], v, buf[3])
            self._mm4(buf[2], buf[3], buf[0])
        if self.m == 0:
            self._mm4(fr[0], fr[1], out)
        else:
            self._mm4(buf[0], fr[self.m + 1], out)

    def _axis(self, lin, v, A):
        """A = ``Ax(v)``: ``Tz(v)`` (numpy's eye with A[2, 3] = v) or ``frame_to_matrix(0, 0, 0, v,
        0, 0)``'s numbers (its expressions, in its order)."""
        for i in range(4):
            for j in range(4):
                A[i, j] = 1.0 if i == j else 0.0
        if lin:
            A[2, 3] = v
            return
        ra = v * DEG_TO_RAD
        rb = 0.0 * DEG_TO_RAD
        rc = 0.0 * DEG_TO_RAD
        ca, sa, cb, sb, cc, sc = cos(ra), sin(ra), cos(rb), sin(rb), cos(rc), sin(rc)  # noqa: F405
        A[0, 0], A[0, 1], A[0, 2] = ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc
        A[1, 0], A[1, 1], A[1, 2] = sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc
        A[2, 0], A[2, 1], A[2, 2] = -sb, cb * sc, cb * cc

    def _mm4(self, A, B, C):
        """C = A @ B of 4x4 float64 matrices: numpy's product (compiled: its ``cblas_dgemm``)."""
        if _COMPILED:
            self.gemm(_ROW, _NOTRANS, _NOTRANS, 4, 4, 4, 1.0, cython.address(A[0, 0]), 4, cython.address(B[0, 0]), 4,
                      0.0, cython.address(C[0, 0]), 4)
        else:
            np.matmul(A, B, out=C)


class ArmCycle:
    """The kinematic playback of one IPO cycle on a MuJoCo arm of n rotary axes without
    external axes (robot/mjcf.py ``ArmModel``: its ``set_axes``, ``axes_deg`` and
    ``flange_pose_world`` in one call, the same numbers): `kinematics` is ``mujoco.mj_kinematics``
    (called as Python), `fn` its address in the library the package loaded (called compiled, on
    the `model`'s and `data`'s ``_address``); `qidx` the arm's n ``qpos`` indices, `sign` its n KUKA
    signs, `site_xmat` (9,) and `site_xpos` (3,) the views of the ``tool0`` site in `data`. The
    arrays are views into MuJoCo's data, kept alive here. Raises ValueError for a missing address
    when compiled, an index out of range or views of other sizes."""

    def __init__(self, kinematics, fn, model, data, qidx, sign, site_xmat, site_xpos):
        n = self.n = len(qidx)
        if len(sign) != n:
            raise ValueError("ArmCycle: a sign for each qpos index")
        if site_xmat.shape[0] != 9 or site_xpos.shape[0] != 3:
            raise ValueError("ArmCycle: the site's xmat is 9 values and its xpos 3")
        for i in range(n):
            if not 0 <= qidx[i] < data.qpos.shape[0]:
                raise ValueError("ArmCycle: a qpos index out of range")
        if _COMPILED:
            if fn == 0:
                raise ValueError("ArmCycle: no mj_kinematics")
            self.fn = cython.cast(mj_kinematics_t, cython.cast(cython.size_t, fn))  # noqa: F821  (ipocycle.pxd's C types)
            self.m, self.d = model._address, data._address
        self.keep = (kinematics, model, data)
        self.qidx = np.array(qidx, dtype=np.intc)
        self.sign = np.array(sign, dtype=float)
        self.qpos, self.xmat, self.xpos = data.qpos, site_xmat, site_xpos
        self.has_gemm = False
        self.tmp = np.empty((4, 4))
        self.keeping = False
        self.row = self.rows_n = self.at = self.width = 0

    def _play(self, q, qa, F):
        """Set the axes q (its first n), run mj_kinematics, read back qa (n) and F (4x4)."""
        for i in range(self.n):
            self.qpos[self.qidx[i]] = self.sign[i] * (q[i] * DEG_TO_RAD)
        if _COMPILED:
            self.fn(cython.cast(cython.p_void, self.m), cython.cast(cython.p_void, self.d))
        else:
            kinematics, model, data = self.keep
            kinematics(model, data)
        if self.keeping:
            # the qpos slice after this cycle into the next row of the block :meth:`keep_rows` gave
            # (a cell keeps each cycle of a turn for its contact check: interp/cellcontacts.py)
            if self.row < self.rows_n:
                for i in range(self.width):
                    self.rows[self.row, i] = self.qpos[self.at + i]
            self.row += 1
        for i in range(self.n):
            qa[i] = (self.sign[i] * self.qpos[self.qidx[i]]) * RAD_TO_DEG
        for i in range(3):
            for j in range(3):
                F[i, j] = self.xmat[3 * i + j]
            F[i, 3] = 1000.0 * self.xpos[i]
            F[3, i] = 0.0
        F[3, 3] = 1.0

    def cycle(self, q, qa, F):
        """Set the axes q (A1..An, deg; further values ignored), run ``mj_kinematics``, and
        write the axes read back (deg) into qa (n,) and the flange in WORLD (4x4, mm) into F.
        Raises ValueError for other shapes."""
        if q.shape[0] < self.n or qa.shape[0] != self.n or F.shape[0] != 4 or F.shape[1] != 4:
            raise ValueError("ArmCycle.cycle: q (>= n,), qa (n,), F (4, 4)")
        self._play(q, qa, F)

    def keep_rows(self, rows, at):
        """Keep, after each :meth:`cycle` from now on, the `rows`' width of ``qpos`` values from
        index `at` (MuJoCo's units: the arm's joint values) in the next row of `rows` (a
        C-contiguous float64 block, rows x width), :attr:`row` counting the cycles kept (from 0
        now; past the block's rows it counts on and keeps nothing); `rows` None: keep nothing
        from now on. Raises ValueError for a slice beyond ``qpos``. (Issue 89: a cell's turn
        keeps each robot's pose of each cycle without Python a cycle; docs/cells.md "Speed".)"""
        if rows is None:
            self.keeping = False
            return
        if at < 0 or at + rows.shape[1] > self.qpos.shape[0]:
            raise ValueError("ArmCycle.keep_rows: the kept slice lies beyond qpos")
        self.rows = rows
        self.rows_n, self.width, self.at = rows.shape[0], rows.shape[1], at
        self.row = 0
        self.keeping = True

    def use_gemm(self, gemm):
        """Compute :meth:`product` compiled with the BLAS ``cblas_dgemm`` at address `gemm` (the
        one numpy calls; 0: none). As Python the products are numpy's own."""
        self.has_gemm = gemm != 0
        if _COMPILED:
            self.gemm = cython.cast(dgemm_t, cython.cast(cython.size_t, gemm))  # noqa: F821

    def product(self, A, B, C, out):
        """``out = (A @ B) @ C`` for 4x4 float64 matrices as numpy's ``@`` computes it (compiled:
        numpy's two ``cblas_dgemm`` calls with numpy's arguments, the first into a numpy-allocated
        4x4); False when compiled without :meth:`use_gemm` (the caller multiplies with numpy).
        Raises ValueError for other shapes (compiled: or matrices not C-contiguous)."""
        if _COMPILED and not self.has_gemm:
            return False
        if (A.shape[0] != 4 or A.shape[1] != 4 or B.shape[0] != 4 or B.shape[1] != 4
                or C.shape[0] != 4 or C.shape[1] != 4 or out.shape[0] != 4 or out.shape[1] != 4):
            raise ValueError("ArmCycle.product: 4x4 matrices")
        self._product(A, B, C, out)
        return True

    def _product(self, A, B, C, out):
        """out = (A @ B) @ C: numpy's two products (compiled: its cblas_dgemm calls, row-major,
        no transposes, leading dimension 4, alpha 1, beta 0), the first into :attr:`tmp`."""
        if _COMPILED:
            self.gemm(_ROW, _NOTRANS, _NOTRANS, 4, 4, 4, 1.0, cython.address(A[0, 0]), 4, cython.address(B[0, 0]), 4,
                      0.0, cython.address(self.tmp[0, 0]), 4)
            self.gemm(_ROW, _NOTRANS, _NOTRANS, 4, 4, 4, 1.0, cython.address(self.tmp[0, 0]), 4,
                      cython.address(C[0, 0]), 4, 0.0, cython.address(out[0, 0]), 4)
        else:
            np.matmul(np.matmul(A, B, out=self.tmp), C, out=out)
