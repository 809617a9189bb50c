"""`krl debug`: a Debug Adapter Protocol server over one run of a KRL program (issue 24;
docs/editors.md, "Debugging").

How it runs (docs/architecture.md, "Debugger"): the program runs in this process, on the
thread that serves the protocol, exactly as ``krl run`` runs it (interp/run.py
``make_runtime``: the cooperative tasks of interp/runtime/scheduler.py, each in a greenlet).
A reader thread only parses messages into a queue. The debugger sees the program through
three hooks of :class:`interp.runtime.core.Runtime`, shared by both interpreters:

* ``stmt_hook(task, info)`` before every statement (``Runtime.before_statement``; the VM's
  quiet fast path is off while a hook is set): breakpoints, steps, pause, entry;
* ``step_hook(task, mode, text)`` at a run mode's step stop (#MSTEP, #ISTEP, #BSTEP);
* ``error_hook(task, frame, err)`` where a run-time error leaves the routine it occurred
  in, with that frame still alive.

A stop is a loop inside the hook that serves requests until one resumes: the tasks stay
suspended where they are, so stacks, variables and the robot are the live ones.

Reverse execution (``stepBack``, ``reverseContinue``) is deterministic replay: the run is
rebuilt from the start (same files, inputs, seeds) and run to the statement before (the
hook count, ``n``); the simulation is deterministic, so the state there is the state the
program had. Greenlet stacks cannot be copied, so there are no snapshots: a replay always
starts at the beginning (at most krl.limits.MAX_DAP_REPLAY_STEPS statements).
"""

from __future__ import annotations

import contextlib
import os
import queue
import sys
import threading
from pathlib import Path

from dap_types import (Breakpoint as DapBreakpoint, Capabilities, ExceptionBreakpointsFilter, Scope, Source,
                       StackFrame, Thread, Variable)

from krl.limits import MAX_DAP_BREAKPOINTS, MAX_DAP_REPLAY_STEPS

from .expr import ExpressionError, compile_in_frame
from .values import children, has_children, value_text
from .wire import ProtocolError, read_message, write_message

ROBOT_THREAD = 1
SUBMIT_THREAD = 2            # + index among the submit tasks
INTERRUPT_THREAD = 1000      # + interrupt number (1..128)

#: system variables shown in the "System variables" scope (any other: evaluate it)
SHOWN_SYSVARS = ("$POS_ACT", "$AXIS_ACT", "$VEL_ACT", "$OV_PRO", "$MODE_OP", "$PRO_MODE", "$ADVANCE",
                 "$TOOL", "$BASE", "$VEL", "$ACC", "$APO", "$ORI_TYPE", "$PRO_STATE", "$ERR")
IO_ALWAYS = 16               # $IN[1..16] and $OUT[1..16] always; higher numbers when TRUE
IO_SIZE = 8192


def _dump(model) -> dict:
    return model.model_dump(exclude_none=True, by_alias=True, mode="json")


class Restart(BaseException):
    """Unwinds the run for a replay to hook count ``target`` (reason of the stop there)."""

    def __init__(self, target: int, reason: str = "step", scan: int | None = None) -> None:
        super().__init__(target)
        self.target = target
        self.reason = reason
        self.scan = scan


class Terminate(BaseException):
    """The client disconnected: the run ends at once."""


class LineBreakpoint:
    def __init__(self, bid: int, line: int, condition: str | None, hit: str | None) -> None:
        self.id = bid
        self.line = line
        self.condition = condition.strip() if condition and condition.strip() else None
        self.hit_text = hit.strip() if hit and hit.strip() else None
        self.hit_test = _hit_test(self.hit_text) if self.hit_text else None
        self.hits = 0
        self.compiled: dict = {}      # id(layout) -> expression AST


def _hit_test(text: str):
    """DAP hitCondition: ``N`` or ``>=N`` (from the Nth hit on), ``=N``/``==N`` (the Nth
    hit only), ``>N``, ``%N`` (every Nth hit). None when the text is none of these."""
    t = text.replace(" ", "")
    for op, fn in ((">=", lambda h, n: h >= n), ("==", lambda h, n: h == n), ("=", lambda h, n: h == n),
                   (">", lambda h, n: h > n), ("%", lambda h, n: n > 0 and h % n == 0), ("", lambda h, n: h >= n)):
        if t.startswith(op) and t[len(op):].isdigit() and len(t) - len(op) <= 9:
            n = int(t[len(op):])
            return lambda h, n=n, fn=fn: fn(h, n)
    return None


class DebugSession:
    """One DAP session on the byte streams ``rfile`` (requests) and ``wfile`` (responses,
    events)."""

    def __init__(self, rfile, wfile) -> None:
        self.rfile = rfile
        self.wfile = wfile
        self.wlock = threading.Lock()
        self.seq = 0
        self.inbox: queue.Queue = queue.Queue()
        self.launch_args: dict | None = None
        self.configured = False
        self.started = False
        self.state = "init"                    # init | running | stopped | ended
        self.line_bps: dict[str, dict[int, LineBreakpoint]] = {}
        self.func_bps: dict[str, LineBreakpoint] = {}
        self.next_bp = 1
        self.rt = None
        self.tree = None
        self.n = 0                             # statements seen (hook count) in this run
        self.target: int | None = None         # replay: stop at this hook count
        self.target_reason = "step"
        self.scan: int | None = None           # reverseContinue: find the last breakpoint before this
        self.scan_last = 0
        self.busy = False                      # hooks ignored (evaluating, backward motion)
        self.pause_req = False
        self.step: tuple | None = None         # (kind, task, depth)
        self.resume: tuple | None = None
        self.stop_n = 0
        self.stop_mid = False                  # stopped inside a statement (step stop, error)
        self.stop_task = None
        self.stop_error = None
        self.handles: list = []
        self.frames: list = []
        self.realpaths: dict[str, str] = {}
        self.prev_frame: dict = {}             # task -> frame seen at its previous statement
        self.done = False
        self.last_refusal: str | None = None
        self.break_on_errors = True
        self.cleanup = contextlib.ExitStack()  # an extracted backup, removed when the session ends
        self._stop_thread = ROBOT_THREAD

    # ------------------------------------------------------------------ wire
    def send(self, msg: dict) -> None:
        with self.wlock:
            self.seq += 1
            msg["seq"] = self.seq
            write_message(self.wfile, msg)

    def respond(self, req: dict, body: dict | None = None, ok: bool = True, message: str | None = None) -> None:
        msg = {"type": "response", "request_seq": req.get("seq", 0), "success": ok,
               "command": req.get("command", "")}
        if message is not None:
            msg["message"] = message
        if body is not None:
            msg["body"] = body
        self.send(msg)

    def event(self, name: str, body: dict | None = None) -> None:
        msg = {"type": "event", "event": name}
        if body is not None:
            msg["body"] = body
        self.send(msg)

    def output(self, text: str, category: str = "console") -> None:
        self.event("output", {"category": category, "output": text if text.endswith("\n") else text + "\n"})

    def _reader(self) -> None:
        try:
            while True:
                msg = read_message(self.rfile)
                self.inbox.put(msg)
                if msg is None:
                    return
        except ProtocolError as exc:
            self.inbox.put({"type": "_protocol_error", "text": str(exc)})
        except (OSError, ValueError):
            self.inbox.put(None)

    # ------------------------------------------------------------------ main loop
    def serve(self) -> int:
        """Serve until the client disconnects or the input ends; the exit status (0)."""
        threading.Thread(target=self._reader, daemon=True).start()
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
            self.cleanup.close()
        return 0

    def dispatch(self, msg: dict) -> None:
        if msg.get("type") == "_protocol_error":
            from krl.terminal import printable  # noqa: PLC0415

            sys.stderr.write(f"krl debug: protocol error: {printable(msg['text'])}\n")
            self.done = True
            raise Terminate()
        if msg.get("type") != "request":
            return
        cmd = msg.get("command")
        name = str(cmd).replace("/", "_")
        handler = getattr(self, "req_" + name, None) if isinstance(cmd, str) and name.isidentifier() else None
        if handler is None:
            self.respond(msg, ok=False, message=f"request {str(cmd)[:40]!r} is not supported")
            return
        args = msg.get("arguments") or {}
        if not isinstance(args, dict):
            self.respond(msg, ok=False, message="arguments must be an object")
            return
        try:
            handler(msg, args)
        except (Restart, Terminate):
            raise
        except _Refused as exc:
            self.respond(msg, ok=False, message=str(exc))
        except Exception as exc:  # noqa: BLE001 - a request never ends the session with a traceback
            self.respond(msg, ok=False, message=f"{type(exc).__name__}: {exc}"[:300])

    # ------------------------------------------------------------------ requests: setup
    def req_initialize(self, req, args) -> None:
        caps = Capabilities(
            supportsConfigurationDoneRequest=True, supportsConditionalBreakpoints=True,
            supportsHitConditionalBreakpoints=True, supportsFunctionBreakpoints=True,
            supportsEvaluateForHovers=True, supportsSetVariable=True, supportsStepBack=True,
            supportsExceptionInfoRequest=True, supportsTerminateRequest=True,
            exceptionBreakpointFilters=[ExceptionBreakpointsFilter(
                filter="runtime_error", label="KRL run-time errors", default=True)])
        self.respond(req, _dump(caps))
        self.event("initialized")

    def req_launch(self, req, args) -> None:
        program = args.get("program")
        if not isinstance(program, str) or not program:
            raise _Refused("launch needs 'program': the path of a .src file")
        workspace = args.get("workspace")
        from krl.archive import ArchiveError, backup_source, is_archive  # noqa: PLC0415

        if workspace is not None and is_archive(Path(str(workspace))):
            # a KRC backup .zip: checked and extracted for the session (krl run --workspace BACKUP.zip)
            from interp.cli import program_in  # noqa: PLC0415

            try:
                folder, _shown = self.cleanup.enter_context(backup_source(str(workspace)))
            except ArchiveError as exc:
                raise _Refused(str(exc)) from None
            found = program_in(folder, Path(program))
            if found is None:
                raise _Refused(f"no program {program} in {workspace}")
            program, workspace = str(found), str(folder)
            args = {**args, "workspace": workspace}
        if not Path(program).is_file():
            raise _Refused(f"no such program: {program}")
        mode = str(args.get("mode") or "T1").upper()
        if mode not in ("T1", "T2", "AUT", "EXT"):
            raise _Refused(f"mode {mode!r}: one of T1, T2, AUT, EXT")
        run_mode = str(args.get("runMode") or "GO").upper().lstrip("#")
        if run_mode not in ("GO", "MSTEP", "ISTEP", "BSTEP"):
            raise _Refused(f"runMode {run_mode!r}: one of GO, MSTEP, ISTEP, BSTEP")
        interp = str(args.get("interp") or "tree")
        if interp not in ("tree", "vm"):
            raise _Refused(f"interp {interp!r}: tree or vm")
        for key in ("workspace", "inputs"):
            if args.get(key) is not None and not Path(str(args[key])).exists():
                raise _Refused(f"{key}: no such file or folder: {args[key]}")
        self.launch_args = {"program": program, "workspace": workspace, "inputs": args.get("inputs"),
                            "mode": mode, "run_mode": run_mode, "interp": interp,
                            "stop_on_entry": bool(args.get("stopOnEntry", False)),
                            "max_sim_time": float(args.get("maxSimTime", 600.0)),
                            "submit": [str(s) for s in (args.get("submit") or [])]}
        rt, _ = self._build()           # the checker's refusal is the launch's error
        errors = rt.program.errors_of(rt.program.module_of(rt.program.main_path))
        rt.scheduler.close()
        if errors:
            self.launch_args = None
            raise _Refused("not started: the checker finds errors: " + "; ".join(str(d) for d in errors[:5]))
        self.respond(req)

    def req_configurationDone(self, req, args) -> None:  # noqa: N802 - DAP's name
        self.configured = True
        self.respond(req)

    def req_setBreakpoints(self, req, args) -> None:  # noqa: N802
        src = args.get("source") or {}
        path = src.get("path")
        if not isinstance(path, str):
            raise _Refused("setBreakpoints needs source.path")
        real = os.path.realpath(path)
        bps = {}
        out = []
        for b in (args.get("breakpoints") or [])[:MAX_DAP_BREAKPOINTS]:
            bp = LineBreakpoint(self.next_bp, int(b.get("line", 0)), b.get("condition"), b.get("hitCondition"))
            self.next_bp += 1
            message = None
            verified = True
            if bp.condition is not None:
                try:
                    from .expr import parse_expression  # noqa: PLC0415

                    parse_expression(bp.condition)
                except ExpressionError as exc:
                    verified, message = False, f"condition: {exc}"
            if bp.hit_text is not None and bp.hit_test is None:
                verified, message = False, f"hit condition {bp.hit_text!r}: N, >=N, =N, >N or %N"
            if verified:
                bps[bp.line] = bp
            out.append(_dump(DapBreakpoint(id=bp.id, verified=verified, line=bp.line, message=message,
                                           source=Source(path=path, name=Path(path).name))))
        self.line_bps[real] = bps
        self.respond(req, {"breakpoints": out})

    def req_setFunctionBreakpoints(self, req, args) -> None:  # noqa: N802
        self.func_bps = {}
        out = []
        for b in (args.get("breakpoints") or [])[:MAX_DAP_BREAKPOINTS]:
            name = str(b.get("name", "")).strip().upper()
            bp = LineBreakpoint(self.next_bp, 0, b.get("condition"), b.get("hitCondition"))
            self.next_bp += 1
            self.func_bps[name] = bp
            out.append(_dump(DapBreakpoint(id=bp.id, verified=bool(name))))
        self.respond(req, {"breakpoints": out})

    def req_setExceptionBreakpoints(self, req, args) -> None:  # noqa: N802
        """The filter ``runtime_error`` (on by default): stop where a run-time error occurs."""
        filters = args.get("filters") or []
        self.break_on_errors = "runtime_error" in filters
        self.respond(req, {"breakpoints": [{"verified": True} for _ in filters]})

    def req_threads(self, req, args) -> None:
        threads = []
        if self.rt is not None:
            for tid, name, _task, _frames in self.thread_list():
                threads.append(_dump(Thread(id=tid, name=name)))
        self.respond(req, {"threads": threads})

    def req_disconnect(self, req, args) -> None:
        self.respond(req)
        self.done = True
        if self.state in ("running", "stopped"):
            raise Terminate()

    req_terminate = req_disconnect

    # ------------------------------------------------------------------ requests: execution
    def _need_stopped(self) -> None:
        if self.state != "stopped":
            raise _Refused("the program is not stopped")

    def req_continue(self, req, args) -> None:
        self._need_stopped()
        self.respond(req, {"allThreadsContinued": True})
        self.resume = ("run", None)

    def _step(self, req, kind: str) -> None:
        self._need_stopped()
        self.respond(req)
        task = self._task_of_thread(req["arguments"].get("threadId") if req.get("arguments") else None)
        self.resume = ("run", (kind, task, _depth(task)))

    def req_next(self, req, args) -> None:
        self._step(req, "over")

    def req_stepIn(self, req, args) -> None:  # noqa: N802
        self._step(req, "in")

    def req_stepOut(self, req, args) -> None:  # noqa: N802
        self._step(req, "out")

    def req_pause(self, req, args) -> None:
        self.respond(req)
        if self.state == "running":
            self.pause_req = True

    def req_stepBack(self, req, args) -> None:  # noqa: N802
        self._need_stopped()
        self.respond(req)
        # a stop inside statement n (a step stop, an error) goes back to n's start, else to n - 1
        self.resume = ("restart", Restart(max(1, self.stop_n - (0 if self.stop_mid else 1)), "step"))

    def req_reverseContinue(self, req, args) -> None:  # noqa: N802
        self._need_stopped()
        self.respond(req)
        self.resume = ("restart", Restart(0, "breakpoint", scan=self.stop_n + (1 if self.stop_mid else 0)))

    # ------------------------------------------------------------------ requests: inspection
    def req_stackTrace(self, req, args) -> None:  # noqa: N802
        self._need_stopped()
        tid = args.get("threadId")
        out = []
        for t, _name, task, frames in self.thread_list():
            if t != tid:
                continue
            for i, f in enumerate(frames):
                self.frames.append((task, f))
                fid = len(self.frames)
                line = f.line or 1
                if i == 0 and task is self.stop_task and self.stop_error is not None and t == self._stop_thread:
                    line = self.stop_error.line or line
                path = f.module.path if f.module is not None else ""
                out.append(_dump(StackFrame(id=fid, name=f"{f.name}()", line=line, column=1,
                                            source=Source(path=str(path), name=Path(str(path)).name))))
        start = int(args.get("startFrame") or 0)
        levels = int(args.get("levels") or 0)
        page = out[start:start + levels] if levels else out[start:]
        self.respond(req, {"stackFrames": page, "totalFrames": len(out)})

    def _frame_of(self, fid) -> tuple:
        if not isinstance(fid, int) or not 1 <= fid <= len(self.frames):
            raise _Refused(f"no frame {fid}")
        return self.frames[fid - 1]

    def req_scopes(self, req, args) -> None:
        self._need_stopped()
        task, frame = self._frame_of(args.get("frameId"))
        scopes = [("Locals", ("locals", frame)), ("Module data", ("module", frame.module)),
                  ("Globals ($config.dat)", ("globals",)), ("System variables", ("sysvars",)), ("I/O", ("io",))]
        out = []
        for name, handle in scopes:
            self.handles.append(handle)
            out.append(_dump(Scope(name=name, variablesReference=len(self.handles), expensive=False)))
        self.respond(req, {"scopes": out})

    def req_variables(self, req, args) -> None:
        self._need_stopped()
        out = []
        for name, ref in self._entries(self._handle(args.get("variablesReference"))):
            out.append(self._variable(name, ref))
        self.respond(req, {"variables": out})

    def _handle(self, ref) -> tuple:
        if not isinstance(ref, int) or not 1 <= ref <= len(self.handles):
            raise _Refused(f"no variables reference {ref}")
        return self.handles[ref - 1]

    def _entries(self, handle: tuple) -> list:
        """(name, Ref or a value) of the variables under a handle."""
        rt = self.rt
        kind = handle[0]
        out = []
        if kind == "locals":
            frame = handle[1]
            if frame.layout is not None:
                for k, s in enumerate(frame.layout.slots):
                    out.append((s.name, frame.vars[k]))
        elif kind == "module":
            m = handle[1]
            if m is not None:
                out = list(m.data.items())
        elif kind == "globals":
            for m in rt.modules:
                if m is not None and m.name == "$CONFIG":
                    out = list(m.data.items())
        elif kind == "sysvars":
            for name in SHOWN_SYSVARS:
                out.append((name, rt.sysvars.lookup(name)))
            out.append(("(simulated time s)", rt.controller.time))
        elif kind == "io":
            io = rt.controller.io
            for arr, get in (("$IN", io.get_in), ("$OUT", io.get_out)):
                for i in range(1, IO_SIZE + 1):
                    v = get(i)
                    if i <= IO_ALWAYS or v:
                        out.append((f"{arr}[{i}]", _Const(bool(v), self.rt.sysvars.lookup(arr), i)))
        elif kind == "ref":
            _, ref, name = handle
            v = self._peek(ref)
            for label, step in children(v):
                if isinstance(ref, _Const):     # an evaluated value: its parts are values
                    part = v.f[step[1]] if step[0] == "field" else v.data[v.flat(step[1])]
                    out.append((label, _Const(part, None, None)))
                else:
                    out.append((label, self._child(ref, step, name)))
        return out

    def _child(self, ref, step, name):
        if step[0] == "field":
            return self.rt.field(ref, step[1], name)
        return self.rt.index(ref, step[1], name)

    @staticmethod
    def _peek(ref):
        from interp.runtime.errors import KrlRuntimeError  # noqa: PLC0415

        if ref is None:
            return None
        if isinstance(ref, _Const):
            return ref.value
        if not hasattr(ref, "peek"):
            return ref
        try:
            return ref.peek()
        except KrlRuntimeError as exc:
            return _Invalid(exc.message)

    def _variable(self, name: str, ref) -> dict:
        v = self._peek(ref)
        vref = 0
        if has_children(v) and hasattr(ref, "peek"):
            self.handles.append(("ref", ref, name))
            vref = len(self.handles)
        text = v.text if isinstance(v, _Invalid) else value_text(v)
        from interp.runtime.values import type_name_of  # noqa: PLC0415

        return _dump(Variable(name=name, value=text, variablesReference=vref,
                              type=None if isinstance(v, _Invalid) or v is None else type_name_of(v)))

    def req_setVariable(self, req, args) -> None:  # noqa: N802
        self._need_stopped()
        handle = self._handle(args.get("variablesReference"))
        name = str(args.get("name"))
        target = None
        for n, ref in self._entries(handle):
            if n == name:
                target = ref
        if isinstance(target, _Const):
            target = self.rt.index(target.ref, [target.index], name.split("[")[0])
        if target is None or not hasattr(target, "peek"):
            raise _Refused(f"{name} cannot be set")
        task, frame = self._top()
        value = self._eval(str(args.get("value", "")), frame)
        from interp.runtime.errors import KrlRuntimeError  # noqa: PLC0415

        try:
            self.rt.assign(target, value)
        except KrlRuntimeError as exc:
            raise _Refused(exc.message) from None
        v = self._peek(target)
        self.respond(req, {"value": value_text(v)})

    def _top(self) -> tuple:
        task = self.stop_task
        return task, task.frame if task is not None else None

    def _eval(self, text: str, frame):
        """Evaluate a KRL expression in ``frame`` (no statement hook, no trace, no end of
        the time slice while it runs)."""
        from interp.runtime.errors import ControlSignal, KrlRuntimeError  # noqa: PLC0415

        rt = self.rt
        try:
            expr = compile_in_frame(rt, text, frame)
        except ExpressionError as exc:
            raise _Refused(str(exc)) from None
        task = rt.current_task
        saved = (rt.trace, self.busy, task.slice_end if task else None, rt.max_steps, rt.steps)
        rt.trace, self.busy = None, True
        if task is not None:
            task.slice_end = sys.maxsize
        rt.max_steps = None
        try:
            return self.tree.eval(expr, frame)
        except KrlRuntimeError as exc:
            raise _Refused(exc.message + (f" ({exc.number})" if exc.number else "")) from None
        except ControlSignal:
            raise _Refused("the expression cannot be evaluated here") from None
        finally:
            rt.trace, self.busy = saved[0], saved[1]
            if task is not None:
                task.slice_end = saved[2]
            rt.max_steps, rt.steps = saved[3], saved[4]

    def req_evaluate(self, req, args) -> None:
        self._need_stopped()
        fid = args.get("frameId")
        frame = self._frame_of(fid)[1] if fid is not None else self._top()[1]
        v = self._eval(str(args.get("expression", "")), frame)
        vref = 0
        if has_children(v):
            self.handles.append(("ref", _Const(v, None, None), str(args.get("expression"))))
            vref = len(self.handles)
        self.respond(req, {"result": value_text(v), "variablesReference": vref})

    def req_exceptionInfo(self, req, args) -> None:  # noqa: N802
        self._need_stopped()
        e = self.stop_error
        if e is None:
            raise _Refused("not stopped at a run-time error")
        self.respond(req, {"exceptionId": f"KSS {e.number}" if e.number else "KRL run-time error",
                           "description": e.message, "breakMode": "always"})

    def req_source(self, req, args) -> None:
        raise _Refused("sources are files: open the source's path")

    # custom requests ----------------------------------------------------------
    def req_krl_pointers(self, req, args) -> None:
        self.respond(req, self.pointers())

    def req_krl_backwardStep(self, req, args) -> None:  # noqa: N802
        """One backward motion (#BSTEP, T1/T2) at the stop; no statement runs."""
        self._need_stopped()
        task = self.stop_task
        if task is None or task.kind != "robot" or self._stop_thread != ROBOT_THREAD:
            raise _Refused("backward motion: stop the robot program first")
        events_before = len(self.rt.history.records)
        self.busy = True
        try:
            ok = self.rt.backward_step(task)
        finally:
            self.busy = False
        if not ok:
            raise _Refused(self.last_refusal or "backward motion not possible")
        self.respond(req, {"retraced": events_before - len(self.rt.history.records), **self.pointers()})

    # ------------------------------------------------------------------ the run
    def _build(self):
        from interp.run import make_runtime  # noqa: PLC0415

        a = self.launch_args
        rt, interp = make_runtime(a["program"], workspace=a["workspace"], inputs=a["inputs"],
                                  max_sim_time=a["max_sim_time"], max_steps=MAX_DAP_REPLAY_STEPS,
                                  interp=a["interp"], mode=a["mode"], submit=a["submit"],
                                  run_mode=a["run_mode"])
        return rt, interp

    def run_loop(self) -> None:
        from interp.tree import TreeInterpreter  # noqa: PLC0415

        target, reason, scan = None, "step", None
        while True:
            rt, _ = self._build()
            self.rt = rt
            self.tree = TreeInterpreter(rt)
            rt.stmt_hook = self.on_statement
            rt.step_hook = self.on_step_stop
            rt.error_hook = self.on_error
            rt.cycle_hook = self.on_cycle
            self.n = 0
            self.target, self.target_reason, self.scan, self.scan_last = target, reason, scan, 0
            self.step = None
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
                continue
            except Terminate:
                rt.scheduler.close()
                self.state = "ended"
                self.event("terminated")
                return
            break
        self.state = "ended"
        where = f" at {res.file}:{res.line}" if res.line else ""
        self.output(f"program ended: {res.reason}{where}{': ' + res.text if res.text else ''} "
                    f"(t={res.sim_time:.3f} s)")
        self.event("exited", {"exitCode": res.exit_code})
        self.event("terminated")

    # ------------------------------------------------------------------ hooks
    def on_statement(self, task, info) -> None:
        if self.busy:       # a function called by a watch, a backward motion: not counted
            return
        self.n += 1
        if self.n > MAX_DAP_REPLAY_STEPS:
            return
        hit = self._breakpoint(task, info)
        if self.scan is not None:
            if hit is not None and self.n < self.scan:
                self.scan_last = self.n
            if self.n >= self.scan - 1:
                raise Restart(self.scan_last or 1, "breakpoint" if self.scan_last else "entry")
            return
        if self.target is not None:
            if self.n < self.target:
                return
            self.target = None
            self.stop(task, self.target_reason)
            return
        self.pump()
        reason, desc = None, None
        if self.n == 1 and self.launch_args["stop_on_entry"]:
            reason = "entry"
        elif self.pause_req:
            reason = "pause"
        elif self.step is not None and self._step_done(task):
            reason = "step"
        if hit is not None:
            reason, desc = reason or ("function breakpoint" if hit[1] else "breakpoint"), hit[2]
        if reason is not None:
            self.stop(task, reason, description=desc, bp=hit[0] if hit else None)

    def on_cycle(self, task) -> None:
        """A task resumes in a new IPO cycle (it waits: WAIT FOR, WAIT SEC, the advance-run
        stop, a full motion queue): a pause requested meanwhile stops it there."""
        if self.busy or self.target is not None or self.scan is not None:
            return
        self.pump()
        if self.pause_req:
            self.stop(task, "pause", description="paused while waiting", mid=True)

    def on_step_stop(self, task, mode: str, text: str | None) -> None:
        if text:
            self.last_refusal = text
        if self.busy or self.target is not None or self.scan is not None:
            return
        what = {"MSTEP": "MSTEP: the motion has ended", "ISTEP": "ISTEP: before the next statement",
                "BSTEP": "BSTEP: the backward motion has ended"}.get(mode, mode)
        self.stop(task, "step", description=text or what, mid=True)

    def on_error(self, task, frame, err) -> None:
        if self.busy or self.target is not None or self.scan is not None or not self.break_on_errors:
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
                except _Refused as exc:
                    ok, desc = True, f"condition error: {exc}"
                if not ok:
                    continue
            bp.hits += 1
            if bp.hit_test is not None and not bp.hit_test(bp.hits):
                continue
            return bp, is_fn, desc
        return None

    def _condition(self, bp: LineBreakpoint, frame) -> bool:
        from interp.runtime.convert import to_bool  # noqa: PLC0415
        from interp.runtime.errors import KrlRuntimeError  # noqa: PLC0415

        v = self._eval(bp.condition, frame)
        try:
            return bool(to_bool(v, "breakpoint condition"))
        except KrlRuntimeError as exc:
            raise _Refused(exc.message) from None

    def _step_done(self, task) -> bool:
        kind, t0, d0 = self.step
        if task is not t0:
            return False
        d = _depth(task)
        return kind == "in" or (kind == "over" and d <= d0) or (kind == "out" and d < d0)

    def pump(self) -> None:
        """Serve the requests that arrived while the program runs (pause, breakpoints)."""
        while True:
            try:
                msg = self.inbox.get_nowait()
            except queue.Empty:
                return
            if msg is None:
                self.done = True
                raise Terminate()
            self.dispatch(msg)

    def stop(self, task, reason: str, description: str | None = None, text: str | None = None,
             bp=None, error=None, mid: bool = False) -> None:
        """Stop every thread here and serve requests until one resumes."""
        self.state = "stopped"
        self.stop_mid = mid
        self.stop_task = task
        self.stop_n = self.n
        self.stop_error = error
        self.pause_req = False
        self.step = None
        self.handles, self.frames = [], []
        self.resume = None
        tid = self._thread_of(task)
        self._stop_thread = tid
        body = {"reason": reason, "threadId": tid, "allThreadsStopped": True}
        if description:
            body["description"] = description
        if text:
            body["text"] = text
        if bp is not None:
            body["hitBreakpointIds"] = [bp.id]
        self.event("stopped", body)
        self.event("krl/pointers", self.pointers())
        while self.resume is None:
            msg = self.inbox.get()
            if msg is None:
                self.done = True
                raise Terminate()
            self.dispatch(msg)
        action, arg = self.resume
        self.state = "running"
        self.handles, self.frames = [], []
        if action == "restart":
            raise arg
        self.step = arg
        self.prev_frame[task] = task.frame

    def pointers(self) -> dict:
        """The pendant's two pointers and the simulated time: ``advanceRun`` — the statement
        the robot interpreter reached (the advance run); ``mainRun`` — the motion statement
        the robot executes now (None when it stands); ``time`` (s), ``cycle`` (IPO cycles),
        ``step`` (statements so far: the position stepBack counts in)."""
        rt = self.rt
        if rt is None:
            return {}
        ctl = rt.controller
        robot = rt.robot
        adv = {"path": robot.file, "line": robot.line} if robot is not None and robot.at is not None else None
        req = ctl.current_request()
        main = {"path": req.file, "line": req.line, "motion": req.id} if req is not None and req.line else None
        return {"advanceRun": adv, "mainRun": main, "time": round(ctl.time, 6), "cycle": ctl.cycle,
                "step": self.n, "runMode": rt.run_mode}

    # ------------------------------------------------------------------ threads and stacks
    def thread_list(self) -> list:
        """(thread id, name, task, frames innermost first) of the robot program, each running
        interrupt handler and each submit program."""
        out = []
        subs = 0
        for task in self.rt.scheduler.tasks:
            if task.kind == "robot":
                base = ROBOT_THREAD
                name = f"robot program {task.name}"
            else:
                base = SUBMIT_THREAD + subs
                subs += 1
                name = f"submit interpreter {task.name}"
            if task.done:
                continue
            inner = []
            top = task.frame
            for c in reversed([c for c in task.contexts if c.kind == "interrupt"]):
                frames = []
                f = top
                while f is not None and top is not c.interrupted:
                    frames.append(f)
                    if f.caller is c.frame:
                        break
                    f = f.caller
                handler = frames[-1].name if frames else "BRAKE"
                inner.append((INTERRUPT_THREAD + (c.number or 0) + (0 if task.kind == "robot" else 200),
                              f"interrupt {c.number} {handler}", task, frames))
                top = c.interrupted
            out.append((base, name, task, _chain(top)))
            out.extend(reversed(inner))
        return out

    def _thread_of(self, task) -> int:
        """The thread a stop of ``task`` belongs to: its innermost running interrupt's, else
        its own."""
        last = ROBOT_THREAD
        for tid, _n, t, _f in self.thread_list():
            if t is task:
                last = tid
        return last

    def _task_of_thread(self, tid):
        for t, _n, task, _f in self.thread_list():
            if t == tid:
                return task
        return self.stop_task


class _Refused(Exception):
    """A request that cannot be served (its message goes to the client)."""


class _Invalid:
    def __init__(self, text: str) -> None:
        self.text = f"<{text}>"


class _Const:
    """A value with no reference (an I/O element shown by number, an evaluated result)."""

    def __init__(self, value, ref, index) -> None:
        self.value = value
        self.ref = ref
        self.index = index

    def peek(self):
        return self.value


def _chain(frame) -> list:
    out = []
    while frame is not None:
        out.append(frame)
        frame = frame.caller
    return out


def _depth(task) -> int:
    """Call depth of ``task`` counting the frames of every interrupted level."""
    if task is None or task.frame is None:
        return 0
    d = task.frame.depth + 1
    for c in task.contexts:
        if c.kind == "interrupt" and c.interrupted is not None:
            d += c.interrupted.depth + 1
    return d
