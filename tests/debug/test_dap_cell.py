"""`krl debug` on a cell of several robots: a thread per robot (issue 89; interp/debug/cellrun.py,
docs/cells.md "The debugger"), driven over stdio by the project's DAP client.

The cell, read by hand: R1 (handler.src) raises $OUT[10] at line 4 after 0.5 s and waits at
line 5 for $IN[11]; R2 (pal.src) waits at line 2 for $IN[10] (wired from R1's $OUT[10]), then
reaches line 3, raises $OUT[11] at line 4 (wired to R1's $IN[11]) and moves. So when R2 stops at
pal.src:3, R1 stands at handler.src:5 with $OUT[10] TRUE and $IN[11] FALSE; R2 sees $IN[10] TRUE
and its $OUT[11] still FALSE. Robot k's threads are numbered k * 10000 + a single run's (the
robot program 1): R1's robot program is thread 1, R2's 10001.
"""

from __future__ import annotations

import pytest

from interp.debug.client import DapClient
from tests.interp.test_robotcell import _cell


def _files(tmp_path):
    """The hand-off cell of tests/interp/test_robotcell.py (handler.src, pal.src, cell.yaml)."""
    return _cell(tmp_path)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_thread_per_robot_breakpoints_stacks_and_values_of_each(tmp_path, interp):
    cell = _files(tmp_path)
    with DapClient() as c:
        st = c.start(cell, breakpoints={tmp_path / "pal.src": [3]}, interp=interp)
        assert st["body"]["reason"] == "breakpoint" and st["body"]["threadId"] == 10001
        assert st["body"]["allThreadsStopped"] is True
        threads = {t["id"]: t["name"] for t in c.request("threads")["body"]["threads"]}
        assert threads == {1: "R1: robot program handler", 10001: "R2: robot program pal"}
        r2 = c.stack(10001)
        r1 = c.stack(1)
        assert [(f["name"], f["line"], f["source"]["path"].endswith("pal.src")) for f in r2] == [("pal()", 3, True)]
        assert [(f["name"], f["line"], f["source"]["path"].endswith("handler.src")) for f in r1] == \
            [("handler()", 5, True)]
        # each thread's values are its own robot's
        assert (c.value("$OUT[10]", r1[0]["id"]), c.value("$IN[11]", r1[0]["id"])) == ("TRUE", "FALSE")
        assert (c.value("$IN[10]", r2[0]["id"]), c.value("$OUT[11]", r2[0]["id"])) == ("TRUE", "FALSE")
        assert c.scope_vars(r1[0]["id"], "I/O")["$OUT[10]"] == "TRUE"
        # reverse execution is refused in a cell, the session goes on
        back = c.request("stepBack", {"threadId": 10001}, ok=False)
        assert back["success"] is False and "cell" in back["message"]
        # a step follows R2's task: pal.src:4, R1 still waiting at handler.src:5
        st = c.step("next", thread=10001)
        assert st["body"]["reason"] == "step" and st["body"]["threadId"] == 10001
        assert [f["line"] for f in c.stack(10001)] == [4] and [f["line"] for f in c.stack(1)] == [5]
        c.request("continue", {"threadId": 10001})
        assert c.wait_event("exited")["body"]["exitCode"] == 0
        out = "".join(e["body"]["output"] for e in c.events if e.get("event") == "output")
        assert "cell       2 robots: completed" in out and "released by R2 $OUT[11] -> R1 $IN[11]" in out


def test_a_breakpoint_in_each_robot_stops_each_thread_in_turn(tmp_path):
    """Breakpoints in both robots' programs: R1's line 4 first (0.5 s), then R2's line 3 (after
    R1's $OUT[10] reaches it); each stop names its own robot's thread."""
    cell = _files(tmp_path)
    with DapClient() as c:
        st = c.start(cell, breakpoints={tmp_path / "handler.src": [4], tmp_path / "pal.src": [3]}, interp="vm")
        assert st["body"]["threadId"] == 1 and [f["line"] for f in c.stack(1)] == [4]
        assert [f["line"] for f in c.stack(10001)] == [2]            # R2 waits for $IN[10]
        c.request("continue", {"threadId": 1})
        st = c.wait_event("stopped")
        assert st["body"]["threadId"] == 10001 and [f["line"] for f in c.stack(10001)] == [3]
        c.request("continue", {"threadId": 10001})
        assert c.wait_event("exited")["body"]["exitCode"] == 0
