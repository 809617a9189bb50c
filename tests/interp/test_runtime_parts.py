"""The runtime stays split along its seams (issue 62, "Split the grab-bags"): ``Runtime``
(interp/runtime/core.py) holds the run state, its tasks, the statement hook and the waits;
routine calls, run-time names, $ERR, cyclic evaluation, motion statements, interrupts and the
run mode with the debugger's hooks are its parts, each a class in its own module. The issue
counts a class's methods as the functions defined in its body (88 in Runtime before the split)."""

from __future__ import annotations

import ast
import inspect

from interp.runtime import core

from .test_run_spec import PARTS

#: the most methods Runtime may define (issue 62: "below 40")
MAX_METHODS = 39


def methods(cls) -> list[str]:
    """The names of the functions defined in `cls`'s body (properties and static methods too; not
    inherited ones nor class attributes bound to functions defined elsewhere)."""
    tree = ast.parse(inspect.getsource(inspect.getmodule(cls)))
    body = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls.__name__).body
    return [n.name for n in body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]


def test_runtime_has_fewer_than_40_methods():
    names = methods(core.Runtime)
    assert len(names) <= MAX_METHODS, f"Runtime defines {len(names)} methods: {names}"


def test_the_count_sees_every_kind_of_method():
    """The count is not blind: a plain method, a property and a static method of Runtime's are
    counted, the operators bound from interp/runtime/convert.py are not."""
    names = methods(core.Runtime)
    assert {"before_statement", "mode_op", "_break"} <= set(names)
    assert "binary_op" not in names and callable(core.Runtime.binary_op)


def test_each_part_is_its_own_module_and_says_what_it_holds():
    """Each part lives in a module of its own whose docstring says what it holds now, and a run's
    Runtime has one of each (tests/interp/test_run_spec.py checks that nothing outside sets them)."""
    modules = [inspect.getmodule(cls) for cls in PARTS.values()]
    assert len(set(modules)) == len(PARTS) and core not in modules
    for module in modules:
        assert "holds" in (module.__doc__ or ""), module.__name__
    assert set(PARTS) <= set(core.Runtime.__slots__)

