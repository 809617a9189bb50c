"""Simulated time and the cooperative tasks (reference §6.10, §9; docs/architecture.md
"Interpreters").

No threads. The :class:`Scheduler` owns simulated time: the robot controller's 12 ms IPO
clock, and the run's counters (:class:`RunClock`: steps, the step limit's mark, the running
task, the state epoch; the Runtime's ``clock``). The robot program and every submit program run as :class:`Task` objects, each in
its own greenlet. Per IPO cycle the scheduler

1. resumes every live task once (robot first, then the submit tasks in start order); a
   task runs until it must wait — queue full at ``$ADVANCE``, an advance-run stop waiting
   for the main run, ``WAIT SEC``/``WAIT FOR`` not yet satisfied, ``BRAKE`` ramping — or
   until it has used its statement budget for this cycle (:data:`ROBOT_BUDGET` statements
   or loop iterations for the robot program, :data:`SUBMIT_BUDGET` for a submit program),
   so endless loops advance simulated time;
2. checks the end conditions: robot program finished (``completed``), HALT (``halt``),
   error (``error``), ``--max-steps`` (``max_steps``), ``--max-sim-time``
   (``max_sim_time``), deadlock (``deadlock``: the robot program waits in WAIT FOR while
   nothing can change any more — no motion, no stimulus or pulse pending, no running
   timer, no submit program, no armed interrupt);
3. lets the idle watch fast-forward a run in which nothing changes to the cycle before its
   next event (interp/runtime/idle.py), and the spin watch wake a parked task the controller's
   next step may concern (interp/runtime/spin.py);
4. runs one ``controller.step()`` and hands its events to the robot task: TRIGGER actions
   and main-run errors are picked up when the robot task resumes (its first act after a
   switch is :meth:`core.Runtime.service`: triggers, then interrupt conditions).

A task that is parked (a spin: interp/runtime/spin.py) or waits on a test of the controller's
state (``Runtime._wait``: queue space, the main run's end, a WAIT SEC) is not resumed: the cycle
is counted as its own (:meth:`Scheduler._waits`, ``SpinWatch.resuming``).

**Steady cycles.** While the robot moves and every task is parked or waits so, with nothing to
do (no TRIGGER, error or interrupt — each armed interrupt's condition ``steady``: it changes only
with the I/O image, a statement, a cyclic flag or a task's state, interp/runtime/watch.py), the
I/O image, the cyclic flags and the statements executed unchanged since the first such cycle,
the controller's next event not due, the run not idle: then each cycle's tasks, idle watch and
spin watch would only count it. :meth:`Scheduler._steady` knows that from a few tests, and
:meth:`Scheduler._steady_cycle` counts it as they would (the parked tasks' steps and positions,
the state epoch, a waiting task's clock reads, the idle watch's windows: ``IdleWatch.moved``);
the controller steps as always. While the robot stands the same holds for the tasks (issue 48,
session 2), and the rest of the cycle — the deadlock test, the idle watch (whose windows make the
automatic cell's answers; ``IdleWatch.cycle(still=True)`` returns at once while they only
count), the controller's step — runs as in any cycle; the controller's next event is looked up
each such cycle (an answer schedules one). A cycle that fails a test is an ordinary one.

**Clock jumps.** While the robot stands and no task runs — every task parked, or waiting so in a
steady cycle — such cycles follow each other unchanged until the next thing that can change
what a task reads, the idle watch's next look or the time limit: interp/runtime/jump.py counts
them in one step (``jump.span``, ``jump.count``; ``Scheduler.jumps``, from RunSpec ``fast_forward`` and ``clock_jumps``, False: never), the
controller skipping them (``Controller.skip``).
"""

from __future__ import annotations

from greenlet import GreenletExit, greenlet

from .contexts import Context, InterruptTable
from robot.cellrules import rules_may_fire

from . import jump
from .inputwait import wait_on_inputs

#: steps (a statement or a loop iteration) per IPO cycle: the robot interpreter's and the submit
#: interpreter's time slices (docs/architecture.md, "The submit interpreter's pace": KUKA
#: describes a time slice of the 12 ms cycle, the submit interpreter's the lower-priority one, and
#: publishes no statement count; these counts are the simulator's)
ROBOT_BUDGET = 1000
SUBMIT_BUDGET = 100

#: "no step limit" (RunClock.limit_at, Runtime.step_limit_left): an int past any run's steps
NO_LIMIT = 1 << 62


class _Ran:
    """The type of :data:`RAN`."""

    def __repr__(self) -> str:
        return "RAN"


#: what a held run's :meth:`Scheduler.cycles` yields after a cycle that may have changed what a
#: cell reads of the robot between its cycles (its tasks ran, or its main run changed the
#: motions it executes); None after a cycle that only advanced the same motions (a steady one)
RAN = _Ran()


def program_budget(path) -> int | None:
    """The time slice of the program run as the robot task: a submit program (``.sub``) selected
    on its own runs at the submit interpreter's pace (:data:`SUBMIT_BUDGET`), as it does beside a
    robot program; None: the robot interpreter's (:data:`ROBOT_BUDGET`)."""
    return SUBMIT_BUDGET if str(path).lower().endswith(".sub") else None


class Task:
    """One interpreter: ``kind`` 'robot' or 'submit'."""

    def __init__(self, kind: str, name: str, body, budget: int | None = None) -> None:
        self.kind = kind
        self.name = name
        self.body = body
        self.budget = budget if budget is not None else (ROBOT_BUDGET if kind == "robot" else SUBMIT_BUDGET)
        self.steps = 0                  # the steps counted for this task (Runtime.steps_by_task)
        self.limited = False            # the step limit counts its steps (Runtime.add_task)
        self.slice_end = 0              # value of RunClock.steps that ends this IPO cycle's time slice
        self.quiet = 0                  # quiet-step limit (Runtime.quiet_limit)
        self.calm = False               # its advance-run stops are no-ops (Runtime.quiet_limit)
        self.contexts = [Context("main" if kind == "robot" else "submit")]
        self.irqs = InterruptTable()
        self.err = None                 # $ERR of this interpreter (Struct ERROR_T)
        self.continue_line = None       # (file, line) of a CONTINUE
        self.pending_triggers: list = []
        self.pending_error = None
        self.next_triggers: list = []   # TRIGGERs waiting for the next motion
        self.waiting: str | None = None
        self.wake_cycle: int | None = None  # the IPO cycle that ends its WAIT SEC (idle fast-forward)
        self.at = None                  # StmtInfo of the statement that ran last (file, line)
        self.done = False
        self.outcome = None             # (reason, error or None)
        self.in_poll = False
        self.glet: greenlet | None = None
        self.frame = None               # innermost frame (VARSTATE)
        self.err_text = ""
        # the spin watch (interp/runtime/spin.py): its statements take the full hook
        # (``watched``, a recording; ``replay``, a catch-up), the spin it parks at the end of this
        # loop iteration (``park``), the state of a parked task (``parked``)
        self.watched = False
        self.replay = None
        self.park = None
        self.parked = None
        self.shadow = None
        self.until = None               # the test that ends its wait (Runtime._wait), while it waits
        self.clock_reads = 0            # clock reads an evaluation of that wait makes (running timers)
        self.timer_due = None           # with them: the IPO cycle its timers may change its value at (None: none)

    @property
    def file(self) -> str | None:
        """File of the statement that ran last."""
        return self.at.file if self.at is not None else None

    @property
    def line(self) -> int | None:
        """Line of the statement that ran last."""
        return self.at.line if self.at is not None else None

    @property
    def context(self) -> Context:
        return self.contexts[-1]


def moved_axes(q, q0) -> list | None:
    """The axes `q` as a list where they differ from `q0` (``not (q == q0).all()`` for two axis
    vectors of one length, 1-D float arrays), else None: compared as lists, Python's float ``==``
    is numpy's element by element (-0.0 equals 0.0, a NaN nothing), at a fifth of the cost of
    numpy's comparison and reduction of six elements (an IPO cycle's test); the list is kept for
    the steady cycle's ``IdleWatch.moved``."""
    ql = q.tolist()
    return None if ql == q0.tolist() else ql


def break_quiet(task: Task) -> None:
    """The next step of `task` takes the full hook: no quiet steps until the hook sets them
    again (interp/runtime/core.py ``Runtime.quiet_limit``)."""
    task.quiet = 0
    task.calm = False


class RunClock:
    """The counters of one run, in one place (issue 76), owned by its :class:`Scheduler` (the
    Runtime's ``clock``), written only by its own methods (issue 87 item 3: every other part
    reads them and asks for the change it makes: :meth:`count`, :meth:`enter`, :meth:`leave`,
    :meth:`restore`, :meth:`epochs`, :meth:`bump_epoch`; tests/interp/test_clock_writer.py):
    ``steps``, the steps of every task so far (statements and loop
    iterations; Runtime.before_statement, loop_tick and the VM's quiet steps count them);
    ``limit_at``, the value of ``steps`` past which the running task has used its step limit
    (``Scheduler._resume`` sets it from Runtime.step_limit_left; :data:`NO_LIMIT` between
    resumes); ``current_task``, the :class:`Task` running now (None between resumes);
    ``state_epoch``, bumped by everything that may change a probed system variable
    (sysvars.py ``EPOCH_PROBED``: a task resumed after an IPO cycle, RESUME, BRAKE, the end of an
    interrupt routine of the robot task, the operating mode, a task's end): an interrupt's poll
    reads those once per epoch."""

    __slots__ = ("steps", "limit_at", "current_task", "state_epoch")

    def __init__(self) -> None:
        self.steps = 0
        self.limit_at = NO_LIMIT
        self.current_task: Task | None = None
        self.state_epoch = 0

    def count(self, n: int) -> None:
        """`n` steps taken (statements, loop iterations, a parked task's counted time slice)."""
        self.steps += n

    def enter(self, task: "Task | None", limit_at: int) -> tuple:
        """`task` runs now, with the step limit's mark `limit_at` (a value of :attr:`steps`;
        :data:`NO_LIMIT`: none); the counters before, for :meth:`restore`."""
        saved = (self.current_task, self.steps, self.limit_at)
        self.current_task, self.limit_at = task, limit_at
        return saved

    def leave(self) -> None:
        """No task runs (between resumes)."""
        self.current_task, self.limit_at = None, NO_LIMIT

    def restore(self, saved: tuple) -> None:
        """The counters as :meth:`enter` found them (`saved`): the steps of a catch-up or of an
        evaluation from outside are not counted again."""
        self.current_task, self.steps, self.limit_at = saved

    def epochs(self, n: int = 1) -> None:
        """`n` state epochs passed (a task resumed or counted after an IPO cycle) without the
        running task's next step being told (:meth:`bump_epoch`)."""
        self.state_epoch += n

    def bump_epoch(self) -> None:
        """A probed system variable may have changed (:attr:`state_epoch`): the running task's
        next step takes the full hook, whose interrupt poll reads the probes again."""
        self.state_epoch += 1
        if self.current_task is not None:
            break_quiet(self.current_task)


class Scheduler:
    """The IPO cycles and the tasks of one run (module docstring)."""

    def __init__(self, clock: RunClock, controller, ff, cyclic_watch, cyclic, stepping, tracing,
                 task_main, step_limit_left, max_sim_time: float | None = None,
                 max_steps: int | None = None, jumps: bool = True) -> None:
        """For the run whose counters are `clock` (:class:`RunClock`, the scheduler's from now
        on), of `controller` (robot/controller.py: stepped once per IPO cycle), with the run's
        fast-forward `ff` (fastforward.py FastForward: its entries only), `cyclic_watch`
        (watch.py CyclicWatch), `cyclic` (cyclic.py Cyclic: analog outputs written at any step)
        and `stepping` (stepping.py: a debugger's cycle hook), writing a submit program's error to
        `tracing` (tracing.py); `task_main(task)` (a task's greenlet body) and
        `step_limit_left(task)` are the runtime's (core.py Runtime). `max_sim_time` (s) and
        `max_steps` end the run; `jumps` False: no clock jump (jump.py; RunSpec.fast_forward)."""
        self.clock = clock                  # the run's counters (the Runtime's ``clock``)
        self.controller = controller
        self.cyclic_watch = cyclic_watch
        self.cyclic = cyclic
        self.stepping = stepping
        self.task_main = task_main
        self.tracing = tracing
        self.step_limit_left = step_limit_left
        self.max_sim_time = max_sim_time
        self.max_steps = max_steps
        self.tasks: list[Task] = []
        self.stop: tuple | None = None      # (reason, text, task)
        self.main = greenlet.getcurrent()
        self.ff = ff                        # the fast-forward (interp/runtime/fastforward.py)
        self.robot_io = 0                   # I/O changes the robot program made (the idle watch reads them)
        self.jumps = jumps                  # False: no clock jump over cycles that only count (interp/runtime/jump.py)
        self.return_to = None               # a catch-up's caller (SpinWatch.wake); else main
        self._calm = None                   # what steady cycles found first (_steady)
        self._axes = None                   # the robot's axes as _steady listed them, while it moves (deg)
        self.steady = 0                     # steady cycles in the run
        self.jumped = 0                     # cycles counted by clock jumps (interp/runtime/jump.py)
        self.held = False                   # a robot of a cell of several: its deadlock is the cell's to decide
        self.blocked: str | None = None     # held: what the robot program waits for, deadlocked this cycle

    def stop_by(self, seconds: float) -> None:
        """The run ends at the simulated time `seconds` (s) at the latest, as if its time limit
        were that (a test's network partner that finished: tests/net/helpers.py); safe from
        another thread (one attribute written, read once per IPO cycle)."""
        if self.max_sim_time is None or seconds < self.max_sim_time:
            self.max_sim_time = seconds

    def hold(self) -> None:
        """This run is a robot of a cell of several (interp/robotcell.py): its deadlock is the
        cell's to decide, and its clock jumps and idle skips are offered to the cell (:meth:`cycles`)."""
        self.held = True
        self.ff.hold()

    def end_deadlocked(self, text: str) -> None:
        """The cell this held run belongs to deadlocked: the run ends ``deadlock`` with `text` at
        its next cycle."""
        self.stop = ("deadlock", text, self.tasks[0])

    def add(self, task: Task) -> None:
        main = self.task_main
        task.glet = greenlet(lambda: main(task), parent=self.main)
        self.tasks.append(task)

    def yield_cycle(self) -> None:
        """Called inside a task: give the IPO cycle back to the scheduler (or to whoever made a
        parked task catch up: interp/runtime/spin.py)."""
        (self.return_to or self.main).switch()

    def _resume(self, task: Task) -> None:
        clock = self.clock
        steps = clock.steps
        task.slice_end = steps + task.budget
        clock.enter(task, steps + self.step_limit_left(task))
        task.quiet = 0
        clock.epochs()                     # the IPO cycle moved the robot, another task ran
        log = self.controller.io.log
        before = len(log)
        try:
            task.glet.switch()
        finally:
            clock.leave()
            task.steps += clock.steps - steps
            if task.kind == "robot":
                self.robot_io += len(log) - before     # the robot program's own I/O changes

    def _waits(self, task: Task) -> bool:
        """`task` waits (Runtime._wait) and its resume would only find that the wait goes on:
        its test still fails and there is no TRIGGER action, main-run error or interrupt to run
        (the interrupt poll its resume makes is made here: interp/runtime/core.py
        ``Runtime.service``), and no debugger watches the cycle. True: the cycle is counted as
        the task's, and the task is not resumed."""
        if task.pending_triggers or task.pending_error is not None or self.stepping.cycle_hook is not None \
                or task.until():
            return False
        clock = self.clock
        clock.epochs()                     # as _resume: the IPO cycle moved the robot
        if task.irqs.armed and not task.in_poll:
            ctl = self.controller
            if task.irqs.poll(ctl.io.version, ctl.time, clock.state_epoch, self.cyclic_watch.written()):
                return False            # an interrupt to run: resumed, its poll finds it pending
        if task.clock_reads:
            self.ff.clock_read(task, task.clock_reads)     # the condition's reads of running timers
        return True

    def _steady(self) -> int:
        """This cycle is a steady one (module docstring): 1 while the robot moves, 2 while it
        stands (the idle watch then makes its own cycle, :meth:`run`); 0 when it is not."""
        ctl = self.controller
        q, q0 = ctl._q, ctl._q_prev
        ql = None if q is q0 else moved_axes(q, q0)
        moving = ql is not None
        if moving:
            self._axes = ql             # (for the steady cycle's IdleWatch.moved)
        calm = self._calm
        if calm is not None and calm[4] != moving:
            calm = None
        if calm is None:
            calm = self._calm = self._calm_now(moving)
            if calm is None:
                return 0
        io, cyc, executed, nxt, _m = calm
        if not moving:
            # the idle watch's cycle runs in a still one: an answer of the automatic cell may
            # have scheduled an input, a window be watched or the run be idle since
            if not self.ff.idle_counts():
                self._calm = None
                return 0
            nxt = ctl.signals.next_event_cycle(ctl.cycle)
        if ctl.io.version != io or self.cyclic_watch.version != cyc \
                or self.ff.executed() != executed \
                or (nxt is not None and ctl.cycle + 1 >= nxt) \
                or (self.max_sim_time is not None and ctl.time >= self.max_sim_time - 1e-9):
            self._calm = None
            return 0
        for task in self.tasks:
            if task.done:
                continue
            if task.pending_triggers or task.pending_error is not None:
                self._calm = None
                return 0
            if task.parked is not None:
                # (a task the step limit does not count has none near: Runtime.step_limit_left)
                if task.limited and self.ff.limit_near(task):
                    self._calm = None
                    return 0
            elif task.until():
                self._calm = None
                return 0
        return 1 if moving else 2

    def _calm_now(self, moving: bool):
        """The first of a run of steady cycles: the tests that hold for the whole run of them,
        and what the later cycles compare with; None when this is not one."""
        ctl = self.controller
        ff = self.ff
        for task in self.tasks:
            if not task.done and task.parked is None and task.until is None:
                return None         # a task runs (the common case: tested first)
        if not ff.calm():
            return None
        for task in self.tasks:
            if task.done:
                continue
            p = task.parked
            if p is None and (task.until is None or task.replay is not None):
                return None
            if p is not None and not ff.steady_parked(task):
                return None         # (a period's task, a pass's transients change the state at its cycles;
                #                     a pass that reads a running timer reads the clock at them)
            if task.irqs.armed and (not all(i.steady and not i.pending for i in task.irqs.irqs.values() if i.on)
                                    or ff.interrupt_due(task)):
                # (polled as its resume would: the I/O may have changed in the step before this
                # cycle, and a steady run of cycles compares the I/O from now on; a waiting task
                # whose recording used to make the cycle unsteady missed conformance 096's
                # interrupt without this)
                return None
        if any(k[0] == "analog output" for k in self.cyclic.handles):
            return None             # an output written at any step
        return (ctl.io.version, self.cyclic_watch.version, ff.executed(),
                ctl.signals.next_event_cycle(ctl.cycle), moving)

    def _steady_cycle(self, moving: bool = True) -> None:
        """Count a steady cycle as the tasks and the fast-forward would."""
        ff = self.ff
        self.steady += 1
        live = 0
        for task in self.tasks:
            if task.done:
                continue
            live += 1                          # an epoch each, as its resume or its parked or waiting count
            if task.parked is not None:
                ff.count(task, task.budget, moving)
            elif task.clock_reads:
                ff.clock_read(task, task.clock_reads)     # as _waits
        self.clock.epochs(live)                # (no count reads the epoch: one call for them all)
        if moving:
            ff.moved(self._axes)                # the axes _steady listed in this cycle

    def run(self) -> None:
        """Run the tasks to the end of the run (module docstring)."""
        for _ in self.cycles():
            pass

    def cycles(self):
        """:meth:`run`, yielding None after each IPO cycle (a clock jump's cycles: one yield). With
        :attr:`held` (a robot of a cell of several, interp/robotcell.py) a deadlock does not end
        the run: its partners may still set what the robot program waits for, so the cycle's
        :attr:`blocked` says it, and the cell decides; and a clock jump of n cycles (or the idle
        watch's skip: this cycle and the n - 1 before its step) is first yielded as n, the cell
        sending back how many cycles this one advances (0 or 1: an ordinary cycle); a cycle is
        then yielded as :data:`RAN` when a task ran in it or its main run's motions changed,
        else as None (a steady cycle that advanced the same motions: the robot's tasks, their
        waits and the motions its main run executes as after the cycle before;
        interp/cellturns.py takes such cycles without a look)."""
        ctl = self.controller
        robot = self.tasks[0]
        ff = self.ff
        # a held run (a robot of a cell) tells the cycles the cell must look at from the steady
        # ones: RAN after a cycle in which a task ran or the main run's motions changed (the
        # controller replaces its ``_runs`` list, never changes one in place: robot/controller.py)
        held = self.held
        ran = RAN if held else None
        runs = ctl._runs
        self._boot(robot)
        while True:
            steady = self._steady()
            if steady == 1:
                self._steady_cycle()
                for ev in ctl.step():
                    k = ev.kind
                    if k == "trigger":
                        robot.pending_triggers.append(ev)
                    elif k == "error":
                        robot.pending_error = ev.error
                if held and ctl._runs is not runs:
                    runs = ctl._runs
                    yield RAN
                else:
                    yield
                continue
            n = jump.span(self, steady) if self.jumps else 0
            if n and self.held:
                n = yield n                 # a cell's robots jump together: the cell grants 0..n
                n = n if n >= 2 else 0      # (one cycle: an ordinary one)
            if n:
                jump.count(self, n)         # these cycles only count: at once (interp/runtime/jump.py)
                runs = ctl._runs
                yield ran
                continue
            if steady == 2:
                self._steady_cycle(False)   # the robot stands: the rest of the cycle as always
            else:
                for task in list(self.tasks):
                    if not task.done and self.stop is None:
                        self._turn(task, robot)
            ff.turns_done()
            if robot.done or self.stop is not None:
                break
            if self.max_sim_time is not None and ctl.time >= self.max_sim_time - 1e-9:
                self.stop = ("max_sim_time", f"simulated time limit {self.max_sim_time} s reached", robot)
                break
            self.blocked = None
            if robot.waiting and self.deadlocked(steady):
                if not ff.answers():
                    if not self.held:
                        self.stop = ("deadlock", f"deadlocked {robot.waiting}", robot)
                        break
                    self.blocked = robot.waiting
            offer = ff.cycle_ends(steady == 2)
            if offer:                       # held: the idle watch's skip, the cell's to grant
                n = yield offer + 1         # this cycle's step included: skips n - 1 before it
                if n >= 2:
                    ff.skip(n - 1)
            ff.before_step()
            events = ctl.step()
            for ev in events:
                k = ev.kind
                if k == "trigger":
                    robot.pending_triggers.append(ev)
                elif k == "error":
                    robot.pending_error = ev.error
            runs = ctl._runs
            yield ran
        # tasks still suspended stay so until close()

    def _boot(self, robot: Task) -> None:
        """Each submit task's time slice before the robot program's first: on a controller the
        submit interpreter runs from boot (custom.dat), long before the operator starts a
        program, so the robot program's first statement finds the submit program's first
        statements done (OsmanMarangoz's motion_eki.src reads META_VELOCITY_OVERRIDE, which its
        meta_eki.sub sets; docs/architecture.md, "Interpreters"). Its passes are checked before
        the robot runs, as at the end of any cycle (a pass parked with a state the robot program
        then changed would not wake: interp/runtime/spin.py)."""
        for task in self.tasks[1:]:
            if not task.done and self.stop is None:
                self._turn(task, robot)
        self.ff.turns_done()

    def _turn(self, task: Task, robot: Task) -> None:
        """`task`'s turn in a cycle: counted, not run, while parked or while it waits on a test
        of the controller's state; else resumed."""
        if self.ff.resuming(task):
            return                  # parked: this cycle counted, not run (its steps too)
        if task.until is not None and self._waits(task):
            return                  # waits on: its resume would only test that
        self._resume(task)
        if task.done and task is not robot:
            self._submit_finished(task)

    def _submit_finished(self, task: Task) -> None:
        """A submit program ended: its run-time error is an ``error`` event (it does not end the
        run)."""
        reason, err = task.outcome
        trace = self.tracing.writer
        if reason == "error" and err is not None and trace is not None:
            trace.write("error", self.controller.time, text=f"submit {task.name}: {err.message}",
                        number=err.number, line=err.line, file=err.file)

    def close(self) -> None:
        """End the tasks still suspended (the run stopped: a limit, an error, HALT, the
        robot program's end): each unwinds now, with GreenletExit, in the run that owns
        it. Left to the garbage collector, a suspended task would unwind at any later
        moment, inside unrelated code (a signal handler's exception could be raised in
        it and lost)."""
        for task in self.tasks:
            g = task.glet
            if g is not None and g and not g.dead:
                self.clock.enter(task, NO_LIMIT)
                try:
                    g.throw(GreenletExit)
                finally:
                    self.clock.leave()

    def deadlocked(self, steady: int = 0) -> bool:
        """True when the robot program's wait cannot end by anything its own controller does.
        `steady`: this cycle's :meth:`_steady` (2: the robot stands and every task's state is
        unchanged), for a held run in such a cycle or once the run is idle (the idle watch's:
        since 2026-11-30, before which a robot beside its submit program was blocked only until
        its run went idle, a window after it began to wait): see :meth:`_stands_on_inputs`, unless an automatic cell
        (``--inputs auto``) would answer the wait (fastforward.py ``will_answer``): it then
        answers it when it would in a run alone, the idle watch's window after the robot began
        to starve (before 2026-11-30 the cell's deadlock test answered such a wait at once, a
        window early, and the robot's run differed from its run alone and from the cell run with
        a trace, whose steady cycles are off)."""
        ctl = self.controller
        if not ctl.is_idle() or ctl.is_suspended():
            return False
        if self.held and (steady == 2 or self.ff.run_idle()) and self._stands_on_inputs() \
                and not self.ff.will_answer(self.tasks[0]):
            return True
        if any(not t.done for t in self.tasks[1:]):
            return False
        if ctl.signals.may_change():   # a stimulus, a PULSE, a cyclic hook or a running timer
            return False
        robot = self.tasks[0]
        if robot.irqs.armed or robot.pending_triggers:
            return False
        return True

    def _stands_on_inputs(self) -> bool:
        """A held run (a robot of a cell of several) whose robot program waits in a WAIT FOR that
        reads inputs and constants alone (interp/runtime/inputwait.py), in a steady cycle or
        once the run is idle (:meth:`deadlocked`; every task's state unchanged either way), with
        nothing of its own controller due (no stimulus, rule answer or PULSE reset to come): its
        submit program, its armed interrupts and its cyclic flags run on unchanged, and none of
        them can write an input, so only the cell can end the wait. (A run alone keeps the
        stricter test below: the idle watch and the automatic cell build on it.) Steady cycles
        need the spin watch, off while a trace, a debugger or stepping observes the statements:
        then such a robot is not seen blocked (docs/cells.md)."""
        sig = self.controller.signals
        return (wait_on_inputs(self.ff.statements(self.tasks[0].at))
                and sig.next_event_cycle(self.controller.cycle) is None
                and all(st.fired for st in sig.stimuli)
                and not (sig.rules and rules_may_fire(sig.rules, sig.io)))

