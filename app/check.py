"""`krl check PATH... [--json]`: the front end's command (registered by app/__init__.py).

PATH is a file (checked with the .src/.dat of its module), a KRC backup folder (one
workspace), a folder holding backups (one workspace per backup) or plain files (one
workspace), or a backup archive (.zip, checked as the folder it holds: krl/archive.py; a
refused archive is error E004; paths are shown as ``backup.zip/KRC/R1/...``). Output (``--format``): compiler-style text (``path:line:col: error[CODE]: message``,
the source line and a caret, krl/diagnostics/render.py, then a count line), one JSON object per
workspace, or SARIF 2.1.0. ``--ignore CODE`` and the workspace's ``krl.toml`` select codes and
severities (krl/semantics/config.py). Exit 1 when there are errors, 0 otherwise, 2 for a bad
configuration or an internal failure; never a Python traceback for bad input.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from types import SimpleNamespace

import click

from krl.diagnostics import Diagnostic
from krl.diagnostics.codes import E004, E901
from krl.limits import PARSE_TIMEOUT_S
from krl.project import folder_groups
from krl.source import read_source
from krl.terminal import printable
from krl.diagnostics.render import Renderer, use_colour
from krl.archive import ArchiveError
from krl.backups import BackupsError, opened
from krl.kssarchive import ARCHIVE_MANIFESTS, packages_text
from krl.cluster import run_batches, SchedulerError
from krl.semantics.config import ConfigError, Selection, config_for, parse_codes
from krl.workspace import load_workspaces, not_understood, on_each_file, Workspace, workspaces_for
from krl import store
from krl.parsecache import through_store
from krl.diagnostics.sarif import to_sarif

@click.command()
@click.argument("paths", nargs=-1, required=True)
@click.option("--format", "fmt", type=click.Choice(["text", "json", "sarif"]), default="text", show_default=True,
              help="text: compiler style; json: one object per workspace; sarif: SARIF 2.1.0.")
@click.option("--json", "as_json", is_flag=True, help="Same as --format json.")
@click.option("--no-warnings", is_flag=True, help="Print errors only.")
@click.option("--ignore", "ignore", multiple=True, metavar="CODE",
              help="Do not report CODE (or a prefix: W1); repeatable, or comma-separated. Adds to krl.toml.")
@click.option("--report", "report_dir", default=None,
              help="Instead: write check_report.md/.json for the KRC backups below PATH into this folder.")
@click.option("--timeout", type=click.FloatRange(min=0, min_open=True), default=PARSE_TIMEOUT_S,
              show_default=True, help="Seconds one file may parse; past it the parse is stopped (error E005).")
@click.option("--no-cache", "no_cache", is_flag=True,
              help="Parse every file again: parses are neither read from nor kept in the store (krl/store.py).")
@click.option("--jobs", type=click.IntRange(min=1), default=None,
              help="Worker processes that parse the files (default: the number of cores).")
@click.option("--scheduler", default=None, metavar="tcp://HOST:PORT",
              help="Check the backups of a folder on this Dask distributed scheduler's cluster, one "
                   "backup per task (its workers see the folder at the same path); the same output.")
@click.option("--reach", is_flag=True,
              help="Instead: for each PROGRAM, the taught points its robot cannot reach and the motions "
                   "that collide with the cell (--inputs), without running it (interp/reach.py).")
@click.option("--robot", default=None, help="With --reach: the robot (as `krl run --robot`).")
@click.option("--inputs", default=None, help="With --reach: the cell file (its geometry:, tool:, floor:).")
def check(paths: tuple[str, ...], fmt: str, as_json: bool, no_warnings: bool, ignore: tuple[str, ...],
          report_dir: str | None, timeout: float, jobs: int | None, scheduler: str | None,
          reach: bool = False, robot: str | None = None, inputs: str | None = None,
          no_cache: bool = False) -> None:
    """Type-check KRL files, KRC backup folders or backup .zip archives; exit 1 when there are
    errors. Every code is explained in docs/diagnostics.md."""
    if no_cache:       # for the whole command and the workers it starts (krl/store.py turned_off)
        click.get_current_context().with_resource(store.turned_off())
    if reach:
        sys.exit(_reach(paths, robot, inputs))
    if report_dir is not None:
        # deferred: tools/startup_bench.py, krl check +5 ms at the top (2026-11-26)
        from krl.survey.report import check_report  # noqa: PLC0415
        try:
            for path in paths:
                _data, md = check_report(path, report_dir, timeout=timeout, jobs=jobs)
                click.echo(md)
        except Exception as exc:  # noqa: BLE001
            click.echo(f"krl check: internal error: {type(exc).__name__}: {exc}")
            sys.exit(2)
        sys.exit(0)

    fmt = "json" if as_json else fmt
    status = run_check(list(paths), no_warnings=no_warnings, echo=click.echo, fmt=fmt,
                       ignore=[c for v in ignore for c in v.split(",") if c.strip()],
                       colour=fmt == "text" and use_colour(sys.stdout), timeout=timeout, jobs=jobs,
                       scheduler=scheduler)
    sys.exit(status)


def _reach(paths: tuple[str, ...], robot: str | None, inputs: str | None) -> int:
    """``krl check --reach``: interp/reach.py on each program; exit 1 when a point is out of
    reach or a motion collides, 2 when a program cannot be loaded."""
    # deferred: tools/startup_bench.py, krl check +382 ms at the top (2026-11-26)
    from interp.reach import REACH_ERRORS, reach_check  # noqa: PLC0415

    status = 0
    for path in paths:
        try:
            report = reach_check(Path(path), robot=robot, inputs=inputs)
        except REACH_ERRORS as exc:
            click.echo(f"error: {printable(str(exc))}", err=True)
            return 2
        for line in report.lines():
            click.echo(printable(line))
        status = max(status, 1 if report.problems else 0)
    return status


def run_check(paths: list[str], as_json: bool = False, no_warnings: bool = False, echo=print,
              fmt: str = "text", ignore=(), colour: bool = False, timeout: float | None = None,
              jobs: int | None = None, scheduler: str | None = None) -> int:
    """Check `paths` and print the diagnostics in `fmt` ("text", "json", "sarif"; `as_json` is
    the old spelling of "json"); `ignore`: codes not to report (with the krl.toml of each
    workspace, krl/semantics/config.py). `timeout`: seconds per file, files parsed in worker
    processes that are killed past it (None: parse here, without a limit; the command passes
    krl.limits.PARSE_TIMEOUT_S); `jobs`: worker processes. `scheduler`: the address of a Dask
    scheduler whose workers load and check the backups of a folder holding several, one per
    task (:func:`check_group`; the output is the local one). Returns the exit status: 0, 1
    (errors), 2 (bad configuration, internal failure, a scheduler that cannot be used)."""
    fmt = "json" if as_json else fmt
    renderer = Renderer(echo, colour)
    all_shown = []
    files = 0
    any_error = False
    seen: set = set()      # files already checked: `krl check A.src A.dat` checks module A once

    def report(root: str, n_files: int, diags: list, partial: list = (), named=str, packages=()) -> None:
        shown = [d for d in diags if d.is_error or not no_warnings]
        if fmt == "json":
            echo(json.dumps({
                "workspace": root,
                **({"installed_packages": [{"name": n, "version": v} for n, v in packages]} if packages else {}),
                "files": n_files,
                "errors": sum(d.is_error for d in diags),
                "warnings": sum(not d.is_error for d in diags),
                "not_understood": [{"file": named(p.path), "lines": [{"line": n, "message": m} for n, m in p.lines],
                                    "understood": p.understood, "total": p.total, "noun": p.noun} for p in partial],
                "diagnostics": [d.as_json() for d in shown],
            }))
        elif fmt == "sarif":
            all_shown.extend(shown)
        else:
            if packages:      # what the check took as installed software (krl/semantics/outside.py)
                echo(printable(f"{root}: the archive's am.ini lists these technology packages as installed: "
                               f"{packages_text(packages)}"))
            # the lines not understood first, once each: the rest of each file is checked (issue 63)
            for p in partial:
                echo(printable(p.headline("checked", named)))
                for line in p.details(named):
                    echo("  " + printable(line))
            renderer.emit(shown)

    try:
        cli_sel = Selection(ignore=parse_codes(ignore, "--ignore"))
        for path in paths:
            if _resolved(path) in seen:
                continue
            try:
                # a folder, a .zip, or a folder of controller archives: each part (krl/backups.py)
                with opened(path, ARCHIVE_MANIFESTS) as parts:
                    for part in parts:
                        if part.error:
                            any_error = True
                            report(part.source, 0, [Diagnostic(part.source, 1, 1, *E004(detail=part.error))])
                            continue
                        where = part.folder if part.archive else path
                        for ws in _loaded(where, timeout, jobs, scheduler, part.walked):
                            seen.update(_resolved(f.path) for f in ws.files)
                            try:
                                sel = config_for(ws.root, where).merged(cli_sel)
                            except ConfigError as exc:   # name the krl.toml as the user sees it
                                raise ConfigError(str(exc).replace(str(part.folder), part.source)
                                                  if part.archive else str(exc)) from None
                            diags = sel.apply(ws.check(resolve=False))   # nothing runs: no storage placed
                            files += len(ws.files)
                            if part.archive:
                                for real in {d.path for d in diags}:
                                    renderer.sources.add(part.shown(real), read_source(real).text or "")
                                diags = [part.shown.diagnostic(d) for d in diags]
                            any_error |= any(d.is_error for d in diags)
                            partial = not_understood(ws) if isinstance(ws, Workspace) else []
                            report(part.shown(ws.root), len(ws.files), diags, partial, part.shown,
                                   getattr(ws, "installed_packages", ()))
            except ArchiveError as exc:
                any_error = True
                message = str(exc).removeprefix(f"{path}: ")
                report(str(path), 0, [Diagnostic(str(path), 1, 1, *E004(detail=message))])
    except ConfigError as exc:
        echo(f"krl check: {printable(exc)}")
        return 2
    except (SchedulerError, BackupsError) as exc:
        echo(f"krl check: error: {printable(exc)}")
        return 2
    except Exception as exc:  # noqa: BLE001 - a last line of defence: no traceback
        echo(f"krl check: internal error: {type(exc).__name__}: {printable(exc)}")
        return 2
    if fmt == "sarif":
        echo(json.dumps(to_sarif(all_shown), indent=2))
    elif fmt == "text" and (files or any_error):   # nothing read is said once, below
        echo(renderer.summary(files))
    if not files and not any_error:     # nothing read is no check passed (issue 85)
        echo(f"krl check: error: no KRL file in {', '.join(printable(p) for p in paths)}")
        return 2
    return 1 if any_error else 0


def _loaded(path, timeout: float | None = None, jobs: int | None = None, scheduler: str | None = None,
            walked: list | None = None) -> list:
    """workspaces_for(path), with a transient progress bar on standard error when it is a
    terminal (a KRC backup of a few hundred files takes tens of seconds to parse); piped or
    redirected, nothing is shown, so the output is the same either way. With `scheduler`, a
    folder holding backups is checked on that Dask cluster (:class:`Checked` per group).
    `walked`: the folder's one walk, made already (krl/backups.py ``Opened.walked``)."""
    if scheduler is not None:
        groups = folder_groups(Path(path), walked)
        if groups is not None and (len(groups) > 1 or groups[0][0] != str(path)):
            return _on_cluster(scheduler, groups, timeout)

    with through_store():       # each file's parse from the one store (krl/store.py) when it holds it
        return _loaded_here(path, timeout, jobs, walked)


def _loaded_here(path, timeout: float | None, jobs: int | None, walked: list | None = None) -> list:

    if not _progress_shown():
        groups = folder_groups(Path(path), walked) if walked is not None else None
        return workspaces_for(path, timeout=timeout, jobs=jobs, groups=groups)
    # deferred: tools/startup_bench.py, krl check --reach +33 ms at the top (2026-11-26)
    from recovery.progress import bar  # noqa: PLC0415

    p = Path(path)
    groups = folder_groups(p, walked)   # the one walk of the folder; its entries are loaded below
    total = sum(e.kind == "file" for _, entries in groups or () for e in entries) if p.is_dir() else None
    with bar("parsing", total) as advance, on_each_file(lambda file: advance(Path(file).name)):
        return workspaces_for(path, timeout=timeout, jobs=jobs, groups=groups)


class Checked:
    """A workspace checked on a Dask worker, as run_check uses it: `root`, `files` (objects
    with a ``path``) and its diagnostics (:meth:`check`)."""

    def __init__(self, root: str, files: list[str], diagnostics: list) -> None:
        self.root = root
        self.files = [SimpleNamespace(path=f) for f in files]
        self.diagnostics = diagnostics

    def check(self, resolve: bool = False) -> list:
        """The diagnostics, as ``Workspace.check(resolve)`` returns them (checked already)."""
        return self.diagnostics


def check_group(root: str, entries: list, timeout: float | None) -> tuple[str, list[str], list]:
    """On a worker: (root, file paths, sorted diagnostics) of the workspace of one (root,
    entries) group of krl.project.folder_groups, loaded and checked as workspaces_for does
    (the files are parsed in the worker's process: a Dask worker may not start the killable
    pool; the batch's deadline on the cluster bounds it, krl/cluster.py)."""

    ws = load_workspaces([(root, entries)], None)[0]
    diags = ws.check(resolve=False)     # nothing runs: no storage placed
    return ws.root, [str(f.path) for f in ws.files], list(diags)


def _on_cluster(scheduler: str, groups: list, timeout: float | None) -> list:
    """The groups checked on the Dask cluster at `scheduler`, in their order. Raises
    krl.cluster.SchedulerError; a group whose task fails is an E901 diagnostic of its root."""
    tasks = [(i, (root, entries, timeout)) for i, (root, entries) in enumerate(groups)]
    # a task's deadline: the per-file timeout times its files (krl/cluster.py adds the transfer)
    most = max((sum(e.kind == "file" for e in entries) for _r, entries in groups), default=1)
    got = {}
    for o in run_batches(scheduler, check_group, tasks, batch_files=1, name="krl-check",
                         timeout=None if timeout is None else timeout * max(most, 1)):
        root = groups[o.key][0]
        if o.status == "done":
            got[o.key] = Checked(*o.value)
        else:
            got[o.key] = Checked(root, [], [Diagnostic(root, 1, 1, *E901("cluster", status=o.status, detail=o.detail))])
    return [got[i] for i in range(len(groups))]


def _progress_shown() -> bool:
    try:
        return sys.stderr.isatty() and os.environ.get("TERM", "") != "dumb"
    except (AttributeError, ValueError):
        return False


def _resolved(path) -> str:
    try:
        return str(Path(path).resolve())
    except OSError:
        return str(path)


commands = [check]
