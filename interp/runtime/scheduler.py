"""Simulated time and the cooperative tasks (reference §6.10, §9; docs/architecture.md
"Interpreters").

No threads. The :class:`Scheduler` owns simulated time: the robot controller's 12 ms IPO
clock. The robot program and every submit program run as :class:`Task` objects, each in
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
   next event (interp/runtime/idle.py);
4. runs one ``controller.step()`` and hands its events to the robot task: TRIGGER actions
   and main-run errors are picked up when the robot task resumes (its first act after a
   switch is :meth:`core.Runtime.service`: triggers, then interrupt conditions).
"""

from __future__ import annotations

from greenlet import GreenletExit, greenlet

from .contexts import Context, InterruptTable

ROBOT_BUDGET = 1000
SUBMIT_BUDGET = 100


class Task:
    """One interpreter: ``kind`` 'robot' or 'submit'."""

    def __init__(self, kind: str, name: str, body, budget: int | None = None) -> None:
        self.kind = kind
        self.name = name
        self.body = body
        self.budget = budget if budget is not None else (ROBOT_BUDGET if kind == "robot" else SUBMIT_BUDGET)
        self.slice_end = 0              # value of Runtime.steps that ends this IPO cycle's time slice
        self.quiet = 0                  # quiet-step limit (Runtime.quiet_limit)
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


class Scheduler:
    def __init__(self, rt, max_sim_time: float | None = None, max_steps: int | None = None) -> None:
        self.rt = rt
        self.max_sim_time = max_sim_time
        self.max_steps = max_steps
        self.tasks: list[Task] = []
        self.stop: tuple | None = None      # (reason, text, task)
        self.main = greenlet.getcurrent()
        from .idle import IdleWatch  # noqa: PLC0415

        self.idle = IdleWatch(rt)           # fast-forward of idle cycles (interp/runtime/idle.py)
        from .spin import SpinWatch  # noqa: PLC0415

        self.spin = SpinWatch(rt)           # parked spins (interp/runtime/spin.py)
        self.return_to = None               # a catch-up's caller (SpinWatch.wake); else main

    def add(self, task: Task) -> None:
        task.glet = greenlet(lambda: self.rt.task_main(task), parent=self.main)
        self.tasks.append(task)

    def yield_cycle(self) -> None:
        """Called inside a task: give the IPO cycle back to the scheduler (or to whoever made a
        parked task catch up: interp/runtime/spin.py)."""
        (self.return_to or self.main).switch()

    def _resume(self, task: Task) -> None:
        self.rt.current_task = task
        task.slice_end = self.rt.steps + task.budget
        task.quiet = 0
        self.rt.state_epoch += 1        # the IPO cycle moved the robot, another task ran
        log = self.rt.controller.io.log
        before = len(log)
        try:
            task.glet.switch()
        finally:
            self.rt.current_task = None
            if task.kind == "robot":
                self.idle.robot_io += len(log) - before     # the robot program's own I/O changes

    def run(self) -> None:
        rt = self.rt
        ctl = rt.controller
        robot = self.tasks[0]
        spin = self.spin
        while True:
            for task in list(self.tasks):
                if not task.done and self.stop is None:
                    if spin.resuming(task):
                        continue            # parked: this cycle counted, not run
                    self._resume(task)
                    if task.done and task is not robot:
                        rt.submit_finished(task)
            if spin.shadowed:
                spin.check_shadows()
            if robot.done or self.stop is not None:
                break
            if self.max_sim_time is not None and ctl.time >= self.max_sim_time - 1e-9:
                self.stop = ("max_sim_time", f"simulated time limit {self.max_sim_time} s reached", robot)
                break
            if robot.waiting and self.deadlocked():
                auto = self.idle.auto
                if auto is None or (not auto.pending() and auto.answer(self.idle) != "answered"):
                    self.stop = ("deadlock", f"deadlocked {robot.waiting}", robot)
                    break
            self.idle.cycle()
            if spin.parked or spin.shadowed:
                spin.before_step()
            events = ctl.step()
            for ev in events:
                k = ev.kind
                if k == "trigger":
                    robot.pending_triggers.append(ev)
                elif k == "error":
                    robot.pending_error = ev.error
        # tasks still suspended stay so until close()

    def close(self) -> None:
        """End the tasks still suspended (the run stopped: a limit, an error, HALT, the
        robot program's end): each unwinds now, with GreenletExit, in the run that owns
        it. Left to the garbage collector, a suspended task would unwind at any later
        moment, inside unrelated code (a signal handler's exception could be raised in
        it and lost)."""
        for task in self.tasks:
            g = task.glet
            if g is not None and g and not g.dead:
                self.rt.current_task = task
                try:
                    g.throw(GreenletExit)
                finally:
                    self.rt.current_task = None

    def deadlocked(self) -> bool:
        rt = self.rt
        ctl = rt.controller
        if not ctl.is_idle() or ctl.is_suspended():
            return False
        if any(not t.done for t in self.tasks[1:]):
            return False
        if ctl.io_may_change():   # a stimulus, a PULSE, a cyclic hook or a running timer
            return False
        robot = self.tasks[0]
        if robot.irqs.armed or robot.pending_triggers:
            return False
        return True
