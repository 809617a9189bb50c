"""Issue 74, case 7: a Dask scheduler lost in the middle of a job is waited for at the same
address (krl/cluster.py RECONNECT_S, ``KRL_RECONNECT_S``) and the job goes on; one that does not
come back in time is a clear error (krl.cluster.SchedulerError, which every command prints as
``error: ...`` with exit 2), never a traceback. A real scheduler and workers on loopback, each
its own process; the scheduler is killed (SIGKILL) while batches are in flight.
tests/faults/test_cluster_retry.py is the cheap version in the default suite."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from interp import variants as V
from krl import cluster
from krl.lsp.sample import generate
from tests.interp.test_variants import _backup

BIN = Path(sys.executable).parent


def _start(args: list[str], log: Path) -> subprocess.Popen:
    return subprocess.Popen([str(BIN / "dask"), *args], stdout=subprocess.DEVNULL, stderr=open(log, "w"),
                            start_new_session=True)


def _address(log: Path, deadline: float) -> str:
    while time.monotonic() < deadline:
        m = re.search(r"Scheduler at:\s+(tcp://[\d.]+:\d+)", log.read_text())
        if m:
            return m.group(1)
        time.sleep(0.1)
    pytest.fail(f"the scheduler did not start:\n{log.read_text()}")


@pytest.mark.slow
def test_a_scheduler_killed_mid_job_is_a_clear_error(tmp_path: Path) -> None:
    sched = _start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard"], tmp_path / "s.log")
    worker = None
    try:
        address = _address(tmp_path / "s.log", time.monotonic() + 60)
        worker = _start(["worker", address, "--nthreads", "1", "--no-dashboard"], tmp_path / "w.log")
        deadline = time.monotonic() + 60
        while "Registered to" not in (tmp_path / "w.log").read_text() and time.monotonic() < deadline:
            time.sleep(0.1)
        got: list = []
        outcome: dict = {}

        def job():
            try:
                for o in cluster.run_batches(address, time.sleep, ((i, (0.3,)) for i in range(60)),
                                             batch_files=1, connect_s=30, reconnect_s=2):
                    got.append(o)
            except BaseException as exc:       # what a command would meet
                outcome["exc"] = exc
            else:
                outcome["done"] = True

        t = threading.Thread(target=job, daemon=True)
        t.start()
        deadline = time.monotonic() + 90
        while len(got) < 3 and time.monotonic() < deadline and t.is_alive():
            time.sleep(0.05)
        assert len(got) >= 3, f"the job never ran on the cluster: {outcome}"
        os.killpg(sched.pid, signal.SIGKILL)
        sched.wait()
        t.join(120)
        assert not t.is_alive(), "the job hung after the scheduler was lost"
        exc = outcome.get("exc")
        assert isinstance(exc, cluster.SchedulerError), repr(exc)
        assert address in str(exc) and "lost" in str(exc)
    finally:
        for p in (sched, worker):
            if p is not None and p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()


@pytest.mark.slow
def test_krl_recover_whose_scheduler_dies_is_a_clear_error_exit_2(tmp_path: Path) -> None:
    # the probe's case 7 as the user meets it: before, an 80-line FuturesCancelledError
    # traceback from krl/cluster.py and exit 1
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    unit = generate(3000)
    for i in range(24):          # about 3 s of the Python engine's parse each, on one worker
        (corpus / f"p{i:02}.src").write_text(unit.replace("DEF bench", f"DEF p{i:02}", 1) * 2, newline="")
    sched = _start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard"], tmp_path / "s.log")
    worker = recover = None
    try:
        address = _address(tmp_path / "s.log", time.monotonic() + 60)
        worker = subprocess.Popen([str(BIN / "dask"), "worker", address, "--nthreads", "1", "--no-dashboard"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                                  env={**os.environ, "KRL_ENGINE": "python"})
        recover = subprocess.Popen([str(BIN / "krl"), "recover", str(corpus), "--out", str(tmp_path / "out"),
                                    "--no-cache", "--engine", "python", "--scheduler", address],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                   env={**os.environ, "KRL_RECONNECT_S": "3"})
        deadline = time.monotonic() + 120       # imported, connected (a loaded machine: more than 8 s)
        while "Receive client connection" not in (tmp_path / "s.log").read_text() and time.monotonic() < deadline:
            time.sleep(0.2)
        time.sleep(3)                # batches on the worker
        assert recover.poll() is None, recover.communicate()
        os.killpg(sched.pid, signal.SIGKILL)
        sched.wait()
        out, err = recover.communicate(timeout=120)
        assert recover.returncode == 2, out + err
        assert f"error: lost the Dask scheduler at {address}" in err
        assert "Traceback" not in err
        assert not (tmp_path / "out").exists() and [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []
    finally:
        for p in (sched, worker):
            if p is not None and p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
        if recover is not None and recover.poll() is None:
            recover.kill()
            recover.wait()


def _registered(*logs: Path) -> None:
    deadline = time.monotonic() + 60
    while not all("Registered to" in log.read_text() for log in logs):
        if time.monotonic() > deadline:
            pytest.fail("a worker did not register with the scheduler")
        time.sleep(0.1)


def _lines(log: Path) -> int:
    return len(log.read_text().splitlines()) if log.exists() else 0


@pytest.mark.slow
def test_the_variants_sweep_survives_a_lost_worker_and_resumes_after_a_lost_scheduler(tmp_path: Path,
                                                                                      monkeypatch) -> None:
    # issue 74's long sweeps: python -m interp.variants --scheduler on a real cluster of two
    # workers; one worker killed mid-way (Dask runs its variants again on the other), then the
    # scheduler killed and not back within KRL_RECONNECT_S (exit 2, a clear error), started
    # again elsewhere: the sweep resumes from its --log and its counts are those of the local
    # sweep of the same variants
    monkeypatch.setenv("KRL_RECONNECT_S", "2")
    for i in range(4):           # 52 variants (the issue: a sample of at least 40 in the nightly)
        _backup(tmp_path / "src" / f"cell{i}")
    src = str(tmp_path / "src")
    assert V.main([src, "--jobs", "2", "--json", str(tmp_path / "local.json")]) == 0
    local = json.loads((tmp_path / "local.json").read_text())["summary"]
    n = local["variants"]
    assert n >= 40          # the issue: a sample of at least 40 variants (4 x 13 today)

    log = tmp_path / "sweep.jsonl"
    procs: list[subprocess.Popen] = []
    try:
        sched = _start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard"], tmp_path / "s1.log")
        procs.append(sched)
        address = _address(tmp_path / "s1.log", time.monotonic() + 60)
        workers = [_start(["worker", address, "--nthreads", "1", "--no-dashboard"], tmp_path / f"w{i}.log")
                   for i in range(2)]
        procs += workers
        _registered(tmp_path / "w0.log", tmp_path / "w1.log")
        outcome: dict = {}
        t = threading.Thread(target=lambda: outcome.setdefault(
            "code", V.main([src, "--scheduler", address, "--log", str(log)])), daemon=True)
        t.start()
        deadline = time.monotonic() + 300
        while _lines(log) < 3 and time.monotonic() < deadline and t.is_alive():
            time.sleep(0.1)
        os.killpg(workers[0].pid, signal.SIGKILL)        # a worker lost mid-way
        while _lines(log) < 20 and time.monotonic() < deadline and t.is_alive():
            time.sleep(0.1)
        assert t.is_alive() and _lines(log) < n, f"the sweep ended first: {outcome}, {_lines(log)} lines"
        os.killpg(sched.pid, signal.SIGKILL)             # then the scheduler
        t.join(120)
        assert outcome.get("code") == 2
        done_before = _lines(log)

        sched2 = _start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard"], tmp_path / "s2.log")
        procs.append(sched2)
        address2 = _address(tmp_path / "s2.log", time.monotonic() + 60)
        procs.append(_start(["worker", address2, "--nthreads", "1", "--no-dashboard"], tmp_path / "w3.log"))
        _registered(tmp_path / "w3.log")
        assert V.main([src, "--scheduler", address2, "--log", str(log), "--json", str(tmp_path / "dask.json")]) == 0
        resumed = json.loads((tmp_path / "dask.json").read_text())["summary"]
        assert resumed == local
        assert _lines(log) == n and done_before >= 20
    finally:
        for p in procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_the_variants_sweep_rides_out_a_restarted_scheduler_and_a_lost_worker(tmp_path: Path) -> None:
    # issue 74: one sweep, never stopped: a worker killed mid-way (Dask runs its variants again
    # on the other), then the scheduler killed and started again at the same address with new
    # workers (as a supervisor restarts them: a worker whose scheduler died ends); the sweep waits
    # for it (RECONNECT_S), sends again the variants in flight and ends with exit 0, each variant
    # in its --log once, and the counts of the local sweep of the same variants
    for i in range(4):           # 52 variants
        _backup(tmp_path / "src" / f"cell{i}")
    src = str(tmp_path / "src")
    assert V.main([src, "--jobs", "2", "--json", str(tmp_path / "local.json")]) == 0
    local = json.loads((tmp_path / "local.json").read_text())["summary"]
    n = local["variants"]
    assert n >= 40          # the issue: a sample of at least 40 variants (4 x 13 today)

    log, port = tmp_path / "sweep.jsonl", _free_port()
    address = f"tcp://127.0.0.1:{port}"
    scheduler = ["scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"]
    procs: list[subprocess.Popen] = []
    try:
        sched = _start(scheduler, tmp_path / "s1.log")
        procs.append(sched)
        _address(tmp_path / "s1.log", time.monotonic() + 60)
        workers = [_start(["worker", address, "--nthreads", "1", "--no-dashboard"], tmp_path / f"w{i}.log")
                   for i in range(2)]
        procs += workers
        _registered(tmp_path / "w0.log", tmp_path / "w1.log")
        outcome: dict = {}
        t = threading.Thread(target=lambda: outcome.setdefault(
            "code", V.main([src, "--scheduler", address, "--log", str(log), "--json", str(tmp_path / "dask.json")])),
            daemon=True)
        t.start()
        deadline = time.monotonic() + 300
        while _lines(log) < 3 and time.monotonic() < deadline and t.is_alive():
            time.sleep(0.1)
        os.killpg(workers[0].pid, signal.SIGKILL)        # a worker lost mid-way
        while _lines(log) < 16 and time.monotonic() < deadline and t.is_alive():
            time.sleep(0.1)
        assert t.is_alive() and _lines(log) < n, f"the sweep ended first: {outcome}, {_lines(log)} lines"
        os.killpg(sched.pid, signal.SIGKILL)             # then the scheduler
        sched.wait()
        lost_at = _lines(log)
        time.sleep(2)
        assert t.is_alive(), f"the sweep did not wait for its scheduler: {outcome}"
        procs.append(_start(scheduler, tmp_path / "s2.log"))      # the same address
        _address(tmp_path / "s2.log", time.monotonic() + 60)
        procs += [_start(["worker", address, "--nthreads", "1", "--no-dashboard"], tmp_path / f"w{i}.log")
                  for i in (2, 3)]
        t.join(600)
        assert not t.is_alive(), "the sweep hung"
        assert outcome.get("code") == 0
        assert json.loads((tmp_path / "dask.json").read_text())["summary"] == local
        lines = [json.loads(line) for line in log.read_text().splitlines()]
        assert len(lines) == n and len({(r["backup"], r["variant"]) for r in lines}) == n
        assert lost_at < n
    finally:
        for p in procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
