"""Interrupts of a run (reference §5.17): :class:`Interrupts` (``Runtime.interrupts``), for both
interpreters: INTERRUPT DECL and its switches, the poll of a task's armed interrupts and their
routines, BRAKE, RESUME, and a TRIGGER's action run when its switching point is reached.

It holds nothing of its own now: each task's interrupts are its ``Task.irqs``
(interp/runtime/contexts.py ``InterruptTable``: declarations, states, watch keys), the running
routine's context its ``Task.contexts``. A poll reads the conditions once per state epoch
(``RunClock.state_epoch``) and I/O version (contexts.py ``InterruptTable.settled``). Errors
raised: KrlRuntimeError (BRAKE outside an interrupt routine or in the submit interpreter,
RESUME outside an interrupt routine), ResumeSignal (RESUME, caught where its routine was
declared: interp/runtime/calls.py).
"""

from __future__ import annotations

from .contexts import Context, Irq
from .convert import trunc_int
from .errors import KrlRuntimeError, ResumeSignal
from .memory import Frame
from .scheduler import Task, break_quiet
from .sysvars import EPOCH_PROBED
from .watch import reader, split_watch, steady


class Interrupts:
    """The interrupts of one run's tasks (module docstring)."""

    __slots__ = ("clock", "controller", "sysvars", "watch", "tracing", "proceed", "yield_cycle")

    def __init__(self, clock, controller, sysvars, watch, tracing, proceed, yield_cycle) -> None:
        """For the run whose counters are `clock` (scheduler.py RunClock: the running task, the
        state epoch), of `controller` (robot/controller.py: I/O, time, BRAKE, the planned
        motions), `sysvars` (sysvars.SysVars: a condition's probes), `watch` (watch.py
        CyclicWatch: what wrote a variable), `tracing` (tracing.py: the ``interrupt`` events);
        `proceed()` (a task goes on: a parked spin catches up first) and `yield_cycle(task)`
        (the rest of the IPO cycle given back) are the runtime's (core.py Runtime._proceed,
        yield_cycle)."""
        self.clock = clock
        self.controller = controller
        self.sysvars = sysvars
        self.watch = watch
        self.tracing = tracing
        self.proceed = proceed
        self.yield_cycle = yield_cycle

    def run_trigger(self, task: Task, ev) -> None:
        """The action of the TRIGGER whose switching point `ev` the main run reached, in a
        context of its own (priority 129 unless the TRIGGER gives one)."""
        self.proceed()
        action = ev.trigger.action
        prio = ev.trigger.prio if ev.trigger.prio and ev.trigger.prio > 0 else 129
        task.contexts.append(Context("trigger", prio=prio))
        at = task.at
        try:
            action()
        finally:
            task.contexts.pop()
            task.at = at            # where the interrupted context stands (:meth:`fire`)

    def declare(self, number, cond_fn, handler_fn, name: str, frame: Frame,
                is_global: bool = False, line: int | None = None, watch: str = "") -> None:
        """INTERRUPT DECL: `watch` is the condition's watch class (interp/runtime/watch.py
        ``watch_of``; "" = evaluated at every poll)."""
        task = self.clock.current_task
        n = trunc_int(number, "interrupt number")
        cls, names = split_watch(watch)
        # a computed variable's getter is its peek, one call less at each poll
        probes = tuple(reader(self.sysvars.lookup(k)) for k in names)
        task.irqs.declare(Irq(n, cond_fn, handler_fn, name, frame, is_global, line, watch=cls,
                              probes=probes, by_epoch=all(k in EPOCH_PROBED for k in names),
                              steady=steady(watch)))
        if not frame.interrupts:
            frame.interrupts = []
        frame.interrupts.append(n)
        break_quiet(task)

    def control(self, action: str, number=None) -> None:
        task = self.clock.current_task
        n = trunc_int(number, "interrupt number") if number is not None else None
        ctl = self.controller
        task.irqs.control(action.upper(), n, ctl.io.version, ctl.time, self.watch.written())
        break_quiet(task)
        if action.upper() in ("ENABLE", "ON") and task.irqs.armed:
            self.check(task)

    def check(self, task: Task) -> None:
        """Poll ``task``'s armed interrupts and run those ready, by priority. Nothing to do
        while the last poll left them settled in this state epoch (contexts.py
        ``InterruptTable.settled``): a poll would evaluate and fire nothing."""
        if task.in_poll or task.irqs.settled == self.clock.state_epoch:
            return
        task.in_poll = True
        ctl = self.controller
        try:
            ready = task.irqs.poll(ctl.io.version, ctl.time, self.clock.state_epoch, self.watch.written())
        finally:
            task.in_poll = False
        if not ready:
            return          # nothing pending and enabled: next_ready would find nothing
        while True:
            irq = task.irqs.next_ready(task.context.prio)
            if irq is None:
                return
            irq.pending = False
            self.fire(task, irq)

    def fire(self, task: Task, irq: Irq) -> None:
        self.proceed()
        ctl = self.controller
        ctx = Context("interrupt", prio=irq.number, number=irq.number)
        if task.kind == "robot":
            ctx.pos_int = ctl.actual.pos_act()
            ctx.axis_int = ctl.actual.axis_act()
        ctx.frame = irq.frame
        ctx.interrupted = task.frame
        task.contexts.append(ctx)
        trace = self.tracing.writer
        if trace is not None:
            trace.write("interrupt", ctl.time, prio=irq.number, name=irq.name, line=task.line,
                        phase="entry")
        ok = False
        at = task.at
        try:
            irq.handler()
            ok = True
        finally:
            task.contexts.pop()
            trace = self.tracing.writer
            if trace is not None:
                trace.write("interrupt", ctl.time, prio=irq.number, name=irq.name,
                            line=task.line, phase="exit")
            # the task stands again at the statement the routine interrupted (a WAIT FOR, the
            # advance-run stop of one): its file and line are that statement's, not the
            # routine's last one, for what it waits on (the automatic cell's starving WAIT FOR,
            # the run summary) and for an error the statement raises next (issue 72)
            task.at = at
        if ok and task.irqs.armed and not task.in_poll:
            # the conditions are monitored while the handler runs: what it leaves (a timer it
            # restarted, a flag it reset) is sampled at its end, so the next rising edge counts
            # (ROS-Industrial's EKI state timer: `$TIMER[1] = -10` in its own handler)
            task.in_poll = True
            try:
                task.irqs.poll(ctl.io.version, ctl.time, self.clock.state_epoch, self.watch.written())
            finally:
                task.in_poll = False
        if ok and task.kind == "robot":
            ctl.release()
            self.clock.bump_epoch()       # $PRO_MOVE: the motion suspended by BRAKE runs again

    def brake(self, fast: bool = False) -> None:
        """BRAKE / BRAKE F: ramp the path speed down and wait until the robot stands (5.17).
        Only in an interrupt routine (a routine run by an interrupt, at any depth below it):
        elsewhere it is the run-time error "BRAKE outside an interrupt routine" at its line.

        Standstill is confirmed one IPO cycle after the path speed has reached zero (the
        controller sees two equal setpoints), so even `DO BRAKE`, whose interrupt ends with
        the brake, leaves the robot at rest for at least one cycle before it goes on.
        """
        task = self.clock.current_task
        if task.kind != "robot":
            raise KrlRuntimeError("BRAKE is not allowed in the submit interpreter")
        if not any(c.kind == "interrupt" for c in task.contexts):
            # reference §5.17 and §8.2: BRAKE only in interrupt routines; the checker cannot
            # tell a routine that only ever runs as an interrupt routine, so the run says it
            raise KrlRuntimeError("BRAKE outside an interrupt routine: BRAKE is allowed only in "
                                  "interrupt routines (reference 5.17)")
        ctl = self.controller
        ctl.brake(fast)
        self.clock.bump_epoch()           # $PRO_MOVE, $VEL_ACT
        while ctl.is_braking():
            self.yield_cycle(task)
        self.yield_cycle(task)
        self.proceed()

    def resume(self) -> None:
        """RESUME: discard the planned motions and unwind to the declaring routine."""
        task = self.clock.current_task
        ctx = None
        for c in reversed(task.contexts):
            if c.kind == "interrupt":
                ctx = c
                break
        if ctx is None:
            raise KrlRuntimeError("RESUME outside an interrupt routine")
        if task.kind == "robot":
            self.controller.cancel_pending()
            self.clock.bump_epoch()       # $PRO_MOVE
        raise ResumeSignal(ctx.frame)
