"""A small DAP client: starts ``krl debug`` as a subprocess and talks to it over stdio
(the tests in tests/debug and the session transcript in docs/editors.md use it).

    with DapClient() as c:
        c.initialize()
        c.launch(program="prog.src", stopOnEntry=True)
        c.set_breakpoints("prog.src", [7])
        c.request("configurationDone")
        stopped = c.wait_event("stopped")
"""

from __future__ import annotations

import os
import queue
import subprocess
import sys
import threading
from pathlib import Path

from .wire import read_message, write_message

ROOT = Path(__file__).resolve().parents[2]


class DapError(Exception):
    """A request failed (its message) or an expected message did not come in time."""


class DapClient:
    def __init__(self, timeout: float = 60.0, transcript: list | None = None, root: Path = ROOT,
                 python: str | None = None, env: dict | None = None) -> None:
        """``root``: the checkout whose ``krl debug`` runs (default this one), with ``python``
        (default this interpreter); ``env``: variables added to the environment."""
        env = {**os.environ, **(env or {})}
        env["PYTHONPATH"] = str(root) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
        self.proc = subprocess.Popen([python or sys.executable, "-m", "app", "debug"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, cwd=str(root))
        self.timeout = timeout
        self.seq = 0
        self.msgs: queue.Queue = queue.Queue()
        self.events: list[dict] = []
        self.transcript = transcript
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        try:
            while True:
                msg = read_message(self.proc.stdout)
                self.msgs.put(msg)
                if msg is None:
                    return
        except Exception as exc:  # noqa: BLE001 - reported to the waiting test
            self.msgs.put({"type": "_error", "text": str(exc)})

    def _next(self) -> dict:
        try:
            msg = self.msgs.get(timeout=self.timeout)
        except queue.Empty:
            raise DapError("no message from krl debug in time") from None
        if msg is None:
            raise DapError("krl debug closed its output: " + self.proc.stderr.read().decode(errors="replace")[-2000:])
        if msg.get("type") == "_error":
            raise DapError(msg["text"])
        if self.transcript is not None:
            self.transcript.append(("<-", msg))
        return msg

    def send(self, command: str, arguments: dict | None = None) -> int:
        self.seq += 1
        msg = {"seq": self.seq, "type": "request", "command": command}
        if arguments is not None:
            msg["arguments"] = arguments
        if self.transcript is not None:
            self.transcript.append(("->", msg))
        write_message(self.proc.stdin, msg)
        return self.seq

    def request(self, command: str, arguments: dict | None = None, ok: bool = True) -> dict:
        """Send a request; its response (events that come first are kept). With ``ok`` a
        failed response raises :class:`DapError`."""
        seq = self.send(command, arguments)
        while True:
            msg = self._next()
            if msg.get("type") == "event":
                self.events.append(msg)
                continue
            if msg.get("type") == "response" and msg.get("request_seq") == seq:
                if ok and not msg.get("success"):
                    raise DapError(f"{command}: {msg.get('message')}")
                return msg

    def wait_event(self, name: str) -> dict:
        """The next event ``name`` (from those kept, then from the stream)."""
        for i, ev in enumerate(self.events):
            if ev.get("event") == name:
                return self.events.pop(i)
        while True:
            msg = self._next()
            if msg.get("type") == "event":
                if msg.get("event") == name:
                    return msg
                self.events.append(msg)

    # conveniences -----------------------------------------------------------------
    def initialize(self) -> dict:
        return self.request("initialize", {"adapterID": "krl", "linesStartAt1": True, "columnsStartAt1": True})

    def start(self, program, breakpoints: dict | None = None, function_breakpoints: list | None = None,
              **launch) -> dict:
        """initialize, launch, breakpoints, configurationDone; returns the first stopped event."""
        self.initialize()
        self.request("launch", {"program": str(program), **launch})
        for path, lines in (breakpoints or {}).items():
            self.set_breakpoints(path, lines)
        if function_breakpoints:
            self.request("setFunctionBreakpoints", {"breakpoints": [{"name": n} for n in function_breakpoints]})
        self.request("configurationDone")
        return self.wait_event("stopped")

    def set_breakpoints(self, path, lines: list) -> dict:
        bps = [x if isinstance(x, dict) else {"line": x} for x in lines]
        return self.request("setBreakpoints", {"source": {"path": str(path)}, "breakpoints": bps})

    def stack(self, thread: int = 1) -> list[dict]:
        return self.request("stackTrace", {"threadId": thread})["body"]["stackFrames"]

    def scope_vars(self, frame_id: int, scope: str) -> dict[str, str]:
        """name -> value text of a scope (Locals, Module data, Globals ($config.dat), System
        variables, I/O) of a frame."""
        scopes = self.request("scopes", {"frameId": frame_id})["body"]["scopes"]
        ref = next(s["variablesReference"] for s in scopes if s["name"] == scope)
        return {v["name"]: v["value"] for v in self.request("variables", {"variablesReference": ref})["body"]["variables"]}

    def evaluate(self, expression: str, frame_id: int | None = None, ok: bool = True) -> dict:
        args = {"expression": expression, "context": "watch"}
        if frame_id is not None:
            args["frameId"] = frame_id
        return self.request("evaluate", args, ok=ok)

    def value(self, expression: str, frame_id: int | None = None) -> str:
        return self.evaluate(expression, frame_id)["body"]["result"]

    def step(self, command: str = "next", thread: int = 1) -> dict:
        self.request(command, {"threadId": thread})
        return self.wait_event("stopped")

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                self.request("disconnect", {})
            except (DapError, OSError):
                pass
            try:
                self.proc.stdin.close()
            except OSError:
                pass
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        for s in (self.proc.stdout, self.proc.stderr):
            s.close()

    def __enter__(self) -> "DapClient":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
