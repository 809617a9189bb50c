"""Cyclic evaluation of a run (reference §5.14, §5.15): :class:`Cyclic` (``Runtime.cyclic``),
what ``ANOUT ON``, ``ANIN ON`` and ``$CYCFLAG[n] = expr`` switch on, for both interpreters.

It holds now: ``handles``, the controller's handle (robot/signals.py ``Signals.add_cyclic``) of each
cyclic evaluation by its key (("cyclic flag", name), ("analog output", channel key), ("analog
input", channel key)); ``restless``, the keys of the cyclic flags whose expression does not
settle (interp/runtime/watch.py ``settles``); and, by ``id`` of the assignment, how a cyclic
flag's expression is evaluated again (decided once per statement: at every IPO cycle, when a
statement ran or the I/O image or a flag changed, or, over the signals and constants only, when
a signal or the flags changed). Each evaluation runs once per
IPO cycle; an error in it becomes a run-time error of the robot program at its next
resumption (``Task.pending_error``).
"""

from __future__ import annotations

from krl.ast import nodes as N
from robot.errors import RobotError

from .errors import KrlRuntimeError
from .watch import CONSTANT, IO, SETTLES, settles, split_watch, watch_of


class Cyclic:
    """The cyclic evaluations of one run (module docstring)."""

    __slots__ = ("controller", "sysvars", "clock", "spin", "watch", "robot", "handles", "restless", "_settling")

    def __init__(self, controller, sysvars, clock, spin, watch, robot) -> None:
        """For the run of `controller` (robot/controller.py: its signals run the evaluations),
        `sysvars` (sysvars.SysVars: ``$CYCFLAG``), `clock` (scheduler.py RunClock: the running
        task), `spin` (spin.py SpinWatch: the running statement's nodes), `watch` (watch.py
        CyclicWatch: when a cyclic flag is evaluated again) and the robot task `robot()` gives
        (an evaluation's error becomes its error)."""
        self.controller = controller
        self.sysvars = sysvars
        self.clock = clock
        self.spin = spin
        self.watch = watch
        self.robot = robot
        self.handles: dict = {}         # key -> the controller's handle
        #: the cyclic flags whose expression does not settle (watch.py ``settles``: it reads a
        #: timer, the robot's position, a call...): evaluated at every IPO cycle, they may change
        #: $CYCFLAG at any cycle, so a spin that reads $CYCFLAG is not parked beside one
        self.restless: set = set()
        self._settling: dict = {}       # id(assignment) -> how its cyclic flag is evaluated again (_settles)

    def analog_inputs(self) -> bool:
        """An ``ANIN ON`` is on."""
        return any(k[0] == "analog input" for k in self.handles)

    def on(self, key, fn) -> None:
        """Evaluate ``fn()`` once per IPO cycle until :meth:`off` (``ANOUT ON``,
        ``ANIN ON``, ``$CYCFLAG[n] = expr``; §5.14, §5.15). An error in ``fn`` becomes a
        run-time error of the robot program at its next resumption."""
        self.off(key)
        robot = self.robot()
        # a cyclic flag's expression over variables and I/O is evaluated again only when one of
        # them may have changed (interp/runtime/watch.py CyclicWatch); every cyclic flag counts
        # the changes it makes to $CYCFLAG
        flag = key[0] == "cyclic flag"
        watch = self.watch
        kind = self._settles() if flag else None
        memo = kind is not None
        io_only = kind == IO
        if flag and not memo:
            self.restless.add(key)
        cyc = self.sysvars.store.get("$CYCFLAG") if flag else None
        ctl = self.controller
        seen = [None]

        def moment():
            # the key of the present moment (None: evaluate); an expression over the signals and
            # constants only: the signals' changes (each one is logged: robot/io.py; a timer's
            # write moves the I/O image's version, not the log) and the flags as the last
            # evaluation left them
            k = watch.key()
            return (len(ctl.io.log), tuple(cyc.data)) if io_only and k is not None else k

        def tick(ctl):
            if memo:
                k = moment()
                if k is not None and k == seen[0]:
                    return
            before = tuple(cyc.data) if cyc is not None else None
            try:
                fn()
            except KrlRuntimeError as e:
                self.off(key)
                if robot is not None and robot.pending_error is None:
                    robot.pending_error = RobotError(e.message, e.number)
                return
            if before is not None and tuple(cyc.data) != before:
                watch.version += 1
            if memo:
                seen[0] = moment()
        self.handles[key] = ctl.signals.add_cyclic(tick)
        watch.anin = self.analog_inputs()

    def _settles(self) -> str | None:
        """How the cyclic flag the running statement switches on is evaluated again, decided once
        per statement (an SPS.SUB switches its flags on again in every pass: the analysis cost
        about 40 µs each time): None, at every IPO cycle; :data:`~.watch.IO`, its expression
        reads the signals ($IN, $OUT, $ANIN, $ANOUT, a SIGNAL over them) and constants only
        (:func:`~.watch.watch_of`: no probed state), so its value changes only when a signal
        changes (the I/O log grows: a submit program's timers do not count); :data:`~.watch.SETTLES`, it
        :func:`~.watch.settles` (a statement, the I/O image or a cyclic flag changes it)."""
        task = self.clock.current_task
        at = task.at if task is not None else None
        for node in (self.spin.statements(at) or ()) if at is not None else ():
            if isinstance(node, N.Assign):
                got = self._settling.get(id(node), False)
                if got is False:
                    got = None
                    if settles(node.value):
                        cls, probes = split_watch(watch_of(node.value))
                        got = IO if cls in (CONSTANT, IO) and not probes else SETTLES
                    self._settling[id(node)] = got
                return got
        return None

    def off(self, key) -> None:
        h = self.handles.pop(key, None)
        self.restless.discard(key)
        if h is not None:
            self.controller.signals.remove_cyclic(h)
            self.watch.anin = self.analog_inputs()
