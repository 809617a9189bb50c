"""What a native implementation may do on its run: :class:`NativeContext` (issue 87 item 4).

It holds now the calls a system function of KRL (this package's ``fn(ctx, args)``) makes on
the run that calls it, and nothing else: the controller it reads (its robot model, actual
axes, network hub, message log, clock), the system variables, the names (VARSTATE's text),
the message window, $ERR, the $CMD program states, the running task, the waits of the advance and main run (an
advance-run stop, an IPO cycle given back, a blocking call's cycle), PULSE, the run's notes,
its random numbers and its clock reads (the fast-forward's, interp/runtime/idle.py: a native
that reads the clock says so here), and the answers ``INVERSE`` keeps for the run (invmemo.py). The runtime (interp/runtime/core.py) builds one per run
with exactly these collaborators; a native writes no attribute of the run: what it changes
goes through a call here or through a part's method (the message window's
``messages.add``, the system variables' ``sysvars.link_base``).
"""

from __future__ import annotations

import random

from .invmemo import InverseMemo


class NativeContext:
    """The calls a native may make on its run (module docstring). Attributes, read: ``controller``
    (robot/controller.py Controller), ``sysvars`` (interp/runtime/sysvars.py SysVars), ``names``
    (names.py Names), ``messages`` (messages.py MessageWindow), ``errstate`` (errstate.py
    ErrorState), ``programs`` (cmdchannel.py ProgramControl: the $CMD commands). Callables given by the run: ``wait_main_run(task)``, ``yield_cycle(task)``,
    ``block_cycle(task)``, ``pulse(ref, level, seconds)``, ``message(text)``, ``clock_read()``;
    ``inverse_memo``: the run's invmemo.py ``InverseMemo`` (made here: one per run)."""

    __slots__ = ("controller", "sysvars", "names", "messages", "errstate", "programs", "wait_main_run", "yield_cycle",
                 "block_cycle", "pulse", "message", "clock_read", "_clock", "_noted", "_random", "inverse_memo")

    def __init__(self, controller, sysvars, names, messages, errstate, programs, clock, noted: set,
                 rng: random.Random, *, wait_main_run, yield_cycle, block_cycle, pulse, message, clock_read) -> None:
        """`clock`: the run's scheduler.RunClock (its running task); `noted`: the notes the run
        gave (each once, :meth:`note_once`); `rng`: the run's seeded random generator; the
        keyword callables as the class docstring lists them."""
        self.controller, self.sysvars, self.names = controller, sysvars, names
        self.messages, self.errstate, self.programs = messages, errstate, programs
        self._clock, self._noted, self._random = clock, noted, rng
        self.wait_main_run, self.yield_cycle, self.block_cycle = wait_main_run, yield_cycle, block_cycle
        self.pulse, self.message, self.clock_read = pulse, message, clock_read
        self.inverse_memo = InverseMemo()

    def current_task(self):
        """The task that runs the call (scheduler.Task)."""
        return self._clock.current_task

    def note_once(self, key: str, text: str) -> None:
        """The controller message `text`, given once per run for `key`."""
        if key not in self._noted:
            self._noted.add(key)
            self.message(text)

    def uniform(self, lo: float, hi: float) -> float:
        """A number drawn from the run's seeded random generator in [lo, hi] (random.uniform).
        The value differs at each call: the native that draws it declares ``reads=CLOCK``
        (FRAND), so the registry reads the clock for it (natives/registry.py)."""
        return self._random.uniform(lo, hi)
