"""The controller logbooks of a fleet (issue 75 item 3): ``krl audit`` groups its units by the
logbook's messages. A unit that is the KRC folder of a controller archive with event logs
(krl/kssarchive.py finds the archive from the unit's root; krl/logbook reads its ``Log Files``)
gets its records by module and message number (:func:`unit_logbook`); the fleet's groups
(:func:`fleet_logbook`) say, for each (module, number), which units logged it, how often, and
when first and last -- the message that stops several cells at night stands out. Read in the
main process (event logs are read in about 0.5 ms a record), after the runs.
"""

from __future__ import annotations

from krl.kssarchive import archive_root
from krl.logbook.record import has_event_logs, log_sources, read_logbook
from krl.logbook.summary import messages

__all__ = ["MAX_AUDIT_LOG_GROUPS", "fleet_logbook", "unit_logbook"]

#: the message groups listed per unit and for the fleet (the rest are counted in ``left_out``)
MAX_AUDIT_LOG_GROUPS = 200


def unit_logbook(root: str) -> dict | None:
    """{records, errors, messages: [{module, number, key, count, first, last}], left_out} of the
    archive holding the unit's `root`; None when it is no archive or has no event log."""
    arch = archive_root(root)
    if arch is None or not has_event_logs(arch):
        return None
    with log_sources(arch) as src:
        if not src.logs:
            return None
        book = read_logbook(src.logs)
    groups = [{"module": g.module, "number": g.number, "key": g.key, "count": g.count,
               "first": g.first.iso_time, "last": g.last.iso_time} for g in messages(book.records)]
    return {"records": len(book.records), "errors": book.errors, "messages": groups[:MAX_AUDIT_LOG_GROUPS],
            "left_out": max(0, len(groups) - MAX_AUDIT_LOG_GROUPS)}


def fleet_logbook(units: list[dict]) -> list[dict]:
    """The fleet's messages: for each (module, number) of the units' logbooks (``unit["logbook"]``),
    {module, number, key, units (names, in the units' order), count (all units), first, last};
    those logged by the most units first, then the most frequent."""
    out: dict[tuple, dict] = {}
    for u in units:
        for m in (u.get("logbook") or {}).get("messages", []):
            g = out.setdefault((m["module"], m["number"]), {"module": m["module"], "number": m["number"],
                                                            "key": m["key"], "units": [], "count": 0,
                                                            "first": m["first"], "last": m["last"]})
            g["units"].append(u["name"])
            g["count"] += m["count"]
            g["first"], g["last"] = min(g["first"], m["first"]), max(g["last"], m["last"])
    ranked = sorted(out.values(), key=lambda g: (-len(g["units"]), -g["count"], g["module"].lower(),
                                                 g["number"] if g["number"] is not None else -1))
    return ranked[:MAX_AUDIT_LOG_GROUPS]
