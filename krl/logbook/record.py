"""A KUKA logbook record, and the logbook of a path (one log, a ``Log Files`` folder, an archive).

**The record.** Each EVTX record of ``KUKA-KSS-KRC`` carries one ``EventData/Data Name="LS"``
whose text is a small XML document (``../shared/event-logs/README.md``)::

    <LE><S>source</S><M>module</M><N>number</N><DB>text key</DB>
        <P S="parameter" K="kind"/>...<DS>short key</DS><KT>controller time</KT></LE>

``M`` ``CrossMeld`` is the controller's message system (``N`` the KUKA message number, KSS01008
...; ``DB`` its key ``M_1008``); the message texts are not in the file. ``K="1"`` marks a
parameter that is itself a text key (``KrcSecurity#Operator``), ``K="0"`` a literal value.
``KT`` is the controller's local clock (``19:08:19.930``), TimeCreated the same instant in UTC.

**The logbook** (:func:`read_logbook`) of the logs :func:`log_sources` finds for a path: every
record of every log, in time order (TimeCreated; records of one instant in file order, logs by
name), filtered by time (``since`` <= time <= ``until``), module and number. A log that cannot be
read (krl/logbook/evtx.py ``LogError``) is one error of the result, its records before the damage
kept, and the other logs are read. At most ``MAX_LOG_RECORDS`` records are read in all.
"""

from __future__ import annotations

import datetime as dt
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree.ElementTree import ParseError

from defusedxml import ElementTree as SafeET
from defusedxml.common import DefusedXmlException

from krl.archive import Shown, is_archive
from krl.backups import one_source
from krl.kssarchive import archive_root, evt_files, log_files
from krl.limits import MAX_LOG_RECORD_CHARS, MAX_LOG_RECORDS

from .evtx import Event, LogError, read_events

__all__ = ["ARCHIVE_FILES", "LogRecord", "Logbook", "Sources", "has_event_logs", "iso_time", "log_sources", "parse_time",
           "read_logbook", "record_of"]

#: what krl log extracts of a zipped archive besides its KRL files
ARCHIVE_FILES = (".evt", "am.ini", "archiveinfo.xml")


@dataclass(slots=True)
class LogRecord:
    """One record of the logbook. ``time`` UTC; ``log`` the file it came from (as shown);
    ``record`` its EventRecordID; ``channel``, ``level``; from the LS document ``source`` (S),
    ``module`` (M), ``number`` (N, None when not a number), ``key`` (DB), ``short`` (DS),
    ``params`` (each P's S, in order) and ``kinds`` (each P's K: 1 a text key, 0 a value),
    ``controller_time`` (KT); ``note`` why the LS document was not read ("" when it was).
    krl/logbook/links.py fills ``file``, ``line`` and ``names`` (what a parameter names:
    ``MODULE`` or ``MODULE.variable``)."""

    time: dt.datetime
    log: str
    record: int
    channel: str
    level: int
    source: str = ""
    module: str = ""
    number: int | None = None
    key: str = ""
    short: str = ""
    params: tuple[str, ...] = ()
    kinds: tuple[int, ...] = ()
    controller_time: str = ""
    note: str = ""
    file: str = ""
    line: int | None = None
    names: str = ""

    @property
    def iso_time(self) -> str:
        """The record's time as :func:`iso_time` writes it."""
        return iso_time(self.time)


def iso_time(t: dt.datetime) -> str:
    """``2026-01-27T10:43:12.084Z``: the UTC time `t` in ISO 8601, to the millisecond (cut, not
    rounded), as the logbook shows every time."""
    return t.strftime("%Y-%m-%dT%H:%M:%S.") + f"{t.microsecond // 1000:03d}Z"


def _text(node, tag: str) -> str:
    got = node.find(tag)
    return (got.text or "") if got is not None else ""


def record_of(event: Event, log: str) -> LogRecord:
    """The :class:`LogRecord` of one event of the log `log` (its LS document parsed with
    defusedxml; a document that is not one leaves the KUKA fields empty and says why in ``note``)."""
    rec = LogRecord(event.time, log, event.record, event.channel, event.level)
    if not event.ls:
        rec.note = "no LS data in the record"
        return rec
    if len(event.ls) > MAX_LOG_RECORD_CHARS:
        rec.note = f"LS data of {len(event.ls)} characters, more than MAX_LOG_RECORD_CHARS; not read"
        return rec
    try:
        le = SafeET.fromstring(event.ls)
    except (ParseError, DefusedXmlException, ValueError) as exc:
        rec.note = f"LS data not readable ({exc})"
        return rec
    rec.source, rec.module, rec.key, rec.short = (_text(le, t) for t in ("S", "M", "DB", "DS"))
    rec.controller_time = _text(le, "KT")
    n = _text(le, "N").strip()
    rec.number = int(n) if n.lstrip("-").isdigit() else None
    ps = le.findall("P")
    rec.params = tuple(p.get("S", "") for p in ps)
    rec.kinds = tuple(1 if p.get("K", "0") == "1" else 0 for p in ps)
    return rec


def parse_time(text: str, end: bool = False) -> dt.datetime:
    """A time given on the command line: ISO 8601 (``2026-01-27``, ``2026-01-27T10:43``,
    ``2026-01-27T10:43:12.5Z``, ``...+03:00``); without a zone it is UTC. A date alone is its
    first instant, or with `end` its last. Raises ValueError."""
    t = text.strip()
    if t.endswith(("Z", "z")):
        t = t[:-1] + "+00:00"
    got = dt.datetime.fromisoformat(t)
    if end and len(text.strip()) == 10:
        got = got + dt.timedelta(days=1) - dt.timedelta(microseconds=1)
    return got.replace(tzinfo=dt.timezone.utc) if got.tzinfo is None else got.astimezone(dt.timezone.utc)


@dataclass
class Sources:
    """The logs of a path: ``logs`` (path, shown name), ``root`` the archive's folder (its KRL
    backup and manifest; None for a log or a folder of logs alone), ``shown`` its path mapping
    (krl/archive.py), ``notes``."""

    logs: list[tuple[Path, str]]
    root: Path | None
    shown: Shown
    notes: list[str] = field(default_factory=list)


def _found(path: Path, shown: Shown) -> Sources:
    """The logs of an existing path: the file itself; the .evt files of the folder; else the
    ``Log Files`` of the archive the folder belongs to (or of the folder)."""
    root = archive_root(path)
    if path.is_file():
        files = [path]
    else:
        files = evt_files(path) or log_files(root if root is not None else path)
    return Sources([(f, shown(str(f))) for f in files], root, shown)


def has_event_logs(path: str | Path) -> bool:
    """True when :func:`log_sources` would find an event log for `path`, found cheaply: a zip's
    entry names (nothing extracted), else the folders :func:`log_sources` looks in."""
    p = Path(path)
    if is_archive(p):
        try:
            with zipfile.ZipFile(p) as zf:
                return any(n.lower().endswith(".evt") for n in zf.namelist())
        except (zipfile.BadZipFile, OSError, ValueError):
            return False
    if not p.exists():
        return False
    return bool(_found(p, Shown()).logs)


@contextmanager
def log_sources(path: str | Path) -> Iterator[Sources]:
    """``with log_sources(p) as src``: the logs of `p`: one ``.evt`` file; a folder of logs
    (``Log Files``); a controller archive's folder (its ``Log Files``) or any folder inside it; a
    zipped archive (its logs, manifest and KRL files extracted into a temporary folder by
    krl/archive.py, removed afterwards). Raises krl.archive.ArchiveError for a refused zip,
    FileNotFoundError for a path that is not there."""
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"{path}: no such file or folder")
    with one_source(p, ARCHIVE_FILES) as (folder, shown):      # a folder of archives: its one (krl/backups.py)
        if shown.archive:
            tops = [c for c in folder.iterdir() if c.is_dir()]
            base = tops[0] if len(tops) == 1 and archive_root(tops[0]) == tops[0] else folder
            yield _found(base, shown)
        else:
            yield _found(p, shown)


@dataclass
class Logbook:
    """The records of some logs in time order (those that passed the filters), the errors of the
    logs not read whole, and ``read``: each log (as shown) -> the records read of it, before
    the filters (0: an empty log)."""

    records: list[LogRecord]
    errors: list[str]
    read: dict[str, int] = field(default_factory=dict)

    @property
    def empty_logs(self) -> list[str]:
        """The logs read whole that hold no record (a cleared log), as shown."""
        failed = {e.split(":", 1)[0] for e in self.errors}
        return [name for name, n in self.read.items() if n == 0 and name not in failed]


def _wanted(rec: LogRecord, since, until, module: str | None, number: int | None) -> bool:
    """The filters of :func:`read_logbook`; times compare to the millisecond, as they are shown
    (a record shown at ``...31.901Z`` passes ``--until ...31.901Z``)."""
    shown = rec.time.replace(microsecond=rec.time.microsecond // 1000 * 1000)
    return ((since is None or shown >= since) and (until is None or shown <= until)
            and (module is None or rec.module.lower() == module.lower())
            and (number is None or rec.number == number))


def read_logbook(logs: list[tuple[Path, str]], since: dt.datetime | None = None, until: dt.datetime | None = None,
                 module: str | None = None, number: int | None = None) -> Logbook:
    """Every record of `logs` ((path, shown) pairs) that passes the filters, in time order (see
    the module docstring). Never raises for a log's content: a log not read whole is an error."""
    out: list[LogRecord] = []
    errors: list[str] = []
    read: dict[str, int] = {}
    total = 0
    for path, shown in sorted(logs, key=lambda x: x[1].lower()):
        read[shown] = 0
        try:
            for event in read_events(path, shown):
                total += 1
                read[shown] += 1
                if total > MAX_LOG_RECORDS:
                    errors.append(f"{shown}: more than MAX_LOG_RECORDS = {MAX_LOG_RECORDS} records in all; "
                                  f"the rest of the logs is not read")
                    break
                rec = record_of(event, shown)
                if _wanted(rec, since, until, module, number):
                    out.append(rec)
        except LogError as exc:
            errors.append(str(exc))
        if total > MAX_LOG_RECORDS:
            break
    out.sort(key=lambda r: r.time)         # stable: one instant keeps the logs' and files' order
    return Logbook(out, errors, read)

