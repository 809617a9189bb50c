"""The report of ``krl audit``: its data (JSON, docs/schemas/audit.schema.json), each unit's
health, and the HTML page (docs/audit.md).

**Health.** Each backup or program folder gets a *status* and the *reasons* for it, each reason
a sentence with its count and a link to the items behind it; no weighted score (a number
whose weights nobody can defend explains nothing). The rules, in :func:`health`:

* ``attention`` -- an entry point ends in a program error (a KRL run-time error at its
  file:line, or a target the backup's own robot cannot take); a run on the backup's own robot
  (its ``$machine.dat``) raised a motion error (workspace error, software limit switch, a CP
  path through a singularity, any other motion error of the controller); an output is written
  by two programs that run at once, or by a program and the PLC's map (audit/outputs.py); the
  backup could not be checked;
* ``review`` -- the checker reports errors; an entry point stops at a limit of the audit (it
  starves for an input the automatic cell cannot set, or loops) or at a gap of the simulator;
  a run on a stand-in robot (no machine data name the backup's own) raised a motion error;
  an output is written under two SIGNAL names; entry points past MAX_AUDIT_ENTRIES were not
  run;
* ``ok`` -- none of these.

**Evidence.** Every item names its file and line (relative to the unit's root). The HTML page
carries each place's source lines (two before, two after: read here through krl/source.py,
at most MAX_AUDIT_EVIDENCE_CHARS in all) in an evidence list at its end; each item links to
its evidence in the page, and the evidence to the file (a ``file:`` URL). The page is rendered
in the project's one Jinja environment (krl/render.py, autoescape on); its only script sorts
the tables (by a cell's ``data-sort`` value, numbers as numbers) and reads nothing else.
"""

from __future__ import annotations

import json
from datetime import datetime, timezone
from pathlib import Path

from krl import __version__
from krl.limits import MAX_AUDIT_EVIDENCE_CHARS
from interp.realprograms import cause_of
from interp.summary import ENDINGS, ending_of
from krl.render import render_html
from krl.durable import write_text
from krl.source import read_source

from audit.logbook import fleet_logbook, unit_logbook

__all__ = ["AUDIT_FORMAT", "STATUSES", "rel_path", "plural", "report_data", "health", "write_report", "to_html",
           "causes_of", "motion_causes", "finding_groups"]

#: the version of the report's JSON (docs/schemas/audit.schema.json)
AUDIT_FORMAT = 1
#: the statuses, worst first
STATUSES = ("attention", "review", "ok")
#: answers of the automatic cell kept per run (all are counted)
MAX_ANSWERS_SHOWN = 10
#: lines of source shown before and after an item's line
CONTEXT_LINES = 2
#: characters of one source line shown in the evidence
MAX_EVIDENCE_LINE = 240


def rel_path(path, root: str) -> str | None:
    """`path` relative to the unit's `root` when inside it (also when one of them is given
    relative to the current folder and the other resolved: a run reports resolved paths), else
    as given; None for none."""
    if not path:
        return None
    p, r = Path(path), Path(root)
    for a, b in ((p, r), (p.absolute(), r.absolute()), (p.resolve(), r.resolve())):
        try:
            return a.relative_to(b).as_posix()
        except ValueError:
            continue
    return str(path)




def plural(n: int, word: str) -> str:
    """``1 entry point``, ``2 entry points``, ``3 check errors``, ``2 bodies``."""
    return f"{n} {word}" if n == 1 else f"{n} {word}s" if not word.endswith("y") else f"{n} {word[:-1]}ies"


def _cycle(requests: list[float], motions: list[int] | None, total: int) -> dict | None:
    """The cell program's production cycles from the times P00 asked for a program number
    (`requests`, s) and the motions started before each (`motions`): the time from one request
    to the next in which the robot moved (s), their count, mean, shortest and longest; None
    without such a cycle. A handshake after which no motion started picked nothing (an empty
    CASE branch, a number no branch selects): it times P00's handshake alone, no cycle of the
    cell (issue 85 item 5: "cell cycle 0.240 s" of a run with 0 picks)."""
    if len(requests) < 2 or motions is None or len(motions) != len(requests):
        return None
    cycles = [round(b - a, 3) for a, b, m, n in zip(requests, requests[1:], motions, motions[1:]) if n > m]
    if not cycles:
        return None
    return {"requests": total, "cycles": len(cycles), "mean": round(sum(cycles) / len(cycles), 3),
            "min": min(cycles), "max": max(cycles), "first": cycles[:20]}


def _entry(row: dict, program: dict, root: str) -> dict:
    """One entry point of a unit in the report, from its run row (interp.realprograms.run_one)
    and its listing (audit.fleet.check_unit)."""

    reason = row.get("reason", "internal")
    own_end = reason in ("completed", "halt")
    requests = row.get("requests") or []
    return {
        "program": rel_path(program["path"], root), "kind": program.get("kind") or "", "why": program.get("why") or "",
        "cause": row.get("cause") or cause_of(row), "reason": reason,
        "ending": ending_of(reason, row.get("text")) if reason in ENDINGS
        else "stopped at the audit's wall-clock limit" if reason == "wall_time"
        else "internal error of the simulator" if reason == "internal" else reason,
        "text": row.get("text") or "", "file": rel_path(row.get("file"), root), "line": row.get("line"),
        "sim_time": row.get("sim_time", 0.0), "run_time": row.get("sim_time") if own_end else None,
        "steps": row.get("steps", 0), "robot": row.get("robot", ""), "robot_own": bool(row.get("robot_own")),
        "motions": row.get("motions", 0),
        "event_counts": row.get("event_counts") or {},
        "events": [{**e, "file": rel_path(e.get("file"), root)} for e in row.get("events") or ()],
        # a cycle time only for a cell program that selects a production program (issue 63):
        # KUKA's template loop, whose CASE branches call nothing, times P00's handshake alone
        "cycle": _cycle(requests, row.get("request_motions"), row.get("requests_total", len(requests)))
        if program.get("kind") == "cell" and program.get("selects") else None,
        "stubs": row.get("stubs") or {}, "submit_errors": row.get("submit") or [],
        "requests": row.get("requests_total", len(requests)),
        "answers": len(row.get("answers") or ()), "answers_shown": (row.get("answers") or [])[:MAX_ANSWERS_SHOWN],
    }


def health(unit: dict) -> tuple[str, list[dict]]:
    """The status of a unit of the report and its reasons (module docstring): ``(status,
    [{"level", "text", "target"}])``, `target` the id of the report's section behind it."""
    reasons: list[dict] = []

    def add(level: str, text: str, target: str) -> None:
        reasons.append({"level": level, "text": text, "target": target})

    if unit.get("error"):
        add("attention", unit["error"], "check")
    entries = unit.get("entries", [])
    by = {}
    for e in entries:
        by[e["cause"]] = by.get(e["cause"], 0) + 1
    n = len(entries)
    groups: dict[str, int] = {}
    for c in unit.get("causes", []):
        groups[c["cause"]] = groups.get(c["cause"], 0) + 1
    if by.get("program error"):
        add("attention", f"{by['program error']} of {n} entry points end in a program error "
                         f"({plural(groups.get('program error', 0), 'cause')})", "causes")
    words = {"reach": "workspace error", "limit": "software limit switch", "singularity": "singularity",
             "motion": "other motion error"}
    for own in (True, False):
        events: dict[str, int] = {}
        for e in entries:
            if e["robot_own"] == own:
                for k, c in e["event_counts"].items():
                    events[k] = events.get(k, 0) + c
        if events:
            detail = ", ".join(plural(c, words.get(k, k)) for k, c in events.items())
            if own:
                add("attention", f"{plural(sum(events.values()), 'motion error')} on the backup's own robot "
                                 f"({detail})", "events")
            else:
                add("review", f"{plural(sum(events.values()), 'motion error')} on a stand-in robot (the backup's "
                              f"machine data do not name this robot: {detail})", "events")
    ov = unit.get("outputs", {}).get("overlaps", [])
    two = sum("two programs" in o["flags"] for o in ov)
    plc = sum("PLC map" in o["flags"] for o in ov)
    names = sum(o["flags"] == ["two names"] for o in ov)
    if two:
        add("attention", f"{plural(two, 'output')} written by two programs that run at once", "outputs")
    if plc:
        add("attention", f"{plural(plc, 'output')} of the PLC map written by a program", "outputs")
    if unit.get("errors"):
        add("review", f"{plural(unit['errors'], 'check error')}", "check")
    if by.get("limit"):
        add("review", f"{by['limit']} of {n} entry points stop at a limit of the audit (starving or looping)",
            "causes")
    if by.get("interpreter gap"):
        add("review", f"{by['interpreter gap']} of {n} entry points stop at a gap of the simulator "
                      f"({plural(groups.get('interpreter gap', 0), 'cause')})", "causes")
    if names:
        add("review", f"{plural(names, 'output')} written under two SIGNAL names", "outputs")
    if unit.get("programs_left_out"):
        add("review", f"{unit['programs_left_out']} entry points not run (MAX_AUDIT_ENTRIES)", "entries")
    if not entries and not unit.get("error") and not unit.get("programs_left_out"):
        add("review", f"no entry point: none of its {plural(unit.get('files', 0), 'file')} holds a program (a "
                      "module whose first routine is a DEF without parameters), so none of it ran", "entries")
    status = next((s for s in STATUSES if any(r["level"] == s for r in reasons)), "ok")
    return status, reasons


def report_data(folders: list[str], units: list, checked: list[dict], runs: list[list[dict]], settings: dict) -> dict:
    """The report (docs/schemas/audit.schema.json) from the units (audit.fleet.Unit), their
    static half (audit.fleet.check_unit, or ``{"error"}``) and their run rows, in order."""
    out_units = []
    for u, c, rows in zip(units, checked, runs):
        progs = [dict(p, selects=c.get("cell_selects", [])) for p in c.get("programs", [])]
        entries = [_entry(r, p, u.root) for r, p in zip(rows, progs)]
        machine = c.get("machine") or {"robot": "", "mada": "", "kss": "", "controller": ""}
        robot = machine["robot"]
        unit = {
            "name": u.name, "title": f"{u.name} ({robot})" if robot else u.name,
            "root": u.shown(u.root), "kind": "backup" if u.backup else "folder",
            "error": c.get("error"), "files": c.get("files", 0), "errors": c.get("errors", 0),
            "warnings": c.get("warnings", 0), "codes": c.get("codes", {}), "findings": c.get("findings", []),
            "finding_groups": finding_groups(c.get("findings", [])),
            "findings_left_out": c.get("findings_left_out", 0),
            "robot": robot, "machine": machine,
            "entries": entries, "causes": causes_of(entries), "motion_causes": motion_causes(entries),
            "programs_left_out": c.get("programs_left_out", 0),
            "handlers": [{"program": rel_path(h["path"], u.root), "why": h["why"]} for h in c.get("handlers", [])],
            "outputs": c.get("outputs", {"writes": 0, "computed": 0, "plc_map": 0, "overlaps": []}),
        }
        cell = next((e for e in entries if e["kind"] == "cell"), None)
        unit["cell"] = None if cell is None else {"program": cell["program"], "cause": cell["cause"],
                                                  "cycle": cell["cycle"], "selects": c.get("cell_selects", []),
                                                  "requests": cell["requests"], "motions": cell["motions"]}
        causes = [e["cause"] for e in entries]
        unit["tally"] = {
            "entry_points": len(entries),
            "completed_or_intended": causes.count("completed") + causes.count("intended end"),
            "program_errors": causes.count("program error"),
            "limit_or_gap": causes.count("limit") + causes.count("interpreter gap"),
            "motion_errors": sum(sum(e["event_counts"].values()) for e in entries),
            "cell_cycle": cell["cycle"]["mean"] if cell is not None and cell["cycle"] else None,
            "overlaps": len(unit["outputs"]["overlaps"]),
        }
        unit["status"], unit["reasons"] = health(unit)
        unit["logbook"] = unit_logbook(u.root)
        out_units.append(unit)
    causes: dict[str, int] = {}
    for u in out_units:
        for e in u["entries"]:
            causes[e["cause"]] = causes.get(e["cause"], 0) + 1
    summary = {
        "backups": sum(u["kind"] == "backup" for u in out_units),
        "folders": sum(u["kind"] == "folder" for u in out_units),
        "entry_points": sum(len(u["entries"]) for u in out_units),
        "causes": causes,
        "status": {s: sum(u["status"] == s for u in out_units) for s in STATUSES},
        "check_errors": sum(u["errors"] for u in out_units),
        "motion_errors": sum(sum(e["event_counts"].values()) for u in out_units for e in u["entries"]),
        "overlaps": sum(len(u["outputs"]["overlaps"]) for u in out_units),
        "logbook": fleet_logbook(out_units),
    }
    return {"format": AUDIT_FORMAT, "tool": f"krl-tools {__version__}",
            "generated": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC"),
            "folders": [str(f) for f in folders], "settings": settings, "summary": summary, "units": out_units}


#: the sites listed per cause (all are counted)
MAX_SITES = 50


def causes_of(entries: list[dict]) -> list[dict]:
    """The entry points of a unit by cause (issue 63): those that end alike are one row
    ``{cause, reason, ending, text, file, line, count, programs}``, the commonest first. A
    program error, a limit or a gap is the same cause when its message and its file:line are
    (39 programs stopped by one line of a shared routine: one row, 39 sites); a completed run
    or an intended end is one cause whatever its line."""
    rows: dict[tuple, dict] = {}
    for e in entries:
        own = e["cause"] in ("completed", "intended end")
        key = (e["cause"], e["reason"]) if own else (e["cause"], e["reason"], e["text"], e["file"], e["line"])
        r = rows.get(key)
        if r is None:
            r = rows[key] = {"cause": e["cause"], "reason": e["reason"], "ending": e["ending"],
                             "text": "" if own else e["text"], "file": None if own else e["file"],
                             "line": None if own else e["line"], "count": 0, "programs": []}
        r["count"] += 1
        if len(r["programs"]) < MAX_SITES:
            r["programs"].append(e["program"])
    order = {c: i for i, c in enumerate(("program error", "interpreter gap", "limit", "intended end", "completed"))}
    return sorted(rows.values(), key=lambda r: (order.get(r["cause"], 9), -r["count"]))


def motion_causes(entries: list[dict]) -> list[dict]:
    """The motion errors of a unit's runs by cause: one row per kind, message and motion
    (file:line) ``{kind, text, file, line, count, programs}``, the commonest first."""
    rows: dict[tuple, dict] = {}
    for e in entries:
        for x in e["events"]:
            key = (x.get("kind"), x.get("text"), x.get("file"), x.get("line"))
            r = rows.setdefault(key, {"kind": x.get("kind") or "", "text": x.get("text") or "", "file": x.get("file"),
                                      "line": x.get("line"), "count": 0, "programs": []})
            r["count"] += 1
            if e["program"] not in r["programs"] and len(r["programs"]) < MAX_SITES:
                r["programs"].append(e["program"])
    return sorted(rows.values(), key=lambda r: -r["count"])


def finding_groups(findings: list[dict]) -> list[dict]:
    """The check findings listed by cause: one row per code and message ``{code, severity,
    message, count, sites: [{file, line, column}]}``, errors first, then the commonest."""
    rows: dict[tuple, dict] = {}
    for f in findings:
        r = rows.setdefault((f["code"], f["message"]), {"code": f["code"], "severity": f["severity"],
                                                        "message": f["message"], "count": 0, "sites": []})
        r["count"] += 1
        if len(r["sites"]) < MAX_SITES:
            r["sites"].append({"file": f["file"], "line": f["line"], "column": f["column"]})
    return sorted(rows.values(), key=lambda r: (r["severity"] != "error", -r["count"], r["code"]))


class _Evidence:
    """The evidence list of the page: one item per (file, line) of a unit, with its source lines
    (within MAX_AUDIT_EVIDENCE_CHARS in all) and its ``file:`` link."""

    def __init__(self) -> None:
        self.items: list[dict] = []
        self._ids: dict[tuple, str] = {}
        self._texts: dict[str, list[str]] = {}
        self.budget = MAX_AUDIT_EVIDENCE_CHARS

    def _lines(self, path: Path) -> list[str]:
        key = str(path)
        if key not in self._texts:

            src = read_source(path, follow_symlinks=False) if path.is_file() else None
            self._texts[key] = (src.text or "").splitlines() if src is not None else []
        return self._texts[key]

    def ref(self, root: str, file: str | None, line: int | None) -> str:
        """The id of the evidence of `file`:`line` (a path relative to the unit's `root`, or
        absolute), added on first use; "" for no place."""
        if not file:
            return ""
        line = int(line or 1)
        key = (root, file, line)
        if key in self._ids:
            return self._ids[key]
        path = Path(file) if Path(file).is_absolute() else Path(root) / file
        lines = self._lines(path)
        first = max(1, line - CONTEXT_LINES)
        shown = [(n, lines[n - 1][:MAX_EVIDENCE_LINE]) for n in range(first, min(len(lines), line + CONTEXT_LINES) + 1)]
        cost = sum(len(t) + 8 for _n, t in shown)
        if cost > self.budget:
            shown = []
        self.budget -= cost if shown else 0
        ident = f"ev{len(self.items) + 1}"
        href = path.absolute().as_uri() if path.is_file() else ""
        self.items.append({"id": ident, "file": file, "line": line, "lines": shown, "href": href})
        self._ids[key] = ident
        return ident


def to_html(data: dict) -> str:
    """The report's page (module docstring) from :func:`report_data`'s data."""

    ev = _Evidence()
    return render_html("audit", "audit.html.j2", data=data, ev=ev, statuses=STATUSES)


def write_report(data: dict, out: str | Path) -> tuple[Path, Path]:
    """Write ``audit.json`` and ``audit.html`` into the folder `out` (created), each through
    a temporary file renamed over the old one (krl/durable.py write_text); returns their paths."""

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    j, h = out / "audit.json", out / "audit.html"
    write_text(j, json.dumps(data, indent=1, ensure_ascii=False) + "\n")
    write_text(h, to_html(data))
    return j, h
