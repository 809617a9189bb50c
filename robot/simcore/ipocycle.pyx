# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False, auto_pickle=False
"""The IPO cycle's kinematics in C (issue 39, "Simulator"; issue 47; issue 76 item 5), one of
robot/simcore's modules (robot/build.py ``SIMCORE``):

* :class:`Forward`: the joints' forward kinematics (robot/kinematics/joints.py
  ``JointChain.forward_py``: scipy's rotation matrices, numpy's own BLAS through its address);
* :class:`ArmCycle`: the IPO cycle's MuJoCo playback (``mj_kinematics`` through its address)
  with its TCP product (robot/controller.py ``Controller.step``, robot/mjcf.py ``ArmModel``).

Bit for bit the Python code they stand for, which stays the fallback and the reference
(tests/robot/test_simcore.py compares the two; robot/kinematics/joints.py checks ``Forward``
once a process): the same operations in the same order on C doubles, libm's functions,
``degrees`` and ``radians`` as CPython's multiplications by 180/pi and pi/180, numpy's products
through the BLAS routines numpy itself calls (robot/blas.py), no fused multiply-add
(``-ffp-contract=off``). ``SOURCE_SHA``: the sha256 of the sources it was built from
(robot/build.py ``simcore_sha``).
"""

from libc.math cimport sin, cos, sqrt, M_PI
import numpy as np

from robot.simcore.capi cimport SIMCORE_SOURCE_SHA, dgemm_t, dgemv_t, mj_kinematics_t

#: The sha256 of the sources this module was compiled from (robot/build.py ``simcore_sha``)
SOURCE_SHA = SIMCORE_SOURCE_SHA.decode("ascii")

cdef double DEG_TO_RAD = M_PI / 180.0
cdef double RAD_TO_DEG = 180.0 / M_PI


cdef class Forward:
    """``JointChain.forward`` (robot/kinematics/joints.py) in one call, the same numbers: the joint
    rotations of scipy's ``Rotation.from_rotvec(axis * q).as_matrix()`` (its quaternion, then
    its matrix, the same operations in the same order), and every product ``@`` of the Python
    code through numpy's own BLAS as numpy calls it (``cblas_dgemm`` for a 3x3 by 3x3 product,
    ``cblas_dgemv`` for a 3x3 by vector one, at the addresses given). Its users check it against
    the Python code at set-up (robot/kinematics/joints.py ``JointChain._compiled``)."""

    cdef dgemm_t gemm
    cdef dgemv_t gemv
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
        self.gemm = <dgemm_t>gemm
        self.gemv = <dgemv_t>gemv
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

    cdef mj_kinematics_t fn
    cdef dgemm_t gemm
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
        self.fn = <mj_kinematics_t>fn
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
        self.gemm = <dgemm_t>gemm

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
