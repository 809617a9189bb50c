"""`krl diff OLD NEW`, `krl graph BACKUP` and `krl report BACKUP [--since OLD]` (issue 26):
what changed between two backups (krl/diff), the program map (krl/programmap), and one HTML
page with both and the check summary. Registered by app/__init__.py.

Exit status of ``krl diff``: 0 no change, 1 changes, 2 error (a path that does not exist, a
refused archive: the messages of ``krl check``, E001 and E004; files with syntax errors are
listed as not compared and their errors printed on standard error: without other changes the
exit status is then 2, since "no change" cannot be said). ``krl graph`` and
``krl report``: 0, or 2 for an error. Never a traceback for bad input.
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

import click

from krl.durable import write_text
from krl import limits   # limits.PARSE_TIMEOUT_S read at each call (tests lengthen it)
from krl.source import read_source
from krl.terminal import printable
from krl.diagnostics.render import Renderer
from krl.diff.core import diff_sides
from krl.diff.load import DiffInputError, side
from krl.diff.text import diff_html, diff_text
from krl.archive import ArchiveError
from krl.backups import BackupsError, archive_named, one_backup
from krl.programmap import build_map
from krl.workspace import workspaces_for
from krl.programmap.render import GraphTooLarge, GraphvizMissing, to_dot, to_html, to_svg, to_text
from krl.diff.ident import generator, identify
from krl.diff.report import findings, relative, report_html, touched_entries, unread_lines
from interp.outcomes import ends_alike, outcome_changes, run_outcomes
from robot.machine import load_machine
from robot.named import Named
from interp.realprograms import REPORT_SIM_TIME_S
from app.reportlog import graph_marks, report_logbooks


def _fail(command: str, exc: Exception) -> None:
    click.echo(f"krl {command}: {printable(exc)}", err=True)
    sys.exit(2)


def _write(text: str, output: str | None) -> None:
    if output is None:
        click.echo(text)
    else:
        write_text(Path(output), text + ("" if text.endswith("\n") else "\n"))


def _echo_errors(sides, paths) -> None:
    """The input and syntax errors of the sides' files `paths` (shown paths), on standard error
    as krl check prints them."""

    renderer = Renderer(lambda s: click.echo(s, err=True), False)
    for s in sides:
        for path, text in s.sources.items():
            renderer.sources.add(path, text)
        renderer.emit([d for d in s.errors if d.path in paths])


@click.command()
@click.argument("old")
@click.argument("new")
@click.option("--format", "fmt", type=click.Choice(["text", "json", "html"]), default="text", show_default=True,
              help="text; json: one object (docs/diff.md); html: one page.")
@click.option("--tolerance", type=click.FloatRange(min=0), default=0.0, show_default=True,
              help="Hide point and frame deltas up to this size (mm or deg).")
@click.option("--timeout", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Seconds one file may parse (default: krl check's); past it the file is not compared (E005).")
@click.option("-o", "--output", default=None, help="Write to this file instead of standard output.")
def diff(old: str, new: str, fmt: str, tolerance: float, timeout: float | None, output: str | None) -> None:
    """What changed between two KRC backups (folders or .zip) or two files: points, frames and
    loads, routines, declarations and signals, inline-form motions. Exit 0 no change, 1
    changes, 2 error."""

    single = Path(old).is_file() and Path(new).is_file() and not any(
        p.lower().endswith(".zip") for p in (old, new))
    try:
        with side(old, single, timeout) as a, side(new, single, timeout) as b:
            d = diff_sides(a, b, tolerance)
            _echo_errors((a, b), set(d.not_compared))
        if fmt == "json":
            text = json.dumps(d.as_json(), indent=2, ensure_ascii=False)
        elif fmt == "html":
            text = diff_html(d)
        else:
            text = "\n".join(diff_text(d))
    except (DiffInputError, BackupsError) as exc:
        _fail("diff", exc)
    except Exception as exc:  # noqa: BLE001 - a last line of defence: no traceback
        _fail("diff", RuntimeError(f"internal error: {type(exc).__name__}: {exc}"))
    _write(text, output)
    # files not compared (syntax errors): "no change" cannot be said
    sys.exit(1 if d.changed else 2 if d.not_compared else 0)


def load_map(path: str):
    """``(map, diagnostics, files, lines)`` of the backup (folder or .zip) or file at `path`:
    its program map and ``krl check``'s diagnostics with paths shown as the user names them,
    its files (shown paths), and ``lines(shown path)``: the text lines of a file with a
    diagnostic (read while an archive is extracted; [] for others). Raises ValueError with the
    message of ``krl check`` for bad input."""

    p = Path(path)
    if not p.exists() and not p.is_symlink():
        raise ValueError(f"{path}:1:1: error[E001]: no such file or folder")
    try:
        with one_backup(p) as (part, root, entries):
            shown = part.shown
            wss = workspaces_for(part.folder, timeout=limits.PARSE_TIMEOUT_S, groups=None if entries is None else [(root, entries)])
            ws = wss[0]
            pm = build_map(ws)
            diags = [shown.diagnostic(d) for d in ws.diagnostics]
            texts = {shown(real): (read_source(real).text or "").splitlines()
                     for real in {d.path for d in ws.diagnostics} if Path(real).is_file()}
            pm.root = shown(pm.root)
            for n in pm.nodes.values():
                n.path = shown(n.path) if n.path else n.path
                n.uses = {(shown(f), name) for f, name in n.uses}
            pm.edges = [replace(e, path=shown(e.path)) for e in pm.edges]
            pm.unresolved = [(s, n, shown(f), ln) for s, n, f, ln in pm.unresolved]
            pm.not_understood = [replace(p, path=shown(p.path)) for p in pm.not_understood]
            return pm, diags, [shown(f.path) for f in ws.files], lambda shown_path: texts.get(shown_path, [])
    except ArchiveError as exc:
        raise ValueError(f"{path}:1:1: error[E004]: {str(exc).removeprefix(f'{path}: ')}") from None


@click.command()
@click.argument("backup")
@click.option("--format", "fmt", type=click.Choice(["dot", "svg", "html", "json", "text"]), default="dot", show_default=True,
              help="dot: Graphviz source; svg: drawn by Graphviz's dot; html: an interactive page; json: nodes and "
                   "edges; text: entry points, modules only an operator starts, dead routines.")
@click.option("--links", type=click.Choice(["file", "vscode", "none"]), default="file", show_default=True,
              help="html: how a routine links to its file:line (file: URL, vscode: URL, or no link).")
@click.option("-o", "--output", default=None, help="Write to this file instead of standard output.")
def graph(backup: str, fmt: str, links: str, output: str | None) -> None:
    """The program map of a KRC backup (folder or .zip) or a folder: routines, calls,
    interrupts, triggers, RUN commands and EKI channels, entry points and unreachable routines.
    html: an interactive page (zoom, pan, search, a routine's neighbourhood), offline; in a
    controller archive the routines its logbook names are marked."""

    try:
        pm, _diags, _n, _lines = load_map(backup)
        if fmt == "json":
            text = json.dumps(pm.as_json(), indent=2, ensure_ascii=False)
        elif fmt == "svg":
            text = to_svg(pm)
        elif fmt == "html":
            text = to_html(pm, links, graph_marks(pm, archive_named(backup)))
        elif fmt == "text":
            text = "\n".join(to_text(pm))
        else:
            text = to_dot(pm)
    except (ValueError, GraphTooLarge, GraphvizMissing) as exc:
        _fail("graph", exc)
    except Exception as exc:  # noqa: BLE001 - a last line of defence: no traceback
        _fail("graph", RuntimeError(f"internal error: {type(exc).__name__}: {exc}"))
    _write(text, output)


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


commands = [diff, graph, report]
