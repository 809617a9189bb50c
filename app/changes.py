"""`krl diff OLD NEW` and `krl graph BACKUP` (issue 26): what changed between two backups
(krl/diff) and the program map (krl/programmap); :func:`load_map`, which app/report.py's
``krl report`` reads both with. Registered by app/__init__.py. Neither imports an interpreter or
the simulator (app/report.py does, for the report's runs): of the palletizer
backup (ingeniado), best of three beside the earlier module: ``krl graph --format text`` 4.8 ->
3.0 s of CPU, ``krl diff`` 2.6 -> 1.4 s (2026-11-28, a loaded machine). The logbook's message
texts come from interp/runtime/kssmessages.py, which no longer imports the natives either.

Exit status of ``krl diff``: 0 no change, 1 changes, 2 error (a path that does not exist, a
refused archive: the messages of ``krl check``, E001 and E004; files with syntax errors are
listed as not compared and their errors printed on standard error: without other changes the
exit status is then 2, since "no change" cannot be said). ``krl graph``: 0, or 2 for an error. Never a traceback for bad input.
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
from krl.parsecache import through_store
from krl.programmap import build_map
from krl.workspace import workspaces_for
from krl.programmap.render import GraphTooLarge, GraphvizMissing, to_dot, to_html, to_svg, to_text
from app.reportlog import graph_marks


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
            # each file's parse from the one store (krl/store.py) when it holds it, as krl check and
            # krl diff take theirs: krl graph of the palletizer, the store warm: 4.8 -> 1.0 s of CPU, 19 -> 4 s of wall time (a loaded machine, 2026-11-28)
            with through_store():
                wss = workspaces_for(part.folder, timeout=limits.PARSE_TIMEOUT_S,
                                     groups=None if entries is None else [(root, entries)])
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


commands = [diff, graph]
