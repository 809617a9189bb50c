"""Every README and docs example that shows output is run and compared (issue 49): the
transcripts (``$`` blocks) of README.md and docs/*.md, by tests/docs/transcripts.py. A
difference fails with a unified diff per command; `python -m tests.docs.transcripts --update
FILE` writes what the commands print (see that module for the rules and the one
normalisation)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.docs import transcripts as T

# the README's example runs 44 programs for its report: minutes on a loaded machine (the first
# test that asks for the documents' run pays for it)
# and they share that run: one xdist worker takes the whole group (make test: --dist loadgroup)
pytestmark = [pytest.mark.timeout(3600), pytest.mark.xdist_group("docs")]

DOCS = [p for p in T.documents() if T.transcripts(p)]


def test_the_parser_finds_the_readme_transcripts_and_their_output(tmp_path):
    # a transcript, a command list without $ lines, and a transcript marked not run
    doc = tmp_path / "x.md"
    doc.write_text("text\n\n```sh\n$ echo a \\\n  b\na b\n$ true\n$ printf 'x\\n\\n'\nx\n```\n\n"
                   "```sh\nmake test\n```\n\n<!-- not run: needs a partner -->\n```sh\n$ nc -l 1\n```\n")
    ts = T.transcripts(doc)
    assert len(ts) == 1 and ts[0].line == 3
    cmds = ts[0].commands
    assert [(c.text, c.line, c.shown, c.first, c.last) for c in cmds] == [
        ("echo a \\\n  b", 4, ["a b"], 6, 7), ("true", 7, [], 8, 8), ("printf 'x\\n\\n'", 8, ["x"], 9, 10)]
    results = [T.Result(c, T.run(c.text, tmp_path)) for c in cmds]
    assert all(r.same for r in results), [r.printed for r in results]
    # an output changed by hand is found, and --update writes it back
    doc.write_text(doc.read_text().replace("a b\n$ true", "a c\n$ true"))
    results = [T.Result(c, T.run(c.text, tmp_path)) for c in T.transcripts(doc)[0].commands]
    assert [r.same for r in results] == [False, True, True]
    assert "-a c" in results[0].diff(doc) and "+a b" in results[0].diff(doc)
    assert T.update(doc, results) and "a b\n$ true" in doc.read_text()
    # the README has transcripts (the diff, graph and report examples)
    assert any(p.name == "README.md" for p in DOCS)


def test_clock_times_are_the_only_normalisation():
    assert T.normalise(["took 1.25 s wall, 3 s CPU, 40 ms wall  ", "", ""]) == ["took N s wall, N s CPU, N ms wall"]
    assert T.normalise(["ended at t=17.844 s", "3 files"]) == ["ended at t=17.844 s", "3 files"]


@pytest.mark.parametrize("doc", DOCS, ids=[str(p.relative_to(T.REPO)) for p in DOCS])
def test_every_transcript_prints_what_the_docs_show(doc: Path, document_runs):
    results, _work = document_runs(doc)
    bad = [r.diff(doc) for r in results if not r.same]
    assert not bad, ("\n".join(bad) + "\n\nIf the new output is right: .venv/bin/python -m tests.docs.transcripts "
                     f"--update {doc.relative_to(T.REPO)}")
