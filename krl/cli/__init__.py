"""The `krl` command line: one subcommand per job of the pipeline.

Exit codes follow the compilers' habit: 0 success, 1 the input has errors, 2 usage or
internal error.
"""

from __future__ import annotations

import importlib

import click

from krl import __version__


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="krl")
def main() -> None:
    """Tools for the KUKA Robot Language: parse, recover a grammar, check, run."""


# Each pipeline stage contributes its subcommands from its own package: a module listed
# here exposes `commands`, a list of click commands.
SUBCOMMAND_MODULES = (
    "krl.cli.parse",       # parse
    "recovery.cli",        # recover, growth, validate
    "krl.cli.check",       # check
    "robot.cli",           # plot
    "interp.cli",          # run, asm
    "krl.cli.bench",       # bench
    "conformance.cli",     # conformance
    "krl.fmt.cli",         # fmt
    "krl.lsp.cli",         # lsp
    "interp.debug.cli",    # debug
    "krl.cli.changes",     # diff, graph, report
    "pendant.cli",         # pendant
    "audit.cli",           # audit
)


def _register_subcommands() -> None:
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
