"""``krl debug``'s launch configuration: every option of ``krl run``, read off the click
command itself (interp/cli.py ``run``), so that the two never differ (docs/editors.md, "Launch").

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

PACKAGE_JSON = Path(__file__).resolve().parents[2] / "editors" / "vscode" / "package.json"

#: attributes of the debugger only: (JSON schema, default)
DEBUG_ATTRIBUTES = {
    "stopOnEntry": ({"type": "boolean", "description": "Stop at the first statement of the program.",
                     "default": False}, False),
}

#: what a launch attribute means under the debugger beyond krl run's help text
DEBUG_NOTES = {"runMode": "Under the debugger each step stop is a stop of the session."}

#: what the editor fills in by default (VS Code variables), and the argument's description
EDITOR_DEFAULTS = {"program": "${file}", "workspace": "${workspaceFolder}"}
PROGRAM_TEXT = ("The KRL program to run: a .src file (its main routine); with a backup .zip as "
                "workspace, its path in the archive or its module name.")


def run_command() -> click.Command:

    return run


def attribute(param: click.Parameter) -> str:
    """The launch attribute of a parameter of ``krl run``: its long option in camelCase."""
    if isinstance(param, click.Argument):
        return param.name
    longs = [o for o in param.opts if o.startswith("--")]
    words = max(longs, key=len)[2:].split("-")
    return words[0] + "".join(w.capitalize() for w in words[1:])


def _describe(text: str, names: dict[str, str]) -> str:
    """A click help text with each ``--option`` of krl run named as its launch attribute."""
    return re.sub(r"--[a-z][a-z-]*", lambda m: names.get(m.group(0), m.group(0)), " ".join(text.split()))


def launch_schema() -> dict:
    """The JSON schema (``properties``) of the launch attributes."""
    cmd = run_command()
    ctx = click.Context(cmd)
    names = {o: attribute(p) for p in cmd.params for o in p.opts if o.startswith("--")}
    props: dict = {}
    for p in cmd.params:
        key = attribute(p)
        t = p.type
        if p.multiple:
            prop = {"type": "array", "items": {"type": "string"}}
        elif getattr(p, "is_flag", False):
            prop = {"type": "boolean"}
        elif isinstance(t, click.Choice):
            prop = {"type": "string", "enum": list(t.choices)}
        elif isinstance(t, click.types.IntParamType):
            prop = {"type": "integer"}
            if isinstance(t, click.IntRange):
                if t.min is not None:
                    prop["minimum"] = t.min
                if t.max is not None:
                    prop["maximum"] = t.max
        elif isinstance(t, click.types.FloatParamType):
            prop = {"type": "number"}
        else:
            prop = {"type": "string"}
        text = PROGRAM_TEXT if isinstance(p, click.Argument) else _describe(p.help or "", names)
        prop["description"] = text + (" " + DEBUG_NOTES[key] if key in DEBUG_NOTES else "")
        if key in EDITOR_DEFAULTS:
            prop["default"] = EDITOR_DEFAULTS[key]
        else:
            default = p.get_default(ctx) if not p.multiple else None
            if isinstance(default, (bool, int, float, str)):
                prop["default"] = default
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
