"""The runtime of one run: :class:`Runtime`, used by the tree interpreter and the VM alike
(docs/architecture.md, "Runtime API", lists the contracts).

It holds now the run state: the spec, the program model it runs (interp/runtime/model.py
ProgramModel, shared by runs) and its own copy of the model's data memory, system variables,
I/O image, KSS stand-ins and names (model.py ``RunData``), the controller, the tasks, the run
clock (interp/runtime/scheduler.py ``RunClock``, the scheduler's: the steps, the step
limit's mark, the running task, the state epoch), the trace it writes to now (tracing.py
``Tracing``), the message window; its methods are a task's life (start, end, result), the
statement hook (``before_statement``, ``loop_tick``, the VM's quiet steps) and the waits (WAIT
FOR, WAIT SEC, HALT, advance-run stops). The rest of the semantics is in its parts, one class per
module, each built here once, after what it uses, with exactly its collaborators (never the
runtime; what the runtime owns or builds later as a callable: docs/architecture.md "The
runtime's parts"): the scheduler (scheduler.py), routine calls (calls.py ``Calls``), $ERR
(errstate.py), cyclic evaluation (cyclic.py), motion statements (motions.py), interrupts
(interrupts.py), the run mode with the debugger's hooks (stepping.py), the $CMD program states
(cmdchannel.py) and the automatic cell (autocell.py). Also here: a run's result
(:class:`RunResult`) and the cell a run's controller is built for (:class:`CellPlan`).
"""

from __future__ import annotations

import contextlib
import random
import sys
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from krl.ast import nodes as N
from krl.semantics.advance import StmtInfo
from net.hub import NetError, Network
from robot.controller import Controller

from .autocell import AUTO_DELAY_S, AutoCell
from .calls import Calls
from .cmdchannel import ProgramControl
from .contexts import Context, InterruptTable
from .convert import binary_op, num, to_bool, unary_op
from .cyclic import Cyclic
from .errors import HaltSignal, KrlRuntimeError, ProgramSelected, ResumeSignal, StopRun
from .errstate import ErrorState
from .fastforward import FastForward
from .idle import probe_state
from .interrupts import Interrupts
from .memory import ProxyRef, Ref, SignalRef
from .messages import MessageWindow
from .model import ProgramModel
from .natives.context import NativeContext
from .motions import MotionStatements
from .netvars import RuntimeSink
from .scheduler import NO_LIMIT, RunClock, Scheduler, Task, break_quiet, program_budget
from .stepping import Stepping
from .sysvars import RunReads
from .tracing import Tracing
from .undeclared import explain_unknown
from .watch import (CONSTANT, IO, SETTLES, CyclicWatch, reader, split_watch, stamp_key, timer_due, timer_reads,
                    timer_watch, watch_of)


#: s the operator takes to press Start again after a HALT (``krl run --on-halt continue``; a
#: stated figure)
OPERATOR_DELAY_S = 1.0

EXIT_CODES = {"completed": 0, "halt": 3, "deadlock": 3, "max_steps": 3, "max_sim_time": 3,
              "error": 1, "internal": 2}


@dataclass
class RunResult:
    reason: str                 # completed | halt | error | deadlock | max_steps | max_sim_time
    error: KrlRuntimeError | None = None
    file: str | None = None
    line: int | None = None
    context: str | None = None
    text: str = ""
    sim_time: float = 0.0
    steps: int = 0
    #: (file, line) of each frame of the robot program's call stack where it stopped, innermost
    #: first (the run summary says what a wait in a caller waits for: interp/summary.py)
    stack: tuple = ()

    @property
    def exit_code(self) -> int:
        return EXIT_CODES.get(self.reason, 2)


def call_stack(task, limit: int = 64) -> tuple:
    """(file, line) of each frame of `task` (innermost first, at most `limit`): where each
    routine of its call stack stands."""
    out = []
    frame = task.frame
    while frame is not None and len(out) < limit:
        span = getattr(frame.routine, "span", None)
        if span is not None and span.file and frame.line:
            out.append((span.file, frame.line))
        frame = frame.caller
    return tuple(out)


@dataclass
class RunStart:
    """How a run started (shown in the run summary): the operating mode (``mode``: T1, T2,
    AUT, EX) and who chose it (``mode_why``; "" for the default AUT), where the robot stood
    (``where``: an E6AXIS literal or a point name, None for ``$AXIS_HOME[1]``) and why
    (``why``)."""

    mode: str = "AUT"
    mode_why: str = ""
    where: str | None = None
    why: str = ""


@dataclass
class CellPlan:
    """What of a run's controller depends on its program (interp/run.py ``plan_cell``): the
    operating mode, how the run started (:class:`RunStart`), the start axes (KRL's order; None:
    ``$AXIS_HOME[1]``), the cell's stimuli and rules (the run's own, SIGNALs resolved), the
    network partners (net.settings.NetworkSettings or None), the PLC's address map (a
    zero-argument callable: net/plc.py) and the bodies the robot is checked against
    (robot/collision.py CellGeometry or None)."""

    mode_op: str = "AUT"
    start: RunStart = field(default_factory=RunStart)
    start_axes: object = None
    stimuli: list = field(default_factory=list)
    rules: list = field(default_factory=list)
    network: object = None
    plc_map: object = None
    geometry: object = None


class Runtime:
    """Shared runtime of one run, built on its program model (interp/runtime/model.py) for
    the cell its plan describes (:class:`CellPlan`; :meth:`__init__`). ``max_sim_time`` (s) and
    ``max_steps`` (statements + loop iterations of the robot interpreter:
    :meth:`step_limit_left`; docs/architecture.md "The step limit") come from its spec.
    """

    # Every attribute of a run is a slot: the interpreters read them at every statement, and
    # CPython 3.11 keeps an instance's attributes in fast inline storage only up to 30 names
    # (past that every attribute read and method call on the runtime is a dictionary lookup:
    # the tree interpreter ran 5-10 % slower with 32). A new attribute is added here too.
    __slots__ = ("controller", "tracing", "clock", "natives", "messages",
                 "noted", "max_steps", "robot_budget", "sysvars", "memory", "program", "kss",
                 "modules", "scheduler", "robot", "result", "cyclic", "interrupts", "motions", "errstate",
                 "stepping",
                 "autocell", "halt_continues", "start", "halts", "ff", "cyclic_watch",
                 "spec", "machine", "io", "interpreter", "model", "notes", "calls", "names", "programs", "reads")

    def __init__(self, model: ProgramModel, plan, spec, sinks, *, interpreter=None) -> None:
        """The run `spec` (interp/spec.py RunSpec, its robot given) describes, on its own copy
        of the program `model` (interp/runtime/model.py ProgramModel ``data``), for the cell
        `plan(data)` plans from that copy (interp/run.py ``plan_cell``: a :class:`CellPlan`),
        writing to `sinks` (interp/run.py RunSinks), complete: its controller, its tasks run by
        `interpreter(rt)` (the tree interpreter or the VM; None: a test adds its own). Nothing
        sets its attributes afterwards (tests/interp/test_run_spec.py). Raises
        net.hub.NetError when a partner cannot start."""
        self.spec = spec
        self.model = model
        self.machine = model.machine
        self.controller = None
        #: where the interpreters trace now (interp/runtime/tracing.py: None while an
        #: evaluation from outside runs, and after the run)
        self.tracing = Tracing(sinks.trace)
        self.messages = MessageWindow(spec.interactive)  # the message window (interp/runtime/messages.py)
        self.noted: set[str] = set()    # simulator notes given once per run (builtins)
        self.max_steps = spec.max_steps
        # the program's time slice: a .sub selected on its own runs at the submit pace
        self.robot_budget = spec.robot_budget if spec.robot_budget is not None else program_budget(spec.program)
        self.clock = RunClock()     # steps, the step limit's mark, the running task, the state epoch
        reads = self.reads = RunReads(self.clock)     # what its computed system variables read (attach)
        data = model.data(reads, self.message, self.clock, spec)     # the run's own copy of the model
        self.notes, self.io, self.memory = data.notes, data.io, data.memory     # notes: until the controller
        self.sysvars, self.program, self.modules = data.sysvars, data.program, data.modules
        self.kss, self.names = data.kss, data.names     # stand-ins for KUKA's software; what a name denotes
        plan = plan(data)
        self.halt_continues = spec.halt_continues   # krl run --on-halt continue: Start pressed again at most so often
        self.halts = 0                  # HALTs continued so far
        self.start = plan.start         # how the run started (mode, place: interp/run.py)
        self.robot: Task | None = None
        self.result: RunResult | None = None
        # the parts, each after what it uses, with exactly that (docs/architecture.md "The runtime's
        # parts"); what the runtime owns or builds later as a callable (the waits, the robot task)
        self.controller = self._controller(plan, sinks.events, self.notes)
        robot = lambda: self.robot      # noqa: E731 - the robot task, once add_task adds it
        ctl, sv, clock, tracing = self.controller, self.sysvars, self.clock, self.tracing
        # the run mode, backward motion and the debugger's hooks (interp/runtime/stepping.py)
        self.stepping = Stepping(ctl, sv, clock, tracing, self.message, self.wait_main_run)
        # the fast-forward: idle cycles, parked spins (interp/runtime/fastforward.py)
        ff = self.ff = FastForward(spec, ctl, clock, tracing, self.stepping, self.program, self.names, sv, self.kss,
                                   self.messages, robot, self.yield_cycle, self.step_limit_left)
        self.cyclic_watch = CyclicWatch(ctl, clock, self.stepping, ff.spin)  # cyclic flags: watch.py
        # ANIN/ANOUT ON, cyclic flags (interp/runtime/cyclic.py)
        self.cyclic = Cyclic(ctl, sv, clock, ff.spin, self.cyclic_watch, robot)
        self.scheduler = Scheduler(clock, ctl, ff, self.cyclic_watch, self.cyclic, self.stepping, tracing,
                                   self.task_main, self.step_limit_left, spec.max_sim_time, spec.max_steps,
                                   jumps=spec.fast_forward and spec.clock_jumps)
        # the interpreters' program states, as the $CMD commands set them (interp/runtime/cmdchannel.py)
        self.programs = ProgramControl(self.scheduler, self.program.main_path, robot, self.tasks_state_changed,
                                       self.noted, self.message)
        self.errstate = ErrorState(clock, robot)   # $ERR, ON_ERROR_PROCEED (interp/runtime/errstate.py)
        self.calls = Calls(self.program, self.memory, self.modules, self.kss, clock, ctl, tracing, self.stepping,
                           self.run_native)       # routine calls (interp/runtime/calls.py)
        # interrupts, BRAKE, RESUME (interp/runtime/interrupts.py)
        self.interrupts = Interrupts(clock, ctl, sv, self.cyclic_watch, tracing, self._proceed, self.yield_cycle)
        self.motions = MotionStatements(ctl, sv, clock, self.stepping, self._wait, self._proceed, self.wait_main_run,
                                        self.wait_for)  # motion statements (interp/runtime/motions.py, teamsync.py)
        # what a native may do on this run (interp/runtime/natives/context.py)
        self.natives = NativeContext(ctl, sv, self.names, self.messages, self.errstate, self.programs, clock,
                                     self.noted, random.Random(0), wait_main_run=self.wait_main_run,
                                     yield_cycle=self.yield_cycle, block_cycle=self.block_cycle, pulse=self.pulse,
                                     message=self.message, clock_read=self.reads.clock_read)
        self.autocell = None            # krl run --inputs auto (interp/runtime/autocell.py)
        if spec.auto:
            self.autocell = AutoCell(self.program, ctl, self.names, self.scheduler, robot, tracing,
                                     AUTO_DELAY_S, [spec.program, *spec.submit], spec.wired)
        ff.attach(self.scheduler, self.cyclic, self.cyclic_watch, self.calls, self.autocell)
        reads.attach(self.program, ctl, self.programs, self.errstate, self.stepping, ff)
        if spec.run_mode != "GO":
            self.stepping.set_run_mode(spec.run_mode)
        if spec.override is not None:
            self.sysvars.store["$OV_PRO"] = int(spec.override)   # krl run --override, set before the start
        self.interpreter = interpreter(self) if interpreter is not None else None
        if self.interpreter is not None:
            run = self.interpreter.run_program
            self.add_task("robot", spec.program.stem, lambda: run())
            for sub in spec.submit:
                sp = Path(sub).resolve()
                self.add_task("submit", sp.stem, lambda name=sp: run(name))

    def _controller(self, plan: "CellPlan", events, notes: list):
        """The run's controller (robot/controller.py), complete: the spec's robot, its trace (an
        observer's, which passes the events on to the trace), MuJoCo or not, on the run's I/O
        image, with the `plan`'s cell (mode, stimuli, rules, start, geometry), the workspace
        monitor the program's data lists made active (interp/runtime/sysvars.py) and the network hub
        (net/hub.py: the plan's partners; without any its EKI channels stay "not connected"); the
        `notes` given while the program loaded are its first messages (taken from the list)."""
        spec = self.spec
        prog = self.program
        sink = RuntimeSink(self.changed_outside, self.sysvars, prog, self.names, self.io)
        net = Network(plan.network, program=prog.main_path,
                      backup=prog.workspace if prog.backup else None, sink=sink)
        try:
            ctl = Controller(spec.robot, trace=events,
                             stimuli=plan.stimuli, rules=plan.rules, start_axes=plan.start_axes,
                             mujoco=spec.mujoco, mode_op=plan.mode_op, io=self.io, network=net,
                             cell={"plc_map": plan.plc_map}, geometry=plan.geometry,
                             workspaces=self.sysvars.workspaces)
        except OSError as exc:
            net.close()
            raise NetError(f"a network partner cannot start: {exc.strerror or exc}") from None
        for text in notes:
            ctl.log.message(text)
        notes.clear()
        return ctl

    # ================================================================== tasks and run
    def add_task(self, kind: str, name: str, body) -> Task:
        """Register a task; ``body()`` runs the program (the first task is the robot)."""
        task = Task(kind, name, body, self.robot_budget if kind == "robot" else None)
        # the step limit stops a runaway robot program, not a submit program (a .sub run as the
        # program too) cycling at its time slice: docs/architecture.md "The step limit"
        task.limited = kind == "robot" and program_budget(self.program.main_path) is None
        if kind == "robot":
            self.robot = task
        self.scheduler.add(task)
        self.clock.bump_epoch()     # $PRO_STATE0, $PRO_ACT
        return task

    def run_native(self, fn, args: list):
        """A native implementation `fn` (interp/runtime/natives: ``fn(ctx, args)``) run with
        reference `args` on this run's :class:`NativeContext` (natives/context.py: the calls a
        native may make): for routine calls (calls.py ``Calls.call_native``)."""
        return fn(self.natives, args)

    def step_limit_left(self, task: Task) -> int:
        """The steps `task` may still take before the step limit (``max_steps``) stops the run:
        the robot interpreter's (the robot program with its interrupt routines and TRIGGER
        actions) are counted; a submit program's are not, nor those of a .sub run as the program
        (NO_LIMIT): docs/architecture.md "The step limit"."""
        if self.max_steps is None or not task.limited:
            return NO_LIMIT
        return self.max_steps - task.steps

    def steps_by_task(self) -> list[tuple[str, int]]:
        """(task name, steps) of every task of the run, robot first: which task used the steps
        (the run summary's ``time`` line)."""
        return [(t.name, t.steps) for t in self.scheduler.tasks]

    def task_main(self, task: Task) -> None:
        """Greenlet body of a task: run it and record its outcome."""
        self.clock.enter(task, self.clock.limit_at)
        self._proceed()     # a task that starts goes on too: a parked spin catches up first
        try:
            body = task.body
            while True:
                try:
                    body()
                    break
                except ProgramSelected as sel:
                    body = start_selected(self, task, sel)
            if task.kind == "robot":
                self.wait_main_run(task)      # END: the main run finishes its motions
                if self.stepping.run_mode == "BSTEP":
                    self.stepping.retrace(task)
            task.outcome = ("completed", None)
        except HaltSignal:
            task.outcome = ("halt", None)
        except StopRun as s:
            task.outcome = (s.reason, s.text)
        except KrlRuntimeError as e:
            e.at(task.file, task.line)
            explain_unknown(e, self.program.ws)     # the backup's own undeclared name (E101)
            task.outcome = ("error", e)
        except ResumeSignal:
            task.outcome = ("error", KrlRuntimeError(
                "RESUME not possible: the advance run is in the routine that declared the interrupt",
                None, task.file, task.line))
        except RecursionError:
            task.outcome = ("error", KrlRuntimeError("stack overflow", None, task.file, task.line))
        finally:
            self.ff.ending(task)        # what a parked task reads of the tasks' state changes
            task.done = True
            self.clock.bump_epoch()     # $PRO_STATE0/1, $PRO_ACT
        reason = task.outcome[0]
        if task.kind == "robot" or reason in ("max_steps", "max_sim_time"):
            if self.scheduler.stop is None and (task.kind == "robot" and reason != "completed" or task.kind != "robot"):
                self.scheduler.stop = (reason, task.outcome[1], task)

    def run(self) -> RunResult:
        """Run all tasks to the end; writes the ``end`` trace event; returns the result."""
        for _ in run_cycles(self):
            pass
        return self.result

    @property
    def trace(self):
        """The trace the interpreters write to now (robot.trace.TraceWriter or None):
        :attr:`tracing`'s writer."""
        return self.tracing.writer

    @property
    def mode_op(self) -> str:
        """``$MODE_OP``'s name (T1, T2, AUT, EX)."""
        return self.controller.mode_op

    def select_mode(self, mode: str) -> None:
        """The operator selects the operating mode `mode` (T1, T2, AUT, EX) between two runs of
        the program (the pendant's mode selector): ``$MODE_OP``, the controller's and its robot
        model's (T1's reduced speeds, robot/limits.py)."""
        self.controller.select_mode(mode)
        self.clock.bump_epoch()

    @contextlib.contextmanager
    def evaluation(self) -> Iterator[None]:
        """An evaluation from outside the program (a debugger's watch, a breakpoint's condition):
        while it runs nothing is traced, the running task's time slice does not end and no step
        limit stops it, and the steps it takes are not counted; afterwards the run stands as
        before."""
        clock = self.clock
        task = clock.current_task
        saved = (self.tracing.writer, task.slice_end if task is not None else None)
        self.tracing.writer = None
        if task is not None:
            task.slice_end = sys.maxsize
        counters = clock.enter(task, NO_LIMIT)
        try:
            yield
        finally:
            self.tracing.writer = saved[0]
            if task is not None:
                task.slice_end = saved[1]
            clock.restore(counters)

    def changed_outside(self) -> None:
        """The operator changed the run's state between two statements or IPO cycles (a front
        end's edit: interp/debug/engine.py ``Engine.edit``/``edit_now``; a variable, a message
        acknowledged, the override): every watch key moves (the probes, ``CyclicWatch.version``)
        and parked spins run again, so that no wait, interrupt or spin misses the change."""
        self.cyclic_watch.version += 1
        self.clock.bump_epoch()
        ff = getattr(self, "ff", None)
        if ff is not None:
            ff.outside_change()

    def tasks_state_changed(self) -> None:
        """An interpreter's program state changed without a task's end (a $CMD command:
        interp/runtime/cmdchannel.py): as at a task's end, the probed state variables
        ($PRO_STATE0/1, $PRO_ACT) are read again and a parked task that reads one catches up."""
        self.ff.ending(self.clock.current_task)
        self.clock.bump_epoch()

    # the operators of expressions (interp/runtime/convert.py), for both interpreters
    binary_op = staticmethod(binary_op)
    unary_op = staticmethod(unary_op)
    to_bool = staticmethod(to_bool)

    # ================================================================== time
    def yield_cycle(self, task: Task) -> None:
        """Give the rest of this IPO cycle back; on return run :meth:`service`."""
        self.ff.waiting(task)
        self.scheduler.yield_cycle()
        self.service(task)
        hook = self.stepping.cycle_hook
        if hook is not None:
            hook(task)

    def block_cycle(self, task: Task) -> None:
        """One IPO cycle of a statement that blocks its interpreter until something outside
        it happens (a client's EKI_Open waiting for its connection, docs/network.md
        "EthernetKRL"): the controller's clock, the main run and the other interpreters go on;
        the task's interrupt conditions are monitored, an event is kept pending and its
        routine runs when the statement has returned (at the next statement), as the
        statement is one step of the program run; a main-run error ends the wait."""
        self.ff.waiting(task)
        self.scheduler.yield_cycle()
        self._proceed()
        if task.pending_error is not None:
            e, task.pending_error = task.pending_error, None
            if isinstance(e, ProgramSelected):
                raise e                 # $CMD selected another program, which the PLC starts
            err = KrlRuntimeError(e.message, e.number)
            err.traced = True
            raise err
        if task.irqs.armed and not task.in_poll:
            ctl = self.controller
            task.in_poll = True
            try:
                task.irqs.poll(ctl.io.version, ctl.time, self.clock.state_epoch)
            finally:
                task.in_poll = False
        hook = self.stepping.cycle_hook
        if hook is not None:
            hook(task)

    def _proceed(self) -> None:
        """A task goes on after a wait (or runs a TRIGGER action, an interrupt routine): a
        parked spin catches up first (interp/runtime/spin.py)."""
        self.ff.proceeding()

    def service(self, task: Task) -> None:
        """First act of a resumed task: main-run errors (or another program $CMD selected and
        the PLC starts: errors.py ProgramSelected), TRIGGER actions, interrupts."""
        if task.pending_error is not None:
            e, task.pending_error = task.pending_error, None
            if isinstance(e, ProgramSelected):
                raise e
            err = KrlRuntimeError(e.message, e.number)
            err.traced = True          # robot/controller.py wrote its error event
            raise err
        while task.pending_triggers:
            self.interrupts.run_trigger(task, task.pending_triggers.pop(0))
        if task.irqs.armed:
            self.interrupts.check(task)

    def before_statement(self, info: StmtInfo) -> None:
        """Called by an interpreter before every statement: counts the step (limits,
        time slice), checks interrupts, applies CONTINUE and the advance-run stop, writes
        the ``stmt`` trace event."""
        task = self.clock.current_task
        task.at = info
        ff = self.ff
        if ff.on:
            ff.statement(task, info, False)
        self._count_step(task)
        cont = False
        if task.continue_line is not None:
            cf, cl = task.continue_line
            cont = cf == info.file and info.line == cl + 1
            task.continue_line = None
        if info.stops and not cont and task.kind == "robot":
            self.advance_stop(task)
        stepping = self.stepping
        if stepping.run_mode == "ISTEP" and task.kind == "robot" and task.context.kind != "trigger":
            # ISTEP: a stop after each statement, reached with the main run caught up
            self.wait_main_run(task)
            stepping.step_stop(task, "ISTEP")
        trace = self.tracing.writer
        if trace is not None:
            trace.write("stmt", self.controller.time, file=info.file, line=info.line,
                             context=task.context.kind)
        if self.autocell is not None and self.autocell.recording is not None:
            self.autocell.record(task, info)
        if stepping.stmt_hook is not None:
            stepping.stmt_hook(task, info)

    def _count_step(self, task: Task) -> None:
        """One step of a task: the step limit, the end of its time slice, interrupts."""
        self.clock.count(1)
        if self.clock.steps > self.clock.limit_at:
            raise StopRun("max_steps", f"step limit {self.max_steps} reached")
        if self.clock.steps >= task.slice_end:
            self.yield_cycle(task)
            self._proceed()
        elif task.irqs.armed:
            self.interrupts.check(task)

    def quiet_limit(self, task: Task) -> int:
        """The *quiet-step limit* of ``task`` (the VM's fast path; docs/architecture.md,
        "Bytecode VM"): while ``self.clock.steps`` is below it, a statement whose StmtInfo does
        not stop the advance run (or a loop iteration whose condition does not) has no
        effect of :meth:`before_statement` / :meth:`loop_tick` but ``steps += 1`` and
        ``task.at = info``: no trace, no step limit or end of the time slice
        reached, no armed interrupt, no pending CONTINUE or ON_ERROR_PROCEED. 0 when a
        step needs the full hook. An interpreter that takes the fast path stores the
        limit in ``task.quiet`` after each full hook; :meth:`_break` (a task switch,
        CONTINUE, ON_ERROR_PROCEED, an interrupt declared or switched, a new state epoch)
        resets it. Armed interrupts allow quiet steps while their last poll left them settled
        in this state epoch (contexts.py ``InterruptTable.settled``): conditions over
        constants and probed state only, nothing pending, so a poll before these steps would
        evaluate and fire nothing.

        Sets ``task.calm``: the task's advance-run stops are no-ops during these steps (a
        submit task's always: :meth:`before_statement`; the robot task's while the main run is
        idle, which only its own motion statement changes within its time slice: motions.py
        ``MotionStatements._enqueue`` breaks), so a statement or loop condition that stops the
        advance run may be a quiet step too. Until 2026-11-26 every such statement took the full hook: an
        SPS.SUB writes outputs and reads timers, and 40 % of its steps did.

        A parked pass's catch-up (interp/runtime/spin.py ``SpinWatch.wake``: ``task.replay`` with
        its start's step count) takes quiet steps too: it is checked against the recorded pass
        at the steps that take the hook, its last one always (a period's catch-up sets the
        timers at its steps: every one takes the hook). So does a task whose recording looks
        for its loop's iteration, up to LOOK_MARGIN steps before the boundary its wake predicts
        (spin.py ``SpinWatch.quiet_until``): the iteration itself takes the hook."""
        irqs = task.irqs
        stepping = self.stepping
        # (the fast-forward's watch first: every step of a recorded pass asks)
        lim = self.ff.quiet_steps(task, task.slice_end - 1)
        if lim is None or self.tracing.writer is not None \
                or (irqs.armed and irqs.settled != self.clock.state_epoch) \
                or task.continue_line is not None \
                or stepping.stmt_hook is not None or stepping.run_mode == "ISTEP" \
                or any(c.error_proceed for c in task.contexts):
            task.calm = False
            return 0
        task.calm = task.kind != "robot" or self.controller.is_idle()
        return self.clock.limit_at if self.clock.limit_at < lim else lim

    @staticmethod
    def _break(task: Task) -> None:
        """The next step of ``task`` takes the full hook (see :meth:`quiet_limit`):
        scheduler.py ``break_quiet``, for the fast-forward's modules."""
        break_quiet(task)

    def loop_tick(self, info: StmtInfo) -> None:
        """Called once per loop iteration (WHILE/REPEAT/LOOP/FOR): counts a step, may end
        the time slice, applies a loop condition's advance-run stop. No trace event."""
        task = self.clock.current_task
        ff = self.ff
        if ff.on:
            ff.statement(task, info, True)
        self._count_step(task)
        if task.park is not None:
            ff.park(task)         # a spin: parked until something it reads can change
        if info.cond_stops and task.kind == "robot":
            self.advance_stop(task)
        if self.autocell is not None and self.autocell.recording is not None:
            self.autocell.record(task, info)

    def set_continue(self, info: StmtInfo) -> None:
        """CONTINUE: the next line does not stop the advance run."""
        task = self.clock.current_task
        task.continue_line = (info.file, info.line)
        break_quiet(task)

    def advance_stop(self, task: Task) -> None:
        """The advance-run stop of a statement. Main context: wait for the main run. An
        interrupt routine waits only for the motions of its own level (after BRAKE: the
        interrupted motion is suspended and not counted); before BRAKE the planned motions
        keep running and the routine does not wait for them. A TRIGGER action never waits."""
        kind = task.context.kind
        if kind == "main" or (kind == "interrupt" and self.controller.is_suspended()):
            self.wait_main_run(task)

    def wait_main_run(self, task: Task) -> None:
        """Advance-run stop: wait until the main run is idle (robot at rest)."""
        ctl = self.controller
        if not ctl.is_idle():
            self._wait(task, ctl.is_idle)
            self._proceed()

    def _wait(self, task: Task, until) -> None:
        """Give IPO cycles back until ``until()`` — a test of the controller's state, with no
        effect — holds. While the task waits so, the scheduler makes the test itself instead of
        resuming it (interp/runtime/scheduler.py ``Scheduler._waits``)."""
        outer, task.until = task.until, until
        try:
            while not until():
                self.yield_cycle(task)
        finally:
            task.until = outer

    def wait_for(self, cond_fn, text: str = "WAIT FOR") -> None:
        """WAIT FOR: ``cond_fn()`` is evaluated now and once per IPO cycle."""
        task = self.clock.current_task
        if to_bool(cond_fn(), "WAIT FOR condition"):
            return
        task.waiting = f"{text} at {task.file}:{task.line}" if task.kind == "robot" else None
        # a condition over inputs and variables (interp/runtime/watch.py) gives the same value
        # while its watch key stands: the scheduler tests the key instead of resuming the task
        # (and one that compares running timers with numbers, until a timer reaches its bound:
        # watch.timer_watch; the scheduler then makes the condition's clock reads itself)
        key, tests = self._wait_key(task) if text == "WAIT FOR" else (None, ())
        outer, reads, due0 = task.until, task.clock_reads, task.timer_due
        ctl = self.controller
        try:
            while True:
                if key is not None:
                    seen = key()
                    if seen is None:
                        task.until = None
                    elif not tests:
                        task.until = lambda seen=seen: key() != seen
                    else:
                        due = timer_due(tests, ctl.io, ctl.cycle, ctl._dt_ms)
                        task.clock_reads = timer_reads(tests, ctl.io)
                        task.timer_due = due
                        task.until = (lambda seen=seen: key() != seen) if due is None else \
                            (lambda seen=seen, due=due: ctl.cycle >= due or key() != seen)
                self.yield_cycle(task)
                if to_bool(cond_fn(), "WAIT FOR condition"):
                    self._proceed()
                    return
        finally:
            task.waiting = None
            task.until, task.clock_reads, task.timer_due = outer, reads, due0

    def _wait_key(self, task: Task):
        """``(key, tests)``: the watch key (interp/runtime/watch.py ``stamp_key``) of the condition
        of the WAIT FOR `task` stands at, as a zero-argument callable, and the comparisons of
        running timers with numbers in it (``watch.timer_watch``: the key is the rest's, and the
        condition stands until a timer reaches its bound, ``watch.timer_due``); ``(None, ())``
        when its class has no key that stands (it reads the clock otherwise, calls a routine, ...)."""
        node = next((n for n in self.ff.statements(task.at) or () if isinstance(n, N.WaitFor)), None)
        if node is None:
            return None, ()
        ann = node.annotate()
        w = ann.extra.get("watch")
        if w is None:
            w = ann.extra["watch"] = watch_of(node.cond)
        cls, names = split_watch(w)
        tests = ()
        if cls not in (CONSTANT, IO, SETTLES):
            tw = ann.extra.get("timer_watch", False)
            if tw is False:
                tw = ann.extra["timer_watch"] = timer_watch(node.cond)
            if tw is None:
                return None, ()
            w, tests = tw
            cls, names = split_watch(w)
            if cls not in (CONSTANT, IO, SETTLES):
                return None, ()
        probes = tuple(reader(self.sysvars.lookup(k)) for k in names)
        ctl = self.controller
        written = self.cyclic_watch.written
        return (lambda: stamp_key(cls, ctl.io.version, ctl.time, probes, written())), tests

    def wait_sec(self, seconds) -> None:
        """WAIT SEC t: t seconds of simulated time (rounded up to IPO cycles)."""
        t = float(num(seconds, "WAIT SEC time"))
        if t != t or t in (float("inf"), float("-inf")):
            raise KrlRuntimeError(f"WAIT SEC with an invalid time ({t})")
        if t < 0:
            raise KrlRuntimeError(f"WAIT SEC with a negative time ({t})")
        task = self.clock.current_task
        ctl = self.controller
        ff = self.ff
        outer, task.wake_cycle = task.wake_cycle, ctl.cycle + ctl.cycles_for(t)
        shifted = ff.shifted
        try:
            # task.wake_cycle, not a local: a periodic jump of the idle watch moves it
            self._wait(task, lambda: ctl.cycle >= task.wake_cycle)
            self._proceed()
        finally:
            # an outer WAIT SEC (this one ran in an interrupt routine) moves with the jumps too
            task.wake_cycle = None if outer is None else outer + ff.shifted - shifted

    def halt(self) -> None:
        """HALT (reference §5.7): the program stops as if the operator pressed STOP. With
        ``krl run --on-halt continue`` (:attr:`halt_continues` > 0) the operator presses Start
        again: the robot comes to rest at the end of its motion, :data:`OPERATOR_DELAY_S`
        later the program goes on with the next statement — at most :attr:`halt_continues`
        times in a run, then the HALT ends it. Each is a ``step_stop`` trace event (mode
        HALT) and a message. HALT in a submit program ends that program."""
        task = self.clock.current_task
        if task is None or task.kind != "robot" or self.halts >= self.halt_continues:
            raise HaltSignal()
        self.halts += 1
        self.wait_main_run(task)
        where = f"{Path(task.file).name}:{task.line}" if task.file else "?"
        text = f"HALT at {where}: Start pressed again ({self.halts} of {self.halt_continues}, --on-halt continue)"
        self.stepping.step_stop(task, "HALT", text=text)
        self.message(text)
        self.wait_sec(OPERATOR_DELAY_S)

    # ================================================================== I/O, messages
    def pulse(self, ref: Ref, level: bool, duration: float) -> None:
        """PULSE(signal, level, duration) on an output (§5.12)."""
        if isinstance(ref, ProxyRef) and ref.proxy.name.upper() == "$OUT":
            n = ref.index
        elif isinstance(ref, SignalRef) and ref.b is None and ref.proxy.name.upper() == "$OUT":
            n = ref.a
        else:
            raise KrlRuntimeError("PULSE needs an output ($OUT[n] or an output SIGNAL)")
        self.controller.signals.pulse(n, level, duration, self.reads.io_source())

    def message(self, text: str) -> None:
        """A controller message (its message log and the trace); one given while the program
        loads waits for the controller (the run's ``notes``, which begin with the model's)."""
        if self.controller is None:
            self.notes.append(text)
            return
        self.controller.log.message(text)

    def stub_statement(self, what: str) -> None:
        """A statement of §5.20 that is recognised and not simulated (CONFIRM, ASYPTP,
        MOVE_EMI, ...): logged once as a ``message`` event, no effect."""
        self.kss.statement(what)


def start_selected(rt: "Runtime", task: Task, sel: ProgramSelected):
    """`rt`'s robot task after $CMD stopped and deselected its program and Automatic
    External's PLC started the one RUN selected (`sel`, interp/runtime/cmdchannel.py): the
    motions still planned are discarded (the robot stops at its setpoint: STOP's brake ramp
    is not simulated), the old program's interrupts and contexts go with it, and the body
    that runs the selected module's main routine from its start is returned. A module function
    (Runtime keeps under 40 methods)."""
    rt.controller.cancel_pending()
    task.contexts = [Context("main")]
    task.irqs = InterruptTable()
    task.waiting = None
    task.name = sel.module
    rt.programs.started(1)
    rt.message(sel.text)
    run = rt.interpreter.run_program
    return lambda: run(sel.module)


def run_cycles(rt: "Runtime") -> Iterator[None]:
    """`rt`'s run (:meth:`Runtime.run`) one IPO cycle at a time: yields after each cycle (a
    clock jump is one yield; a held run's offers: interp/runtime/scheduler.py
    ``Scheduler.cycles``), so that a cell of several robots (interp/robotcell.py) steps their
    runs on one clock; when it ends, ``rt.result`` is the run's result (as :meth:`Runtime.run`
    returns it). A module function, not a method: Runtime keeps to 40."""
    for writer in (rt.tracing.writer, getattr(rt.controller, "trace", None)):
        if hasattr(writer, "state_probe"):
            # a bounded trace leaves a pass out only when the state repeats too (robot/trace.py)
            writer.state_probe = lambda: probe_state(rt)
    old = sys.getrecursionlimit()
    sys.setrecursionlimit(max(old, 20000))
    try:
        yield from rt.scheduler.cycles()
    finally:
        sys.setrecursionlimit(old)
        net = getattr(rt.controller, "network", None)
        if net is not None:
            net.close()
    robot = rt.robot
    stop = rt.scheduler.stop
    if stop is not None:
        reason, detail, task = stop
    else:
        reason, detail, task = robot.outcome[0], robot.outcome[1], robot
    err = detail if isinstance(detail, KrlRuntimeError) else None
    text = err.message if err is not None else (detail or "")
    file = (err.file if err is not None else None) or task.file
    line = (err.line if err is not None else None) or task.line
    ctx = task.context.kind if task.contexts else None
    if reason in ("max_sim_time", "max_steps") and robot.waiting:
        text = f"{text} while the robot program waits: {robot.waiting}"
    if reason == "completed":
        file, line, ctx = robot.file, robot.line, "main"
    rt.result = RunResult(reason, err, file, line, ctx, text, rt.controller.time, rt.clock.steps,
                            call_stack(robot))
    trace = rt.tracing.writer
    if trace is not None and reason == "error" and err is not None and not err.traced:
        # the robot program's run-time error, before the `end` event (robot/trace.py);
        # a submit program's error was written when that task ended (scheduler.py Scheduler._turn)
        trace.write("error", rt.controller.time, text=err.message, number=err.number,
                    line=line, file=file)
    if trace is not None:
        rt.controller.log.finish(reason, text=text or None,
                               number=err.number if err is not None else None,
                               file=file, line=line, context=ctx)
    rt.tracing.writer = None      # the suspended tasks unwind now: nothing more is traced
    rt.scheduler.close()
