"""The recovery report (issues 12 and 13): ranked missing constructs apart from known-invalid
files and internal failures, clusters in KRL words, and HTML that runs nothing from the corpus."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

from recovery.report import md_code, summarise, write_report
from recovery.scan import FileResult, IssueRecord

SCRIPT = "<script>alert(1)</script>"


def issue(line: int, shape: list[str], text: str, kind: str = "syntax", rule: str = "statementLine",
          offending_type: str = "'='") -> IssueRecord:
    return IssueRecord(line=line, column=4, kind=kind, message="mismatched input", offending=shape[-1],
                       offending_type=offending_type, expected=["THEN"], rule_stack=["module", rule],
                       shape=shape, line_text=text, cascade=False)


def result(path: str, *issues: IssueRecord) -> FileResult:
    return FileResult(path=path, bytes=100, sha="0" * 64, encoding="utf-8",
                      status="syntax_error" if issues else "ok", ok=not issues, issues=list(issues))


def corpus_results() -> list[FileResult]:
    if_shape = ["IF", "id", "="]
    return [
        # two valid files use the same missing construct: one cluster, 2 files
        result(f"prog/{SCRIPT}.src", issue(3, if_shape, f"IF x = 1 THEN ; {SCRIPT}", rule="ifStatement")),
        result("prog/b.src", issue(7, if_shape, "IF nCount = 2 THEN", rule="ifStatement")),
        # a known-invalid file (a template) fails at a TODO line
        result("tmpl/k.src", issue(2, ["TODO"], "TODO fill in", rule="statementLine",
                                   offending_type="IDENTIFIER")),
        # the parser itself failed: never a cluster
        result("deep/i.src", issue(1, ["DEF"], "DEF i()", kind="internal")),
        result("ok.src"),
    ]


def test_known_invalid_and_internal_are_apart_from_the_ranked_clusters():
    s = summarise(corpus_results(), "g" * 64, "/corpus", 1.0, known_invalid={"tmpl/k.src"})
    assert [(c.leading_keyword, c.files, c.occurrences) for c in s.clusters] == [("IF", 2, 2)]
    assert [(c.leading_keyword, c.files) for c in s.known_invalid_clusters] == [("TODO", 1)]
    assert s.internal_failures == [{"path": "deep/i.src", "line": 1, "message": "mismatched input"}]
    c = s.clusters[0]
    assert c.keyword == "IF"
    assert c.line_shape == "IF ‹name› ="
    assert c.where == "in the IF statement"
    assert c.stopped_at == "="


def test_every_valid_file_parses_is_said_plainly(tmp_path):
    results = [r for r in corpus_results() if r.path in ("tmpl/k.src", "ok.src")]
    s = summarise(results, "g" * 64, "/corpus", 1.0, known_invalid={"tmpl/k.src"})
    write_report(tmp_path, s, results)
    html = (tmp_path / "report.html").read_text()
    assert s.clusters == []
    assert "Every valid file parses." in html
    assert "Every valid file parses." in (tmp_path / "report.md").read_text()
    assert not (tmp_path / "clusters.png").exists()
    # the known-invalid cluster is still listed, in its own section
    known = html[html.index('id="known-invalid"'):html.index('id="internal"')]
    assert "TODO" in known


def test_html_runs_nothing_from_the_corpus(tmp_path):
    results = corpus_results()
    s = summarise(results, "g" * 64, str(tmp_path / "corpus"), 1.0, known_invalid={"tmpl/k.src"})
    s.extra["check"] = {"markdown": "## Front end: `krl check`\n\n| backup | errors |\n|---|---:|\n"
                                    f"| {SCRIPT} | 3 |\n\n<img src=x onerror=alert(2)>\n"}
    write_report(tmp_path / "out", s, results)
    html = (tmp_path / "out" / "report.html").read_text()
    # no markup from the corpus (KRL line, file name) or from the Markdown goes live
    assert "<script" not in html
    assert "<img src=x" not in html
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    # the Markdown section is real HTML: a table, a heading, no Markdown table rule left
    section = html[html.index('id="static-check"'):]
    assert "<table>" in section and "<h2>" in section and "|---|" not in section
    assert "&lt;img src=x onerror=alert(2)&gt;" in section
    # the example lines link to the files, relative to the report folder, percent-encoded
    hrefs = re.findall(r'<a class="example" href="([^"]*)"', html)
    assert "../corpus/prog/%3Cscript%3Ealert%281%29%3C/script%3E.src" in hrefs
    assert "../corpus/prog/b.src" in hrefs


def test_markdown_report_quotes_corpus_text_as_code(tmp_path):
    results = corpus_results()
    s = summarise(results, "g" * 64, "/corpus", 1.0, known_invalid={"tmpl/k.src"})
    write_report(tmp_path, s, results)
    md = (tmp_path / "report.md").read_text()
    assert f"`IF x = 1 THEN ; {SCRIPT}`" in md
    assert md_code("a`b") == "``a`b``"
    assert md_code("x | y") == "`x \\| y`"
    assert md_code("`") == "`` ` ``"


def test_summary_json_and_clusters_csv_keep_the_groups_apart(tmp_path):
    results = corpus_results()
    s = summarise(results, "g" * 64, "/corpus", 1.0, known_invalid={"tmpl/k.src"})
    write_report(tmp_path, s, results)
    j = json.loads((tmp_path / "summary.json").read_text())
    assert [c["leading_keyword"] for c in j["clusters"]] == ["IF"]
    assert j["clusters"][0]["line_shape"] == "IF ‹name› ="
    assert [c["leading_keyword"] for c in j["known_invalid_clusters"]] == ["TODO"]
    assert j["internal_failures"][0]["path"] == "deep/i.src"
    with (tmp_path / "clusters.csv").open(newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert [(r["rank"], r["leading_keyword"], r["group"]) for r in rows] == [
        ("1", "IF", "missing"), ("", "TODO", "known_invalid")]
