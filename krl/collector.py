"""The process's one policy on Python's cyclic garbage collector (the ``gc`` module): every
pause and every freeze of the project goes through here (tests/test_collector.py holds the
rest of the code to it).

Its thresholds are set when this module is first imported. Every process of the tools imports
it: krl.workspace (what loads KRL: the `krl` command's, the pool's workers, a Dask worker's
task, the tests') and the robot package (``python -m robot.bench``) import it:
:data:`YOUNG_THRESHOLD` new container objects before a young collection, not CPython's 700.

Three uses, each measured where it is used:

* :func:`paused`: no collection while a batch of long-lived objects is built (a workspace's
  ASTs, a parse tree rebuilt from a worker's answer, a whole check); the collector runs again
  afterwards as it was.
* :func:`keep`: what the process made so far lives as long as the process (the language
  server's checked workspace, a debug session's program): it is moved to the collector's
  permanent generation (``gc.freeze``) and the process is marked as one that keeps frozen
  objects. ``renew=True`` first returns what an earlier call froze (``gc.unfreeze``), so that
  what has died since is collected.
* :func:`frozen_during`: a bounded job (one KRL run, interp/runtime/core.py) freezes its
  set-up so that the collections while it runs walk only what it makes, and unfreezes it at
  the end, unless the process keeps frozen objects (then an unfreeze would return those too,
  and the job leaves the permanent generation alone).

A process forked from one of the tools (krl.pool's workers, forked from the command that
loaded the parser and often whole backups) starts with everything it inherited frozen, and keeps
it so (:func:`_inherited`, registered with ``os.register_at_fork``): its collections walk only
what it makes, not the parent's heap, and do not write to the inherited objects' pages, which
stay shared with the parent (Python's documentation of ``gc.freeze`` recommends it for fork
without exec).

Whether the process keeps frozen objects is recorded here, in O(1). CPython's
``gc.get_freeze_count()`` walks the whole permanent generation (3.11: ``gc_list_size``): 0.1 s
per call with 6 million frozen objects (2026-11-25), paid by every KRL run of a test worker
that had run the language server's checks in-process before it.
"""

from __future__ import annotations

import contextlib
import gc
import os
from collections.abc import Iterator

_kept = False      # the process keeps frozen objects (keep() was called)

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
    (the child is a process that keeps frozen objects, :func:`keep`). Reference counting still
    frees an inherited object the child drops; only inherited reference cycles are never
    collected in the child (their memory is the parent's copy until written)."""
    global _kept
    gc.freeze()
    _kept = True


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
    global _kept
    if renew:
        gc.unfreeze()
    gc.freeze()
    _kept = True


@contextlib.contextmanager
def frozen_during() -> Iterator[None]:
    """The objects that exist now are out of the collector's generations while the block runs
    and back in them after it; nothing is done when the process keeps frozen objects or the
    collector is off."""
    froze = not _kept and gc.isenabled()
    if froze:
        gc.freeze()
    try:
        yield
    finally:
        if froze:
            gc.unfreeze()
