"""`krl audit --scheduler` (issue 49): the audit of a corpus backup on a real Dask LocalCluster (two
worker processes on loopback) writes the same report as the local run, and a scheduler nobody
answers at is a usage error, never a traceback.

The backup is the corpus's smallest (rawpython__kukaKRLmagic: three entry points, its P00
handshake answered by the automatic cell); the whole corpus was compared the same way by hand
(docs/audit.md, "On a Dask cluster")."""

from __future__ import annotations

import json
import re

import dask
import pytest
from click.testing import CliRunner

from app import main
from krl.files import SHARED_CORPUS

SMALL = SHARED_CORPUS / "rawpython__kukaKRLmagic"
#: the one line of the reports that says when they were written
_WHEN = re.compile(r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d UTC")

pytestmark = [pytest.mark.corpus, pytest.mark.timeout(900), pytest.mark.xdist_group("dask")]


@pytest.fixture
def cluster(shared_corpus, dask_cluster):
    """The cluster of consecutive tests (tests/conftest.py, _DaskCluster)."""
    return dask_cluster


def test_the_audit_on_a_local_cluster_equals_the_local_run(cluster, tmp_path):
    out = {}
    for name, extra in (("local", ["--jobs", "2"]), ("dask", ["--scheduler", cluster.scheduler_address])):
        res = CliRunner().invoke(main, ["audit", str(SMALL), "--out", str(tmp_path / name), "--max-sim-time", "2",
                                        *extra])
        # sample_program.src does not parse (line 26): a program error, so attention (exit 1)
        assert res.exit_code == 1, res.output
        out[name] = res
    local, dask = (json.loads((tmp_path / n / "audit.json").read_text(encoding="utf-8")) for n in ("local", "dask"))
    assert {e["program"] for u in local["units"] for e in u["entries"]} == {
        "R1/cell.src", "R1/Program/sample_program.src", "R1/Program/sample_program_with_globals.src"}
    assert {**dask, "generated": ""} == {**local, "generated": ""}
    pages = [_WHEN.sub("WHEN", (tmp_path / n / "audit.html").read_text(encoding="utf-8")) for n in ("local", "dask")]
    assert pages[0] == pages[1]
    assert out["dask"].output.splitlines()[:-1] == out["local"].output.splitlines()[:-1]   # all but the time


def test_an_unreachable_scheduler_is_a_clear_error(tmp_path, monkeypatch, shared_corpus):
    # nothing listens on port 1 of loopback; Dask's connect timeout is shortened for the test
    monkeypatch.setenv("DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT", "2s")
    dask.config.refresh()
    try:
        res = CliRunner().invoke(main, ["audit", str(SMALL), "--out", str(tmp_path / "o"),
                                        "--scheduler", "tcp://127.0.0.1:1"])
    finally:
        monkeypatch.undo()
        dask.config.refresh()
    assert res.exit_code == 2 and isinstance(res.exception, SystemExit), res.output
    assert "krl audit: error: cannot reach the Dask scheduler at tcp://127.0.0.1:1" in res.output
    assert "Traceback" not in res.output and not (tmp_path / "o").exists()
