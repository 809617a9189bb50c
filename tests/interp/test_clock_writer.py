"""The run's counters have one writer (issue 87 item 3: "``RunClock`` is a record written from
five modules"): interp/runtime/scheduler.py ``RunClock`` assigns its fields in its own methods
(count, enter, leave, restore, epochs, bump_epoch); every other module of the interpreters reads
them and calls those. The check reads the source (an assignment or augmented assignment to
``<anything>.clock.<field>``, or to ``clock.<field>``, outside the class), so it costs no run.
"""

from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
FIELDS = frozenset({"steps", "limit_at", "current_task", "state_epoch"})


def clock_writes(source: str, name: str) -> list[str]:
    """``name:line`` of each write of a RunClock field in the module text `source`, the
    methods of a class named RunClock aside."""
    tree = ast.parse(source)
    skip = set()
    for c in ast.walk(tree):
        if isinstance(c, ast.ClassDef) and c.name == "RunClock":
            skip |= {id(n) for n in ast.walk(c)}
    out = []
    for node in ast.walk(tree):
        if id(node) in skip or not isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
            continue
        targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        while any(isinstance(t, (ast.Tuple, ast.List, ast.Starred)) for t in targets):
            targets = [x for t in targets for x in (t.elts if isinstance(t, (ast.Tuple, ast.List)) else
                                                    [t.value] if isinstance(t, ast.Starred) else [t])]
        for e in targets:
            if isinstance(e, ast.Attribute) and e.attr in FIELDS and (
                    (isinstance(e.value, ast.Attribute) and e.value.attr == "clock")
                    or (isinstance(e.value, ast.Name) and e.value.id == "clock")):
                out.append(f"{name}:{node.lineno}")
    return out


def test_the_check_sees_a_write_of_the_clock():
    """It can fail: each form of write found on a module of the old shape, none in RunClock."""
    src = ("class RunClock:\n"
           "    def count(self, n):\n"
           "        self.steps += n\n"
           "def resume(clock, rt, task):\n"
           "    clock.current_task = task\n"
           "    rt.clock.steps += 3\n"
           "    rt.clock.limit_at, x = 5, 1\n"
           "    rt.clock.count(2)\n"
           "    task.steps += 1\n"
           "    clock.current_task.err_text = ''\n")
    assert clock_writes(src, "m.py") == ["m.py:5", "m.py:6", "m.py:7"]


def test_only_the_clock_writes_its_counters():
    """No module of interp/ (the VM's generated loop included) writes a RunClock field."""
    found = []
    for path in sorted((REPO / "interp").rglob("*.py")):
        found += clock_writes(path.read_text(encoding="utf-8"), path.relative_to(REPO).as_posix())
    assert found == []
