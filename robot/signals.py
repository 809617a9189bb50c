"""What changes the simulated controller's I/O without the program: the I/O image's side of
each IPO cycle (robot/controller.py's ``Controller.signals``; reference §5.12-§5.15, §7.1).

:class:`Signals` holds the :class:`~robot.io.IOImage` (``io``: the same object as the
controller's), the pending PULSE resets (``pulses``: ``(t_end s, output n, level)``, reference
§5.12), the cyclic hooks (ANIN ON, ANOUT ON, ``$CYCFLAG``, a display: ``fn(controller)`` once per
IPO cycle), the cell's stimuli (robot/stimuli.py ``Stimulus``: timed, on a motion's phase, on
reaching a point) and reactive rules (robot/cellrules.py ``Rule``), and the network hub
(net/hub.py ``Network``: its partners answer on the I/O too). Times are in s of simulated time,
cycles are IPO cycles (``time = k · dt``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .cellrules import Rule, rules_may_fire, step_rules
from .io import IOImage
from .stimuli import Stimulus

EPS = 1e-9


class Signals:
    """The I/O side of the main run (module docstring).

    Args:
        io: the controller's I/O image.
        stimuli: the cell's stimuli (the list is this object's; the automatic cell adds to it).
        rules: the cell's reactive rules.
        network: the network hub or None.
        dt: the IPO cycle (s).
    """

    def __init__(self, io: IOImage, stimuli: list[Stimulus], rules: list[Rule], network: Any, dt: float) -> None:
        self.io = io
        self.stimuli = stimuli
        self.rules = rules
        self.network = network
        self.dt = dt
        self._dt_ms = int(round(dt * 1000))
        self.pulses: list[tuple[float, int, bool]] = []
        self.cyclic: dict[int, Callable[[Any], None]] = {}
        self._cyclic_next = 1
        self._rules_seen = None         # what the rules' conditions last saw (cellrules.step_rules)
        #: called before a stimulus ``reached`` sets its signals (:meth:`reach`): the run's spin watch
        #: catches its parked passes up over the inputs as they were (interp/runtime/spin.py)
        self.on_reach: Callable[[], None] | None = None


    def set_reach_hook(self, hook: Callable[[], None] | None) -> None:
        """`hook()` is called by the step that fires a stimulus set on reaching a point, just
        before it sets the inputs (:attr:`on_reach`: the spin watch's catch-up,
        interp/runtime/spin.py ``SpinWatch.reaching``); None: no hook."""
        self.on_reach = hook
    def pulse(self, n: int, level: bool, duration_s: float, source: str = "program") -> None:
        """``PULSE($OUT[n], level, duration)``: set now, set to ``NOT level`` after
        ``duration_s`` (at the first IPO cycle at or after it; reference §5.12)."""
        self.io.set_out(n, level, source)
        self.pulses.append((self.io.now + float(duration_s), int(n), not level))

    def add_cyclic(self, fn: Callable[[Any], None]) -> int:
        """Call ``fn(controller)`` once per IPO cycle after the setpoint is computed
        (ANOUT ON, ANIN ON, $CYCFLAG). Returns a handle for :meth:`remove_cyclic`."""
        h = self._cyclic_next
        self._cyclic_next += 1
        self.cyclic[h] = fn
        return h

    def remove_cyclic(self, handle: int) -> None:
        """Stop the cyclic hook `handle` (:meth:`add_cyclic`); an unknown handle is ignored."""
        self.cyclic.pop(handle, None)

    def may_change(self) -> bool:
        """True if an input or output can still change without the program doing anything:
        a stimulus not yet applied, a PULSE not yet reset, a cyclic hook, a running timer, a
        cell rule with an answer pending or about to fire (for deadlock detection of WAIT FOR)."""
        return (any(not st.fired for st in self.stimuli) or bool(self.pulses)
                or bool(self.cyclic) or not all(self.io.timer_stop[1:])
                or (bool(self.rules) and rules_may_fire(self.rules, self.io))
                or (self.network is not None and self.network.may_change()))

    def next_event_cycle(self, k: int) -> int | None:
        """The first IPO cycle after cycle `k` at which the controller changes something by
        itself while the program does nothing: a timed stimulus, a stimulus delay that runs, a
        cell rule's pending answer, a PULSE's reset, the network's next message (net.hub.Network:
        any cycle while a partner is attached, the next recorded one of a replay). None when
        there is none. (A cycle ``k`` is the one whose step makes ``time = k · dt``.)"""
        times = [st.at if st.at is not None else st.due for st in self.stimuli
                 if not st.fired and (st.at is not None or st.due is not None)]
        times += [r.due[0] for r in self.rules if r.due]
        times += [te for te, _, _ in self.pulses]
        net = self.network.next_event_cycle(k) if self.network is not None else None
        if not times:
            return net
        nxt = max(k + 1, int(math.ceil(min(times) / self.dt - EPS)))
        return nxt if net is None else min(nxt, net)

    def before_motion(self, t: float) -> None:
        """This IPO cycle's I/O before the setpoint (time `t`): the timers count, due PULSEs
        reset, due stimuli apply, the cell's rules step."""
        io = self.io
        io.tick_timers(self._dt_ms)
        if self.pulses:
            keep = []
            for (te, n, lvl) in self.pulses:
                if t >= te - EPS:
                    io.set_out(n, lvl, "pulse")
                else:
                    keep.append((te, n, lvl))
            self.pulses = keep
        if self.stimuli:
            for st in self.stimuli:
                if st.fired:
                    continue
                due = st.at if st.at is not None else st.due
                if due is not None and t >= due - EPS:
                    st.fired = True
                    for name, v in st.set.items():
                        io.set_signal(name, v, st.source)
                    if st.on_fire is not None:
                        st.on_fire(t)
        if self.rules:
            self._rules_seen = step_rules(self.rules, io, t, self.dt, self._rules_seen)

    def motion_phase(self, motion_id: int, line: int | None, phase: str, t: float) -> None:
        """A motion reached `phase` at time `t`: the stimuli waiting for it start their delay."""
        for st in self.stimuli:
            if (not st.fired and st.due is None and st.phase == phase
                    and st.matches_motion(motion_id, line)):
                st.due = t + st.delay

    def reach_waits(self) -> bool:
        """Whether a stimulus waits for the robot to come within its distance of a motion's end
        point (:meth:`reach` has something to test: the main run gathers its segments only then)."""
        for st in self.stimuli:       # _waits_for_reach, inline (every moving IPO cycle asks)
            if st.reached_mm is not None and not st.fired and st.due is None:
                return True
        return False

    def reach(self, active: list, q: np.ndarray, t: float) -> None:
        """The stimuli waiting for the robot to come within their distance of a motion's end
        point (``reached``): `active` the segments the main run executes, `q` the setpoint,
        `t` the time."""
        for st in self.stimuli:
            if not _waits_for_reach(st):
                continue
            for seg in active:
                if st.matches_motion(seg.id, seg.req.line):
                    p_end = seg.model.tcp(seg.q1, seg.tool_T, seg.base_inv_T)[:3, 3]
                    here = seg.model.tcp(q, seg.tool_T, seg.base_inv_T)[:3, 3]
                    if float(np.linalg.norm(here - p_end)) <= st.reached_mm + 1e-9:
                        st.due = t + st.delay
                        if st.delay <= 0:
                            st.fired = True
                            if self.on_reach is not None:
                                self.on_reach()
                            for name, v in st.set.items():
                                self.io.set_signal(name, v, st.source)


def _waits_for_reach(st) -> bool:
    """Whether stimulus `st` still waits for the robot to come within its distance (``reached``)
    of a motion's end point: one is given, and it has neither fired nor been scheduled."""
    return st.reached_mm is not None and not st.fired and st.due is None


__all__ = ["Signals"]
