"""The recovery job: scan, cluster, measure the negative corpus, write the report."""

from __future__ import annotations

import csv
import time
from pathlib import Path

from recovery.cluster import cluster_results
from recovery.report import Summary, summarise, write_report
from recovery.scan import FileResult, grammar_sha, scan

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


def run_recovery(corpus: Path, out: Path, jobs: int | None = None, use_cache: bool = True) -> Summary:
    start = time.perf_counter()
    gsha = current_grammar_sha()
    results = scan(corpus, gsha, jobs=jobs, use_cache=use_cache)
    clusters = cluster_results(results)
    summary = summarise(results, clusters, gsha, str(corpus), 0.0)
    summary.negative = negative_figures(gsha, jobs, use_cache)
    ki = known_invalid_figures(results)
    if ki:
        summary.extra["known_invalid"] = ki
    summary.seconds = time.perf_counter() - start
    write_report(out, summary, results)
    return summary
