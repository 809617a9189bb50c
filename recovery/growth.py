"""`krl growth`: replay every committed grammar version over a corpus.

Writes growth.csv (one row per version: commit, date, subject, parser_rules, lexer_rules,
alternatives, files_ok, bytes_ok, clusters, files, bytes) and growth.png (files and bytes
parsed against grammar version). Parsers and per-file results are cached by (grammar sha,
file sha), so a replay only parses what changed.
"""

from __future__ import annotations

import csv
from pathlib import Path

from recovery.cluster import cluster_results
from recovery.grammar_versions import committed_versions, grammar_metrics, parser_dir_for
from recovery.scan import scan

COLUMNS = ["commit", "date", "subject", "parser_rules", "lexer_rules", "alternatives",
           "files_ok", "bytes_ok", "clusters", "files", "bytes"]


def growth_rows(corpus: Path, jobs: int | None = None, use_cache: bool = True,
                progress: bool = True) -> list[dict]:
    from recovery.progress import steps  # noqa: PLC0415

    rows = []
    versions = committed_versions()
    shown = steps(versions, "replaying grammar versions", lambda v: f"{v.commit[:10]} {v.subject[:40]}") \
        if progress else versions
    for version in shown:
        pdir = parser_dir_for(version.text)
        results = scan(corpus, version.sha, parser_dir=str(pdir), jobs=jobs, use_cache=use_cache,
                       progress=False)
        row = {"commit": version.commit[:10], "date": version.date, "subject": version.subject}
        row.update(grammar_metrics(version.text))
        row.update({"files_ok": sum(r.ok for r in results),
                    "bytes_ok": sum(r.bytes for r in results if r.ok),
                    "clusters": len(cluster_results(results)),
                    "files": len(results), "bytes": sum(r.bytes for r in results)})
        rows.append(row)
    return rows


def write_growth(out: Path, rows: list[dict]) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with (out / "growth.csv").open("w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS)
        w.writeheader()
        w.writerows(rows)
    plot_growth(out / "growth.png", rows)


def plot_growth(path: Path, rows: list[dict]) -> None:
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

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
    fig.savefig(path, dpi=110)
    plt.close(fig)
