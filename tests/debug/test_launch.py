"""krl debug's launch attributes are krl run's options (interp/debug/launch.py): the VS Code
extension declares them all, each converted and checked by krl run's own click option."""

from __future__ import annotations

import json
from pathlib import Path

import click
import jsonschema
import pytest

from interp.cli import run
from interp.debug.engine import Refused
from interp.debug.launch import PACKAGE_JSON, attribute, launch_schema, run_options


def _launch_block() -> dict:
    pkg = json.loads(PACKAGE_JSON.read_text(encoding="utf-8"))
    return next(d for d in pkg["contributes"]["debuggers"] if d["type"] == "krl")


def test_the_extension_declares_every_krl_run_option():
    props = _launch_block()["configurationAttributes"]["launch"]["properties"]
    assert props == launch_schema(), "run: python -m interp.debug.launch --write"
    # every option of krl run, by its long option in camelCase, and stopOnEntry
    longs = {o for p in run.params for o in p.opts if o.startswith("--")}
    for opt in longs:
        words = opt[2:].split("-")
        assert words[0] + "".join(w.title() for w in words[1:]) in props, opt
    assert {"program", "submit", "maxSimTime", "inputs", "robot", "mode", "runMode", "pgno",
            "noSubmit", "stopOnEntry"} <= set(props)
    assert props["submit"]["type"] == "array" and props["pgno"]["maximum"] == 65535
    assert set(props["mode"]["enum"]) == {"T1", "T2", "AUT", "EXT"}


def test_the_extension_configurations_satisfy_the_schema():
    block = _launch_block()
    schema = {"type": "object", "properties": block["configurationAttributes"]["launch"]["properties"],
              "required": block["configurationAttributes"]["launch"]["required"]}
    for conf in block["initialConfigurations"]:
        jsonschema.validate(conf, schema)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"program": "a.src", "runMode": "FAST"}, schema)


def test_launch_arguments_become_krl_run_options():
    options, extra = run_options({"program": "a.src", "mode": "t1", "runMode": "#MSTEP", "maxSimTime": 12,
                                  "submit": ["x.sub"], "noSubmit": False, "pgno": 3, "stopOnEntry": True})
    assert options["program"] == Path("a.src") and options["mode"] == "T1" and options["run_mode"] == "MSTEP"
    assert options["max_sim_time"] == 12.0 and options["submit"] == (Path("x.sub"),) and options["pgno"] == 3
    assert options["interp_kind"] == "tree" and options["max_steps"] is None   # krl run's defaults
    assert extra == {"stopOnEntry": True}
    # the same names the click command gives its callback
    ctx = run.make_context("run", ["a.src", "--mode", "t1", "--run-mode", "mstep", "--max-sim-time", "12",
                                   "--submit", "x.sub", "--pgno", "3"])
    assert ctx.params == options


@pytest.mark.parametrize("args, message", [
    ({}, "launch needs 'program'"),
    ({"program": "a.src", "mode": "T3"}, "mode: 'T3' is not one of"),
    ({"program": "a.src", "pgno": 0}, "pgno: 0 is not in the range"),
    ({"program": "a.src", "maxSimTime": "soon"}, "maxSimTime: 'soon' is not a valid float"),
    ({"program": "a.src", "noSubmit": "yes"}, "noSubmit: 'yes' is not true or false"),
    ({"program": "a.src", "submit": "sps.sub"}, "submit: a list"),
])
def test_bad_launch_arguments_are_refused_by_name(args, message):
    with pytest.raises(Refused, match=message):
        run_options(args)


def test_attribute_names():
    by_name = {p.name: attribute(p) for p in run.params}
    assert by_name["max_sim_time"] == "maxSimTime" and by_name["trace_path"] == "trace"
    assert by_name["interp_kind"] == "interp" and by_name["program"] == "program"
    assert all(isinstance(p, (click.Option, click.Argument)) for p in run.params)
