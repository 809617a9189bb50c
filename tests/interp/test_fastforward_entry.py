"""The scheduler reaches the fast-forward through its entries only (issue 87 item 3: "one entry
the scheduler calls"; docs/architecture.md "The fast-forward: one part"): interp/runtime/
scheduler.py and jump.py (the clock jump, the scheduler's) hold the run's ``FastForward`` and call
it; they name neither of its watches (the spin watch, the idle watch) nor import the modules
that hold them and what they record (spin.py, idle.py, period.py, passes.py, transient.py).

An AST scan (no run): an attribute named ``spin`` or ``idle`` (``self.spin``, ``sched.idle``,
``task.parked.spin``) or an import of those modules is a reach into a watch.
"""

from __future__ import annotations

import ast
from pathlib import Path

RUNTIME = Path(__file__).resolve().parents[2] / "interp" / "runtime"
#: the watches' names as the scheduler's modules would reach them
WATCHES = frozenset({"spin", "idle"})
#: the fast-forward's modules behind its entries
INSIDE = frozenset({"spin", "idle", "period", "passes", "transient"})


def reaches(source: str, name: str) -> list[str]:
    """``name:line what`` of each reach into a watch in the module text `source`."""
    out = []
    for n in ast.walk(ast.parse(source)):
        if isinstance(n, ast.Attribute) and n.attr in WATCHES:
            out.append(f"{name}:{n.lineno} .{n.attr}")
        elif isinstance(n, ast.ImportFrom) and (n.module or "").rsplit(".", 1)[-1] in INSIDE:
            out.append(f"{name}:{n.lineno} from {n.module}")
        elif isinstance(n, ast.Import) and any(a.name.rsplit(".", 1)[-1] in INSIDE for a in n.names):
            out.append(f"{name}:{n.lineno} import")
    return sorted(out, key=lambda s: (int(s.split(":")[1].split()[0]), s))


def test_the_scan_sees_each_form_of_reach():
    src = ("from .period import Period\n"
           "from . import jump\n"
           "def span(sched):\n"
           "    spin = sched.spin\n"
           "    return sched.idle.start, sched.tasks[0].parked.spin, sched.ff.span()\n")
    assert reaches(src, "x.py") == ["x.py:1 from period", "x.py:4 .spin", "x.py:5 .idle", "x.py:5 .spin"]


def test_the_scheduler_and_the_clock_jump_call_the_fast_forward_only():
    found = []
    for mod in ("scheduler.py", "jump.py"):
        found += reaches((RUNTIME / mod).read_text(encoding="utf-8"), mod)
    assert found == []
