"""The `krl` command line, the application on the top floor (issue 62): one subcommand per job
of the pipeline, each defined by its stage's own module (:data:`SUBCOMMANDS`), and the
subcommands of no single stage here (parse, check, bench, diff, graph, report). It imports the
library and the stages; nothing imports it (docs/architecture.md "Packages and layers").

Exit codes follow the compilers' habit: 0 success, 1 the input has errors, 2 usage or
internal error; every command ends on SIGINT with 130 and on SIGTERM with 143, printing
``interrupted`` (krl/signals.py; docs/security.md "Faults").
"""

from __future__ import annotations

import importlib
import os
import sys

import click

from krl import __version__
from krl import signals


# Each pipeline stage contributes its subcommands from its own package: the module named here
# for a subcommand defines it and lists it in its `commands` (tests/test_cli_registry.py checks
# that this table and the modules' lists are the same). A module is imported when one of its
# subcommands runs (`krl --help` lists them from SUMMARIES): `krl check` or `krl lsp` does not
# import the simulator (numpy, scipy: 0.3 s of CPU at each start, 2026-11-25).
SUBCOMMANDS = {
    "parse": "app.parse",
    "recover": "recovery.cli", "growth": "recovery.cli", "validate": "recovery.cli", "construct": "recovery.cli",
    "check": "app.check",
    "plot": "robot.cli", "robot": "robot.cli", "trace": "robot.cli",
    "run": "interp.cli", "asm": "interp.cli", "cell": "interp.cli",
    "bench": "app.bench",
    "cache": "app.cache",
    "conformance": "conformance.cli",
    "fmt": "krl.fmt.cli",
    "lsp": "krl.lsp.cli",
    "debug": "interp.debug.cli",
    "diff": "app.changes", "graph": "app.changes", "report": "app.report",
    "pendant": "pendant.cli",
    "audit": "audit.cli",
    "log": "app.log",
}

#: each subcommand's summary in `krl --help`: the first sentence of its help (tests/test_cli_registry.py
#: holds the two equal), so that `krl --help` lists the subcommands without importing their modules
SUMMARIES = {
    'parse': 'Parse FILES; exit 0 when every file parses.',
    'recover': 'Parse every KRL file under CORPUS (a folder, a backup or archive .zip, or a folder of them), cluster the failures, write the report to --out.',
    'growth': 'Replay every committed version of grammar/KRL.g4 over CORPUS: growth.csv and growth.png.',
    'validate': "Run every grammar construct's positive and negative examples (or only NAMES).",
    'construct': 'Grammar constructs: start a new one from a cluster of the recovery report.',
    'check': 'Type-check KRL files, KRC backup folders or backup .zip archives; exit 1 when there are errors.',
    'plot': "Draw the TCP path of a JSON Lines TRACE (3D and top view, programmed points, approximation zones, I/O events) as a PNG; a cell's result run.cell.json (krl run CELL.yaml --trace run.jsonl): every robot's TCP path in the cell's world.",
    'robot': "The simulated robot: its model from a backup's machine data or a robot YAML (issue 22).",
    'trace': "KUKA Trace recordings (a KR C4's KRCIpo CSV and PROG.TXT) and simulated runs' traces: show one, compare a run with a recording (issue 60; docs/trace.md).",
    'run': 'Run PROGRAM (.src) on the simulated KR C4; print where and why it ended.',
    'asm': 'Print the VM assembly of PROGRAM (one instruction per line, source lines as comments).',
    'cell': "The cell of a backup: the PLC's answers as reactive rules (robot/cellrules.py).",
    'bench': 'Benchmarks (ratios measured in one run).',
    'cache': 'The store of parses and checks in the user cache folder (krl/store.py): where it is, clear it.',
    'conformance': 'Run the hand-written cases on every available interpreter, the differential fuzzer and the corpus programs; write summary.json, report.md and report.html to --out.',
    'fmt': 'Format KRL files in place (indentation, keyword case, spacing); comments, folds, inline forms, header lines and line ends are kept.',
    'lsp': 'Run the KRL language server on stdin/stdout (see docs/editors.md).',
    'debug': 'Debug a KRL program over the Debug Adapter Protocol on stdin/stdout.',
    'diff': 'What changed between two KRC backups (folders or .zip) or two files: points, frames and loads, routines, declarations and signals, inline-form motions.',
    'graph': "The program map of a KRC backup (folder or .zip) or a folder: routines, calls, interrupts, triggers, RUN commands and EKI channels, entry points and unreachable routines. html: an interactive page (zoom, pan, search, a routine's neighbourhood), offline; in a controller archive the routines its logbook names are marked.",
    'report': 'The change report a customer signs: one HTML page that opens with both backups identified (their robot, controller, software, dates and SHA-256) and a signature block, a summary, then (with --since OLD) the diff from OLD to BACKUP, the check findings the change introduced or removed, the run outcomes of the entry points it touches (old against new), what to retest on the robot, the interactive program map, and every check finding of BACKUP.',
    'pendant': 'Serve a virtual smartPAD for TARGET (a KRC backup folder or .zip, a folder of KRL, a program .src: selected at the start, or a cell of several robots CELL.yaml: every robot in the 3D view; default the current folder) on 127.0.0.1 and open it in the browser.',
    'log': 'The controller\'s logbook: the event logs (Log Files/KrcLog*.evt) of a KUKA archive, tied to its code (docs/log.md).',
    'audit': "Check every KRC backup and program folder in FOLDERS and run every entry point with --inputs auto; write one report (HTML and JSON) with each backup's health.",
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

    def main(self, *args, **kwargs):
        """click's main, with SIGTERM raising like SIGINT while a command runs (krl/signals.py).
        No command draws with MuJoCo (the pendant draws in the browser, `krl robot` writes
        files): its rendering back end (GLFW, with cffi and pycparser) is not loaded when a
        command imports the simulator (`import mujoco`: 0.39-0.41 s of CPU with it, 0.28-0.29 s
        without, 2026-11-27); a user's own ``MUJOCO_GL`` is kept."""
        os.environ.setdefault("MUJOCO_GL", "disable")
        with signals.handling():
            return super().main(*args, **kwargs)

    def invoke(self, ctx: click.Context):
        """Run the subcommand; every command ends the same way on a signal: ``interrupted`` on
        stderr, exit 130 (SIGINT) or 143 (SIGTERM); never click's "Aborted!" with exit 1, the
        code of "the input has errors"."""
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as exc:
            _interrupted(exc)

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(SUBCOMMANDS)

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        return subcommand(cmd_name)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """The list of `krl --help` from :data:`SUMMARIES`, shortened as click shortens a
        command's help, without importing a subcommand's module (click's own listing imports
        every one: 0.58 s of CPU for `krl --help`, tools/startup_bench.py, 2026-11-26)."""
        names = self.list_commands(ctx)
        limit = formatter.width - 6 - max(len(n) for n in names)
        rows = [(n, click.Command(n, help=SUMMARIES[n]).get_short_help_str(limit)) for n in names]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


def _interrupted(exc: BaseException) -> None:
    click.echo(signals.MESSAGE, err=True)
    sys.exit(signals.exit_code(exc))


@click.group(cls=_Subcommands, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="krl")
def main() -> None:
    """Tools for the KUKA Robot Language: parse, recover a grammar, check, run."""


if __name__ == "__main__":
    main()
