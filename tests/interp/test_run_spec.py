"""One run described once (issue 62, interp/spec.py): every front door builds a RunSpec,
``make_runtime`` takes that one value, and the runtime and controller it builds are complete —
from the end of their construction to the start of the run nothing outside their classes sets
one of their attributes (a method of theirs may change what it holds).

The guard wraps ``Runtime``, its parts (:data:`PARTS`: interp/runtime/calls.py, names.py, ...),
``Controller`` and the controller's components (:data:`COMPONENTS`: robot/motionqueue.py,
signals.py, readback.py, monitor.py, events.py) for the test: their constructors note each
object built (and the Runtime its spec), ``Runtime.run`` notes the run's start, and an attribute
set on a built object that is not yet running is a violation unless the code setting it is one of
the class's own (a method, or a function defined in one)."""

from __future__ import annotations

import dataclasses
import inspect
import sys

import pytest

from interp.debug.engine import Engine, LaunchConfig
from interp.outcomes import run_outcome
from interp.run import RunSetup, RunSinks, make_runtime, run_setup, run_spec
from interp.runtime.calls import Calls
from interp.runtime.core import Runtime
from interp.runtime.cyclic import Cyclic
from interp.runtime.errstate import ErrorState
from interp.runtime.interrupts import Interrupts
from interp.runtime.motions import MotionStatements
from interp.runtime.names import Names
from interp.runtime.stepping import Stepping
from interp.spec import RUN_SIM_TIME_S, RunSpec, SpecError
from interp.summary import RunObserver
from robot.collision import CellGeometry
from robot.controller import Controller
from robot.events import EventLog
from robot.monitor import Monitor
from robot.motionqueue import MotionQueue
from robot.readback import ReadBack
from robot.signals import Signals
from robot.trace import TraceWriter

from .helpers import write

PROG = """
DEF prog()
  WAIT FOR $IN[5]
  $OUT[3] = TRUE
  PTP {A1 10, A2 -90, A3 90, A4 0, A5 30, A6 0}
END
"""

CELL = """
stimuli:
  - at: 0.1
    set: {"$IN[5]": true}
rules:
  - when: $OUT[3]
    set: {"$IN[6]": true}
start: "{A1 5, A2 -90, A3 90, A4 0, A5 30, A6 0}"
"""


#: the runtime's parts (interp/runtime/core.py ``Runtime.__init__``): its attribute -> class
PARTS = {"calls": Calls, "names": Names, "errstate": ErrorState, "cyclic": Cyclic, "motions": MotionStatements,
         "interrupts": Interrupts, "stepping": Stepping}
#: the controller's components (robot/controller.py ``Controller.__init__``): its attribute -> class
COMPONENTS = {"queue": MotionQueue, "signals": Signals, "actual": ReadBack, "monitor": Monitor, "log": EventLog}


class _Guard:
    """Attribute sets on built runtimes and controllers from outside their classes (module
    docstring)."""

    def __init__(self, monkeypatch) -> None:
        self.built: dict = {}           # id -> the object (kept alive for the test)
        self.running: set = set()
        self.specs: list = []
        self.violations: list[str] = []
        for cls in (Runtime, Controller, *PARTS.values(), *COMPONENTS.values()):
            self._wrap(monkeypatch, cls)
        run = Runtime.run

        def run_(rt):
            ctl = rt.controller
            self.running.add(id(rt))
            self.running.add(id(ctl))
            self.running.update(id(getattr(rt, name)) for name in PARTS)
            self.running.update(id(getattr(ctl, name)) for name in COMPONENTS)
            return run(rt)
        monkeypatch.setattr(Runtime, "run", run_)

    def _wrap(self, monkeypatch, cls) -> None:
        init = cls.__init__
        module = inspect.getsourcefile(cls)
        guard = self

        def init_(obj, *a, **k):
            init(obj, *a, **k)
            guard.built[id(obj)] = obj
            if cls is Runtime:
                guard.specs.append(obj.spec)       # Runtime(loaded, plan, spec, sinks)

        def setattr_(obj, name, value):
            if id(obj) in guard.built and id(obj) not in guard.running:
                f = sys._getframe(1)
                code = f.f_code
                if code.co_filename != module or code.co_qualname.split(".")[0] != cls.__name__:
                    guard.violations.append(f"{cls.__name__}.{name} set by {code.co_qualname} "
                                            f"({code.co_filename}:{f.f_lineno})")
            object.__setattr__(obj, name, value)
        monkeypatch.setattr(cls, "__init__", init_)
        monkeypatch.setattr(cls, "__setattr__", setattr_)


@pytest.fixture
def guard(monkeypatch):
    return _Guard(monkeypatch)


def test_the_guard_sees_a_set_from_outside(tmp_path, guard):
    """The test can fail: a runtime attribute, a controller attribute and an attribute of each of
    the runtime's parts and of the controller's components set here are caught; a part's own
    method setting its attribute is not."""
    rt, _ = make_runtime(run_spec(write(tmp_path, "prog.src", PROG), mujoco=False, max_sim_time=1.0))
    rt.halt_continues = 3
    ctl = rt.controller
    ctl.time = 1.0
    for name, cls in PARTS.items():
        part = getattr(rt, name)
        assert type(part) is cls
        first = cls.__slots__[0]                # an attribute of the part's own
        setattr(part, first, getattr(part, first))
    rt.stepping.set_hooks(stmt=lambda task, info: None)
    for name, cls in COMPONENTS.items():
        assert type(getattr(ctl, name)) is cls
    ctl.queue.advance = 1
    ctl.signals.pulses = []
    ctl.actual.tool_T = ctl.actual.tool_T
    ctl.monitor.workspaces = None
    ctl.log.trace = None
    ctl.queue.set_advance(2)                    # a component's own method
    assert [v.split(" set by ")[0] for v in guard.violations] == \
        ["Runtime.halt_continues", "Controller.time"] + [f"{cls.__name__}.{cls.__slots__[0]}" for cls in PARTS.values()] + \
        ["MotionQueue.advance", "Signals.pulses", "ReadBack.tool_T", "Monitor.workspaces", "EventLog.trace"]
    assert rt.stepping.stmt_hook is not None and ctl.queue.advance == 2


def test_make_runtime_builds_complete_objects(tmp_path, guard):
    """A cell file (stimuli, a rule, a start), the automatic cell, a trace and an observer (the
    run's sinks, apart from its spec), the VM: the run is built without a set from outside, and
    runs to the end."""
    p = write(tmp_path, "prog.src", PROG)
    cell = write(tmp_path, "cell.yaml", CELL)
    trace = TraceWriter(keep=True)
    for kw, sinks in ((dict(inputs=cell), None), (dict(inputs="auto", interp="vm"), None),
                      (dict(inputs=cell, run_mode="MSTEP", mode="T1"),
                       RunSinks(trace=trace, observer=RunObserver(inner=trace)))):
        rt, _ = make_runtime(run_spec(p, mujoco=False, max_sim_time=5.0, **kw), sinks)
        assert rt.spec is guard.specs[-1] and isinstance(rt.spec, RunSpec)
        res = rt.run()
        assert res.reason == "completed", (kw, res.text)
    assert guard.violations == []


def test_krl_run_and_the_debugger_build_one_spec(tmp_path, guard):
    """krl run's and the debugger's front door (run_setup: krl run's options by their click
    names) makes one RunSpec, validated there, defaults from interp/spec.py; the debugger's
    launch builds its run from it."""
    p = write(tmp_path, "prog.src", PROG)
    cell = write(tmp_path, "cell.yaml", CELL)
    with run_setup({"program": p, "inputs": cell, "max_steps": 1000, "override": 40, "on_halt": "continue:2"}) as setup:
        assert isinstance(setup, RunSetup) and isinstance(setup.spec, RunSpec)
        assert setup.spec.max_sim_time == RUN_SIM_TIME_S and setup.spec.run_mode == "GO"
        assert setup.spec.cell is not None and setup.spec.robot is not None
        assert (setup.spec.override, setup.spec.halt_continues) == (40, 2)
        trace = setup.trace_writer()
        rt, _ = setup.make_runtime(RunSinks(trace=trace, observer=RunObserver(inner=trace)))
        assert rt.sysvars.store["$OV_PRO"] == 40 and rt.halt_continues == 2
    engine = Engine()
    engine.launch(LaunchConfig.of(str(p), inputs=str(cell)))
    assert isinstance(engine.setup.spec, RunSpec)
    assert len(guard.specs) == 2 and all(isinstance(s, RunSpec) for s in guard.specs)
    assert guard.violations == []


def test_the_change_reports_front_door_builds_a_spec(tmp_path, guard):
    """The change report's and the audit's run of a program (interp/outcomes.py, --inputs auto)."""
    out = run_outcome(str(write(tmp_path, "prog.src", PROG)), max_sim_time=2.0)
    assert out["reason"] == "completed"
    assert len(guard.specs) == 1 and isinstance(guard.specs[0], RunSpec)
    assert guard.violations == []


def test_a_spec_is_frozen_and_checked():
    spec = RunSpec("prog.src")
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.max_steps = 3
    assert spec.with_(max_steps=3).max_steps == 3 and spec.max_steps is None
    for bad in (dict(interp="jit"), dict(run_mode="FAST"), dict(max_sim_time=0.0), dict(max_steps=0),
                dict(auto=True, cell=object()), dict(override=0), dict(override=101)):
        with pytest.raises(SpecError):
            RunSpec("prog.src", **bad)
    assert inspect.signature(make_runtime).parameters.keys() == {"spec", "sinks"}


def test_the_spec_carries_the_collision_geometry(tmp_path, guard):
    """The bodies the robot is checked against come with the spec (tools/whole_run_bench.py
    --collision: the robot against itself, no cell file), else from the cell file; without
    either no collision check is built."""
    p = write(tmp_path, "prog.src", PROG)
    rt, _ = make_runtime(run_spec(p, mujoco=False, max_sim_time=1.0))
    assert rt.controller.monitor.collision is None
    rt, _ = make_runtime(run_spec(p, mujoco=False, max_sim_time=1.0, geometry=CellGeometry(floor=None)))
    assert rt.controller.monitor.collision is not None
    cell = write(tmp_path, "cell.yaml", "floor: 0\n")
    rt, _ = make_runtime(run_spec(p, mujoco=False, max_sim_time=1.0, inputs=cell))
    assert rt.controller.monitor.collision is not None
    assert guard.violations == []
