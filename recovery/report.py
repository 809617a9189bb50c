"""Writing the recovery report: summary.json, files.csv, clusters.csv, report.md/.html, a chart.

The report separates what a grammar author should add next from what needs no grammar work:

* **missing constructs, ranked**: clusters of the syntax errors of files that should parse;
* **known-invalid files** (``corpus/known-invalid.csv``): clusters of files that are not KRL
  and must keep failing, shown apart and never ranked;
* **internal failures**: files where the parser itself failed (issue kind ``internal``), listed
  by file, never clustered.

When no ranked cluster remains, the report says so: "every valid file parses". report.html is
rendered by the project's one HTML environment (``krl/render.py``, autoescape on; the Markdown
of the static-check section through markdown-it-py with raw HTML off).
"""

from __future__ import annotations

import csv
import json
import os
from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import quote

from jinja2 import Environment, PackageLoader

from krl.render import markdown_code as md_code
from recovery.cluster import Cluster, cluster_results, clusters_of_file
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
    clusters: list[Cluster]           # missing constructs: files that should parse, ranked
    statuses: dict[str, int] = field(default_factory=dict)
    negative: dict | None = None      # {"programs": Y, "rejected": X, "accepted": [paths]}
    extra: dict = field(default_factory=dict)
    known_invalid_clusters: list[Cluster] = field(default_factory=list)
    internal_failures: list[dict] = field(default_factory=list)   # {"path", "line", "message"}

    def to_json(self) -> dict:
        obj = {"grammar_sha": self.grammar_sha, "corpus": self.corpus, "files": self.files,
               "files_ok": self.files_ok, "bytes": self.bytes, "bytes_ok": self.bytes_ok,
               "seconds": round(self.seconds, 3), "statuses": self.statuses,
               "clusters": [c.to_json() for c in self.clusters],
               "known_invalid_clusters": [c.to_json() for c in self.known_invalid_clusters],
               "internal_failures": self.internal_failures}
        if self.negative is not None:
            obj["negative"] = self.negative
        obj.update(self.extra)
        return obj


def _without_internal(r: FileResult) -> FileResult:
    return FileResult(r.path, r.bytes, r.sha, r.encoding, r.status, r.ok, r.seconds,
                      [i for i in r.issues if i.kind != "internal"])


def summarise(results: list[FileResult], gsha: str, corpus: str, seconds: float,
              known_invalid: Collection[str] = ()) -> Summary:
    """Figures and clusters of one scan. `known_invalid`: paths (as in the results) of files
    listed in ``corpus/known-invalid.csv``; their clusters are kept apart from the ranked
    missing constructs, and issues of kind ``internal`` form no cluster at all."""
    statuses: dict[str, int] = {}
    for r in results:
        statuses[r.status] = statuses.get(r.status, 0) + 1
    known = set(known_invalid)
    internal = [{"path": r.path, "line": i.line, "message": i.message}
                for r in results for i in r.issues if i.kind == "internal"]
    clean = [_without_internal(r) for r in results]
    return Summary(grammar_sha=gsha, corpus=corpus, files=len(results),
                   files_ok=sum(r.ok for r in results), bytes=sum(r.bytes for r in results),
                   bytes_ok=sum(r.bytes for r in results if r.ok), seconds=seconds,
                   clusters=cluster_results([r for r in clean if r.path not in known]),
                   statuses=dict(sorted(statuses.items())),
                   known_invalid_clusters=cluster_results([r for r in clean if r.path in known]),
                   internal_failures=internal)


def write_files_csv(path: Path, results: list[FileResult]) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["path", "bytes", "encoding", "status", "ok", "line", "column", "clusters"])
        for r in results:
            first = next((i for i in r.issues if not i.cascade), None)
            w.writerow([r.path, r.bytes, r.encoding, r.status, int(r.ok),
                        first.line if first else "", first.column + 1 if first else "",
                        " ".join(clusters_of_file(r))])


def write_clusters_csv(path: Path, clusters: list[Cluster], known_invalid: list[Cluster] = ()) -> None:
    """One row per cluster: the ranked missing constructs (``group`` missing, ranked 1..n),
    then the clusters of known-invalid files (``group`` known_invalid, no rank)."""
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["rank", "id", "files", "occurrences", "leading_keyword", "signature",
                    "expected", "example_path", "example_line", "example_text", "group", "line_shape"])
        rows = [(rank, c, "missing") for rank, c in enumerate(clusters, 1)]
        rows += [("", c, "known_invalid") for c in known_invalid]
        for rank, c, group in rows:
            ex = c.examples[0] if c.examples else {"path": "", "line": "", "text": ""}
            w.writerow([rank, c.id, c.files, c.occurrences, c.leading_keyword, c.signature,
                        " ".join(c.expected[:12]), ex["path"], ex["line"], ex["text"], group, c.line_shape])


def chart_label(c: Cluster, width: int = 48) -> str:
    """The y-axis label of a cluster: its leading keyword and line shape, cut to `width`."""
    text = c.keyword if c.is_lexer else f"{c.keyword}: {c.line_shape}"
    return text if len(text) <= width else text[:width - 1] + "…"


def write_chart(path: Path, clusters: list[Cluster]) -> bool:
    """A horizontal bar chart of the top :data:`TOP_CHART` missing constructs (files affected).
    Each bar has its own row of at least 0.42 in, labels in 9 pt: no label overlaps another.
    Returns False (and writes nothing) when there is no cluster."""
    if not clusters:
        return False
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    top = clusters[:TOP_CHART]
    fig, ax = plt.subplots(figsize=(11, 0.42 * len(top) + 1.4))
    ax.barh(range(len(top)), [c.files for c in top], color="#4a7ab5", height=0.7)
    ax.set_yticks(range(len(top)), [chart_label(c) for c in top], fontsize=9, family="monospace")
    ax.set_ylim(len(top) - 0.5, -0.5)
    for i, c in enumerate(top):
        ax.annotate(str(c.files), (c.files, i), xytext=(3, 0), textcoords="offset points",
                    va="center", fontsize=8)
    from matplotlib.ticker import MaxNLocator  # noqa: PLC0415

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("files affected")
    ax.set_title(f"Top {len(top)} missing constructs (files that should parse)")
    ax.margins(x=0.08)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def _markdown_env() -> Environment:
    """report.md only (Markdown, not HTML): text from the corpus goes through the ``code``
    filter, a code span that nothing inside can close."""
    env = Environment(loader=PackageLoader("recovery", "templates"), autoescape=False,
                      trim_blocks=True, lstrip_blocks=True)
    env.filters["code"] = md_code
    return env


def source_link(corpus: str, path: str, out: Path) -> str:
    """A relative URL from the report folder to a corpus file (percent-encoded bytes)."""
    target = os.path.relpath(os.path.abspath(os.path.join(corpus, path)), os.path.abspath(out))
    return quote(os.fsencode(target).replace(os.sep.encode(), b"/"))


def _expected_words(expected: list[str]) -> str:
    """The tokens expected at a cluster's error in KRL words: at most six grouped alternatives
    ("a statement, ELSE, ENDIF or end of line"), as in the compiler-style messages."""
    from krl.syntax.messages import expected_phrase  # noqa: PLC0415

    return expected_phrase(list(expected)).replace("`", "")


def write_report(out: Path, summary: Summary, results: list[FileResult]) -> None:
    """Write every report file into `out` (created if needed)."""
    from krl.render import render_html  # noqa: PLC0415

    out.mkdir(parents=True, exist_ok=True)
    (out / "summary.json").write_text(json.dumps(summary.to_json(), indent=1) + "\n")
    write_files_csv(out / "files.csv", results)
    write_clusters_csv(out / "clusters.csv", summary.clusters, summary.known_invalid_clusters)
    chart = write_chart(out / "clusters.png", summary.clusters)
    if not chart and (out / "clusters.png").exists():
        (out / "clusters.png").unlink()
    links = {}
    # a corpus read from an archive has no files left to link to: the examples are plain text
    linkable = not summary.corpus.lower().endswith(".zip")
    for c in summary.clusters[:TOP_REPORT] + summary.known_invalid_clusters:
        for e in c.examples:
            links[e["path"]] = source_link(summary.corpus, e["path"], out) if linkable else ""
    for f in summary.internal_failures:
        links[f["path"]] = source_link(summary.corpus, f["path"], out) if linkable else ""
    context = {"s": summary, "clusters": summary.clusters[:TOP_REPORT],
               "known_clusters": summary.known_invalid_clusters,
               "internal": summary.internal_failures, "chart": chart, "links": links,
               "expected_words": _expected_words,
               "more": max(0, len(summary.clusters) - TOP_REPORT),
               "pct": (100.0 * summary.files_ok / summary.files) if summary.files else 0.0,
               "bytes_pct": (100.0 * summary.bytes_ok / summary.bytes) if summary.bytes else 0.0,
               "bad_input": [r for r in results if r.status not in ("ok", "syntax_error")]}
    (out / "report.md").write_text(_markdown_env().get_template("report.md.j2").render(**context),
                                   encoding="utf-8")
    (out / "report.html").write_text(render_html("recovery.html.j2", **context), encoding="utf-8")
