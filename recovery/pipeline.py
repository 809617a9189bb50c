"""The recovery job: scan, cluster, measure the negative corpus, write the report."""

from __future__ import annotations

import csv
import hashlib
import json
import time
from pathlib import Path

from recovery.report import Summary, summarise, write_report
from recovery.scan import FileResult, cache_dir, grammar_sha, scan

REPO_ROOT = Path(__file__).resolve().parents[1]
GRAMMAR = REPO_ROOT / "grammar" / "KRL.g4"
NEGATIVE_DIR = REPO_ROOT / "tests" / "negative"
KNOWN_INVALID = REPO_ROOT / "corpus" / "known-invalid.csv"


def current_grammar_sha() -> str:
    return grammar_sha(GRAMMAR.read_text(encoding="utf-8"))


def negative_figures(gsha: str, jobs: int | None, use_cache: bool) -> dict | None:
    """How many programs of tests/negative the grammar rejects (the target is all)."""
    if not NEGATIVE_DIR.is_dir():
        return None
    results = scan(NEGATIVE_DIR, gsha, jobs=jobs, use_cache=use_cache, progress=False)
    accepted = [r.path for r in results if r.ok]
    return {"programs": len(results), "rejected": len(results) - len(accepted), "accepted": accepted}


def load_known_invalid(path: Path = KNOWN_INVALID) -> dict[str, str]:
    """corpus/known-invalid.csv: path (relative to the shared corpus) -> reason."""
    if not path.exists():
        return {}
    with path.open(newline="", encoding="utf-8") as fh:
        return {row["path"]: row["reason"] for row in csv.DictReader(fh) if row.get("path")}


def known_invalid_figures(results: list[FileResult]) -> dict | None:
    known = load_known_invalid()
    present = [r for r in results if r.path in known]
    if not present:
        return None
    return {"listed": len(known), "present": len(present),
            "still_failing": sum(not r.ok for r in present),
            "now_parsing": [r.path for r in present if r.ok]}


def _front_end_code_sha() -> str:
    h = hashlib.sha256()
    for p in sorted((REPO_ROOT / "krl").rglob("*")):
        if p.is_file() and "generated" not in p.parts and p.suffix in (".py", ".yaml"):
            h.update(p.as_posix().encode())
            h.update(p.read_bytes())
    return h.hexdigest()


def static_check_figures(corpus: Path, results: list[FileResult], gsha: str,
                         use_cache: bool) -> dict | None:
    """`krl check` over the KRC backups of the corpus (issue 4's report), cached by the
    grammar, the front end's code and the corpus files."""
    from krl.workspace import find_backups  # noqa: PLC0415

    if not find_backups(corpus):
        return None
    key = hashlib.sha256("|".join([gsha, _front_end_code_sha()] +
                                  sorted(f"{r.path}:{r.sha}" for r in results)).encode()).hexdigest()
    path = cache_dir() / "check" / f"{key[:32]}.json"
    if use_cache and path.exists():
        try:
            return json.loads(path.read_text())
        except ValueError:
            pass
    from krl.semantics.report import check_report  # noqa: PLC0415

    data, markdown = check_report(corpus)
    figures = {"files": data["total"]["files"], "files_clean": data["total"]["files_clean"],
               "errors": data["total"]["errors"], "warnings": data["total"]["warnings"],
               "top_kinds": data["top_kinds"], "markdown": markdown}
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(figures))
    return figures


def run_recovery(corpus: Path, out: Path, jobs: int | None = None, use_cache: bool = True,
                 label: str | None = None) -> Summary:
    """Scan `corpus`, cluster, write the report into `out`. `label`: how the report names the
    corpus when it is not the folder itself (a backup .zip extracted to a temporary folder:
    the report then names the archive and does not link to the vanished files)."""
    start = time.perf_counter()
    gsha = current_grammar_sha()
    results = scan(corpus, gsha, jobs=jobs, use_cache=use_cache)
    summary = summarise(results, gsha, label or str(corpus), 0.0, known_invalid=load_known_invalid())
    summary.negative = negative_figures(gsha, jobs, use_cache)
    ki = known_invalid_figures(results)
    if ki:
        summary.extra["known_invalid"] = ki
    check = static_check_figures(Path(corpus), results, gsha, use_cache)
    if check:
        summary.extra["check"] = check
    summary.seconds = time.perf_counter() - start
    write_report(out, summary, results)
    return summary
