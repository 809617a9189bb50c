"""The `krl` command line: one subcommand per job of the pipeline.

Exit codes follow the compilers' habit: 0 success, 1 the input has errors, 2 usage or
internal error.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from krl import __version__


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="krl")
def main() -> None:
    """Tools for the KUKA Robot Language: parse, recover a grammar, check, run."""


@main.command()
@click.argument("files", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--json", "as_json", is_flag=True, help="One JSON object per file.")
@click.option("--outline", is_flag=True, help="Print the tree outline of each file that parses.")
def parse(files: tuple[Path, ...], as_json: bool, outline: bool) -> None:
    """Parse FILES; exit 0 when every file parses."""
    from krl.syntax.outline import outline as tree_outline  # noqa: PLC0415
    from krl.syntax.parse import parse_file  # noqa: PLC0415

    all_ok = True
    for path in files:
        result = parse_file(path, keep_tree=outline)
        if outline and result.ok:
            for entry in tree_outline(result.tree):
                click.echo(f"{path}:{entry}")
        all_ok &= result.ok
        if as_json:
            obj = result.as_json()
            if result.status not in ("ok", "syntax_error"):
                obj["status"] = result.status
            click.echo(json.dumps(obj))
        elif result.ok:
            click.echo(f"{path}: ok")
        elif not result.errors:
            click.echo(f"{path}: {result.status}", err=False)
        else:
            for err in result.errors:
                if err.cascade:
                    continue
                click.echo(f"{path}:{err.line}:{err.column + 1}: error: {err.message}")
    sys.exit(0 if all_ok else 1)


# Each pipeline stage contributes its subcommands from its own package: a module listed
# here exposes `commands`, a list of click commands.
SUBCOMMAND_MODULES = (
    "recovery.cli",        # recover, growth, validate
    "krl.semantics.cli",   # check
    "robot.cli",           # plot
    "interp.cli",          # run, asm
    "krl.bench",           # bench
    "conformance.cli",     # conformance
)


def _register_subcommands() -> None:
    import importlib  # noqa: PLC0415

    for module_name in SUBCOMMAND_MODULES:
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name and (module_name + ".").startswith(exc.name + "."):
                continue  # that stage (or its package) is not built yet
            raise
        for command in module.commands:
            main.add_command(command)


_register_subcommands()


if __name__ == "__main__":
    main()
