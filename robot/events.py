"""What the simulated controller's main run tells: the events of each IPO cycle and the
trace it writes (robot/controller.py's ``Controller.log``; docs/architecture.md, "Robot
interface"; the trace's kinds: robot/trace.py).

The event classes are what :meth:`robot.controller.Controller.step` returns (times in s of
simulated time). :class:`EventLog` holds this cycle's events (``events``: the controller's step
starts a new list each IPO cycle and returns it), the
:class:`~robot.trace.TraceWriter` (``trace``, None: no trace), the message watchers (the
pendant's message window) and whether the ``end`` event was written.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from .errors import RobotError
from .motion import MotionRequest, Trigger


@dataclass(frozen=True)
class MotionEvent:
    """A motion reached a phase: ``start``, ``blend_start``, ``blend_end`` or ``end``."""

    t: float
    id: int
    phase: str
    request: MotionRequest = field(repr=False, compare=False)
    kind: str = "motion"


@dataclass(frozen=True)
class TriggerEvent:
    """A TRIGGER's switching point was reached: the interpreter runs ``trigger.action``
    now, as a short interrupt-like context (no motion statements)."""

    t: float
    id: int
    index: int
    trigger: Trigger
    kind: str = "trigger"


@dataclass(frozen=True)
class IoEvent:
    """A signal changed (``source``: program, trigger, pulse, stimulus)."""

    t: float
    signal: str
    value: Any
    source: str
    kind: str = "io"


@dataclass(frozen=True)
class MessageEvent:
    """A controller message (e.g. "approximation not possible")."""

    t: float
    text: str
    id: int | None = None
    kind: str = "message"


@dataclass(frozen=True)
class ErrorEvent:
    """A motion error in the main run (workspace error, software limit switch, ...): the
    robot stopped, the motion queue was discarded. The interpreter raises ``error``."""

    t: float
    error: RobotError
    id: int | None = None
    kind: str = "error"


Event = MotionEvent | TriggerEvent | IoEvent | MessageEvent | ErrorEvent


class EventLog:
    """This cycle's events and the trace (module docstring).

    Args:
        trace: the TraceWriter or None.
        now: the simulated time (s) now: the controller's clock.
    """

    def __init__(self, trace: Any, now: Callable[[], float]) -> None:
        self.trace = trace
        self.now = now
        self.events: list[Event] = []
        self._message_watchers: list[Callable] = []
        self._ended = False

    def io(self, t: float, name: str, value: Any, source: str) -> None:
        """Signal `name` took `value` at `t` (the I/O image's ``on_change``, a workspace's state)."""
        self.events.append(IoEvent(t, name, value, source))
        if self.trace is not None:
            self.trace.write("io", t, signal=name, value=value, source=source)

    def message(self, text: str, motion_id: int | None = None, number: int | None = None) -> None:
        """Log a controller message (event + trace), and tell the watchers (:meth:`watch_messages`)."""
        t = self.now()
        self.events.append(MessageEvent(t, text, motion_id))
        if self.trace is not None:
            self.trace.write("message", t, text=text, id=motion_id, number=number)
        for fn in self._message_watchers:
            fn(text, motion_id, number)

    def watch_messages(self, fn: Callable[[str, int | None, int | None], None]) -> None:
        """Call ``fn(text, motion_id, number)`` for each message (the pendant's message window)."""
        self._message_watchers.append(fn)

    def finish(self, reason: str = "program_end", **fields: Any) -> None:
        """Write the ``end`` trace event (once); ``fields`` add where and why (the
        interpreters pass text, number, file, line and context)."""
        if not self._ended and self.trace is not None:
            self.trace.write("end", self.now(), reason=reason, **fields)
        self._ended = True


__all__ = ["MotionEvent", "TriggerEvent", "IoEvent", "MessageEvent", "ErrorEvent", "Event", "EventLog"]
