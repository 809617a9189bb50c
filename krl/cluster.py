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

Errors: :class:`SchedulerError` when the scheduler cannot be reached (within Dask's connect
timeout, 30 s by default) or the address is malformed, and when it is lost in the middle of a
job (killed, its machine gone: Dask cancels the futures in flight; issue 74): a clear message
naming the address, never a traceback from the command. A lost worker is Dask's to handle (its
tasks are run again on the others).
"""

from __future__ import annotations

import contextlib
import logging
import uuid
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
                connect_s: float | None = None, name: str = "krl") -> Iterator[Outcome]:
    """Run ``fn(*args)`` for every ``(key, args)`` of `tasks` on the cluster at `address`
    (``tcp://HOST:PORT``), in batches of `batch_files`; yield one Outcome per task as batches
    finish. `fn` and `initializer` must be importable module-level functions on the workers.
    `timeout`: seconds per file (None: no deadline). `connect_s`: seconds to reach the
    scheduler (None: Dask's ``distributed.comm.timeouts.connect``, 30 s unless configured).
    `name`: the prefix of the tasks' keys on the cluster's dashboard. Raises SchedulerError."""
    try:
        # deferred: tools/startup_bench.py, krl check +295 ms at the top (2026-11-26)
        from distributed import Client, wait  # noqa: PLC0415
    except ImportError as exc:  # pragma: no cover - dask.distributed is a dependency
        raise SchedulerError(f"dask.distributed is not installed: {exc}") from exc
    if batch_files < 1:
        raise ValueError("batch_files must be at least 1")
    try:
        kw = {} if connect_s is None else {"timeout": connect_s}
        client = Client(address, set_as_default=False, **kw)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SchedulerError(f"cannot reach the Dask scheduler at {address}: {exc}") from exc
    quiet = _NoTracebacks()
    handlers = logging.getLogger("distributed").handlers
    for h in handlers:
        h.addFilter(quiet)
    try:
        yield from _run_on(client, address, fn, tasks, timeout, initializer, initargs, batch_files, name, wait)
    except SchedulerError:
        raise
    except Exception as exc:  # noqa: BLE001 - a lost scheduler surfaces as many exception types
        if client.status == "running" and not isinstance(exc, (OSError, CancelledError)):
            raise
        raise SchedulerError(f"lost the Dask scheduler at {address} in the middle of the job "
                             f"({type(exc).__name__}); the results received so far were given, run "
                             "the command again (or without --scheduler)") from None
    finally:
        with contextlib.suppress(Exception):
            client.close(timeout=CLOSE_S)
        for h in handlers:
            h.removeFilter(quiet)


class _NoTracebacks(logging.Filter):
    """Dask's own log lines on stderr keep their message but lose their traceback while a job
    runs (a lost scheduler: Dask logs each failed reconnection with one); the command says what
    happened in one line (SchedulerError)."""

    def filter(self, record: logging.LogRecord) -> bool:
        record.exc_info = None
        record.exc_text = None
        record.stack_info = None
        return True


def _run_on(client, address: str, fn, tasks, timeout, initializer, initargs, batch_files: int, name: str,
            wait) -> Iterator[Outcome]:
    """The body of :func:`run_batches` on a connected client."""
    run = uuid.uuid4().hex[:12]
    threads = sum(client.nthreads().values())
    if threads == 0:
        raise SchedulerError(f"the Dask cluster at {address} has no workers")
    limit = max(2, threads * IN_FLIGHT_PER_THREAD)
    in_flight: dict[Any, list[tuple[Hashable, tuple]]] = {}
    source = _batches(tasks, batch_files)
    n = 0

    def submit() -> bool:
        nonlocal n
        batch = next(source, None)
        if batch is None:
            return False
        fut = client.submit(_run_batch, fn, batch, initializer, initargs, pure=False,
                            key=f"{name}-{run}-{n}")
        n += 1
        in_flight[fut] = batch
        return True

    while len(in_flight) < limit and submit():
        pass
    while in_flight:
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
            while len(in_flight) < limit and submit():
                pass
            continue
        for fut in done:
            batch = in_flight.pop(fut)
            if fut.status == "cancelled" and client.status != "running":
                raise CancelledError(f"batch {fut.key} cancelled: the client lost its scheduler")
            if fut.status == "finished":
                for key, status, value, detail in fut.result():
                    yield Outcome(key, status, value, detail)
            else:
                detail = f"the Dask worker failed: {fut.exception()!r}" if fut.status == "error" \
                    else f"the Dask task ended as {fut.status}"
                for key, _args in batch:
                    yield Outcome(key, "internal_error", detail=detail)
        while len(in_flight) < limit and submit():
            pass
