"""The pendant's websocket protocol as a client sees it (pendant/server.py): the state comes
whole first and then as what changed, which merged gives what a new page is sent whole; the
messages are not compressed. The server is the real command; the client is the `websockets`
package's."""

from __future__ import annotations

import asyncio
import json
from urllib.parse import urlsplit

import pytest
import websockets

from tests.pendant.harness import pendant_server


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    ws = tmp_path_factory.mktemp("ws") / "cell"
    ws.mkdir()
    (ws / "prog.src").write_text("DEF prog()\n  WAIT FOR $IN[3]\n  $OUT[2] = TRUE\nEND\n", encoding="utf-8")
    with pendant_server(ws, "--no-realtime") as url:
        yield url, ws


async def _connect(url: str):
    u = urlsplit(url)
    token = u.query.split("token=", 1)[1]
    return await websockets.connect(f"ws://{u.hostname}:{u.port}/ws?token={token}", max_size=None,
                                    additional_headers={"Origin": f"http://{u.hostname}:{u.port}"})


async def _act(ws, rid: int, op: str, **args) -> list[dict]:
    """One action; the state messages that came with it (in order)."""
    await ws.send(json.dumps({"op": op, "id": rid, **args}))
    states = []
    while True:
        m = json.loads(await asyncio.wait_for(ws.recv(), 300))
        if m["type"] == "state":
            states.append(m)
        if m.get("id") == rid and m["type"] in ("done", "error"):
            assert m["type"] == "done", m
            return states


def _merge(state: dict, m: dict) -> dict:
    out = {} if m.get("full") else dict(state)
    for k, v in m.items():
        if v is None:
            out.pop(k, None)
        else:
            out[k] = v
    return out


def _in(state: dict, n: int) -> bool:
    return next(r["value"] for r in state["io"]["$IN"] if r["index"] == n)


def test_state_is_sent_whole_then_as_what_changed(server):
    url, _root = server

    async def go():
        ws = await _connect(url)
        try:
            # no compression is negotiated (the client offers permessage-deflate by default)
            assert ws.response.headers.get("Sec-WebSocket-Extensions") is None
            first = await _act(ws, 1, "hello")
            assert first and first[0]["full"] is True and first[0]["state"] == "none"
            state = {}
            for m in first:
                state = _merge(state, m)
            for m in await _act(ws, 2, "select", program="prog.src"):
                state = _merge(state, m)
            assert state["state"] == "stopped" and _in(state, 3) is False
            # nothing changed: the state message holds its state and nothing else of it
            same = await _act(ws, 3, "watch", exprs=[])
            assert same and all(set(m) <= {"type", "state", "full"} for m in same), same
            assert not any(m.get("full") for m in same)
            # an input set by hand: the I/O is sent again, the unchanged parts are not
            changed = await _act(ws, 4, "input", index=3, value=True)
            assert any("io" in m for m in changed), changed
            assert not any("pointers" in m or "position" in m for m in changed), changed
            for m in changed:
                state = _merge(state, m)
            assert _in(state, 3) is True
            # what the page keeps is what a page connecting now is sent whole
            other = await _connect(url)
            try:
                fresh = await _act(other, 1, "watch", exprs=[])
            finally:
                await other.close()
            assert fresh[0]["full"] is True
            whole = {}
            for m in fresh:
                whole = _merge(whole, m)
            strip = ("type", "full")
            assert {k: v for k, v in state.items() if k not in strip} == \
                   {k: v for k, v in whole.items() if k not in strip}
        finally:
            await ws.close()
    asyncio.run(go())
