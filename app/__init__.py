"""The `krl` command line, the application on the top floor (issue 62): one subcommand per job
of the pipeline, each defined by its stage's own module (:data:`SUBCOMMANDS`), and the
subcommands of no single stage here (parse, check, bench, diff, graph, report). It imports the
library and the stages; nothing imports it (docs/architecture.md "Packages and layers").

Exit codes follow the compilers' habit: 0 success, 1 the input has errors, 2 usage or
internal error.
"""

from __future__ import annotations

import importlib

import click

from krl import __version__


# Each pipeline stage contributes its subcommands from its own package: the module named here
# for a subcommand defines it and lists it in its `commands` (tests/test_cli_registry.py checks
# that this table and the modules' lists are the same). A module is imported when one of its
# subcommands runs, or for `krl --help`: `krl check` or `krl lsp` does not import the simulator
# (numpy, scipy: 0.3 s of CPU at each start, 2026-11-25).
SUBCOMMANDS = {
    "parse": "app.parse",
    "recover": "recovery.cli", "growth": "recovery.cli", "validate": "recovery.cli", "construct": "recovery.cli",
    "check": "app.check",
    "plot": "robot.cli", "robot": "robot.cli", "trace": "robot.cli",
    "run": "interp.cli", "asm": "interp.cli", "cell": "interp.cli",
    "bench": "app.bench",
    "conformance": "conformance.cli",
    "fmt": "krl.fmt.cli",
    "lsp": "krl.lsp.cli",
    "debug": "interp.debug.cli",
    "diff": "app.changes", "graph": "app.changes", "report": "app.changes",
    "pendant": "pendant.cli",
    "audit": "audit.cli",
}


def subcommand(name: str) -> click.Command | None:
    """The click command ``krl NAME``, its module imported; None for a name not in
    :data:`SUBCOMMANDS` or whose stage's package is not there (not built yet)."""
    module_name = SUBCOMMANDS.get(name)
    if module_name is None:
        return None
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name and (module_name + ".").startswith(exc.name + "."):
            return None  # that stage (or its package) is not built yet
        raise
    return next((c for c in module.commands if c.name == name), None)


class _Subcommands(click.Group):
    """The `krl` group: its subcommands come from :data:`SUBCOMMANDS`, each loaded on first use."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(SUBCOMMANDS)

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        return subcommand(cmd_name)


@click.group(cls=_Subcommands, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="krl")
def main() -> None:
    """Tools for the KUKA Robot Language: parse, recover a grammar, check, run."""


if __name__ == "__main__":
    main()
