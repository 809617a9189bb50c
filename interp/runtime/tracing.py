"""Where a run's interpreters trace now: :class:`Tracing` (``Runtime.tracing``).

It holds now one writer (robot.trace.TraceWriter, or None: nothing is traced), the run's
sinks' trace at the start (interp/run.py RunSinks), None while an evaluation from outside
the program runs (interp/runtime/core.py ``Runtime.evaluation``: a debugger's watch) and
once the run has ended (``Runtime.run``: the suspended tasks unwind untraced). The runtime's
parts that write trace events (calls.py, interrupts.py, stepping.py, autocell.py) take this
holder when they are built and read :attr:`Tracing.writer` at each event, so that the
runtime's changes reach them without their holding the runtime.
"""

from __future__ import annotations


class Tracing:
    """The trace a run writes to now (module docstring): ``writer``, a
    robot.trace.TraceWriter or None."""

    __slots__ = ("writer",)

    def __init__(self, writer=None) -> None:
        self.writer = writer
