"""The pendant's web application: Starlette on uvicorn (its websockets come from the
``websockets`` package), bound to loopback, behind :class:`pendant.security.Guard`.

Routes: ``/`` the page, ``/static/...`` its bundle (built from pendant/web, committed), ``/ws``
the one websocket. On the websocket the page sends operator actions as JSON objects
``{"op": ..., ...}`` (:data:`OPS`) and receives ``{"type": ...}`` objects: ``init`` (workspace,
programs, robot), ``module`` (a file's text and taught points), ``logbook`` (a controller
archive's logbook records with the file and line each names: pendant/logbook.py), ``state`` (pendant/state.py: the
whole state first, ``"full": true``, then only the top-level keys that changed, a key gone as
null), ``live`` (time, axes, the TCP path's new points and, when they changed, the pointers, at
display rate while the program runs), ``done`` (an action carried out: its id and op, and ``ms``
the server's time from the message's arrival to this answer; a key's changed state went out
just before it), ``error`` (a key's refusal, in the controller's words) and ``event`` (the
engine's stops and ends). The messages are not compressed (loopback: deflate was
the largest CPU cost of a connected page).

Threads: uvicorn's event loop serves the page; the program runs on the engine's thread
(pendant/engine.py), whose answers the loop awaits (``Engine.do_async``); what blocks (select,
cancel, reading files) runs in the loop's executor. Limits
(krl/limits.py): MAX_WEB_MESSAGE_BYTES per websocket message (uvicorn's ``ws_max_size``: a
larger one closes the connection, 1009), MAX_WEB_CONNECTIONS websockets at once,
MAX_WEB_MESSAGES_PER_S per connection, counted as they arrive (past it, or with a second's
worth of actions not yet carried out: closed, 1008). A binary frame closes the connection with
1003 (the protocol is JSON text), one connection past the limit is accepted and closed with 1013
(issue 61: a binary frame raised ``KeyError: 'text'`` and dropped the connection without a close
frame, a flood logged a traceback although it was closed with 1008, and the ninth connection was
refused at the handshake, HTTP 403). The actions of a connection stop before it is closed, so
none of them sends on a closed connection.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import time
from collections.abc import Awaitable, Callable
from pathlib import Path

from starlette.applications import Starlette
from starlette.responses import FileResponse, PlainTextResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect, WebSocketState

from interp.debug.engine import Refused

from krl.limits import (MAX_WEB_BODY_BYTES, MAX_WEB_CONNECTIONS, MAX_WEB_EXPRESSION_CHARS, MAX_WEB_MESSAGE_BYTES,
                        MAX_WEB_MESSAGES_PER_S, MAX_WEB_WATCHES)

from . import engine as keys
from .engine import MODES_OP, RUN_MODES, Engine, EngineError
from .security import COOKIE, Guard, PathRefused, inside
from .state import message_rows, snapshot
from krl.files import spelled
from .view import module_view, modules, programs, robot_view
from .logbook import logbook_view
from interp.run import robot_for

STATIC = Path(__file__).resolve().parent / "static"
#: display rate of the live pose (Hz) and of the full state while running
LIVE_HZ = 30.0
STATE_HZ = 2.0
#: module views kept (text and taught points of a file, until it changes)
MODULE_CACHE = 64
CSP = ("default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data: blob:; "
       "connect-src 'self'; font-src 'self'; frame-ancestors 'self' vscode-webview:; base-uri 'none'; "
       "form-action 'none'")
#: close codes (RFC 6455 7.4.1; 1013 "Try Again Later", IANA's WebSocket Close Code registry)
CLOSE_POLICY_VIOLATION, CLOSE_UNSUPPORTED_DATA, CLOSE_MESSAGE_TOO_BIG, CLOSE_TRY_AGAIN_LATER = 1008, 1003, 1009, 1013
#: the operator actions a page sends (``{"op": name, ...}``): name -> the :class:`Pendant`
#: method that carries it out, ``async handler(pendant, action: _Action)``; each handler is
#: entered by its ``@_operation(name)``, so this table is the one list of the operations
#: (:data:`OPS` is its keys; tests/pendant/test_protocol.py checks it against the page's)
OPERATIONS: dict[str, Callable[..., Awaitable[object]]] = {}
#: a handler's answer when the action changed no state (nothing to push)
_NO_STATE = object()


def _operation(name: str) -> Callable:
    """The decorator entering a :class:`Pendant` method as the handler of operation `name`
    (:data:`OPERATIONS`). Raises ValueError for a name entered twice."""
    def enter(fn: Callable[..., Awaitable[object]]) -> Callable[..., Awaitable[object]]:
        if name in OPERATIONS:
            raise ValueError(f"pendant operation {name!r} has two handlers")
        OPERATIONS[name] = fn
        return fn
    return enter


class _Action:
    """One operator action being carried out: the page's socket `ws`, its message `msg`, the
    watch list when it arrived, and the state snapshots :meth:`do` took (``fresh``)."""

    def __init__(self, pendant: "Pendant", ws: WebSocket, msg: dict) -> None:
        self.pendant, self.ws, self.msg = pendant, ws, msg
        self.watch = list(pendant.watch)
        self.fresh: list = []

    async def do(self, fn, timeout: float = 120.0, *, state: bool = True):
        """The key ``fn(core)`` and, with ``state``, the state snapshot after it in the same
        engine call (one round trip to the engine thread: the answer carries what the key
        changed). Not for Start and Stop: their change comes after the call (the program
        goes on, stops at its next statement), and the state is asked for afterwards."""
        eng, watch, fresh = self.pendant.engine, self.watch, self.fresh

        def key_and_state(core):
            result = fn(core)
            if state:
                try:
                    fresh.append(snapshot(eng, core, watch))
                except Refused:
                    pass                           # asked for again by push_state
            return result
        return await eng.do_async(key_and_state, timeout)


class Pendant:
    """One workspace served to the pages connected to it (they share one selected program)."""

    def __init__(self, root: Path, *, inputs: str | None = None, mode: str = "T1", realtime: bool = True,
                 trace: str | None = None, program: str | None = None, readonly: bool = False,
                 shown_root: str | None = None) -> None:

        self.root = spelled(root)        # the user's spelling, links kept: the page's paths are the user's
        self.shown_root = shown_root or str(root)
        self.inputs = inputs
        self.mode = mode
        self.run_mode = "GO"
        self.trace = trace
        self.readonly = readonly
        self.initial = program
        self.engine = Engine(self._engine_event, realtime=realtime)
        self.clients: set[WebSocket] = set()
        self.loop: asyncio.AbstractEventLoop | None = None
        self.program: str | None = None
        self.drives = False
        self.watch: list[str] = []
        self.breakpoints: dict[str, set[int]] = {}
        self.busy = asyncio.Lock()
        self._robot = None
        self._programs = None
        self._last_live = None
        self._live_pointers = None
        self._path_run, self._path_sent = None, 0
        self._shown: dict[WebSocket, dict] = {}     # per page: the state it was last sent
        self._pushing = asyncio.Lock()
        self._pushed_seq = 0                        # the newest engine snapshot pushed (pendant/state.py)
        self._modules: dict[str, tuple] = {}
        self._position = None                       # where the robot stands when no program is selected
        self._logbook: dict | None = None           # the archive's logbook, once read (pendant/logbook.py)

    # ------------------------------------------------------------------ static data
    def robot(self) -> dict:
        if self._robot is None:

            probe = self.initial or next(iter(self.programs()), None)
            prog = str(self.root / probe) if probe else str(self.root / "none.src")
            self._robot = robot_view(robot_for(prog, str(self.root), None, self.inputs), self.inputs)
        return self._robot

    def programs(self) -> list[str]:
        if self._programs is None:

            self._programs = programs(self.root)
        return self._programs

    # ------------------------------------------------------------------ engine events
    def _engine_event(self, name: str, body: dict) -> None:
        """Engine thread: hand the event to the loop."""
        if self.loop is not None and name in ("stopped", "terminated", "exited", "output"):
            self.loop.call_soon_threadsafe(lambda: asyncio.ensure_future(self._on_event(name, body)))

    async def _on_event(self, name: str, body: dict) -> None:
        await self.broadcast({"type": "event", "event": name, "body": body or {}})
        await self.push_state()

    async def broadcast(self, msg: dict) -> None:
        text = json.dumps(msg, allow_nan=False, default=str)
        for ws in list(self.clients):
            try:
                await ws.send_text(text)
            except Exception:  # noqa: BLE001 - a client gone meanwhile
                self.clients.discard(ws)

    async def state(self, fresh: dict | None = None) -> dict:
        """The page's state: ``fresh`` (a snapshot the engine took right after a key, in the
        key's own engine call), else a snapshot asked for now. Without a selected program: the
        modes, the message window's system messages (they outlive a run) and where the robot
        stands (its start pose before the first selection: :meth:`robot`, else where the last
        run left it)."""
        if not self.engine.selected:
            if self._position is None:
                self._position = self.robot().get("start")
            return {"state": "none", "program": None, "programLabel": None, "drives": self.drives,
                    "modeOp": self.mode, "runMode": self.run_mode, "messages": message_rows(self.engine, None),
                    "position": self._position}
        if fresh is not None:
            s = dict(fresh)
        else:
            try:
                eng, watch = self.engine, list(self.watch)
                s = await eng.do_async(lambda core: snapshot(eng, core, watch), 60.0)
            except EngineError as exc:
                s = {"state": "ended" if not self.engine.selected else "busy", "note": str(exc),
                     "messages": message_rows(self.engine, None)}
        if s.get("position") is not None:
            self._position = s["position"]
        if s.get("state") == "ended":                 # the modes the next run starts with
            s.update({"modeOp": self.mode, "runMode": self.run_mode})
        s.update({"program": self.program, "programLabel": self._label(self.program), "drives": self.drives,
                  "breakpoints": {p: sorted(v) for p, v in self.breakpoints.items()}})
        return s

    def _label(self, program: str | None) -> str | None:
        """``program`` as the programs list names it (relative to the workspace)."""
        if program is None:
            return None
        try:
            return str(Path(program).relative_to(self.root))
        except ValueError:
            return program

    async def push_state(self, fresh: dict | None = None) -> None:
        """The state to every page, as what changed since the state that page was sent last
        (pendant/state.py: top-level keys, a key gone is sent as null; the first is whole,
        ``"full": true``): a page keeps its state and redraws only the changed parts.
        ``fresh``: a snapshot taken in a key's engine call (:meth:`state`)."""
        if not self.clients:
            return
        async with self._pushing:                     # one at a time: each page's diffs in order
            await self._push_state(fresh)

    async def _push_state(self, fresh: dict | None) -> None:
        # A key's snapshot is taken in its engine call, and pushed when the key's coroutine
        # resumes; meanwhile the run may have gone on and a newer snapshot been pushed (the
        # program ended right after an acknowledgement: the "exited" event's push came first).
        # An older snapshot is never pushed over a newer one: the state is asked for anew.
        if fresh is not None and fresh.get("seq", 0) < self._pushed_seq:
            fresh = None
        s = await self.state(fresh)
        seq = s.pop("seq", None)
        if seq is not None:
            self._pushed_seq = max(self._pushed_seq, seq)
        texts: dict[tuple, str] = {}                  # one encoding per distinct message
        for ws in list(self.clients):
            last = self._shown.get(ws)
            if last is None:
                msg = {"type": "state", "full": True, **s}
            else:
                msg = {k: v for k, v in s.items() if k not in last or last[k] != v}
                msg.update({k: None for k in last if k not in s})
                msg = {"type": "state", "state": s.get("state"), **msg}
            key = tuple(msg) if last is not None else ("full",)
            text = texts.get(key)
            if text is None:
                text = texts[key] = json.dumps(msg, allow_nan=False, default=str)
            try:
                await ws.send_text(text)
            except Exception:  # noqa: BLE001 - a client gone meanwhile
                self.clients.discard(ws)
                self._shown.pop(ws, None)
                continue
            self._shown[ws] = s

    async def ticker(self) -> None:
        """Display rate: the live pose while the program runs, the state now and then."""
        period = 1.0 / LIVE_HZ
        every = max(1, int(LIVE_HZ / STATE_HZ))
        k = 0
        while True:
            await asyncio.sleep(period)
            if not self.clients:
                continue
            live = self.engine.live
            if live and (live is not self._last_live or len(self.engine.path) > self._path_sent):
                self._last_live = live
                path, run = self.engine.path, live.get("run")
                if run != self._path_run:
                    self._path_run, self._path_sent = run, 0
                new = path[self._path_sent:self._path_sent + 5000]
                self._path_sent += len(new)
                msg = {"type": "live", **live, "axes": [round(v, 4) for v in live["axes"]], "path": new}
                if live.get("pointers") == self._live_pointers:
                    del msg["pointers"]              # unchanged since the last pose sent
                else:
                    self._live_pointers = live.get("pointers")
                await self.broadcast(msg)
                k += 1
                if k % every == 0 and self.engine.state == "running":
                    await self.push_state()

    # ------------------------------------------------------------------ operator actions
    async def handle(self, ws: WebSocket, msg: dict) -> None:
        """Carry out the operator action `msg` (``{"op": name, ...}``) of the page on `ws`: its
        handler in :data:`OPERATIONS`, then the state it changed pushed to the pages. Raises
        EngineError for an unknown operation and for a key the controller refuses."""
        op = msg.get("op")
        handler = OPERATIONS.get(op) if isinstance(op, str) else None
        if handler is None:
            raise EngineError(f"unknown action {str(op)[:40]!r}")
        action = _Action(self, ws, msg)
        if await handler(self, action) is _NO_STATE:
            return
        fresh = action.fresh
        await self.push_state(fresh[-1] if fresh and self.watch == action.watch else None)

    @_operation("hello")
    async def _hello(self, act: "_Action") -> None:

        loop = asyncio.get_running_loop()
        entries = self.programs()
        others = [m for m in await loop.run_in_executor(None, modules, self.root) if m not in set(entries)]
        await act.ws.send_text(json.dumps({"type": "init", "workspace": self.shown_root, "programs": entries,
                                           "modules": others,
                                           "robot": self.robot(), "modes": MODES_OP, "runModes": RUN_MODES,
                                           "readonly": self.readonly}))
        if self.program is not None:
            await self.send_module(act.ws, self.program)

    @_operation("select")
    async def _select(self, act: "_Action") -> None:
        await self.select(str(act.msg.get("program", "")))

    @_operation("cancel")
    async def _cancel(self, act: "_Action") -> None:
        await asyncio.get_running_loop().run_in_executor(None, self.engine.cancel)
        self.program = None

    @_operation("reset")
    async def _reset(self, act: "_Action") -> None:
        if self.program is None:
            raise EngineError("no program is selected")
        await self.select(self.program)

    @_operation("start")
    async def _start(self, act: "_Action") -> None:
        self._need_drives(start=True)
        await act.do(lambda core: core.resume(), state=False)

    @_operation("stop")
    async def _stop(self, act: "_Action") -> None:
        # in a cell: the cell stops in the chosen robot's program (the engine points at it)
        await act.do(lambda core: core.pause(core.rt), state=False)

    @_operation("backward")
    async def _backward(self, act: "_Action") -> None:
        self._need_drives()
        await act.do(lambda core: core.backward_motion(), 900.0, state=False)

    @_operation("runMode")
    async def _run_mode(self, act: "_Action") -> None:
        value = str(act.msg.get("value", "")).upper()
        if value not in RUN_MODES:
            raise EngineError(f"run mode: one of {', '.join(RUN_MODES)}")
        self.run_mode = value
        if self._live():
            await act.do(lambda core: keys.run_mode(core, value))

    @_operation("modeOp")
    async def _mode_op(self, act: "_Action") -> None:
        value = str(act.msg.get("value", "")).upper()
        if value not in MODES_OP:
            raise EngineError(f"operating mode: one of {', '.join(MODES_OP)}")
        if self._live():
            await act.do(lambda core: keys.mode_op(core, value))
        self.mode = value
        self.drives = False          # turning the mode switch switches the drives off

    @_operation("drives")
    async def _drives(self, act: "_Action") -> None:
        self.drives = bool(act.msg.get("on"))

    @_operation("override")
    async def _override(self, act: "_Action") -> None:
        await act.do(lambda core: keys.override(core, act.msg.get("value")))

    @_operation("breakpoint")
    async def _breakpoint(self, act: "_Action") -> None:
        msg = act.msg
        path = str(inside(self.root, str(msg.get("path", "")), suffixes=(".src", ".sub")))
        line = msg.get("line")
        if not isinstance(line, int) or isinstance(line, bool) or line < 1:
            raise EngineError("breakpoint: a line number")
        lines = self.breakpoints.setdefault(path, set())
        (lines.add if msg.get("on") else lines.discard)(line)
        if self.engine.selected:
            specs = [{"line": n} for n in sorted(lines)]
            await act.do(lambda core: core.set_breakpoints(path, specs))

    @_operation("input")
    async def _input(self, act: "_Action") -> None:
        await act.do(lambda core: keys.set_input(core, act.msg.get("index"), bool(act.msg.get("value"))))

    @_operation("ack")
    async def _ack(self, act: "_Action") -> None:
        handle = act.msg.get("handle")
        if isinstance(handle, str):               # the controller's own message (pendant/engine.py)
            self.engine.system.acknowledge(handle)
        else:
            await act.do(lambda core: keys.message(core, handle))

    @_operation("ackAll")
    async def _ack_all(self, act: "_Action") -> None:
        # "Confirm all": the controller's messages and the program's notification and
        # acknowledgement messages (status, wait and dialog messages stay)
        self.engine.system.acknowledge_all()
        if self._live():
            await act.do(keys.acknowledge_all)

    @_operation("answer")
    async def _answer(self, act: "_Action") -> None:
        await act.do(lambda core: keys.message(core, act.msg.get("handle"), act.msg.get("key")))

    @_operation("watch")
    async def _watch(self, act: "_Action") -> None:
        exprs = act.msg.get("exprs")
        if not isinstance(exprs, list) or len(exprs) > MAX_WEB_WATCHES or \
                any(not isinstance(e, str) or len(e) > MAX_WEB_EXPRESSION_CHARS for e in exprs):
            raise EngineError(f"watch list: at most {MAX_WEB_WATCHES} expressions of "
                              f"{MAX_WEB_EXPRESSION_CHARS} characters")
        self.watch = list(exprs)

    @_operation("setWatch")
    async def _set_watch(self, act: "_Action") -> None:
        msg = act.msg
        await act.do(lambda core: keys.set_watch(core, str(msg.get("expr", "")), str(msg.get("value", ""))))

    @_operation("jog")
    async def _jog(self, act: "_Action") -> None:
        if self.mode != "T1":                     # the robot's rule first: jog keys work in T1 only
            raise EngineError(f"jog: only in T1 (operating mode {self.mode})")
        self._need_drives()
        msg = act.msg
        await act.do(lambda core: keys.jog(core, str(msg.get("system", "")).upper(), msg.get("axis"), msg.get("step")),
                     900.0)

    @_operation("touchup")
    async def _touchup(self, act: "_Action") -> None:
        if self.readonly:
            raise EngineError("touch-up: the workspace is a backup archive (read-only)")
        dat = inside(self.root, str(act.msg.get("path", "")), suffixes=(".dat",))
        await act.do(lambda core: keys.touch_up(core, str(dat), str(act.msg.get("name", ""))))
        if self.program is not None:
            await self.broadcast_module(self.program)

    @_operation("logbook")
    async def _logbook(self, act: "_Action") -> object:
        """The archive's logbook (pendant/logbook.py), read once, for the page's Logbook tab."""
        if self._logbook is None:
            self._logbook = await asyncio.get_running_loop().run_in_executor(None, logbook_view, self.root)
        await act.ws.send_text(json.dumps({"type": "logbook", **self._logbook}))
        return _NO_STATE

    @_operation("chooseRobot")
    async def _choose_robot(self, act: "_Action") -> object:
        """The robot a cell's page shows (pendant/cell.py); one robot's workspace has no other."""
        raise EngineError("choose a robot: only in a cell of several robots (krl pendant CELL.yaml)")

    @_operation("open")
    async def _open(self, act: "_Action") -> object:
        path = inside(self.root, str(act.msg.get("path", "")), suffixes=(".src", ".sub", ".dat"))
        await self.send_module(act.ws, str(path))
        return _NO_STATE                           # a view of a file: no state changed

    def _live(self) -> bool:
        """A selected program that has not ended: a mode key goes to its run. After its end
        the key sets the mode the next selection (Reset, Select) starts with."""
        return self.engine.selected and self.engine.state in ("running", "stopped")

    def _need_drives(self, start: bool = False) -> None:
        """Refused while the drives are off (`start`: Start's test; a cell tests every robot's)."""
        if not self.drives:
            raise EngineError("the drives are off: switch them on first")

    async def select(self, program: str) -> None:
        path = inside(self.root, program, suffixes=(".src",))
        loop = asyncio.get_running_loop()
        await self.broadcast({"type": "event", "event": "selecting", "body": {"program": str(path)}})
        bps = {p: sorted(v) for p, v in self.breakpoints.items()}
        await loop.run_in_executor(None, lambda: self.engine.select(
            str(path), workspace=str(self.root), inputs=self.inputs, mode=self.mode, run_mode=self.run_mode,
            trace=self.trace, breakpoints=bps))
        self.program = str(path)
        await self.broadcast_module(str(path))

    async def send_module(self, ws: WebSocket, path: str) -> None:
        await ws.send_text(await self.module_text(path))

    async def module_text(self, path: str) -> str:
        """The ``module`` message of ``path``, kept while the file and its data list are
        unchanged (the page follows the advance run through modules again and again)."""

        p = Path(path)
        key = []
        for f in (p, *[q for q in p.parent.iterdir() if q.stem.lower() == p.stem.lower() and q != p]):
            try:
                st = f.stat()
                key.append((str(f), st.st_mtime_ns, st.st_size))
            except OSError:
                pass
        hit = self._modules.get(path)
        if hit is not None and hit[0] == key:
            return hit[1]
        view = await asyncio.get_running_loop().run_in_executor(None, module_view, p, self.root)
        text = json.dumps({"type": "module", **view})
        self._modules[path] = (key, text)
        while len(self._modules) > MODULE_CACHE:
            del self._modules[next(iter(self._modules))]
        return text

    async def broadcast_module(self, path: str) -> None:
        for ws in list(self.clients):
            try:
                await self.send_module(ws, path)
            except Exception:  # noqa: BLE001
                self.clients.discard(ws)

    # ------------------------------------------------------------------ websocket
    async def websocket(self, ws: WebSocket) -> None:
        """One page's connection. Its messages are read as they arrive and counted there (the
        rate limit holds however slowly the actions are carried out) and queued for
        :meth:`_actions`; a backlog of more than a second's worth of actions is a flood too."""
        if len(self.clients) >= MAX_WEB_CONNECTIONS:
            # refused after the handshake, so that the page sees the close code (before it,
            # Starlette can only answer HTTP 403)
            await ws.accept()
            await ws.close(code=CLOSE_TRY_AGAIN_LATER, reason="too many connections")
            return
        await ws.accept()
        self.clients.add(ws)
        queue: asyncio.Queue = asyncio.Queue(maxsize=MAX_WEB_MESSAGES_PER_S)
        worker = asyncio.ensure_future(self._actions(ws, queue))
        window, count = time.monotonic(), 0
        close = None
        try:
            while not worker.done():
                msg = await ws.receive()
                if msg["type"] == "websocket.disconnect":
                    break
                text = msg.get("text")
                if text is None:                 # a binary frame: the protocol is JSON text only
                    close = (CLOSE_UNSUPPORTED_DATA, "binary frames are not accepted")
                    break
                now = time.monotonic()
                if now - window >= 1.0:
                    window, count = now, 0
                count += 1
                if count > MAX_WEB_MESSAGES_PER_S or queue.full():
                    close = (CLOSE_POLICY_VIOLATION, "too many messages")
                    break
                if len(text) > MAX_WEB_MESSAGE_BYTES:
                    close = (CLOSE_MESSAGE_TOO_BIG, "message too large")
                    break
                queue.put_nowait((now, text))
        except WebSocketDisconnect:
            pass
        finally:
            # the actions stop before the connection closes: none of them sends on a closed one
            worker.cancel()
            with contextlib.suppress(asyncio.CancelledError, WebSocketDisconnect):
                await worker
            self.clients.discard(ws)
            self._shown.pop(ws, None)
            if close is not None:
                with contextlib.suppress(WebSocketDisconnect, RuntimeError):    # the page left meanwhile
                    await ws.close(code=close[0], reason=close[1])

    async def _actions(self, ws: WebSocket, queue: asyncio.Queue) -> None:
        """Carry out the queued messages of one connection in order, each answered with
        ``done`` or ``error`` (its id and op). A failure that is not a refusal closes the
        connection (1011) and is logged by uvicorn."""
        try:
            await self._carry_out(ws, queue)
        except (asyncio.CancelledError, WebSocketDisconnect):
            raise
        except Exception:
            if WebSocketState.DISCONNECTED in (ws.client_state, ws.application_state):
                return                  # the page left while an answer was being sent: nothing to report
            with contextlib.suppress(Exception):
                await ws.close(code=1011, reason="server error")
            raise

    async def _carry_out(self, ws: WebSocket, queue: asyncio.Queue) -> None:
        while True:
            arrived, text = await queue.get()
            try:
                msg = json.loads(text)
                if not isinstance(msg, dict):
                    raise ValueError("not an object")
            except ValueError:
                await ws.send_text(json.dumps({"type": "error", "text": "not a JSON object"}))
                continue
            rid = msg.get("id")
            try:
                async with self.busy:
                    await self.handle(ws, msg)
                await ws.send_text(json.dumps({"type": "done", "id": rid, "op": str(msg.get("op"))[:40],
                                               "ms": round((time.monotonic() - arrived) * 1000.0, 1)}))
            except (EngineError, PathRefused) as exc:
                await ws.send_text(json.dumps({"type": "error", "id": rid, "op": str(msg.get("op"))[:40],
                                               "text": str(exc)[:500]}))


#: the operations a page may send: :data:`OPERATIONS`' keys
OPS = tuple(OPERATIONS)


def create_app(pendant: Pendant, token: str, port_of) -> Guard:
    """The ASGI application: the page, its bundle and the websocket behind the guard."""

    async def index(request) -> Response:
        resp = FileResponse(STATIC / "index.html", media_type="text/html")
        resp.set_cookie(COOKIE, token, httponly=True, samesite="strict", path="/")
        return resp

    async def ws_endpoint(ws: WebSocket) -> None:
        await pendant.websocket(ws)

    @contextlib.asynccontextmanager
    async def lifespan(app):
        pendant.loop = asyncio.get_running_loop()
        ticker = asyncio.ensure_future(pendant.ticker())
        if pendant.initial:
            try:
                await pendant.select(pendant.initial)
            except (EngineError, PathRefused) as exc:
                print(f"krl pendant: {exc}", flush=True)
        try:
            yield
        finally:
            ticker.cancel()
            await asyncio.get_running_loop().run_in_executor(None, pendant.engine.cancel)

    async def not_found(request, exc) -> Response:
        return PlainTextResponse("not found\n", status_code=404)

    app = Starlette(routes=[Route("/", index), WebSocketRoute("/ws", ws_endpoint),
                            Mount("/static", StaticFiles(directory=STATIC), name="static")],
                    lifespan=lifespan, exception_handlers={404: not_found}, max_body_size=MAX_WEB_BODY_BYTES)
    return Guard(_Headers(app), token, port_of)


class _Headers:
    """Adds the page's security headers (CSP, no sniffing, no referrer, no caching of the token
    page) to every HTTP response."""

    def __init__(self, app) -> None:
        self.app = app

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def send_with(msg):
            if msg["type"] == "http.response.start":
                headers = list(msg.get("headers") or [])
                headers += [(b"content-security-policy", CSP.encode()), (b"x-content-type-options", b"nosniff"),
                            (b"referrer-policy", b"no-referrer"), (b"cache-control", b"no-store")]
                msg = {**msg, "headers": headers}
            await send(msg)
        await self.app(scope, receive, send_with)


__all__ = ["Pendant", "create_app", "CSP", "OPS"]
