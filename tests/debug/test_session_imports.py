"""A debug session imports what a launch needs in a thread of its own while the client starts
(interp/debug/session.py ``_prepare``); every request after ``initialize`` waits for that thread,
so that two threads never import the project's packages at once (the launch failed one time in
two with "KeyError: 'robot.kinematics'" when they did)."""

from __future__ import annotations

import io
import threading

from interp.debug.session import DebugSession


def test_a_request_after_initialize_waits_for_the_sessions_imports():
    s = DebugSession(io.BytesIO(), io.BytesIO())
    release = threading.Event()
    order: list[str] = []

    def imports():
        release.wait(60)
        order.append("imports")

    s._preparing = threading.Thread(target=imports, daemon=True)
    s._preparing.start()
    s.req_initialize = lambda req, args: order.append("initialize")
    s.req_threads = lambda req, args: order.append("threads")
    s.dispatch({"type": "request", "command": "initialize", "seq": 1})
    assert order == ["initialize"]                  # initialize is answered at once
    later = threading.Thread(target=s.dispatch, args=({"type": "request", "command": "threads", "seq": 2},))
    later.start()
    later.join(0.5)
    assert order == ["initialize"]                  # still waiting for the imports
    release.set()
    later.join(60)
    assert order == ["initialize", "imports", "threads"]
