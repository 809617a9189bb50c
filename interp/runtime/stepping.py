"""The program run mode and the debugger's hooks of a run: :class:`Stepping` (``Runtime.stepping``).

It holds now: ``run_mode``, the robot interpreter's ``$PRO_MODE`` by name (GO, MSTEP, ISTEP,
BSTEP: interp/runtime/runmode.py; KSS 8.3 SI, program run modes); ``history``, the executed
motions (runmode.py ``MotionHistory``) that #BSTEP retraces; and the hooks a debugger sets
(docs/architecture.md "Debugger"; interp/debug/engine.py, the pendant): ``stmt_hook(task, info)``
before every statement, ``step_hook(task, mode, text)`` at a step stop, ``error_hook(task,
frame, err)`` where a run-time error leaves a routine, ``cycle_hook(task)`` when a waiting task
resumes; None: no hook. A step stop is a ``step_stop`` trace event (robot/trace.py) where the
debugger stops and ``krl run`` goes on at once. Errors raised: ValueError (a run mode that is
not one of KRL's), KrlRuntimeError (a backward motion the controller refuses).
"""

from __future__ import annotations

from robot.errors import RobotError

from .errors import KrlRuntimeError
from .motion import frame_of
from .runmode import BackwardRefused, MotionHistory, mode_name
from .scheduler import Task, break_quiet
from .values import EnumValue


class Stepping:
    """The run mode, step stops, backward motion and debugger hooks of one run (module
    docstring)."""

    __slots__ = ("controller", "sysvars", "clock", "tracing", "message", "wait_main_run",
                 "run_mode", "history", "stmt_hook", "step_hook", "error_hook", "cycle_hook", "watching")

    def __init__(self, controller, sysvars, clock, tracing, message, wait_main_run) -> None:
        """For the run of `controller` (robot/controller.py: its time, operating mode and motion
        queue), `sysvars` (sysvars.SysVars: ``$PRO_MODE``, ``$TOOL``, ``$BASE``), `clock`
        (scheduler.py RunClock: the running task), `tracing` (tracing.py: the ``step_stop``
        events), `message(text)` (a controller message) and `wait_main_run(task)` (core.py
        Runtime.wait_main_run: the advance-run stop)."""
        self.controller = controller
        self.sysvars = sysvars
        self.clock = clock
        self.tracing = tracing
        self.message = message
        self.wait_main_run = wait_main_run
        self.run_mode = "GO"            # $PRO_MODE of the robot interpreter
        self.history = MotionHistory()  # executed motions, for backward motion
        self.stmt_hook = None           # debugger: stmt_hook(task, info) before every statement
        self.step_hook = None           # debugger: step_hook(task, mode, text) at a step stop
        self.error_hook = None          # debugger: error_hook(task, frame, err) where an error leaves a routine
        self.cycle_hook = None          # debugger: cycle_hook(task) when a waiting task resumes (pause in a WAIT)
        #: a debugger watches the run between statements or IPO cycles (a statement, step or cycle
        #: hook is set): nothing that skips statements or cycles may run (interp/runtime/spin.py,
        #: idle.py, watch.py; read at every IPO cycle, so a flag, not a test of the three)
        self.watching = False

    def set_hooks(self, *, stmt=None, step=None, error=None, cycle=None) -> None:
        """A debugger's hooks (docs/architecture.md "Debugger"): `stmt(task, info)` before every
        statement, `step(task, mode, text)` at a run mode's stop, `error(task, frame, err)` where
        a run-time error leaves a routine, `cycle(task)` when a waiting task resumes; None: none."""
        self.stmt_hook, self.step_hook, self.error_hook, self.cycle_hook = stmt, step, error, cycle
        self.watching = stmt is not None or step is not None or cycle is not None

    def set_run_mode(self, mode) -> None:
        """``$PRO_MODE`` of the robot interpreter (``#GO``, ``#MSTEP``, ``#ISTEP``,
        ``#BSTEP``; interp/runtime/runmode.py). ValueError for another mode."""
        name = mode_name(mode)
        self.sysvars.store["$PRO_MODE"] = EnumValue(name)
        self.run_mode_changed()

    def run_mode_changed(self) -> None:
        """``$PRO_MODE`` was written: the new mode applies from the next statement."""
        v = self.sysvars.store.get("$PRO_MODE")
        try:
            self.run_mode = mode_name(v)
        except ValueError:
            self.run_mode = "GO"
            self.message(f"run mode {getattr(v, 'name', v)} is not simulated: #GO")
        if self.clock.current_task is not None:
            break_quiet(self.clock.current_task)

    def step_stop(self, task: Task, mode: str, motion: int | None = None, text: str | None = None,
                  at: tuple | None = None) -> None:
        """A step stop (the operator presses Start again): a ``step_stop`` trace event; the
        debugger's ``step_hook`` stops there, ``krl run`` goes on at once."""
        trace = self.tracing.writer
        if trace is not None:
            file, line = at if at is not None else (task.file, task.line)
            trace.write("step_stop", self.controller.time, mode=mode, file=file, line=line,
                                id=motion, text=text)
        if self.step_hook is not None:
            self.step_hook(task, mode, text)

    def backward_step(self, task: Task) -> bool:
        """One backward motion (#BSTEP): the newest executed motion not yet retraced, back
        to its start point, as exact positioning with its own speed, frames and the
        operating mode's limits; no statement runs. False (and a ``step_stop`` event whose
        text is the reason) when it is refused (interp/runtime/runmode.py)."""
        store = self.sysvars.store
        try:
            req, rec = self.history.next_backward(self.controller.mode_op, frame_of(store["$TOOL"]),
                                                  frame_of(store["$BASE"]))
        except BackwardRefused as r:
            self.message(r.reason)
            self.step_stop(task, "BSTEP", text=r.reason)
            return False
        ctl = self.controller
        self.wait_main_run(task)
        try:
            mid = ctl.queue.enqueue(req)
        except RobotError as e:
            raise KrlRuntimeError(e.message, e.number) from None
        break_quiet(task)
        self.wait_main_run(task)
        self.step_stop(task, "BSTEP", motion=mid, at=(rec.file, rec.line))
        return True

    def retrace(self, task: Task) -> None:
        """#BSTEP at the end of the program: backward motions until one is refused."""
        while self.backward_step(task):
            pass
