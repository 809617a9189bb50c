"""Each part of a run gets its collaborators explicitly (issue 76 item 1; docs/architecture.md
"The runtime's parts"): no part holds the runtime (interp/runtime/core.py Runtime) whole, and the
runtime builds none as ``X(self)``. A part that needs something the runtime owns (a wait, the
robot task, which is added later) takes that callable, never the runtime.

Two checks, each shown to fail on a part of the old shape:

* :func:`holders`: a run is built (``--inputs auto``: the automatic cell too) and every part
  reachable from its attributes (one level below: the scheduler's, the network hub's sink) is
  read: an attribute whose value is the runtime itself is a part holding it;
* :func:`whole_runtime_builds`: the constructor calls of ``Runtime.__init__`` that pass ``self``
  as an argument, and :func:`rt_reach`: every ``self.rt`` in a method of interp/runtime/'s
  modules.

Left as they are, and listed by name here: the interpreters (``interpreter(self)``: the tree
interpreter and the VM run on the runtime, they are not its parts). The fast-forward
(fastforward.py and its watches) and the parts of a run's copy of its program model
(interp/runtime/model.py ``ProgramModel.data``: the system variables, whose computed ones read
the run's parts through sysvars.py ``RunReads``, and the stand-ins) are held to the rule like any
part (issue 87 item 3; until 2026-11-28 the copy's modules were exempt and ``sysvars.run``,
``kss.run`` held the runtime).
"""

from __future__ import annotations

import ast
from pathlib import Path

from interp.run import make_runtime, run_spec
from interp.runtime.core import Runtime

REPO = Path(__file__).resolve().parents[2]
RUNTIME = REPO / "interp" / "runtime"
#: the calls of Runtime.__init__ that may pass the runtime: the interpreter a run is built with
WHOLE_ALLOWED = frozenset({"interpreter"})


def _attributes(obj) -> list[tuple[str, object]]:
    """(name, value) of each attribute `obj` holds (its slots, its __dict__)."""
    names = set(getattr(obj, "__dict__", {}))
    for cls in type(obj).__mro__:
        names.update(s for s in getattr(cls, "__slots__", ()) if isinstance(s, str))
    out = []
    for n in sorted(names):
        try:
            out.append((n, getattr(obj, n)))
        except AttributeError:
            pass
    return out


def holders(rt, parts: dict) -> list[str]:
    """``part.attribute`` of each of `parts` (name -> object) that holds `rt` itself."""
    return [f"{name}.{attr}" for name, part in parts.items() for attr, v in _attributes(part) if v is rt]


def run_parts(rt) -> dict:
    """The parts of the run `rt` that must not hold it: its attributes' objects of the
    runtime's own modules (interp/runtime/),
    the scheduler's, the fast-forward's (its watches), and the network hub's sink."""
    out = {}
    for name, v in _attributes(rt) + [("scheduler." + n, v) for n, v in _attributes(rt.scheduler)] \
            + [("ff." + n, v) for n, v in _attributes(rt.ff)] \
            + [("controller.network.sink", rt.controller.network.sink)]:
        mod = getattr(type(v), "__module__", "")
        if not mod.startswith("interp.runtime.") or v is rt:
            continue
        out[name] = v
    return out


def whole_runtime_builds(source: str) -> list[str]:
    """The callee names of the calls in ``Runtime.__init__`` (of the module text `source`)
    that pass the runtime (``self``) as an argument."""
    tree = ast.parse(source)
    init = next(f for c in tree.body if isinstance(c, ast.ClassDef) and c.name == "Runtime"
                for f in c.body if isinstance(f, ast.FunctionDef) and f.name == "__init__")
    out = []
    for node in ast.walk(init):
        if isinstance(node, ast.Call) and any(isinstance(a, ast.Name) and a.id == "self"
                                              for a in list(node.args) + [k.value for k in node.keywords]):
            f = node.func
            out.append(f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "?"))
    return out


def rt_reach(source: str, name: str) -> list[str]:
    """``name:line`` of each ``self.rt`` (or ``self.runtime``) in the module text `source`."""
    return [f"{name}:{n.lineno}" for n in ast.walk(ast.parse(source))
            if isinstance(n, ast.Attribute) and n.attr in ("rt", "runtime")
            and isinstance(n.value, ast.Name) and n.value.id == "self"]


def test_the_checks_see_a_part_that_takes_the_runtime():
    """The checks can fail: a part built as ``X(self)`` that keeps the runtime is seen by
    each of them."""
    src = ("class Runtime:\n"
           "    def __init__(self, loaded):\n"
           "        self.errstate = ErrorState(self)\n"
           "        self.calls = Calls(program=self)\n"
           "        self.spin = SpinWatch(self)\n"
           "        self.cyclic = Cyclic(self.controller)\n"
           "class ErrorState:\n"
           "    def __init__(self, rt):\n"
           "        self.rt = rt\n"
           "    def err(self):\n"
           "        return self.rt.clock\n")
    assert whole_runtime_builds(src) == ["ErrorState", "Calls", "SpinWatch"]
    assert rt_reach(src, "x.py") == ["x.py:9", "x.py:11"]

    class Part:
        __slots__ = ("rt", "clock")

        def __init__(self, rt):
            self.rt, self.clock = rt, None
    rt = object()
    assert holders(rt, {"part": Part(rt), "other": Part(None)}) == ["part.rt"]


def test_runtime_builds_no_part_with_itself():
    """``Runtime.__init__`` passes ``self`` to no constructor but the interpreter's (the model's
    copy for the run gets the parts its system variables read, not the runtime)."""
    text = (RUNTIME / "core.py").read_text(encoding="utf-8")
    assert set(whole_runtime_builds(text)) <= WHOLE_ALLOWED


def test_no_runtime_module_reaches_through_a_held_runtime():
    """No method of interp/runtime/'s modules reads ``self.rt``."""
    found = []
    for path in sorted(RUNTIME.rglob("*.py")):
        found += rt_reach(path.read_text(encoding="utf-8"), path.relative_to(REPO).as_posix())
    assert found == []


def test_no_part_of_a_run_holds_the_runtime(tmp_path):
    """A run with every part (the automatic cell included): no part, none of the scheduler's
    and not the network hub's sink holds the runtime; each was built with its collaborators."""
    prog = tmp_path / "cell.src"
    prog.write_text("DEF cell()\n  WAIT FOR $IN[3]\nEND\n", encoding="utf-8")
    rt, _ = make_runtime(run_spec(prog, inputs="auto", mujoco=False, max_sim_time=1.0))
    assert isinstance(rt, Runtime)
    parts = run_parts(rt)
    # the parts the check reads: every one of those issue 76 names, and the ones beside them
    assert {"calls", "cyclic", "interrupts", "motions", "errstate", "stepping", "autocell", "programs", "sysvars", "kss",
            "scheduler", "tracing", "controller.network.sink", "ff", "scheduler.ff", "ff.spin", "ff.idle"} <= set(parts)
    assert holders(rt, parts) == []
    assert parts["errstate"].clock is rt.clock is rt.scheduler.clock
    assert rt.run().reason == "completed"       # the automatic cell answers the WAIT FOR
