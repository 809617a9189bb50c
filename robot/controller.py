"""The simulated KR C4 main run: motion queue, 12 ms IPO cycle, triggers, BRAKE, I/O
(reference §5.8, §5.12-§5.18, §6, §7; issue 5).

The interpreters are the advance run; they drive a :class:`Controller` through a small
protocol (docs/architecture.md, "Robot interface")::

    ctl = Controller(trace=TraceWriter("run.jsonl"))
    while not ctl.can_enqueue():          # $ADVANCE: a full queue blocks the advance run
        handle(ctl.step())
    ctl.enqueue(MotionRequest("LIN", {"X": 500}, params, approx="C_DIS", triggers=...))
    while not ctl.is_idle():              # an advance-run stop (WAIT, $OUT write, ...)
        handle(ctl.step())

:meth:`Controller.step` runs one IPO cycle (12 ms of simulated time) and returns the events
of that cycle (:class:`MotionEvent`, :class:`TriggerEvent`, :class:`IoEvent`,
:class:`MessageEvent`, :class:`ErrorEvent`). Interrupt conditions are the interpreter's:
it evaluates them after every step.

Time: the clock is the integer IPO cycle count ``k``; ``time = k · 0.012`` s. Motion timing
uses a *path time* that equals the clock except while BRAKE ramps the path speed down, the
robot is held, and :meth:`Controller.release` ramps it back up within the axis accelerations
(the robot stays on its path, because every setpoint is a function of path time).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import blending
from .exactstop import DONE_CYCLES, END_DELAY_CYCLES
from .errors import RobotError
from .frames import frame_to_matrix, inv_pos, matrix_to_frame
from .io import IOImage
from .limits import normalise_mode
from .machine import MachineData, load_machine
from .motion import CondStop, MotionRequest, Trigger
from .planner import CP_SPEED_LIMIT_FACTOR, RobotModel, Segment, TriggerPlan, plan, resolved_target
from .cellrules import Rule, rules_may_fire, step_rules
from .kinematics import compiled_module
from .stimuli import Cell, Stimulus
from .trace import TraceWriter


def _compiled_module() -> Any:
    """The compiled module robot/simcore.pyx when it is built, current and switched on
    (robot/kinematics ``compiled_module``: ``USE_COMPILED``), else None."""
    return compiled_module()

EPS = 1e-9
_F8 = np.dtype(np.float64)
MSG_APPROX_IMPOSSIBLE = "approximation not possible"


# ----------------------------------------------------------------------------- events
@dataclass(frozen=True)
class MotionEvent:
    """A motion reached a phase: ``start``, ``blend_start``, ``blend_end`` or ``end``."""

    t: float
    id: int
    phase: str
    request: MotionRequest = field(repr=False, compare=False)
    kind: str = "motion"


@dataclass(frozen=True)
class TriggerEvent:
    """A TRIGGER's switching point was reached: the interpreter runs ``trigger.action``
    now, as a short interrupt-like context (no motion statements)."""

    t: float
    id: int
    index: int
    trigger: Trigger
    kind: str = "trigger"


@dataclass(frozen=True)
class IoEvent:
    """A signal changed (``source``: program, trigger, pulse, stimulus)."""

    t: float
    signal: str
    value: Any
    source: str
    kind: str = "io"


@dataclass(frozen=True)
class MessageEvent:
    """A controller message (e.g. "approximation not possible")."""

    t: float
    text: str
    id: int | None = None
    kind: str = "message"


@dataclass(frozen=True)
class ErrorEvent:
    """A motion error in the main run (workspace error, software limit switch, ...): the
    robot stopped, the motion queue was discarded. The interpreter raises ``error``."""

    t: float
    error: RobotError
    id: int | None = None
    kind: str = "error"


Event = MotionEvent | TriggerEvent | IoEvent | MessageEvent | ErrorEvent


# ----------------------------------------------------------------------------- main run
@dataclass
class _Run:
    """A segment being executed by the main run."""

    seg: Segment
    t0: float                     # path time of local time 0
    blend_in_end: float | None = None   # path time where the blend into it ended/ends
    blend_mid: float | None = None      # path time of the middle of its outgoing blend
    planned_mid: float | None = None    # expected blend middle (for DISTANCE=1 early)
    decided: bool = False               # approximation decided (blend or exact stop)
    fired: set[int] = field(default_factory=set)
    tau_cache: tuple[int | None, float | None] | None = None
    stops: dict[int, str] = field(default_factory=dict)   # conditional stop index -> braking / stopped

    def shift(self, d: float) -> None:
        self.t0 += d
        for name in ("blend_in_end", "blend_mid", "planned_mid"):
            v = getattr(self, name)
            if v is not None:
                setattr(self, name, v + d)

    def trigger_time(self, tp: TriggerPlan) -> float:
        """Path time at which trigger ``tp`` switches (reference §5.18; see docs)."""
        seg = self.seg
        if tp.u_ref is not None:
            ref = self.t0 + seg.profile.t_of_u(tp.u_ref)
        elif tp.kind == "start":
            ref = self.blend_in_end if self.blend_in_end is not None else self.t0
        else:  # end
            if self.blend_mid is not None:
                ref = self.blend_mid
            elif self.planned_mid is not None and not self.decided:
                ref = self.planned_mid
            else:
                ref = self.t0 + seg.T
        return max(self.t0, ref + tp.trigger.delay_ms / 1000.0)

    @property
    def pending_triggers(self) -> bool:
        return len(self.fired) < len(self.seg.triggers)


@dataclass
class _Blend:
    prev: _Run
    nxt: _Run
    pa: float
    pb: float
    space: str
    keyword: str


@dataclass
class _Held:
    """Main-run state suspended by BRAKE (restored by :meth:`Controller.release`)."""

    runs: list[_Run]
    blend: _Blend | None
    pending: deque
    tracked: list[_Run]
    pt: float
    q: np.ndarray
    tool_T: np.ndarray
    base_T: np.ndarray
    plan_q: np.ndarray            # end point of the last motion planned before the hold


@dataclass
class _Ending:
    """An exact-stop motion whose interpolation has ended at ``reached`` (s): the main run keeps
    the robot at its end point, signals the motion's END at cycle ``k_end`` and is done with it
    at cycle ``k_done`` (robot/exactstop.py)."""

    seg: Segment
    reached: float
    k_end: int
    k_done: int
    signalled: bool = False


class Controller:
    """The simulated controller (main run). See the module docstring for the protocol.

    Args:
        machine: machine data (default :func:`robot.machine.load_machine`).
        trace: a :class:`~robot.trace.TraceWriter` or None.
        stimuli: list of :class:`~robot.stimuli.Stimulus`, a cell file's
            :class:`~robot.stimuli.Cell` (its stimuli, rules and presets; read by
            :func:`robot.stimuli.load_cell`, the one loader), or None.
        rules: reactive rules of the cell (:class:`~robot.cellrules.Rule`), added to those of a
            `stimuli` Cell.
        start_axes: initial axes A1..A6 (deg), default HOME.
        actuated: drive MuJoCo with position/velocity actuators instead of qpos replay.
        strict_bco: the first motion needs a complete PTP/LIN target (reference §6.3).
        mujoco: False to skip MuJoCo entirely (axis_act then returns the setpoint).
        mode_op: operating mode ``T1``, ``T2``, ``AUT`` or ``EX`` (``EXT``); default AUT
            (reference §7.5; T1 limits TCP and flange to 250 mm/s, PTP to ``$RED_T1``).

    Attributes:
        advance: ``$ADVANCE`` (0..5), set by the interpreter; default 3.
        io: the :class:`~robot.io.IOImage`.
        dt: IPO cycle in s (0.012).
        last_error: the last :class:`RobotError` of the main run, or None.
        batch: class switch (default True): a CP segment at full path speed solves its
            coming IPO cycles at once (robot/planner.py ``CartSegment.axes_run``; the same
            setpoints bit for bit). False: every cycle alone (the reference path of
            ``python -m robot.tracecheck --per-cycle``).
    """

    batch: bool = True

    def __init__(self, machine: MachineData | None = None, *, trace: TraceWriter | None = None,
                 stimuli: list[Stimulus] | Cell | None = None, rules: list[Rule] | None = None,
                 start_axes: Any = None, actuated: bool = False, strict_bco: bool = True,
                 mujoco: bool = True, mode_op: str | None = None, io: IOImage | None = None,
                 network: Any = None, cell: dict | None = None, geometry: Any = None,
                 workspaces: Any = None) -> None:
        """A complete controller (interp/runtime/core.py ``Runtime`` builds its run's with
        everything it needs; nothing sets its attributes afterwards): the robot `machine`
        (default the KR 6 R900), the `trace` it writes, the cell's `stimuli` (or a whole Cell:
        its stimuli, rules and autoext preset) and `rules`, the `start_axes` (KRL's order; None:
        $AXIS_HOME[1]), the operating mode `mode_op`, the I/O image `io` (default a new one),
        the network hub `network` (net/hub.py Network: attached here, with the `cell` facts its
        partners ask for, ``plc_map``), the cell's `geometry` (robot/collision.py CellGeometry:
        collisions checked at every IPO cycle; a whole Cell's own by default) and the
        `workspaces` monitor (robot/workspace.py; None: none yet). Raises SoftLimitError for
        start axes outside the software limits, OSError when a network partner cannot start."""
        self.machine = machine if machine is not None else load_machine()
        self.rules: list[Rule] = []
        self._rules_seen = None         # what the rules' conditions last saw (cellrules.step_rules)
        if isinstance(stimuli, (str, Path)):
            raise TypeError("a cell file is read by robot.stimuli.load_cell; pass its Cell")
        if isinstance(stimuli, Cell):
            if stimuli.autoext and mode_op is None:
                mode_op = "EX"            # Automatic External (robot/cellpresets.py)
            if geometry is None:
                geometry = stimuli.geometry
            stimuli, self.rules = stimuli.stimuli, list(stimuli.rules)
        for st in stimuli or ():
            if st.reached_default:        # `reached: true`: this robot's $IN_POS_CAR
                st.reached_mm = self.machine.in_pos_car_mm
        self.mode_op = normalise_mode(mode_op)
        self.model = RobotModel(self.machine, mode=self.mode_op)
        self.dt = float(self.machine.ipo_cycle_s)
        self._dt_ms = int(round(self.dt * 1000))
        self.trace = trace
        self.advance = self.machine.def_advance
        self.strict_bco = strict_bco
        self._bco_done = False
        self.io = io if io is not None else IOImage()
        self.io.on_change = self._on_io
        self.rules += list(rules or [])
        self.stimuli: list[Stimulus] = list(stimuli or [])
        #: the robot's axis count: axis vectors are A1..An, then E1..En (robot/planner.py)
        self.n = self.model.n
        if start_axes is None:
            q = np.array(self.machine.home_all, dtype=float)
        else:
            # KRL's order (A1..A6, E1..E6); E from $AXIS_HOME[1] unless given
            q = self.model.from_krl(start_axes)
        self.model.check_limits(q)
        self._arm = None
        self.actuated = actuated
        # the MuJoCo arm (robot/mjcf.py ArmModel) is compiled at its first use (_arm_model), reset
        # to the axes it stands at then: a debugger's launch and first stop do not wait for
        # MuJoCo's import and compile (issue 37); None: built, or no MuJoCo
        self._arm_q: np.ndarray | None = q.copy() if mujoco else None
        self._k = 0
        #: simulated time in s (IPO cycles · the IPO cycle): ``_k * dt``, kept with ``_k`` (the
        #: interpreters read it before every statement)
        self.time = self._k * self.dt
        self._pt = 0.0
        self._pt_step = self.dt       # the path time the last cycle advanced (s)
        self._scale = 1.0
        self._scale_rate = 0.0
        self._braking = False
        self._brake_T = 0.0
        self._stop_T = 0.0               # a conditional stop's braking ramp (s), for the ramp up
        self._ramp_up = False      # release(): the path speed ramps up within a_max
        self._held: _Held | None = None
        self._moved_while_held = False
        self._q = q.copy()
        self._q_prev = q.copy()
        self._plan_q = q.copy()        # end point of the last planned motion
        self._pending: deque[Segment] = deque()
        self._runs: list[_Run] = []
        self._ending: _Ending | None = None   # an exact stop between its end point and done
        self._blend: _Blend | None = None
        self._tracked: list[_Run] = []  # runs with unfired triggers
        self._next_id = 1
        self._events: list[Event] = []
        self._pulses: list[tuple[float, int, bool]] = []
        self._cyclic: dict[int, Callable[["Controller"], None]] = {}
        self._message_watchers: list[Callable] = []
        self._cyclic_next = 1
        self._tool_T = np.eye(4)
        self._base_T = np.eye(4)
        self._base_inv_T = np.eye(4)
        self._tcp_T = self.model.tcp(self._q, self._tool_T, self._base_inv_T)
        self._tcp_prev = self._tcp_T[:3, 3].copy()
        #: the last forward kinematics of _tcp_read_back: (q, tool, INV_POS(base) as bytes), TCP
        self._tcp_last: tuple | None = None
        self.last_error: RobotError | None = None
        self._step_lim: list[float] | None = None   # largest axis step per cycle (_check_speed)
        self._step_lim_a: np.ndarray | None = None  # the same as an array (the compiled check)
        #: robot/simcore.pyx (None: the Python code alone) and its per-cycle step check
        self._simcore = _compiled_module()
        self._speed_ok = getattr(self._simcore, "speed_ok", None)
        self._ret_q: np.ndarray | None = None
        self._ended = False
        # a sensor correction superposed on the setpoint (RSI, net/rsi.py): an object with
        # `axes` (A1..A6 deg) and `cart` (X, Y, Z mm, A, B, C deg in $BASE, or in `frame`:
        # "TOOL", "WORLD" when it has one); None: none
        self.correction = None
        self._q_raw = self._q.copy()
        #: KUKA's workspace monitoring (robot/workspace.py ``WorkspaceMonitor``), None while no
        #: workspace can be active (interp/runtime/sysvars.py makes it: :meth:`watch_workspaces`)
        self.workspaces = workspaces
        #: the robot against its cell (robot/collision.py), None without a cell file's geometry
        self.collision = None
        if geometry is not None:
            # deferred: tools/startup_bench.py, krl run +4 ms at the top (2026-11-26)
            from .collision import CollisionChecker  # noqa: PLC0415

            self.collision = CollisionChecker(self.machine, geometry)
        self.network = network  # net.hub.Network: the partners, polled at each cycle's start
        if network is not None:
            network.attach(self, **(cell or {}))

    def select_mode(self, mode: str) -> None:
        """The operating mode `mode` (T1, T2, AUT, EX; robot/limits.py) selected between two runs
        of the program (the pendant): the controller's and its robot model's."""
        self.mode_op = self.model.mode = normalise_mode(mode)

    def watch_workspaces(self, monitor) -> None:
        """KUKA's workspace monitoring from now on (robot/workspace.py ``WorkspaceMonitor``): a
        program that names ``$WORKSPACE``/``$AXWORKSPACE`` while it runs (interp/runtime/sysvars.py)."""
        self.workspaces = monitor

    def _arm_model(self):
        """The MuJoCo arm, compiled now (its first use) and reset to the axes it would have
        been reset to when built at once (the start axes, or :meth:`place`'s): the same state."""
        if self._arm_q is not None:
            # deferred: tools/startup_bench.py, krl run +93 ms at the top (2026-11-26)
            from .mjcf import ArmModel  # noqa: PLC0415

            arm = ArmModel(self.machine, actuated=self.actuated)
            arm.reset(self._arm_q)
            self._arm, self._arm_q = arm, None
        return self._arm

    # ================================================================= clock
    @property
    def cycle(self) -> int:
        """Number of IPO cycles run so far."""
        return self._k

    def cycles_for(self, seconds: float) -> int:
        """IPO cycles a ``WAIT SEC seconds`` takes: rounded up, 0 for ``WAIT SEC 0``
        (reference §5.8: WAIT SEC 0.012 waits one cycle)."""
        if seconds <= 0:
            return 0
        return int(math.ceil(seconds / self.dt - 1e-9))

    # ================================================================= advance-run side
    def can_enqueue(self) -> bool:
        """True if the advance run may plan another motion now: fewer than ``$ADVANCE``
        motions wait in the queue (with ``$ADVANCE = 0``: only when the robot is idle)."""
        if self.advance <= 0:
            return self.is_idle()
        return len(self._pending) < self.advance

    def enqueue(self, req: MotionRequest) -> int:
        """Plan ``req`` from the end point of the previously planned motion and queue it.

        Returns the motion id (1, 2, ... in enqueue order). Raises
        :class:`~robot.errors.RobotError` (WorkspaceError, SoftLimitError, BCO errors) when
        the motion cannot be planned; nothing is queued then. It does not wait for queue
        space: check :meth:`can_enqueue` first.
        """
        req.id = self._next_id
        seg = plan(req, self._plan_q, self.model, first=self.strict_bco and not self._bco_done)
        self._next_id += 1
        self._bco_done = True
        self._pending.append(seg)
        self._plan_q = seg.q1.copy()
        if self._held is not None:
            self._moved_while_held = True
        return req.id

    def target_outside_limits(self, req: MotionRequest) -> bool:
        """True when the target of `req` is itself out of this robot's reach: an absolute
        Cartesian target with X, Y, Z, A, B, C in ``$BASE``/``$TOOL`` (``$IPO_MODE #BASE``) for
        which no axis configuration — any of the analytic solutions, any status and turn,
        each axis with its ±360° variants — lies within ``$SOFTN_END``/``$SOFTP_END``. Then no
        path and no S/T of the program reaches it: the robot of this machine data cannot take
        that pose. False for any other request (an axis target, a relative or partial one,
        ``#TCP``), or when some configuration is within the limits."""
        p = req.params
        keys = ("X", "Y", "Z", "A", "B", "C")
        if req.relative or req.is_axis_target or p.ipo_mode != "BASE" or \
                not all(k in req.target for k in keys):
            return False
        flange = (inv_pos(self.model.robroot_T) @ frame_to_matrix(*p.base)
                  @ frame_to_matrix(*(float(req.target[k]) for k in keys)) @ inv_pos(frame_to_matrix(*p.tool)))
        limits = [j.limit_deg for j in self.machine.joints]
        for q in self.model.kin.solutions(flange):
            if all(any(lo <= v + k <= hi for k in (-720.0, -360.0, 0.0, 360.0, 720.0))
                   for v, (lo, hi) in zip(q, limits)):
                return False
        return True

    def last_planned(self):
        """The Segment (robot.planner) that :meth:`enqueue` planned last (for the motion
        history of backward motion, interp/runtime/runmode.py)."""
        return self._pending[-1]

    def is_idle(self) -> bool:
        """True when the main run has caught up: no motion executing, ending (an exact stop
        until it is done, robot/exactstop.py) or queued, no pending trigger, not braking (the
        condition an advance-run stop waits for). After BRAKE the suspended motion does not
        count (interrupt level)."""
        return self._ending is None and self._main_idle()

    def _main_idle(self) -> bool:
        """:meth:`is_idle` but for an exact stop that is ending."""
        return (not self._runs and self._blend is None and not self._pending
                and not self._tracked and not self._braking)

    def is_suspended(self) -> bool:
        """True while motions are suspended by a finished BRAKE (until :meth:`release` or
        :meth:`cancel_pending`)."""
        return self._held is not None

    def io_may_change(self) -> bool:
        """True if an input or output can still change without the program doing anything:
        a stimulus not yet applied, a PULSE not yet reset, a cyclic hook, a running timer, a
        cell rule with an answer pending or about to fire (for deadlock detection of WAIT FOR)."""
        return (any(not st.fired for st in self.stimuli) or bool(self._pulses)
                or bool(self._cyclic) or not all(self.io.timer_stop[1:])
                or (bool(self.rules) and rules_may_fire(self.rules, self.io))
                or (self.network is not None and self.network.may_change()))

    def is_moving(self) -> bool:
        """True while a motion is being executed."""
        return bool(self._runs) or self._blend is not None

    def place(self, axes: Any) -> None:
        """Set the scene (``krl run --start``, a cell file's ``start:``): the robot stands at
        `axes` (KRL's order: A1..A6, E1..E6, deg; robot/planner.py ``RobotModel.from_krl``) before
        the first cycle. Raises
        :class:`~robot.errors.SoftLimitError` for axes outside the software limits, ValueError
        once the run has started."""
        if self._k or self._runs or self._pending or self._next_id > 1:
            raise ValueError("the robot can only be placed before the run starts")
        q = self.model.from_krl(axes)
        self.model.check_limits(q)
        self._q = q.copy()
        self._q_prev = q.copy()
        self._plan_q = q.copy()
        if self._arm_q is not None:
            self._arm_q = q.copy()
        elif self._arm is not None:
            self._arm.reset(q)
        self._tcp_T = self.model.tcp(self._q, self._tool_T, self._base_inv_T)
        self._tcp_prev = self._tcp_T[:3, 3].copy()

    # ================================================================= idle fast-forward
    def at_rest(self) -> bool:
        """True when nothing the main run has will move the robot or change by itself: no
        motion suspended, braking or blending, every motion executing or queued leads from
        its start to the same axes without a TRIGGER (``PTP XHOME`` at XHOME, again and
        again), no cell rule about to rise (the condition of :meth:`skip`;
        interp/runtime/idle.py)."""
        if (self._braking or self._held is not None or self._blend is not None or self._tracked
                or self._ending is not None):
            return False
        for seg in [r.seg for r in self._runs] + list(self._pending):
            if seg.triggers or not np.array_equal(seg.q0, seg.q1) or not np.array_equal(seg.q0, self._q):
                return False
        return not (self.rules and any(not r.last and r.holds(self.io) for r in self.rules))

    def next_event_cycle(self) -> int | None:
        """The first IPO cycle at which the controller changes something by itself while the
        program does nothing: a timed stimulus, a stimulus delay that runs, a cell rule's
        pending answer, a PULSE's reset, the network's next message (net.hub.Network: any
        cycle while a partner is attached, the next recorded one of a replay). None when
        there is none. (A cycle ``k`` is the one whose :meth:`step` makes ``time = k · dt``.)"""
        times = [st.at if st.at is not None else st.due for st in self.stimuli
                 if not st.fired and (st.at is not None or st.due is not None)]
        times += [r.due[0] for r in self.rules if r.due]
        times += [te for te, _, _ in self._pulses]
        net = self.network.next_event_cycle(self._k) if self.network is not None else None
        if not times:
            return net
        k = max(self._k + 1, int(math.ceil(min(times) / self.dt - EPS)))
        return k if net is None else min(k, net)

    def skip(self, cycles: int) -> None:
        """Fast-forward `cycles` IPO cycles in which nothing happens (interp/runtime/idle.py
        decides that; issue 34 "Idle time costs nothing"): the clock, the path time and every
        running ``$TIMER`` advance exactly as :meth:`step` would advance them, no event,
        pose or cyclic hook runs (the robot stands: the pose is the one of the last cycle; a
        motion that does not move it, executing or queued, goes on after the jump).
        Raises ValueError when the main run is not :meth:`at_rest` or a skipped cycle would
        reach :meth:`next_event_cycle`."""
        if cycles <= 0:
            return
        nxt = self.next_event_cycle()
        if not self.at_rest() or (nxt is not None and self._k + cycles >= nxt):
            raise ValueError("the controller cannot skip these cycles: something happens in them")
        self._k += cycles
        self.time = self._k * self.dt
        self._pt += cycles * self.dt
        tm, st = self.io.timer_ms, self.io.timer_stop
        for i in range(1, len(tm)):
            if not st[i]:
                tm[i] += cycles * self._dt_ms
        self.io.now = self.time

    def queue_length(self) -> int:
        """Motions planned but not yet started by the main run."""
        return len(self._pending)

    def step_until(self, predicate: Callable[[], bool], max_cycles: int = 10_000_000) -> list[Event]:
        """Step until ``predicate()`` is true (checked before each cycle); returns all
        events. Interpreters that evaluate interrupts should call :meth:`step` themselves."""
        out: list[Event] = []
        n = 0
        while not predicate() and n < max_cycles:
            out.extend(self.step())
            n += 1
        return out

    def wait_idle(self) -> list[Event]:
        """Step until :meth:`is_idle`."""
        return self.step_until(self.is_idle)

    def wait_sec(self, seconds: float) -> list[Event]:
        """Step for ``WAIT SEC seconds`` (see :meth:`cycles_for`)."""
        out: list[Event] = []
        for _ in range(self.cycles_for(seconds)):
            out.extend(self.step())
        return out

    # ================================================================= BRAKE / RESUME
    def brake(self, fast: bool = False) -> None:
        """Start ``BRAKE`` (``fast=False``) or ``BRAKE F`` (``fast=True``): the path speed
        ramps down linearly to zero, the robot stays on its path (reference §5.17).

        Ramp time ``T = max_i |q̇_i| / (f · a_max_i)`` with f = 0.5 (BRAKE) or 1.0 (BRAKE F)
        of the machine acceleration. The interpreter steps until :meth:`is_braking` is False.
        """
        if self._braking:
            return
        if not self.is_moving():
            if self._pending:  # at rest between motions: hold the queued ones
                self._hold()
            return
        qd = np.abs(self._q - self._q_prev) / self.dt
        f = 1.0 if fast else 0.5
        T = max(self.dt, float(np.max(qd / (f * self.model.a_max))))
        self._brake_T = T
        self._scale_rate = -self._scale / T
        self._ramp_up = False
        self._braking = True

    def _ramp_scale(self, s_old: float, s_lin: float) -> float:
        """The path-time step (in IPO cycles) of this cycle while :meth:`release` ramps the
        path speed back up: the linear ramp's `s_lin` where the setpoint it gives keeps every
        axis within its machine acceleration, else the largest step in ``[s_old, s_lin]`` that
        does (found by bisection). A scaled path time ``pt(t)`` gives the axes
        ``q'·ṡ + q''·s²``: the linear ramp alone adds ``q'·ṡ`` to the profile's own
        acceleration ``q''`` (up to twice ``a_max`` when the motion was braked while it
        accelerated); the bisection keeps their sum within ``a_max`` (second differences of
        the setpoints, as robot/limits.py measures them). ``s_old`` itself adds only
        ``q''·s²``."""
        if s_lin <= s_old or self.correction is not None:
            return s_lin
        dt = self.dt
        q, qp = self._q, self._q_prev
        a_lim = self.model.a_max * (dt * dt)
        segs = [r.seg for r in self._runs]
        if self._blend is not None:
            segs.append(self._blend.prev.seg)
        saved = [(sg, sg._last_q) for sg in segs if hasattr(sg, "_last_q")]

        def ok(s_new: float) -> bool | None:
            qn = self._peek(self._pt + dt * s_new)
            for sg, lq in saved:          # a peek must not move the IK references
                sg._last_q = lq
            if qn is None or len(qn) != len(q):
                return None
            return bool(np.all(np.abs(qn - 2.0 * q + qp) <= a_lim))

        first = ok(s_lin)
        if first is None or first:
            return s_lin
        lo, hi = s_old, s_lin
        for _ in range(12):
            mid = 0.5 * (lo + hi)
            if ok(mid):
                lo = mid
            else:
                hi = mid
        if lo >= 1.0 - 1e-6:
            return 1.0
        return max(lo, min(s_lin, s_old + 1e-6))

    def _peek(self, pt: float) -> np.ndarray | None:
        """The setpoint the main run would give at path time `pt` (for :meth:`_ramp_scale`),
        without its events; None when that would start, blend into or end a motion."""
        try:
            b = self._blend
            if b is not None:
                if pt < b.pb - EPS:
                    return self._blend_setpoint(b, pt)
                return None
            if not self._runs:
                return None
            r = self._runs[0]
            tau = pt - r.t0
            if tau >= r.seg.T - EPS:
                return None
            if r.seg.req.approx is not None and not r.decided and r.tau_cache is not None \
                    and r.tau_cache[1] is not None and tau >= r.tau_cache[1] - EPS:
                return None
            return np.asarray(r.seg.axes(tau), dtype=float)
        except RobotError:
            return None

    def is_braking(self) -> bool:
        """True while a BRAKE ramp is running."""
        return self._braking

    def release(self) -> None:
        """Return from an interrupt routine without RESUME: the motion suspended by BRAKE
        continues from where the robot stands along its path (the path speed ramps up within
        the axis accelerations, :meth:`_ramp_scale`), and the advance run plans on from the end
        point of the last motion planned before the BRAKE. If the routine moved the robot,
        the suspended motions are re-planned from the current position (the braked motion
        as a PTP/LIN to its end point)."""
        h = self._held
        if h is None:
            return
        self._held = None
        if not self._moved_while_held and self._main_idle():
            d = self._pt - h.pt
            objs = list(h.runs) + list(h.tracked)
            if h.blend is not None:
                objs += [h.blend.prev, h.blend.nxt]
                h.blend.pa += d
                h.blend.pb += d
            seen: set[int] = set()
            for r in objs:
                if id(r) not in seen:
                    seen.add(id(r))
                    r.shift(d)
            self._runs, self._blend, self._pending = h.runs, h.blend, h.pending
            self._tracked = list(dict.fromkeys(h.tracked))
            self._tool_T, self._base_T = h.tool_T, h.base_T
            self._base_inv_T = inv_pos(h.base_T)
            self._scale = 0.0
            self._scale_rate = 1.0 / max(self._brake_T, self.dt)
            self._ramp_up = True
            # the interrupt level planned from the standstill point; the advance run plans on
            # from where the suspended chain ends (else the next motion would start at the
            # standstill point while the robot stands at the braked motion's end point)
            self._plan_q = h.plan_q
            return
        # re-plan from where the planning chain ends now
        segs = []
        cur = h.blend.nxt if h.blend is not None else (h.runs[-1] if h.runs else None)
        if cur is not None:
            req = resolved_target(cur.seg)
            left = tuple(tp.trigger for tp in cur.seg.triggers if tp.index not in cur.fired)
            req.triggers = left
            req.segments = ()
            segs.append(req)
        segs.extend(s.req for s in h.pending)
        for req in segs:
            seg = plan(req, self._plan_q, self.model)
            self._pending.append(seg)
            self._plan_q = seg.q1.copy()
        self._moved_while_held = False

    def cancel_pending(self) -> None:
        """``RESUME``: discard the motions suspended by BRAKE (the braked one and everything
        planned after it, reference §5.17). Motions the interrupt routine itself planned
        after the BRAKE are kept and run; the next motion starts where they end, or from the
        current position. Called while the robot moves without a BRAKE before, it discards
        everything and the robot stops at the current setpoint."""
        if self._held is not None:
            h = self._held
            self._abort(h.runs, h.blend)
            self._held = None
            self._moved_while_held = False
            if not self.is_moving() and not self._pending:
                self._plan_q = self._q.copy()
            return
        self._moved_while_held = False
        self._abort(self._runs, self._blend)
        self._pending.clear()
        self._runs = []
        self._blend = None
        self._tracked = []
        self._braking = False
        self._scale, self._scale_rate = 1.0, 0.0
        self._ramp_up = False
        self._plan_q = self._q.copy()

    def _abort(self, runs: list[_Run], blend: _Blend | None) -> None:
        """Log ``end`` with ``reason: abort`` for started motions that are abandoned before
        their end point (RESUME, a main-run error)."""
        segs = ([blend.prev.seg] if blend is not None else []) + [r.seg for r in runs]
        seen: set[int] = set()
        for seg in segs:
            if seg.id not in seen:
                seen.add(seg.id)
                self._motion_event(seg, "end", reason="abort")

    def axis_ret(self) -> np.ndarray | None:
        """``$AXIS_RET``: the axes where BRAKE (or an error) made the robot leave its path,
        or None if that never happened (deg, KRL's order)."""
        return None if self._ret_q is None else self._ret_q.copy()

    # ================================================================= I/O
    def _on_io(self, t: float, name: str, value: Any, source: str) -> None:
        self._events.append(IoEvent(t, name, value, source))
        if self.trace is not None:
            self.trace.write("io", t, signal=name, value=value, source=source)

    def set_out(self, n: int, value: bool, source: str = "program") -> None:
        """``$OUT[n] = value`` (logged as an io event)."""
        self.io.now = self.time
        self.io.set_out(n, value, source)

    def get_in(self, n: int) -> bool:
        """``$IN[n]``."""
        return self.io.get_in(n)

    def pulse(self, n: int, level: bool, duration_s: float, source: str = "program") -> None:
        """``PULSE($OUT[n], level, duration)``: set now, set to ``NOT level`` after
        ``duration_s`` (at the first IPO cycle at or after it; reference §5.12)."""
        self.set_out(n, level, source)
        self._pulses.append((self.time + float(duration_s), int(n), not level))

    def add_cyclic(self, fn: Callable[["Controller"], None]) -> int:
        """Call ``fn(controller)`` once per IPO cycle after the setpoint is computed
        (ANOUT ON, ANIN ON, $CYCFLAG). Returns a handle for :meth:`remove_cyclic`."""
        h = self._cyclic_next
        self._cyclic_next += 1
        self._cyclic[h] = fn
        return h

    def remove_cyclic(self, handle: int) -> None:
        self._cyclic.pop(handle, None)

    # ================================================================= read-back
    def axis_act(self) -> np.ndarray:
        """``$AXIS_ACT`` in KRL's order (robot/axismap.py ``to_krl``): A1..A6 (deg) read back from
        the MuJoCo model (0 for the axes of a robot with fewer than six, a SCARA's A5 and A6); then
        E1.. (mm, deg) on a robot with external axes or a seven-axis arm's redundancy."""
        return self.model.to_krl(self._axes_act())

    def _axes_act(self) -> np.ndarray:
        """The axes read back (A1..An, E1..En: the model's order)."""
        arm = self._arm if self._arm_q is None else self._arm_model()
        if arm is not None:
            return arm.axes_deg()
        return self._q.copy()

    def axis_setpoint(self) -> np.ndarray:
        """The current IPO setpoint in KRL's order (as :meth:`axis_act`)."""
        return self.model.to_krl(self._q.copy())

    def pos_act(self, tool: Any = None, base: Any = None, ipo_mode: str = "BASE") -> dict[str, float]:
        """``$POS_ACT`` as an E6POS dict {X, Y, Z, A, B, C, S, T} (mm, deg): the TCP of
        :meth:`axis_act` in ``base`` for ``tool`` (6-tuples or 4x4; default: the $BASE/$TOOL
        of the motion the main run executes, ``$BASE_C``/``$TOOL_C``). ``ipo_mode`` "TCP"
        (external TCP, reference §6.4): ``tool`` is the workpiece on the flange, ``base`` the
        fixed tool in WORLD, and the pose is the fixed tool in the workpiece frame,
        ``INV_POS($ROBROOT : FLANGE(q) : $TOOL) : $BASE`` (robot/external_tcp.py)."""
        q = self._axes_act()
        tool_T = self._tool_T if tool is None else _as4(tool)
        base_inv = self._base_inv_T if base is None else inv_pos(_as4(base))
        T = self._tcp_read_back(q, tool_T, base_inv)
        if ipo_mode == "TCP":
            T = inv_pos(T)
        x, y, z, a, b, c = matrix_to_frame(T)
        s, t = self.model.status_turn(q)
        out = {"X": x, "Y": y, "Z": z, "A": a, "B": b, "C": c, "S": s, "T": t}
        out.update(self.model.axes.e_components(q))
        return out

    @property
    def _tcp_T(self) -> np.ndarray:
        """The TCP read back this cycle (4x4, in $BASE; :meth:`step` may leave it to be made
        here, when first asked for)."""
        T = self._tcp_m
        if T is None:
            T = self._tcp_m = self._tcp_read_back(*self._tcp_src)
            self._tcp_src = None
        return T

    @_tcp_T.setter
    def _tcp_T(self, T: np.ndarray) -> None:
        self._tcp_m, self._tcp_src = T, None

    @property
    def _tcp_prev(self) -> np.ndarray:
        """The TCP's position (mm) read back the cycle before (:attr:`_tcp_T`'s)."""
        p = self._tcp_pp
        if p is None:
            p = self._tcp_pp = self._tcp_read_back(*self._tcp_psrc)[:3, 3].copy()
            self._tcp_psrc = None
        return p

    @_tcp_prev.setter
    def _tcp_prev(self, p: np.ndarray) -> None:
        self._tcp_pp, self._tcp_psrc = p, None

    def _tcp_read_back(self, q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """TCP in $BASE from the MuJoCo flange site (``INV_POS($BASE) : FLANGE_world : $TOOL``),
        or from the forward kinematics of ``q`` without MuJoCo."""
        arm = self._arm if self._arm_q is None else self._arm_model()
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

    def axis_vel_act(self) -> np.ndarray:
        """The axes' velocities over the last IPO cycle in KRL's order (A1..A6 deg/s, then
        E1..En deg/s or mm/s): the source of ``$VEL_AXIS_ACT`` (interp/runtime/sysvars.py)."""
        return self.model.to_krl((self._q - self._q_prev) / self.dt)

    def vel_act(self) -> float:
        """``$VEL_ACT``: TCP speed in m/s over the last IPO cycle."""
        return float(np.linalg.norm(self._tcp_T[:3, 3] - self._tcp_prev)) / self.dt / 1000.0

    def current_request(self) -> MotionRequest | None:
        """The motion the main run executes now (the newer one during a blend), or None:
        the source of the ``_C`` variables (``$VEL_C``, ``$TOOL_C``, ...) and ``$POS_FOR``."""
        return self._runs[-1].seg.req if self._runs else None

    def planned_axes(self) -> np.ndarray:
        """End point (deg) of the last planned motion (the start of the next one)."""
        return self._plan_q.copy()

    # ================================================================= trace helpers
    def message(self, text: str, motion_id: int | None = None, number: int | None = None) -> None:
        """Log a controller message (event + trace), and tell the watchers (:meth:`watch_messages`)."""
        self._events.append(MessageEvent(self.time, text, motion_id))
        if self.trace is not None:
            self.trace.write("message", self.time, text=text, id=motion_id, number=number)
        for fn in self._message_watchers:
            fn(text, motion_id, number)

    def watch_messages(self, fn: Callable[[str, int | None, int | None], None]) -> None:
        """Call ``fn(text, motion_id, number)`` for each message (the pendant's message window)."""
        self._message_watchers.append(fn)

    def set_advance(self, n: int) -> None:
        """``$ADVANCE``: how many motions the advance run may plan ahead of the main run."""
        self.advance = n

    def finish(self, reason: str = "program_end", **fields: Any) -> None:
        """Write the ``end`` trace event (once); ``fields`` add where and why (the
        interpreters pass text, number, file, line and context)."""
        if not self._ended and self.trace is not None:
            self.trace.write("end", self.time, reason=reason, **fields)
        self._ended = True

    def _motion_event(self, seg: Segment, phase: str, reason: str | None = None,
                      reached: float | None = None) -> None:
        req = seg.req
        self._events.append(MotionEvent(self.time, req.id, phase, req))
        if self.trace is not None:
            limits = seg.limits.as_trace() if phase == "start" else None
            self.trace.write("motion", self.time, id=req.id, type=req.type_name,
                             target=dict(req.target), approximation=req.approx,
                             phase=phase, point=seg.end_frame, line=req.line, file=req.file,
                             reason=reason, limits=limits, reached=reached)
        for st in self.stimuli:
            if (not st.fired and st.due is None and st.phase == phase
                    and st.matches_motion(req.id, req.line)):
                st.due = self.time + st.delay

    # ================================================================= the IPO cycle
    def step(self) -> list[Event]:
        """Run one IPO cycle (12 ms): I/O timers, pulses and stimuli, the main-run setpoint
        (motion start, approximation, blend, end), triggers, MuJoCo, the pose trace event.

        Returns the events of this cycle, in order.
        """
        self._events = []
        self._k += 1
        t = self.time = self._k * self.dt
        self.io.now = t
        if self.network is not None and self.network.polling:
            self.network.cycle(self)
        self.io.tick_timers(self._dt_ms)
        if self._pulses:
            keep = []
            for (te, n, lvl) in self._pulses:
                if t >= te - EPS:
                    self.io.set_out(n, lvl, "pulse")
                else:
                    keep.append((te, n, lvl))
            self._pulses = keep
        if self.stimuli:
            self._apply_stimuli(t)
        if self.rules:
            self._rules_seen = step_rules(self.rules, self.io, t, self.dt, self._rules_seen)

        if self._tracked:
            self._conditional_stops()
        # path time (BRAKE ramps scale the path speed)
        s_old = self._scale
        pt_old = self._pt
        if self._ramp_up:
            # release(): this cycle's path-time step is dt · scale, the scale chosen within
            # the axes' accelerations (_ramp_scale)
            self._scale = self._ramp_scale(s_old, min(1.0, s_old + self._scale_rate * self.dt))
            self._pt += self.dt * self._scale
            if self._scale >= 1.0:
                self._scale, self._scale_rate = 1.0, 0.0
                self._ramp_up = False
        else:
            if self._scale_rate != 0.0:
                self._scale = min(1.0, max(0.0, self._scale + self._scale_rate * self.dt))
                if self._scale in (0.0, 1.0):
                    self._scale_rate = 0.0
            self._pt += self.dt * 0.5 * (s_old + self._scale)
        self._pt_step = self._pt - pt_old
        self._q_prev = self._q
        try:
            q = self._main_run(self._pt)
            if self.correction is not None:
                q = self._corrected(q)
            self._check_speed(q)
        except RobotError as err:
            q = self._fault(err)
        self._q = np.asarray(q, dtype=float)
        if self._braking and self._scale <= 0.0:
            self._hold()
        if self._tracked:
            self._fire_triggers(self._pt)
        arm = self._arm if self._arm_q is None else self._arm_model()
        cyc = arm.compiled_cycle(self._simcore) if arm is not None and not self.actuated else None
        if cyc is not None:
            # set_axes, axis_act and the flange site in one compiled call (the same numbers)
            qa, T = np.empty(self._q.shape[0]), np.empty((4, 4))
            self._tcp_prev = self._tcp_T[:3, 3].copy()
            try:
                # with _tcp_read_back's product in numpy's own BLAS call (robot/mjcf.py
                # _same_products)
                done = cyc.cycle_tcp(self._q, qa, self._base_inv_T, self._tool_T, T)
            except (TypeError, ValueError):      # a frame not C-contiguous float64: numpy's @
                done = False
            if not done:
                F = np.empty((4, 4))
                cyc.cycle(self._q, qa, F)
                T = self._base_inv_T @ F @ self._tool_T
            self._tcp_T = T
        else:
            if arm is not None:
                if self.actuated:
                    arm.step_actuated(self._q, self.dt, (self._q - self._q_prev) / self.dt)
                else:
                    arm.set_axes(self._q)
            qa = self._axes_act()
            if arm is None:
                # without MuJoCo the read-back is the forward kinematics of these arrays alone:
                # made when first asked for ($POS_ACT, $VEL_ACT, the trace's pose), the same numbers
                if self._tcp_m is not None:
                    self._tcp_pp, self._tcp_psrc = self._tcp_m[:3, 3].copy(), None
                else:
                    self._tcp_pp, self._tcp_psrc = None, self._tcp_src
                self._tcp_m, self._tcp_src = None, (qa, self._tool_T, self._base_inv_T)
            else:
                self._tcp_prev = self._tcp_T[:3, 3].copy()
                self._tcp_T = self._tcp_read_back(qa, self._tool_T, self._base_inv_T)
        if self.collision is not None and (self._runs or self._blend is not None):
            self._watch_collisions()
        if self.workspaces is not None:
            self._watch_workspaces(qa)
        if self._cyclic:
            for fn in list(self._cyclic.values()):
                fn(self)
        if self.stimuli and self._runs:
            self._reach_stimuli()
        tr = self.trace
        if tr is not None and tr.takes_poses:
            tr.write_pose(t, qa, self._tcp_T)
        return self._events

    # ----------------------------------------------------------------- main run
    def _start(self, seg: Segment, pt: float) -> _Run:
        run = _Run(seg, pt)
        self._tool_T, self._base_T = seg.tool_T, seg.base_T
        self._base_inv_T = seg.base_inv_T
        self._motion_event(seg, "start")
        if seg.triggers:
            self._tracked.append(run)
        # expected blend (for DISTANCE=1 triggers with a negative DELAY)
        if seg.req.approx is not None and self._pending and seg.triggers:
            nxt = self._pending[0]
            kw = blending.effective_keyword(seg, nxt)
            ta = blending.blend_start_tau(seg, nxt, kw) if kw else None
            if ta is not None:
                te = self._blend_window(seg, nxt, kw, ta)
                run.planned_mid = pt + ta + 0.5 * te
        return run

    def _main_run(self, pt: float) -> np.ndarray:
        if self._ending is not None and self._exact_stop_ending():
            return self._q
        if self._blend is not None:
            b = self._blend
            if pt < b.pb - EPS:
                return self._blend_setpoint(b, pt)
            self._end_blend(b)
        if not self._runs:
            if self._pending:
                seg = self._pending.popleft()
                self._runs = [self._start(seg, pt)]
            else:
                return self._q
        r = self._runs[0]
        seg = r.seg
        tau = pt - r.t0
        if seg.req.approx is not None and not r.decided:
            nxt = self._pending[0] if self._pending else None
            key = nxt.id if nxt is not None else None
            if r.tau_cache is None or r.tau_cache[0] != key:
                kw = blending.effective_keyword(seg, nxt)
                r.tau_cache = (key, blending.blend_start_tau(seg, nxt, kw) if kw else None)
            tau_a = r.tau_cache[1]
            if tau_a is None:
                r.decided = True
            elif tau >= tau_a - EPS:
                if nxt is not None:
                    kw = blending.effective_keyword(seg, nxt) or "C_DIS"
                    bp = blending.plan_blend(seg, nxt, kw, tau)
                    if bp is None:
                        # an axis would reverse with both accelerations added: the blend
                        # waits until the approximated motion reaches its point
                        bp = blending.plan_blend(seg, nxt, kw, max(tau, seg.T))
                        if tau < seg.T - EPS:
                            r.tau_cache = (key, seg.T)
                            return seg.axes(tau)
                    r.decided = True
                    return self._begin_blend(r, pt, bp)
                r.decided = True
                self.message(MSG_APPROX_IMPOSSIBLE, seg.id)
        if tau >= seg.T - EPS:
            # an exact stop: the robot stands at the end point; END and done come later
            self._runs = []
            r.decided = True
            # the interpolation ended between the last cycle and this one (in clock time)
            over = (pt - (r.t0 + seg.T)) * self.dt / max(self._pt_step, EPS)
            reached = self.time - min(max(over, 0.0), self.dt)
            k_end = int(math.floor(reached / self.dt + 1e-6)) + END_DELAY_CYCLES
            self._ending = _Ending(seg, reached, k_end, k_end + DONE_CYCLES)
            seg._last_q = seg.q1.copy()
            return seg.q1.copy()
        if self.batch and self._scale == 1.0 and self._scale_rate == 0.0:
            # at full path speed pt advances by one cycle each step: the segment solves the
            # coming cycles at once, up to its end or its blend start (robot/planner.py)
            end = seg.T - EPS
            if not r.decided and r.tau_cache is not None and r.tau_cache[1] is not None:
                end = min(end, r.tau_cache[1] - EPS)
            return seg.axes_run(pt, r.t0, self.dt * 0.5 * (1.0 + 1.0), end)
        return seg.axes(tau)

    def _exact_stop_ending(self) -> bool:
        """The exact stop that is ending (robot/exactstop.py): its END signal (the motion's
        ``end`` event, with the time its interpolation ended) at its cycle; True while the main
        run is not done with it (the robot stands; no motion starts), False from the cycle after
        it is done."""
        e = self._ending
        if not e.signalled and self._k >= e.k_end:
            e.signalled = True
            self._motion_event(e.seg, "end", reached=e.reached)
        if self._k >= e.k_done:
            self._ending = None
            return self._k == e.k_done
        return True

    def _end_now(self) -> None:
        """An ending exact stop gives its END at once (the run stops: an error, a reset)."""
        e = self._ending
        if e is not None:
            self._ending = None
            if not e.signalled:
                self._motion_event(e.seg, "end", reached=e.reached)

    def _begin_blend(self, r: _Run, pt: float, bp: "blending.BlendPlan") -> np.ndarray:
        nseg = self._pending.popleft()
        kw = blending.effective_keyword(r.seg, nseg) or "C_DIS"
        # the blend's own time laws (robot/blending.py plan_blend): prev brakes through the
        # zone, the next motion ramps up to the blend end
        r.seg.profile = bp.prev_profile
        nseg.profile = bp.next_profile
        tau_e = bp.window
        self._motion_event(r.seg, "blend_start")
        nr = self._start(nseg, pt)
        nr.blend_in_end = pt + tau_e
        r.blend_mid = pt + 0.5 * tau_e
        b = _Blend(r, nr, pt, pt + tau_e, blending.blend_space(r.seg, nseg), kw)
        self._runs = [nr]
        self._blend = b
        if tau_e <= EPS:
            self._end_blend(b)
            return nr.seg.axes(pt - nr.t0)
        return self._blend_setpoint(b, pt)

    def _blend_window(self, seg: Segment, nxt: Segment, kw: str, tau_a: float) -> float:
        """Length (s) of the blend that starts at local time ``tau_a`` of ``seg`` (it ends
        when ``seg`` reaches its point)."""
        bp = blending.plan_blend(seg, nxt, kw, tau_a) or blending.plan_blend(seg, nxt, kw, seg.T)
        assert bp is not None
        return bp.window

    def _end_blend(self, b: _Blend) -> None:
        self._blend = None
        self._motion_event(b.prev.seg, "blend_end")
        self._motion_event(b.prev.seg, "end")
        b.nxt.seg._last_q = self._q.copy()

    def _blend_setpoint(self, b: _Blend, pt: float) -> np.ndarray:
        """The blend's setpoint: the overlap of the two velocity profiles (robot/blending.py),
        in Cartesian space or in axis space."""
        t_prev = min(pt - b.prev.t0, b.prev.seg.T)
        t_next = pt - b.nxt.t0
        if b.space == "cart":
            p0, R0 = b.prev.seg.pose(t_prev)
            p1, R1 = b.nxt.seg.pose(t_next)
            pc, Rc = b.nxt.seg.pose(0.0)
            if blending.reduced_orientation(self.model):
                # a palletizer: overlap the poses it reaches, not the paths' own orientations
                # (robot/blending.py reached_pose)
                u0, u1 = b.prev.seg.u(t_prev), b.nxt.seg.u(t_next)
                p0, R0 = blending.reached_pose(b.prev.seg, p0, R0, self._q, u0)
                p1, R1 = blending.reached_pose(b.nxt.seg, p1, R1, self._q, u1)
                pc, Rc = blending.reached_pose(b.nxt.seg, pc, Rc, self._q, 0.0)
            p, R = blending.superpose_pose(p0, R0, p1, R1, pc, Rc)
            ref = self._q
            n = self.n
            if len(ref) > n:
                # the external axes overlap like axes: E_prev(t) + E_next(t) - E at the point
                e = (_e_at(b.prev.seg, b.prev.seg.u(t_prev), n) + _e_at(b.nxt.seg, b.nxt.seg.u(t_next), n)
                     - b.nxt.seg.q0[n:])
                ref = np.concatenate([ref[:n], e])
            return b.nxt.seg.ik(p, R, ref)  # type: ignore[attr-defined]
        q = b.prev.seg.axes(t_prev) + (b.nxt.seg.axes(t_next) - b.nxt.seg.q0)
        self.model.check_limits(q)
        return q

    def _corrected(self, q: np.ndarray) -> np.ndarray:
        """The setpoint `q` with the sensor correction superposed: the axis correction added,
        the Cartesian one applied to the TCP in $BASE (translation added, rotation
        pre-multiplied) and solved back to axes near `q`. At rest the main run keeps its last
        setpoint, which already holds the correction: the uncorrected one is used instead."""
        if q is self._q:
            q = self._q_raw
        self._q_raw = np.asarray(q, dtype=float)
        out = self._q_raw.copy()
        corr = self.correction
        n = self.n
        axes = np.asarray(corr.axes, dtype=float)        # KRL's A1..A6
        if np.any(axes):
            out[:n] += self.model.axes.from_krl(axes, fill=np.zeros(len(out)))[:n]
        cart = np.asarray(corr.cart, dtype=float)
        if np.any(cart):
            T = self.model.tcp(out[:n], self._tool_T, self._base_inv_T)
            C = frame_to_matrix(*cart)
            frame = getattr(corr, "frame", "BASE")      # RSI's POSCORR RefCorrSys (net/rsi.py)
            if frame == "WORLD":                        # a correction in $WORLD, seen from $BASE
                Rb = self._base_T[:3, :3]
                C[:3, 3] = Rb.T @ C[:3, 3]
                C[:3, :3] = Rb.T @ C[:3, :3] @ Rb
            if frame == "TOOL":                         # in the programmed TCP's own frame
                target = T @ C
            else:
                target = T.copy()
                target[:3, 3] = T[:3, 3] + C[:3, 3]
                target[:3, :3] = C[:3, :3] @ T[:3, :3]
            out[:n] = self.model.ik(target, np.linalg.inv(self._tool_T), self._base_T, None, None, out[:n])
        return out

    def set_correction(self, correction) -> None:
        """Superpose `correction` (``axes``, ``cart``; see ``__init__``) from the next cycle on."""
        self.correction = correction
        self._q_raw = self._q.copy()

    def keep_correction(self) -> None:
        """The sensor correction ends (RSI_OFF) and the robot keeps its corrected position: the
        next motion is planned from it."""
        self.correction = None
        self._q_raw = self._q.copy()
        if self.is_idle():
            self._plan_q = self._q.copy()

    def stop_with(self, text: str, number: int | None = None) -> None:
        """Stop the robot now with the message `text` (a sensor's error, as KSS stops on
        RSI's): the main run is aborted and the program gets the error at its next step."""
        q = self._fault(RobotError(text, number))
        self._q = q
        self.correction = None

    def tcp_frame(self) -> tuple:
        """The TCP (X, Y, Z mm, A, B, C deg) in $BASE read back this cycle (``$POS_ACT``'s frame)."""
        return matrix_to_frame(self._tcp_T)

    def _check_speed(self, q: np.ndarray) -> None:
        """Reject a setpoint that would move an axis faster than
        ``CP_SPEED_LIMIT_FACTOR`` x its maximum speed (a CP path through a singularity)."""
        if q is self._q_prev:        # at rest: the main run kept the last setpoint
            return
        lim = self._step_lim
        if lim is None:
            lim = self._step_lim = (CP_SPEED_LIMIT_FACTOR * self.model.v_max * self.dt + 1e-9).tolist()
            self._step_lim_a = np.array(lim, dtype=float)
        if self._speed_ok is not None and type(q) is np.ndarray:
            try:
                if self._speed_ok(q, self._q_prev, self._step_lim_a):
                    return
            except (TypeError, ValueError):      # not float64: the loop below takes it
                pass
        step = [abs(a - b) for a, b in zip(q.tolist() if type(q) is np.ndarray else np.asarray(q).tolist(),
                                           self._q_prev.tolist())]
        for d, m in zip(step, lim):
            if d > m:
                i = max(range(len(step)), key=lambda j: step[j] / lim[j])
                name = self.model.axes.model_keys[i]
                raise RobotError(f"speed limit exceeded {name}: CP path through a singularity")

    def _watch_collisions(self) -> None:
        """The robot against its cell at this IPO cycle's setpoint (robot/collision.py: MuJoCo's
        contacts of the links, the tool, the cell's bodies and the floor): a contact stops the
        robot here, a main-run error naming both bodies, the motion's line and the TCP in
        ``$WORLD``."""
        c = self.collision.check(self._q)
        if c is None:
            return
        p = (self._base_T @ self._tcp_T)[:3, 3]
        req = self._runs[0].seg.req if self._runs else None
        line = f" at the motion of line {req.line}" if req is not None and req.line is not None else ""
        self._fault(RobotError(f"collision: {c.a} touches {c.b}{line}; TCP X {p[0]:.1f}, Y {p[1]:.1f}, "
                               f"Z {p[2]:.1f} mm in $WORLD"))

    def _watch_workspaces(self, qa: np.ndarray) -> None:
        """KUKA's workspace monitoring at this IPO cycle (robot/workspace.py): the TCP of the main
        run's ``$TOOL`` in ``$WORLD`` and the axes read back; each state signal that changes is an
        I/O event (source ``workspace``); a STOP workspace violated stops the robot here, with
        its message, as a main-run error (the queue discarded, the program stopped)."""
        p = (self._base_T @ self._tcp_T)[:3, 3]
        changes, stop = self.workspaces.cycle(p, self.model.axes.components(qa))
        for name, value in changes:
            self._events.append(IoEvent(self.time, name, value, "workspace"))
            if self.trace is not None:
                self.trace.write("io", self.time, signal=name, value=value, source="workspace")
        if stop is not None and (self._runs or self._blend is not None or self._pending):
            self._fault(RobotError(stop))

    def _fault(self, err: RobotError) -> np.ndarray:
        self._end_now()
        mid = self._runs[0].seg.id if self._runs else None
        self.last_error = err
        self._events.append(ErrorEvent(self.time, err, mid))
        if self.trace is not None:
            line = self._runs[0].seg.req.line if self._runs else None
            self.trace.write("error", self.time, text=err.message, number=err.number,
                             id=mid, line=line)
        q = self._q.copy()
        self._ret_q = q.copy()
        self._abort(self._runs, self._blend)
        if self._held is not None:
            self._abort(self._held.runs, self._held.blend)
        self._runs = []
        self._blend = None
        self._pending.clear()
        self._tracked = []
        self._held = None
        self._braking = False
        self._scale, self._scale_rate = 1.0, 0.0
        self._ramp_up = False
        self._plan_q = q.copy()
        return q

    def _hold(self) -> None:
        """BRAKE finished: suspend the main run (interrupt level starts empty)."""
        self._braking = False
        self._held = _Held(self._runs, self._blend, self._pending, self._tracked, self._pt,
                           self._q.copy(), self._tool_T, self._base_T, self._plan_q.copy())
        self._ret_q = self._q.copy()
        self._runs, self._blend, self._pending, self._tracked = [], None, deque(), []
        self._scale, self._scale_rate = 1.0, 0.0
        self._ramp_up = False
        self._moved_while_held = False
        self._plan_q = self._q.copy()

    # ----------------------------------------------------------------- conditional stops
    def _conditional_stops(self) -> None:
        """STOP WHEN PATH (robot.motion.CondStop), each IPO cycle before the path time moves.
        The stop point is the path time of its planned point (a TRIGGER WHEN PATH's). The
        braking point is the last cycle from which the robot, braking as BRAKE does at its
        present axis speeds (:meth:`brake`: half the machine acceleration), still stops before
        the stop point: there the condition is evaluated. Not met: the robot goes on, even if
        it is met later. Met: the path speed ramps down linearly so that the robot stands at
        the stop point; while it brakes or stands the condition is evaluated at every cycle,
        and once it no longer holds the path speed ramps up again within the axes'
        accelerations (:meth:`_ramp_scale`, as after a BRAKE). A stop point the robot has passed
        when it is first looked at (one too close to where a blend began) is braked for as
        soon as possible. KUKA's manual (KSS 8.3 Operating and Programming Instructions for
        System Integrators, "Conditional stop"); docs/robot.md, "Conditional stop"."""
        for run in self._tracked:
            for tp in run.seg.triggers:
                st = tp.trigger
                if not isinstance(st, CondStop) or tp.index in run.fired:
                    continue
                state = run.stops.get(tp.index)
                if state is None:
                    t_stop = run.t0 + run.seg.profile.t_of_u(tp.u_ref) if tp.u_ref is not None else run.t0
                    s = self._scale
                    v = np.abs(self._q - self._q_prev) / self.dt
                    T = max(self.dt, float(np.max(v / (0.5 * self.model.a_max))))
                    if self._pt + s * (0.5 * T + self.dt) < t_stop - EPS:
                        continue            # the braking point lies ahead
                    if not st.condition():
                        run.fired.add(tp.index)      # not met at the braking point: it goes on
                        continue
                    self._stop_T = T
                    self._ramp_up = False
                    left = t_stop - self._pt
                    if s <= 0.0 or float(np.max(v)) <= 1e-9:
                        self._scale, self._scale_rate = 0.0, 0.0      # standing: it stays
                        run.stops[tp.index] = "stopped"
                    else:
                        self._scale_rate = -(s * s) / (2.0 * left) if left > EPS else -s / T
                        run.stops[tp.index] = "braking"
                elif not st.condition():
                    run.fired.add(tp.index)          # no longer met: the path speed ramps up
                    del run.stops[tp.index]
                    self._scale_rate = 1.0 / max(self._stop_T, self.dt)
                    self._ramp_up = True
                elif state == "braking" and self._scale <= 0.0:
                    run.stops[tp.index] = "stopped"

    # ----------------------------------------------------------------- triggers
    def _fire_triggers(self, pt: float) -> None:
        if not self._tracked:
            return
        still = []
        for run in self._tracked:
            due = []
            for tp in run.seg.triggers:
                if tp.index in run.fired or isinstance(tp.trigger, CondStop):
                    continue            # a conditional stop is the main run's (_conditional_stops)
                tf = run.trigger_time(tp)
                if pt >= tf - EPS:
                    due.append((tf, tp.index, tp))
            for _, _, tp in sorted(due, key=lambda x: (x[0], x[1])):
                run.fired.add(tp.index)
                ev = TriggerEvent(self.time, run.seg.id, tp.index, tp.trigger)
                self._events.append(ev)
                if self.trace is not None:
                    self.trace.write("trigger", self.time, id=run.seg.id, index=tp.index,
                                     line=tp.trigger.line)
            if run.pending_triggers:
                still.append(run)
        self._tracked = still

    # ----------------------------------------------------------------- stimuli
    def _apply_stimuli(self, t: float) -> None:
        for st in self.stimuli:
            if st.fired:
                continue
            due = st.at if st.at is not None else st.due
            if due is not None and t >= due - EPS:
                st.fired = True
                for name, v in st.set.items():
                    self.io.set_signal(name, v, st.source)
                if st.on_fire is not None:
                    st.on_fire(t)

    def _reach_stimuli(self) -> None:
        if not self.stimuli or not self._runs:
            return
        active = [r.seg for r in self._runs]
        if self._blend is not None:
            active.append(self._blend.prev.seg)
        for st in self.stimuli:
            if st.fired or st.due is not None or st.reached_mm is None:
                continue
            for seg in active:
                if st.matches_motion(seg.id, seg.req.line):
                    p_end = seg.model.tcp(seg.q1, seg.tool_T, seg.base_inv_T)[:3, 3]
                    here = seg.model.tcp(self._q, seg.tool_T, seg.base_inv_T)[:3, 3]
                    if float(np.linalg.norm(here - p_end)) <= st.reached_mm + 1e-9:
                        st.due = self.time + st.delay
                        if st.delay <= 0:
                            st.fired = True
                            for name, v in st.set.items():
                                self.io.set_signal(name, v, st.source)


def _e_at(seg: Segment, u: float, n: int) -> np.ndarray:
    """The external axes of `seg` (after its n robot axes) at its path parameter `u` (linear
    from start to end)."""
    return seg.q0[n:] + u * (seg.q1[n:] - seg.q0[n:])


def _as4(F: Any) -> np.ndarray:
    arr = np.asarray(F, dtype=float)
    if arr.shape == (4, 4):
        return arr
    return frame_to_matrix(*arr)


__all__ = ["Controller", "MotionEvent", "TriggerEvent", "IoEvent", "MessageEvent",
           "ErrorEvent", "Event", "MSG_APPROX_IMPOSSIBLE"]
