"""SARIF 2.1.0 output of diagnostics (`krl parse --format sarif`, `krl check --format sarif`).

One run of the tool ``krl`` with one rule per code that occurs (id, short description, default
level, help text naming its section of docs/diagnostics.md) and one result per diagnostic: ruleId, level, message,
and a physical location whose region has 1-based startLine/startColumn/endLine/endColumn
(columns count Unicode code points: ``columnKind: unicodeCodePoints``). Notes become
relatedLocations. Reference: OASIS SARIF 2.1.0, sections 3.11 (message), 3.27 (result),
3.30 (region), 3.49 (reportingDescriptor).
"""

from __future__ import annotations

from pathlib import Path, PurePath
from urllib.parse import quote

from krl import __version__
from krl.diagnostics import CODES, Diagnostic

SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
DOCS = "docs/diagnostics.md"


def artifact_uri(path: str) -> str:
    """A relative path as a relative URI reference (forward slashes, percent-encoded); an
    absolute one as a file: URI."""
    p = PurePath(path)
    if p.is_absolute():
        return Path(path).as_uri()
    return quote(p.as_posix(), safe="/")


def _location(path: str, line: int, column: int, end_line: int, end_column: int, message: str = "") -> dict:
    loc: dict = {"physicalLocation": {
        "artifactLocation": {"uri": artifact_uri(path)},
        "region": {"startLine": max(line, 1), "startColumn": max(column, 1),
                   "endLine": max(end_line, line, 1), "endColumn": max(end_column, 1)}}}
    if message:
        loc["message"] = {"text": message}
    return loc


def to_sarif(diags: list[Diagnostic]) -> dict:
    """The SARIF 2.1.0 log (a JSON-ready dict) of `diags`."""
    codes = sorted({d.code for d in diags})
    index = {c: i for i, c in enumerate(codes)}
    rules = []
    for c in codes:
        sev, kind = CODES.get(c, ("error" if c.startswith("E") else "warning", c))
        rules.append({"id": c, "name": c, "shortDescription": {"text": kind},
                      "help": {"text": f"{c}: {kind}; see {DOCS}, section {c}"},
                      "defaultConfiguration": {"level": "error" if sev == "error" else "warning"}})
    results = []
    for d in diags:
        end_line, end_column = d.span_end
        r = {"ruleId": d.code, "ruleIndex": index[d.code],
             "level": "error" if d.is_error else "warning",
             "message": {"text": d.message + (f" (help: {d.help})" if d.help else "")},
             "locations": [_location(d.path, d.line, d.column, end_line, end_column)]}
        if d.notes:
            r["relatedLocations"] = [dict(_location(n.path, n.line, n.column, n.line, n.column + 1, n.message), id=i)
                                     for i, n in enumerate(d.notes)]
        results.append(r)
    return {"$schema": SCHEMA, "version": "2.1.0", "runs": [{
        "tool": {"driver": {"name": "krl", "version": __version__, "rules": rules}},
        "columnKind": "unicodeCodePoints",
        "results": results}]}
