"""The run-control engine (interp/debug/engine.py) driven through its Python API from another
thread, as the pendant's web front drives it: launch, a breakpoint, the stopped event, the
variables, an edit, step back with the edit replayed. Expected values are read off the
conformance programs by hand (the comments say how)."""

from __future__ import annotations

import queue
from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main
from interp.debug.engine import Engine, LaunchConfig, Refused, thread_main

CASES = Path(__file__).resolve().parents[2] / "conformance" / "cases"
CALL = CASES / "011_call_in_out" / "program.src"
WHILE = CASES / "007_while" / "program.src"


class Front:
    """A front end: the engine on its own thread, its events in a queue."""

    def __init__(self) -> None:
        self.events: queue.Queue = queue.Queue()
        self.engine = Engine(on_event=lambda name, body: self.events.put((name, body)))
        self.thread = thread_main(self.engine)

    def call(self, fn, *args):
        return self.engine.call(fn, *args, timeout=120)

    def wait(self, name: str) -> dict:
        while True:
            ev, body = self.events.get(timeout=120)
            if ev == name:
                return body

    def close(self) -> None:
        self.engine.close()
        self.thread.join(60)
        assert not self.thread.is_alive()


@pytest.fixture
def front():
    f = Front()
    yield f
    f.close()


def test_breakpoint_edit_and_step_back_through_the_python_api(front):
    # 011_call_in_out: a = 1 (l.4), arr[2] = 5 (l.5), f = {X 1, Y 2, Z 3, ...} (l.6), Bump (l.7)
    e = front.engine
    front.call(e.launch, LaunchConfig.of(CALL))
    front.call(e.set_breakpoints, str(CALL), [{"line": 6}])
    front.call(e.configuration_done)
    stopped = front.wait("stopped")
    assert stopped["reason"] == "breakpoint" and stopped["threadId"] == 1
    assert front.wait("krl/pointers")["advanceRun"]["line"] == 6
    frame = front.call(e.stack, 1)[0]
    assert (frame.name, frame.line) == ("program", 6)
    scopes = dict(front.call(e.scopes, frame))
    local = {v.name: v.value for v in front.call(e.variables, scopes["Locals"])}
    assert local["a"] == "1" and local["f"] == "{}"
    # edits at this stop, by names in another letter case
    assert front.call(e.set_variable, scopes["Locals"], "A", "40 + 2") == "42"
    assert front.call(e.assign, "ARR[1]", "a + 1") == "43"
    assert front.call(e.evaluate, "a * 2") == 84
    # step over line 6, then back: the edited state, not the original one
    front.call(e.step, "over", 1)
    assert front.wait("stopped")["reason"] == "step"
    assert front.call(e.stack, 1)[0].line == 7
    front.call(e.step_back)
    assert front.wait("stopped")["reason"] == "step"
    assert front.call(e.stack, 1)[0].line == 6
    assert (front.call(e.evaluate, "a"), front.call(e.evaluate, "arr[1]")) == (42, 43)
    # to the end: a is 42 after Bump, so the IF of line 8 is FALSE and $OUT[1] stays FALSE
    front.call(e.set_breakpoints, str(CALL), [{"line": 8}])
    front.call(e.resume)
    front.wait("stopped")
    assert front.call(e.evaluate, "a") == 42 and front.call(e.evaluate, "arr[2]") == 6
    front.call(e.resume)
    assert front.wait("exited")["exitCode"] == 0


def test_going_back_before_an_edit_forgets_it(front):
    # 007_while: n = 1 (l.3); WHILE n < 20 (l.4): n = n * 3 (l.5) runs with n = 1, 3, 9
    e = front.engine
    front.call(e.launch, LaunchConfig.of(WHILE))
    front.call(e.set_breakpoints, str(WHILE), [{"line": 5}])
    front.call(e.configuration_done)
    front.wait("stopped")
    assert front.call(e.evaluate, "n") == 1
    frame = front.call(e.stack, 1)[0]
    front.call(e.set_variable, dict(front.call(e.scopes, frame))["Locals"], "n", "100")
    front.call(e.step_back)                                 # before the edit: n = 1 at l.4
    front.wait("stopped")
    assert front.call(e.stack, 1)[0].line == 4 and front.call(e.evaluate, "n") == 1
    front.call(e.resume)                                    # the loop runs as written: n = 1 at l.5
    front.wait("stopped")
    assert front.call(e.evaluate, "n") == 1


def test_refusals_are_refused_errors(front):
    e = front.engine
    with pytest.raises(Refused, match="not stopped"):
        front.call(e.resume)
    front.call(e.launch, LaunchConfig.of(CALL, stop_on_entry=True))
    front.call(e.configuration_done)
    assert front.wait("stopped")["reason"] == "entry"
    with pytest.raises(Refused, match="value invalid"):
        front.call(e.evaluate, "a")
    with pytest.raises(Refused, match="backward motion"):
        front.call(e.backward_motion)


def test_the_trace_is_whole_when_the_program_ends(front, tmp_path):
    # 053_lin_straight moves (a PTP, then a LIN of 200 mm): the writer completes its trace at
    # its close. A front end that shows "ended" (the pendant's page, a DAP client's
    # "terminated") may read the file at once: it must then hold the whole run, the same bytes
    # as `krl run --trace` of the program writes (interp/run.py RunSetup.trace_writer: one rule
    # for both) and as the file after the session's end.
    program = CASES / "053_lin_straight" / "program.src"
    trace, by_run = tmp_path / "debug.jsonl", tmp_path / "run.jsonl"
    e = front.engine
    front.call(e.launch, LaunchConfig.of(program, trace_path=str(trace)))
    front.call(e.configuration_done)
    front.wait("terminated")
    at_end = trace.read_bytes()
    result = CliRunner().invoke(main, ["run", str(program), "--trace", str(by_run)])
    assert result.exit_code == 0, result.output
    assert at_end == by_run.read_bytes()
    assert at_end.count(b'"kind":"motion"') == 4 and b'"kind":"end","reason":"completed"' in at_end
    front.close()
    front.close = lambda: None
    assert trace.read_bytes() == at_end
