"""One `krl audit` of the whole shared corpus per test session, shared by the corpus tests
(test_corpus.py) and the browser's (test_page.py): both are in the xdist group "audit-corpus",
so one worker makes the run (make test: --dist loadgroup).

Each entry point runs :data:`SIM_TIME` simulated seconds (the audit's option --max-sim-time;
``make nightly`` runs the full 600 s): enough for the expectations of the tests (the first
cycles of rawpython's cell program start at 0.216 s), little CPU for ``make test``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main

#: simulated seconds per entry point in the tests' audit of the corpus
SIM_TIME = 2.0


@pytest.fixture(scope="session")
def corpus_audit(tmp_path_factory, shared_corpus) -> tuple[dict, Path, object]:
    """(the report's JSON, its HTML file, the CliRunner result) of `krl audit CORPUS`."""
    out = tmp_path_factory.mktemp("audit-corpus")
    res = CliRunner().invoke(main, ["audit", str(shared_corpus), "--out", str(out), "--max-sim-time", str(SIM_TIME),
                                    "--jobs", "2"])
    assert (out / "audit.json").is_file(), res.output
    return json.loads((out / "audit.json").read_text(encoding="utf-8")), out / "audit.html", res
