"""The robot as the simulated controller reads it back each IPO cycle: ``$AXIS_ACT``,
``$POS_ACT``, ``$VEL_ACT`` (reference §7.1; robot/controller.py's ``Controller.actual``).

:class:`ReadBack` holds the MuJoCo arm (robot/mjcf.py ``ArmModel``, compiled at its first use:
a debugger's launch does not wait for MuJoCo, issue 37; None without MuJoCo, then the read-back
is the forward kinematics of the setpoint), the frames of the motion the main run executes
(``tool_T``, ``base_T``, ``base_inv_T``: 4x4, mm; ``$TOOL_C``, ``$BASE_C``) and the TCP read back
this cycle and the cycle before (4x4 in ``$BASE``, made when first asked for where MuJoCo is not
used). Axis vectors are in the model's order (A1..An deg, then E1..En deg or mm); what callers
get is in KRL's order (robot/planner.py ``RobotModel.to_krl``).
"""

from __future__ import annotations

import struct
from typing import Any

import numpy as np

from .axismap import CART_KEYS
from .frames import frame_to_matrix, inv_pos, matrix_to_frame
from .robotmodel import RobotModel

_F8 = np.dtype(np.float64)
_PACK6 = struct.Struct(f"<{len(CART_KEYS)}d").pack
#: the ($TOOL, $BASE, ipo_mode) reads of one IPO cycle ReadBack.pos_act keeps (more: started again)
_POS_MEMO_MAX = 8


class ReadBack:
    """The robot read back (module docstring).

    Args:
        model: the robot model.
        q: the axes it stands at (model order).
        actuated: MuJoCo driven by position/velocity actuators instead of qpos replay.
        mujoco: False: no MuJoCo arm (the read-back is the setpoint's forward kinematics).
        cycles: robot/ipocycle.py, compiled or as Python (robot/kinematics/compiled.py ``pure_module``):
            its ``ArmCycle`` plays an arm of rotary axes back in one call per cycle.
        dt: the IPO cycle (s).
    """

    def __init__(self, model: RobotModel, q: np.ndarray, *, actuated: bool, mujoco: bool, cycles: Any,
                 dt: float) -> None:
        self.model = model
        self.dt = dt
        self.actuated = actuated
        self._cycles = cycles
        self._arm = None
        # the axes the arm is reset to when it is compiled (its first use); None: built, or no MuJoCo
        self._arm_q: np.ndarray | None = q.copy() if mujoco else None
        #: the arm's playback of one IPO cycle (robot/ipocycle.py ArmCycle), found at the first
        #: cycle; None: not yet looked for, False: none (actuated, external axes, no MuJoCo)
        self._cyc: Any = None
        self._q = q                      # the setpoint of the last cycle (without MuJoCo: the axes)
        self._q_prev = q                 # the setpoint of the cycle before
        self.tool_T = np.eye(4)
        self.base_T = np.eye(4)
        self.base_inv_T = np.eye(4)
        #: the last forward kinematics of tcp_of: (q, tool, INV_POS(base) as bytes), TCP
        self._tcp_last: tuple | None = None
        #: pos_act's reads of this IPO cycle: the axes' bytes they were made for, and
        #: (tool bytes, base bytes, ipo_mode) -> the E6POS dict (cleared by cycle and place)
        self._pos_q = b""
        self._pos_memo: dict = {}
        self.tcp = self.model.tcp(q, self.tool_T, self.base_inv_T)
        self.tcp_prev = self.tcp[:3, 3].copy()

    def arm(self):
        """The MuJoCo arm, compiled now (its first use) and reset to the axes it would have
        been reset to when built at once (the start axes, or :meth:`place`'s): the same state."""
        if self._arm_q is not None:
            # deferred: tools/startup_bench.py, krl run +93 ms at the top (2026-11-26)
            from .mjcf import ArmModel  # noqa: PLC0415

            arm = ArmModel(self.model.machine, actuated=self.actuated)
            arm.reset(self._arm_q)
            self._arm, self._arm_q = arm, None
        return self._arm

    def place(self, q: np.ndarray) -> None:
        """The robot stands at `q` (model order) before the first cycle."""
        self._q = self._q_prev = q.copy()
        self._pos_memo = {}
        if self._arm_q is not None:
            self._arm_q = q.copy()
        elif self._arm is not None:
            self._arm.reset(q)
        self.tcp = self.model.tcp(q, self.tool_T, self.base_inv_T)
        self.tcp_prev = self.tcp[:3, 3].copy()

    def set_frames(self, tool_T: np.ndarray, base_T: np.ndarray, base_inv_T: np.ndarray) -> None:
        """The ``$TOOL``/``$BASE`` (4x4) of the motion the main run executes from now on."""
        self.tool_T, self.base_T, self.base_inv_T = tool_T, base_T, base_inv_T

    # ------------------------------------------------------------------ the TCP, lazily
    @property
    def tcp(self) -> np.ndarray:
        """The TCP read back this cycle (4x4, in $BASE; :meth:`cycle` may leave it to be made
        here, when first asked for)."""
        T = self._tcp_m
        if T is None:
            T = self._tcp_m = self._made(self._tcp_src)
            self._tcp_src = None
        return T

    @tcp.setter
    def tcp(self, T: np.ndarray) -> None:
        self._tcp_m, self._tcp_src = T, None

    @property
    def tcp_prev(self) -> np.ndarray:
        """The TCP's position (mm) read back the cycle before (:attr:`tcp`'s)."""
        p = self._tcp_pp
        if p is None:
            src = self._tcp_psrc
            p = self._tcp_pp = (src if src.__class__ is np.ndarray else self._made(src))[:3, 3].copy()
            self._tcp_psrc = None
        return p

    @tcp_prev.setter
    def tcp_prev(self, p: np.ndarray) -> None:
        self._tcp_pp, self._tcp_psrc = p, None

    def _made(self, src: tuple) -> np.ndarray:
        """The TCP of a lazy source :meth:`cycle` left: ``(q, tool_T, base_inv_T)``, the forward
        kinematics of :meth:`tcp_of`; or ``(cycles, F, base_inv_T, tool_T)``, the flange `F` (4x4
        mm, WORLD) MuJoCo gave that cycle, as ``INV_POS($BASE) : F : $TOOL`` (robot/ipocycle.py
        ``ArmCycle.product``: numpy's own BLAS call compiled, else numpy's ``@``)."""
        if len(src) == 3:
            return self.tcp_of(*src)
        cyc, F, base_inv, tool = src
        T = np.empty((4, 4))
        try:
            done = cyc.product(base_inv, F, tool, T)
        except (TypeError, ValueError):      # a frame not C-contiguous float64: numpy's @
            done = False
        return T if done else base_inv @ F @ tool

    def tcp_of(self, q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """TCP in $BASE from the MuJoCo flange site (``INV_POS($BASE) : FLANGE_world : $TOOL``),
        or from the forward kinematics of ``q`` without MuJoCo."""
        arm = self._arm if self._arm_q is None else self.arm()
        if arm is not None:
            return base_inv_T @ arm.flange_pose_world() @ tool_T
        if q.dtype is _F8 and tool_T.dtype is _F8 and base_inv_T.dtype is _F8:
            # a robot at rest reads back the same pose every cycle: the model's forward
            # kinematics is a function of these three arrays alone, so equal bytes give it again
            key = (q.tobytes(), tool_T.tobytes(), base_inv_T.tobytes())
            last = self._tcp_last
            if last is not None and last[0] == key:
                return last[1].copy()
            T = self.model.tcp(q, tool_T, base_inv_T)
            self._tcp_last = (key, T.copy())
            return T
        return self.model.tcp(q, tool_T, base_inv_T)

    # ------------------------------------------------------------------ each IPO cycle
    def _playback(self, arm: Any) -> Any:
        """The arm's playback of one IPO cycle (:attr:`_cyc`), found once the arm is built
        (robot/mjcf.py ``ArmModel.ipo_cycle``; False: none)."""
        self._cyc = (arm.ipo_cycle(self._cycles) if arm is not None and not self.actuated else None) or False
        return self._cyc

    def keep_poses(self, rows: np.ndarray, at: int) -> bool:
        """From the next :meth:`cycle` on, keep the arm's ``qpos`` after each cycle, the `rows`'
        width of values from index `at` (MuJoCo's units), in the next row of `rows` (a
        C-contiguous float64 block, rows x width), in the compiled cycle itself
        (robot/ipocycle.py ``ArmCycle.keep_rows``): a cell's turn keeps each robot's pose of
        each cycle for its contact check without Python a cycle (interp/cellkeep.py; issue 89).
        False, keeping nothing, when the arm has no such playback (actuated, external axes, no
        MuJoCo). Raises ValueError for a slice beyond ``qpos``."""
        arm = self._arm if self._arm_q is None else self.arm()
        cyc = self._cyc if self._cyc is not None else self._playback(arm)
        if cyc is False:
            return False
        cyc.keep_rows(rows, at)
        return True

    def poses_kept(self) -> int:
        """The cycles since :meth:`keep_poses` (each kept in its row while the block had one);
        from now on nothing is kept."""
        cyc = self._cyc
        cyc.keep_rows(None, 0)
        return cyc.row

    def cycle(self, q: np.ndarray, q_prev: np.ndarray) -> np.ndarray:
        """The IPO cycle's setpoint `q` (the cycle before: `q_prev`) sent to the arm and read
        back: returns the axes read back (model order); the TCP follows (:attr:`tcp`)."""
        self._q, self._q_prev = q, q_prev
        if self._pos_memo:
            self._pos_memo = {}
        arm = self._arm if self._arm_q is None else self.arm()
        cyc = self._cyc
        if cyc is None:
            cyc = self._playback(arm)
        if cyc is not False:
            # set_axes, axis_act and the flange site in one call (robot/ipocycle.py: the same numbers);
            # the TCP, INV_POS($BASE) : FLANGE : $TOOL, and the last cycle's position made when
            # first asked for (a run without a trace reads neither at most cycles): the same numbers
            qa, F = np.empty(q.shape[0]), np.empty((4, 4))
            cyc.cycle(q, qa, F)
            T = self._tcp_m
            self._tcp_pp, self._tcp_psrc = None, (T if T is not None else self._tcp_src)
            self._tcp_m, self._tcp_src = None, (cyc, F, self.base_inv_T, self.tool_T)
            return qa
        if arm is not None:
            if self.actuated:
                arm.step_actuated(q, self.dt, (q - q_prev) / self.dt)
            else:
                arm.set_axes(q)
            qa = arm.axes_deg()
            self.tcp_prev = self.tcp[:3, 3].copy()
            self.tcp = self.tcp_of(qa, self.tool_T, self.base_inv_T)
            return qa
        # without MuJoCo the read-back is the forward kinematics of these arrays alone:
        # made when first asked for ($POS_ACT, $VEL_ACT, the trace's pose), the same numbers
        qa = q.copy()
        T = self._tcp_m
        self._tcp_pp, self._tcp_psrc = None, (T if T is not None else self._tcp_src)
        self._tcp_m, self._tcp_src = None, (qa, self.tool_T, self.base_inv_T)
        return qa

    # ------------------------------------------------------------------ what the program reads
    def axes(self) -> np.ndarray:
        """The axes read back (A1..An, E1..En: the model's order)."""
        arm = self._arm if self._arm_q is None else self.arm()
        if arm is not None:
            return arm.axes_deg()
        return self._q.copy()

    def axis_act(self) -> np.ndarray:
        """``$AXIS_ACT`` in KRL's order (robot/axismap.py ``to_krl``): A1..A6 (deg) read back from
        the MuJoCo model (0 for the axes of a robot with fewer than six, a SCARA's A5 and A6); then
        E1.. (mm, deg) on a robot with external axes or a seven-axis arm's redundancy."""
        return self.model.to_krl(self.axes())

    def axis_setpoint(self) -> np.ndarray:
        """The IPO setpoint of the last cycle in KRL's order (as :meth:`axis_act`)."""
        return self.model.to_krl(self._q.copy())

    def axis_vel_act(self) -> np.ndarray:
        """The axes' velocities over the last IPO cycle in KRL's order (A1..A6 deg/s, then
        E1..En deg/s or mm/s): the source of ``$VEL_AXIS_ACT`` (interp/runtime/sysvars.py)."""
        return self.model.to_krl((self._q - self._q_prev) / self.dt)

    def pos_act(self, tool: Any = None, base: Any = None, ipo_mode: str = "BASE") -> dict[str, float]:
        """``$POS_ACT`` as an E6POS dict {X, Y, Z, A, B, C, S, T} (mm, deg): the TCP of
        :meth:`axis_act` in ``base`` for ``tool`` (6-tuples or 4x4; default: the $BASE/$TOOL
        of the motion the main run executes, ``$BASE_C``/``$TOOL_C``). ``ipo_mode`` "TCP"
        (external TCP, reference §6.4): ``tool`` is the workpiece on the flange, ``base`` the
        fixed tool in WORLD, and the pose is the fixed tool in the workpiece frame,
        ``INV_POS($ROBROOT : FLANGE(q) : $TOOL) : $BASE`` (robot/external_tcp.py).

        Computed once per IPO cycle for each ($TOOL, $BASE, ``ipo_mode``) read (issue 86: a
        submit interpreter's passes read it about 9 times per cycle): the pose is a function of
        the axes read back and the two frames' bytes alone, kept until the next :meth:`cycle`
        or :meth:`place` (or other axes), so a read gives the same values bit for bit; each
        caller gets its own dict."""
        q = self.axes()
        qk = q.tobytes()
        memo = self._pos_memo
        if qk != self._pos_q or len(memo) >= _POS_MEMO_MAX:
            memo = self._pos_memo = {}
            self._pos_q = qk
        key = (self.tool_T.tobytes() if tool is None else _frame_key(tool),
               self.base_inv_T.tobytes() if base is None else _frame_key(base), ipo_mode)
        out = memo.get(key)
        if out is None:
            out = memo[key] = self._pos_of(q, tool, base, ipo_mode)
        return dict(out)

    def _pos_of(self, q: np.ndarray, tool: Any, base: Any, ipo_mode: str) -> dict[str, float]:
        """:meth:`pos_act` of the axes `q`, computed (no memo)."""
        tool_T = self.tool_T if tool is None else _as4(tool)
        base_inv = self.base_inv_T if base is None else inv_pos(_as4(base))
        T = self.tcp_of(q, tool_T, base_inv)
        if ipo_mode == "TCP":
            T = inv_pos(T)
        x, y, z, a, b, c = matrix_to_frame(T)
        s, t = self.model.status_turn(q)
        out = {"X": x, "Y": y, "Z": z, "A": a, "B": b, "C": c, "S": s, "T": t}
        out.update(self.model.axes.e_components(q))
        return out

    def vel_act(self) -> float:
        """``$VEL_ACT``: TCP speed in m/s over the last IPO cycle."""
        return float(np.linalg.norm(self.tcp[:3, 3] - self.tcp_prev)) / self.dt / 1000.0

    def tcp_frame(self) -> tuple:
        """The TCP (X, Y, Z mm, A, B, C deg) in $BASE read back this cycle (``$POS_ACT``'s frame)."""
        return matrix_to_frame(self.tcp)


def _frame_key(F: Any) -> bytes:
    """The bytes a frame given to :meth:`ReadBack.pos_act` is kept under: a 6-tuple's float64s
    (48 bytes; -0.0 apart from 0.0), else its array's (a 4x4: 128 bytes)."""
    if F.__class__ is tuple and len(F) == len(CART_KEYS):
        try:
            return _PACK6(*F)
        except struct.error:
            pass
    return np.asarray(F, dtype=float).tobytes()


def _as4(F: Any) -> np.ndarray:
    arr = np.asarray(F, dtype=float)
    if arr.shape == (4, 4):
        return arr
    return frame_to_matrix(*arr)


__all__ = ["ReadBack"]
