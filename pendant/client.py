"""A client of ``krl pendant`` for the benchmark and the tests: the command started as a user
starts it, its websocket protocol spoken with the ``websockets`` package, and the flags
headless Chromium runs the page with here.

Protocol (pendant/server.py, docs/pendant.md): the client connects to ``/ws?token=TOKEN``
with an ``Origin`` of the page's own host; it sends ``{"op": OP, "id": N, ...}`` and receives
``state`` messages (the whole state when ``full`` is true, else what changed, a key gone being
null) and then ``done`` or ``error`` (``text``) carrying the same ``id``.
"""

from __future__ import annotations

import asyncio
import json
import os
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from urllib.parse import parse_qs, urlsplit
import websockets

ROOT = Path(__file__).resolve().parents[1]
#: Debian's Chromium, headless, for Playwright (the machine notes: no sandbox as root, no GPU,
#: nothing fetched from the network)
CHROMIUM_FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync"]
#: how long one answer may take (s): a selection checks a whole backup, minutes when loaded
ANSWER_TIMEOUT_S = 300.0


class PendantClientError(Exception):
    """``krl pendant`` did not start, or refused an action (the reason)."""


@contextmanager
def pendant_server(target: Path, *args: str, root: Path = ROOT, stderr: Path | None = None,
                   python: str | None = None) -> Iterator[tuple[subprocess.Popen, str]]:
    """``krl pendant TARGET --no-browser ARGS...`` of the checkout ``root`` (its packages are
    imported from there), run by ``python`` (default this interpreter; the test suite's fork
    server's launcher, tests/forkserver.py): yields (the process, the URL with the token it
    printed first), and ends the process on exit. Its stderr goes to a file (a pipe nobody
    reads would stall the server once full; ``stderr``: that file, to read it, else a temporary
    one); the last of it is printed when the body fails and is in the error raised
    (``PendantClientError``) when the first line is not the URL."""
    cmd = [python or sys.executable, "-m", "app", "pendant", str(target), "--no-browser", *args]
    with (open(stderr, "w+") if stderr is not None else tempfile.TemporaryFile("w+")) as err:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=err, text=True, cwd=root,
                                env={**os.environ, "PYTHONUNBUFFERED": "1"})
        try:
            url = proc.stdout.readline().strip()
            if not url.startswith("http://127.0.0.1:"):
                proc.kill()
                proc.wait(30)
                err.seek(0)
                raise PendantClientError(f"krl pendant printed {url!r} first; stderr:\n{err.read()[-3000:]}")
            try:
                yield proc, url
            except BaseException:
                err.seek(0)
                print(f"krl pendant's stderr:\n{err.read()[-5000:]}", file=sys.stderr)
                raise
        finally:
            proc.terminate()
            try:
                proc.wait(30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(30)


async def connect(url: str):
    """A websocket connection (``websockets.ClientConnection``) to the pendant at ``url`` (the
    page's URL with ``?token=``), with the token and the page's Origin; no message size limit.
    Raises ValueError for a URL without a token, and what ``websockets.connect`` raises when
    refused (``InvalidStatus``) or unreachable (OSError)."""

    u = urlsplit(url)
    token = parse_qs(u.query).get("token")
    if not token:
        raise ValueError(f"{url!r} holds no token")
    return await websockets.connect(f"ws://{u.hostname}:{u.port}/ws?token={token[0]}", max_size=None,
                                    additional_headers={"Origin": f"http://{u.hostname}:{u.port}"})


def merge(state: dict | None, m: dict) -> dict:
    """The state after the state message ``m`` as the page keeps it: ``m`` itself when it is
    whole (``full``) or nothing came before, else ``state`` with ``m``'s keys replaced and those
    ``m`` sets to null removed. ``state`` is not changed."""
    out = {} if m.get("full") or state is None else dict(state)
    for k, v in m.items():
        if v is None:
            out.pop(k, None)
        else:
            out[k] = v
    return out


async def act(ws, rid: int, op: str, **args) -> list[dict]:
    """Send action ``op`` (with ``id`` ``rid`` and ``args``) and return the state messages that
    came until its answer, in order. Raises PendantClientError when the answer is ``error``,
    TimeoutError when a message takes longer than ANSWER_TIMEOUT_S."""
    await ws.send(json.dumps({"op": op, "id": rid, **args}))
    states = []
    while True:
        m = json.loads(await asyncio.wait_for(ws.recv(), ANSWER_TIMEOUT_S))
        if m["type"] == "state":
            states.append(m)
        if m.get("id") == rid and m["type"] in ("done", "error"):
            if m["type"] == "error":
                raise PendantClientError(f"{op}: {m.get('text')} ({m})")
            return states


async def act_state(ws, rid: int, op: str, **args) -> dict:
    """``act``, its state messages merged (a fresh connection's first is whole); when none came
    with the answer, the next state message. Raises as ``act``."""
    state = None
    for m in await act(ws, rid, op, **args):
        state = merge(state, m)
    while state is None:
        m = json.loads(await asyncio.wait_for(ws.recv(), ANSWER_TIMEOUT_S))
        if m["type"] == "state":
            state = merge(state, m)
    return state
