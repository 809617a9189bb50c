"""Forward and inverse kinematics of any robot model (:class:`~robot.machine.MachineData`:
the KR 6 R900 yaml or a backup's machine data) in KUKA's conventions.

Sources: robot-model.md §2-§4 (chain, OPW parameters), §7 (frame chain),
§8 (status S and turn T), reference §6.4-§6.5 and §8.2 (errors).

Units: mm and degrees everywhere (axis values A1..A6 in deg, frames as 4x4
homogeneous transforms in mm). The FLANGE frame is KUKA's flange (= URDF
``tool0``: +Z out of the flange), expressed in ``$ROBROOT``.

Forward kinematics walks the URDF-style joints of the model (joint origins and axes,
``q_urdf = radians(A_i)``, robot-model.md §3). The inverse kinematics is chosen from the
chain, never from the robot's name (:attr:`Kinematics.family`):

* ``"opw"``: the six-axis arm with a spherical wrist, the analytic OPW solution
  (Brandstötter et al. 2014; its parameters from robot/chain.py ``opw_form``, with any
  ``$TIRORO`` before it and any ``$TFLWP`` after it), up to 8 solutions, one per status S;
* ``"palletizer4"`` (``$DEF_A4FIX`` and ``$DEF_A5LINK``) and ``"palletizer5"``
  (``$DEF_A4FIX`` only): the closed forms of robot/ik_palletizer.py;
* ``"numeric"``: any other arm, robot/ik_numeric.py (the MuJoCo model of the robot solved by
  the ``mink`` library from seeds), with the same status/turn selection and errors.

Each analytic form is checked against the machine-data chain when it is chosen. A vectorised
entry point, :meth:`Kinematics.inverse_many`, solves N targets at once with numpy. For the OPW
family, :meth:`Kinematics.inverse` runs the compiled mirror of its Python code when it is built
(robot/simcore.pyx, robot/build.py; the same axes bit for bit, about 20x faster), and so do
:meth:`Kinematics.forward` (the same frames bit for bit, checked at set-up) and the 4-axis
palletizer's solutions (the same rows).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from .errors import SoftLimitError, WorkspaceError
from .frames import as_matrix, inv_pos
from .machine import MachineData, load_machine

try:  # the compiled OPW inverse (robot/build.py); absent without a build: the Python code runs
    from . import simcore as _simcore
except ImportError:
    _simcore = None

#: Values closer than this to a status/turn switching point count as "on" it (deg, mm).
BOUNDARY_EPS = 1e-9
#: |A5| (deg) below which the wrist is treated as singular (A4 + A6 only defined).
WRIST_SINGULAR_DEG = 1e-6
#: Wrist point distance from the A1 axis (mm) below which A1 is undefined.
OVERHEAD_SINGULAR_MM = 1e-6
#: Tolerance of the reachability test on the cosine-law arguments.
_ACOS_TOL = 1e-9
#: Tolerance of the soft-limit test (deg), absorbs floating-point noise.
LIMIT_EPS_DEG = 1e-9
#: Results :meth:`Kinematics.forward` keeps (by the axes' bytes; cleared when full).
FK_MEMO = 256
#: Use the compiled OPW inverse (robot/simcore.pyx) when it is built; False: the Python code
#: (the reference: the two agree bit for bit, tests/robot/test_simcore.py)
USE_COMPILED = True
#: The ``ABI`` of robot/simcore.pyx this module mirrors (a stale build is not used)
SIMCORE_ABI = 5


def _wrap180(v: np.ndarray) -> np.ndarray:
    """Wrap angles (deg) to (-180, 180]."""
    return -((-np.asarray(v, dtype=float) + 180.0) % 360.0) + 180.0


def _compiled_opw(kin: "Kinematics") -> Any:
    """The compiled OPW inverse of `kin` (robot/simcore.pyx, built by robot/build.py), or False
    when the extension is not built, is stale (its ``ABI``) or :data:`USE_COMPILED` is off."""
    if not USE_COMPILED or _simcore is None or getattr(_simcore, "ABI", None) != SIMCORE_ABI:
        return False
    return _simcore.OPW(kin._opw, kin._kappa_2, kin._c2_2, kin._k, kin._at23, kin.phi_deg, kin._sgn,
                      kin._offs, kin._lo_l, kin._hi_l, kin._ks_l, kin._s_free, kin._t_free)


class Kinematics:
    """Kinematics of one robot, built from :class:`~robot.machine.MachineData`.

    Public methods: :meth:`forward`, :meth:`solutions`, :meth:`inverse`,
    :meth:`status_turn`, :meth:`check_soft_limits`, :meth:`tcp_pose`,
    :meth:`flange_target`, :meth:`wrist_point_x`.
    """

    def __init__(self, machine: MachineData | None = None) -> None:
        self.machine = machine if machine is not None else load_machine()
        m = self.machine
        self._origins = np.array([j.origin_mm for j in m.joints], dtype=float)  # (6, 3) mm
        axes = np.array([j.joint_axis for j in m.joints], dtype=float)
        self._axes = axes / np.linalg.norm(axes, axis=1)[:, None]
        self._kuka_sign = np.array([j.kuka_sign for j in m.joints], dtype=float)  # q_urdf = sign * A
        self._R_origin = Rotation.from_euler("xyz", [j.origin_rpy_rad for j in m.joints]).as_matrix()
        self._origin_rot = any(np.any(r) for r in (j.origin_rpy_rad for j in m.joints))
        w, x, y, z = m.flange_quat_wxyz
        self._R_flange = Rotation.from_quat([x, y, z, w]).as_matrix()  # link_6 -> KUKA flange
        self._p_flange = np.array(m.flange_pos_mm, dtype=float)
        self._lo = np.array([j.limit_deg[0] for j in m.joints], dtype=float)
        self._hi = np.array([j.limit_deg[1] for j in m.joints], dtype=float)
        o = m.opw
        self._opw = o
        self._sign = np.array(o.sign_corrections, dtype=float)
        self._off = np.radians(np.array(o.offsets_deg, dtype=float))
        self._home = np.array(m.home_deg, dtype=float)
        self.phi_deg = float(m.status_phi_deg)
        self._ks = np.arange(-2, 3) * 360.0
        self._rows = np.arange(6)
        #: FLANGE of recent forward() axes, by their bytes (a robot at rest asks for the same axes
        #: every IPO cycle; a program's cycle plans the same points again); at most FK_MEMO
        self._fk_memo: dict[bytes, np.ndarray] = {}
        # per-robot constants of the OPW solution and of the status test (hot loop: plain floats)
        self._kappa_2 = o.a2 * o.a2 + o.c3 * o.c3
        self._c2_2 = o.c2 * o.c2
        self._k = math.sqrt(self._kappa_2)
        self._at23 = math.atan2(o.a2, o.c3)
        self._tmp2 = None
        self._sgn = [float(v) for v in self._sign]
        self._offs = [float(v) for v in self._off]
        self._lo_l = [float(v) - LIMIT_EPS_DEG for v in self._lo]
        self._hi_l = [float(v) + LIMIT_EPS_DEG for v in self._hi]
        self._ks_l = [float(v) for v in self._ks]
        # the 4-axis palletizer ($DEF_A5LINK, docs/robot.md "The palletizer"): its own inverse
        self._pa: tuple[np.ndarray, np.ndarray] | None = None
        self._pa5: Any = None       # the 5-axis palletizer (robot/ik_palletizer.py)
        self._numeric: Any = None   # the numeric solver (robot/ik_numeric.py), built on first use
        self._base_inv: np.ndarray | None = None   # INV(frame before the OPW arm), None: identity
        self._end_inv: np.ndarray | None = None    # INV(frame after it)
        self._c_opw: Any = None     # robot/simcore.pyx's OPW for this robot; False: not used
        self._c_pal: Any = None     # robot/simcore.pyx's 4-axis palletizer rows; False: not used
        self._c_fk: Any = None      # robot/simcore.pyx's forward kinematics; False: not used
        self._s_free = 0            # S bits that select nothing on this robot
        self._t_free = 0            # T bits that select nothing on this robot
        #: the inverse kinematics of this robot: "opw", "palletizer4", "palletizer5" or "numeric"
        self.family = "opw"
        where = m.provenance.get("$DEF_A4FIX", m.source)
        if m.a5link:
            self.family = "palletizer4"
            self._init_palletizer()
            self._check_palletizer4(where)
        elif m.a4fix:
            from .ik_palletizer import Palletizer5  # noqa: PLC0415

            self.family = "palletizer5"
            self._pa5 = Palletizer5(self)
            self._s_free = 4
            self._t_free = 0b01000
            self._pa5.check(where)
        elif m.chain is not None:
            self._choose_form()

    def _choose_form(self) -> None:
        """The inverse of a machine-data arm: the standard OPW parameters of robot/mada.py when
        they reproduce the chain, else the OPW form found in the chain's geometry
        (robot/chain.py), else the numeric solver."""
        from dataclasses import replace  # noqa: PLC0415

        from .chain import opw_form  # noqa: PLC0415

        if self._form_agrees():
            return
        form = opw_form(self.machine.chain)
        if form is not None:
            self._set_opw(form.params)
            self._base_inv = np.linalg.inv(form.base) if form.base is not None else None
            self._end_inv = np.linalg.inv(form.end) if form.end is not None else None
            self.phi_deg = form.phi_deg
            if self._form_agrees():
                return
            self._base_inv = self._end_inv = None
        self._set_opw(replace(self.machine.opw))
        self.phi_deg = float(self.machine.status_phi_deg)
        self.family = "numeric"

    def _set_opw(self, o) -> None:
        self._opw = o
        self._c_opw = None
        self._sign = np.array(o.sign_corrections, dtype=float)
        self._off = np.radians(np.array(o.offsets_deg, dtype=float))
        self._kappa_2 = o.a2 * o.a2 + o.c3 * o.c3
        self._c2_2 = o.c2 * o.c2
        self._k = math.sqrt(self._kappa_2)
        self._at23 = math.atan2(o.a2, o.c3)
        self._sgn = [float(v) for v in self._sign]
        self._offs = [float(v) for v in self._off]

    def _form_agrees(self) -> bool:
        """True when the joints reproduce the machine-data chain and the analytic solutions
        reproduce every sample pose (1e-6 mm; robot/chain.py ``chain_forward``)."""
        from .chain import chain_forward  # noqa: PLC0415

        chain = self.machine.chain
        rng = np.random.default_rng(0)
        lo = np.maximum(self._lo, -170.0)
        hi = np.minimum(self._hi, 170.0)
        for q in rng.uniform(lo, hi, size=(4, 6)):
            T = chain_forward(chain, q)
            if np.abs(self.forward(q) - T).max() > 1e-6:
                return False
            rows = self._opw_rows(T, None)
            if not rows or min(np.abs(self.forward(r) - T).max() for r in rows) > 1e-6:
                return False
        return True

    # ------------------------------------------------------------------ FK
    def forward(self, axes_deg: Sequence[float]) -> np.ndarray:
        """FLANGE(A1..A6): KUKA flange frame in ``$ROBROOT`` (robot-model.md §2-§3).

        Args:
            axes_deg: A1..A6 in degrees (6 values).
        Returns:
            4x4 homogeneous transform, translation in mm.

        Recent results are kept by the axes' bytes (at most :data:`FK_MEMO`): a robot at rest
        asks for the same axes every IPO cycle, and a program's cycle plans the same points again.
        """
        a = np.asarray(axes_deg, dtype=float)[:6]
        key = a.tobytes()
        known = self._fk_memo.get(key)
        if known is not None:
            return known.copy()
        c = self._c_fk
        if c is None:
            c = self._c_fk = self._compiled_forward()
        if c:
            T = np.empty((4, 4))
            c.forward(a, T)
        else:
            T = self._forward_py(a)
        if len(self._fk_memo) >= FK_MEMO:
            self._fk_memo.clear()
        self._fk_memo[key] = T.copy()
        return T

    def _forward_py(self, a: np.ndarray) -> np.ndarray:
        """:meth:`forward` of the axes a (6,, deg) in numpy and scipy: the reference the
        compiled forward (robot/simcore.pyx ``Forward``) reproduces bit for bit."""
        q = self._kuka_sign * np.radians(a)
        Rj = Rotation.from_rotvec(self._axes * q[:, None]).as_matrix()  # (6, 3, 3)
        R = np.eye(3)
        p = np.zeros(3)
        for i in range(6):
            p = p + R @ self._origins[i]
            if self._origin_rot:
                R = R @ self._R_origin[i]
            R = R @ Rj[i]
        T = np.eye(4)
        T[:3, :3] = R @ self._R_flange
        T[:3, 3] = p + R @ self._p_flange
        return T

    def _compiled_forward(self) -> Any:
        """robot/simcore.pyx's ``Forward`` of this robot when it is built, numpy's BLAS is at hand
        (robot/blas.py) and it gives :meth:`_forward_py` bit for bit on 64 random axis sets
        (wide angles, small ones, zeros and signed zeros); else False."""
        if not USE_COMPILED or _simcore is None or getattr(_simcore, "ABI", None) != SIMCORE_ABI:
            return False
        from .blas import numpy_cblas  # noqa: PLC0415

        gemm, gemv = numpy_cblas("dgemm"), numpy_cblas("dgemv")
        if not gemm or not gemv:
            return False
        c = _simcore.Forward(gemm, gemv, self._origins.tolist(), self._axes.tolist(), self._kuka_sign.tolist(),
                             self._R_origin, self._origin_rot, self._R_flange, self._p_flange.tolist())
        rng = np.random.default_rng(39)
        T = np.empty((4, 4))
        for i in range(64):
            a = rng.uniform(-360.0, 360.0, 6) * (1e-4 if i % 4 == 1 else 1.0)
            if i % 3 == 0:
                a[rng.integers(0, 6)] = -0.0 if i % 2 else 0.0
            c.forward(a, T)
            if T.tobytes() != self._forward_py(a).tobytes():
                return False
        return c

    def forward_many(self, axes_deg: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`forward`: axes (n, 6) in deg -> flange frames (n, 4, 4), mm."""
        Q = self._kuka_sign * np.radians(np.atleast_2d(np.asarray(axes_deg, dtype=float))[:, :6])
        n = Q.shape[0]
        Rj = Rotation.from_rotvec((self._axes[None, :, :] * Q[:, :, None]).reshape(-1, 3)).as_matrix()
        Rj = Rj.reshape(n, 6, 3, 3)
        R = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
        p = np.zeros((n, 3))
        for i in range(6):
            p = p + R @ self._origins[i]
            if self._origin_rot:
                R = R @ self._R_origin[i]
            R = R @ Rj[:, i]
        T = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
        T[:, :3, :3] = R @ self._R_flange
        T[:, :3, 3] = p + R @ self._p_flange
        return T

    # ------------------------------------------------------------------ S/T
    def wrist_point_x(self, axes_deg: Sequence[float]) -> float:
        """x of the wrist point in the A1 frame, mm (robot-model.md §4.4; S bit 0)."""
        q = np.asarray(axes_deg, dtype=float)
        o = self._opw
        t2 = math.radians(self._sign[1] * q[1]) - self._off[1]
        t3 = math.radians(self._sign[2] * q[2]) - self._off[2]
        return float(o.a1 + o.c2 * math.sin(t2) + o.c3 * math.sin(t2 + t3)
                     + o.a2 * math.cos(t2 + t3))

    def status_turn(self, axes_deg: Sequence[float]) -> tuple[int, int]:
        """Status S and turn T of an axis configuration (robot-model.md §8, reference §6.5).

        S bit 0 = 1 if the wrist point is behind the A1 axis (overhead area);
        bit 1 = 1 if A3 >= phi (4.764°); bit 2 = 1 if A5 < 0 (A5 = 0 counts as
        0, matching the HOME test vector S = 2).
        T bit i = 1 if A(i+1) < 0 (0 counts as positive).
        Values within 1e-9 deg/mm of a switching point count as on its
        non-negative side (floating-point noise).

        Returns:
            (S, T) as ints.
        """
        q = np.asarray(axes_deg, dtype=float)[:6]
        s = 0
        if self.wrist_point_x(q) < -BOUNDARY_EPS:
            s |= 1
        if q[2] >= self.phi_deg - BOUNDARY_EPS:
            s |= 2
        if q[4] < -BOUNDARY_EPS:
            s |= 4
        t = 0
        for i in range(6):
            if q[i] < -BOUNDARY_EPS:
                t |= 1 << i
        return s, t

    def _status_row(self, q: list[float]) -> tuple[int, int]:
        """S of one axis configuration (list of 6 floats, deg) and the mask of its S bits
        that sit on their switching point (see :meth:`_status_bits`)."""
        o = self._opw
        t2 = math.radians(self._sgn[1] * q[1]) - self._offs[1]
        t23 = t2 + math.radians(self._sgn[2] * q[2]) - self._offs[2]
        xw = o.a1 + o.c2 * math.sin(t2) + o.c3 * math.sin(t23) + o.a2 * math.cos(t23)
        phi = self.phi_deg
        s = int(xw < -BOUNDARY_EPS) | (int(q[2] >= phi - BOUNDARY_EPS) << 1) | (int(q[4] < -BOUNDARY_EPS) << 2)
        amb = (int(abs(xw) < OVERHEAD_SINGULAR_MM) | (int(abs(q[2] - phi) < 1e-7) << 1)
               | (int(abs(q[4]) < WRIST_SINGULAR_DEG) << 2) | self._s_free)
        return s, amb

    def _status_bits(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Vectorised S of the rows of Q (n, 6), plus a mask of the S bits that sit
        on their switching point (wrist point on the A1 axis, A3 = phi, A5 = 0)."""
        pairs = [self._status_row(q) for q in np.asarray(Q, dtype=float).tolist()]
        s_out = [p[0] for p in pairs]
        amb_out = [p[1] for p in pairs]
        return np.array(s_out, dtype=int), np.array(amb_out, dtype=int)

    # ------------------------------------------------------------------ limits
    def check_soft_limits(self, axes_deg: Sequence[float]) -> None:
        """Raise :class:`~robot.errors.SoftLimitError` for the first axis outside
        ``$SOFTN_END``/``$SOFTP_END`` (reference §8.2): message
        ``"software limit switch +A1"`` / ``"... -A2"``. Returns None otherwise."""
        q = np.asarray(axes_deg, dtype=float)[:6]
        for i in range(6):
            if q[i] < self._lo[i] - LIMIT_EPS_DEG:
                raise SoftLimitError(i + 1, float(q[i]), positive=False)
            if q[i] > self._hi[i] + LIMIT_EPS_DEG:
                raise SoftLimitError(i + 1, float(q[i]), positive=True)

    def within_limits(self, axes_deg: Sequence[float]) -> bool:
        """True if every axis lies within its soft limits."""
        q = np.asarray(axes_deg, dtype=float)[:6]
        return bool(np.all(q >= self._lo - LIMIT_EPS_DEG) and np.all(q <= self._hi + LIMIT_EPS_DEG))

    # ------------------------------------------------------------------ IK
    def _opw_solve(self, flange_T: np.ndarray, ref_deg: np.ndarray | None) -> np.ndarray:
        """OPW closed form: (n, 6) array of KUKA axis values (deg, wrapped to (-180, 180]);
        see :meth:`_opw_rows`."""
        rows = self._opw_rows(flange_T, ref_deg)
        return np.array(rows) if rows else np.empty((0, 6))

    # ------------------------------------------------------------------ palletizer
    def _init_palletizer(self) -> None:
        """The 4-axis palletizer (``$DEF_A4FIX``, ``$DEF_A5LINK``; docs/robot.md "The
        palletizer"): A4 stays at 0 and the parallelogram keeps the flange vertical, so a
        flange pose has four degrees of freedom (X, Y, Z and the rotation about the vertical).
        Kept here: the flange's offset from the A5 axis point in the arm's vertical plane at
        A1 = 0 (mm), and the flange rotation at HOME with A1 = A6 = 0. The OPW solver then runs
        on the A5 point (``c4 = 0``). S bit 2 and T bits 3, 4 (A4, A5) select nothing."""
        from dataclasses import replace  # noqa: PLC0415

        q = np.array(self.machine.home_deg, dtype=float)
        q[0] = q[3] = q[5] = 0.0
        T = self.forward(q)
        self._pa = (T[:3, 3] - self._joint_point(q, 4), T[:3, :3].copy())
        self._opw = replace(self._opw, c4=0.0)
        self._s_free = 4
        self._t_free = 0b11000

    def _check_palletizer4(self, where: str) -> None:
        """The 4-axis closed form must give back random linked configurations of the chain
        (A4 = 0, A2 + A3 + A5 as at HOME); robot.mada.MachineDataError otherwise."""
        home = self._home

        def link(q):
            q[4] = home[4] + home[1] + home[2] - q[1] - q[2]

        led = "$NUM_AX=4" if "a5_led" in self.machine.provenance else "$DEF_A5LINK=TRUE"
        self.check_closed_form(
            self._palletizer_rows, where,
            f"$DEF_A4FIX=TRUE, A5 led ({led}): this palletizer's arm ($TIRORO, $TX3P3, $DH_4, $DH_5, "
            f"$TFLWP) is not one the 4-axis closed form covers", link=link)

    def check_closed_form(self, rows, where: str, message: str, link=None) -> None:
        """Raise robot.mada.MachineDataError (``"{where}: {message}"``) unless the closed form
        ``rows(T, q)`` (a list of axis rows for the flange pose T, 4x4, mm) gives back four
        random configurations of the machine-data chain within 1e-6: A4 = 0, and `link(q)`
        sets the axes the arm's linkage leads. Also raises when the chain of the machine data
        does not close on :meth:`forward`."""
        from .chain import chain_forward  # noqa: PLC0415
        from .mada import MachineDataError  # noqa: PLC0415

        rng = np.random.default_rng(0)
        lo = np.maximum(self._lo, -170.0)
        hi = np.minimum(self._hi, 170.0)
        for q in rng.uniform(lo, hi, size=(4, 6)):
            q[3] = 0.0
            if link is not None:
                link(q)
            T = self.forward(q)
            if self.machine.chain is not None and np.abs(chain_forward(self.machine.chain, q) - T).max() > 1e-6:
                raise MachineDataError(f"{where}: internal chain does not close")
            found = rows(T, q)
            if not found or min(np.abs(self.forward(r) - T).max() for r in found) > 1e-6:
                raise MachineDataError(f"{where}: {message}")

    def _joint_point(self, axes_deg: Sequence[float], index: int) -> np.ndarray:
        """Position (mm, in ``$ROBROOT``) of the origin of joint `index` (0 = A1)."""
        q = self._kuka_sign * np.radians(np.asarray(axes_deg, dtype=float)[:6])
        R = np.eye(3)
        p = np.zeros(3)
        for i in range(index + 1):
            p = p + R @ self._origins[i]
            if self._origin_rot:
                R = R @ self._R_origin[i]
            R = R @ Rotation.from_rotvec(self._axes[i] * q[i]).as_matrix()
        return p

    def _palletizer_rows(self, flange_T: np.ndarray, ref_deg: np.ndarray | None) -> list[list[float]]:
        """Solutions of a flange pose on the 4-axis palletizer (see :meth:`_init_palletizer`).

        The pose's tilt (its B and C against the vertical) is not followed: KUKA's 4-axis
        transformation has no axis for it, and the flange keeps the nearest vertical pose
        (the rotation about the vertical that is closest in the least-squares sense). The arm
        plane's direction is that of the flange seen from the A1 axis; the A5 point lies the
        fixed offset back from the flange in that plane; OPW solves the arm for that point.
        Only rows that put the flange where asked (1e-6 mm) are kept; A4 is 0."""
        offset, R_ref = self._pa  # type: ignore[misc]
        T = np.asarray(flange_T, dtype=float)
        R_rel = T[:3, :3] @ R_ref.T
        psi = math.atan2(R_rel[1, 0] - R_rel[0, 1], R_rel[0, 0] + R_rel[1, 1])
        c, s = math.cos(psi), math.sin(psi)
        Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        R_v = Rz @ R_ref
        p = T[:3, 3]
        c_pal = self._c_pal
        if c_pal is None:
            c_pal = self._c_pal = self._compiled_palletizer()
        if c_pal:
            # the compiled mirror of the loop below (robot/simcore.pyx Palletizer4): the same rows
            return c_pal.rows(R_v, p, ref_deg)
        rows: list[list[float]] = []
        phi = math.atan2(p[1], p[0])
        for arm in (phi, phi + math.pi):
            ca, sa = math.cos(arm), math.sin(arm)
            w = p - np.array([ca * offset[0] - sa * offset[1], sa * offset[0] + ca * offset[1], offset[2]])
            Tw = np.eye(4)
            Tw[:3, :3] = R_v
            Tw[:3, 3] = w
            for row in self._opw_core(Tw, ref_deg):
                if abs(row[3]) < 1e-6:
                    row[3] = 0.0
                elif abs(abs(row[3]) - 180.0) < 1e-6:
                    continue                    # the flipped wrist: A4 cannot turn
                if float(np.abs(self.forward(row)[:3, 3] - p).max()) < 1e-6:
                    rows.append(row)
        return rows

    def _compiled_palletizer(self) -> Any:
        """robot/simcore.pyx's ``Palletizer4`` for this robot, or False (not built, stale, or
        :data:`USE_COMPILED` off: :meth:`_palletizer_rows` runs its Python loop)."""
        c = _compiled_opw(self)
        if not c:
            return False
        return _simcore.Palletizer4(c, self._origins.tolist(), self._axes.tolist(), self._kuka_sign.tolist(),
                                    self._R_origin.tolist(), self._origin_rot, self._R_flange.tolist(),
                                    self._p_flange.tolist(), self._pa[0].tolist())

    def _opw_rows(self, flange_T: np.ndarray, ref_deg: np.ndarray | None) -> list[list[float]]:
        """The analytic solutions of a flange pose: :meth:`_opw_core`, or for the 4-axis
        palletizer :meth:`_palletizer_rows`."""
        if self._pa is not None:
            return self._palletizer_rows(flange_T, ref_deg)
        if self._pa5 is not None:
            return self._pa5.rows(flange_T, ref_deg)
        if self.family == "numeric":
            if self._numeric is None:
                from .ik_numeric import NumericIK  # noqa: PLC0415

                self._numeric = NumericIK(self)
            return self._numeric.rows(flange_T, ref_deg)
        if self._base_inv is not None or self._end_inv is not None:
            T = np.asarray(flange_T, dtype=float)
            if self._base_inv is not None:
                T = self._base_inv @ T
            if self._end_inv is not None:
                T = T @ self._end_inv
            return self._opw_core(T, ref_deg)
        return self._opw_core(flange_T, ref_deg)

    def _opw_core(self, flange_T: np.ndarray, ref_deg: np.ndarray | None) -> list[list[float]]:
        """OPW closed form: up to 8 lists of KUKA axis values (deg, wrapped to (-180, 180]).

        With ``ref_deg`` the free angle at a singularity is taken from it:
        A1 when the wrist point is on the A1 axis, A4 when A5 = 0.
        """
        o = self._opw
        rows = np.asarray(flange_T, dtype=float).tolist()
        (r00, r01, r02, px), (r10, r11, r12, py), (r20, r21, r22, pz) = rows[0], rows[1], rows[2]
        cx, cy, cz = px - o.c4 * r02, py - o.c4 * r12, pz - o.c4 * r22  # wrist point
        rho2 = cx * cx + cy * cy - o.b * o.b
        if rho2 < 0.0:
            return []
        nx1 = math.sqrt(rho2) - o.a1
        if math.sqrt(cx * cx + cy * cy) < OVERHEAD_SINGULAR_MM and ref_deg is not None:
            tmp1 = math.radians(self._sgn[0] * float(ref_deg[0])) - self._offs[0]
        else:
            tmp1 = math.atan2(cy, cx)
        tmp2 = math.atan2(o.b, nx1 + o.a1)
        th1_i = tmp1 - tmp2
        th1_ii = tmp1 + tmp2 - math.pi
        tmp3 = cz - o.c1
        s1_2 = nx1 * nx1 + tmp3 * tmp3
        tmp4 = nx1 + 2.0 * o.a1
        s2_2 = tmp4 * tmp4 + tmp3 * tmp3
        kappa_2 = self._kappa_2
        c2_2 = self._c2_2
        s1 = math.sqrt(s1_2)
        s2 = math.sqrt(s2_2)
        k = self._k
        at23 = self._at23

        arms = []  # (th1, th2, th3)
        for th1, s_, s_2, base2 in ((th1_i, s1, s1_2, math.atan2(nx1, tmp3)),
                                    (th1_ii, s2, s2_2, -math.atan2(tmp4, tmp3))):
            if s_ < 1e-12:
                continue
            arg2 = (s_2 + c2_2 - kappa_2) / (2.0 * s_ * o.c2)
            arg3 = (s_2 - c2_2 - kappa_2) / (2.0 * o.c2 * k)
            if abs(arg2) > 1.0 + _ACOS_TOL or abs(arg3) > 1.0 + _ACOS_TOL:
                continue
            a2c = math.acos(min(1.0, max(-1.0, arg2)))
            a3c = math.acos(min(1.0, max(-1.0, arg3)))
            arms.append((th1, -a2c + base2, a3c - at23))
            arms.append((th1, a2c + base2, -a3c - at23))
        if not arms:
            return []

        sols = []
        for th1, th2, th3 in arms:
            sn1, cs1 = math.sin(th1), math.cos(th1)
            s23, c23 = math.sin(th2 + th3), math.cos(th2 + th3)
            mm = r02 * s23 * cs1 + r12 * s23 * sn1 + r22 * c23
            th5 = math.atan2(math.sqrt(max(0.0, 1.0 - mm * mm)), mm)
            th4 = math.atan2(r12 * cs1 - r02 * sn1,
                             r02 * c23 * cs1 + r12 * c23 * sn1 - r22 * s23)
            th6 = math.atan2(r01 * s23 * cs1 + r11 * s23 * sn1 + r21 * c23,
                             -r00 * s23 * cs1 - r10 * s23 * sn1 - r20 * c23)
            if ref_deg is not None and abs(math.degrees(th5)) < WRIST_SINGULAR_DEG:
                # Wrist singularity: only th4 + th6 is defined; keep A4 of the reference.
                total = th4 + th6
                th4 = math.radians(self._sgn[3] * float(ref_deg[3])) - self._offs[3]
                th6 = total - th4
            sols.append((th1, th2, th3, th4, th5, th6))
            sols.append((th1, th2, th3, th4 + math.pi, -th5, th6 - math.pi))
        # q = wrap180(degrees((opw + offset) * sign)), in plain floats (the same operations,
        # in the same order, as numpy's degrees/remainder: the same values)
        offs, sgn, deg = self._offs, self._sgn, math.degrees
        return [[-((-deg((th + offs[i]) * sgn[i]) + 180.0) % 360.0) + 180.0 for i, th in enumerate(sol)]
                for sol in sols]

    def solutions(self, flange_T: np.ndarray) -> list[np.ndarray]:
        """All analytic OPW solutions for a flange pose (robot-model.md §4.2, §8).

        Args:
            flange_T: 4x4 flange frame in ``$ROBROOT``, mm.
        Returns:
            list of up to 8 arrays of shape (6,), A1..A6 in deg wrapped to
            (-180, 180], any order, before soft-limit filtering and without the
            ±360° variants. Empty if the pose is out of reach. At a singularity
            the split of the free angles is arbitrary.
        """
        return [row.copy() for row in self._opw_solve(flange_T, None)]

    def inverse(self, flange_T: np.ndarray, status: int | None = None, turn: int | None = None,
                reference_deg: Sequence[float] | None = None) -> np.ndarray:
        """Axis values for a flange pose, selected by status and turn (robot-model.md §8,
        reference §6.5).

        Args:
            flange_T: 4x4 flange frame in ``$ROBROOT``, mm.
            status: S; bits 0..2 select the IK branch (masked with 7). None: keep
                the status of ``reference_deg`` (a bit whose switching point the
                reference sits on, e.g. A5 = 0 for bit 2, is left free).
            turn: T; bit i = 1 means A(i+1) < 0, selecting the ±360° variant of
                each axis. None: each axis takes the value nearest to
                ``reference_deg`` (shortest axis motion).
            reference_deg: current axes A1..A6 (deg); default HOME. Also supplies
                the free angle at singularities (A4 when A5 = 0, A1 when the wrist
                point is on the A1 axis).
        Returns:
            array (6,) A1..A6 in deg.
        Raises:
            WorkspaceError: no solution (out of reach) or none with the requested S.
            SoftLimitError: the solution(s) with the requested S/T violate
                ``$SOFTN_END``/``$SOFTP_END``.
        """
        ref = self._home.copy() if reference_deg is None else np.asarray(reference_deg, dtype=float)[:6]
        c = self._c_opw
        if c is None:
            c = self._compiled()
        if c:
            # the compiled mirror of _opw_core + _select (robot/simcore.pyx); None: Python decides
            T = np.asarray(flange_T, dtype=float)
            if self._base_inv is not None:
                T = self._base_inv @ T
            if self._end_inv is not None:
                T = T @ self._end_inv
            q = c.inverse(T, status, turn, ref)
            if q is not None:
                return q
        if self.family == "numeric" and reference_deg is not None:
            # the solution reached from the reference: the nearest one, when its S and T fit
            if self._numeric is None:
                self._opw_rows(np.eye(4), None)
            near = self._numeric.rows(flange_T, ref, near_only=True)
            if near:
                try:
                    return self._select(near, status, turn, ref)
                except (WorkspaceError, SoftLimitError):
                    pass
        return self._select(self._opw_rows(flange_T, ref), status, turn, ref)

    def _compiled(self) -> Any:
        """The compiled OPW inverse of this robot (kept), or False (not built, not the OPW family)."""
        if self._c_opw is None:
            ok = self.family == "opw" and self._pa is None and self._pa5 is None
            self._c_opw = _compiled_opw(self) if ok else False
        return self._c_opw

    @property
    def compiled_inverse(self) -> bool:
        """True when :meth:`inverse` runs the compiled OPW code (robot/simcore.pyx)."""
        return bool(self._compiled())

    def _select(self, rows: list[list[float]], status: int | None, turn: int | None,
                ref: np.ndarray) -> np.ndarray:
        """The solution of `rows` that :meth:`inverse` returns (its steps 1-3), or its error."""
        if not rows:
            raise WorkspaceError("workspace error: target not reachable")
        if status is not None:
            s_target, free = int(status) & 7, 0
        else:
            # keep the reference's status; bits the reference sits exactly on
            # (A5 = 0, A3 = phi, wrist point on the A1 axis) are free
            s_target, free = self._status_row(ref.tolist())
        keep = ~free
        matching_rows = []
        for r in rows:
            s_r, amb = self._status_row(r)
            if ((s_r ^ s_target) & ~amb & keep & 7) == 0:
                matching_rows.append(r)
        if not matching_rows:
            raise WorkspaceError(f"workspace error: target not reachable with status S={s_target}")
        # per solution and axis the ±360° variant within the limits (and the turn) nearest to
        # the reference, then the solution with the least axis motion (the first of equals)
        ref_l = ref.tolist()
        lo, hi = self._lo_l, self._hi_l
        if turn is not None:
            turn = int(turn) & ~self._t_free
        negs = [(int(turn) >> i) & 1 == 1 for i in range(6)] if turn is not None else None
        free_t = [(self._t_free >> i) & 1 == 1 for i in range(6)]
        best: tuple[float, list[float]] | None = None
        for b in matching_rows:
            q: list[float] = []
            for i in range(6):
                best_c, best_d = None, math.inf
                for kk in self._ks_l:
                    c = b[i] + kk
                    if c < lo[i] or c > hi[i]:
                        continue
                    if negs is not None and not ((c < 0) == negs[i] or abs(c) < 1e-6 or free_t[i]):
                        continue
                    d = abs(c - ref_l[i])
                    if d < best_d:
                        best_c, best_d = c, d
                if best_c is None:
                    break
                q.append(best_c)
            else:
                cost = 0.0
                for i in range(6):
                    cost += abs(q[i] - ref_l[i])
                if best is None or cost < best[0]:
                    best = (cost, q)
        if best is not None:
            return np.array(best[1])
        matching = np.array(matching_rows)
        if turn is not None:
            neg = ((int(turn) >> np.arange(6)) & 1).astype(bool)[:, None]  # (6, 1)
            t_free = ((self._t_free >> np.arange(6)) & 1).astype(bool)[:, None]
        best_ok: tuple[float, np.ndarray] | None = None
        best_bad: tuple[float, np.ndarray, int] | None = None
        for b in matching:
            cands = b[:, None] + self._ks[None, :]  # (6, 5): the ±360° variants per axis
            ok = np.ones(cands.shape, dtype=bool)
            if turn is not None:
                ok = ((cands < 0) == neg) | (np.abs(cands) < 1e-6) | t_free
            inlim = ok & (cands >= self._lo[:, None] - LIMIT_EPS_DEG) & (cands <= self._hi[:, None] + LIMIT_EPS_DEG)
            dist = np.where(inlim, np.abs(cands - ref[:, None]), np.inf)
            pick = np.argmin(dist, axis=1)
            q = cands[self._rows, pick]
            axis_bad = ~inlim.any(axis=1)
            if not axis_bad.any():
                cost = float(np.sum(np.abs(q - ref)))
                if best_ok is None or cost < best_ok[0]:
                    best_ok = (cost, q)
                continue
            # for the error: the allowed (turn) variant nearest to the limits
            over = np.maximum(self._lo[:, None] - cands, cands - self._hi[:, None])
            over = np.where(ok, over, np.inf)
            q_bad = np.where(axis_bad, cands[self._rows, np.argmin(over, axis=1)], q)
            cost = float(np.sum(np.abs(q_bad - ref)))
            if best_bad is None or cost < best_bad[0]:
                best_bad = (cost, q_bad, int(np.argmax(axis_bad)))
        if best_ok is not None:
            return best_ok[1]
        assert best_bad is not None
        _, q, i = best_bad
        raise SoftLimitError(i + 1, float(q[i]), positive=bool(q[i] > self._hi[i]))

    # ------------------------------------------------------------------ vectorised IK
    def inverse_many(self, flange_T: np.ndarray, status: int | None = None, turn: int | None = None,
                     reference_deg: Sequence[float] | np.ndarray | None = None) -> np.ndarray:
        """:meth:`inverse` of N flange poses at once (numpy over the targets).

        Args:
            flange_T: (N, 4, 4) flange frames in ``$ROBROOT``, mm.
            status, turn: as for :meth:`inverse`, the same for every target.
            reference_deg: (6,) or (N, 6) axes (deg); default HOME.
        Returns:
            (N, 6) A1..A6 in deg, row i equal to ``inverse(flange_T[i], status, turn,
            reference_deg[i])`` — bit for bit on the OPW family, where every operation is the
            scalar one in the same order (``math.acos`` is used, as numpy's ``arccos`` may differ
            in the last bit); the other families solve the rows one by one.
        Raises:
            WorkspaceError, SoftLimitError: those of the first row that fails, with the
                attribute ``row`` (its index).
        """
        Ts = orig = np.asarray(flange_T, dtype=float).reshape(-1, 4, 4)
        n = Ts.shape[0]
        if reference_deg is None:
            refs = np.broadcast_to(self._home, (n, 6)).astype(float)
        else:
            refs = np.broadcast_to(np.asarray(reference_deg, dtype=float)[..., :6], (n, 6)).astype(float)
        if self.family != "opw" or n == 0:
            return self._inverse_rows(Ts, status, turn, refs, range(n))
        if self._base_inv is not None:
            Ts = self._base_inv @ Ts
        if self._end_inv is not None:
            Ts = Ts @ self._end_inv
        Q, valid, _ = self._opw_core_many(Ts, refs)                # (n, 8, 6), (n, 8)
        return self._select_many(Q, valid, orig, status, turn, refs)

    def inverse_chain(self, flange_T: np.ndarray, status: int | None, reference_deg: Sequence[float],
                      passes: int) -> np.ndarray | None:
        """:meth:`inverse` along a chain of N flange poses, each solution the reference of
        the next one (the first one's: `reference_deg`; turn None): (N, 6) axes, bit for bit
        those of N calls in turn, or None when the chain is to be solved call by call (not
        the OPW family, an error on some pose, no fixed point within `passes`).

        Each pass solves every row at once (:meth:`inverse_many`) with a guess of the rows,
        shifted by one, as references (first pass: `reference_deg` for all; then the previous
        pass's rows, unwrapped); a pass that gives back its guess is the sequential chain
        (row i's reference is row i-1's solution, by induction over i). The analytic solutions are computed once unless a
        pose sits at a singularity, where they take a free angle from the reference.
        Raises nothing: errors give None (the caller's per-pose solve raises them)."""
        if self.family != "opw":
            return None
        Ts = orig = np.asarray(flange_T, dtype=float).reshape(-1, 4, 4)
        n = Ts.shape[0]
        if n == 0:
            return None
        refs = np.empty((n, 6))
        refs[:] = np.asarray(reference_deg, dtype=float)[:6]
        if self._base_inv is not None:
            Ts = self._base_inv @ Ts
        if self._end_inv is not None:
            Ts = Ts @ self._end_inv
        try:
            Q, valid, ref_free = self._opw_core_many(Ts, refs)
            out = self._select_many(Q, valid, orig, status, None, refs)
            for _ in range(passes):
                # the guess: each axis continued from the row before (±360°, np.unwrap), so a
                # turn past ±180° is followed in one pass, within the soft limits (past one
                # the pass's own value); unchanged values keep their bits
                g = np.unwrap(out, period=360.0, axis=0)
                g = np.where((g == out) | (g < self._lo) | (g > self._hi), out, g)
                refs[1:] = g[:-1]
                if not ref_free:
                    Q, valid, _ = self._opw_core_many(Ts, refs)
                new = self._select_many(Q, valid, orig, status, None, refs)
                if new.tobytes() == g.tobytes():
                    return new
                out = new
        except (WorkspaceError, SoftLimitError):
            return None
        return None

    def _select_many(self, Q: np.ndarray, valid: np.ndarray, orig: np.ndarray, status: int | None,
                     turn: int | None, refs: np.ndarray) -> np.ndarray:
        """:meth:`_select` over the analytic solutions Q (N, 8, 6) of the flange poses `orig`
        (rows without a usable solution are solved by :meth:`inverse`, raising its error)."""
        n = Q.shape[0]
        S, amb = self._status_many(Q)                              # (n, 8)
        if status is not None:
            s_target = np.full(n, int(status) & 7)
            free = np.zeros(n, dtype=int)
        else:
            s_target, free = self._status_many(refs[:, None, :])
            s_target, free = s_target[:, 0], free[:, 0]
        keep = ~free
        match = valid & ((((S ^ s_target[:, None]) & ~amb & keep[:, None] & 7) == 0))
        cands = Q[:, :, :, None] + np.array(self._ks_l)[None, None, None, :]   # (n, 8, 6, 5)
        lo = np.array(self._lo_l)[None, None, :, None]
        hi = np.array(self._hi_l)[None, None, :, None]
        ok = (cands >= lo) & (cands <= hi)
        if turn is not None:
            t = int(turn) & ~self._t_free
            neg = (((t >> np.arange(6)) & 1) == 1)[None, None, :, None]
            free_t = (((self._t_free >> np.arange(6)) & 1) == 1)[None, None, :, None]
            ok &= ((cands < 0) == neg) | (np.abs(cands) < 1e-6) | free_t
        dist = np.where(ok, np.abs(cands - refs[:, None, :, None]), np.inf)
        pick = np.argmin(dist, axis=3)                                          # first of equals
        best = np.take_along_axis(cands, pick[..., None], axis=3)[..., 0]       # (n, 8, 6)
        axis_ok = np.isfinite(np.take_along_axis(dist, pick[..., None], axis=3)[..., 0]).all(axis=2)
        d = np.abs(best - refs[:, None, :])
        cost = ((((d[..., 0] + d[..., 1]) + d[..., 2]) + d[..., 3]) + d[..., 4]) + d[..., 5]
        usable = match & axis_ok
        cost = np.where(usable, cost, np.inf)
        j = np.argmin(cost, axis=1)
        out = best[np.arange(n), j]
        bad = ~usable.any(axis=1)
        if bad.any():
            out[bad] = self._inverse_rows(orig, status, turn, refs, np.flatnonzero(bad))
        return out

    def _inverse_rows(self, Ts: np.ndarray, status, turn, refs: np.ndarray, rows) -> np.ndarray:
        """:meth:`inverse` row by row for the indices `rows`; the first error gets ``.row``."""
        out = []
        for i in rows:
            try:
                out.append(self.inverse(Ts[i], status, turn, refs[i]))
            except (WorkspaceError, SoftLimitError) as exc:
                exc.row = int(i)                     # type: ignore[attr-defined]
                raise
        return np.array(out, dtype=float).reshape(-1, 6)

    def _status_many(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_status_row` over the last axis of Q (..., 6): (S, ambiguous bits) arrays."""
        o = self._opw
        t2 = np.radians(self._sgn[1] * Q[..., 1]) - self._offs[1]
        t23 = t2 + np.radians(self._sgn[2] * Q[..., 2]) - self._offs[2]
        xw = o.a1 + o.c2 * np.sin(t2) + o.c3 * np.sin(t23) + o.a2 * np.cos(t23)
        phi = self.phi_deg
        s = ((xw < -BOUNDARY_EPS).astype(int) | ((Q[..., 2] >= phi - BOUNDARY_EPS).astype(int) << 1)
             | ((Q[..., 4] < -BOUNDARY_EPS).astype(int) << 2))
        amb = ((np.abs(xw) < OVERHEAD_SINGULAR_MM).astype(int) | ((np.abs(Q[..., 2] - phi) < 1e-7).astype(int) << 1)
               | ((np.abs(Q[..., 4]) < WRIST_SINGULAR_DEG).astype(int) << 2) | self._s_free)
        return s, amb

    def _opw_core_many(self, Ts: np.ndarray, refs: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
        """:meth:`_opw_core` over N targets: (N, 8, 6) axes (deg, wrapped; NaN where a branch
        does not exist), the (N, 8) mask of existing solutions, in the scalar order, and
        whether the result is free of `refs` (no target at a singularity)."""
        o = self._opw
        acos = np.frompyfunc(math.acos, 1, 1)
        atan2_ = np.frompyfunc(math.atan2, 2, 1)

        def atan2(y, x):
            return atan2_(y, x).astype(float)
        r00, r01, r02, px = Ts[:, 0, 0], Ts[:, 0, 1], Ts[:, 0, 2], Ts[:, 0, 3]
        r10, r11, r12, py = Ts[:, 1, 0], Ts[:, 1, 1], Ts[:, 1, 2], Ts[:, 1, 3]
        r20, r21, r22, pz = Ts[:, 2, 0], Ts[:, 2, 1], Ts[:, 2, 2], Ts[:, 2, 3]
        cx, cy, cz = px - o.c4 * r02, py - o.c4 * r12, pz - o.c4 * r22
        rho2 = cx * cx + cy * cy - o.b * o.b
        reach = rho2 >= 0.0
        nx1 = np.sqrt(np.where(reach, rho2, 0.0)) - o.a1
        over = np.sqrt(cx * cx + cy * cy) < OVERHEAD_SINGULAR_MM
        ref_free = not bool(over.any())
        tmp1 = np.where(over, np.radians(self._sgn[0] * refs[:, 0]) - self._offs[0], atan2(cy, cx))
        tmp2 = atan2(o.b, nx1 + o.a1)
        th1s = (tmp1 - tmp2, tmp1 + tmp2 - math.pi)
        tmp3 = cz - o.c1
        s1_2 = nx1 * nx1 + tmp3 * tmp3
        tmp4 = nx1 + 2.0 * o.a1
        s2_2 = tmp4 * tmp4 + tmp3 * tmp3
        s_ = (np.sqrt(s1_2), np.sqrt(s2_2))
        s_2 = (s1_2, s2_2)
        base2 = (atan2(nx1, tmp3), -atan2(tmp4, tmp3))
        n = Ts.shape[0]
        Q = np.full((n, 8, 6), np.nan)
        valid = np.zeros((n, 8), dtype=bool)
        col = 0
        for b in range(2):
            with np.errstate(divide="ignore", invalid="ignore"):
                arg2 = (s_2[b] + self._c2_2 - self._kappa_2) / (2.0 * s_[b] * o.c2)
                arg3 = (s_2[b] - self._c2_2 - self._kappa_2) / (2.0 * o.c2 * self._k)
            exists = reach & (s_[b] >= 1e-12) & (np.abs(arg2) <= 1.0 + _ACOS_TOL) & (np.abs(arg3) <= 1.0 + _ACOS_TOL)
            a2c = acos(np.clip(np.where(exists, arg2, 0.0), -1.0, 1.0)).astype(float)
            a3c = acos(np.clip(np.where(exists, arg3, 0.0), -1.0, 1.0)).astype(float)
            for th1, th2, th3 in ((th1s[b], -a2c + base2[b], a3c - self._at23),
                                  (th1s[b], a2c + base2[b], -a3c - self._at23)):
                sn1, cs1 = np.sin(th1), np.cos(th1)
                s23, c23 = np.sin(th2 + th3), np.cos(th2 + th3)
                mm = r02 * s23 * cs1 + r12 * s23 * sn1 + r22 * c23
                th5 = atan2(np.sqrt(np.maximum(0.0, 1.0 - mm * mm)), mm)
                th4 = atan2(r12 * cs1 - r02 * sn1, r02 * c23 * cs1 + r12 * c23 * sn1 - r22 * s23)
                th6 = atan2(r01 * s23 * cs1 + r11 * s23 * sn1 + r21 * c23,
                                 -r00 * s23 * cs1 - r10 * s23 * sn1 - r20 * c23)
                sing = np.abs(np.degrees(th5)) < WRIST_SINGULAR_DEG
                ref_free = ref_free and not bool((sing & exists).any())
                total = th4 + th6
                th4 = np.where(sing, np.radians(self._sgn[3] * refs[:, 3]) - self._offs[3], th4)
                th6 = np.where(sing, total - th4, th6)
                for sol in ((th1, th2, th3, th4, th5, th6), (th1, th2, th3, th4 + math.pi, -th5, th6 - math.pi)):
                    for i, th in enumerate(sol):
                        Q[:, col, i] = -((-np.degrees((th + self._offs[i]) * self._sgn[i]) + 180.0) % 360.0) + 180.0
                    valid[:, col] = exists
                    col += 1
        Q[~valid] = np.nan
        return Q, valid, ref_free

    # ------------------------------------------------------------------ frame chain
    def tcp_pose(self, axes_deg: Sequence[float], tool: Any = None, base: Any = None,
                 robroot: Any = None) -> np.ndarray:
        """``$POS_ACT`` as a matrix: TCP in ``$BASE`` for ``$IPO_MODE=#BASE``.

        ``INV_POS($BASE) : $ROBROOT : FLANGE(q) : $TOOL`` (robot-model.md §7,
        reference §6.4). ``tool``, ``base``, ``robroot``: 4x4 arrays, 6-tuples
        (X, Y, Z, A, B, C) or None (= ``$NULLFRAME``). Returns 4x4, mm.
        """
        return inv_pos(as_matrix(base)) @ as_matrix(robroot) @ self.forward(axes_deg) @ as_matrix(tool)

    def flange_target(self, tcp_in_base: Any, tool: Any = None, base: Any = None,
                      robroot: Any = None) -> np.ndarray:
        """Flange frame in ``$ROBROOT`` that puts the TCP at ``tcp_in_base``
        (a Cartesian KRL target in ``$BASE``): the inverse of :meth:`tcp_pose`,
        ``INV_POS($ROBROOT) : $BASE : P : INV_POS($TOOL)`` (robot-model.md §7).
        Arguments as in :meth:`tcp_pose`; returns 4x4, mm."""
        return inv_pos(as_matrix(robroot)) @ as_matrix(base) @ as_matrix(tcp_in_base) @ inv_pos(as_matrix(tool))

    def pos_act(self, axes_deg: Sequence[float], tool: Any = None, base: Any = None,
                robroot: Any = None) -> tuple[float, float, float, float, float, float, int, int]:
        """``$POS_ACT`` as an E6POS-like tuple (X, Y, Z, A, B, C, S, T): TCP of
        :meth:`tcp_pose` in mm/deg (ABC as in :func:`~robot.frames.matrix_to_frame`)
        with the status and turn of the axes (robot-model.md §7-§8)."""
        from .frames import matrix_to_frame

        x, y, z, a, b, c = matrix_to_frame(self.tcp_pose(axes_deg, tool, base, robroot))
        s, t = self.status_turn(axes_deg)
        return (x, y, z, a, b, c, s, t)
