"""The robot's joints as URDF-style joints, and their forward kinematics: the one forward
kinematics every kinematic family shares (robot-model.md §2-§3; robot/mada.py builds the joints
from machine data, robot/machine.py from the yaml).

Each joint ``i`` has an origin (translation, mm, and a rotation, URDF rpy) in the link before
it and a unit axis; a rotary joint turns about its axis by ``kuka_sign * radians(A_i)``, a
linear one (``JointData.kind == "linear"``, a SCARA's A3) moves along it by ``A_i`` mm. After
the last joint the fixed flange frame (``flange_pos_mm``, ``flange_quat_wxyz``) gives KUKA's
flange frame (+Z out of the flange) in ``$ROBROOT``.

:meth:`JointChain.forward` is robot/ipocycle.py's ``Forward`` (scipy's rotation-vector
matrices and numpy's products, written once): compiled when it is built and gives the same bits as
that file run as Python on 64 random axis sets (checked when it is first needed: the BLAS found is
numpy's), else as Python; a linear joint there moves along its axis (issue 86: a SCARA's forward in
C). The vectorised :meth:`JointChain.forward_many` runs numpy and scipy here.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from .. import ipocycle
from ..blas import numpy_cblas
from ..machinememo import derived
from .compiled import pure_module, pure_python


def _geometry(m: Any) -> tuple:
    """(n, origins, axes, kuka_sign, R_origin, origin_rot, R_flange, p_flange, linear, any_linear)
    of the machine data `m` (:class:`JointChain`'s attributes)."""
    origins = np.array([j.origin_mm for j in m.joints], dtype=float)  # (n, 3) mm
    axes = np.array([j.joint_axis for j in m.joints], dtype=float)
    axes = axes / np.linalg.norm(axes, axis=1)[:, None]
    sign = np.array([j.kuka_sign for j in m.joints], dtype=float)  # q_urdf = sign * A
    R_origin = Rotation.from_euler("xyz", [j.origin_rpy_rad for j in m.joints]).as_matrix()
    origin_rot = any(np.any(r) for r in (j.origin_rpy_rad for j in m.joints))
    w, x, y, z = m.flange_quat_wxyz
    R_flange = Rotation.from_quat([x, y, z, w]).as_matrix()  # last link -> KUKA flange
    p_flange = np.array(m.flange_pos_mm, dtype=float)
    linear = np.array([getattr(j, "kind", "rotary") == "linear" for j in m.joints], dtype=bool)
    return (len(m.joints), origins, axes, sign, R_origin, origin_rot, R_flange, p_flange, linear,
            bool(linear.any()))


class JointChain:
    """The joints of one robot (:class:`~robot.machine.MachineData`), n = ``len(machine.joints)``.

    Attributes (numpy, mm): ``origins`` (n, 3), ``axes`` (n, 3) unit vectors, ``kuka_sign`` (n,),
    ``R_origin`` (n, 3, 3), ``origin_rot`` (any joint origin rotated), ``R_flange`` (3, 3) and
    ``p_flange`` (3,) the last link to the KUKA flange, ``linear`` (n,) bool.
    """

    def __init__(self, machine: Any) -> None:
        # the machine data's geometry: read-only arrays, the same for every chain of this
        # machine (robot/machinememo.py: scipy's rotations were a third of a controller's build)
        (self.n, self.origins, self.axes, self.kuka_sign, self.R_origin, self.origin_rot, self.R_flange,
         self.p_flange, self.linear, self.any_linear) = derived(machine, "joint chain", lambda: _geometry(machine))
        self._c: Any = None          # robot/ipocycle.py's Forward of these joints compiled; False: not used
        self._py: Any = None         # the same Forward as Python

    def forward(self, a: np.ndarray) -> np.ndarray:
        """FLANGE(a): the KUKA flange frame (4x4, mm) in ``$ROBROOT`` for the axes `a` ((n,),
        deg or mm), compiled when robot/ipocycle.py's compiled ``Forward`` reproduces :meth:`forward_py`."""
        c = self._c
        if c is None:
            c = self._c = self._compiled()
        if c:
            T = np.empty((4, 4))
            c.forward(a, T)
            return T
        return self.forward_py(a)

    def forward_py(self, a: np.ndarray) -> np.ndarray:
        """:meth:`forward` as Python: robot/ipocycle.py's ``Forward`` run as Python, the reference its
        compiled form reproduces bit for bit."""
        a = np.asarray(a, dtype=float)
        T = np.empty((4, 4))
        self._python().forward(a, T)
        return T

    def tcp_points(self, q0: np.ndarray, dq: np.ndarray, us: np.ndarray, robroot: np.ndarray | None,
                   base_inv: np.ndarray, tool: np.ndarray) -> np.ndarray:
        """TCP positions (m, 3), mm, of the axes ``q0 + u * dq`` ((>= n,) deg or mm) for each u of `us`
        ((m,)): ``(base_inv @ (robroot @ FLANGE)) @ tool``'s translation (`robroot` None: FLANGE alone;
        4x4 frames), the numbers of :meth:`forward` and numpy's products point by point, in one call
        of robot/ipocycle.py ``Forward.tcp_points`` (compiled where :meth:`forward` is). Raises
        ValueError for other shapes."""
        c = self._c
        if c is None:
            c = self._c = self._compiled()
        f = c if c else self._python()
        out = np.empty((len(us), 3))
        eye = robroot is None
        f.tcp_points(_c64(q0), _c64(dq), _c64(us), _EYE4 if eye else _c64(robroot), not eye, _c64(base_inv),
                     _c64(tool), out)
        return out

    def _python(self) -> Any:
        """robot/ipocycle.py's ``Forward`` of these joints as Python (made once)."""
        f = self._py
        if f is None:
            f = self._py = self._forward_of(pure_python(ipocycle), 0, 0)
        return f

    def forward_many(self, axes_deg: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`forward`: axes (N, n) -> flange frames (N, 4, 4), mm."""
        A = np.atleast_2d(np.asarray(axes_deg, dtype=float))[:, :self.n]
        if self.any_linear:
            return self._forward_mixed(A)
        Q = self.kuka_sign * np.radians(A)
        N = Q.shape[0]
        Rj = Rotation.from_rotvec((self.axes[None, :, :] * Q[:, :, None]).reshape(-1, 3)).as_matrix()
        Rj = Rj.reshape(N, self.n, 3, 3)
        R = np.broadcast_to(np.eye(3), (N, 3, 3)).copy()
        p = np.zeros((N, 3))
        for i in range(self.n):
            p = p + R @ self.origins[i]
            if self.origin_rot:
                R = R @ self.R_origin[i]
            R = R @ Rj[:, i]
        T = np.broadcast_to(np.eye(4), (N, 4, 4)).copy()
        T[:, :3, :3] = R @ self.R_flange
        T[:, :3, 3] = p + R @ self.p_flange
        return T

    def _forward_mixed(self, A: np.ndarray) -> np.ndarray:
        """:meth:`forward_many` of a chain with linear joints (each moves along its axis by its
        value in mm; the rotary ones as above)."""
        N = A.shape[0]
        R = np.broadcast_to(np.eye(3), (N, 3, 3)).copy()
        p = np.zeros((N, 3))
        for i in range(self.n):
            p = p + R @ self.origins[i]
            if self.origin_rot:
                R = R @ self.R_origin[i]
            if self.linear[i]:
                p = p + (R @ self.axes[i]) * (self.kuka_sign[i] * A[:, i])[:, None]
            else:
                R = R @ Rotation.from_rotvec(self.axes[i][None, :] * np.radians(self.kuka_sign[i] * A[:, i])[:, None]
                                             ).as_matrix()
        T = np.broadcast_to(np.eye(4), (N, 4, 4)).copy()
        T[:, :3, :3] = R @ self.R_flange
        T[:, :3, 3] = p + R @ self.p_flange
        return T

    def joint_point(self, axes_deg, index: int) -> np.ndarray:
        """Position (mm, in ``$ROBROOT``) of the origin of joint `index` (0 = A1), rotary joints."""
        q = self.kuka_sign * np.radians(np.asarray(axes_deg, dtype=float)[:self.n])
        R = np.eye(3)
        p = np.zeros(3)
        for i in range(index + 1):
            p = p + R @ self.origins[i]
            if self.origin_rot:
                R = R @ self.R_origin[i]
            R = R @ Rotation.from_rotvec(self.axes[i] * q[i]).as_matrix()
        return p

    def _compiled(self) -> Any:
        """robot/ipocycle.py's ``Forward`` of these joints compiled when it is built and current
        (robot/kinematics/compiled.py ``pure_module``), numpy's BLAS is at hand (robot/blas.py),
        it gives :meth:`forward_py` bit for bit on 64 random axis sets
        (wide angles, small ones, zeros and signed zeros); else False."""
        mod = pure_module(ipocycle)
        if not mod.COMPILED:
            return False
        gemm, gemv = numpy_cblas("dgemm"), numpy_cblas("dgemv")
        if not gemm or not gemv:
            return False
        c = self._forward_of(mod, gemm, gemv)
        key = (id(mod), gemm, gemv, self.origin_rot, *(a.tobytes() for a in (
            self.origins, self.axes, self.kuka_sign, self.R_origin, self.R_flange, self.p_flange, self.linear)))
        verdict = _CHECKED.get(key)
        if verdict is None:
            verdict = _CHECKED[key] = self._same_as_python(c)
        return c if verdict else False

    def _forward_of(self, mod: Any, gemm: int, gemv: int) -> Any:
        """The ``Forward`` of robot/ipocycle.py `mod` (compiled or as Python) for these joints."""
        return mod.Forward(gemm, gemv, self.origins.tolist(), self.axes.tolist(), self.kuka_sign.tolist(),
                           self.R_origin, self.origin_rot, self.R_flange, self.p_flange.tolist(),
                           self.linear.tolist())

    def _same_as_python(self, c: Any) -> bool:
        """The compiled Forward `c` gives :meth:`forward_py` bit for bit on the 64 axis sets, and
        its ``tcp_points`` the Python one's on 9 points between two of them in random frames."""
        rng = np.random.default_rng(39)
        T = np.empty((4, 4))
        for i in range(64):
            a = rng.uniform(-360.0, 360.0, self.n) * (1e-4 if i % 4 == 1 else 1.0)
            if i % 3 == 0:
                a[rng.integers(0, self.n)] = -0.0 if i % 2 else 0.0
            c.forward(a, T)
            if T.tobytes() != self.forward_py(a).tobytes():
                return False
        frames = []
        for _ in range(3):
            F = np.eye(4)
            F[:3, :3] = Rotation.from_rotvec(rng.uniform(-2.0, 2.0, 3)).as_matrix()
            F[:3, 3] = rng.uniform(-900.0, 900.0, 3)
            frames.append(F)
        q0, dq, us = rng.uniform(-170.0, 170.0, self.n), rng.uniform(-90.0, 90.0, self.n), np.linspace(0.0, 1.0, 9)
        a, b = np.empty((9, 3)), np.empty((9, 3))
        for has in (True, False):
            c.tcp_points(q0, dq, us, frames[0], has, frames[1], frames[2], a)
            self._python().tcp_points(q0, dq, us, frames[0], has, frames[1], frames[2], b)
            if a.tobytes() != b.tobytes():
                return False
        return True


#: the identity as ``tcp_points``' unused $ROBROOT
_EYE4 = np.eye(4)


def _c64(a: np.ndarray) -> np.ndarray:
    """`a` as a C-contiguous float64 array (itself when it is one)."""
    return np.ascontiguousarray(a, dtype=float)


#: :meth:`JointChain._compiled`'s verdicts in this process, by the chain's numbers (their bytes)
#: and the compiled module's BLAS: a process that runs many programs on one robot (a conformance
#: worker, the tests) checks its compiled forward once, not at each run (64 forward_py, 0.02 s of
#: CPU, a quarter of a small program's run). Each chain keeps its own Forward (its scratch buffers).
_CHECKED: dict[tuple, bool] = {}


__all__ = ["JointChain"]
