"""The front end's corpus report: `krl check` over every KRC backup of a corpus.

:func:`check_report` finds the backups below a folder (:func:`krl.workspace.find_backups`),
checks each as one workspace and returns the result as JSON-ready data and markdown:
per backup the number of files, files that check clean (no error), errors and warnings,
parse and check time; overall the most common diagnostic kinds. The recovery report
includes it.
"""

from __future__ import annotations

import gc
import json
from collections import Counter
from pathlib import Path
import csv
import ctypes
import sys

from krl.diagnostics import CODES
from krl.durable import write_text
from krl.project import collect_entries, find_backups
from krl.terminal import printable
from krl.workspace import load_workspace, load_workspaces


def check_report(corpus: str | Path, out_dir: str | Path | None = None, top: int = 15,
                 timeout: float | None = None, jobs: int | None = None) -> tuple[dict, str]:
    """Check every backup below `corpus`; returns (data, markdown). With `out_dir`, also
    writes check_report.json and check_report.md there. `timeout`, `jobs`: files are parsed
    in that many worker processes, each file stopped past `timeout` seconds (see
    krl.workspace.load_workspace; None: in this process). Never raises for bad input files."""

    corpus = Path(corpus)
    backups = find_backups(corpus) if corpus.exists() else []
    rows = []
    kinds: Counter = Counter()
    for b, ws in _loaded_backups(backups, timeout, jobs):
        diags = ws.check(resolve=False)
        err_files = {d.path for d in diags if d.is_error}
        codes = Counter(d.code for d in diags)
        kinds.update(codes)
        rows.append({
            "backup": str(b.relative_to(corpus)) if b != corpus else b.name,
            "files": len(ws.files),
            "files_parsed": sum(f.ok for f in ws.files),
            "files_clean": sum(1 for f in ws.files if f.path not in err_files),
            "errors": sum(d.is_error for d in diags),
            "warnings": sum(not d.is_error for d in diags),
            "parse_seconds": round(ws.parse_seconds, 3),
            "check_seconds": round(ws.check_seconds, 3),
            "codes": dict(codes.most_common()),
        })
        ws = diags = None    # not held while the next batch loads
    total = {k: sum(r[k] for r in rows) for k in
             ("files", "files_parsed", "files_clean", "errors", "warnings")}
    total["parse_seconds"] = round(sum(r["parse_seconds"] for r in rows), 3)
    total["check_seconds"] = round(sum(r["check_seconds"] for r in rows), 3)
    top_kinds = [{"code": c, "severity": CODES.get(c, ("?", c))[0], "kind": CODES.get(c, ("", c))[1],
                  "count": n} for c, n in kinds.most_common(top)]
    data = {"corpus": str(corpus), "backups": rows, "total": total, "top_kinds": top_kinds}
    md = render_markdown(data)
    if out_dir is not None:

        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        write_text(out / "check_report.json", json.dumps(data, indent=2))
        write_text(out / "check_report.md", md)
    return data, md


# Backups are loaded in batches of about this many bytes of KRL (and one more backup): one pool of workers (and the
# Java engine) for many small backups, while memory holds one batch of ASTs at a time.
BATCH_BYTES = 512 * 1024


def _loaded_backups(backups: list[Path], timeout: float | None, jobs: int | None):
    """(backup, its loaded Workspace) for each backup, in order, loaded in batches."""

    batch: list[tuple[Path, list]] = []
    size = 0
    for k, b in enumerate(backups):
        entries = collect_entries(b)
        batch.append((b, entries))
        size += sum(e.size for e in entries if e.kind == "file")
        if size >= BATCH_BYTES or k == len(backups) - 1:
            spaces = load_workspaces([(str(bb), ee) for bb, ee in batch], timeout=timeout, jobs=jobs)
            for (bb, _), ws in zip(batch, spaces):
                yield bb, ws
            batch, size, spaces, ws = [], 0, None, None
            # the batch's ASTs and scopes hold reference cycles: free them before the next batch
            # is loaded, so that memory holds one batch, not two
            gc.collect()
            _trim()


def _trim() -> None:
    """Give the C heap's free pages back to the system (glibc ``malloc_trim``; elsewhere
    nothing): the results of a batch are unpickled on a thread of the worker pool, whose malloc
    arena otherwise keeps the memory of the largest batch for every later one."""
    global _MALLOC_TRIM
    if _MALLOC_TRIM is None:
        try:

            _MALLOC_TRIM = ctypes.CDLL("libc.so.6").malloc_trim
        except (OSError, AttributeError):
            _MALLOC_TRIM = False
    if _MALLOC_TRIM:
        _MALLOC_TRIM(0)


_MALLOC_TRIM = None


def render_markdown(data: dict) -> str:
    t = data["total"]
    lines = ["## Front end: `krl check` over the KRC backups", ""]
    if not data["backups"]:
        return "\n".join(lines + ["No KRC backups found.", ""])
    lines += [f"{t['files_clean']} of {t['files']} files check clean (no error); "
              f"{t['errors']} errors, {t['warnings']} warnings. "
              f"Parsing took {t['parse_seconds']:.2f} s, AST building and checking {t['check_seconds']:.2f} s.", "",
              "| backup | files | parsed | clean | errors | warnings | parse s | check s |",
              "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in data["backups"]:
        lines.append(f"| {r['backup']} | {r['files']} | {r['files_parsed']} | {r['files_clean']} | "
                     f"{r['errors']} | {r['warnings']} | {r['parse_seconds']:.2f} | {r['check_seconds']:.2f} |")
    lines += ["", "Most common diagnostic kinds:", "", "| code | severity | kind | count |", "|---|---|---|---:|"]
    for k in data["top_kinds"]:
        lines.append(f"| {k['code']} | {k['severity']} | {k['kind']} | {k['count']} |")
    return "\n".join(lines) + "\n"


def known_invalid(repo_root: str | Path | None = None) -> set[str]:
    """Corpus-relative paths listed in corpus/known-invalid.csv (files that are not valid KRL)."""
    root = Path(repo_root) if repo_root is not None else Path(__file__).resolve().parents[2]
    try:
        with open(root / "corpus" / "known-invalid.csv", encoding="utf-8") as fh:
            return {row["path"] for row in csv.DictReader(fh)}
    except OSError:
        return set()


def measure(corpus: str | Path) -> dict:
    """`krl check` over every KRC backup below `corpus`, split by file validity: errors and
    warnings by code on files that are not in corpus/known-invalid.csv ("valid") and on the
    listed ones ("known_invalid"), and the error lines on valid files (path:line CODE message,
    paths relative to `corpus`). The figure of issue 14; reproducible with
    ``python -m krl.survey.report ../shared/krl-corpus``."""

    corpus = Path(corpus).resolve()
    invalid = known_invalid()
    out = {"backups": 0, "valid": {"errors": Counter(), "warnings": Counter()},
           "known_invalid": {"errors": Counter(), "warnings": Counter()}, "valid_errors": []}
    for b in find_backups(corpus):
        out["backups"] += 1
        for d in load_workspace([b], str(b)).check(resolve=False):
            try:
                rel = Path(d.path).resolve().relative_to(corpus).as_posix()
            except ValueError:
                rel = d.path
            part = out["known_invalid" if rel in invalid else "valid"]
            part["errors" if d.is_error else "warnings"][d.code] += 1
            if d.is_error and rel not in invalid:
                out["valid_errors"].append(f"{rel}:{d.line} {d.code} {d.message}")
    return out


def main(argv: list[str]) -> int:
    if len(argv) != 1 or not Path(argv[0]).is_dir():
        print("usage: python -m krl.survey.report CORPUS_FOLDER", file=sys.stderr)
        return 2
    m = measure(argv[0])
    print(f"{m['backups']} KRC backups")
    for part in ("valid", "known_invalid"):
        for sev in ("errors", "warnings"):
            c = m[part][sev]
            codes = ", ".join(f"{k} {v}" for k, v in sorted(c.items()))
            print(f"{part} files: {sum(c.values())} {sev}" + (f" ({codes})" if codes else ""))
    for line in m["valid_errors"]:
        print("  " + printable(line))
    return 0


if __name__ == "__main__":  # pragma: no cover
    import sys
    sys.exit(main(sys.argv[1:]))
