"""``krl debug``'s launch configuration: every option of ``krl run``, both made from the one
description of a run's settings (interp/spec.py: RunSpec's fields and their :class:`Option`,
the door options), so that the two never differ (docs/editors.md, "Launch").

Each parameter of ``krl run`` is a launch attribute named in camelCase after its long option
(``--max-sim-time`` is ``maxSimTime``, ``--no-submit`` is ``noSubmit``, the argument PROGRAM is
``program``), converted and checked by the option's own click type (a choice, a range, a
path); a repeatable option is an array. The debugger adds :data:`DEBUG_ATTRIBUTES`
(``stopOnEntry``). :func:`launch_schema` is the JSON schema of the attributes that the VS Code
extension declares (editors/vscode/package.json; ``python -m interp.debug.launch --write``
writes it, tests/debug/test_launch.py checks it).

Errors: :class:`interp.debug.errors.Refused` naming the attribute ("maxSimTime: ... is not a
valid float").
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import click

from .errors import Refused
from interp.cli import run
from interp.spec import Option, run_options as spec_options

PACKAGE_JSON = Path(__file__).resolve().parents[2] / "editors" / "vscode" / "package.json"

#: attributes of the debugger only: (JSON schema, default)
DEBUG_ATTRIBUTES = {
    "stopOnEntry": ({"type": "boolean", "description": "Stop at the first statement of the program.",
                     "default": False}, False),
}

#: what a launch attribute means under the debugger beyond krl run's help text
DEBUG_NOTES = {"runMode": "Under the debugger each step stop is a stop of the session."}

#: what the editor fills in by default (VS Code variables)
EDITOR_DEFAULTS = {"program": "${file}", "workspace": "${workspaceFolder}"}


def run_command() -> click.Command:

    return run


def attribute_name(name: str, opt: Option) -> str:
    """The launch attribute of krl run's parameter `name` (interp/spec.py ``run_options``):
    its long option in camelCase, the argument's name."""
    return _camel(opt.flag) if opt.flag else name


def attribute(param: click.Parameter) -> str:
    """The launch attribute of a parameter of ``krl run``: its long option in camelCase."""
    if isinstance(param, click.Argument):
        return param.name
    return _camel(max((o for o in param.opts if o.startswith("--")), key=len))


def _camel(flag: str) -> str:
    """A long option in camelCase (``--max-sim-time`` -> ``maxSimTime``)."""
    words = flag[2:].split("-")
    return words[0] + "".join(w.capitalize() for w in words[1:])


def _describe(text: str, names: dict[str, str]) -> str:
    """A click help text with each ``--option`` of krl run named as its launch attribute."""
    return re.sub(r"--[a-z][a-z-]*", lambda m: names.get(m.group(0), m.group(0)), " ".join(text.split()))


def attribute_schema(opt: Option) -> dict:
    """The JSON schema of a launch attribute of the option `opt` (its type, choices, range),
    without its description and default."""
    if opt.multiple:
        return {"type": "array", "items": {"type": "string"}}
    if opt.kind is bool:
        return {"type": "boolean"}
    if opt.choices:
        return {"type": "string", "enum": list(opt.choices)}
    if opt.kind is int:
        prop: dict = {"type": "integer"}
        if opt.minimum is not None:
            prop["minimum"] = opt.minimum
        if opt.maximum is not None:
            prop["maximum"] = opt.maximum
        return prop
    return {"type": "number"} if opt.kind is float else {"type": "string"}


def launch_schema() -> dict:
    """The JSON schema (``properties``) of the launch attributes: krl run's parameters as
    interp/spec.py describes them (``run_options``: RunSpec's fields and the door options),
    and :data:`DEBUG_ATTRIBUTES`."""
    params = spec_options()
    names = {opt.flag: attribute_name(name, opt) for name, opt in params if opt.flag}
    props: dict = {}
    for name, opt in params:
        key = attribute_name(name, opt)
        prop = attribute_schema(opt)
        prop["description"] = _describe(opt.help, names) + (" " + DEBUG_NOTES[key] if key in DEBUG_NOTES else "")
        if key in EDITOR_DEFAULTS:
            prop["default"] = EDITOR_DEFAULTS[key]
        elif not opt.multiple and isinstance(opt.default, (bool, int, float, str)):
            prop["default"] = opt.default
        props[key] = prop
    for key, (schema, _default) in DEBUG_ATTRIBUTES.items():
        props[key] = dict(schema)
    return props


def run_defaults() -> dict:
    """krl run's options at their defaults, by click name (the program excepted)."""
    cmd = run_command()
    ctx = click.Context(cmd)
    return {p.name: (p.get_default(ctx) if not p.multiple else ()) for p in cmd.params if not p.required}


def run_options(args: dict) -> tuple[dict, dict]:
    """(krl run's options by their click names, the debugger's own attributes) of a launch
    request's arguments; each value converted by its option's click type. Raises
    :class:`Refused` for a value the option refuses, or a missing program."""
    cmd = run_command()
    ctx = click.Context(cmd)
    options: dict = {}
    for p in cmd.params:
        key = attribute(p)
        value = args.get(key)
        if value is None:
            if p.required:
                raise Refused(f"launch needs '{key}': the path of a .src file")
            options[p.name] = p.get_default(ctx) if not p.multiple else ()
            continue
        try:
            if p.multiple:
                if not isinstance(value, list):
                    raise click.BadParameter("a list", ctx, p)
                options[p.name] = tuple(p.type.convert(str(v), p, ctx) for v in value)
            elif getattr(p, "is_flag", False):
                if not isinstance(value, bool):
                    raise click.BadParameter(f"{value!r} is not true or false", ctx, p)
                options[p.name] = value
            else:
                if isinstance(p.type, click.Choice) and isinstance(value, str):
                    value = value.lstrip("#")          # "#MSTEP", as $PRO_MODE writes it
                options[p.name] = p.type.convert(value if not isinstance(value, (dict, list)) else str(value),
                                                 p, ctx)
        except click.BadParameter as exc:
            raise Refused(f"{key}: {exc.message}"[:300]) from None
    extra = {key: (args[key] if key in args else default) for key, (_s, default) in DEBUG_ATTRIBUTES.items()}
    if not isinstance(extra["stopOnEntry"], bool):
        raise Refused("stopOnEntry: true or false")
    return options, extra


def write_package_json(path: Path = PACKAGE_JSON) -> bool:
    """Write the launch schema into the VS Code extension's package.json; True when it
    changed."""
    text = path.read_text(encoding="utf-8")
    pkg = json.loads(text)
    dbg = next(d for d in pkg["contributes"]["debuggers"] if d.get("type") == "krl")
    dbg["configurationAttributes"]["launch"]["properties"] = launch_schema()
    new = json.dumps(pkg, indent=2, ensure_ascii=False) + "\n"
    if new == text:
        return False
    path.write_text(new, encoding="utf-8")
    return True


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv == ["--write"]:
        print("package.json " + ("updated" if write_package_json() else "already current"))
        return 0
    print(json.dumps(launch_schema(), indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
