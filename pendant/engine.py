"""The pendant's handle on the run: the one run-control engine of ``krl debug``
(interp/debug/session.py), driven in this process, on a thread of its own.

Nothing of run control is written here. Every key of the pendant is a request of the debug
engine (``continue``, ``pause``, ``krl/backwardStep``, ``disconnect``, ``setBreakpoints``,
``setVariable`` ...) put on its request queue, exactly as an editor's DAP client would send it,
and answered on that engine's thread, where the program and the simulated controller live.
The pendant's own requests (override, operating mode, run mode, an input set by hand, a jog,
the message window, the state snapshot) are engine requests too, served on the same thread
between two statements or IPO cycles (:class:`_Engine`), so that nothing touches the runtime
from the web server's thread.

Display: once per IPO cycle the engine thread publishes :attr:`Engine.live` (simulated time,
$AXIS_ACT, the TCP, the two pointers) and, when the run is paced (``realtime``), sleeps until
the wall clock has caught up with the simulated clock. The web server reads ``live`` at display
rate; a replay (step back) is never paced.
"""

from __future__ import annotations

import itertools
import queue
import threading
import time
from concurrent.futures import Future
from pathlib import Path

from interp.debug.session import DebugSession, Terminate, _Refused

#: the operating modes and run modes the keys offer (robot/limits.py, interp/runtime/runmode.py)
MODES_OP = ("T1", "T2", "AUT", "EXT")
RUN_MODES = ("GO", "MSTEP", "ISTEP")
#: jog: the coordinate systems and the increment of one press of a jog key (mm, deg)
JOG_SYSTEMS = ("AXIS", "WORLD", "BASE", "TOOL")
JOG_MAX_STEP = 100.0


class EngineError(Exception):
    """A request the engine refused (its message is the pendant's text)."""


class Engine:
    """One selected program: a debug engine running on its own thread.

    ``on_event(msg)`` receives the engine's events (``stopped``, ``krl/pointers``, ``output``,
    ``terminated`` ...) on the engine thread; it must only hand them on."""

    def __init__(self, on_event, *, realtime: bool = True) -> None:
        self.on_event = on_event
        self.realtime = realtime
        self.session: _Engine | None = None
        self.thread: threading.Thread | None = None
        self.live: dict = {}
        self._seq = itertools.count(1)
        self._pending: dict[int, Future] = {}
        self._lock = threading.Lock()

    # ------------------------------------------------------------------ lifecycle
    def select(self, program: str, *, workspace: str | None, inputs: str | None, mode: str,
               run_mode: str, trace: str | None, submit: list[str]) -> None:
        """Select ``program`` (a .src path): launch it and stop at its first statement, as the
        smartPAD's program pointer stands on the first line after Select. Raises
        :class:`EngineError` (the checker's errors, a bad cell file)."""
        self.cancel()
        s = _Engine(self)
        self.session = s
        self.thread = threading.Thread(target=self._serve, args=(s,), name="krl-pendant-engine", daemon=True)
        self.thread.start()
        self.request("initialize", {"adapterID": "krl-pendant"})
        self.request("launch", {"program": program, "workspace": workspace, "inputs": inputs,
                                "mode": mode, "runMode": run_mode, "stopOnEntry": True,
                                "maxSimTime": 7 * 24 * 3600.0, "submit": submit, "trace": trace})
        self.request("setExceptionBreakpoints", {"filters": ["runtime_error"]})
        self.request("configurationDone", {})

    def cancel(self, timeout: float = 10.0) -> None:
        """Cancel the selected program (the run ends at once)."""
        s, t = self.session, self.thread
        if s is None:
            return
        s.inbox.put(None)
        if t is not None:
            t.join(timeout)
        self.session = self.thread = None
        self.live = {}
        with self._lock:
            for f in self._pending.values():
                if not f.done():
                    f.set_exception(EngineError("the program was cancelled"))
            self._pending.clear()

    def _serve(self, s: "_Engine") -> None:
        try:
            s.serve()
        except Exception as exc:  # noqa: BLE001 - the engine thread never dies with a traceback
            self.on_event({"type": "event", "event": "output",
                           "body": {"category": "stderr", "output": f"engine stopped: {type(exc).__name__}: {exc}\n"}})
            self.on_event({"type": "event", "event": "terminated"})

    # ------------------------------------------------------------------ requests
    def request(self, command: str, arguments: dict | None = None, timeout: float = 60.0) -> dict:
        """Send one request to the engine and wait for its answer; the response body. Raises
        :class:`EngineError` when it is refused, when nothing is selected or on timeout."""
        s = self.session
        if s is None or s.done:
            raise EngineError("no program is selected")
        seq = next(self._seq)
        fut: Future = Future()
        with self._lock:
            self._pending[seq] = fut
        s.inbox.put({"type": "request", "seq": seq, "command": command, "arguments": arguments or {}})
        try:
            resp = fut.result(timeout)
        except TimeoutError:
            raise EngineError(f"{command}: no answer within {timeout:.0f} s") from None
        finally:
            with self._lock:
                self._pending.pop(seq, None)
        if not resp.get("success", False):
            raise EngineError(resp.get("message") or f"{command} refused")
        return resp.get("body") or {}

    def _receive(self, msg: dict) -> None:
        """The engine's output (engine thread): a response completes its request, an event
        goes to ``on_event``."""
        if msg.get("type") == "response":
            with self._lock:
                fut = self._pending.get(msg.get("request_seq"))
            if fut is not None and not fut.done():
                fut.set_result(msg)
            return
        self.on_event(msg)

    @property
    def selected(self) -> bool:
        return self.session is not None and not self.session.done


class _Engine(DebugSession):
    """The debug engine with the pendant's requests (served on the engine thread, running or
    stopped) and the pacing/display hook."""

    def __init__(self, owner: Engine) -> None:
        super().__init__(None, None)
        self.owner = owner
        self._pace0: tuple[float, float] | None = None
        self.trace_path: str | None = None
        self._trace = None
        self.notes: list[dict] = []           # the simulator's own notes (not KRL messages)
        self.signals: list[dict] | None = None
        self.stop_reason: str | None = None
        self.stop_description: str | None = None

    # wire: in-process, no framing
    def send(self, msg: dict) -> None:
        with self.wlock:
            self.seq += 1
            msg["seq"] = self.seq
        self.owner._receive(msg)

    def serve(self) -> int:
        try:
            while not self.done:
                msg = self.inbox.get()
                if msg is None:
                    break
                self.dispatch(msg)
                if self.launch_args is not None and self.configured and not self.started:
                    self.started = True
                    self.run_loop()
        except Terminate:
            pass
        finally:
            self.done = True
            self._close_trace()
            self.cleanup.close()
        return 0

    # ------------------------------------------------------------------ the run
    def req_launch(self, req, args) -> None:
        self.trace_path = args.get("trace")
        super().req_launch(req, args)

    def _build(self):
        from interp.run import make_runtime, robot_for  # noqa: PLC0415
        from krl.limits import MAX_DAP_REPLAY_STEPS  # noqa: PLC0415
        from robot.trace import TraceWriter  # noqa: PLC0415

        a = self.launch_args
        machine = robot_for(a["program"], a["workspace"], None, a["inputs"])
        trace = None
        self._close_trace()
        if self.trace_path and self.started:      # not for the launch's check, only for runs
            trace = self._trace = TraceWriter(self.trace_path)
            trace.write("robot", 0.0, name=machine.name, source=machine.source,
                        trafoname=machine.trafoname or None)
        rt, interp = make_runtime(a["program"], workspace=a["workspace"], inputs=a["inputs"], trace=trace,
                                  max_sim_time=a["max_sim_time"], max_steps=MAX_DAP_REPLAY_STEPS,
                                  interp=a["interp"], mode=a["mode"], submit=a["submit"],
                                  run_mode=a["run_mode"], robot=machine)
        rt.messages.interactive = True
        rt.controller.add_cyclic(self._cycle)
        self._observe_notes(rt.controller)
        if self.signals is None and self.started:
            from .state import signals_of  # noqa: PLC0415

            self.signals = signals_of(rt)
        self._pace0 = None
        return rt, interp

    def _close_trace(self) -> None:
        if self._trace is not None:
            self._trace.close()
            self._trace = None

    def _flush_trace(self) -> None:
        if self._trace is not None:
            self._trace.flush()
            fh = getattr(self._trace, "_fh", None)
            if fh is not None:
                fh.flush()

    def req_krl_backwardStep(self, req, args) -> None:  # noqa: N802
        try:
            super().req_krl_backwardStep(req, args)
        finally:
            self._flush_trace()

    def _cycle(self, ctl) -> None:
        """Once per IPO cycle (engine thread): publish the live pose, pace to the wall clock."""
        if self.rt is None or ctl is not self.rt.controller:
            return
        replay = self.target is not None or self.scan is not None
        robot = self.rt.robot
        req = ctl.current_request()
        self.owner.live = {
            "time": round(ctl.time, 6), "axes": [float(v) for v in ctl.axis_act()],
            "blending": getattr(ctl, "_blend", None) is not None,
            "pointers": {"advanceRun": {"path": robot.file, "line": robot.line}
                         if robot is not None and robot.at is not None else None,
                         "mainRun": {"path": req.file, "line": req.line} if req is not None and req.line else None}}
        if replay or not self.owner.realtime or self.busy and not getattr(self, "pacing_busy", False):
            self._pace0 = None
            return
        now = time.perf_counter()
        if self._pace0 is None:
            self._pace0 = (now, ctl.time)
            return
        ahead = (ctl.time - self._pace0[1]) - (now - self._pace0[0])
        if ahead > 0:
            time.sleep(ahead)
        elif ahead < -0.25:
            self._pace0 = (now, ctl.time)    # fell behind (a stop, a slow cycle): restart the pacing

    def _observe_notes(self, ctl) -> None:
        """Keep the controller's messages that are the simulator's own notes (not the KRL
        message functions'), newest last, at most MAX_KRL_MESSAGES."""
        from krl.limits import MAX_KRL_MESSAGES  # noqa: PLC0415

        inner = ctl.message
        self.notes = []

        def message(text, motion_id=None, number=None):
            if not (text.startswith("KRL message: ") or text.startswith("KRL dialog")):
                self.notes.append({"time": round(ctl.time, 3), "text": str(text)[:300]})
                del self.notes[:-MAX_KRL_MESSAGES]
            inner(text, motion_id, number)
        ctl.message = message

    def run_loop(self) -> None:
        try:
            super().run_loop()
        finally:
            self._close_trace()

    def stop(self, task, reason: str, description: str | None = None, *args, **kw) -> None:
        self._pace0 = None                   # time stands while stopped
        self._flush_trace()                  # the trace up to the stop is on disk while it stands
        self.stop_reason, self.stop_description = reason, description or kw.get("text")
        super().stop(task, reason, description, *args, **kw)

    # ------------------------------------------------------------------ watch list
    def _watch_frame(self):
        task = self.stop_task if self.state == "stopped" else (self.rt.robot if self.rt is not None else None)
        return task.frame if task is not None else None

    def watch_value(self, text: str) -> str:
        """The value of the KRL expression ``text`` in the robot program's innermost frame
        (the stop's while stopped), as the debugger's watch shows it."""
        from interp.debug.values import value_text  # noqa: PLC0415

        return value_text(self._eval(text, self._watch_frame()))

    def req_krl_setWatch(self, req, args) -> None:  # noqa: N802
        """Assign ``value`` (a KRL expression) to the variable ``expr`` (a name, an element, a
        component) while the program stands."""
        from interp.runtime.errors import KrlRuntimeError  # noqa: PLC0415

        from .state import MAX_WEB_EXPRESSION_CHARS  # noqa: PLC0415

        self._need_stopped()
        target, value = str(args.get("expr", "")), str(args.get("value", ""))
        if len(target) > MAX_WEB_EXPRESSION_CHARS or len(value) > MAX_WEB_EXPRESSION_CHARS:
            raise _Refused(f"at most {MAX_WEB_EXPRESSION_CHARS} characters")
        frame = self._watch_frame()
        self._assign(target, self._eval(value, frame), frame)
        try:
            self.respond(req, {"value": self.watch_value(target)})
        except KrlRuntimeError as exc:
            raise _Refused(exc.message) from None

    def _assign(self, target: str, value, frame) -> None:
        from interp.debug.expr import ExpressionError, compile_in_frame  # noqa: PLC0415
        from interp.runtime.errors import KrlRuntimeError  # noqa: PLC0415

        try:
            expr = compile_in_frame(self.rt, target, frame)
            ref = self.tree.ref(expr, frame)
            self.rt.assign(ref, value)
        except ExpressionError as exc:
            raise _Refused(str(exc)) from None
        except KrlRuntimeError as exc:
            raise _Refused(exc.message) from None
        except (AttributeError, TypeError):
            raise _Refused(f"{target} is not a variable") from None

    # ------------------------------------------------------------------ touch-up
    def req_krl_touchUp(self, req, args) -> None:  # noqa: N802
        """Touch up the point ``name`` of the data list ``path`` (inside the workspace, checked
        by the server) with the actual position; the running program's copy of the point gets
        the same values."""
        from .touchup import TouchUpError, touch_up  # noqa: PLC0415

        self._need_stopped()
        rt = self._rt()
        if rt.mode_op not in ("T1", "T2"):
            raise _Refused("touch-up: only in T1 or T2")
        name = str(args.get("name", ""))
        if not name.replace("_", "").replace("$", "").isalnum() or len(name) > 24:
            raise _Refused("touch-up: a point name")
        pos = rt.controller.pos_act()
        axes = [float(v) for v in rt.controller.axis_act()]
        try:
            new = touch_up(Path(str(args.get("path"))), name, pos, axes)
        except TouchUpError as exc:
            raise _Refused(str(exc)) from None
        except OSError as exc:
            raise _Refused(f"touch-up: cannot write the data list ({exc.strerror})") from None
        frame = self._watch_frame()
        for k, v in new.items():
            try:
                self._assign(f"{name}.{k}", v, frame)
            except _Refused:
                pass                              # not visible here: the file holds the new point
        self.respond(req, {"name": name, "values": new})

    # ------------------------------------------------------------------ pendant requests
    def _rt(self):
        if self.rt is None:
            raise _Refused("no program is running")
        return self.rt

    def req_krl_override(self, req, args) -> None:
        """$OV_PRO (0..100 %): applies to the motions planned from now on."""
        v = args.get("value")
        if not isinstance(v, int) or isinstance(v, bool) or not 0 <= v <= 100:
            raise _Refused("override: an integer 0..100")
        self._rt().sysvars.store["$OV_PRO"] = v
        self.respond(req, {"value": v})

    def req_krl_runMode(self, req, args) -> None:  # noqa: N802
        mode = str(args.get("value", "")).upper()
        if mode not in RUN_MODES:
            raise _Refused(f"run mode {mode!r}: one of {', '.join(RUN_MODES)}")
        self._rt().set_run_mode(mode)
        self.respond(req, {"value": mode})

    def req_krl_modeOp(self, req, args) -> None:  # noqa: N802
        """The operating mode, changed only while the program stands (as on the robot, where
        turning the key switch stops the program)."""
        from robot.limits import normalise_mode  # noqa: PLC0415

        mode = str(args.get("value", "")).upper()
        if mode not in MODES_OP:
            raise _Refused(f"operating mode {mode!r}: one of {', '.join(MODES_OP)}")
        rt = self._rt()
        if self.state == "running":
            raise _Refused("operating mode: stop the program first")
        m = normalise_mode(mode)
        rt.mode_op = m
        rt.controller.mode_op = m
        rt.controller.model.mode = m
        self.respond(req, {"value": mode})

    def req_krl_setInput(self, req, args) -> None:  # noqa: N802
        """``$IN[n]`` set by hand (source ``operator`` in the trace); the cell rules stay active."""
        from robot.io import N_DIGITAL  # noqa: PLC0415

        n = args.get("index")
        if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= N_DIGITAL:
            raise _Refused(f"input: an index 1..{N_DIGITAL}")
        ctl = self._rt().controller
        ctl.io.now = ctl.time
        ctl.io.set_in(n, bool(args.get("value")), "operator")
        self.respond(req, {"index": n, "value": ctl.get_in(n)})

    def req_krl_jog(self, req, args) -> None:
        """One jog increment in T1 with the program stopped: ``system`` AXIS (``axis`` 1..6,
        ``step`` deg) or WORLD/BASE/TOOL (``axis`` X,Y,Z,A,B,C, ``step`` mm or deg), as a PTP
        (axis) or LIN_REL (Cartesian) under the T1 speed limits (robot/limits.py)."""
        from robot.motion import NULLFRAME, MotionRequest  # noqa: PLC0415

        rt = self._rt()
        self._need_stopped()
        if rt.mode_op != "T1":
            raise _Refused(f"jog: only in T1 (operating mode {rt.mode_op})")
        system = str(args.get("system", "")).upper()
        step = args.get("step")
        if system not in JOG_SYSTEMS:
            raise _Refused(f"jog: coordinate system one of {', '.join(JOG_SYSTEMS)}")
        if not isinstance(step, (int, float)) or isinstance(step, bool) or not 0 < abs(step) <= JOG_MAX_STEP:
            raise _Refused(f"jog: a step of at most {JOG_MAX_STEP:g} mm or deg")
        task = self.stop_task
        if task is None or task.kind != "robot":
            raise _Refused("jog: stop the robot program first")
        from interp.runtime.motion import params_from  # noqa: PLC0415

        params = params_from(rt.sysvars.store).with_(ov_pro=100.0)
        ctl = rt.controller
        if system == "AXIS":
            axis = args.get("axis")
            if axis not in (1, 2, 3, 4, 5, 6):
                raise _Refused("jog: axis 1..6")
            q = ctl.axis_setpoint()
            target = {f"A{i + 1}": float(v) for i, v in enumerate(q)}
            target[f"A{axis}"] += float(step)
            req_m = MotionRequest("PTP", target, params)
        else:
            comp = str(args.get("axis", "")).upper()
            if comp not in ("X", "Y", "Z", "A", "B", "C"):
                raise _Refused("jog: component X, Y, Z, A, B or C")
            if system == "WORLD":
                params = params.with_(base=NULLFRAME)
            req_m = MotionRequest("LIN", {comp: float(step)}, params, relative=True,
                                  rel_frame="TOOL" if system == "TOOL" else "BASE")
        from robot.errors import RobotError  # noqa: PLC0415

        self.busy = True
        try:
            rt.wait_main_run(task)
            try:
                ctl.enqueue(req_m)
            except RobotError as e:
                raise _Refused(f"jog: {e.message}") from None
            rt.wait_main_run(task)
        finally:
            self.busy = False
            self._flush_trace()
        self.respond(req, {"axes": [float(v) for v in ctl.axis_act()]})

    def req_krl_message(self, req, args) -> None:
        """Acknowledge a message (``ack``: its handle) or answer a dialog (``answer``: the
        softkey number) of the message window."""
        rt = self._rt()
        handle = args.get("handle")
        win = rt.messages
        try:
            if args.get("answer") is not None:
                win.answer(handle, args.get("answer"))
            else:
                win.acknowledge(handle)
        except ValueError as exc:
            raise _Refused(str(exc)) from None
        self.respond(req, {})

    def req_krl_state(self, req, args) -> None:
        """The snapshot the page shows (pendant/state.py)."""
        from .state import snapshot  # noqa: PLC0415

        self.respond(req, snapshot(self, args))


def program_label(path: str | Path, root: str | Path | None) -> str:
    """A program's path as the page shows it: relative to the workspace root."""
    p = Path(path)
    try:
        return str(p.resolve().relative_to(Path(root).resolve())) if root else p.name
    except ValueError:
        return p.name


__all__ = ["Engine", "EngineError", "MODES_OP", "RUN_MODES", "JOG_SYSTEMS", "program_label"]
_ = queue  # the engine's inbox is a queue.Queue (interp/debug/session.py)
