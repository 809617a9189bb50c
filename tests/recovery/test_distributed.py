"""`krl recover --scheduler` (issue 17): the scan on a real Dask LocalCluster on loopback gives the
same report as the local process pool, timings aside; an unreachable scheduler is a clear error."""

from __future__ import annotations

import json
import re
from pathlib import Path

import dask
import pytest
from click.testing import CliRunner

from krl import cluster as distributed
from recovery.cli import recover
from recovery.pipeline import run_recovery

REPO = Path(__file__).resolve().parents[2]
EMBEDDED = REPO / "corpus"
# the one line of each report that says how long the run took
_SECONDS = re.compile(r"\d+\.\d s\.")

pytestmark = pytest.mark.xdist_group("dask")     # one cluster for the group's tests (tests/conftest.py)


def _report(out: Path) -> dict[str, str]:
    files = {}
    for name in ("files.csv", "clusters.csv", "report.md"):
        files[name] = _SECONDS.sub("N s.", (out / name).read_text(encoding="utf-8"))
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    summary.pop("seconds", None)
    files["summary.json"] = json.dumps(summary, sort_keys=True)
    return files


@pytest.fixture
def cluster(dask_cluster):
    """The cluster of consecutive tests (tests/conftest.py, _DaskCluster)."""
    return dask_cluster


def test_report_on_a_local_cluster_equals_the_local_run(cluster, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("KRL_CACHE_DIR", str(tmp_path / "cache"))
    # small batches, so that the 43 KRL files of the embedded corpus make many tasks on two workers
    monkeypatch.setattr(distributed, "DEFAULT_BATCH_FILES", 4)
    local = run_recovery(EMBEDDED, tmp_path / "local", jobs=2, use_cache=False)
    remote = run_recovery(EMBEDDED, tmp_path / "dask", use_cache=False, scheduler=cluster.scheduler_address)
    assert (remote.files, remote.files_ok) == (local.files, local.files_ok)
    krl_files = [p for p in EMBEDDED.rglob("*") if p.suffix.lower() in (".src", ".dat", ".sub")]
    assert local.files == len(krl_files) and 0 < local.files_ok < local.files   # failures: clusters to compare
    assert local.clusters
    assert [c.signature for c in remote.clusters] == [c.signature for c in local.clusters]
    assert _report(tmp_path / "dask") == _report(tmp_path / "local")


def test_one_failing_task_fails_only_its_file(cluster) -> None:
    outcomes = list(distributed.run_batches(cluster.scheduler_address, _maybe_fail,
                                            ((i, (i,)) for i in range(10)), batch_files=3))
    by_key = {o.key: o for o in outcomes}
    assert sorted(by_key) == list(range(10))
    assert by_key[7].status == "internal_error" and "ValueError: seven" in by_key[7].detail
    assert all(by_key[i].status == "done" and by_key[i].value == i * i for i in range(10) if i != 7)


def _maybe_fail(i: int) -> int:
    if i == 7:
        raise ValueError("seven")
    return i * i


def test_unreachable_scheduler_is_a_clear_error(tmp_path: Path, monkeypatch) -> None:
    # port 9 (discard) on loopback: nothing listens there in a test machine, so every connect is
    # refused at once and Dask tries again until its connect timeout: 1 s, not 3, suffices (the
    # error is the same; 2 s less of waiting)
    # `krl recover` in this process (click's runner, as tests/conformance/test_on_dask.py runs
    # `krl conformance` and `krl check` against an unreachable scheduler): the same command, exit
    # status and message, without a process that imports recovery.cli, Matplotlib and Dask again
    # (1.0 s of CPU in a fork of the fork server, 2026-11-29; the installed `krl`'s start:
    # tests/test_wheel.py)
    monkeypatch.setenv("KRL_CACHE_DIR", str(tmp_path / "c"))
    monkeypatch.chdir(REPO)
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        run = CliRunner().invoke(recover, [str(EMBEDDED), "--out", str(tmp_path / "o"), "--no-cache",
                                           "--scheduler", "tcp://127.0.0.1:9"])
    assert run.exit_code == 2, run.output
    assert isinstance(run.exception, SystemExit)        # the command's own exit, not an exception
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in run.stderr
    assert "Traceback" not in run.output
