"""RunSpec is the one schema of a run (issue 76, interp/spec.py): every field typed (no ``Any``),
pure data (no sink: the trace and the observer are interp/run.py ``RunSinks``), and its field
metadata makes krl run's click options (interp/cli.py) and the debugger's launch schema
(interp/debug/launch.py): each RunSpec field is an option of both, with one default and one
type, or says why it is none."""

from __future__ import annotations

import dataclasses
import types
import typing
from pathlib import Path

import click
import pytest

from interp.cli import run
from interp.debug.engine import Engine
from interp.debug.launch import DEBUG_ATTRIBUTES, attribute_name, launch_schema, run_options as launch_options
from interp.run import RunSetupError, RunSinks, make_runtime, run_setup, run_spec
from interp.spec import (
    DOOR_OPTIONS, NOT_AN_OPTION, OPTION, RUN_OPTIONS, RunSpec, param_of, run_options,
)
from net.settings import NetworkSettings
from robot.collision import CellGeometry
from robot.machine import MachineData
from robot.stimuli import Cell
from robot.trace import TraceWriter

from .helpers import write

#: the types a field of a run's description may hold: values and read data, nothing that is written to
DATA_TYPES = {Path, str, int, float, bool, type(None), tuple, Cell, MachineData, NetworkSettings, CellGeometry}


def _leaves(hint) -> list:
    """The types a type hint is made of (``float | None`` -> float, NoneType; ``tuple[Path, ...]``
    -> tuple, Path)."""
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        return [t for a in typing.get_args(hint) for t in _leaves(a)]
    if origin is not None:
        return [origin] + [t for a in typing.get_args(hint) if a is not Ellipsis for t in _leaves(a)]
    return [hint]


def hints(cls) -> dict:
    """The resolved type hints of the dataclass `cls` (interp/spec.py names CellGeometry for the
    type checker only: robot/collision.py is not imported by krl run's start)."""
    return typing.get_type_hints(cls, localns={"CellGeometry": CellGeometry})


def schema_faults(cls) -> list[str]:
    """What makes the dataclass `cls` no pure, typed description: a field that is ``Any`` (or
    untyped ``object``), or whose type is not one of :data:`DATA_TYPES` (a trace writer, an
    observer, a callable: a sink)."""
    faults = []
    for name, hint in hints(cls).items():
        for t in _leaves(hint):
            if t is typing.Any or t is object:
                faults.append(f"{name}: Any")
            elif t not in DATA_TYPES or callable(getattr(t, "write", None)):
                faults.append(f"{name}: {getattr(t, '__name__', t)} is no data")
    return faults


def test_every_field_is_typed_data():
    """No field of RunSpec is Any or holds a sink; the check finds both in a spec that has them."""
    assert schema_faults(RunSpec) == []

    @dataclasses.dataclass(frozen=True)
    class Bad:
        program: Path
        cell: typing.Any = None
        trace: TraceWriter | None = None
        hook: typing.Callable | None = None

    assert schema_faults(Bad) == ["cell: Any", "trace: TraceWriter is no data", "hook: Callable is no data"]
    assert {f.name for f in dataclasses.fields(RunSinks)} == {"trace", "observer"}


def _kind(hint) -> type:
    """A field's type without None (``int | None`` -> int)."""
    kinds = [t for t in _leaves(hint) if t is not type(None)]
    return tuple if tuple in kinds else kinds[0]


def _click_kind(param: click.Parameter) -> type:
    """The type of a click parameter's value: a flag's bool, a path, an integer (a range), a number,
    a text (a choice)."""
    t = param.type
    if getattr(param, "is_flag", False):
        return bool
    if isinstance(t, click.Path):
        return Path
    if isinstance(t, click.types.IntParamType):
        return int
    return float if isinstance(t, click.types.FloatParamType) else str


#: the fields whose option names a file the front door reads (interp/run.py spec_of): the value read
READ_BY_THE_DOOR = {"cell": Cell, "robot": MachineData}
JSON_TYPES = {bool: "boolean", int: "integer", float: "number", str: "string", Path: "string"}


def test_every_field_is_an_option_of_krl_run_and_the_launch_or_says_why_not():
    """Each RunSpec field has an Option or a reason; each Option is a parameter of krl run (its
    click name, its flag, its default, its type: a flag, a choice, a range, a path, a number) and
    an attribute of the launch schema (its camelCase name, the JSON type, the same default,
    choices and range); the field's default is the option's default made a field value; a
    field that takes the option's value has the option's type."""
    types_of = hints(RunSpec)
    given = run.make_context("run", ["a.src"]).params      # each option at its default
    params = {p.name: p for p in run.params}
    schema = launch_schema()
    optioned = []
    for f in dataclasses.fields(RunSpec):
        assert (OPTION in f.metadata) != bool(f.metadata.get(NOT_AN_OPTION)), f.name
        opt = f.metadata.get(OPTION)
        if opt is None:
            continue
        optioned.append(f.name)
        default = f.default if f.default is not dataclasses.MISSING else None
        assert opt.field_value(opt.default) == default, f.name
        if opt.to_field is None and not opt.multiple:
            # the front door reads two of them: the cell file a Cell, the robot's files a MachineData
            assert _kind(types_of[f.name]) is READ_BY_THE_DOOR.get(f.name, opt.kind), f.name
            assert opt.door or f.name not in READ_BY_THE_DOOR
        elif opt.multiple:
            assert typing.get_origin(types_of[f.name]) is tuple and typing.get_args(types_of[f.name])[0] is opt.kind
    for name, opt in run_options():
        p = params.pop(param_of(name, opt))
        assert (opt.flag in p.opts) if opt.flag else isinstance(p, click.Argument), name
        assert p.multiple == opt.multiple and _click_kind(p) is opt.kind, name
        choice = isinstance(p.type, click.Choice)
        assert (tuple(p.type.choices) if choice else ()) == opt.choices, name
        assert not choice or p.type.case_sensitive == opt.case_sensitive, name
        ranged = isinstance(p.type, click.IntRange)
        assert ((p.type.min, p.type.max) if ranged else (None, None)) == (opt.minimum, opt.maximum), name
        if opt.flag:
            assert given[p.name] == opt.default and p.help == opt.help, name
        prop = schema.pop(attribute_name(name, opt))
        assert prop["type"] == ("array" if opt.multiple else JSON_TYPES[opt.kind]), name
        assert prop.get("enum", []) == list(opt.choices)
        assert (prop.get("minimum"), prop.get("maximum")) == (opt.minimum, opt.maximum)
        if opt.flag and not opt.multiple and opt.default is not None:
            assert prop["default"] == opt.default, name
    assert params == {} and set(schema) == set(DEBUG_ATTRIBUTES)
    # every option is krl run's: the fields' and the door's (the trace, how submit programs are found)
    assert sorted(optioned) == sorted(n for n in RUN_OPTIONS if n not in DOOR_OPTIONS)
    assert [p.name for p in run.params[:4]] == ["program", "interp_kind", "workspace", "inputs"]


def test_krl_run_and_the_tools_make_a_spec_the_same_way(tmp_path):
    """krl run's options (run_setup) and the tools' keywords (run_spec) give one spec for one run
    (the time limit given: the tools' default is none); the debugger's launch attribute onHalt
    reaches the spec as krl run's --on-halt does."""
    p = write(tmp_path, "prog.src", "DEF prog()\n  HALT\nEND\n")
    cell = write(tmp_path, "cell.yaml", 'stimuli:\n  - at: 0.1\n    set: {"$IN[5]": true}\n')
    with run_setup({"program": p, "inputs": cell, "mode": "T1", "on_halt": "continue:3", "no_check": True,
                    "interp_kind": "vm", "pgno": 7}) as setup:
        by_door = setup.spec
    by_tool = run_spec(p, inputs=cell, mode="T1", halt_continues=3, check=False, interp="vm", pgno=7,
                       max_sim_time=600.0)
    assert dataclasses.replace(by_door, cell=None) == dataclasses.replace(by_tool, cell=None)
    assert by_door.cell.stimuli[0].at == by_tool.cell.stimuli[0].at == 0.1
    options, _extra = launch_options({"program": str(p), "onHalt": "continue:3", "noCheck": True})
    with run_setup(options) as setup:
        assert (setup.spec.halt_continues, setup.spec.check, setup.spec.max_sim_time) == (3, False, 600.0)
    with pytest.raises(RunSetupError, match="--on-halt 'later'"):
        with run_setup({"program": p, "on_halt": "later"}):
            pass


def test_interactive_and_fast_forward_are_fields(tmp_path):
    """The pendant's waiting message window and the fast-forward switch are set in the spec,
    not on the built run: a debugger engine made interactive builds interactive runs."""
    p = write(tmp_path, "prog.src", "DEF prog()\n  WAIT SEC 1\nEND\n")
    rt, _ = make_runtime(run_spec(p, mujoco=False, max_sim_time=5.0))
    assert not rt.messages.interactive and rt.ff.idle.enabled and rt.ff.spin.enabled
    rt, _ = make_runtime(run_spec(p, mujoco=False, max_sim_time=5.0, interactive=True, fast_forward=False))
    assert rt.messages.interactive and not rt.ff.idle.enabled and not rt.ff.spin.enabled
    with run_setup({"program": p}) as setup:
        engine = Engine(interactive=True)
        engine.setup = setup
        rt, _ = engine._build()
        assert rt.messages.interactive and setup.spec.interactive is False
        rt.scheduler.close()
