"""The simulated KR C4 main run: the 12 ms IPO cycle, motion execution (start, approximation,
exact stop, triggers, conditional stops), BRAKE and RESUME (reference §5.8, §5.12-§5.18, §6, §7;
issue 5).

The interpreters are the advance run; they drive a :class:`Controller` through a small
protocol (docs/architecture.md, "Robot interface")::

    ctl = Controller(trace=TraceWriter("run.jsonl"))
    while not ctl.can_enqueue():          # $ADVANCE: a full queue blocks the advance run
        handle(ctl.step())
    ctl.queue.enqueue(MotionRequest("LIN", {"X": 500}, params, approx="C_DIS", triggers=...))
    while not ctl.is_idle():              # an advance-run stop (WAIT, $OUT write, ...)
        handle(ctl.step())

:meth:`Controller.step` runs one IPO cycle (12 ms of simulated time) and returns the events
of that cycle (robot/events.py: :class:`MotionEvent`, :class:`TriggerEvent`, :class:`IoEvent`,
:class:`MessageEvent`, :class:`ErrorEvent`). Interrupt conditions are the interpreter's:
it evaluates them after every step.

The controller's parts (issue 62), each its own module, reached as attributes: ``queue`` the
motions planned and not started and ``$ADVANCE`` (robot/motionqueue.py), ``io`` the I/O image
(robot/io.py), ``signals`` what changes the I/O without the program: PULSE, cyclic hooks, the
cell's stimuli and rules (robot/signals.py), ``actual`` the robot read back: ``$AXIS_ACT``,
``$POS_ACT``, the MuJoCo arm (robot/readback.py), ``monitor`` the checks of each cycle: axis
speed, collisions, workspaces (robot/monitor.py), ``log`` the events and the trace
(robot/events.py). This class keeps the clock and the main run that ties them.

Time: the clock is the integer IPO cycle count ``k``; ``time = k · 0.012`` s. Motion timing
uses a *path time* that equals the clock except while BRAKE ramps the path speed down, the
robot is held, and :meth:`Controller.release` ramps it back up within the axis accelerations
(the robot stays on its path, because every setpoint is a function of path time).
"""

from __future__ import annotations

import math
from collections import deque
from pathlib import Path
from typing import Any

import numpy as np

from .actualvalue import stream_for
from .settlelag import settle_tau
from . import blending
from .exactstop import DONE_CYCLES, END_DELAY_CYCLES
from .errors import RobotError
from .events import ErrorEvent, Event, EventLog, IoEvent, MessageEvent, MotionEvent, TriggerEvent
from .frames import frame_to_matrix, inv_pos
from .io import IOImage
from .limits import normalise_mode
from .machine import MachineData, load_machine
from .motion import CondStop, MotionRequest
from .monitor import Monitor
from .motionqueue import MotionQueue
from .planner import resolved_target
from .robotmodel import RobotModel
from .segments import Segment
from .cellrules import Rule
from . import ipocycle
from .kinematics.compiled import pure_module
from .readback import ReadBack
from .signals import Signals
from .stimuli import Cell, Stimulus
from .trace import TraceWriter
from .mainrun import _Blend, _Ending, _Held, _Run


EPS = 1e-9
_F8 = np.dtype(np.float64)
MSG_APPROX_IMPOSSIBLE = "approximation not possible"


def _cell_parts(stimuli: Any, mode_op: str | None, geometry: Any) -> tuple[Any, list[Rule], str | None, Any]:
    """(stimuli, the cell's rules, operating mode, geometry) of the Controller's `stimuli`: a whole
    Cell gives its stimuli, rules, geometry (unless given) and, with its autoext preset, the mode
    EX (unless given). Raises TypeError for a cell file's path (robot.stimuli.load_cell reads it)."""
    rules_all: list[Rule] = []
    if isinstance(stimuli, (str, Path)):
        raise TypeError("a cell file is read by robot.stimuli.load_cell; pass its Cell")
    if isinstance(stimuli, Cell):
        if stimuli.autoext and mode_op is None:
            mode_op = "EX"            # Automatic External (robot/cellpresets.py)
        if geometry is None:
            geometry = stimuli.geometry
        stimuli, rules_all = stimuli.stimuli, list(stimuli.rules)
    return stimuli, rules_all, mode_op, geometry



def _push_actual(ctl: Any, t: float, qa: Any) -> None:
    """The read-back axes `qa` of `ctl`'s (Controller) cycle at `t` into its actual-value stream: the row's
    motion kind picks its average (robot/actualvalue.py: a PTP's filter), its motion's end pose and load
    the settling lag's τ (robot/settlelag.py, once per segment); at rest, the last motion's."""
    st, actual = ctl.act_stream, ctl.actual
    seg = ctl._runs[0].seg if ctl._runs else None
    tau = None
    if seg is not None and st.lag:
        if ctl._tau_of[0] is not seg:
            p = seg.req.params
            ctl._tau_of = (seg, settle_tau(ctl.machine, seg.q1, p.load, p.load_a3))
        tau = ctl._tau_of[1]
    st.push(t, np.array(qa, dtype=float), (actual.tool_T, actual.base_inv_T) if st.keep else None,
            ptp=(not seg.cart) if seg is not None else None, tau=tau)

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
        mujoco: False to skip MuJoCo entirely (``actual.axis_act`` then returns the setpoint).
        mode_op: operating mode ``T1``, ``T2``, ``AUT`` or ``EX`` (``EXT``); default AUT
            (reference §7.5; T1 limits TCP and flange to 250 mm/s, PTP to ``$RED_T1``).

    Attributes:
        queue: the :class:`~robot.motionqueue.MotionQueue` (``$ADVANCE``: ``queue.advance``).
        io: the :class:`~robot.io.IOImage`.
        signals: the :class:`~robot.signals.Signals` (PULSE, cyclic hooks, stimuli, rules).
        actual: the :class:`~robot.readback.ReadBack` (``$AXIS_ACT``, ``$POS_ACT``, ``$VEL_ACT``).
        monitor: the :class:`~robot.monitor.Monitor` (speed, collisions, workspaces).
        log: the :class:`~robot.events.EventLog` (this cycle's events, the trace, messages).
        time: simulated time in s; ``cycle``: IPO cycles run.
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
        stimuli, rules_all, mode_op, geometry = _cell_parts(stimuli, mode_op, geometry)
        for st in stimuli or ():
            if st.reached_default:        # `reached: true`: this robot's $IN_POS_CAR
                st.reached_mm = self.machine.in_pos_car_mm
        self.mode_op = normalise_mode(mode_op)
        self.model = RobotModel(self.machine, mode=self.mode_op)
        self.dt = float(self.machine.ipo_cycle_s)
        self._dt_ms = int(round(self.dt * 1000))
        self.trace = trace
        #: this cycle's events, the trace's, the messages' watchers (robot/events.py)
        self.log = EventLog(trace, lambda: self.time)
        self.io = io if io is not None else IOImage()
        self.io.on_change = self.log.io
        #: the I/O side of each cycle: PULSE, cyclic hooks, the cell's stimuli and rules (robot/signals.py)
        self.signals = Signals(self.io, list(stimuli or []), rules_all + list(rules or []), network, self.dt)
        #: the robot's axis count: axis vectors are A1..An, then E1..En (robot/planner.py)
        self.n = self.model.n
        if start_axes is None:
            q = np.array(self.machine.home_all, dtype=float)
        else:
            # KRL's order (A1..A6, E1..E6); E from $AXIS_HOME[1] unless given
            q = self.model.from_krl(start_axes)
        self.model.check_limits(q)
        #: the motions planned and not yet started, $ADVANCE (robot/motionqueue.py)
        self.queue = MotionQueue(self.model, q, self.machine.def_advance, strict_bco)
        self._pending = self.queue.pending      # the one deque of the queue (the main run's cached reference)
        #: the robot read back: $AXIS_ACT, $POS_ACT, the MuJoCo arm (robot/readback.py), its IPO
        #: cycle's playback robot/ipocycle.py compiled where built and current, else as Python
        self.actual = ReadBack(self.model, q, actuated=actuated, mujoco=mujoco, cycles=pure_module(ipocycle),
                               dt=self.dt)
        #: the actual-value model's stream (robot/actualvalue.py; None: the robot has none): the
        #: axes the drives reach, the settled end (interp/summary.py), the trace's axes_act/tcp_act
        self.act_stream = stream_for(self.machine)
        self._tau_of: tuple[Any, float] = (None, 0.0)   # (segment, its settling lag's τ s: _push_actual)
        if self.act_stream is not None and trace is not None and trace.takes_poses \
                and getattr(trace, "use_actual", None) is not None:
            self.act_stream.keep = True
            trace.use_actual(self.act_stream, self.model.tcp)
        _init_main_run(self, q)
        _init_monitor(self, geometry, workspaces)
        self.network = network  # net.hub.Network: the partners, polled at each cycle's start
        if network is not None:
            network.attach(self, **(cell or {}))

    def select_mode(self, mode: str) -> None:
        """The operating mode `mode` (T1, T2, AUT, EX; robot/limits.py) selected between two runs
        of the program (the pendant): the controller's and its robot model's."""
        self.mode_op = self.model.mode = normalise_mode(mode)

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
        advance = self.queue.advance
        if advance <= 0:
            return self.is_idle()
        return len(self._pending) < advance

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

    def is_moving(self) -> bool:
        """True while a motion is being executed."""
        return bool(self._runs) or self._blend is not None

    def place(self, axes: Any) -> None:
        """Set the scene (``krl run --start``, a cell file's ``start:``): the robot stands at
        `axes` (KRL's order: A1..A6, E1..E6, deg; robot/planner.py ``RobotModel.from_krl``) before
        the first cycle. Raises
        :class:`~robot.errors.SoftLimitError` for axes outside the software limits, ValueError
        once the run has started."""
        if self._k or self._runs or self._pending or self.queue.next_id > 1:
            raise ValueError("the robot can only be placed before the run starts")
        q = self.model.from_krl(axes)
        self.model.check_limits(q)
        self._q = q.copy()
        self._q_prev = q.copy()
        self.queue.plan_from(q)
        self.actual.place(q)

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
        rules = self.signals.rules
        return not (rules and any(not r.last and r.holds(self.io) for r in rules))

    def skip(self, cycles: int) -> None:
        """Fast-forward `cycles` IPO cycles in which nothing happens (interp/runtime/idle.py
        decides that; issue 34 "Idle time costs nothing"): the clock, the path time and every
        running ``$TIMER`` advance exactly as :meth:`step` would advance them, no event,
        pose or cyclic hook runs (the robot stands: the pose is the one of the last cycle; a
        motion that does not move it, executing or queued, goes on after the jump).
        Raises ValueError when the main run is not :meth:`at_rest` or a skipped cycle would
        reach the next event (robot/signals.py ``Signals.next_event_cycle``)."""
        if cycles <= 0:
            return
        nxt = self.signals.next_event_cycle(self._k)
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
        # the interrupt routine planned no motion: the suspended chain goes on
        if self.queue.next_id == h.next_id and self._main_idle():
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
            self._runs, self._blend = h.runs, h.blend
            self._pending.extend(h.pending)           # empty here (_main_idle)
            self._tracked = list(dict.fromkeys(h.tracked))
            self.actual.set_frames(h.tool_T, h.base_T, inv_pos(h.base_T))
            self._scale = 0.0
            self._scale_rate = 1.0 / max(self._brake_T, self.dt)
            self._ramp_up = True
            # the interrupt level planned from the standstill point; the advance run plans on
            # from where the suspended chain ends (else the next motion would start at the
            # standstill point while the robot stands at the braked motion's end point)
            self.queue.plan_from(h.plan_q)
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
            self.queue.replan(req)

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
            if not self.is_moving() and not self._pending:
                self.queue.plan_from(self._q)
            return
        self._abort(self._runs, self._blend)
        self._pending.clear()
        self._runs = []
        self._blend = None
        self._tracked = []
        self._braking = False
        self._scale, self._scale_rate = 1.0, 0.0
        self._ramp_up = False
        self.queue.plan_from(self._q)

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
    # ================================================================= read-back
    def set_input(self, index: int, value: bool | float, source: str = "operator", analog: bool = False):
        """The operator (or a front end on its behalf, or the cell's PLC: `source`) sets
        ``$IN[index]`` now (robot/io.py ``set_in``: source ``operator`` in the trace; programs
        cannot write inputs), or with `analog` ``$ANIN[index]`` (``set_anin``: -1.0..1.0); the
        cell's rules stay active. Returns the input's value (input 1025 is always TRUE)."""
        self.io.now = self.time
        if analog:
            self.io.set_anin(index, float(value), source)
            return self.io.get_anin(index)
        self.io.set_in(index, bool(value), source)
        return self.io.get_in(index)

    def current_request(self) -> MotionRequest | None:
        """The motion the main run executes now (the newer one during a blend), or None:
        the source of the ``_C`` variables (``$VEL_C``, ``$TOOL_C``, ...) and ``$POS_FOR``."""
        return self._runs[-1].seg.req if self._runs else None

    # ================================================================= trace helpers
    def _motion_event(self, seg: Segment, phase: str, reason: str | None = None,
                      reached: float | None = None) -> None:
        req = seg.req
        self.log.events.append(MotionEvent(self.time, req.id, phase, req))
        tr = self.trace
        if tr is not None:
            if getattr(tr, "takes_motion_points", True):
                limits = seg.limits.as_trace() if phase == "start" else None
                tr.write("motion", self.time, id=req.id, type=req.type_name,
                         target=dict(req.target), approximation=req.approx,
                         phase=phase, point=seg.end_frame, line=req.line, file=req.file,
                         reason=reason, limits=limits, reached=reached)
            else:       # an observer without use for the target, the end point and the limits
                tr.write("motion", self.time, id=req.id, type=req.type_name, approximation=req.approx,
                         phase=phase, line=req.line, file=req.file, reason=reason, reached=reached)
        if self.signals.stimuli:
            self.signals.motion_phase(req.id, req.line, phase, self.time)

    # ================================================================= the IPO cycle
    def step(self) -> list[Event]:
        """Run one IPO cycle (12 ms): I/O timers, pulses and stimuli, the main-run setpoint
        (motion start, approximation, blend, end), triggers, MuJoCo, the pose trace event.

        Returns the events of this cycle, in order.
        """
        log = self.log
        log.events = []
        self._k += 1
        dt = self.dt
        t = self.time = self._k * dt
        self.io.now = t
        if self.network is not None and self.network.polling:
            self.network.cycle(self)
        self._before_motion(t)

        if self._tracked:
            self._conditional_stops()
        # path time (BRAKE ramps scale the path speed)
        s_old = self._scale
        pt_old = self._pt
        if self._ramp_up:
            # release(): this cycle's path-time step is dt · scale, the scale chosen within
            # the axes' accelerations (_ramp_scale)
            self._scale = self._ramp_scale(s_old, min(1.0, s_old + self._scale_rate * dt))
            self._pt += dt * self._scale
            if self._scale >= 1.0:
                self._scale, self._scale_rate = 1.0, 0.0
                self._ramp_up = False
        else:
            if self._scale_rate != 0.0:
                self._scale = min(1.0, max(0.0, self._scale + self._scale_rate * dt))
                if self._scale in (0.0, 1.0):
                    self._scale_rate = 0.0
            self._pt = pt_old + dt * 0.5 * (s_old + self._scale)
        pt = self._pt
        self._pt_step = pt - pt_old
        q_prev = self._q_prev = self._q
        try:
            q = self._main_run(pt)
            if self.correction is not None:
                q = self._corrected(q)
            self._check_speed(q, q_prev)
        except RobotError as err:
            q = self._fault(err)
        if q.__class__ is not np.ndarray or q.dtype is not _F8:
            q = np.asarray(q, dtype=float)
        self._q = q
        if self._braking and self._scale <= 0.0:
            self._hold()
        if self._tracked:
            self._fire_triggers(self._pt)
        qa = self._read_back(q, q_prev)
        actual, mon = self.actual, self.monitor
        if mon.collision is not None and (self._runs or self._blend is not None):
            req = self._runs[0].seg.req if self._runs else None
            err = mon.collision_error(self._q, (actual.base_T @ actual.tcp)[:3, 3], req.line if req is not None else None)
            if err is not None:
                self._fault(err)
        if mon.workspaces is not None:
            changes, stop = mon.workspaces_cycle((actual.base_T @ actual.tcp)[:3, 3], qa)
            for name, value in changes:
                log.io(self.time, name, value, "workspace")
            if stop is not None and (self._runs or self._blend is not None or self._pending):
                self._fault(RobotError(stop))
        if self._cyclic:
            for fn in list(self._cyclic.values()):
                fn(self)
        if self._stimuli and self._runs and self.signals.reach_waits():
            active = [r.seg for r in self._runs]
            if self._blend is not None:
                active.append(self._blend.prev.seg)
            self.signals.reach(active, self._q, self.time)
        if self.act_stream is not None:
            _push_actual(self, t, qa)
        tr = self.trace
        if tr is not None and tr.takes_poses:
            tr.write_pose(t, qa, actual.tcp)
        return log.events

    # ----------------------------------------------------------------- main run
    def _start(self, seg: Segment, pt: float) -> _Run:
        run = _Run(seg, pt)
        self.actual.set_frames(seg.tool_T, seg.base_T, seg.base_inv_T)
        self._motion_event(seg, "start")
        if seg.triggers:
            self._tracked.append(run)
        # expected blend (for DISTANCE=1 triggers with a negative DELAY)
        if seg.req.approx is not None and self._pending and seg.triggers:
            nxt = self._pending[0]
            kw = blending.effective_keyword(seg, nxt)
            ta = blending.blend_start_tau(seg, nxt, kw) if kw else None
            if ta is not None:
                te = blending.blend_window(seg, nxt, kw, ta)
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
                self.log.message(MSG_APPROX_IMPOSSIBLE, seg.id)
        T = seg.T
        if tau >= T - EPS:
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
            end = T - EPS
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
        b = _Blend(r, nr, pt, pt + tau_e, bp.space or blending.blend_space(r.seg, nseg), kw)
        self._runs = [nr]
        self._blend = b
        if tau_e <= EPS:
            self._end_blend(b)
            return nr.seg.axes(pt - nr.t0)
        return self._blend_setpoint(b, pt)

    def _end_blend(self, b: _Blend) -> None:
        self._blend = None
        self._motion_event(b.prev.seg, "blend_end")
        self._motion_event(b.prev.seg, "end")
        b.nxt.seg._last_q = self._q.copy()

    def _blend_setpoint(self, b: _Blend, pt: float) -> np.ndarray:
        """The blend's setpoint at path time `pt` (robot/blending.py ``blend_setpoint``)."""
        return blending.blend_setpoint(b.prev.seg, min(pt - b.prev.t0, b.prev.seg.T), b.nxt.seg, pt - b.nxt.t0,
                                       b.space, self.model, self._q)

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
            actual = self.actual
            T = self.model.tcp(out[:n], actual.tool_T, actual.base_inv_T)
            C = frame_to_matrix(*cart)
            frame = getattr(corr, "frame", "BASE")      # RSI's POSCORR RefCorrSys (net/rsi.py)
            if frame == "WORLD":                        # a correction in $WORLD, seen from $BASE
                Rb = actual.base_T[:3, :3]
                C[:3, 3] = Rb.T @ C[:3, 3]
                C[:3, :3] = Rb.T @ C[:3, :3] @ Rb
            if frame == "TOOL":                         # in the programmed TCP's own frame
                target = T @ C
            else:
                target = T.copy()
                target[:3, 3] = T[:3, 3] + C[:3, 3]
                target[:3, :3] = C[:3, :3] @ T[:3, :3]
            out[:n] = self.model.ik(target, np.linalg.inv(actual.tool_T), actual.base_T, None, None, out[:n])
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
            self.queue.plan_from(self._q)

    def stop_with(self, text: str, number: int | None = None) -> None:
        """Stop the robot now with the message `text` (a sensor's error, as KSS stops on
        RSI's): the main run is aborted and the program gets the error at its next step."""
        q = self._fault(RobotError(text, number))
        self._q = q
        self.correction = None

    def _fault(self, err: RobotError) -> np.ndarray:
        self._end_now()
        mid = self._runs[0].seg.id if self._runs else None
        self.last_error = err
        self.log.events.append(ErrorEvent(self.time, err, mid))
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
        self.queue.plan_from(q)
        return q

    def _hold(self) -> None:
        """BRAKE finished: suspend the main run (interrupt level starts empty)."""
        self._braking = False
        actual = self.actual
        self._held = _Held(self._runs, self._blend, deque(self._pending), self._tracked, self._pt,
                           self._q.copy(), actual.tool_T, actual.base_T, self.queue.planned_axes(),
                           self.queue.next_id)
        self._ret_q = self._q.copy()
        self._runs, self._blend, self._tracked = [], None, []
        self._pending.clear()
        self._scale, self._scale_rate = 1.0, 0.0
        self._ramp_up = False
        self.queue.plan_from(self._q)

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
                self.log.events.append(ev)
                if self.trace is not None:
                    self.trace.write("trigger", self.time, id=run.seg.id, index=tp.index,
                                     line=tp.trigger.line)
            if run.pending_triggers:
                still.append(run)
        self._tracked = still


def _init_main_run(self: "Controller", q: np.ndarray) -> None:
    """The main run's state of the Controller being built (its __init__ only; not a method: the class
    keeps below 40, tests/robot/test_controller.py) at the start axes q: time 0, no motion, brake or
    blend."""
    self._k = 0
    #: simulated time in s (IPO cycles · the IPO cycle): ``_k * dt``, kept with ``_k`` (the
    #: interpreters read it before every statement)
    self.time = self._k * self.dt
    self.io.now = self.time          # the I/O image's clock (robot/io.py): the controller's
    self._pt = 0.0
    self._pt_step = self.dt       # the path time the last cycle advanced (s)
    self._scale = 1.0
    self._scale_rate = 0.0
    self._braking = False
    self._brake_T = 0.0
    self._stop_T = 0.0               # a conditional stop's braking ramp (s), for the ramp up
    self._ramp_up = False      # release(): the path speed ramps up within a_max
    self._held: _Held | None = None
    self._q = q.copy()
    self._q_prev = q.copy()
    self._runs: list[_Run] = []
    self._ending: _Ending | None = None   # an exact stop between its end point and done
    self._blend: _Blend | None = None
    self._tracked: list[_Run] = []  # runs with unfired triggers
    self.last_error: RobotError | None = None
    self._ret_q: np.ndarray | None = None
    # a sensor correction superposed on the setpoint (RSI, net/rsi.py): an object with
    # `axes` (A1..A6 deg) and `cart` (X, Y, Z mm, A, B, C deg in $BASE, or in `frame`:
    # "TOOL", "WORLD" when it has one); None: none
    self.correction = None
    self._q_raw = self._q.copy()


def _init_monitor(self: "Controller", geometry: Any, workspaces: Any) -> None:
    """The checks of each cycle of the Controller being built (its __init__ only, as
    :func:`_init_main_run`): the cell's `geometry`, the `workspaces` monitor, and what step()
    calls every IPO cycle."""
    collision = None
    if geometry is not None:
        # deferred: tools/startup_bench.py, krl run +4 ms at the top (2026-11-26)
        from .collision import CollisionChecker  # noqa: PLC0415

        collision = CollisionChecker(self.machine, geometry)
    #: the checks of each cycle: axis speed, the robot against its cell (None without a cell
    #: file's geometry), KUKA's workspace monitoring (None while no workspace can be active;
    #: interp/runtime/sysvars.py makes it) (robot/monitor.py)
    self.monitor = Monitor(self.model, self.dt, collision, workspaces)
    # what step() calls or reads every IPO cycle, cached (the components keep these objects for
    # the controller's life: the hook table and the stimulus list change only in place)
    self._before_motion = self.signals.before_motion
    self._check_speed = self.monitor.check_speed
    self._read_back = self.actual.cycle
    self._cyclic = self.signals.cyclic
    self._stimuli = self.signals.stimuli



def holds(ctl: "Controller") -> list[str]:
    """What holds the robot on its path now, in words (issue 85 item 9: a run that ends with
    the robot still at a motion says why): a conditional stop met (``STOP WHEN PATH`` of
    the motion at FILE:LINE, its condition still TRUE: :meth:`Controller._conditional_stops`) and the
    motions a finished BRAKE suspended (until RESUME or the interrupt routine's end);
    [] when nothing does."""
    out = []
    for run in ctl._tracked:
        for tp in run.seg.triggers:
            st = tp.trigger
            if isinstance(st, CondStop) and run.stops.get(tp.index) in ("stopped", "braking"):
                req = run.seg.req
                out.append(f"STOP WHEN PATH (line {st.line}) of the {req.type_name} at {req.file}:{req.line}: "
                           f"its condition is still TRUE, the robot stands at its stop point")
    if ctl._held is not None:
        out.append("a BRAKE of an interrupt routine: the motions stay suspended until RESUME or the "
                   "routine's end")
    return out

__all__ = ["Controller", "holds", "MotionEvent", "TriggerEvent", "IoEvent", "MessageEvent",
           "ErrorEvent", "Event", "MSG_APPROX_IMPOSSIBLE"]
