"""`krl audit FOLDER...` (registered by app/__init__.py): every KRC backup and program folder
of the folders checked and run, one HTML and JSON report (docs/audit.md)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from krl.limits import AUDIT_RUN_TIMEOUT_S, MAX_CELL_SIM_TIME_S
from krl.terminal import printable, printable_path
from audit.fleet import AuditError, run_audit
from audit.report import plural as n, write_report
from recovery.progress import shown
from rich.markup import escape
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn


@click.command()
@click.argument("folders", nargs=-1, required=True)
@click.option("--out", default="reports/audit", show_default=True, type=click.Path(path_type=Path),
              help="Folder the report is written into (audit.html, audit.json).")
@click.option("--jobs", type=click.IntRange(min=1), default=None,
              help="Worker processes of this machine (default: one per core).")
@click.option("--scheduler", default=None, metavar="tcp://HOST:PORT",
              help="Check and run on this Dask distributed scheduler's cluster instead (its workers see the "
                   "folders at the same paths); the same report.")
@click.option("--max-sim-time", type=click.FloatRange(min=0, min_open=True, max=MAX_CELL_SIM_TIME_S), default=600.0,
              show_default=True, help="Simulated seconds each entry point may run (an SPS.SUB at most 60).")
@click.option("--max-steps", type=click.IntRange(min=1), default=None,
              help="Statements of the program's own each run may execute (default: the real-programs report's "
                   "300 000, plus its submit program's).")
@click.option("--run-timeout", type=click.FloatRange(min=0, min_open=True), default=AUDIT_RUN_TIMEOUT_S,
              show_default=True, help="Wall-clock seconds one run may take before its worker is stopped.")
@click.option("--interp", type=click.Choice(["vm", "tree"]), default="vm", show_default=True,
              help="The interpreter of the runs (the same causes, the VM takes less CPU).")
def audit(folders: tuple[str, ...], out: Path, jobs: int | None, scheduler: str | None, max_sim_time: float,
          max_steps: int | None, run_timeout: float, interp: str) -> None:
    """Check every KRC backup and program folder in FOLDERS and run every entry point with
    --inputs auto; write one report (HTML and JSON) with each backup's health.

    Exit code: 0 when no backup needs attention, 1 when one does (docs/audit.md, "Status"),
    2 on a usage error (not a folder, too many backups, a scheduler that cannot be used).
    """

    start = time.perf_counter()
    try:
        with _progress() as progress:
            data = run_audit(list(folders), jobs=jobs, scheduler=scheduler, max_sim_time=max_sim_time,
                             max_steps=max_steps, interp=interp, run_timeout=run_timeout, progress=progress)
        j, h = write_report(data, out)
    except AuditError as exc:
        click.echo(f"krl audit: error: {printable(exc)}", err=True)
        sys.exit(2)
    except OSError as exc:
        click.echo(f"krl audit: error: cannot write the report: {printable(exc)}", err=True)
        sys.exit(2)
    for line in summary_lines(data):
        click.echo(line)
    click.echo(f"{time.perf_counter() - start:.0f} s; report: {printable_path(h)} (JSON: {printable_path(j)})")
    sys.exit(1 if data["summary"]["status"]["attention"] else 0)


def summary_lines(data: dict) -> list[str]:
    """The terminal's summary of a report: one line per backup (status, name and robot, its counts), then
    the totals."""

    out = []
    for u in data["units"]:
        t = u["tally"]
        cyc = f", cell cycle {t['cell_cycle']:.3f} s" if t["cell_cycle"] is not None else ""
        out.append(f"{u['status']:9s} {printable(u['title'])}: {n(u['errors'], 'check error')}, "
                   f"{n(t['entry_points'], 'entry point')} ({t['completed_or_intended']} completed or intended end, "
                   f"{n(t['program_errors'], 'program error')}, {t['limit_or_gap']} limit or gap), "
                   f"{n(t['motion_errors'], 'motion error')}, {n(t['overlaps'], 'output')} to review{cyc}")
    s = data["summary"]
    # what was read (issue 85): KRL files, and the logbook records of the units that have one
    files = sum(u["files"] for u in data["units"])
    records = sum((u.get("logbook") or {}).get("records", 0) for u in data["units"])
    read = f" ({n(files, 'file')}" + (f", {n(records, 'logbook record')})" if records else ")")
    out.append(f"{n(s['backups'], 'backup')}, {n(s['folders'], 'program folder')}{read}, "
               f"{n(s['entry_points'], 'entry point')}: "
               f"{s['status']['attention']} attention, {s['status']['review']} review, {s['status']['ok']} ok")
    return out


class _progress:
    """The progress bars (rich, on standard error when it is a terminal, transient: nothing of
    them stays in the output; piped or redirected, nothing is shown): one per phase, named by
    the backup or program in hand."""

    def __enter__(self):

        self.bar = None
        if shown():

            self.bar = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                                TimeElapsedColumn(), console=Console(stderr=True), transient=True)
            self.bar.start()
        self.tasks: dict[str, int] = {}
        return self

    def __call__(self, phase: str, done: int, total: int, label: str) -> None:
        if self.bar is None:
            return

        what = {"check": "checking", "run": "running"}.get(phase, phase)
        if phase not in self.tasks:
            self.tasks[phase] = self.bar.add_task(what, total=total)
        self.bar.update(self.tasks[phase], completed=done, total=total,
                        description=escape(f"{what} {label}" if label else what))

    def __exit__(self, *exc) -> None:
        if self.bar is not None:
            self.bar.stop()


commands = [audit]
