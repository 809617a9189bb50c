"""The pendant's websocket protocol as a client sees it (pendant/server.py): the state comes
whole first and then as what changed, which merged gives what a new page is sent whole; the
messages are not compressed. The server is the real command; the client is the `websockets`
package's."""

from __future__ import annotations

import asyncio

import pytest

from pendant.client import act, connect, merge
from tests.pendant.harness import pendant_server


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    ws = tmp_path_factory.mktemp("ws") / "cell"
    ws.mkdir()
    (ws / "prog.src").write_text("DEF prog()\n  WAIT FOR $IN[3]\n  $OUT[2] = TRUE\nEND\n", encoding="utf-8")
    with pendant_server(ws, "--no-realtime") as url:
        yield url, ws


def _in(state: dict, n: int) -> bool:
    return next(r["value"] for r in state["io"]["$IN"] if r["index"] == n)


def test_state_is_sent_whole_then_as_what_changed(server):
    url, _root = server

    async def go():
        ws = await connect(url)
        try:
            # no compression is negotiated (the client offers permessage-deflate by default)
            assert ws.response.headers.get("Sec-WebSocket-Extensions") is None
            first = await act(ws, 1, "hello")
            assert first and first[0]["full"] is True and first[0]["state"] == "none"
            state = {}
            for m in first:
                state = merge(state, m)
            for m in await act(ws, 2, "select", program="prog.src"):
                state = merge(state, m)
            assert state["state"] == "stopped" and _in(state, 3) is False
            # nothing changed: the state message holds its state and nothing else of it
            same = await act(ws, 3, "watch", exprs=[])
            assert same and all(set(m) <= {"type", "state", "full"} for m in same), same
            assert not any(m.get("full") for m in same)
            # an input set by hand: the I/O is sent again, the unchanged parts are not
            changed = await act(ws, 4, "input", index=3, value=True)
            assert any("io" in m for m in changed), changed
            assert not any("pointers" in m or "position" in m for m in changed), changed
            for m in changed:
                state = merge(state, m)
            assert _in(state, 3) is True
            # what the page keeps is what a page connecting now is sent whole
            other = await connect(url)
            try:
                fresh = await act(other, 1, "watch", exprs=[])
            finally:
                await other.close()
            assert fresh[0]["full"] is True
            whole = {}
            for m in fresh:
                whole = merge(whole, m)
            strip = ("type", "full")
            assert {k: v for k, v in state.items() if k not in strip} == \
                   {k: v for k, v in whole.items() if k not in strip}
        finally:
            await ws.close()
    asyncio.run(go())
