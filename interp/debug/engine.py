"""Run control of one KRL program under a debugger: the one engine behind ``krl debug``'s
Debug Adapter Protocol adapter (interp/debug/session.py) and the pendant's web front
(docs/editors.md, "Debugging"; docs/architecture.md, "Debugger").

How it runs: the program runs on the *engine thread* (the thread that calls :meth:`Engine.serve`),
exactly as ``krl run`` runs it (interp/run.py ``make_runtime``: the cooperative tasks of
interp/runtime/scheduler.py, each in a greenlet). The engine sees the program through four
hooks of :class:`interp.runtime.core.Runtime`, shared by both interpreters:

* ``stmt_hook(task, info)`` before every statement: breakpoints, steps, pause, entry;
* ``step_hook(task, mode, text)`` at a run mode's step stop (#MSTEP, #ISTEP, #BSTEP);
* ``error_hook(task, frame, err)`` where a run-time error leaves the routine it occurred in;
* ``cycle_hook(task)`` when a waiting task resumes in a new IPO cycle (pause in a WAIT).

A stop is a loop inside the hook that serves the work posted to the engine until one piece
of it resumes the run: the tasks stay suspended where they are, so stacks, variables and the
robot are the live ones.

Front ends
----------
Everything that touches the run happens on the engine thread. A front end posts work there
with :meth:`Engine.post` (a :class:`concurrent.futures.Future` of the result) or
:meth:`Engine.call` (waits for it); the DAP adapter posts each request it reads. Work runs
between two statements or IPO cycles while the program runs, and at once while it stands.
The front end hears of the run through ``on_event(name, body)`` (called on the engine thread;
it must only hand the event on):

* ``stopped`` — DAP ``StoppedEvent`` body: ``reason`` (entry, step, breakpoint, function
  breakpoint, pause, exception), ``threadId``, ``allThreadsStopped``, ``description``,
  ``text``, ``hitBreakpointIds``;
* ``krl/pointers`` — :meth:`Engine.pointers` at each stop;
* ``output`` — ``{"category", "output"}``: the end of the program, notes;
* ``exited`` — ``{"exitCode"}`` (krl run's exit code); ``terminated`` — ``{}``.

and, through ``on_runtime(rt)``, of each run it builds (the first one, and each replay), to
hook its own display (``rt.controller.signals.add_cyclic``) or message window on it. An engine
made ``interactive`` builds its runs with a message window an operator answers (the pendant:
RunSpec.interactive).

The engine's methods (to be called on the engine thread):

* set-up: :meth:`launch` (a :class:`LaunchConfig`), :meth:`set_breakpoints`,
  :meth:`set_function_breakpoints`, :attr:`break_on_errors`, :meth:`configuration_done`;
* control: :meth:`resume`, :meth:`step` (over, in, out), :meth:`pause`, :meth:`step_back`,
  :meth:`reverse_continue`, :meth:`terminate`;
* inspection while stopped: :meth:`threads`, :meth:`stack`, :meth:`scopes`,
  :meth:`variables`, :meth:`evaluate`, :meth:`pointers`, :meth:`exception`;
* edits while stopped (each recorded, see below): :meth:`set_variable`, :meth:`assign`,
  :meth:`set_input`, :meth:`backward_motion`, :meth:`move` (a jog), and :meth:`edit` for a
  front end's own (the override, the operating mode); :meth:`edit_now` makes an edit while the
  program runs too (the pendant's input toggles and acknowledgements), :meth:`evaluate_now`
  evaluates while it runs, :meth:`flush_trace` puts the trace so far on disk.

Reverse execution and edits
---------------------------
``step_back`` and ``reverse_continue`` are deterministic replay: the run is rebuilt from the
start (same files, inputs, seeds) and run to the statement before (the hook count ``n``);
the simulation is deterministic, so the state there is the state the program had. Greenlet
stacks cannot be copied, so there are no snapshots: a replay always starts at the beginning
(at most krl.limits.MAX_DAP_REPLAY_STEPS statements).

What the user changed at a stop is part of that history: every edit is recorded with the
place of the stop (``n`` and, for a stop inside a statement, the count of the hook calls
since that statement began) and applied again at the same place of each replay, before the
run goes on. Going back before an edit forgets it (as an undo); the run then goes on as if
it had not been made.
"""

from __future__ import annotations

import contextlib
import os
import queue
import threading
from concurrent.futures import Future
from dataclasses import dataclass

from interp.runtime.errors import ControlSignal, KrlRuntimeError
from interp.runtime.values import type_name_of
from krl import collector
from krl.limits import MAX_DAP_BREAKPOINTS, MAX_DAP_REPLAY_STEPS
from robot.errors import RobotError

from . import view
from .cellrun import NO_REVERSE, CellDebug, is_cell_launch
from .breakpoints import Breakpoint
from .errors import Refused
from .expr import ExpressionError, compile_in_frame, parse_expression
from .values import has_children, value_text
from interp.run import RunSetupError, RunSinks, run_setup
from .launch import run_defaults
from robot.io import N_DIGITAL
from interp.tree import TreeInterpreter
from interp.runtime.convert import to_bool


class Terminate(BaseException):
    """The session ends (disconnect, terminate, end of input): the run unwinds at once."""


class Restart(BaseException):
    """Unwinds the run for a replay to hook count ``target`` (reason of the stop there);
    ``scan``: reverseContinue, find the last breakpoint before this hook count."""

    def __init__(self, target: int, reason: str = "step", scan: int | None = None) -> None:
        super().__init__(target)
        self.target = target
        self.reason = reason
        self.scan = scan


@dataclass
class LaunchConfig:
    """What to run and how: ``options``, ``krl run``'s options by their click names
    (interp/cli.py ``run``: program, workspace, inputs, submit, no_submit, robot, mode,
    run_mode, interp_kind, max_sim_time, max_steps, pgno, no_check, trace_path; one left out
    takes krl run's default), and ``stop_on_entry`` (stop at the first statement)."""
    options: dict
    stop_on_entry: bool = False

    @classmethod
    def of(cls, program, stop_on_entry: bool = False, **options) -> "LaunchConfig":
        """``LaunchConfig.of("prog.src", mode="T1", run_mode="MSTEP")``."""
        return cls({"program": str(program), **options}, stop_on_entry)


@dataclass
class Frame:
    """One frame of a thread's stack at a stop: ``thread`` id, ``index`` (0: innermost),
    ``task`` and ``frame`` (the runtime's), ``name`` (the routine), ``path``, ``line``."""
    thread: int
    index: int
    task: object
    frame: object
    name: str
    path: str
    line: int


@dataclass
class Scope:
    """Where variables are listed: ``kind`` one of the scopes of interp/debug/view.py
    (locals, module, globals, sysvars, io), a frame's place (``thread``, ``index``), and
    ``path`` (the names of the parts opened below it: a structure's component, an array
    element). ``value``: an evaluated result's parts (then ``kind`` is "value")."""
    kind: str
    thread: int = 0
    index: int = 0
    path: tuple = ()
    value: object = None


@dataclass
class Variable:
    """One variable of a scope: ``name`` (as declared), ``value`` (display text), ``type``
    (KRL type name or None), ``children`` (a :class:`Scope` of its parts, or None)."""
    name: str
    value: str
    type: str | None
    children: Scope | None


@dataclass
class Edit:
    """A change the user made at a stop: ``where`` (n, hook calls inside statement n), a
    ``label`` for the user, ``apply(engine)`` that makes it (again) on the engine's run."""
    where: tuple
    label: str
    apply: object


class Engine:
    """Run control of one program (see the module docstring)."""

    def __init__(self, on_event=None, on_runtime=None, interactive: bool = False) -> None:
        self.on_event = on_event or (lambda name, body: None)
        self.on_runtime = on_runtime
        #: an operator answers the message window (the pendant; RunSpec.interactive)
        self.interactive = interactive
        self.inbox: queue.Queue = queue.Queue()
        self.config: LaunchConfig | None = None
        self.setup = None                      # interp.run.RunSetup of the launch
        self._trace = None                     # the trace file's writer (krl run --trace)
        self.configured = False
        self.started = False
        self.done = False
        self.state = "init"                    # init | running | stopped | ended
        self.line_bps: dict[str, dict[int, Breakpoint]] = {}
        self.func_bps: dict[str, Breakpoint] = {}
        self.next_bp = 1
        self.break_on_errors = True
        self.rt = None
        self.tree = None
        self.cell: CellDebug | None = None     # a cell of several robots (interp/debug/cellrun.py)
        self._built = None                     # the launch's run, kept for the first run
        self.n = 0                             # statements seen (hook count) in this run
        # the hook count of the robot program's first statement: the entry stop. The submit
        # tasks' boot slice runs before it (interp/runtime/scheduler.py), so it need not be 1;
        # a run replays identically, so it holds for every restart of the launch
        self.entry_n: int | None = None
        self.sub = 0                           # hook calls inside statement n (cycles, step stops)
        self.target: int | None = None         # replay: stop at this hook count
        self.target_reason = "step"
        self.scan: int | None = None           # reverseContinue: find the last breakpoint before this
        self.scan_last = 0
        self.busy = False                      # hooks ignored (evaluating, an edit)
        self.pause_req = False
        self.pause_in = None                   # a cell: the runtime whose robot program a pause stops in
        self.stepping: tuple | None = None     # (kind, task, depth)
        self.resumed: tuple | None = None
        self.stop_n = 0
        self.stop_where: tuple = (0, 0)
        self.stop_mid = False                  # stopped inside a statement (step stop, error)
        self.stop_task = None
        self.stop_error = None
        self.stop_thread = view.ROBOT_THREAD
        self.stop_body: dict | None = None
        self.edits: list[Edit] = []            # every edit, in the order made
        self._pending: list[Edit] = []         # edits a replay has still to apply
        self.realpaths: dict[str, str] = {}
        self.prev_frame: dict = {}             # task -> frame seen at its previous statement
        self.last_refusal: str | None = None
        self.cleanup = contextlib.ExitStack()  # an extracted backup, removed when the session ends

    # ------------------------------------------------------------------ engine thread
    def post(self, fn, *args) -> Future:
        """Run ``fn(*args)`` on the engine thread (any thread may call this); its Future."""
        fut: Future = Future()
        self.inbox.put((fn, args, fut))
        return fut

    def call(self, fn, *args, timeout: float | None = None):
        """:meth:`post` and wait for the result (raises what ``fn`` raised; TimeoutError)."""
        return self.post(fn, *args).result(timeout)

    def close(self) -> None:
        """End the session from any thread: the run unwinds, :meth:`serve` returns."""
        self.inbox.put(None)

    def serve(self) -> None:
        """The engine thread's loop: serve posted work; run the program once it is launched
        and configured; return when the session ends."""
        try:
            while not self.done:
                item = self.inbox.get()
                if item is None:
                    break
                self._do(item)
                if self.config is not None and self.configured and not self.started:
                    self.started = True
                    self._run_loop()
        except Terminate:
            pass
        finally:
            self.done = True
            self.state = "ended"
            if self._built is not None:
                self._built.scheduler.close()
                self._built = None
            self._close_trace()
            self.cleanup.close()

    def _do(self, item) -> None:
        fn, args, fut = item
        if not fut.set_running_or_notify_cancel():
            return
        try:
            result = fn(*args)
        except (Restart, Terminate):
            fut.set_result(None)
            raise
        except Exception as exc:  # noqa: BLE001 - handed to the caller
            fut.set_exception(exc)
        else:
            fut.set_result(result)

    def _next(self, block: bool) -> bool:
        """Serve one posted piece of work; False when there is none (not blocking)."""
        try:
            item = self.inbox.get(block)
        except queue.Empty:
            return False
        if item is None:
            self.done = True
            raise Terminate()
        self._do(item)
        return True

    def emit(self, name: str, body: dict | None = None) -> None:
        self.on_event(name, body if body is not None else {})

    def output(self, text: str, category: str = "console") -> None:
        self.emit("output", {"category": category, "output": text if text.endswith("\n") else text + "\n"})

    # ------------------------------------------------------------------ set-up
    def launch(self, config: LaunchConfig) -> None:
        """Load, check and build the run of ``config`` (not started yet). Raises
        :class:`Refused` when the checker finds errors in the program's own module (the run
        would not start, as with ``krl run``)."""

        options = {**run_defaults(), **config.options}
        if is_cell_launch(options):
            self.cell = CellDebug.open(self, options)
            self.config = config
            return
        try:
            self.setup = self.cleanup.enter_context(run_setup(options))
        except RunSetupError as exc:
            raise Refused(str(exc)) from None
        self.config = config
        with collector.paused():
            try:
                rt, _ = self._build()
            finally:
                # the checked program and the tables live as long as the session: out of the
                # collector's sight (a full collection over them costs as much as loading them)
                collector.keep()
        errors = rt.program.errors_of(rt.program.module_of(rt.program.main_path))
        if errors:
            rt.scheduler.close()
            self._close_trace()
            self.config = None
            raise Refused("not started: the checker finds errors: " + "; ".join(str(d) for d in errors[:5]))
        self._built = rt

    def configuration_done(self) -> None:
        """The front end has set its breakpoints: the run starts once this work is done."""
        self.configured = True

    def set_breakpoints(self, path: str, specs: list[dict]) -> list[tuple[Breakpoint, bool, str | None]]:
        """Replace the line breakpoints of the file ``path``: each spec a dict with ``line``,
        ``condition``, ``hitCondition`` (at most MAX_DAP_BREAKPOINTS). Returns
        (breakpoint, verified, message) per spec."""
        real = os.path.realpath(path)
        bps = {}
        out = []
        for b in specs[:MAX_DAP_BREAKPOINTS]:
            bp = Breakpoint(self.next_bp, int(b.get("line", 0)), b.get("condition"), b.get("hitCondition"))
            self.next_bp += 1
            message = None
            verified = True
            if bp.condition is not None:
                try:
                    parse_expression(bp.condition)
                except ExpressionError as exc:
                    verified, message = False, f"condition: {exc}"
            if bp.hit_text is not None and bp.hit_test is None:
                verified, message = False, f"hit condition {bp.hit_text!r}: N, >=N, =N, >N or %N"
            if verified:
                bps[bp.line] = bp
            out.append((bp, verified, message))
        self.line_bps[real] = bps
        return out

    def set_function_breakpoints(self, specs: list[dict]) -> list[tuple[Breakpoint, bool]]:
        """Replace the function breakpoints: each spec a dict with ``name`` (a routine, any
        case), ``condition``, ``hitCondition``. Returns (breakpoint, verified) per spec."""
        self.func_bps = {}
        out = []
        for b in specs[:MAX_DAP_BREAKPOINTS]:
            name = str(b.get("name", "")).strip().upper()
            bp = Breakpoint(self.next_bp, 0, b.get("condition"), b.get("hitCondition"))
            self.next_bp += 1
            self.func_bps[name] = bp
            out.append((bp, bool(name)))
        return out

    # ------------------------------------------------------------------ control
    def need_stopped(self) -> None:
        if self.state != "stopped":
            raise Refused("the program is not stopped")

    def resume(self) -> None:
        """Continue (all threads)."""
        self.need_stopped()
        self.resumed = ("run", None)

    def step(self, kind: str, thread: int | None = None) -> None:
        """Step ``kind`` (over, in, out) in ``thread`` (default: the stopped one)."""
        self.need_stopped()
        task = self._task_of_thread(thread)
        self.resumed = ("run", (kind, task, view.depth(task)))

    def pause(self, robot=None) -> None:
        """Stop the running program at its next statement (or IPO cycle while it waits). In a
        cell, `robot` (a robot's runtime: the pendant's chosen robot) stops the cell in that
        robot's program (its next statement or IPO cycle; anywhere once it has ended)."""
        if self.state == "running":
            self.pause_req = True
            self.pause_in = robot if self.cell is not None else None

    def step_back(self) -> None:
        """Back to the previous statement (a stop inside statement n: to n's start)."""
        self.need_stopped()
        if self.cell is not None:
            raise Refused(NO_REVERSE)
        self.resumed = ("restart", Restart(max(1, self.stop_n - (0 if self.stop_mid else 1)), "step"))

    def reverse_continue(self) -> None:
        """Back to the last breakpoint hit before this stop (else the start)."""
        self.need_stopped()
        if self.cell is not None:
            raise Refused(NO_REVERSE)
        self.resumed = ("restart", Restart(0, "breakpoint", scan=self.stop_n + (1 if self.stop_mid else 0)))

    def terminate(self) -> None:
        """End the session; a run unwinds at once."""
        self.done = True
        if self.state in ("running", "stopped"):
            raise Terminate()

    # ------------------------------------------------------------------ edits
    def edit(self, label: str, apply) -> object:
        """Make a change at this stop (``apply(engine)``, on the live run) and record it for
        every replay; returns what ``apply`` returned. Raises :class:`Refused`."""
        self.need_stopped()
        result = apply(self)
        self.rt.changed_outside()
        self.edits.append(Edit(self.stop_where, label, apply))
        return result

    def edit_now(self, label: str, apply) -> object:
        """:meth:`edit`, also while the program runs (a front end's key that works at any time:
        an input set by hand, the override, a message acknowledged): made on the live run where
        the work is served (between two statements or IPO cycles) and recorded at that place
        (hook count, hook calls inside the statement) for every replay."""
        if self.state == "stopped":
            return self.edit(label, apply)
        if self.state != "running" or self.rt is None:
            raise Refused("no program is running")
        result = apply(self)
        self.rt.changed_outside()
        self.edits.append(Edit((self.n, self.sub), label, apply))
        return result

    def move(self, request) -> list:
        """A motion made at the stop outside the program (a jog): the robot.motion.MotionRequest
        ``request`` is planned and executed by the main run, within the operating mode's
        limits, and the engine waits until the robot stands; recorded as an edit. Returns the
        axes reached (deg). Raises :class:`Refused` (the controller's reason)."""
        self.need_stopped()
        task = self.stop_task
        if task is None or task.kind != "robot":
            raise Refused("stop the robot program first")

        def apply(engine: Engine) -> list:
            rt, cell = engine.rt, engine.cell
            # in a cell: the stopped task gives the cell's cycles back, the other robot programs
            # hold meanwhile (interp/debug/cellrun.py), whichever robot moves
            wait = (lambda: cell.wait_idle(engine, rt)) if cell is not None else (lambda: rt.wait_main_run(rt.robot))
            with engine._quiet(), cell.held() if cell is not None else contextlib.nullcontext():
                wait()
                try:
                    rt.controller.queue.enqueue(request)
                except RobotError as e:
                    raise Refused(e.message) from None
                wait()
            engine.flush_trace()
            return [float(v) for v in rt.controller.actual.axis_act()]
        return self.edit(getattr(request, "kind", "motion"), apply)

    def evaluate_now(self, text: str):
        """The value of the KRL expression ``text`` in the stopped frame, or, while the program
        runs, in the robot program's innermost frame (a watch list shown as the program goes on)."""
        if self.state == "stopped":
            return self.evaluate(text)
        if self.rt is None or self.state != "running":
            raise Refused("no program is running")
        robot = self.rt.robot
        return self._eval(text, robot.frame if robot is not None else None)

    def flush_trace(self) -> None:
        """Write what the trace file holds so far (at a stop, after an edit): a reader of the
        file sees the run up to here."""
        tr = self._trace
        if tr is not None:
            tr.flush()
            fh = getattr(tr, "_fh", None)
            if fh is not None:
                fh.flush()

    def set_variable(self, scope: Scope, name: str, value: str) -> str:
        """Assign the KRL expression ``value`` (evaluated in the stopped frame) to the
        variable ``name`` (any letter case) listed under ``scope``; the new value's text."""
        def apply(engine: Engine) -> str:
            engine._focus(scope.thread)
            target = None
            for n, ref in view.entries(engine.rt, engine._view_scope(scope)):
                if n.upper() == name.upper():
                    target = ref
            if isinstance(target, view.Const) and target.ref is not None:
                target = engine.rt.names.index(target.ref, [target.index], name.split("[")[0])
            if target is None or isinstance(target, view.Const) or not hasattr(target, "peek"):
                raise Refused(f"{name} cannot be set")
            engine._store(target, engine._eval(value, engine._top()[1]))
            return value_text(view.peek(target))
        return self.edit(f"{name} = {value}", apply)

    def assign(self, target: str, value: str, frame: Frame | None = None) -> str:
        """``target = value`` for the KRL texts ``target`` (a variable, an element, a
        component) and ``value``, both in ``frame`` (default: the stopped frame); the new
        value's text."""
        place = (frame.thread, frame.index) if frame is not None else None

        def apply(engine: Engine) -> str:
            engine._focus(place[0] if place is not None else None)
            f = engine._frame_at(place)
            try:
                ref = engine.tree.ref(engine._compile(target, f), f)
            except (AttributeError, TypeError):
                raise Refused(f"{target} is not a variable") from None
            engine._store(ref, engine._eval(value, f))
            return value_text(view.peek(ref))
        return self.edit(f"{target} = {value}", apply)

    def set_input(self, index: int, value: bool, now: bool = False) -> bool:
        """``$IN[index]`` set by hand (source ``operator`` in the trace) at the stop, or with
        `now` also while the program runs (:meth:`edit_now`: the pendant's key); the cell's
        rules stay active. Returns the input's value. Raises :class:`Refused`."""

        if not isinstance(index, int) or isinstance(index, bool) or not 1 <= index <= N_DIGITAL:
            raise Refused(f"input: an index 1..{N_DIGITAL}")

        def apply(engine: Engine) -> bool:
            return engine.rt.controller.set_input(index, value)
        return (self.edit_now if now else self.edit)(f"$IN[{index}] = {'TRUE' if value else 'FALSE'}", apply)

    def backward_motion(self) -> int:
        """One backward motion (#BSTEP, T1/T2) at the stop; no statement runs. Returns the
        motion events retraced. Raises :class:`Refused` (why not)."""
        self.need_stopped()
        task = self.stop_task
        if self.cell is not None:
            self.cell.need_stop_in(self, "backward motion")
        elif task is None or task.kind != "robot" or self.stop_thread != view.ROBOT_THREAD:
            raise Refused("backward motion: stop the robot program first")

        def apply(engine: Engine) -> int:
            rt = engine.rt
            events_before = len(rt.stepping.history.records)
            with engine._quiet(), engine.cell.held() if engine.cell is not None else contextlib.nullcontext():
                ok = rt.stepping.backward_step(rt.robot)
            engine.flush_trace()
            if not ok:
                raise Refused(engine.last_refusal or "backward motion not possible")
            return events_before - len(rt.stepping.history.records)
        return self.edit("backward motion", apply)

    def _apply_pending(self, task) -> None:
        """A replay reached the place of recorded edits (``task``'s hook): make them again,
        as at that stop."""
        if self._pending[0].where != (self.n, self.sub):
            return
        self.stop_task = task
        self.stop_thread = self._thread_of(task)
        while self._pending and self._pending[0].where == (self.n, self.sub):
            e = self._pending.pop(0)
            try:
                e.apply(self)
                self.rt.changed_outside()
            except Refused as exc:
                self.output(f"replay: the edit {e.label} could not be made again: {exc}", "stderr")

    def _store(self, ref, value) -> None:
        try:
            self.rt.names.assign(ref, value)
        except KrlRuntimeError as exc:
            raise Refused(exc.message) from None

    # ------------------------------------------------------------------ inspection
    def threads(self) -> list[tuple[int, str]]:
        """(thread id, name) of the robot program, each running interrupt handler and each
        submit program."""
        if self.rt is None:
            return []
        return [(tid, name) for tid, name, _t, _f in self._thread_list()]

    def stack(self, thread: int) -> list[Frame]:
        """The frames of ``thread``, innermost first."""
        self.need_stopped()
        self._focus(thread)
        out = []
        for t, _name, task, frames in self._thread_list():
            if t != thread:
                continue
            for i, f in enumerate(frames):
                line = f.line or 1
                if i == 0 and task is self.stop_task and self.stop_error is not None and t == self.stop_thread:
                    line = self.stop_error.line or line
                path = f.module.path if f.module is not None else ""
                out.append(Frame(t, i, task, f, f.name, str(path), line))
        return out

    def scopes(self, frame: Frame) -> list[tuple[str, Scope]]:
        """(name, scope) of the scopes of ``frame``: Locals, Module data, Globals
        ($config.dat), System variables, I/O."""
        kinds = ("locals", "module", "globals", "sysvars", "io")
        return [(name, Scope(kind, frame.thread, frame.index)) for name, kind in zip(view.SCOPE_NAMES, kinds)]

    def variables(self, scope: Scope) -> list[Variable]:
        """The variables listed under ``scope``, with their values."""
        self.need_stopped()
        self._focus(scope.thread if scope.kind != "value" else None)
        out = []
        for name, ref in view.entries(self.rt, self._view_scope(scope)):
            v = view.peek(ref)
            kids = None
            if has_children(v) and hasattr(ref, "peek"):
                kids = Scope(scope.kind, scope.thread, scope.index, scope.path + (name,), scope.value)
            text = v.text if isinstance(v, view.Invalid) else value_text(v)
            out.append(Variable(name, text, None if isinstance(v, view.Invalid) or v is None else type_name_of(v),
                                kids))
        return out

    def evaluate(self, text: str, frame: Frame | None = None):
        """The value of the KRL expression ``text`` in ``frame`` (default: the stopped frame)."""
        self.need_stopped()
        self._focus(frame.thread if frame is not None else None)
        f = frame.frame if frame is not None else self._top()[1]
        return self._eval(text, f)

    def value_scope(self, value) -> Scope | None:
        """The parts of an evaluated value (None for a scalar)."""
        return Scope("value", value=value) if has_children(value) else None

    def exception(self):
        """The run-time error of this stop (a KrlRuntimeError); Refused when there is none."""
        self.need_stopped()
        if self.stop_error is None:
            raise Refused("not stopped at a run-time error")
        return self.stop_error

    def pointers(self) -> dict:
        """The pendant's two pointers and the simulated time: ``advanceRun`` — the statement
        the robot interpreter reached (the advance run); ``mainRun`` — the motion statement
        the robot executes now (None when it stands); ``time`` (s), ``cycle`` (IPO cycles),
        ``step`` (statements so far: the position stepBack counts in), ``runMode``."""
        rt = self.rt
        if rt is None:
            return {}
        ctl = rt.controller
        robot = rt.robot
        adv = {"path": robot.file, "line": robot.line} if robot is not None and robot.at is not None else None
        req = ctl.current_request()
        main = {"path": req.file, "line": req.line, "motion": req.id} if req is not None and req.line else None
        return {"advanceRun": adv, "mainRun": main, "time": round(ctl.time, 6), "cycle": ctl.cycle,
                "step": self.n, "runMode": rt.stepping.run_mode}

    def _view_scope(self, scope: Scope) -> tuple:
        """The view's scope tuple (interp/debug/view.py) of ``scope`` on this run."""
        if scope.kind == "value":
            base = ("ref", view.Const(scope.value, None, None), "")
        elif scope.kind in ("locals", "module"):
            f = self._frame_at((scope.thread, scope.index))
            if f is None:
                raise Refused("no such frame")
            base = ("locals", f) if scope.kind == "locals" else ("module", f.module)
        else:
            base = (scope.kind,)
        for name in scope.path:
            ref = next((r for n, r in view.entries(self.rt, base) if n == name), None)
            if ref is None:
                raise Refused(f"no variable {name}")
            base = ("ref", ref, name)
        return base

    def _frame_at(self, place: tuple | None):
        """The runtime frame at (thread, index) of this stop; None: the stopped frame."""
        if place is None:
            return self._top()[1]
        for t, _name, _task, frames in self._thread_list():
            if t == place[0] and place[1] < len(frames):
                return frames[place[1]]
        return None

    def _thread_list(self) -> list:
        """(thread id, name, task, frames) of the run's threads, or every robot's in a cell."""
        return self.cell.thread_list() if self.cell is not None else view.thread_list(self.rt)

    def _thread_of(self, task) -> int:
        return self.cell.thread_of(self.rt, task) if self.cell is not None else view.thread_of(self.rt, task)

    def _focus(self, thread: int | None) -> None:
        """In a cell: inspect the run of robot whose `thread` it is (None: the stopped one's)."""
        if self.cell is not None:
            self.cell.focus(self, thread)

    def _top(self) -> tuple:
        task = self.stop_task
        return task, task.frame if task is not None else None

    def _task_of_thread(self, tid):
        for t, _n, task, _f in self._thread_list():
            if t == tid:
                return task
        return self.stop_task

    def _compile(self, text: str, frame):
        try:
            return compile_in_frame(self.rt, text, frame)
        except ExpressionError as exc:
            raise Refused(str(exc)) from None

    @contextlib.contextmanager
    def _quiet(self):
        """Hooks ignored (an evaluation, an edit): nothing it runs counts as a step."""
        saved = self.busy
        self.busy = True
        try:
            yield
        finally:
            self.busy = saved

    def _eval(self, text: str, frame):
        """Evaluate a KRL expression in ``frame`` (no statement hook, no trace, no end of
        the time slice while it runs: the runtime's ``evaluation``)."""
        expr = self._compile(text, frame)
        try:
            with self._quiet(), self.rt.evaluation():
                return self.tree.eval(expr, frame)
        except KrlRuntimeError as exc:
            raise Refused(exc.message + (f" ({exc.number})" if exc.number else "")) from None
        except ControlSignal:
            raise Refused("the expression cannot be evaluated here") from None

    # ------------------------------------------------------------------ the run
    def _build(self):
        """A new run of the launch's setup (interp.run.RunSetup), its trace (``trace_path``)
        written anew: the trace file always holds the run as it stands."""
        setup = self.setup
        self._close_trace()
        self._trace = setup.trace_writer()
        return setup.make_runtime(RunSinks(trace=self._trace), interactive=self.interactive)

    def _close_trace(self) -> None:
        if self._trace is not None:
            self._trace.close()
            self._trace = None

    def _run_loop(self) -> None:
        if self.cell is not None:
            self.cell.run(self, Terminate)
            return

        target, reason, scan = None, "step", None
        while True:
            rt, self._built = self._built, None
            if rt is None:
                rt, _ = self._build()
            self.rt = rt
            self.tree = TreeInterpreter(rt)
            rt.stepping.set_hooks(stmt=self.on_statement, step=self.on_step_stop, error=self.on_error, cycle=self.on_cycle)
            if self.on_runtime is not None:
                self.on_runtime(rt)
            self.n = self.sub = 0
            self.target, self.target_reason, self.scan, self.scan_last = target, reason, scan, 0
            self._pending = list(self.edits)
            self.stepping = None
            self.prev_frame = {}
            self.last_refusal = None
            for bps in list(self.line_bps.values()) + [self.func_bps]:
                for bp in bps.values():
                    bp.hits = 0
            self.state = "running"
            try:
                res = rt.run()
            except Restart as r:
                rt.scheduler.close()
                target, reason, scan = r.target, r.reason, r.scan
                if scan is None:        # back before an edit: it is forgotten
                    self.edits = [e for e in self.edits if e.where <= (target, 0)]
                continue
            except Terminate:
                rt.scheduler.close()
                self.state = "ended"
                self._close_trace()
                self.emit("terminated")
                return
            break
        self.state = "ended"
        # the trace whole before a front end hears of the end (it may read the file at once):
        # nothing writes to it after the run (an edit or a jog needs a stop or a running program)
        self._close_trace()
        where = f" at {res.file}:{res.line}" if res.line else ""
        self.output(f"program ended: {res.reason}{where}{': ' + res.text if res.text else ''} "
                    f"(t={res.sim_time:.3f} s)")
        self.emit("exited", {"exitCode": res.exit_code})
        self.emit("terminated")

    # ------------------------------------------------------------------ hooks
    def on_statement(self, task, info) -> None:
        if self.busy:       # a function called by a watch, an edit: not counted
            return
        self.n += 1
        self.sub = 0
        if self.n > MAX_DAP_REPLAY_STEPS:
            return
        hit = self._breakpoint(task, info)
        if self._pending:
            self._apply_pending(task)
        if self.scan is not None:
            if hit is not None and self.n < self.scan:
                self.scan_last = self.n
            if self.n >= self.scan - 1:
                raise Restart(self.scan_last or self.entry_n or 1, "breakpoint" if self.scan_last else "entry")
            return
        if self.target is not None:
            if self.n < self.target:
                return
            self.target = None
            self.stop(task, self.target_reason)
            return
        self._pump()
        reason, desc = None, None
        if self.entry_n is None and task is self.rt.robot:
            self.entry_n = self.n
            if self.config.stop_on_entry:
                reason = "entry"
        elif self.pause_req and self._pause_here(task):
            reason = "pause"
        elif self.stepping is not None and self._step_done(task):
            reason = "step"
        if hit is not None:
            reason, desc = reason or ("function breakpoint" if hit[1] else "breakpoint"), hit[2]
        if reason is not None:
            self.stop(task, reason, description=desc, bp=hit[0] if hit else None)

    def _mid(self, task) -> bool:
        """A hook call inside a statement: counted; False when the engine ignores it
        (busy, a replay or scan on its way)."""
        if self.busy:
            return False
        self.sub += 1
        if self._pending:
            self._apply_pending(task)
        return self.target is None and self.scan is None

    def on_cycle(self, task) -> None:
        """A task resumes in a new IPO cycle (it waits: WAIT FOR, WAIT SEC, the advance-run
        stop, a full motion queue): a pause requested meanwhile stops it there."""
        if not self._mid(task):
            return
        self._pump()
        if self.pause_req and self._pause_here(task):
            self.stop(task, "pause", description="paused while waiting", mid=True)

    def _pause_here(self, task) -> bool:
        """A pause stops at `task`: any task, or in a cell the robot program :meth:`pause` named."""
        rt = self.pause_in
        return rt is None or task is rt.robot or rt.robot.done

    def on_step_stop(self, task, mode: str, text: str | None) -> None:
        if text:
            self.last_refusal = text
        if not self._mid(task):
            return
        what = {"MSTEP": "MSTEP: the motion has ended", "ISTEP": "ISTEP: before the next statement",
                "BSTEP": "BSTEP: the backward motion has ended"}.get(mode, mode)
        self.stop(task, "step", description=text or what, mid=True)

    def on_error(self, task, frame, err) -> None:
        if not self._mid(task) or not self.break_on_errors:
            return
        num = f" ({err.number})" if err.number is not None else ""
        self.stop(task, "exception", description=f"run-time error{num}", text=err.message, error=err, mid=True)

    def _breakpoint(self, task, info):
        """(bp, is_function, description) when a breakpoint stops here (its hit counted), else None."""
        frame = task.frame
        fb = None
        prev = self.prev_frame.get(task)
        self.prev_frame[task] = frame
        if self.func_bps and frame is not None:
            # a routine's first statement: its frame is new, deeper than the last one seen
            if prev is not frame and (prev is None or frame.caller is prev or frame.depth > prev.depth):
                fb = self.func_bps.get(frame.name.upper())
        real = self.realpaths.get(info.file)
        if real is None:
            real = self.realpaths[info.file] = os.path.realpath(info.file) if info.file else ""
        lb = self.line_bps.get(real, {}).get(info.line) if self.line_bps else None
        for bp, is_fn in ((fb, True), (lb, False)):
            if bp is None:
                continue
            desc = None
            if bp.condition is not None:
                try:
                    ok = self._condition(bp, frame)
                except Refused as exc:
                    ok, desc = True, f"condition error: {exc}"
                if not ok:
                    continue
            bp.hits += 1
            if bp.hit_test is not None and not bp.hit_test(bp.hits):
                continue
            return bp, is_fn, desc
        return None

    def _condition(self, bp: Breakpoint, frame) -> bool:
        v = self._eval(bp.condition, frame)
        try:
            return bool(to_bool(v, "breakpoint condition"))
        except KrlRuntimeError as exc:
            raise Refused(exc.message) from None

    def _step_done(self, task) -> bool:
        kind, t0, d0 = self.stepping
        if task is not t0:
            return False
        d = view.depth(task)
        return kind == "in" or (kind == "over" and d <= d0) or (kind == "out" and d < d0)

    def _pump(self) -> None:
        """Serve the work that arrived while the program runs (pause, breakpoints)."""
        while self._next(block=False):
            pass

    def stop(self, task, reason: str, description: str | None = None, text: str | None = None,
             bp=None, error=None, mid: bool = False) -> None:
        """Stop every thread here and serve posted work until a piece of it resumes."""
        self.state = "stopped"
        self.stop_mid = mid
        self.stop_task = task
        self.stop_n = self.n
        self.stop_where = (self.n, self.sub)
        self.stop_error = error
        self.pause_req = False
        self.stepping = None
        self.resumed = None
        tid = self._thread_of(task)
        self.stop_thread = tid
        body = {"reason": reason, "threadId": tid, "allThreadsStopped": True}
        if description:
            body["description"] = description
        if text:
            body["text"] = text
        if bp is not None:
            body["hitBreakpointIds"] = [bp.id]
        self.stop_body = body
        self.flush_trace()
        self.emit("stopped", dict(body))
        self.emit("krl/pointers", self.pointers())
        while self.resumed is None:
            self._next(block=True)
        action, arg = self.resumed
        self.state = "running"
        if action == "restart":
            raise arg
        self.stepping = arg
        self.prev_frame[task] = task.frame


def thread_main(engine: Engine, name: str = "krl-debug-engine") -> threading.Thread:
    """Start ``engine.serve()`` on a thread of its own (a front end that keeps its own thread
    for a web server); the thread."""
    t = threading.Thread(target=engine.serve, name=name, daemon=True)
    t.start()
    return t


__all__ = ["Engine", "Frame", "LaunchConfig", "Refused", "Restart", "Scope", "Terminate", "Variable",
           "thread_main"]
