"""Hostile requests to `krl pendant` (issue 36, docs/security.md "The pendant's web server"):
each is refused. The server is the real command on 127.0.0.1; the websocket client is the
`websockets` package's, the HTTP client the standard library's."""

from __future__ import annotations

import asyncio
import http.client
import json
from pathlib import Path
from urllib.parse import urlsplit

import pytest
import websockets

from krl.limits import MAX_WEB_CONNECTIONS, MAX_WEB_MESSAGE_BYTES, MAX_WEB_MESSAGES_PER_S
from tests.pendant.harness import browser_page, pendant_server, select

# the module's tests share its pendant server (a module fixture): one xdist group, so that one
# worker starts it once (spread over the three workers, each started its own)
pytestmark = [pytest.mark.xdist_group("pendant-security")]

PWNED = '<img src=x onerror="window.pwned=1"><script>window.pwned=1</script>'


@pytest.fixture(scope="module")
def workspace(tmp_path_factory) -> Path:
    """A folder of KRL with markup in its text and in a file name, and a secret beside it."""
    root = tmp_path_factory.mktemp("ws")
    ws = root / "cell"
    ws.mkdir()
    (ws / "prog.src").write_text(f"DEF prog()\n  ; {PWNED}\n  $OUT[1] = TRUE\nEND\n", encoding="utf-8")
    (ws / "prog.dat").write_text("DEFDAT prog\nDECL E6POS XP1={X 1.0,Y 2.0,Z 3.0,A 0.0,B 0.0,C 0.0,S 2,T 0}\nENDDAT\n")
    (root / "secret.dat").write_text("DEFDAT secret\nENDDAT\n")
    return ws


@pytest.fixture(scope="module")
def stderr(workspace) -> Path:
    """The file `krl pendant`'s stderr goes to."""
    return workspace.parent / "stderr.txt"


@pytest.fixture(scope="module")
def server(workspace, stderr):
    with pendant_server(workspace, "--no-realtime", stderr=stderr) as url:
        yield url


def _parts(url: str):
    u = urlsplit(url)
    return u.hostname, u.port, u.query.split("token=", 1)[1]


def _get(url: str, path: str, headers: dict | None = None) -> int:
    host, port, _ = _parts(url)
    c = http.client.HTTPConnection(host, port, timeout=30)
    c.request("GET", path, headers=headers or {})
    status = c.getresponse().status
    c.close()
    return status


def test_http_needs_token_host_and_origin(server):
    host, port, token = _parts(server)
    assert host == "127.0.0.1"                                   # loopback only
    assert _get(server, f"/?token={token}") == 200
    assert _get(server, "/") == 403                              # no token
    assert _get(server, "/?token=" + "x" * len(token)) == 403    # wrong token
    assert _get(server, "/", {"Authorization": "token nope"}) == 403
    assert _get(server, f"/?token={token}", {"Host": "evil.example"}) == 400          # DNS rebinding
    assert _get(server, f"/?token={token}", {"Origin": "http://evil.example"}) == 403  # cross-site
    assert _get(server, f"/static/../../../etc/passwd?token={token}") in (400, 403, 404)
    assert _get(server, f"/static/%2e%2e/%2e%2e/secret.dat?token={token}") in (400, 403, 404)


async def _ws(url: str, origin: str | None, token: str | None):
    host, port, good = _parts(url)
    q = f"?token={token}" if token is not None else ""
    headers = {"Origin": origin} if origin else {}
    return await websockets.connect(f"ws://{host}:{port}/ws{q}", additional_headers=headers,
                                    max_size=None, open_timeout=30)


def _refused(url, origin, token) -> bool:
    async def go():
        try:
            ws = await _ws(url, origin, token)
        except websockets.exceptions.InvalidStatus as exc:
            return exc.response.status_code == 403
        await ws.close()
        return False
    return asyncio.run(go())


def test_websocket_needs_token_and_origin(server):
    host, port, token = _parts(server)
    own = f"http://{host}:{port}"
    assert _refused(server, own, None)                       # no token
    assert _refused(server, own, "wrong")                    # wrong token
    assert _refused(server, "http://evil.example", token)    # cross-site websocket hijacking
    assert _refused(server, None, token)                     # no Origin
    assert not _refused(server, own, token)


def _session(url: str, messages: list) -> list:
    """Send ``messages`` on one accepted connection; the answers (or the close code)."""
    host, port, token = _parts(url)

    async def go():
        ws = await _ws(url, f"http://{host}:{port}", token)
        out = []
        try:
            for m in messages:
                await ws.send(m if isinstance(m, str) else json.dumps(m))
                while True:
                    a = json.loads(await asyncio.wait_for(ws.recv(), 120))
                    if a["type"] in ("done", "error"):
                        out.append(a)
                        break
        except websockets.exceptions.ConnectionClosed as exc:
            out.append({"closed": exc.rcvd.code if exc.rcvd else None})
        finally:
            await ws.close()
        return out
    return asyncio.run(go())


def test_paths_outside_the_workspace_are_refused(server, workspace):
    secret = str(workspace.parent / "secret.dat")
    answers = _session(server, [
        {"op": "open", "id": 1, "path": "../secret.dat"},
        {"op": "open", "id": 2, "path": secret},
        {"op": "open", "id": 3, "path": "/etc/passwd"},
        {"op": "select", "id": 4, "program": "../../../../etc/passwd"},
        {"op": "touchup", "id": 5, "path": secret, "name": "XP1"},
        {"op": "breakpoint", "id": 6, "path": "/etc/hosts", "line": 1, "on": True},
        {"op": "open", "id": 7, "path": "prog.src"},
    ])
    for a in answers[:6]:
        assert a["type"] == "error" and ("outside the workspace" in a["text"] or "no such file" in a["text"]
                                         or "not a" in a["text"]), a
    assert answers[6]["type"] == "done"


def test_bad_and_oversized_messages(server):
    answers = _session(server, ["not json", {"op": "rm -rf", "id": 1}, {"op": "watch", "id": 2, "exprs": ["x" * 10_000]}])
    assert [a["type"] for a in answers] == ["error", "error", "error"]
    assert _session(server, ["x" * (MAX_WEB_MESSAGE_BYTES + 1)]) == [{"closed": 1009}]

    host, port, token = _parts(server)

    async def flood():
        # sent without waiting for answers until the server closes the connection: however
        # slowly the server carries the actions out, it counts them as they arrive
        ws = await _ws(server, f"http://{host}:{port}", token)
        try:
            for i in range(MAX_WEB_MESSAGES_PER_S * 100):
                await ws.send(json.dumps({"op": "drives", "id": i, "on": False}))
            while True:
                await asyncio.wait_for(ws.recv(), 300)
        except websockets.exceptions.ConnectionClosed as exc:
            return exc.rcvd.code if exc.rcvd else None
    assert asyncio.run(flood()) == 1008


def _no_traceback(stderr: Path) -> None:
    text = stderr.read_text()
    assert "Traceback" not in text and "Cannot call" not in text and "KeyError" not in text, text[-3000:]


def test_a_binary_frame_and_a_flood_close_cleanly_with_their_codes(server, stderr):
    """A binary frame closes the connection with 1003 (it raised ``KeyError: 'text'`` and dropped
    it without a close frame), a flood with 1008; neither leaves a traceback on stderr (the
    flood logged "Cannot call send once a close message has been sent")."""
    host, port, token = _parts(server)

    async def binary():
        ws = await _ws(server, f"http://{host}:{port}", token)
        await ws.send(b"\x00\x01binary")
        try:
            await asyncio.wait_for(ws.recv(), 60)
        except websockets.exceptions.ConnectionClosed as exc:
            return exc.rcvd.code if exc.rcvd else None

    async def flood():
        ws = await _ws(server, f"http://{host}:{port}", token)
        try:
            for i in range(MAX_WEB_MESSAGES_PER_S * 20):
                await ws.send(json.dumps({"op": "hello", "id": i}))
            while True:
                await asyncio.wait_for(ws.recv(), 300)
        except websockets.exceptions.ConnectionClosed as exc:
            return exc.rcvd.code if exc.rcvd else None

    assert asyncio.run(binary()) == 1003
    assert asyncio.run(flood()) == 1008
    assert not _refused(server, f"http://{host}:{port}", token)         # the server goes on
    _no_traceback(stderr)


def test_one_connection_past_the_limit_is_closed_with_1013(server, stderr):
    """MAX_WEB_CONNECTIONS websockets are served; the next one is accepted and closed with
    1013 "try again later", as docs/security.md says (it was refused at the handshake: 403)."""
    host, port, token = _parts(server)

    async def go():
        held = [await _ws(server, f"http://{host}:{port}", token) for _ in range(MAX_WEB_CONNECTIONS)]
        try:
            extra = await _ws(server, f"http://{host}:{port}", token)
            try:
                await asyncio.wait_for(extra.recv(), 60)
            except websockets.exceptions.ConnectionClosed as exc:
                return exc.rcvd.code if exc.rcvd else None
        finally:
            for ws in held:
                await ws.close()
    assert asyncio.run(go()) == 1013
    _no_traceback(stderr)


def test_watch_assignment_and_override_go_through_the_write_rules(server):
    """The watch list's assignment and the override slider take the controller's write rules
    (interp/runtime/writerules.py): $OV_PRO 0..100 (the assignment took 1000 while the slider
    refused it), the safety controller's signals write-protected ($MOVE_ENABLE, $DRIVES_ON,
    $USER_SAF were set)."""
    answers = _session(server, [
        {"op": "select", "id": 1, "program": "prog.src"},
        {"op": "setWatch", "id": 2, "expr": "$OV_PRO", "value": "1000"},
        {"op": "setWatch", "id": 3, "expr": "$MOVE_ENABLE", "value": "FALSE"},
        {"op": "setWatch", "id": 4, "expr": "$DRIVES_ON", "value": "TRUE"},
        {"op": "setWatch", "id": 5, "expr": "$USER_SAF", "value": "FALSE"},
        {"op": "override", "id": 6, "value": 1000},
        {"op": "setWatch", "id": 7, "expr": "$OV_PRO", "value": "55"},
        {"op": "override", "id": 8, "value": 20},
    ])
    types = [a["type"] for a in answers]
    assert types == ["done", "error", "error", "error", "error", "error", "done", "done"], answers
    assert "value assignment inadmissible: $OV_PRO = 1000 out of limits [0; 100]" in answers[1]["text"]
    for a, name in zip(answers[2:5], ("$MOVE_ENABLE", "$DRIVES_ON", "$USER_SAF")):
        assert f"{name} is write-protected (a signal of the safety controller)" in a["text"], a
    assert "out of limits" in answers[5]["text"]


def test_krl_text_is_shown_as_text(pw, server):
    with browser_page(pw, server) as page:
        select(page, "prog.src", run_mode="GO", mode="T1")
        page.wait_for_selector('#program-view .ln[data-line="2"]')
        assert PWNED in page.locator('#program-view .ln[data-line="2"] .tx').inner_text()
        assert page.evaluate("() => window.pwned") is None
        assert page.locator("#program-view img, #program-view script").count() == 0
