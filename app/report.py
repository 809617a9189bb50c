"""`krl report BACKUP [--since OLD]` (issue 26): one HTML page a customer signs, with both
backups identified, the diff (krl/diff), the check findings the change introduced or removed,
the run outcomes of the entry points it touches (interp/outcomes.py), the program map
(krl/programmap) and the logbooks. Registered by app/__init__.py.

Exit status: 0, or 2 for an error (the messages of ``krl check``, E001 and E004, for a path
that does not exist or a refused archive). Never a traceback for bad input.
"""

from __future__ import annotations

import sys
from pathlib import Path

import click

from krl.backups import archive_named
from krl.diff.core import diff_sides
from krl.diff.ident import generator, identify
from krl.diff.load import DiffInputError, side
from krl.diff.report import findings, relative, report_html, touched_entries, unread_lines
from krl.programmap.render import GraphTooLarge
from krl.terminal import printable
from interp.outcomes import ends_alike, outcome_changes, run_outcomes
from interp.realprograms import REPORT_SIM_TIME_S
from robot.machine import load_machine
from robot.named import Named
from app.changes import _fail, _write, load_map
from app.reportlog import report_logbooks


@click.command()
@click.argument("backup")
@click.option("--since", "since", default=None, help="An older backup (folder or .zip): the report says what changed since it.")
@click.option("--runs/--no-runs", default=True, show_default=True,
              help="With --since: run the entry points the change touches, old and new (--inputs auto).")
@click.option("--max-sim-time", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Simulated seconds each run may take (default 60).")
@click.option("--jobs", type=click.IntRange(min=1), default=None, help="Worker processes of the runs (default: one per core).")
@click.option("--links", type=click.Choice(["source", "file", "vscode", "none"]), default="source", show_default=True,
              help="How each file:line links to its file: source, the report's own view of the file at that line "
                   "(in the page, below the report; not printed); file: URL; vscode: URL that opens the line; no link.")
@click.option("-o", "--output", default=None, help="Write the HTML page to this file instead of standard output.")
def report(backup: str, since: str | None, runs: bool, max_sim_time: float | None, jobs: int | None,
           links: str, output: str | None) -> None:
    """The change report a customer signs: one HTML page that opens with both backups
    identified (their robot, controller, software, dates and SHA-256) and a signature block,
    a summary, then (with --since OLD) the diff from OLD to BACKUP, the check findings the change
    introduced or removed, the run outcomes of the entry points it touches (old against new),
    what to retest on the robot, the interactive program map, and every check finding of
    BACKUP. Prints as a PDF to sign: numbered pages, the unchanged context collapsed."""

    try:
        # a folder holding one archive .zip is that archive: its cover and logbook too (krl/backups.py)
        backup = archive_named(backup)
        since = archive_named(since) if since is not None else None
        pm, diags, files, lines = load_map(backup)
        new_findings = findings(diags, pm.root, lines, links, pm)
        if since is None:
            with side(backup) as b:
                # the source views are read while an archive is still extracted
                text = report_html(backup, len(files), new_findings, pm, links=links, idents=[_identify(b, "backup")],
                                   generated=generator(), new_root=_root(b, links),
                                   logbooks=report_logbooks((backup, b.root)))
        else:
            pm_old, diags_old, files_old, lines_old = load_map(since)
            with side(since) as a, side(backup) as b:
                d = diff_sides(a, b)
                touched = touched_entries(d, pm_old, pm)
                if max_sim_time is None:

                    max_sim_time = REPORT_SIM_TIME_S
                if runs and touched:
                    _run_touched(touched, a, b, max_sim_time, jobs)
                text = report_html(
                    backup, len(files), new_findings, pm, links=links, diff=d,
                    old_findings=findings(diags_old, pm_old.root, lines_old, links, pm_old),
                    file_sets=(relative(files_old, pm_old.root), relative(files, pm.root)),
                    unread=(unread_lines(pm_old, lines_old), unread_lines(pm, lines)),
                    old_map=pm_old, touched=touched, runs=runs, max_sim_time=max_sim_time,
                    new_root=_root(b, links), old_root=_root(a, links),
                    idents=[_identify(a, "old", touched), _identify(b, "new", touched)], generated=generator(),
                    logbooks=report_logbooks((backup, b.root), (since, a.root)))
    except DiffInputError as exc:
        _fail("report", exc)
    except (ValueError, GraphTooLarge) as exc:
        _fail("report", exc)
    except Exception as exc:  # noqa: BLE001 - a last line of defence: no traceback
        _fail("report", RuntimeError(f"internal error: {type(exc).__name__}: {exc}"))
    _write(text, output)


def _root(s, links: str) -> str | None:
    """The folder of side `s` the report's links point into: with ``--links source`` the folder
    read now (an archive's extracted copy: the report carries what it shows); else a folder
    that outlives the run (an archive's files have no link)."""
    if links == "source":
        return str(s.root)
    return None if s.shown_of.archive else str(s.root)


def _real(s, shown_path: str | None) -> str | None:
    """The file on this machine of a path shown as the user names it (inside an archive: in
    the side's extracted folder)."""
    if shown_path is None:
        return None
    archive = s.shown_of.archive if s.shown_of is not None else ""
    if archive and shown_path.startswith(archive + "/"):
        return str(Path(s.shown_of.folder) / shown_path[len(archive) + 1:])
    return shown_path


def _identify(s, role: str, touched=()) -> dict:
    """krl/diff/ident.py ``identify`` of side `s`, with ``robot_note`` for a robot its
    ``$config.dat`` names (no machine data; robot/named.py): whether the catalogue or the robot
    library has it, and if not, which robot the runs of side `role` drove in its place (the
    robots of its run outcomes among `touched`; without runs the one ``krl run`` drives, the
    KR 6 R900)."""
    ident = identify(s, role)
    if ident.get("robot_from") == "$config.dat MACHINE_DEF[1]":
        side_of = "old" if role == "old" else "new"
        ran = sorted({o["robot"] for t in touched for o in [getattr(t, f"{side_of}_outcome", None)]
                      if isinstance(o, dict) and o.get("robot")})
        ident["robot_note"] = Named.of(ident["robot"], "$config.dat").cover(", ".join(ran) or load_machine().name)
    return ident


def _run_touched(touched, a, b, max_sim_time, jobs) -> None:
    """Run the touched entry points on both sides (interp/outcomes.py) and fill in their
    outcomes and what changed; progress on standard error when it is a terminal."""

    paths = {}
    for t in touched:
        for s, p in ((a, t.old), (b, t.new)):
            real = _real(s, p)
            if real is not None:
                paths[real] = (t, "old" if s is a else "new")
    done = [0]
    tty = sys.stderr.isatty()

    def progress(path: str, outcome: dict) -> None:
        done[0] += 1
        if tty:
            t, which = paths[path]
            click.echo(f"\rkrl report: run {done[0]}/{len(paths)}: {printable(t.name)} ({which}) "
                       f"{outcome['ending']}\033[K", err=True, nl=done[0] == len(paths))

    results = run_outcomes(list(paths), max_sim_time, jobs, progress)
    for real, (t, which) in paths.items():
        setattr(t, f"{which}_outcome", results.get(real))
    for t in touched:
        t.changes = outcome_changes(t.old_outcome, t.new_outcome)
        t.ends_alike = ends_alike(t.old_outcome, t.new_outcome)


commands = [report]
