"""The operator's API (issue 76): the debugger (interp/debug/engine.py) and the pendant
(pendant/engine.py) set an input, the override and a variable, and evaluate an expression,
through the run's own methods (``Controller.set_input``, ``SysVars.set_override``,
``Runtime.evaluation``, ``Names.assign``), never by writing an attribute of the runtime, the
controller, the I/O image or a task from their own modules, also while the run goes on.

The guard wraps those classes' ``__setattr__`` for the test: a set whose code lies in a front
end's module (interp/debug/, pendant/) is a violation, before the run starts and during it."""

from __future__ import annotations

import inspect
import sys
from pathlib import Path

import pytest

from interp.debug.engine import LaunchConfig
from interp.run import make_runtime, run_spec
from interp.runtime.core import Runtime
from interp.runtime.scheduler import Task
from pendant.engine import override, set_input
from robot.controller import Controller
from robot.io import IOImage

from .test_engine import CASES, Front

REPO = Path(__file__).resolve().parents[2]
#: the front ends: code there drives a run through its methods
FRONT_ENDS = (REPO / "interp" / "debug", REPO / "pendant")
#: 011_call_in_out: a = 1 (l.4), arr[2] = 5 (l.5), f = ... (l.6)
CALL = CASES / "011_call_in_out" / "program.src"


class FrontEndGuard:
    """Attribute sets on runtimes, controllers, I/O images and tasks from a front end's code."""

    def __init__(self, monkeypatch) -> None:
        self.violations: list[str] = []
        for cls in (Runtime, Controller, IOImage, Task):
            self._wrap(monkeypatch, cls)

    def _wrap(self, monkeypatch, cls) -> None:
        inner = cls.__setattr__
        guard = self

        def setattr_(obj, name, value):
            f = sys._getframe(1)
            path = Path(f.f_code.co_filename).resolve()
            if any(path.is_relative_to(d) for d in FRONT_ENDS):
                guard.violations.append(f"{cls.__name__}.{name} set by {f.f_code.co_qualname} "
                                        f"({path.relative_to(REPO)}:{f.f_lineno})")
            inner(obj, name, value)
        monkeypatch.setattr(cls, "__setattr__", setattr_)


@pytest.fixture
def guard(monkeypatch):
    return FrontEndGuard(monkeypatch)


def test_the_guard_sees_a_front_ends_set(guard):
    """The test can fail: a set from code compiled as a front end's module is caught."""
    code = compile("rt.trace = None\nrt.controller.io.now = 1.0\n", str(FRONT_ENDS[0] / "x.py"), "exec")
    rt, _ = make_runtime(run_spec(CALL, mujoco=False, max_sim_time=1.0))
    exec(code, {"rt": rt})      # noqa: S102 - a fixed text of the test
    assert [v.split(" set by ")[0] for v in guard.violations] == ["Runtime.trace", "IOImage.now"]


def test_the_debugger_and_the_pendant_use_the_runs_methods(guard):
    """At a stop and while the program runs: evaluate, assign, the debugger's and the pendant's
    input, the pendant's override; each takes effect (read back through the run) and no front
    end writes an attribute of the run."""
    front = Front()
    try:
        e = front.engine
        front.call(e.launch, LaunchConfig.of(CALL))
        front.call(e.set_breakpoints, str(CALL), [{"line": 6}])
        front.call(e.configuration_done)
        assert front.wait("stopped")["reason"] == "breakpoint"
        assert front.call(e.evaluate, "a * 2") == 2                         # a = 1 at line 6
        assert front.call(e.assign, "a", "40 + 2") == "42"
        assert front.call(e.set_input, 7, True) is True
        assert front.call(set_input, e, 8, True) is True
        assert front.call(override, e, 35) == 35
        assert front.call(e.evaluate, "$IN[7] AND $IN[8]") is True
        assert front.call(e.evaluate, "$OV_PRO") == 35
        rt = e.rt
        assert rt.trace is None and rt.controller.io.get_in(7)
        front.call(e.resume)
        assert front.wait("exited")["exitCode"] == 0
    finally:
        front.close()
    assert sorted(set(guard.violations)) == []
