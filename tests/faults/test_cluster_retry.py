"""Issue 74: a job on a Dask cluster whose scheduler is lost waits for it at the same address
(krl/cluster.py RECONNECT_S) and goes on, sending again only the batches whose outcomes it had
not given: one outcome per task, as an uninterrupted run. The cheap version of
tests/faults/test_cluster_loss.py's (slow) process-level tests: a real scheduler and worker on
loopback, in this process (their own event loop in a thread), the scheduler closed mid-job and a
new one started on the same port with a new worker."""

from __future__ import annotations

import asyncio
import multiprocessing
import socket
import threading
import time

import pytest
from distributed import Scheduler, Worker

from krl import cluster
from krl.pool import run_tasks


def _twice(x: int) -> int:
    time.sleep(0.02)
    return 2 * x


class _Loop:
    """An event loop in a thread, where the scheduler and the workers live."""

    def __init__(self) -> None:
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()

    def run(self, coro, timeout: float = 30):
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    def stop(self) -> None:
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(10)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


async def _start(port: int) -> tuple[Scheduler, Worker]:
    sched = await Scheduler(host="127.0.0.1", port=port, dashboard=False, dashboard_address="127.0.0.1:0")
    worker = await Worker(sched.address, nthreads=1, dashboard=False, dashboard_address="127.0.0.1:0")
    return sched, worker


async def _stop(*servers) -> None:
    for s in servers:
        await s.close()


def test_a_job_whose_scheduler_comes_back_gives_each_outcome_once(monkeypatch) -> None:
    monkeypatch.setattr(cluster, "RETRY_EVERY_S", 0.2)
    loop, port = _Loop(), _free_port()
    servers = loop.run(_start(port))
    address = f"tcp://127.0.0.1:{port}"
    got = []
    try:
        for o in cluster.run_batches(address, _twice, ((i, (i,)) for i in range(12)), batch_files=1,
                                     reconnect_s=30):
            got.append(o)
            if len(got) == 3:     # batches in flight: the scheduler goes, a new one comes at the same address
                loop.run(_stop(*reversed(servers)))
                servers = loop.run(_start(port))
        assert sorted((o.key, o.status, o.value) for o in got) == [(i, "done", 2 * i) for i in range(12)]
    finally:
        loop.run(_stop(*reversed(servers)))
        loop.stop()


def test_a_scheduler_that_does_not_come_back_is_a_clear_error_after_the_limit(monkeypatch) -> None:
    monkeypatch.setattr(cluster, "RETRY_EVERY_S", 0.2)
    monkeypatch.setenv("KRL_RECONNECT_S", "1.5")
    loop, port = _Loop(), _free_port()
    servers = loop.run(_start(port))
    address = f"tcp://127.0.0.1:{port}"
    got = []
    try:
        start = time.monotonic()
        with pytest.raises(cluster.SchedulerError) as caught:
            for o in cluster.run_batches(address, _twice, ((i, (i,)) for i in range(12)), batch_files=1):
                got.append(o)
                if len(got) == 3:
                    loop.run(_stop(*reversed(servers)))
                    servers = ()
                    start = time.monotonic()
        assert f"lost the Dask scheduler at {address}" in str(caught.value)
        assert "did not answer again with a worker within 1.5 s (KRL_RECONNECT_S)" in str(caught.value)
        waited = time.monotonic() - start
        assert 1.5 <= waited < 60, waited       # not before the limit; no hang (closing the lost client: 5 s)
        assert 3 <= len(got) < 12, got
    finally:
        loop.run(_stop(*reversed(servers)))
        loop.stop()


def test_the_reconnect_limit_comes_from_the_environment(monkeypatch) -> None:
    monkeypatch.delenv("KRL_RECONNECT_S", raising=False)
    assert cluster.reconnect_limit() == cluster.RECONNECT_S == 120.0
    monkeypatch.setenv("KRL_RECONNECT_S", "0")
    assert cluster.reconnect_limit() == 0.0
    for bad in ("-1", "soon", "inf", "nan"):
        monkeypatch.setenv("KRL_RECONNECT_S", bad)
        with pytest.raises(cluster.SchedulerError, match="KRL_RECONNECT_S must be a number of seconds"):
            cluster.reconnect_limit()


def _in_a_daemon(conn) -> None:
    try:
        conn.send(sorted((o.key, o.status, o.value, o.detail) for o in
                         run_tasks(_twice, ((i, (i,)) for i in range(4)), jobs=2)))
    except Exception as exc:  # noqa: BLE001 - what the test shows
        conn.send(f"{type(exc).__name__}: {exc}")
    conn.close()


def test_a_daemonic_process_such_as_a_dask_worker_runs_its_pools_tasks_itself() -> None:
    # a Dask worker runs under its nanny as a daemonic process, which may not start processes:
    # the variants sweep's runs on the cluster failed "AssertionError: daemonic processes are not
    # allowed to have children" (47 of 244 runs on a sample of 12, the local run 0)
    ctx = multiprocessing.get_context("fork")
    here, there = ctx.Pipe()
    child = ctx.Process(target=_in_a_daemon, args=(there,), daemon=True)
    child.start()
    assert here.poll(60), "no answer from the daemonic process"
    assert here.recv() == [(i, "done", 2 * i, "") for i in range(4)]
    child.join(10)
