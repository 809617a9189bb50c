"""Execution contexts and interrupts (reference §5.16-§5.18, §10.4).

Each task (robot program, submit program) has a stack of :class:`Context` objects: the
bottom one is ``main`` (robot) or ``submit``; an interrupt routine runs in an
``interrupt`` context pushed on top of the interrupted one, a TRIGGER action in a
``trigger`` context. No threads: a handler runs nested on the Python stack of the task it
interrupts (its greenlet), at a statement boundary or at an IPO cycle.

:class:`InterruptTable` holds a task's declarations, one :class:`Irq` per number:

* DECL declares (state ``off``); re-declaring a number replaces it;
* ON arms edge detection (the condition's current value is the reference: a condition
  already TRUE does not fire until it has been FALSE); OFF disarms and drops a pending
  event; DISABLE keeps detecting but defers handling (events are buffered); ENABLE
  releases them;
* a rising edge (FALSE -> TRUE) of an armed condition makes the interrupt *pending*; a
  pending, enabled interrupt runs when its number is smaller (= higher priority) than
  the priority of the running context (main: 129, so every interrupt can run there);
  the smallest number runs first; equal or lower priorities wait;
* a poll evaluates a condition again only when something it reads may have changed (its
  *watch*, interp/runtime/watch.py: an I/O change, the clock, a probed state variable; a
  condition over variables at every poll): the edges are those of evaluating at every poll;
* a poll that leaves every armed interrupt *settled* (constant and probed-state conditions,
  nothing pending) in the runtime's state epoch (interp/runtime/core.py
  ``RunClock.state_epoch``) is the last until the epoch changes or an interrupt is declared,
  switched or removed: no poll could evaluate or fire anything before (``settled``);
* a non-GLOBAL declaration is removed when the routine that declared it returns;
  ON/OFF/ENABLE/DISABLE of an undeclared number is error 1430.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .errors import INTERRUPT_NOT_DECLARED, KrlRuntimeError
from .watch import ALWAYS, CLOCK, CONSTANT, IO, SETTLES, stamp_key

MAIN_PRIO = 129
#: False: every armed condition is evaluated at every poll, whatever its watch (the oracle of
#: tests/interp/test_interrupt_watch.py, with :func:`~.watch.stamp_key` patched to None)
WATCHED = True


@dataclass
class Context:
    kind: str                     # main | interrupt | trigger | submit
    prio: int = MAIN_PRIO
    number: int | None = None     # interrupt number
    pos_int: dict | None = None   # $POS_INT of an interrupt context
    axis_int: object = None       # $AXIS_INT
    frame: object = None          # declaring frame of the running interrupt (RESUME)
    interrupted: object = None    # innermost frame of the interrupted level (a debugger's stacks)
    error_proceed: bool = False   # ON_ERROR_PROCEED seen; the next statement of this context takes it


@dataclass
class Irq:
    number: int
    cond: object                  # zero-argument callable -> bool
    handler: object               # zero-argument callable: runs the handler
    name: str                     # handler routine name (trace)
    frame: object                 # the declaring frame (RESUME target, lifetime)
    is_global: bool = False
    line: int | None = None
    on: bool = False
    enabled: bool = True
    last: bool = False
    pending: bool = False
    watch: str = ""               # when the condition is evaluated again (interp/runtime/watch.py)
    seen: object = None           # the watch key of the evaluation that gave `last`
    probes: tuple = ()            # readers of the probed system variables the condition reads
    by_epoch: bool = False        # every probe changes only with the runtime's state epoch
    probe_epoch: object = None    # the state epoch at which `probed` was read
    probed: tuple = ()            # the probes' values at `probe_epoch`
    steady: bool = False          # its value changes only with the I/O image, a statement, a cyclic
                                  # flag or a task's state, never at a step of the moving robot
                                  # (interp/runtime/watch.py ``steady``)


@dataclass
class InterruptTable:
    irqs: dict = field(default_factory=dict)
    armed: int = 0                # number of interrupts switched on (fast test)
    #: the state epoch of the last poll when it left every armed interrupt *settled* (class
    #: CONSTANT, probes read by epoch, nothing pending): until the epoch changes no poll can
    #: evaluate or fire anything (interp/runtime/core.py ``Runtime.quiet_limit``); else None
    settled: object = None

    def declare(self, irq: Irq) -> None:
        if not 1 <= irq.number <= 128:
            raise KrlRuntimeError(f"interrupt priority {irq.number} outside 1..128")
        self.settled = None
        old = self.irqs.get(irq.number)
        if old is not None and old.on:
            self.armed -= 1
        self.irqs[irq.number] = irq

    def _targets(self, number: int | None) -> list[Irq]:
        if number is None:
            return list(self.irqs.values())
        irq = self.irqs.get(number)
        if irq is None:
            raise KrlRuntimeError(f"interrupt {number} not declared", INTERRUPT_NOT_DECLARED)
        return [irq]

    def control(self, action: str, number: int | None, io_version: int = 0, now: float = 0.0,
                written=None) -> None:
        """INTERRUPT ON/OFF/ENABLE/DISABLE of `number` (None: all); ON takes the condition's
        value with the I/O image at `io_version` at simulated time `now` (s), with `written`
        (interp/runtime/watch.py ``CyclicWatch.written``), as reference."""
        self.settled = None
        for irq in self._targets(number):
            if action == "ON":
                if not irq.on:
                    self.armed += 1
                irq.on = True
                irq.seen = None
                irq.last = bool(irq.cond())
                irq.seen = stamp_key(irq.watch, io_version, now, irq.probes, written)
                irq.pending = False
            elif action == "OFF":
                if irq.on:
                    self.armed -= 1
                irq.on = False
                irq.pending = False
            elif action == "DISABLE":
                irq.enabled = False
            elif action == "ENABLE":
                irq.enabled = True
            else:
                raise KrlRuntimeError(f"unknown INTERRUPT action {action}")

    def poll(self, io_version: int = 0, now: float = 0.0, epoch: int | None = None, written=None) -> bool:
        """Evaluate the armed conditions; a rising edge makes the interrupt pending. A
        condition whose watch key (interp/runtime/watch.py :func:`~.watch.stamp_key`, computed
        here inline: this runs before every statement) at `io_version` and simulated time
        `now` (s) and `written` (what may have written a variable since: watch.py
        ``CyclicWatch.written``) is that of its last evaluation keeps its value: nothing it
        reads changed.
        `epoch`: the runtime's state epoch (interp/runtime/scheduler.py ``RunClock.state_epoch``);
        the probes of an interrupt whose probes all change only with it (``by_epoch``) are
        read once per epoch (None: at every poll). Sets :attr:`settled`.
        Returns True when an interrupt is pending, on and enabled afterwards (then
        :meth:`next_ready` may find one to run), False when none is."""
        ready = False
        watched = WATCHED
        settled = watched and epoch is not None
        for irq in tuple(self.irqs.values()):
            if not irq.on:
                continue
            w = irq.watch if watched else ALWAYS
            if w == CONSTANT:
                key = 0
            elif w == IO:
                key = io_version
                settled = False
            elif w == CLOCK:
                key = (io_version, now)
                settled = False
            elif w == SETTLES and written is not None:
                key = (io_version, written)
                settled = False
            else:
                key = None
                settled = False
            if key is not None:
                probes = irq.probes
                if probes:
                    if epoch is not None and irq.by_epoch:
                        if irq.probe_epoch != epoch:
                            irq.probed = (probes[0](),) if len(probes) == 1 else tuple([p() for p in probes])
                            irq.probe_epoch = epoch
                        key = (key, irq.probed)
                    else:
                        settled = False
                        key = (key, (probes[0](),) if len(probes) == 1 else tuple([p() for p in probes]))
                if key == irq.seen:
                    if irq.pending:
                        settled = False
                        if irq.enabled:
                            ready = True
                    continue
            irq.seen = None
            cur = bool(irq.cond())
            if cur and not irq.last:
                irq.pending = True
            irq.last = cur
            irq.seen = key
            if irq.pending:
                settled = False
                if irq.enabled:
                    ready = True
        self.settled = epoch if settled else None
        return ready

    def next_ready(self, running_prio: int) -> Irq | None:
        best = None
        for irq in self.irqs.values():
            if irq.pending and irq.on and irq.enabled and irq.number < running_prio:
                if best is None or irq.number < best.number:
                    best = irq
        return best

    def remove_frame(self, frame) -> None:
        """The routine ``frame`` returned: drop its non-GLOBAL declarations."""
        for n, irq in list(self.irqs.items()):
            if irq.frame is frame and not irq.is_global:
                self.settled = None
                if irq.on:
                    self.armed -= 1
                del self.irqs[n]
