"""The fast-forward of one run as one part (issue 87 item 3; docs/architecture.md "The
fast-forward: one part"): :class:`FastForward` builds the idle watch (idle.py) and the spin watch
(spin.py) with the run's parts they read, and holds the entries the runtime, the scheduler and its
clock jump (jump.py) call, nothing of the watches' insides (tests/interp/test_fastforward_entry.py).
"""

from __future__ import annotations

from .idle import IdleWatch
from .period import Period
from .spin import SpinWatch


class FastForward:
    """The fast-forward of one run (module docstring). ``on``: a recording, a parked task, a
    catch-up or a shadow is under way: while False no statement is reported to ``statement(task,
    info, tick)`` (`tick`: a loop iteration); ``park(task)``: `task` stands at a recorded spin."""

    __slots__ = ("spin", "idle", "on", "statement", "park", "waiting", "proceeding", "ending", "resuming",
                 "before_step", "quiet_steps", "statements", "interrupt_due", "count", "moved", "skip", "idle_span",
                 "jumped")

    def __init__(self, spec, controller, clock, tracing, stepping, program, names, sysvars, kss, messages,
                 robot, yield_cycle, step_limit_left) -> None:
        """For the run `spec` (RunSpec ``fast_forward``, ``spins``) on `controller`, with the run's
        parts its watches read (`robot()`, `yield_cycle(task)`, `step_limit_left(task)`: the runtime's)."""
        self.on = False
        spin = self.spin = SpinWatch(spec, controller, clock, tracing, stepping, program, names, sysvars, kss,
                                     messages, yield_cycle, step_limit_left, self)
        idle = self.idle = IdleWatch(spec, controller, tracing, stepping, program, sysvars, messages, robot)
        self.statement, self.park, self.quiet_steps, self.statements = spin.event, spin.park, spin.quiet_steps, \
            spin.statements     # (quiet_steps: its terms of core.py quiet_limit; statements: passes.py StatementIndex)
        # a wait; a task goes on (after a wait, a TRIGGER, an interrupt); a task ends: spins catch up
        self.waiting, self.proceeding, self.ending = spin.waiting, spin.proceeding, spin.ending
        # the scheduler's: a turn (True: counted, not run), the step to come, a resume's interrupt
        # poll, a parked task's steps counted at once; the idle watch's cycles moved, skipped, jumped
        self.resuming, self.before_step, self.interrupt_due = spin.resuming, spin.before_step, spin._interrupt_due
        self.count = spin.count
        self.moved, self.skip, self.idle_span, self.jumped = idle.moved, idle.skip, idle.span, idle.jumped

    def attach(self, scheduler, cyclic, cyclic_watch, calls, auto) -> None:
        """The run's parts built after it: the `scheduler`, `cyclic` (cyclic.py), `cyclic_watch`
        (watch.py), `calls` (calls.py) and the automatic cell `auto` (None without ``--inputs auto``)."""
        self.idle.auto = auto
        self.spin.attach(self.idle, scheduler, cyclic, cyclic_watch)
        self.idle.attach(scheduler, self, cyclic_watch, calls)

    # ------------------------------------------------------------------ the runtime's entries
    def outside_change(self) -> None:
        """Something outside the tasks (a debugger, a network partner) changed the run's
        variables: every parked task catches up, the idle window starts again."""
        self.spin.outside_change()
        self.idle.outside_change()

    def clock_read(self, task, n: int = 1) -> None:
        """`task` read the clock ($DATE, a running $TIMER) or drew a random number, `n` times: the
        run is not idle, and a recording of `task` reads the clock."""
        self.idle.clock += n
        if self.on:
            self.spin.clock_read(task, n)

    @property
    def shifted(self) -> int:
        """IPO cycles the idle watch's periodic jumps moved every task's WAIT SEC by so far."""
        return self.idle.shifted

    # ------------------------------------------------------------------ the scheduler's entries
    def hold(self) -> None:
        """The run is a robot of a cell of several: the idle watch offers its skips (Scheduler.hold)."""
        self.idle.held = True

    def turns_done(self) -> None:
        """Every task had its turn in this IPO cycle: the shadowed spins are checked (spin.py)."""
        if self.spin.shadowed:
            self.spin.check_shadows()

    def answers(self) -> bool:
        """The robot program deadlocked: True when the automatic cell has an answer pending or
        gives one now (autocell.py), so the run goes on."""
        auto = self.idle.auto
        return auto is not None and (auto.pending() or auto.answer(self.idle) == "answered")

    def run_idle(self) -> bool:
        """The idle watch found the run idle: nothing changed for a whole window (idle.py)."""
        return self.idle.since is not None

    def will_answer(self, robot) -> bool:
        """The automatic cell (autocell.py), if any, would answer the WAIT FOR the robot program
        `robot` (a Task) waits in now (its ``would_answer``)."""
        auto = self.idle.auto
        return auto is not None and auto.would_answer(robot)

    def cycle_ends(self, still: bool) -> int:
        """The idle watch's end of an IPO cycle (idle.py ``IdleWatch.cycle``; `still`: a still
        steady cycle); held, the cycles it would skip before this one's step (0: none), offered."""
        idle = self.idle
        idle.cycle(still)
        n, idle.offer = idle.offer, 0
        return n

    def executed(self) -> int:
        """The steps the tasks executed so far (RunClock.steps less the parked ones counted)."""
        return self.spin.clock.steps - self.spin.skipped

    def idle_counts(self) -> bool:
        """The idle watch only counts a still cycle: the run is not idle, no automatic cell's
        window is watched."""
        idle = self.idle
        return idle.since is None and (idle.auto is None or idle.auto.recording is None)

    def calm(self) -> bool:
        """Steady cycles may start (scheduler.py): parking allowed, no recording or shadow, the
        idle watch only counting a quiet run."""
        spin = self.spin
        return spin.allowed() and not spin.shadowed and spin.rec is None and self.idle_counts() and \
            self.idle._quiet()

    def limit_near(self, task) -> bool:
        """Parked `task` is woken for the step limit (spin.py ``limit_near``)."""
        return self.spin.limit_near(task, task.parked.spin)

    def _counted(self, s) -> bool:
        """Parked pass or period `s` may be counted in cycles no task runs in: it reads neither
        the robot's motion nor a running timer nor a cyclic flag that does not settle."""
        return not (s.motion or s.reads is not None or self.spin.reads_restless_flag(s))

    def steady_parked(self, task) -> bool:
        """Parked `task` is counted in steady cycles (scheduler.py): besides :meth:`_counted`, no
        period that changes the state at its cycles, no transients."""
        s = task.parked.spin
        return self._counted(s) and not (s.periodic and not s.still) and s.trans is None

    def may_jump(self, steady: int) -> "bool | None":
        """None: no clock jump (a recording, catch-up or shadow, a period parked, a task neither
        parked nor, in a still steady cycle, waiting, the automatic cell recording a running task);
        else whether a parked pass has transients (transient.py: the state changes at its steps)."""
        spin = self.spin
        if spin.rec is not None or spin.shadowed or spin.replaying:
            return None
        tasks = [t for t in spin.scheduler.tasks if not t.done]
        auto = self.idle.auto
        if any(t.parked.spin.__class__ is Period if t.parked is not None else steady != 2 for t in tasks) or \
                (auto is not None and auto.recording is not None and any(t.parked is None for t in tasks)):
            return None
        return any(t.parked is not None and t.parked.spin.trans is not None for t in tasks)

    def parked_span(self, task, stands) -> int:
        """Cycles for which parked `task` stays parked and only counts (spin.py ``_hold``): nothing
        it reads changed, its armed interrupts' conditions each `stands(irq)` and none due, the
        step limit not near."""
        spin, p = self.spin, task.parked
        s = p.spin
        if not self._counted(s) or not spin.parked_ok(task) or (s.io and spin.ctl.io.version != p.io_version) \
                or (s.probes and spin._probed(s) != p.probed):
            return 0
        auto = self.idle.auto
        if auto is not None and auto.recording is not None and (p.fed[0] is not auto.recording or p.fed[1] < s.steps):
            return 0        # the automatic cell's recording has not every step of the pass yet (SpinWatch._feed)
        if task.irqs.armed and (not all(stands(i) for i in task.irqs.irqs.values() if i.on)
                                or spin._interrupt_due(task)):
            return 0
        b = task.budget
        left = spin.step_limit_left(task) - 2 * (b + s.steps)
        return 1 + left // b if left >= 0 else 0
