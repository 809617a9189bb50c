"""`krl construct new NAME --from CLUSTER` on a cluster of a deliberately broken corpus: the
folder, the examples cut from the corpus with their origins, the CHANGES.md row and the
conformance-case stub (issue 27, the maintainer's loop)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from recovery.pipeline import run_recovery
from tests.forkserver import krl_command

REPO = Path(__file__).resolve().parents[2]
BROKEN = REPO / "corpus" / "broken"


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("construct")
    corpus, report, root = tmp / "corpus", tmp / "report", tmp / "project"
    corpus.mkdir()
    for name in ("deffct_closed_by_end.src", "if_without_endif.src", "lexer_error.src"):
        shutil.copyfile(BROKEN / name, corpus / name)
    (root / "grammar" / "constructs").mkdir(parents=True)
    (root / "grammar" / "CHANGES.md").write_text("# Grammar changes\n\n| construct | ... |\n|---|---|\n")
    (root / "conformance" / "cases" / "118_last_case").mkdir(parents=True)
    run_recovery(corpus, report, jobs=1, use_cache=False)
    summary = json.loads((report / "summary.json").read_text())
    (cluster,) = [c for c in summary["clusters"] if c["signature"] == "line-start | END | END"]
    res = subprocess.run([sys.executable, "-m", "app", "construct", "new", "end_closes_everything",
                          "--from", cluster["id"], "--report", str(report), "--corpus", str(corpus),
                          "--root", str(root)], capture_output=True, text=True, cwd=REPO, check=False)
    return root, report, corpus, cluster, res


def test_folder_and_examples_with_their_origins(made):
    root, _, _, cluster, res = made
    assert res.returncode == 0, res.stderr
    folder = root / "grammar" / "constructs" / "end_closes_everything"
    assert sorted(p.name for p in folder.iterdir()) == ["bad_template.src", "ok_1.expect", "ok_1.src",
                                                        "ok_2.expect", "ok_2.src"]
    # the cluster's two examples, in walk order; each cut is the enclosing routine (the END
    # alone, or wrapped in a bare DEF, fails with another signature): lines 1-8 of each file
    first = (BROKEN / "deffct_closed_by_end.src").read_text().splitlines()
    ok1 = (folder / "ok_1.src").read_text().splitlines()
    assert ok1[0] == f"; origin: deffct_closed_by_end.src:8 (cluster {cluster['id']}, cut: block)"
    assert ok1[1:] == first[first.index(next(ln for ln in first if ln.startswith("DEFFCT"))):8]
    ok2 = (folder / "ok_2.src").read_text().splitlines()
    assert ok2[0] == f"; origin: if_without_endif.src:11 (cluster {cluster['id']}, cut: block)"
    assert ok2[-1] == "END" and ok2[1].startswith("DEF if_without_endif")
    # the expect file is a template to fill in by hand: every line commented
    assert all(ln.startswith("#") for ln in (folder / "ok_1.expect").read_text().splitlines())


def test_changes_row_and_case_stub(made):
    root, _, _, cluster, _ = made
    row = (root / "grammar" / "CHANGES.md").read_text().splitlines()[-1]
    assert row.startswith("| end_closes_everything: ")
    assert f"| {cluster['id']} (2 files: `line-start | END | END`) | 0 -> (measure with krl recover) |" in row
    assert row.endswith("| grammar: end closes everything |")
    case = root / "conformance" / "cases" / "119_end_closes_everything"
    assert "status: pending" in (case / "expect.yaml").read_text()
    assert (case / "program.src").read_text() == "\n".join((root / "grammar" / "constructs" / "end_closes_everything"
                                                            / "ok_1.src").read_text().splitlines()[1:]) + "\n"


def test_errors_are_clear(made):
    root, report, corpus, cluster, _ = made
    # `krl` as a fork of the worker's fork server (tests/forkserver.py): the same app.main, exit
    # status and stderr without the project's import at each of the four starts (the `made`
    # fixture's command and every other test's keep the real process start)
    krl = [*krl_command(), "construct", "new"]
    for args, message in ((["x_y", "--from", "Cnope"], "no cluster Cnope"),
                          (["end_closes_everything", "--from", cluster["id"]], "exists already"),
                          (["Bad-Name", "--from", cluster["id"]], "a construct name is"),
                          (["other", "--from", cluster["id"], "--report", str(root)], "no recovery report")):
        base = [] if "--report" in args else ["--report", str(report)]
        res = subprocess.run([*krl, *args, *base, "--corpus", str(corpus), "--root", str(root)],
                             capture_output=True, text=True, cwd=REPO, check=False)
        assert res.returncode == 2 and message in res.stderr and "Traceback" not in res.stderr, res.stderr
