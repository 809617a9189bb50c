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
import sys
from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import quote

from jinja2 import Environment, PackageLoader

from krl.durable import TempFolder, replace_folder
from krl.render import markdown_code as md_code, render_html
from recovery.cluster import Cluster, ClusterBuilder, clusters_of_file
from recovery.scan import FileResult
import matplotlib
import matplotlib.pyplot as plt
from matplotlib.ticker import MaxNLocator
from krl.syntax.messages import expected_phrase

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
                      [i for i in r.issues if i.kind != "internal"], r.detail)


class SummaryBuilder:
    """The figures and clusters of a scan, built one row at a time in any order (each row with
    its index in the corpus walk; see :class:`recovery.cluster.ClusterBuilder`). Keeps counts,
    clusters and the few rows a report lists (files not parsed, internal failures), never the
    issues of every file."""

    def __init__(self, known_invalid: Collection[str] = ()) -> None:
        self.known = set(known_invalid)
        self.statuses: dict[str, int] = {}
        self.files = self.files_ok = self.bytes = self.bytes_ok = 0
        self.missing = ClusterBuilder()
        self.known_builder = ClusterBuilder()
        self._internal: list[tuple[int, dict]] = []
        self._bad_input: list[tuple[int, FileResult]] = []
        self.known_ok: dict[str, bool] = {}         # known-invalid path -> parses
        self.fingerprints: list[str] = []          # "path:sha" of every row (the static check's cache key)

    def add(self, index: int, r: FileResult) -> None:
        self.statuses[r.status] = self.statuses.get(r.status, 0) + 1
        self.files += 1
        self.bytes += r.bytes
        if r.ok:
            self.files_ok += 1
            self.bytes_ok += r.bytes
        self.fingerprints.append(f"{r.path}:{r.sha}")
        for i in r.issues:
            if i.kind == "internal":
                self._internal.append((index, {"path": r.path, "line": i.line, "message": i.message}))
        if r.status not in ("ok", "syntax_error"):
            self._bad_input.append((index, _without_internal(r)))
        clean = _without_internal(r)
        if r.path in self.known:
            self.known_ok[r.path] = r.ok
            self.known_builder.add(index, clean)
        else:
            self.missing.add(index, clean)

    @property
    def bad_input(self) -> list[FileResult]:
        """Rows of files not parsed (status other than ok and syntax_error), in walk order."""
        return [r for _, r in sorted(self._bad_input, key=lambda item: item[0])]

    def summary(self, gsha: str, corpus: str, seconds: float) -> "Summary":
        return Summary(grammar_sha=gsha, corpus=corpus, files=self.files, files_ok=self.files_ok,
                       bytes=self.bytes, bytes_ok=self.bytes_ok, seconds=seconds,
                       clusters=self.missing.clusters(), statuses=dict(sorted(self.statuses.items())),
                       known_invalid_clusters=self.known_builder.clusters(),
                       internal_failures=[d for _, d in sorted(self._internal, key=lambda item: item[0])])


def summarise(results: list[FileResult], gsha: str, corpus: str, seconds: float,
              known_invalid: Collection[str] = ()) -> Summary:
    """Figures and clusters of one scan (results in walk order). `known_invalid`: paths (as in
    the results) of files listed in ``corpus/known-invalid.csv``; their clusters are kept apart
    from the ranked missing constructs, and issues of kind ``internal`` form no cluster at all."""
    builder = SummaryBuilder(known_invalid)
    for index, r in enumerate(results):
        builder.add(index, r)
    return builder.summary(gsha, corpus, seconds)


_FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(value: object) -> object:
    """A CSV cell that a spreadsheet cannot take for a formula (the OWASP rule for CSV
    injection): a text starting with ``= + - @``, TAB or CR gets a leading apostrophe.
    Numbers are left as they are. ``csv_cell("=1+1") == "'=1+1"``."""
    if isinstance(value, str) and value.startswith(_FORMULA_START):
        return "'" + value
    return value


def _writerow(w, cells) -> None:
    w.writerow([csv_cell(c) for c in cells])


FILES_CSV_HEADER = ["path", "bytes", "encoding", "status", "ok", "line", "column", "clusters", "detail"]


def files_csv_row(r: FileResult) -> list:
    """The files.csv cells of one row (before :func:`csv_cell`)."""
    first = next((i for i in r.issues if not i.cascade), None)
    return [r.path, r.bytes, r.encoding, r.status, int(r.ok), first.line if first else "",
            first.column + 1 if first else "", " ".join(clusters_of_file(r)), r.detail]


def write_clusters_csv(path: Path, clusters: list[Cluster], known_invalid: list[Cluster] = ()) -> None:
    """One row per cluster: the ranked missing constructs (``group`` missing, ranked 1..n),
    then the clusters of known-invalid files (``group`` known_invalid, no rank). Every text
    cell through :func:`csv_cell`."""
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["rank", "id", "files", "occurrences", "leading_keyword", "signature",
                    "expected", "example_path", "example_line", "example_text", "group", "line_shape"])
        rows = [(rank, c, "missing") for rank, c in enumerate(clusters, 1)]
        rows += [("", c, "known_invalid") for c in known_invalid]
        for rank, c, group in rows:
            ex = c.examples[0] if c.examples else {"path": "", "line": "", "text": ""}
            _writerow(w, [rank, c.id, c.files, c.occurrences, c.leading_keyword, c.signature,
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

    matplotlib.use("Agg")

    top = clusters[:TOP_CHART]
    fig, ax = plt.subplots(figsize=(11, 0.42 * len(top) + 1.4))
    ax.barh(range(len(top)), [c.files for c in top], color="#4a7ab5", height=0.7)
    ax.set_yticks(range(len(top)), [chart_label(c) for c in top], fontsize=9, family="monospace")
    ax.set_ylim(len(top) - 0.5, -0.5)
    for i, c in enumerate(top):
        ax.annotate(str(c.files), (c.files, i), xytext=(3, 0), textcoords="offset points",
                    va="center", fontsize=8)

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

    return expected_phrase(list(expected)).replace("`", "")


REPORT_FILES = frozenset({"summary.json", "files.csv", "clusters.csv", "clusters.png", "report.md",
                          "report.html", ".krl-report"})


class ReportError(Exception):
    """The report folder cannot be replaced (it holds files that are not a report)."""


def _replaceable(out: Path) -> bool:
    """True when `out` may be replaced as a whole: missing, empty, or a report folder (it holds
    the marker ``.krl-report`` or only report files)."""
    if not out.exists() and not out.is_symlink():
        return True
    if out.is_symlink() or not out.is_dir():
        return False
    names = {p.name for p in out.iterdir()}
    return ".krl-report" in names or names <= REPORT_FILES


def _new_report_folder(out: Path) -> TempFolder:
    """A locked temporary folder next to `out` (krl/durable.py ``TempFolder``; the stale ones
    of killed runs removed first), after checking that `out` may be replaced."""
    if not _replaceable(out):
        raise ReportError(f"{out} holds files that are not a recovery report; choose an empty or "
                          "new folder for --out")
    return TempFolder(out)


def _put_in_place(tmp: Path, out: Path) -> None:
    """Replace the folder `out` by the finished folder `tmp`, durably (krl/durable.py
    ``replace_folder``: every file fsynced, one atomic exchange where the system has it, the
    parent folder fsynced): a reader sees the old report or the new one, never none."""
    (tmp / ".krl-report").write_text("a krl recover report; replaced as a whole by the next run\n")
    replace_folder(tmp, out)


def write_report(out: Path, summary: Summary, results: list[FileResult]) -> None:
    """Write every report file into the folder `out`, atomically: everything is rendered into a
    temporary folder next to `out`, which then replaces `out` by renames. A failure while
    rendering leaves the previous report untouched (and no temporary folder). Raises
    :class:`ReportError` when `out` exists and holds files that are not a report (nothing is
    written or removed then)."""
    with ReportStream(Path(out)) as stream:     # the one writer of files.csv
        for index, r in enumerate(results):
            stream.add(index, r)
        stream.commit(summary, [r for r in results if r.status not in ("ok", "syntax_error")])


class ReportStream:
    """A report written while the scan runs (``krl recover``): :meth:`add` writes each row of
    ``files.csv`` as its file finishes (rows arrive in any order with their walk index; they
    are written in walk order, the ones that arrive early held as CSV text until their turn),
    :meth:`commit` renders the rest and puts the folder in place atomically, like
    :func:`write_report`. Used as a context manager: an exception leaves the previous report
    untouched and removes the temporary folder."""

    def __init__(self, out: Path):
        """files.csv: one row per corpus entry; ``encoding`` is the decoding used
        (krl/source.py), ``detail`` says why a file was not parsed; every text cell
        through :func:`csv_cell`."""
        self.out = Path(out)
        self._folder = _new_report_folder(self.out)
        self.tmp = self._folder.path
        self._fh = (self.tmp / "files.csv").open("w", newline="", encoding="utf-8")
        self._csv = csv.writer(self._fh)
        self._csv.writerow(FILES_CSV_HEADER)
        self._held: dict[int, list] = {}
        self._next = 0

    def add(self, index: int, r: FileResult) -> None:
        self._held[index] = [csv_cell(c) for c in files_csv_row(r)]
        while self._next in self._held:
            self._csv.writerow(self._held.pop(self._next))
            self._next += 1

    def commit(self, summary: Summary, bad_input: list[FileResult]) -> None:
        for index in sorted(self._held):      # entries never reported (none in a whole scan)
            self._csv.writerow(self._held.pop(index))
        self._fh.close()
        render_report(self.tmp, summary, bad_input, link_from=self.out)
        _put_in_place(self.tmp, self.out)
        self._folder.close()

    def __enter__(self) -> "ReportStream":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is not None:
            self._fh.close()
            self._folder.close(remove=True)


def render_report(out: Path, summary: Summary, bad_input: list[FileResult], link_from: Path | None = None) -> None:
    """Render the report files other than files.csv into the existing folder `out`; links to
    corpus files are relative to `link_from` (default `out`), the folder the report will be
    read from. `bad_input`: the rows of files not parsed, listed in report.md/.html."""
    link_from = link_from or out
    (out / "summary.json").write_text(json.dumps(summary.to_json(), indent=1) + "\n", encoding="utf-8")
    write_clusters_csv(out / "clusters.csv", summary.clusters, summary.known_invalid_clusters)
    chart = write_chart(out / "clusters.png", summary.clusters)
    links = {}
    # a corpus read from an archive has no files left to link to: the examples are plain text
    linkable = not summary.corpus.lower().endswith(".zip")
    for c in summary.clusters[:TOP_REPORT] + summary.known_invalid_clusters:
        for e in c.examples:
            links[e["path"]] = source_link(summary.corpus, e["path"], link_from) if linkable else ""
    for f in summary.internal_failures:
        links[f["path"]] = source_link(summary.corpus, f["path"], link_from) if linkable else ""
    context = {"s": summary, "clusters": summary.clusters[:TOP_REPORT],
               "known_clusters": summary.known_invalid_clusters,
               "internal": summary.internal_failures, "chart": chart, "links": links,
               "expected_words": _expected_words,
               "more": max(0, len(summary.clusters) - TOP_REPORT),
               "pct": (100.0 * summary.files_ok / summary.files) if summary.files else 0.0,
               "bytes_pct": (100.0 * summary.bytes_ok / summary.bytes) if summary.bytes else 0.0,
               "bad_input": bad_input}
    (out / "report.md").write_text(_markdown_env().get_template("report.md.j2").render(**context),
                                   encoding="utf-8")
    (out / "report.html").write_text(render_html("recovery", "recovery.html.j2", **context), encoding="utf-8")
