"""The operator's API (issue 76): the debugger (interp/debug/engine.py) and the pendant
(pendant/engine.py) set an input, the override and a variable, and evaluate an expression,
through the run's own methods (``Controller.set_input``, ``SysVars.set_override``,
``Runtime.evaluation``, ``Names.assign``), never by writing an attribute of the runtime, the
controller, the I/O image or a task from their own modules, also while the run goes on; nor
does any other module outside the run (issue 76's Done-when: the tools, the tests and their
helpers included).

The run is the code of :data:`RUN_CODE`: the runtime (interp/runtime/), the interpreters it
builds and that count its steps (interp/tree/, interp/vm/) and the controller's package (robot/).
Two guards: :class:`OutsideGuard` wraps those classes' ``__setattr__`` for a test, and a set
whose code lies elsewhere is a violation, before the run starts and during it (the debugger and
the pendant driving a run); :func:`outside_writes` reads every module of the repository outside
the run, the tests' own included, and finds each assignment to an attribute (or an element of
one) reached from a runtime or a controller: a name bound to one (``rt``, ``ctl``, the first of
``make_runtime``'s pair) or an attribute chain through one (``engine.rt``, ``x.controller``)."""

from __future__ import annotations

import ast
import inspect
import os
import re
import sys
from pathlib import Path

import pytest

from interp.debug.engine import LaunchConfig
from interp.run import make_runtime, run_spec
from interp.runtime.core import Runtime
from interp.runtime.scheduler import Task
from interp.runtime.tracing import Tracing
from pendant.engine import override, set_input
from robot.controller import Controller
from robot.io import IOImage

from .test_engine import CASES, Front

REPO = Path(__file__).resolve().parents[2]
#: the front ends: code there drives a run through its methods
FRONT_ENDS = (REPO / "interp" / "debug", REPO / "pendant")
#: the run's own code (module docstring): it may set its objects' attributes
RUN_CODE = tuple(REPO / d for d in ("interp/runtime", "interp/tree", "interp/vm", "robot"))
#: 011_call_in_out: a = 1 (l.4), arr[2] = 5 (l.5), f = ... (l.6)
CALL = CASES / "011_call_in_out" / "program.src"


class OutsideGuard:
    """Attribute sets on runtimes, their trace holders, controllers, I/O images and tasks from
    code outside the run (:data:`RUN_CODE`), the debugger's, the pendant's and this test's
    included."""

    def __init__(self, monkeypatch) -> None:
        self.violations: list[str] = []
        for cls in (Runtime, Tracing, Controller, IOImage, Task):
            self._wrap(monkeypatch, cls)

    def _wrap(self, monkeypatch, cls) -> None:
        inner = cls.__setattr__
        guard = self

        def setattr_(obj, name, value):
            f = sys._getframe(1)
            path = Path(f.f_code.co_filename).resolve()
            constructing = f.f_code.co_name == "__init__" and f.f_locals.get("self") is obj  # a dataclass's own
            if not constructing and not any(path.is_relative_to(d) for d in RUN_CODE):
                guard.violations.append(f"{cls.__name__}.{name} set by {f.f_code.co_qualname} "
                                        f"({path.relative_to(REPO) if path.is_relative_to(REPO) else path}:{f.f_lineno})")
            inner(obj, name, value)
        monkeypatch.setattr(cls, "__setattr__", setattr_)


@pytest.fixture
def guard(monkeypatch):
    return OutsideGuard(monkeypatch)


def test_the_guard_sees_a_front_ends_set(guard):
    """The test can fail: a set from code compiled as a front end's module is caught."""
    code = compile("rt.tracing.writer = None\nrt.controller.io.now = 1.0\n", str(FRONT_ENDS[0] / "x.py"), "exec")
    rt, _ = make_runtime(run_spec(CALL, mujoco=False, max_sim_time=1.0))
    exec(code, {"rt": rt})      # noqa: S102 - a fixed text of the test
    assert [v.split(" set by ")[0] for v in guard.violations] == ["Tracing.writer", "IOImage.now"]


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


#: names that hold a runtime or a controller wherever they are bound (the code's convention)
RUN_NAMES = frozenset({"rt", "runtime", "ctl", "controller"})
#: the assignments the scan allows, by (file, function): each says why
ALLOWED = {
    # the guards' own tests: each sets attributes from outside to see the guard catch them
    ("tests/interp/test_run_spec.py", "test_the_guard_sees_a_set_from_outside"),
    ("tests/debug/test_operator_api.py", "test_the_scan_sees_each_kind_of_write"),
    # a stand-in controller of the test's own (class _Ctl), no run's
    ("tests/net/test_partners.py", "test_a_partner_is_added_by_its_class_and_one_registration"),
    # a checkout before the run specification (issue 62) has no other way to check collisions
    ("tools/whole_run_bench.py", "_run_one"),
    # a fault injected into the spin watch's names (class _Broken) to see it reach the caller
    ("tests/interp/test_spin_replay.py",
     "test_a_name_the_run_cannot_place_is_not_replayed_and_other_errors_are_not_swallowed"),
}


def _chain(node) -> list[str]:
    """The names of an attribute chain, its root first (``"?"`` for a root that is no name)."""
    parts = []
    while isinstance(node, (ast.Attribute, ast.Subscript)):
        if isinstance(node, ast.Attribute):
            parts.append(node.attr)
        node = node.value
    parts.append(node.id if isinstance(node, ast.Name) else "?")
    return parts[::-1]


def _reaches_run(chain: list[str], aliases: set) -> bool:
    return chain[0] in aliases or any(p in RUN_NAMES for p in chain[:-1])


def _writes_in(fn, aliases: set) -> list[tuple[int, str]]:
    """(line, target) of each write in the function `fn` (or module body) to an attribute of an
    object reached from a run; a name bound to such an object (``task = rt.robot``, ``rt, _ =
    make_runtime(...)``) is one too."""
    aliases = set(aliases) | RUN_NAMES
    out = []
    nodes = sorted((n for n in ast.walk(fn) if isinstance(n, (ast.Assign, ast.AugAssign, ast.AnnAssign))),
                   key=lambda n: (n.lineno, n.col_offset))
    for node in nodes:
        targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        value = node.value
        for t in targets:
            for tt in (t.elts if isinstance(t, ast.Tuple) else [t]):
                if isinstance(tt, (ast.Attribute, ast.Subscript)):
                    c = _chain(tt)
                    if isinstance(tt, ast.Subscript) and len(c) == 1:
                        continue            # an element of a plain name: a local list or dict
                    if _reaches_run(c, aliases):
                        out.append((node.lineno, ".".join(c)))
            first = t.elts[0] if isinstance(t, ast.Tuple) and t.elts else t
            if isinstance(first, ast.Name) and value is not None:
                src = value.func if isinstance(value, ast.Call) else value
                if isinstance(src, ast.Name) and src.id == "make_runtime" or \
                        isinstance(src, ast.Attribute) and _reaches_run(_chain(src) + ["."], aliases):
                    aliases.add(first.id)
    return out


#: a line that may assign to an attribute or an element of one (a cheap filter before parsing)
_MAY_WRITE = re.compile(r"^\s*[\w.\[\]\"', ()]*\.\w+(\[[^\n]*\])?\s*(=|[-+*/|&]=)(?!=)", re.M)


#: every write the scan finds starts from one of these words (RUN_NAMES, make_runtime)
_RUN_WORD = re.compile(r"\b(rt|runtime|ctl|controller|make_runtime)\b")


def _python_files(root: Path, skip: set) -> list[Path]:
    """The Python files below `root`, without the folders in `skip`, hidden folders, build
    output, node_modules and generated code (pruned, not walked)."""
    out = []
    for folder, dirs, files in os.walk(root):
        here = Path(folder)
        dirs[:] = sorted(d for d in dirs if not d.startswith(".") and d not in ("build", "node_modules", "generated")
                         and here / d not in skip)
        out += [here / f for f in sorted(files) if f.endswith(".py")]
    return out


def outside_writes(root: Path = REPO) -> list[str]:
    """``file:line: target`` of each write to a run's attribute in the Python modules of `root`
    outside :data:`RUN_CODE` (module docstring), the assignments of :data:`ALLOWED` aside."""
    found = []
    run_code = {root / d.relative_to(REPO) for d in RUN_CODE}
    for path in _python_files(root, run_code):
        rel = path.relative_to(root)
        text = path.read_text(encoding="utf-8")
        if not _RUN_WORD.search(text) or not _MAY_WRITE.search(text):
            continue            # no run named, or no attribute assignment at all: nothing to parse
        tree = ast.parse(text, str(path))
        functions = [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
        for fn in functions:
            if (rel.as_posix(), fn.name) in ALLOWED:
                continue
            for line, target in _writes_in(fn, set()):
                found.append(f"{rel.as_posix()}:{line}: {target}")
    return sorted(set(found))


def test_the_scan_sees_each_kind_of_write(tmp_path):
    """The scan can fail: an attribute of a runtime, one reached through a controller, an element
    of a runtime's attribute, one of an object taken from a runtime, and one of the first of
    make_runtime's pair are found; a local object's are not."""
    code = tmp_path / "tool.py"
    code.write_text(
        "def f(spec):\n"
        "    run, _ = make_runtime(spec)\n"
        "    run.halts = 1\n"
        "    run.controller.io.now = 1.0\n"
        "    run.sysvars.store['$OV_PRO'] = 5\n"
        "    task = run.robot\n"
        "    task.quiet = 0\n"
        "    box = {}\n"
        "    box['x'] = 1\n"
        "    obj = Thing()\n"
        "    obj.attr = 2\n"
        "def g(engine):\n"
        "    engine.rt.limit = 3\n", encoding="utf-8")
    assert outside_writes(tmp_path) == ["tool.py:13: engine.rt.limit", "tool.py:3: run.halts",
                                        "tool.py:4: run.controller.io.now", "tool.py:5: run.sysvars.store",
                                        "tool.py:7: task.quiet"]


def test_no_module_outside_the_run_writes_its_attributes():
    """Every module of the repository outside the run (the front ends, the tools, the tests and
    their helpers) changes a run through its methods, never by an assignment to its attributes."""
    assert outside_writes() == []


def test_a_partner_stops_the_run_and_sets_an_analog_input_through_methods(tmp_path):
    """What tests/net/helpers.py and net/plc.py did by assignment: ``Scheduler.stop_by`` ends a
    run that waits 10 s at the time given (never later than its own limit), and
    ``Controller.set_input(analog=True)`` sets $ANIN, clamped to KUKA's -1.0..1.0."""
    prog = tmp_path / "waits.src"
    prog.write_text("DEF waits()\n  WAIT SEC 10\nEND\n", encoding="utf-8")
    rt, _ = make_runtime(run_spec(prog, mujoco=False, max_sim_time=5.0))
    ctl = rt.controller
    assert ctl.set_input(3, 0.25, "plc", analog=True) == 0.25
    assert ctl.set_input(3, 2.0, "plc", analog=True) == 1.0
    rt.scheduler.stop_by(0.06)
    rt.scheduler.stop_by(1.0)                   # a later time does not extend it
    res = rt.run()
    assert res.reason == "max_sim_time" and res.sim_time == pytest.approx(0.06, abs=0.012)
