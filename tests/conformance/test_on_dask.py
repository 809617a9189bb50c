"""Many backups on Dask (issue 39): the real-programs report, `krl conformance` and `krl check` of a
folder of backups run on a real Dask LocalCluster (two worker processes on loopback) give the
same report as the local run (and `krl conformance --jobs 2`, in worker processes of this
machine, the same again), and an unreachable scheduler is a clear error, never a traceback.

The programs are those of one small corpus backup (rawpython__kukaKRLmagic: two programs under
R1/Program and its cell.src, whose committed cell file answers it), so the comparison covers a
program with a cell file and programs without."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from conformance import harness as H
from conformance.report import run_all
from interp import realprograms as R
from krl.files import SHARED_CORPUS
from conformance.cli import conformance
from app.check import check, run_check
import dask

REPO = Path(__file__).resolve().parents[2]
SMALL = SHARED_CORPUS / "rawpython__kukaKRLmagic"
#: the conformance cases run both ways: a HALT, a CIRC motion, a path trigger
CASES = ("026_halt", "055_circ", "080_trigger_distance0")
#: the one line of the reports that says when they were written
_WHEN = re.compile(r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d UTC")

pytestmark = [pytest.mark.skipif(not SMALL.is_dir(), reason="the shared corpus is beside the repository"),
              pytest.mark.xdist_group("dask")]      # one cluster for the group's tests (tests/conftest.py)


@pytest.fixture
def cluster(dask_cluster):
    """The cluster of consecutive tests (tests/conftest.py, _DaskCluster)."""
    return dask_cluster


@pytest.fixture
def one_backup(monkeypatch):
    """The corpus as seen by both reports: only the small backup (called on the client, which
    lists the programs; the workers only run them)."""
    monkeypatch.setattr(R, "find_backups", lambda corpus: [SMALL])


def test_the_real_programs_report_on_a_local_cluster_equals_the_local_run(cluster, one_backup):
    local = R.run_rows(SHARED_CORPUS, max_sim_time=5)
    remote = R.run_rows(SHARED_CORPUS, max_sim_time=5, scheduler=cluster.scheduler_address)
    # rawpython's programs, in the corpus's order; cell.src runs with its committed cell file
    assert [Path(r["program"]).relative_to(SMALL).as_posix() for r in local] == [
        "R1/Program/sample_program.src", "R1/Program/sample_program_with_globals.src", "R1/cell.src"]
    assert local[2]["cell"] and local[2]["cell"].endswith("rawpython__kukaKRLmagic/cell.yaml")
    assert all(r["reason"] != "internal" for r in local)

    def same(rows):
        return [{k: v for k, v in r.items() if k != "seconds"} for r in rows]

    assert same(remote) == same(local)
    assert R.report(remote) == R.report(local)


def test_krl_conformance_on_a_local_cluster_writes_the_same_report(cluster, one_backup, tmp_path):
    cases = [H.load_case(H.CASES_DIR / name) for name in CASES]
    outs = {}
    # in this process, in two worker processes of this machine (krl/pool.py), on the cluster
    for name, scheduler, jobs in (("local", None, 1), ("workers", None, 2), ("dask", cluster.scheduler_address, 1)):
        # one real program (sample_program.src, 60 s simulated on both interpreters) keeps it short
        s = run_all(tmp_path / name, fuzz_n=0, corpus=SHARED_CORPUS, cases=cases, echo=lambda _m: None,
                    scheduler=scheduler, real_limit=1, jobs=jobs)
        outs[name] = s
    assert outs["local"]["cases"] == len(CASES) and outs["local"]["real_programs"] == 1
    assert set(outs["local"]["case_status"]) == set(CASES)
    assert list(outs["local"]["real_status"]) == ["rawpython__kukaKRLmagic/R1/Program/sample_program.src"]
    for f in ("summary.json", "report.md", "report.html"):
        local, workers, dask = ((tmp_path / side / f).read_text() for side in ("local", "workers", "dask"))
        assert _WHEN.sub("WHEN", dask) == _WHEN.sub("WHEN", local), f
        assert _WHEN.sub("WHEN", workers) == _WHEN.sub("WHEN", local), f
    assert json.loads((tmp_path / "dask" / "summary.json").read_text()) == outs["local"]
    assert outs["workers"] == outs["local"]


def test_krl_check_of_a_folder_of_backups_on_a_local_cluster_prints_the_same(cluster):
    # examples/ holds two KRC backups (palletizer5 and plc_cell: R1/...) and the loose programs of
    # examples/cells, examples/network and examples/scara beside them: five workspaces, one task each

    folder = str(REPO / "examples")
    out = {}
    for fmt in ("json", "text"):
        for name, scheduler in (("local", None), ("dask", cluster.scheduler_address)):
            lines: list[str] = []
            status = run_check([folder], fmt=fmt, echo=lines.append, timeout=60, scheduler=scheduler)
            out[fmt, name] = (status, lines)
        assert out[fmt, "dask"] == out[fmt, "local"]
    workspaces = [json.loads(line) for line in out["json", "local"][1]]
    assert [Path(w["workspace"]).name for w in workspaces] == ["palletizer5", "plc_cell", "cells", "network", "scara"]
    # backups first; palletizer5: cell.src, two .src/.dat pairs, sps.sub, $config.dat; plc_cell:
    # four .src and $config.dat; cells: the hand-off's two .src and RoboTeam's three (r1, r2,
    # r2_unsynced); network: two .src/.dat pairs; scara: one pair
    assert [w["files"] for w in workspaces] == [7, 5, 5, 4, 2]


def test_an_unreachable_scheduler_is_a_clear_error(tmp_path, monkeypatch, capsys):
    # nothing listens on port 1 of loopback: every connect is refused at once and Dask tries again
    # until its connect timeout, shortened for the test to 1 s (2 s until 2026-11-29: the same error;
    # three connects, 3 s less of the group's Dask cluster idling)
    monkeypatch.setenv("DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT", "1s")

    dask.config.refresh()
    try:
        assert R.main([str(SMALL), "--scheduler", "tcp://127.0.0.1:1"]) == 2
    finally:
        monkeypatch.undo()
        dask.config.refresh()
    err = capsys.readouterr().err
    assert "error: cannot reach the Dask scheduler at tcp://127.0.0.1:1" in err and "Traceback" not in err
    # krl conformance and krl check, as the user runs them (the interpreters' probe is skipped)

    monkeypatch.setattr(H, "_STATUS", {"tree": None, "vm": None})
    monkeypatch.setenv("DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT", "1s")
    dask.config.refresh()
    try:
        for cmd, args in ((conformance, ["--out", str(tmp_path / "c"), "--fuzz", "0", "--no-real"]),
                          (check, [str(REPO / "examples")])):
            r = CliRunner().invoke(cmd, [*args, "--scheduler", "tcp://127.0.0.1:1"])
            assert r.exit_code == 2, r.output
            assert "error: cannot reach the Dask scheduler at tcp://127.0.0.1:1" in r.output
            assert "Traceback" not in r.output and isinstance(r.exception, SystemExit)
    finally:
        monkeypatch.undo()
        dask.config.refresh()
