"""``krl log show`` and ``krl log summary`` (issue 75): the controller's logbook of a KUKA archive
(krl/logbook; docs/log.md). Registered by app/__init__.py.

Exit status: 0 every log read whole and records shown; 1 a log could not be read whole (its
error on standard error, naming the file and the record; the other logs' records are still
shown), or nothing to show (the logs hold no record: each empty log named; or no record passes
the filters); 2 a usage error (no such path, no event log there, a refused archive, a bad time). Never a traceback.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from krl.archive import ArchiveError
from krl.logbook.links import link_all
from krl.backups import BackupsError
from krl.logbook.record import Logbook, log_sources, parse_time, read_logbook
from krl.logbook.summary import record_json, record_line, summary_json, summary_lines
from krl.terminal import printable
from interp.runtime.kssmessages import KNOWN_MESSAGES


def _time(value: str | None, end: bool, name: str):
    if value is None:
        return None
    try:
        return parse_time(value, end)
    except ValueError:
        raise click.BadParameter(f"{value!r} is not an ISO 8601 time (2026-01-27, 2026-01-27T10:43:12Z)",
                                 param_hint=name) from None


def _book(path: Path, since, until, module, number) -> Logbook:
    """The logbook of `path`, filtered and linked to the archive's code; exits 2 for a path
    without event logs or a refused archive."""
    try:
        with log_sources(path) as src:
            if not src.logs:
                click.echo(f"krl log: {printable(path)}: no event log (.evt) here, nor in a 'Log Files' folder "
                           f"of a controller archive", err=True)
                sys.exit(2)
            book = read_logbook(src.logs, _time(since, False, "--since"), _time(until, True, "--until"),
                                module, number)
            link_all(book.records, src.root)
            return book
    except (ArchiveError, BackupsError, FileNotFoundError) as exc:
        click.echo(f"krl log: {printable(exc)}", err=True)
        sys.exit(2)


def _nothing(book: Logbook) -> bool:
    """Say on standard error what holds no record and return True when nothing is to be shown:
    each empty log is named (a cleared log); a logbook without any record, or whose records no
    filter keeps, is an error (exit 1: never "0 records" and success, issue 85)."""
    for name in book.empty_logs:
        click.echo(f"krl log: {printable(name)}: no record (an empty event log)", err=True)
    total = sum(book.read.values())
    if book.records:
        return False
    if total:
        click.echo(f"krl log: no record of the {total} read passes the filters", err=True)
    elif not book.errors and not book.empty_logs:
        click.echo("krl log: the event logs hold no record", err=True)
    return True


def _finish(book: Logbook, nothing: bool = False) -> None:
    for e in book.errors:
        click.echo(f"error: {printable(e)}", err=True)
    sys.exit(1 if book.errors or nothing else 0)


_PATH = click.argument("path", type=click.Path(path_type=Path))
_FILTERS = [
    click.option("--since", default=None, help="Only records at or after this time (ISO 8601; UTC unless a zone is given)."),
    click.option("--until", default=None, help="Only records at or before this time (a date alone: to its end)."),
    click.option("--module", default=None, help="Only records of this logbook module (CrossMeld, Varkor, XEdit, ...; any case)."),
    click.option("--number", type=int, default=None, help="Only records of this message number (N)."),
    click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True),
]


def _filters(f):
    for opt in reversed(_FILTERS):
        f = opt(f)
    return f


@click.group("log")
def log_group() -> None:
    """The controller's logbook: the event logs (Log Files/KrcLog*.evt) of a KUKA archive, tied to its code (docs/log.md)."""


@log_group.command("show")
@_PATH
@_filters
def show(path: Path, since, until, module, number, fmt) -> None:
    """Every record of PATH (one .evt file, a 'Log Files' folder, a controller archive folder or
    .zip) in time order: time (ISO 8601, UTC, ms), channel, source, module, number, key,
    parameters, and the archive's file and declaration line of a module or variable a parameter
    names. --format json: one object per line (docs/schemas/log-record.schema.json)."""
    book = _book(path, since, until, module, number)
    for r in book.records:
        click.echo(json.dumps(record_json(r), ensure_ascii=False) if fmt == "json" else record_line(r))
    _finish(book, _nothing(book))


@log_group.command("summary")
@_PATH
@_filters
def summary(path: Path, since, until, module, number, fmt) -> None:
    """PATH's logbook summed up: messages by number and module (count, first and last time, the
    text where the project knows the number), the programs the records name, and the operator's
    actions (selections, starts, override changes, variables set) as a timeline."""
    book = _book(path, since, until, module, number)
    if _nothing(book):
        _finish(book, True)
    if fmt == "json":
        click.echo(json.dumps(summary_json(book.records, KNOWN_MESSAGES), ensure_ascii=False, indent=1))
    else:
        for line in summary_lines(book.records, KNOWN_MESSAGES):
            click.echo(line)
    _finish(book)


commands = [log_group]
