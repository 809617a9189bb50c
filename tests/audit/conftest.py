"""`krl audit` runs the tests share: the whole shared corpus once per session for the corpus
tests (test_corpus.py, in ``make nightly``: about 45 s of CPU), and a sample of four of its units
for the browser's (test_page.py, in ``make test``: one backup and one program folder of each status
the whole corpus's audit gives, about 4 s). Both are in the xdist group "audit-corpus", so one
worker makes the runs (make test: --dist loadgroup).

Each entry point runs :data:`SIM_TIME` simulated seconds (the audit's option --max-sim-time;
``make nightly`` runs the full 600 s): enough for the expectations of the tests (the first
cycles of rawpython's cell program start at 0.216 s), little CPU for ``make test``."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main

#: simulated seconds per entry point in the tests' audit of the corpus
SIM_TIME = 2.0

#: the browser's sample (test_page.py): the corpus's rawpython backup (34 files, a program error
#: at sample_program.src:26) and three program folders that the whole corpus's audit rates "ok"
#: (AlexeiOvcharov__kuka_rsi3_server: one program that completes), "review" (BmadeRobots: its
#: outputs to review) and "attention" (Bugaj32: 10 files, program errors)
FLEET_SAMPLE = ("rawpython__kukaKRLmagic", "AlexeiOvcharov__kuka_rsi3_server", "BmadeRobots__KukaVarProxy",
                "Bugaj32__KUKA-pick-and-place-palletizing")


def _audit(corpus: Path, out: Path) -> tuple[dict, Path, object]:
    res = CliRunner().invoke(main, ["audit", str(corpus), "--out", str(out), "--max-sim-time", str(SIM_TIME),
                                    "--jobs", "2"])
    assert (out / "audit.json").is_file(), res.output
    return json.loads((out / "audit.json").read_text(encoding="utf-8")), out / "audit.html", res


@pytest.fixture(scope="session")
def corpus_audit(tmp_path_factory, shared_corpus) -> tuple[dict, Path, object]:
    """(the report's JSON, its HTML file, the CliRunner result) of `krl audit CORPUS`."""
    return _audit(shared_corpus, tmp_path_factory.mktemp("audit-corpus"))


@pytest.fixture(scope="session")
def fleet_sample_audit(tmp_path_factory, shared_corpus) -> tuple[dict, Path, object]:
    """(the report's JSON, its HTML file, the CliRunner result) of `krl audit` on a copy of the
    :data:`FLEET_SAMPLE` units of the corpus (a copy: the audit reads no link)."""
    corpus = tmp_path_factory.mktemp("fleet-sample")
    for name in FLEET_SAMPLE:
        shutil.copytree(shared_corpus / name, corpus / name)
    return _audit(corpus, tmp_path_factory.mktemp("fleet-sample-audit"))
