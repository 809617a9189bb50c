"""The process's one policy on Python's cyclic garbage collector (the ``gc`` module): every
pause and every freeze of the project goes through here (tests/test_collector.py holds the
rest of the code to it).

Its thresholds are set when this module is first imported. Every process of the tools imports
it: krl.workspace (what loads KRL: the `krl` command's, the pool's workers, a Dask worker's
task, the tests') and the robot package (``python -m robot.bench``) import it:
:data:`YOUNG_THRESHOLD` new container objects before a young collection, not CPython's 700.

Two uses, each measured where it is used:

* :func:`paused`: no collection while a batch of long-lived objects is built (a workspace's
  ASTs, a parse tree rebuilt from a worker's answer, a whole check); the collector runs again
  afterwards as it was.
* :func:`keep`: what the process made so far lives as long as the process (the language
  server's checked workspace, a debug session's program): it is moved to the collector's
  permanent generation (``gc.freeze``). ``renew=True`` first returns what an earlier call
  froze (``gc.unfreeze``), so that what has died since is collected.

A KRL run does not freeze its set-up. It once did, for the length of the run (so that the
collections during it would walk only what it made; the effect was within the noise), and
that starved the collector: ``gc.freeze`` sets the young generation's count to 0, so in a
process running one run after the other (a Dask worker of the variants sweep) no collection
ever started, and every finished run's reference cycles stayed: 9.9 GB in each worker, which
Dask paused at 80 % of its memory limit, and the sweep stopped (2026-11-27). Without the freeze
a short run's objects die young and a young collection frees them, and Python's own rule
collects the rest (tests/test_collector.py).

A process forked from one of the tools (krl.pool's workers, forked from the command that
loaded the parser and often whole backups) starts with everything it inherited frozen, and keeps
it so (:func:`_inherited`, registered with ``os.register_at_fork``): its collections walk only
what it makes, not the parent's heap, and do not write to the inherited objects' pages, which
stay shared with the parent (Python's documentation of ``gc.freeze`` recommends it for fork
without exec).
"""

from __future__ import annotations

import contextlib
import gc
import os
from collections.abc import Iterator

#: A young collection after this many new container objects. The tools build large object graphs
#: that live on (ASTs, the checker's annotations, a run's program and motion queue); with
#: CPython's 700 each young collection scanned the new objects, which survived, and handed them
#: on to be scanned again. Measured (CPU, warm store, 2026-11-25): ``krl diff`` of a 1.9 MB
#: history pair 3.6 -> 1.4 s; the whole runs of the corpus's 90 entry points, each in a fresh
#: process (tools/whole_run_bench.py), 35.3 -> 32.2 s. Python's default costs more as the
#: process holds more (the same diff: 6.6 s after a check and a whole run in the same process).
#: Reference cycles are still collected, after more allocations (100 000 young objects: about
#: 10 MB). A threshold the process had already raised is kept; the older generations' are Python's.
YOUNG_THRESHOLD = 100_000


def _set_thresholds() -> None:
    young, *older = gc.get_threshold()
    if young < YOUNG_THRESHOLD:
        gc.set_threshold(YOUNG_THRESHOLD, *older)


_set_thresholds()


def _inherited() -> None:
    """In a forked child, right after the fork: what the child inherited is frozen for its life
    (as :func:`keep` freezes). Reference counting still frees an inherited object the child
    drops; only inherited reference cycles are never collected in the child (their memory is
    the parent's copy until written)."""
    gc.freeze()


if hasattr(os, "register_at_fork"):        # POSIX; elsewhere nothing forks without exec
    os.register_at_fork(after_in_child=_inherited)


@contextlib.contextmanager
def paused() -> Iterator[None]:
    """No cyclic collection inside the block; the collector is restored as it was (enabled or
    not) when the block ends, also on an exception."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def keep(renew: bool = False) -> None:
    """Freeze every object the collector tracks now (``gc.freeze``) for the life of the
    process. `renew`: unfreeze what earlier calls froze first, so that what has become garbage
    since is collected as usual."""
    if renew:
        gc.unfreeze()
    gc.freeze()
