"""How a command ends on SIGINT (Ctrl-C) and SIGTERM (``timeout``, a CI cancel, ``kill``): the
same way for every command (issue 74, docs/security.md "Faults").

While :func:`handling` is active, SIGTERM raises :class:`Terminated` in the main thread, as
SIGINT raises KeyboardInterrupt (Terminated is one), so ``finally`` blocks and the
``except BaseException`` clean-ups of the durable writes (krl/durable.py) run: nothing is left
half-written. The command line (app/__init__.py) then prints ``interrupted`` on stderr and
exits with :func:`exit_code`: 130 for SIGINT, 143 for SIGTERM (128 + the signal's number, the
shells' convention, as ``krl run`` always had for Ctrl-C).

A process forked from the command (a worker of the parse pool, krl/pool.py) does not inherit
the conversion: there SIGTERM keeps its default action (the pool stops its workers with it).
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

#: the word every interrupted command prints on stderr
MESSAGE = "interrupted"


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived (raised by the handler of :func:`handling`)."""

    signum = signal.SIGTERM


def exit_code(exc: BaseException) -> int:
    """128 + the signal's number: 143 for :class:`Terminated`, 130 for a KeyboardInterrupt."""
    return 128 + int(getattr(exc, "signum", signal.SIGINT))


def name(exc: BaseException) -> str:
    """The signal's name: SIGTERM for :class:`Terminated`, SIGINT for a KeyboardInterrupt."""
    return signal.Signals(exit_code(exc) - 128).name


@contextmanager
def handling() -> Iterator[None]:
    """SIGTERM raises :class:`Terminated` in this process while the block runs (SIGINT raises
    KeyboardInterrupt, Python's default, re-installed if something had replaced it). The
    previous handlers come back at the end."""
    if threading.current_thread() is not threading.main_thread():
        yield                              # signals reach only the main thread's handlers
        return
    owner = os.getpid()

    def on_term(signum, frame):
        if os.getpid() != owner:           # a forked worker: the default action (end now)
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
            return
        raise Terminated()

    old_term = signal.signal(signal.SIGTERM, on_term)
    old_int = signal.getsignal(signal.SIGINT)
    if old_int not in (signal.SIG_IGN, None):  # a background job's ignored SIGINT stays ignored
        signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        # (None: a handler not installed from Python, which cannot be put back from here)
        signal.signal(signal.SIGTERM, old_term if old_term is not None else signal.SIG_DFL)
        if old_int is not None:
            signal.signal(signal.SIGINT, old_int)
