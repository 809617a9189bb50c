"""Writing the recovery report: summary.json, files.csv, clusters.csv, report.md/.html, a chart."""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path

from jinja2 import Environment, PackageLoader, select_autoescape

from recovery.cluster import Cluster, clusters_of_file
from recovery.scan import FileResult

TOP_CHART = 20
TOP_REPORT = 40


@dataclass(slots=True)
class Summary:
    grammar_sha: str
    corpus: str
    files: int
    files_ok: int
    bytes: int
    bytes_ok: int
    seconds: float
    clusters: list[Cluster]
    statuses: dict[str, int] = field(default_factory=dict)
    negative: dict | None = None      # {"programs": Y, "rejected": X, "accepted": [paths]}
    extra: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        obj = {"grammar_sha": self.grammar_sha, "corpus": self.corpus, "files": self.files,
               "files_ok": self.files_ok, "bytes": self.bytes, "bytes_ok": self.bytes_ok,
               "seconds": round(self.seconds, 3), "statuses": self.statuses,
               "clusters": [c.to_json() for c in self.clusters]}
        if self.negative is not None:
            obj["negative"] = self.negative
        obj.update(self.extra)
        return obj


def summarise(results: list[FileResult], clusters: list[Cluster], gsha: str, corpus: str,
              seconds: float) -> Summary:
    statuses: dict[str, int] = {}
    for r in results:
        statuses[r.status] = statuses.get(r.status, 0) + 1
    return Summary(grammar_sha=gsha, corpus=corpus, files=len(results),
                   files_ok=sum(r.ok for r in results), bytes=sum(r.bytes for r in results),
                   bytes_ok=sum(r.bytes for r in results if r.ok), seconds=seconds,
                   clusters=clusters, statuses=dict(sorted(statuses.items())))


def write_files_csv(path: Path, results: list[FileResult]) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["path", "bytes", "encoding", "status", "ok", "line", "column", "clusters"])
        for r in results:
            first = next((i for i in r.issues if not i.cascade), None)
            w.writerow([r.path, r.bytes, r.encoding, r.status, int(r.ok),
                        first.line if first else "", first.column + 1 if first else "",
                        " ".join(clusters_of_file(r))])


def write_clusters_csv(path: Path, clusters: list[Cluster]) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["rank", "id", "files", "occurrences", "leading_keyword", "signature",
                    "expected", "example_path", "example_line", "example_text"])
        for rank, c in enumerate(clusters, 1):
            ex = c.examples[0] if c.examples else {"path": "", "line": "", "text": ""}
            w.writerow([rank, c.id, c.files, c.occurrences, c.leading_keyword, c.signature,
                        " ".join(c.expected[:12]), ex["path"], ex["line"], ex["text"]])


def write_chart(path: Path, clusters: list[Cluster]) -> None:
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    top = clusters[:TOP_CHART]
    fig, ax = plt.subplots(figsize=(10, 0.35 * max(len(top), 3) + 1.2))
    labels = [f"{c.id} {c.leading_keyword}"[:40] for c in top]
    ax.barh(range(len(top)), [c.files for c in top], color="#4a7ab5")
    ax.set_yticks(range(len(top)), labels, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("files affected")
    ax.set_title(f"Top {len(top)} missing constructs")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _env() -> Environment:
    return Environment(loader=PackageLoader("recovery", "templates"),
                       autoescape=select_autoescape(["html"]), trim_blocks=True, lstrip_blocks=True)


def write_report(out: Path, summary: Summary, results: list[FileResult]) -> None:
    """Write every report file into `out` (created if needed)."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "summary.json").write_text(json.dumps(summary.to_json(), indent=1) + "\n")
    write_files_csv(out / "files.csv", results)
    write_clusters_csv(out / "clusters.csv", summary.clusters)
    write_chart(out / "clusters.png", summary.clusters)
    context = {"s": summary, "clusters": summary.clusters[:TOP_REPORT],
               "more": max(0, len(summary.clusters) - TOP_REPORT),
               "pct": (100.0 * summary.files_ok / summary.files) if summary.files else 0.0,
               "bytes_pct": (100.0 * summary.bytes_ok / summary.bytes) if summary.bytes else 0.0,
               "bad_input": [r for r in results if r.status not in ("ok", "syntax_error")]}
    env = _env()
    (out / "report.md").write_text(env.get_template("report.md.j2").render(**context))
    (out / "report.html").write_text(env.get_template("report.html.j2").render(**context))
