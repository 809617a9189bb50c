"""``krl log summary`` and the logbook's text and JSON forms.

**Messages** (:func:`messages`): the records grouped by (module, number), with their count, key,
first and last time, and the program modules they name (krl/logbook/links.py); a CrossMeld
number's text where the project knows it (the messages its simulated controller raises, each with
the place that raises it: passed in as ``texts``), else "text not in the archive" (the archive
holds only the key, ``M_1008``: ../shared/event-logs/README.md).

**Operator actions** (:func:`timeline`), the records an operator's hand made, from the modules
and keys of the shared KSS 8.7.8 logs (:data:`ACTIONS`): a program selected (Navigator
``LogSelect``), a file opened (XEdit ``logOpenFile``), a program deselected (XEdit
``logCancelProgram``), a block selection (XEdit ``logSelect``: the file and two numbers the log
does not explain, shown as they are), the operating mode changed (XEdit ``logModeOP3``: ``T1``,
``EX`` ...), a program reset (KrcRobotLogic ``LogProgramReset``), the start key
(HardKey ``LogStartPlus``/``LogStartMinus``), the stop key (``LogStop``), the active base
changed (Jogging ``ActiveBaseChanged``), the program override changed (Jogging
``ProgramOverrideChanged``, old and new %), a variable set from the pendant (Varkor
``logSetVar``: name, old and new value), an output set (KRCListMonitor ``LogValueChanged``), a
point taught or changed (TechHandler), the user group changed (LogonDisplay
``logLogonChanged``). Consecutive override changes are one entry (first and last value, count).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from krl.terminal import printable

from .record import LogRecord

__all__ = ["ACTIONS", "Action", "MessageGroup", "messages", "record_json", "record_line", "summary_json",
           "summary_lines", "timeline"]

NO_TEXT = "text not in the archive"

#: (module, key) -> (kind, how the parameters read); the kinds of :func:`timeline`
ACTIONS = {
    ("Navigator", "LogSelect"): ("select", "selected {0}"),
    ("XEdit", "logOpenFile"): ("open", "opened {0}"),
    ("XEdit", "logCancelProgram"): ("deselect", "deselected {0}"),
    ("XEdit", "logSelect"): ("block", "block selection in {0} [{1}; {2}]"),
    ("XEdit", "logModeOP3"): ("mode", "operating mode {0} -> {1}"),
    ("KrcRobotLogic", "LogProgramReset"): ("reset", "program reset"),
    ("HardKey", "LogStartPlus"): ("start", "start key (forward)"),
    ("HardKey", "LogStartMinus"): ("start", "start key (backward)"),
    ("HardKey", "LogStop"): ("stop", "stop key"),
    ("Jogging", "ActiveBaseChanged"): ("base", "active base {0} -> {1}"),
    ("Jogging", "ProgramOverrideChanged"): ("override", "override {0} -> {1} %"),
    ("Varkor", "logSetVar"): ("variable", "set {0}: {1} -> {2}"),
    ("KRCListMonitor", "LogValueChanged"): ("output", "set {0} = {1}"),
    ("TechHandler", "LogBookUserActionPointCreated"): ("point", "point {0} taught"),
    ("TechHandler", "LogBookUserActionPointChanged"): ("point", "point changed: {0}"),
    ("LogonDisplay", "logLogonChanged"): ("user", "user group {0} -> {1}"),
}


@dataclass
class MessageGroup:
    """The records of one (module, number): count, key, first and last record, the modules named."""

    module: str
    number: int | None
    key: str
    count: int
    first: LogRecord
    last: LogRecord
    text: str
    text_source: str
    programs: dict[str, str] = field(default_factory=dict)     # names -> file[:line]


def _place(rec: LogRecord) -> str:
    return rec.file + (f":{rec.line}" if rec.line else "")


def messages(records: Iterable[LogRecord], texts: dict[int, tuple[str, str]] | None = None) -> list[MessageGroup]:
    """The records grouped by (module, number), most frequent first (then by module, number).
    `texts`: CrossMeld number -> (text, source) the project knows."""
    texts = texts or {}
    groups: dict[tuple[str, int | None], MessageGroup] = {}
    for r in records:
        g = groups.get((r.module, r.number))
        if g is None:
            known = texts.get(r.number) if r.module == "CrossMeld" and r.number is not None else None
            text, source = known if known else (NO_TEXT if r.module == "CrossMeld" else "", "")
            g = groups[(r.module, r.number)] = MessageGroup(r.module, r.number, r.key, 0, r, r, text, source)
        g.count += 1
        g.last = r
        if r.names:
            g.programs.setdefault(r.names, _place(r))
    return sorted(groups.values(), key=lambda g: (-g.count, g.module.lower(), g.number if g.number is not None else -1))


@dataclass
class Action:
    """One entry of the operator's timeline: ``kind`` (:data:`ACTIONS`), the record (the first of
    a run of override changes), ``text``, ``count`` (override changes merged), ``place``."""

    kind: str
    record: LogRecord
    text: str
    count: int = 1
    place: str = ""


def _fill(pattern: str, params: tuple[str, ...]) -> str:
    values = [p.replace("\n", " ").strip() for p in params] + ["?"] * 3
    return pattern.format(*values)


def timeline(records: Iterable[LogRecord]) -> list[Action]:
    """The operator's actions in time order (module docstring); consecutive override changes are
    one entry from the first old value to the last new value."""
    out: list[Action] = []
    for r in records:
        known = ACTIONS.get((r.module, r.key))
        if known is None:
            continue
        kind, pattern = known
        prev = out[-1] if out else None
        if kind == "override" and prev is not None and prev.kind == "override":
            prev.count += 1
            first = prev.record.params[0] if prev.record.params else "?"
            prev.text = _fill(pattern, (first, *r.params[1:2]))
            continue
        out.append(Action(kind, r, _fill(pattern, r.params), 1, _place(r)))
    return out


def record_json(r: LogRecord) -> dict:
    """One record as ``krl log show --format json`` writes it (docs/schemas/log-record.schema.json)."""
    obj = {"time": r.iso_time, "log": r.log, "record": r.record, "channel": r.channel, "level": r.level,
           "source": r.source, "module": r.module, "number": r.number, "key": r.key, "short": r.short,
           "params": list(r.params), "param_kinds": list(r.kinds)}
    if r.controller_time:
        obj["controller_time"] = r.controller_time
    if r.note:
        obj["note"] = r.note
    if r.file:
        obj["file"] = r.file
        obj["names"] = r.names
        if r.line:
            obj["line"] = r.line
    return obj


def record_line(r: LogRecord) -> str:
    """One record as ``krl log show`` prints it (every text from the log made printable)."""
    num = "" if r.number is None else str(r.number)
    params = "; ".join(p.replace("\n", " ").strip() for p in r.params)
    where = f"  -> {_place(r)}" if r.file else ""
    note = f"  ({r.note})" if r.note else ""
    return printable(f"{r.iso_time}  {r.channel:<8} {r.module}/{r.source} {num} {r.key}"
                     + (f"  [{params}]" if params else "") + where + note)


def summary_json(records: list[LogRecord], texts: dict[int, tuple[str, str]] | None = None) -> dict:
    """``krl log summary --format json`` (docs/schemas/log-summary.schema.json)."""
    groups = messages(records, texts)
    # one entry per place: modules of one name in two files ($MACHINE of R1 and of STEU) and two
    # program lines of one module (Module@line records) stay apart (issue 85)
    programs: dict[tuple[str, str, int | None], dict] = {}
    for r in records:
        if r.names:
            p = programs.setdefault((r.names, r.file, r.line),
                                    {"names": r.names, "file": r.file, "line": r.line, "count": 0})
            p["count"] += 1
    return {
        "records": len(records),
        "first": records[0].iso_time if records else None,
        "last": records[-1].iso_time if records else None,
        "messages": [{"module": g.module, "number": g.number, "key": g.key, "count": g.count,
                      "first": g.first.iso_time, "last": g.last.iso_time, "text": g.text,
                      "text_source": g.text_source, "programs": sorted(g.programs)} for g in groups],
        "programs": sorted(programs.values(), key=lambda p: (-p["count"], p["names"], p["file"], p["line"] or 0)),
        "actions": [{"time": a.record.iso_time, "kind": a.kind, "text": a.text, "count": a.count,
                     **({"place": a.place} if a.place else {})} for a in timeline(records)],
    }


def summary_lines(records: list[LogRecord], texts: dict[int, tuple[str, str]] | None = None) -> list[str]:
    """``krl log summary`` as text (every text from the log made printable)."""
    s = summary_json(records, texts)
    out = [f"{s['records']} records, {s['first'] or '-'} .. {s['last'] or '-'}", "", "messages by module and number, the most frequent first:"]
    for m in s["messages"]:
        num = "" if m["number"] is None else m["number"]
        text = f"  \"{m['text']}\"" + (f" ({m['text_source']})" if m["text_source"] else "") if m["text"] else ""
        progs = f"  programs: {', '.join(m['programs'])}" if m["programs"] else ""
        out.append(printable(f"  {m['count']:>5}  {m['module']} {num} {m['key']}  {m['first']} .. {m['last']}"
                             + text + progs))
    out += ["", "programs named:" + ("" if s["programs"] else " none (or no archive's code to tie them to)")]
    for p in s["programs"]:
        place = p["file"] + (f":{p['line']}" if p["line"] else "")
        out.append(printable(f"  {p['names']}  {place}  ({p['count']} records)"))
    out += ["", "operator actions:" + ("" if s["actions"] else " none")]
    for a in s["actions"]:
        times = f"  ({a['count']} changes)" if a["count"] > 1 else ""
        place = f"  -> {a['place']}" if a.get("place") else ""
        out.append(printable(f"  {a['time']}  {a['kind']:<9} {a['text']}{times}{place}"))
    return out
