"""The logbook in the change report (issue 75 item 3): each side's controller logbook, for the
report's "Logbook" section (krl/diff/templates/_logbook.html.j2).

For a side that is a controller archive with event logs (krl/logbook: folder or .zip), its
records summed up as ``krl log summary`` sums them (messages by module and number, the programs
named, the operator's actions); with an older side, the newer side's records since the older
archive (after the older archive's last logbook record: the logs of one controller overlap) --
what happened on the robot between the two archives. A side without event
logs has no logbook (None); a log not read whole is listed with its error.
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

from krl.archive import ArchiveError
from krl.logbook.links import link_all
from krl.logbook.record import LogRecord, has_event_logs, iso_time, log_sources, read_logbook
from krl.logbook.summary import summary_json, timeline
from krl.programmap.graph import ProgramMap
from krl.programmap.render import logbook_marks
from interp.runtime.kssmessages import KNOWN_MESSAGES

__all__ = ["graph_marks", "side_logbook", "report_logbooks"]

#: the operator's actions and message groups the report lists per side (the rest are counted)
MAX_REPORT_ACTIONS = 200
MAX_REPORT_MESSAGES = 100
#: the programs (modules and variables) the report names per side, and per message group
MAX_REPORT_PROGRAMS = 200
MAX_NAMES_SHOWN = 20


def _records(path: str) -> tuple[list[LogRecord], list[str], Path | None] | None:
    if not has_event_logs(path):           # a backup that is no archive: nothing extracted again
        return None
    try:
        with log_sources(path) as src:
            if not src.logs:
                return None
            book = read_logbook(src.logs)
            link_all(book.records, src.root)
            return book.records, book.errors, src.root
    except (ArchiveError, FileNotFoundError, OSError):
        return None


def _in_side(file: str, side_root: Path | None) -> str:
    """A logbook `file` (relative to the archive) as a path relative to the side's backup root
    (the report's links are), found by its trailing path parts; "" when the side has no such file."""
    if not file or side_root is None:
        return ""
    parts = Path(file).parts
    for k in range(len(parts)):
        if (side_root.joinpath(*parts[k:])).is_file():
            return Path(*parts[k:]).as_posix()
    return ""


def side_logbook(role: str, path: str, side_root: Path | None, since: dt.datetime | None = None,
                 records=None) -> dict | None:
    """The report's logbook of one side: {role, path, since, records, errors, summary} with each
    place (a message's programs, an action's place) as (file relative to `side_root`, line);
    None when `path` has no event logs. `records`: the side's (records, errors, root) when read."""
    got = records if records is not None else _records(path)
    if got is None:
        return None
    recs, errors, _root = got
    shown = [r for r in recs if since is None or r.time > since]
    s = summary_json(shown, KNOWN_MESSAGES)
    for p in s["programs"]:              # one entry per place (krl/logbook/summary.py): its own file and line
        p["where"] = (_in_side(p["file"], side_root), p["line"]) if p["file"] else None
    s["actions"] = [{"time": a.record.iso_time, "kind": a.kind, "text": a.text, "count": a.count,
                     "where": (_in_side(a.record.file, side_root), a.record.line) if a.record.file else None}
                    for a in timeline(shown)]
    more = {"messages": max(0, len(s["messages"]) - MAX_REPORT_MESSAGES),
            "actions": max(0, len(s["actions"]) - MAX_REPORT_ACTIONS),
            "programs": max(0, len(s["programs"]) - MAX_REPORT_PROGRAMS)}
    s["messages"] = s["messages"][:MAX_REPORT_MESSAGES]
    s["actions"] = s["actions"][:MAX_REPORT_ACTIONS]
    s["programs"] = s["programs"][:MAX_REPORT_PROGRAMS]
    for m in s["messages"]:
        if len(m["programs"]) > MAX_NAMES_SHOWN:
            m["programs"] = m["programs"][:MAX_NAMES_SHOWN] + [f"and {len(m['programs']) - MAX_NAMES_SHOWN} more"]
    return {"role": role, "path": path, "since": iso_time(since) if since else "", "total": len(recs),
            "errors": errors, "summary": s, "more": more}


def report_logbooks(new: tuple[str, Path | None], old: tuple[str, Path | None] | None = None) -> list[dict]:
    """The report's logbooks: without `old`, the new side's whole logbook; with `old`, the old
    side's and the new side's since the older archive (module docstring). Each side: (the path
    as the user named it, its backup root on this machine, for the links)."""
    new_recs = _records(new[0])
    if old is None:
        got = side_logbook("backup", new[0], new[1], records=new_recs)
        return [got] if got is not None else []
    old_recs = _records(old[0])
    since = max((r.time for r in old_recs[0]), default=None) if old_recs else None
    out = [side_logbook("old", old[0], old[1], records=old_recs) if old_recs else None,
           side_logbook("new", new[0], new[1], since, records=new_recs) if new_recs else None]
    return [x for x in out if x is not None]


def graph_marks(pm: ProgramMap, path: str) -> dict[str, str]:
    """The program map's marks (krl/programmap/render.py ``logbook_marks``) of the archive at
    `path`: the modules and variables its logbook names; {} without event logs."""
    got = _records(path)
    named: dict[str, int] = {}
    for r in got[0] if got is not None else []:
        if r.names:
            named[r.names] = named.get(r.names, 0) + 1
    return logbook_marks(pm, named) if named else {}
