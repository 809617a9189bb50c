"""Running per-file work in worker processes that can be killed (pebble).

A parse of untrusted text may take too long, exhaust memory or crash the interpreter (a C
extension, a signal). None of that may stop a scan or hang a command, and a timeout must not
depend on the parsed code cooperating (a SIGALRM is lost when it fires inside a garbage-collector
callback). So each task runs in a worker process of a :class:`pebble.ProcessPool`: past its
timeout the worker is killed and replaced, and a worker that dies (killed, segfault, ``os._exit``)
fails only its own task. :func:`run_tasks` turns every task into one :class:`Outcome`, in
completion order, and keeps a bounded number of tasks in flight, so the arguments (file bytes)
of a large corpus are never all in memory at once.

Workers are forked from the calling process (explicitly, where the platform can fork): they
start with the parser the caller has loaded, and a function patched in the parent before the
pool starts is the function the workers run (the tests' crash hooks rely on it).
"""

from __future__ import annotations

import os
import signal
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, wait
from concurrent.futures import TimeoutError as FutureTimeout
from dataclasses import dataclass
from typing import Any, Hashable


@dataclass(slots=True)
class Outcome:
    """The end of one task: ``status`` is "done" (``value`` is the function's result),
    "timeout" (the worker was killed after the timeout) or "internal_error" (the worker died,
    or the function raised: ``detail`` says how)."""

    key: Hashable
    status: str
    value: Any = None
    detail: str = ""


def default_jobs() -> int:
    """The number of cores this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _death(exitcode: int | None) -> str:
    if exitcode is not None and exitcode < 0:
        try:
            return f"the worker process died ({signal.Signals(-exitcode).name})"
        except ValueError:
            return f"the worker process died (signal {-exitcode})"
    return f"the worker process died (exit status {exitcode})"


def start_fork_server(preload: tuple[str, ...]) -> None:
    """Start the fork server of :func:`run_tasks` ``preload`` now (it takes a second: a fresh
    interpreter importing `preload`), so that the first pool does not wait for it."""
    # deferred: tools/startup_bench.py, krl check +8 ms at the top (2026-11-26)
    import multiprocessing  # noqa: PLC0415
    # deferred: tools/startup_bench.py, krl check +10 ms at the top (2026-11-26)
    from multiprocessing import forkserver  # noqa: PLC0415

    if "forkserver" in multiprocessing.get_all_start_methods():
        multiprocessing.get_context("forkserver").set_forkserver_preload(list(preload))
        forkserver.ensure_running()


def run_tasks(fn: Callable[..., Any], tasks: Iterable[tuple[Hashable, tuple]], *, jobs: int | None = None,
              timeout: float | None = None, initializer: Callable | None = None, initargs: tuple = (),
              in_process: bool = False, preload: tuple[str, ...] | None = None,
              group: Callable[[Hashable], Hashable] | None = None) -> Iterator[Outcome]:
    """Run ``fn(*args)`` for every ``(key, args)`` of `tasks`; yield one :class:`Outcome` per
    task as tasks finish.

    jobs: worker processes (default: :func:`default_jobs`). timeout: seconds of wall time per
    task, counted from when a worker starts it (None: no limit). in_process: run in this
    process, one after the other, with no timeout and no protection from a crash (for callers
    that already run inside a worker, and for tests of the function itself). In a daemonic
    process (a Dask worker), which may not start processes, every call runs so.
    Tasks are taken from `tasks` lazily, at most ``2 * jobs`` ahead of the results.

    group: ``group(key)`` names what a task loads that the next task of the same group finds
    loaded in its worker (the backup of ``krl audit``'s runs: its checked workspace, cached per
    process). Each worker then takes the tasks of one group after the other, a new group when its
    own has none left, and, when no group is left to start, the tasks of the group with the most
    left (:class:`_Groups`): a backup is loaded by one worker, not by every one (``krl audit``
    of the corpus, 2 simulated s per entry point, two workers: 39 -> 31 s of CPU, 21 -> 17 s of wall
    time, the same report; 2026-11-25). The tasks are all read first.
    """
    if in_process:
        if initializer is not None:
            initializer(*initargs)
        for key, args in tasks:
            try:
                yield Outcome(key, "done", fn(*args))
            except Exception as exc:  # noqa: BLE001 - one task never stops the others
                yield Outcome(key, "internal_error", None, f"{type(exc).__name__}: {exc}")
        return
    # deferred: tools/startup_bench.py, krl run +32 ms at the top (2026-11-26)
    from pebble import ProcessExpired, ProcessPool  # noqa: PLC0415

    jobs = max(1, jobs or default_jobs())
    # deferred: tools/startup_bench.py, krl check +8 ms at the top (2026-11-26)
    import multiprocessing  # noqa: PLC0415

    if multiprocessing.current_process().daemon:
        # a daemonic process may not start processes (a Dask worker under its nanny: the variants
        # sweep's runs there failed "daemonic processes are not allowed to have children", 47 of
        # 244 on a sample of 12, 2026-11-27): its tasks run here, as with in_process
        yield from run_tasks(fn, tasks, initializer=initializer, initargs=initargs, in_process=True)
        return

    methods = multiprocessing.get_all_start_methods()
    if preload is not None and "forkserver" in methods:
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(list(preload))   # heeded when the fork server starts
    else:
        # fork, explicitly (Python 3.14 changes the default): workers start with what this
        # process has loaded (the parser) and with what a test patched in it
        context = multiprocessing.get_context("fork" if "fork" in methods else None)
    grouped = group is not None and jobs > 1
    # grouped: one pool of one worker per slot, so that a slot is a worker; else one pool
    pools = [ProcessPool(max_workers=1 if grouped else jobs, initializer=initializer, initargs=initargs,
                         context=context) for _ in range(jobs if grouped else 1)]
    feed = _Groups(tasks, group, len(pools)) if grouped else _InOrder(tasks, 2 * jobs)
    finished = False
    try:
        inflight: dict = {}
        per_slot = [0] * len(pools)
        while True:
            for slot in range(len(pools)):
                while True:
                    task = feed.next(slot, per_slot[slot])
                    if task is None:
                        break
                    key, args = task
                    inflight[pools[slot].schedule(fn, args=args, timeout=timeout)] = (key, slot)
                    per_slot[slot] += 1
            if not inflight:
                break
            done, _ = wait(list(inflight), return_when=FIRST_COMPLETED)
            for fut in done:
                key, slot = inflight.pop(fut)
                per_slot[slot] -= 1
                yield _outcome(fut, key, timeout, ProcessExpired)
        finished = True
    finally:
        for pool in pools:
            if finished:
                pool.close()
            else:
                pool.stop()   # interrupted or abandoned: kill the workers, do not wait for them
        for pool in pools:
            pool.join()


def _outcome(fut, key: Hashable, timeout: float | None, expired: type) -> Outcome:
    """The :class:`Outcome` of a finished task's future (`expired`: pebble's ProcessExpired)."""
    try:
        return Outcome(key, "done", fut.result())
    except FutureTimeout:
        return Outcome(key, "timeout", None, f"killed after {timeout:g} s")
    except expired as exc:
        return Outcome(key, "internal_error", None, _death(exc.exitcode))
    except Exception as exc:  # noqa: BLE001 - raised in the worker, or unpicklable
        return Outcome(key, "internal_error", None, f"{type(exc).__name__}: {exc}")


class _InOrder:
    """The tasks in their order to the one pool, at most `window` in flight."""

    def __init__(self, tasks: Iterable, window: int) -> None:
        self.source = iter(tasks)
        self.window = window

    def next(self, _slot: int, inflight: int):
        if inflight >= self.window:
            return None
        return next(self.source, None)


class _Groups:
    """The tasks to the slots (one worker each) by group (:func:`run_tasks` ``group``), at most
    two in flight per slot (the next one queued while one runs): a slot takes the next task of
    its group; when its group has none left, the next group no slot has started; when every
    group has started, the group with the most tasks left (that slot loads it too)."""

    def __init__(self, tasks: Iterable, group: Callable, slots: int) -> None:
        self.left: dict = {}                 # group -> deque of its tasks not yet given out
        for key, args in tasks:
            self.left.setdefault(group(key), deque()).append((key, args))
        self.fresh = deque(self.left)        # the groups no slot has started, in order
        self.mine: list = [None] * slots     # the group each slot works on

    def next(self, slot: int, inflight: int):
        if inflight >= 2:
            return None
        g = self.mine[slot]
        if g is None or not self.left.get(g):
            g = None
            while self.fresh and g is None:
                c = self.fresh.popleft()
                g = c if self.left.get(c) else None
            if g is None:
                g = max((c for c in self.left if self.left[c]), key=lambda c: len(self.left[c]), default=None)
            if g is None:
                return None
            self.mine[slot] = g
        task = self.left[g].popleft()
        if not self.left[g]:
            del self.left[g]
        return task
