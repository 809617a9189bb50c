"""`krl growth`: replay every committed grammar version over a corpus.

Writes growth.csv (one row per version: commit, date, subject, parser_rules, lexer_rules,
alternatives, files_ok, bytes_ok, clusters, files, bytes) and growth.png (files and bytes
parsed against grammar version). Parsers (Python and Java) are generated once per grammar sha,
in parallel; versions are scanned in parallel (--jobs), each with the fast parse engine when it
can run; per-file results are cached by (grammar sha, file sha), so a replay only parses what
changed.
"""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

from krl.durable import write_text, write_with
from recovery.cluster import cluster_results
from recovery.grammar_versions import committed_versions, grammar_metrics, parser_dir_for, python_target
from recovery.progress import steps
from recovery.scan import grammar_sha, scan
from krl.syntax.engines.java import build_many, close_all, java_target
from krl.syntax.engines import resolve
from concurrent.futures import ProcessPoolExecutor
import matplotlib
import matplotlib.pyplot as plt

COLUMNS = ["commit", "date", "subject", "parser_rules", "lexer_rules", "alternatives",
           "files_ok", "bytes_ok", "clusters", "files", "bytes"]


def _summary(results) -> dict:
    return {"files_ok": sum(r.ok for r in results),
            "bytes_ok": sum(r.bytes for r in results if r.ok),
            "clusters": len(cluster_results(results)),
            "files": len(results), "bytes": sum(r.bytes for r in results)}


def _scan_version(args: tuple[str, str, str, bool]) -> dict:
    """Scan the corpus with one grammar version in this process (a pool worker); its Java
    worker (if any) is stopped afterwards, so that versions do not pile up JVMs."""

    corpus, sha, pdir, use_cache = args
    try:
        return _summary(scan(Path(corpus), sha, parser_dir=pdir, jobs=1, use_cache=use_cache,
                             progress=False))
    finally:
        close_all()


def build_parsers(texts: list[str], jobs: int) -> list[Path]:
    """The Python parser directory of each grammar text, and its Java parser when the Java
    engine can run, generated once per sha: all missing ones in `jobs` JVMs (KrlBuild), so the
    JVM start and warm-up are paid once, not per version."""
    tasks = [("python", t, python_target(t)) for t in texts]
    if resolve() == "java":
        tasks += [("java", t, java_target(t)) for t in texts]
        build_many(tasks, jobs)   # a failed build is done again below, one by one, to say why
    return [parser_dir_for(t) for t in texts]


def scan_versions(corpus: Path, texts: list[str], jobs: int | None = None, use_cache: bool = True,
                  labels: list[str] | None = None, progress: bool = True) -> list[dict]:
    """Scan `corpus` with each grammar text, `jobs` versions at a time (one process and one
    parse engine worker each); returns each version's summary (files_ok, bytes_ok, clusters,
    files, bytes), in order. Per-file results land in the result cache (recovery/scan.py)."""

    jobs = jobs or os.cpu_count() or 1
    pdirs = build_parsers(texts, jobs)
    args = [(str(corpus), grammar_sha(t), str(d), use_cache) for t, d in zip(texts, pdirs)]
    labels = labels or [grammar_sha(t)[:10] for t in texts]
    order = list(range(len(texts)))
    shown = (lambda items: steps(items, "replaying grammar versions", lambda i: labels[i])) if progress \
        else (lambda items: items)
    out: list[dict] = []
    if jobs == 1 or len(texts) == 1:
        for i in shown(order):
            out.append(_scan_version(args[i]))
        return out
    with ProcessPoolExecutor(max_workers=min(jobs, len(texts))) as pool:
        ordered = pool.map(_scan_version, args)
        for _ in shown(order):
            out.append(next(ordered))
    return out


def growth_rows(corpus: Path, jobs: int | None = None, use_cache: bool = True,
                progress: bool = True) -> list[dict]:
    """One row per committed grammar version (COLUMNS); versions scanned in parallel."""
    versions = committed_versions()
    summaries = scan_versions(corpus, [v.text for v in versions], jobs, use_cache,
                              [f"{v.commit[:10]} {v.subject[:40]}" for v in versions], progress)
    rows = []
    for version, summary in zip(versions, summaries):
        row = {"commit": version.commit[:10], "date": version.date, "subject": version.subject}
        row.update(grammar_metrics(version.text))
        row.update(summary)
        rows.append(row)
    return rows


def write_growth(out: Path, rows: list[dict]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    text = io.StringIO(newline="")
    w = csv.DictWriter(text, fieldnames=COLUMNS)
    w.writeheader()
    w.writerows(rows)
    write_text(out / "growth.csv", text.getvalue())
    plot_growth(out / "growth.png", rows)


def plot_growth(path: Path, rows: list[dict]) -> None:

    matplotlib.use("Agg")

    xs = list(range(len(rows)))
    files_pct = [100.0 * r["files_ok"] / r["files"] if r["files"] else 0 for r in rows]
    bytes_pct = [100.0 * r["bytes_ok"] / r["bytes"] if r["bytes"] else 0 for r in rows]
    fig, ax = plt.subplots(figsize=(max(7, 0.45 * len(rows) + 3), 5))
    ax.plot(xs, files_pct, marker="o", label="files parsed")
    ax.plot(xs, bytes_pct, marker="s", label="bytes parsed")
    ax.set_ylabel("% of corpus")
    ax.set_ylim(0, 100.5)
    ax.set_xticks(xs, [f"{i}: {r['subject'].removeprefix('grammar: ')[:28]}" for i, r in enumerate(rows)],
                  rotation=60, ha="right", fontsize=7)
    ax.set_xlabel("grammar version (commit)")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right")
    ax.set_title("Grammar growth over the corpus")
    fig.tight_layout()
    write_with(path, lambda fh: fig.savefig(fh, dpi=110, format="png"))
    plt.close(fig)
