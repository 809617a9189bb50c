"""The `krl` command line: one subcommand per job of the pipeline.

Exit codes follow the compilers' habit: 0 success, 1 the input has errors, 2 usage or
internal error.
"""

from __future__ import annotations

import sys
from pathlib import Path

import click

from krl import __version__
from krl.limits import PARSE_TIMEOUT_S


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="krl")
def main() -> None:
    """Tools for the KUKA Robot Language: parse, recover a grammar, check, run."""


@main.command()
@click.argument("files", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--format", "fmt", type=click.Choice(["text", "json", "sarif"]), default="text",
              show_default=True, help="text: compiler style; json: one object per file; sarif: SARIF 2.1.0.")
@click.option("--json", "as_json", is_flag=True, help="Same as --format json.")
@click.option("--outline", is_flag=True, help="Print the routines and declarations of each file that parses.")
@click.option("--tree", is_flag=True, help="Print the grammar-rule outline of each file that parses.")
@click.option("--engine", type=click.Choice(["auto", "python", "java"]), default=None,
              help="Parse engine: java (fast; needs a JDK), python (the reference), auto: "
                   "java when available (default: $KRL_ENGINE, else auto).")
@click.option("--timeout", type=click.FloatRange(min=0, min_open=True), default=PARSE_TIMEOUT_S,
              show_default=True, help="Seconds one file may parse; past it the parse is stopped (error E005).")
@click.option("--jobs", type=click.IntRange(min=1), default=None,
              help="Worker processes (default: the number of cores).")
def parse(files: tuple[Path, ...], fmt: str, as_json: bool, outline: bool, tree: bool, timeout: float,
          jobs: int | None, engine: str | None) -> None:
    """Parse FILES; exit 0 when every file parses (krl/syntax/cli.py)."""
    from krl.syntax.cli import main_status  # noqa: PLC0415

    sys.exit(main_status(files, fmt, as_json, outline, tree, timeout, jobs, engine))


# Each pipeline stage contributes its subcommands from its own package: a module listed
# here exposes `commands`, a list of click commands.
SUBCOMMAND_MODULES = (
    "recovery.cli",        # recover, growth, validate
    "krl.semantics.cli",   # check
    "robot.cli",           # plot
    "interp.cli",          # run, asm
    "krl.bench",           # bench
    "conformance.cli",     # conformance
    "krl.fmt.cli",         # fmt
    "krl.lsp.cli",         # lsp
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
