"""The controller's logbook beside the program (issue 75 item 3): the records of the event logs
of the controller archive the pendant serves, for the page's Logbook tab.

:func:`logbook_view` reads them with krl/logbook (the ``Log Files`` of the archive holding the
workspace, every record in time order, a program module or variable a record names resolved to
its file and line: krl/logbook/links.py) and gives each record the path the page opens it by
(pendant/security.py ``inside``: a file of the workspace, as the ``open`` operation and the
``module`` message spell it) so that stepping through the records moves the program view to the
file and line a record names. At most ``MAX_PENDANT_LOG_RECORDS`` (the newest) are sent.
"""

from __future__ import annotations

from pathlib import Path

from krl.archive import ArchiveError
from krl.limits import MAX_PENDANT_LOG_RECORDS
from krl.logbook.links import link_all
from krl.logbook.record import log_sources, read_logbook

from .security import PathRefused, inside

__all__ = ["logbook_view"]


def _place(root: Path, archive: Path | None, file: str) -> str | None:
    """The workspace path of the archive file `file` (relative to `archive`), or None when it
    is not a KRL file of the workspace."""
    if not file or archive is None:
        return None
    try:
        return str(inside(root, archive / file, suffixes=(".src", ".sub", ".dat")))
    except PathRefused:
        return None


def logbook_view(root: Path) -> dict:
    """``{records, errors, omitted}`` of the workspace `root`'s controller archive: each record
    ``{time (ISO 8601 UTC), module, number, key, params, path (a workspace file or null), line
    (the line a record names, or null: the file's first)}`` in time order; ``errors`` the logs not read
    whole; ``omitted`` the older records left out past ``MAX_PENDANT_LOG_RECORDS``. No archive,
    no logs: no records. Never raises for the logs' content."""
    try:
        with log_sources(root) as src:
            book = read_logbook(src.logs)
            link_all(book.records, src.root)
            archive = src.root
    except (ArchiveError, OSError) as exc:
        return {"records": [], "errors": [str(exc)], "omitted": 0}
    kept = book.records[-MAX_PENDANT_LOG_RECORDS:]
    out = []
    for r in kept:
        path = _place(root, archive, r.file)
        out.append({"time": r.iso_time, "module": r.module, "number": r.number, "key": r.key,
                    "params": list(r.params), "path": path,
                    "line": r.line if path is not None else None})
    return {"records": out, "errors": list(book.errors), "omitted": len(book.records) - len(kept)}
