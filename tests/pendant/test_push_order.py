"""The order of the state pushed to the pages (pendant/server.py ``Pendant._push_state``).

A key's snapshot is taken in its engine call; the key's coroutine pushes it when it resumes.
Under load the run can end in between, and the "exited" event's push (state "ended") reach the
pages first: pushed afterwards, the key's older snapshot (state "running") left the page showing a
running program that had ended (tests/pendant/test_page.py test_quit_message_is_acknowledged timed
out that way once, under load, on 2026-11-25). The engine here is a stand-in whose posted work
runs at once, so the interleaving is the one of that failure, every time."""

from __future__ import annotations

import asyncio
import json
from concurrent.futures import Future

from pendant.server import Pendant
from pendant.state import snapshot


class _Core:
    """The run-control engine as the server reads it: a state, no run, posted work done at once."""

    def __init__(self) -> None:
        self.state, self.done, self.rt, self.stop_body = "running", False, None, None

    def post(self, fn, *args) -> Future:
        fut: Future = Future()
        fut.set_result(fn(*args))
        return fut


class _Page:
    """A connected page: the state messages it was sent, merged as pendant/web/src/main.js merges
    them (a key sent as null is gone)."""

    def __init__(self) -> None:
        self.state: dict = {}

    async def send_text(self, text: str) -> None:
        msg = json.loads(text)
        if msg.get("type") != "state":
            return
        if msg.get("full"):
            self.state = {}
        for k, v in msg.items():
            if k in ("type", "full"):
                continue
            if v is None:
                self.state.pop(k, None)
            else:
                self.state[k] = v


def _served(tmp_path) -> tuple[Pendant, _Core, _Page]:
    """A pendant of an empty folder whose engine is the stand-in, with one page connected."""
    pendant, core, page = Pendant(tmp_path), _Core(), _Page()
    pendant.engine.core = core
    pendant.clients.add(page)
    return pendant, core, page


def test_an_older_snapshot_is_not_pushed_over_a_newer_one(tmp_path):
    pendant, core, page = _served(tmp_path)

    async def scenario():
        await pendant.push_state()                         # the page's first state: running
        assert page.state["state"] == "running"
        key = snapshot(pendant.engine, core, [])          # the acknowledgement's snapshot: running
        core.state = "ended"                              # the program ends right after the key
        await pendant.push_state()                         # the "exited" event's push
        assert page.state["state"] == "ended"
        await pendant.push_state(key)                      # the key's coroutine resumes
        return page.state["state"]

    assert asyncio.run(scenario()) == "ended"
    assert "seq" not in page.state                         # the engine's numbering stays on the server


def test_a_key_snapshot_newer_than_the_last_push_is_pushed_as_taken(tmp_path):
    pendant, core, page = _served(tmp_path)
    asked = []
    post = core.post
    core.post = lambda fn, *a: (asked.append(1), post(fn, *a))[1]

    async def scenario():
        await pendant.push_state()
        core.state = "stopped"
        key = snapshot(pendant.engine, core, [])          # taken after the last push: the newest
        core.state = "running"                            # (the engine moved on; the key's view stands)
        n = len(asked)
        await pendant.push_state(key)
        return page.state["state"], len(asked) - n

    assert asyncio.run(scenario()) == ("stopped", 0)      # pushed as taken, no new snapshot asked for
