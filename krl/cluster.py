"""Tasks on a Dask distributed cluster (``--scheduler tcp://HOST:8786`` of ``krl recover``, the
real-programs report, ``krl conformance``).

A job is the same wherever it runs: the client lists its tasks, this module ships them in
batches to the cluster's workers, which run the same module-level function as the local run and
send back picklable results. :func:`run_batches` keeps the contract of
:func:`krl.pool.run_tasks`: one :class:`krl.pool.Outcome` per task, in completion order, with a
bounded number of batches in flight (so the inputs of a large job are never all in memory at
once). The per-task timeout becomes a per-batch deadline (``timeout`` x tasks in the batch,
plus the transfer allowance): a batch past it gives each of its tasks a ``timeout`` outcome;
its worker thread cannot be killed from here, which is why the local pool (killable
processes) stays the default.

Workers need the project installed (the same version, with its generated parser). What they
read is the job's: ``krl recover`` sends each file's bytes (its workers never open a path of
the corpus), while the runs of the real-programs report and of ``krl conformance`` read the
programs, the backups and the cell files by path, so their workers see the corpus and the
repository at the same paths as the client (one machine, or a shared file system).

Dask is imported only when a scheduler address is given.

A lost scheduler (killed, its machine restarted: Dask cancels the futures in flight; issue 74)
is waited for: the job reconnects to the same address for up to :data:`RECONNECT_S` seconds
(the environment variable ``KRL_RECONNECT_S`` sets it; 0: no retry) and, once the scheduler
answers again with a worker, sends again the batches whose outcomes it had not given yet; the
outcomes given already (the caller's result log: the variants sweep's ``--log``, the other
commands' results in memory) are never asked for again, so the job ends with one outcome per
task, as an uninterrupted run. A job survives :data:`MAX_RECONNECTS` such losses. A lost worker
is Dask's to handle (its tasks are run again on the others).

Errors: :class:`SchedulerError` when the scheduler cannot be reached at the start (within
Dask's connect timeout, 30 s by default) or the address is malformed, when the cluster has no
workers, and when a lost scheduler does not come back within the limit (or is lost once more
than :data:`MAX_RECONNECTS` times): a clear message naming the address, never a traceback from
the command.
"""

from __future__ import annotations

import contextlib
import logging
import os
import time
import uuid
from collections import deque
from collections.abc import Callable, Hashable, Iterable, Iterator
from typing import Any

from concurrent.futures import CancelledError

from krl.pool import Outcome

#: Tasks per batch sent to a worker (the scan's files): big enough that the scheduler's per-task
#: cost (about a millisecond) is small against the parses, small enough that a slow batch does
#: not hold the tail. A job of long tasks (a program's run) passes ``batch_files=1``.
DEFAULT_BATCH_FILES = 16
#: Batches in flight per worker thread of the cluster (bounds the client's memory).
IN_FLIGHT_PER_THREAD = 4
#: Seconds added to each batch's deadline for transfer and scheduling.
TRANSFER_ALLOWANCE_S = 60.0
#: Seconds the client may take to close (a lost scheduler: it does not wait for it longer).
CLOSE_S = 5.0
#: Seconds a job waits for a lost scheduler to answer again at the same address, with a worker
#: (each loss); ``KRL_RECONNECT_S`` in the environment overrides it (0: a lost scheduler ends the job).
RECONNECT_S = 120.0
#: Losses of the scheduler one job survives; one more ends it (SchedulerError).
MAX_RECONNECTS = 3
#: Seconds between two attempts to reach a lost scheduler.
RETRY_EVERY_S = 1.0

log = logging.getLogger("krl.cluster")


class SchedulerError(RuntimeError):
    """The Dask scheduler could not be used (address unreachable, cluster without workers)."""


def _run_batch(fn: Callable[..., Any], batch: list[tuple[Hashable, tuple]],
               init: Callable[..., None] | None, initargs: tuple) -> list[tuple[Hashable, str, Any, str]]:
    """On a worker: ``fn(*args)`` for each task of the batch; an exception fails only its task."""
    if init is not None:
        init(*initargs)
    out = []
    for key, args in batch:
        try:
            out.append((key, "done", fn(*args), ""))
        except Exception as exc:  # noqa: BLE001 - one bad task never fails its batch
            out.append((key, "internal_error", None, f"{type(exc).__name__}: {exc}"))
    return out


def _batches(tasks: Iterable[tuple[Hashable, tuple]], size: int) -> Iterator[list[tuple[Hashable, tuple]]]:
    batch: list = []
    for task in tasks:
        batch.append(task)
        if len(batch) >= size:
            yield batch
            batch = []
    if batch:
        yield batch


def run_batches(address: str, fn: Callable[..., Any], tasks: Iterable[tuple[Hashable, tuple]], *,
                timeout: float | None = None, initializer: Callable[..., None] | None = None,
                initargs: tuple = (), batch_files: int = DEFAULT_BATCH_FILES,
                connect_s: float | None = None, name: str = "krl",
                reconnect_s: float | None = None) -> Iterator[Outcome]:
    """Run ``fn(*args)`` for every ``(key, args)`` of `tasks` on the cluster at `address`
    (``tcp://HOST:PORT``), in batches of `batch_files`; yield one Outcome per task as batches
    finish. `fn` and `initializer` must be importable module-level functions on the workers.
    `timeout`: seconds per file (None: no deadline). `connect_s`: seconds to reach the
    scheduler (None: Dask's ``distributed.comm.timeouts.connect``, 30 s unless configured).
    `name`: the prefix of the tasks' keys on the cluster's dashboard. `reconnect_s`: seconds to
    wait for a lost scheduler (None: :func:`reconnect_limit`; module docstring). Raises
    SchedulerError."""
    try:
        # deferred: tools/startup_bench.py, krl check +295 ms at the top (2026-11-26)
        from distributed import Client, wait  # noqa: PLC0415
    except ImportError as exc:  # pragma: no cover - dask.distributed is a dependency
        raise SchedulerError(f"dask.distributed is not installed: {exc}") from exc
    if batch_files < 1:
        raise ValueError("batch_files must be at least 1")
    reconnect_s = reconnect_limit() if reconnect_s is None else reconnect_s
    try:
        kw = {} if connect_s is None else {"timeout": connect_s}
        client = Client(address, set_as_default=False, **kw)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SchedulerError(f"cannot reach the Dask scheduler at {address}: {exc}") from exc
    quiet = _NoTracebacks()
    handlers = logging.getLogger("distributed").handlers
    for h in handlers:
        h.addFilter(quiet)
    pending = _Pending(_batches(tasks, batch_files))
    losses = 0
    try:
        while True:
            try:
                yield from _run_on(client, address, fn, pending, timeout, initializer, initargs, batch_files,
                                   name, wait)
                return
            except SchedulerError:
                raise
            except Exception as exc:  # noqa: BLE001 - a lost scheduler surfaces as many exception types
                if client.status == "running" and not isinstance(exc, (OSError, CancelledError)):
                    raise
                losses += 1
                _close(client)
                client = _come_back(Client, address, exc, losses, reconnect_s)
    finally:
        _close(client)
        for h in handlers:
            h.removeFilter(quiet)


def reconnect_limit() -> float:
    """Seconds to wait for a lost scheduler: ``KRL_RECONNECT_S`` (a number of seconds, 0 or
    more) when set, else :data:`RECONNECT_S`. Raises SchedulerError on a malformed value."""
    raw = os.environ.get("KRL_RECONNECT_S", "").strip()
    if not raw:
        return RECONNECT_S
    try:
        value = float(raw)
    except ValueError:
        value = -1.0
    if not 0 <= value < float("inf"):
        raise SchedulerError(f"KRL_RECONNECT_S must be a number of seconds, 0 or more, not {raw!r}")
    return value


def _close(client) -> None:
    with contextlib.suppress(Exception):
        client.close(timeout=CLOSE_S)


def _come_back(client_class, address: str, exc: BaseException, losses: int, reconnect_s: float):
    """A new client of the scheduler at `address`, lost (`exc`) for the `losses`-th time, once
    it answers with a worker within `reconnect_s` seconds. Raises SchedulerError."""
    lost = (f"lost the Dask scheduler at {address} in the middle of the job ({type(exc).__name__})")
    again = "the results received so far were given, run the command again (or without --scheduler)"
    if losses > MAX_RECONNECTS:
        raise SchedulerError(f"{lost}, for the {losses}th time (at most {MAX_RECONNECTS}); {again}") from None
    if reconnect_s <= 0:
        raise SchedulerError(f"{lost}; {again}") from None
    log.warning("krl: %s; waiting up to %g s for it to answer again", lost, reconnect_s)
    deadline = time.monotonic() + reconnect_s
    while True:
        left = deadline - time.monotonic()
        client = None
        try:
            client = client_class(address, set_as_default=False, timeout=max(1.0, min(left, 10.0)))
            client.wait_for_workers(1, timeout=max(1.0, deadline - time.monotonic()))
            log.warning("krl: the Dask scheduler at %s answers again; the job goes on", address)
            return client
        except Exception:  # noqa: BLE001 - not back yet: refused, timed out, no worker yet
            if client is not None:
                _close(client)
        if time.monotonic() + RETRY_EVERY_S >= deadline:
            raise SchedulerError(f"{lost}; it did not answer again with a worker within {reconnect_s:g} s "
                                 f"(KRL_RECONNECT_S); {again}") from None
        time.sleep(RETRY_EVERY_S)


class _Pending:
    """The batches of a job not given yet: those sent again after a lost scheduler first, then
    the rest of the job's tasks."""

    def __init__(self, source: Iterator[list[tuple[Hashable, tuple]]]) -> None:
        self.again: deque[list[tuple[Hashable, tuple]]] = deque()
        self.source = source

    def next(self) -> list[tuple[Hashable, tuple]] | None:
        return self.again.popleft() if self.again else next(self.source, None)

    def put_back(self, batches: Iterable[list[tuple[Hashable, tuple]]]) -> None:
        self.again.extendleft(reversed(list(batches)))


class _NoTracebacks(logging.Filter):
    """Dask's own log lines on stderr keep their message but lose their traceback while a job
    runs (a lost scheduler: Dask logs each failed reconnection with one); the command says what
    happened in one line (SchedulerError)."""

    def filter(self, record: logging.LogRecord) -> bool:
        record.exc_info = None
        record.exc_text = None
        record.stack_info = None
        return True


def _run_on(client, address: str, fn, pending: _Pending, timeout, initializer, initargs, batch_files: int,
            name: str, wait) -> Iterator[Outcome]:
    """The body of :func:`run_batches` on a connected client: the batches of `pending` sent,
    their outcomes given. When the scheduler is lost (an exception out of Dask, or a future
    cancelled that this function did not cancel), the batches in flight go back to `pending`
    and the exception propagates."""
    run = uuid.uuid4().hex[:12]
    threads = sum(client.nthreads().values())
    if threads == 0:
        raise SchedulerError(f"the Dask cluster at {address} has no workers")
    limit = max(2, threads * IN_FLIGHT_PER_THREAD)
    in_flight: dict[Any, list[tuple[Hashable, tuple]]] = {}
    n = 0

    def submit() -> bool:
        nonlocal n
        batch = pending.next()
        if batch is None:
            return False
        try:
            fut = client.submit(_run_batch, fn, batch, initializer, initargs, pure=False,
                                key=f"{name}-{run}-{n}")
        except BaseException:
            pending.put_back([batch])
            raise
        n += 1
        in_flight[fut] = batch
        return True

    try:
        while len(in_flight) < limit and submit():
            pass
        while in_flight:
            yield from _next_done(client, in_flight, timeout, batch_files, wait)
            while len(in_flight) < limit and submit():
                pass
    except Exception:
        pending.put_back(in_flight.values())
        raise


def _next_done(client, in_flight: dict, timeout, batch_files: int, wait) -> Iterator[Outcome]:
    """The outcomes of the batches of `in_flight` that finish first (taken out of it); all of
    them as timeouts when none finishes within a batch's deadline. A cancelled future (the
    scheduler lost) raises CancelledError, its batch left in `in_flight`."""
    deadline = None if timeout is None else timeout * batch_files + TRANSFER_ALLOWANCE_S
    try:
        with client.as_current():
            done, _ = wait(list(in_flight), timeout=deadline, return_when="FIRST_COMPLETED")
    except TimeoutError:
        done = set()
    if not done:   # nothing finished within a whole batch's deadline: give up on them
        for fut, batch in in_flight.items():
            fut.cancel()
            for key, _args in batch:
                yield Outcome(key, "timeout", detail=f"the batch on the Dask cluster took longer "
                                                     f"than {deadline:g} s")
        in_flight.clear()
        return
    for fut in done:
        if fut.status == "cancelled":
            raise CancelledError(f"batch {fut.key} cancelled: the client lost its scheduler")
        if fut.status == "finished":
            results = fut.result()
        batch = in_flight.pop(fut)
        if fut.status == "finished":
            for key, status, value, detail in results:
                yield Outcome(key, status, value, detail)
        else:
            detail = f"the Dask worker failed: {fut.exception()!r}" if fut.status == "error" \
                else f"the Dask task ended as {fut.status}"
            for key, _args in batch:
                yield Outcome(key, "internal_error", detail=detail)
