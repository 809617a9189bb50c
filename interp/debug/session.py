"""`krl debug`: the Debug Adapter Protocol adapter (issue 24; docs/editors.md, "Debugging")
on top of the run-control engine (interp/debug/engine.py).

This module only speaks the protocol: a reader thread parses messages (interp/debug/wire.py)
and posts each request to the engine thread, where :meth:`DebugSession.dispatch` answers it
with the engine's methods; the engine's events go out as DAP events. What DAP numbers
itself lives here: frame ids and variables references (valid until the run resumes).
Custom requests: ``krl/pointers`` (the two pointers, the simulated time, the step),
``krl/backwardStep`` (one backward motion at a stop) and ``krl/setInput`` (an input set by
hand at a stop).
"""

from __future__ import annotations

import importlib
import sys
import threading
from pathlib import Path

from dap_types import (Breakpoint as DapBreakpoint, Capabilities, ExceptionBreakpointsFilter, Scope, Source,
                       StackFrame, Thread, Variable)

from krl.terminal import printable

from .engine import Engine, LaunchConfig, Refused, Restart, Terminate
from .values import value_text
from .wire import ProtocolError, read_message, write_message
from .launch import run_options


def _prepare() -> None:
    """Import what a launch needs (the simulated controller, the interpreters) while the
    client starts the session: the launch request then finds them loaded. Not MuJoCo: the
    controller compiles the arm at its first use (robot/readback.py ``ReadBack.arm``), after
    the launch."""
    for name in ("interp.run", "robot.controller", "interp.tree", "interp.debug.launch"):
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001 - the launch imports it again and says what is wrong
            return


def _dump(model) -> dict:
    return model.model_dump(exclude_none=True, by_alias=True, mode="json")


class DebugSession:
    """One DAP session on the byte streams ``rfile`` (requests) and ``wfile`` (responses,
    events), driving one :class:`interp.debug.engine.Engine`."""

    def __init__(self, rfile, wfile) -> None:
        self.rfile = rfile
        self.wfile = wfile
        self.wlock = threading.Lock()
        self._preparing = threading.Thread(target=_prepare, name="krl-debug-imports", daemon=True)
        self.seq = 0
        self.engine = Engine(on_event=self.event, on_runtime=None)
        self.frames: list = []                  # frame id - 1 -> engine Frame (this stop)
        self.handles: list = []                 # variables reference - 1 -> engine Scope (this stop)

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
        if name == "stopped":
            self.frames, self.handles = [], []      # references are valid for one stop
        msg = {"type": "event", "event": name}
        if body:
            msg["body"] = body
        self.send(msg)

    def _reader(self) -> None:
        post = self.engine.post
        try:
            while True:
                msg = read_message(self.rfile)
                if msg is None:
                    self.engine.close()
                    return
                post(self.dispatch, msg)
        except ProtocolError as exc:
            post(self._protocol_error, str(exc))
        except (OSError, ValueError):
            self.engine.close()

    def _protocol_error(self, text: str) -> None:
        sys.stderr.write(f"krl debug: protocol error: {printable(text)}\n")
        self.engine.done = True
        raise Terminate()

    # ------------------------------------------------------------------ main loop
    def serve(self) -> int:
        """Serve until the client disconnects or the input ends; the exit status (0)."""
        self._preparing.start()
        threading.Thread(target=self._reader, daemon=True).start()
        self.engine.serve()
        return 0

    def dispatch(self, msg: dict) -> None:
        """Answer one message (on the engine thread)."""
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
        if cmd != "initialize" and self._preparing.is_alive():
            # a request after initialize waits for the imports _prepare began: one thread
            # imports the project's packages, never two at once (robot's modules import each
            # other, and two threads importing them each found the other's half-made module:
            # "launch: KeyError: 'robot.kinematics'" in 3 of 6 runs of a test)
            self._preparing.join()
        try:
            handler(msg, args)
        except (Restart, Terminate):
            raise
        except Refused as exc:
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
        """Every option of ``krl run`` (interp/debug/launch.py), and ``stopOnEntry``."""

        options, extra = run_options(args)
        self.engine.launch(LaunchConfig(options, stop_on_entry=extra["stopOnEntry"]))
        self.respond(req)

    def req_configurationDone(self, req, args) -> None:  # noqa: N802 - DAP's name
        self.engine.configuration_done()
        self.respond(req)

    def req_setBreakpoints(self, req, args) -> None:  # noqa: N802
        src = args.get("source") or {}
        path = src.get("path")
        if not isinstance(path, str):
            raise Refused("setBreakpoints needs source.path")
        out = []
        for bp, verified, message in self.engine.set_breakpoints(path, list(args.get("breakpoints") or [])):
            out.append(_dump(DapBreakpoint(id=bp.id, verified=verified, line=bp.line, message=message,
                                           source=Source(path=path, name=Path(path).name))))
        self.respond(req, {"breakpoints": out})

    def req_setFunctionBreakpoints(self, req, args) -> None:  # noqa: N802
        out = [_dump(DapBreakpoint(id=bp.id, verified=ok))
               for bp, ok in self.engine.set_function_breakpoints(list(args.get("breakpoints") or []))]
        self.respond(req, {"breakpoints": out})

    def req_setExceptionBreakpoints(self, req, args) -> None:  # noqa: N802
        """The filter ``runtime_error`` (on by default): stop where a run-time error occurs."""
        filters = args.get("filters") or []
        self.engine.break_on_errors = "runtime_error" in filters
        self.respond(req, {"breakpoints": [{"verified": True} for _ in filters]})

    def req_threads(self, req, args) -> None:
        threads = [_dump(Thread(id=tid, name=name)) for tid, name in self.engine.threads()]
        self.respond(req, {"threads": threads})

    def req_disconnect(self, req, args) -> None:
        self.respond(req)
        self.engine.terminate()

    req_terminate = req_disconnect

    # ------------------------------------------------------------------ requests: execution
    def req_continue(self, req, args) -> None:
        self.engine.resume()
        self.respond(req, {"allThreadsContinued": True})

    def _step(self, req, kind: str) -> None:
        self.engine.step(kind, (req.get("arguments") or {}).get("threadId"))
        self.respond(req)

    def req_next(self, req, args) -> None:
        self._step(req, "over")

    def req_stepIn(self, req, args) -> None:  # noqa: N802
        self._step(req, "in")

    def req_stepOut(self, req, args) -> None:  # noqa: N802
        self._step(req, "out")

    def req_pause(self, req, args) -> None:
        self.respond(req)
        self.engine.pause()

    def req_stepBack(self, req, args) -> None:  # noqa: N802
        self.engine.step_back()
        self.respond(req)

    def req_reverseContinue(self, req, args) -> None:  # noqa: N802
        self.engine.reverse_continue()
        self.respond(req)

    # ------------------------------------------------------------------ requests: inspection
    def req_stackTrace(self, req, args) -> None:  # noqa: N802
        out = []
        for f in self.engine.stack(args.get("threadId")):
            self.frames.append(f)
            out.append(_dump(StackFrame(id=len(self.frames), name=f"{f.name}()", line=f.line, column=1,
                                        source=Source(path=f.path, name=Path(f.path).name))))
        start = int(args.get("startFrame") or 0)
        levels = int(args.get("levels") or 0)
        page = out[start:start + levels] if levels else out[start:]
        self.respond(req, {"stackFrames": page, "totalFrames": len(out)})

    def _frame(self, fid):
        if not isinstance(fid, int) or not 1 <= fid <= len(self.frames):
            raise Refused(f"no frame {fid}")
        return self.frames[fid - 1]

    def _handle(self, ref):
        if not isinstance(ref, int) or not 1 <= ref <= len(self.handles):
            raise Refused(f"no variables reference {ref}")
        return self.handles[ref - 1]

    def _reference(self, scope) -> int:
        if scope is None:
            return 0
        self.handles.append(scope)
        return len(self.handles)

    def req_scopes(self, req, args) -> None:
        self.engine.need_stopped()
        out = [_dump(Scope(name=name, variablesReference=self._reference(scope), expensive=False))
               for name, scope in self.engine.scopes(self._frame(args.get("frameId")))]
        self.respond(req, {"scopes": out})

    def req_variables(self, req, args) -> None:
        out = [_dump(Variable(name=v.name, value=v.value, variablesReference=self._reference(v.children),
                              type=v.type))
               for v in self.engine.variables(self._handle(args.get("variablesReference")))]
        self.respond(req, {"variables": out})

    def req_setVariable(self, req, args) -> None:  # noqa: N802
        self.engine.need_stopped()
        scope = self._handle(args.get("variablesReference"))
        text = self.engine.set_variable(scope, str(args.get("name")), str(args.get("value", "")))
        self.respond(req, {"value": text})

    def req_evaluate(self, req, args) -> None:
        self.engine.need_stopped()
        fid = args.get("frameId")
        frame = self._frame(fid) if fid is not None else None
        v = self.engine.evaluate(str(args.get("expression", "")), frame)
        self.respond(req, {"result": value_text(v), "variablesReference": self._reference(self.engine.value_scope(v))})

    def req_exceptionInfo(self, req, args) -> None:  # noqa: N802
        e = self.engine.exception()
        self.respond(req, {"exceptionId": f"KSS {e.number}" if e.number else "KRL run-time error",
                           "description": e.message, "breakMode": "always"})

    def req_source(self, req, args) -> None:
        raise Refused("sources are files: open the source's path")

    # custom requests ----------------------------------------------------------
    def req_krl_pointers(self, req, args) -> None:
        self.respond(req, self.engine.pointers())

    def req_krl_setInput(self, req, args) -> None:  # noqa: N802
        """``$IN[index]`` set by hand at a stop (``value`` true or false); the cell's rules
        stay active; stepBack replays it."""
        self.engine.need_stopped()
        index, value = args.get("index"), args.get("value")
        if not isinstance(value, bool):
            raise Refused("setInput: value true or false")
        self.respond(req, {"index": index, "value": self.engine.set_input(index, value)})

    def req_krl_backwardStep(self, req, args) -> None:  # noqa: N802
        """One backward motion (#BSTEP, T1/T2) at the stop; no statement runs."""
        retraced = self.engine.backward_motion()
        self.respond(req, {"retraced": retraced, **self.engine.pointers()})

