"""$ERR and ON_ERROR_PROCEED of a run (reference §5.19): :class:`ErrorState`
(``Runtime.errstate``), for both interpreters.

It holds nothing of its own now: $ERR is each task's (``Task.err``, an ERROR_T Struct made on
first read, with its message text in ``Task.err_text``), and the ON_ERROR_PROCEED flag is the
running context's (``Context.error_proceed``); this class reads and fills them for the running
task of its runtime. Raises nothing.
"""

from __future__ import annotations

from .errors import KrlRuntimeError
from .memory import Frame
from .scheduler import break_quiet
from .sysvars import struct_of
from .values import Arr, EnumValue, Struct
from .convert import assign_into


class ErrorState:
    """$ERR and ON_ERROR_PROCEED of the running task (module docstring)."""

    __slots__ = ("clock", "robot")

    def __init__(self, clock, robot) -> None:
        """For the run whose counters are `clock` (scheduler.py RunClock: its running task) and
        whose robot task `robot()` gives (None before it is added): $ERR outside a task is the
        robot task's."""
        self.clock = clock
        self.robot = robot

    def current_err(self) -> Struct:
        task = self.clock.current_task or self.robot()
        if task.err is None:
            task.err = struct_of("ERROR_T", {})
            self.clear_err(task.err)
        return task.err

    def clear_err(self, e: Struct) -> None:
        for k, v in list(e.f.items()):
            if isinstance(v, Arr):
                v.data[:] = ["\0"] * len(v.data)
            elif k in ("NUMBER", "INT_PRIO", "LINE_NR"):
                e.f[k] = 0
        e.f["INTERPRETER"] = EnumValue("R_INT")
        e.f["INT_TYPE"] = EnumValue("INT_NONE")
        e.f["TRIGGER_TYPE"] = EnumValue("NONE")
        if self.clock.current_task is not None:
            self.clock.current_task.err_text = ""

    def take_error_proceed(self) -> bool:
        """True (and reset) if ON_ERROR_PROCEED preceded the statement about to run. Every
        statement takes it, whether or not it can fail (§5.19: it covers the *next*
        statement only); the flag belongs to the running context, so an interrupt routine
        or a TRIGGER action that runs before that statement neither takes nor sees it
        (docs/architecture.md, "Choices on the reference's open points")."""
        ctx = self.clock.current_task.contexts[-1]
        p = ctx.error_proceed
        ctx.error_proceed = False
        return p

    def on_error_proceed(self) -> None:
        task = self.clock.current_task
        task.contexts[-1].error_proceed = True
        break_quiet(task)

    def record_error(self, err: KrlRuntimeError, frame: Frame | None) -> None:
        """A statement under ON_ERROR_PROCEED failed: fill $ERR and go on (§5.19)."""
        task = self.clock.current_task
        e = self.current_err()
        e.f["NUMBER"] = err.number if err.number is not None else 1
        e.f["LINE_NR"] = err.line or task.line or 0
        e.f["INTERPRETER"] = EnumValue("R_INT" if task.kind == "robot" else "S_INT")
        ctx = task.context
        e.f["INT_TYPE"] = EnumValue("INT_IR" if ctx.kind == "interrupt" else "INT_NONE")
        e.f["INT_PRIO"] = ctx.number or 0
        for key, text in (("MODULE", frame.module.name if frame and frame.module else ""),
                          ("UP_NAME", frame.name if frame else "")):
            arr = e.f.get(key)
            if isinstance(arr, Arr):
                assign_into(arr, text[: len(arr.data)])
        task.err_text = err.message

    def err_message(self, e: Struct) -> str:
        task = self.clock.current_task
        return getattr(task, "err_text", "") or f"error {e.f.get('NUMBER')}"
