"""Turns: the robots of a cell that nothing couples run several IPO cycles each in turn, not one
cycle each (issue 89; docs/cells.md "Speed": four runs taking turns every cycle cost about 8 %
more CPU than each run alone, the cell's loop between their cycles about 7 % more).

A cell is *uncoupled* (:func:`uncoupled`) when nothing of it reads two robots' states of the same
cycle except the deadlock test, the RoboTeam release, the robots' own workspaces and the contacts
between robots: no wire, no PLC, no zone, and no debugger's hooks or network partner on any robot
(their timing is the one clock's). Robots within each other's reach take turns too (since
2026-11-28): a collision is reported, never acted on, so the cell keeps each robot's pose of each
cycle of a turn and checks them once every robot has passed the cycle (interp/cellcontacts.py
``record``, ``flush``: the collisions of the cycle-by-cycle run). A robot is
*plain* (:func:`plain`) while it does nothing another robot's cycle reads: not blocked in a wait
only a partner could end, not waiting at a synchronised motion, monitoring no workspace, with no
network partner or RSI polled (net/hub.py ``polling``: its exchanges keep the one clock's time).

:func:`take_turns` runs each robot, in the cell's order, up to the turn's last cycle, and stops a
robot's turn after the first cycle that leaves it not plain, or in which it offers to jump (the
offer answered 0: an ordinary cycle, as the cell answers an offer not every robot makes); the
cycles in which nothing of that can change (its held run yields None: interp/runtime/scheduler.py
``Scheduler.cycles``) pass without a look (:func:`_plain_turn`), and a turn after one every robot
ran through is twice as long, up to :data:`TURN_CYCLES_MAX` (interp/robotcell.py). Every
cycle of a robot before its turn's last was plain, so the cell (interp/robotcell.py ``run_cell``)
then catches the robots behind up, cycle by cycle, reading a robot that is ahead as plain: the
deadlock test, the release of synchronised motions and the workspaces' conflicts of each cycle
are those of the cycle-by-cycle run, and each robot's own run (its trace, its I/O, its end) is
the same, since nothing else reaches it (tests/interp/test_robotcell_turns.py). A robot that
offers to jump stops its turn at the offer, unanswered: the cell answers it with the others'
cycle (interp/robotcell.py ``_step``), so a jump comes in the cycle it comes cycle by cycle.

A cell coupled by wires alone (:func:`wired`) takes :class:`WiredTurns`: robots that move while
the robots wired to them are *held* (:func:`held_test`: blocked, their outputs unable to change
before an input does) or move after them, given their logged output changes cycle by cycle,
each input every robot reads in each cycle the value it reads cycle by cycle (docs/cells.md
"Wires in turns: the decision"; tests/interp/test_cell_wiredturns.py).
"""

from __future__ import annotations

from bisect import bisect_right
from itertools import islice

from interp.runtime.scheduler import RAN

#: IPO cycles of one robot's first turn (12.3 s; docs/cells.md "Speed": 16 recovered little of the
#: cost, 256 about half, 1,024 about all, in one measure each), and of a turn after one that some robot
#: cut short (interp/robotcell.py ``run_cell``)
TURN_CYCLES = 1024
#: the longest turn (49 s): a turn after one every robot ran through is twice as long, up to this
#: (since 2026-11-29 22:45 UTC; fewer turns, fewer contact checks after them: docs/cells.md "Speed")
TURN_CYCLES_MAX = 4096


def uncoupled(cell, runs) -> bool:
    """Whether `cell` (interp/robotcell.py RobotCell) with its `runs` couples its robots only
    through what :func:`take_turns` stops for (module docstring)."""
    return not cell.wires and cell.plc is None and not cell.zones and \
        not any(r.runtime.stepping.watching for r in runs) and all(plain(r) for r in runs)


def plain(run) -> bool:
    """Robot `run` (interp/robotcell.py RobotRun) now does nothing another robot's cycle reads."""
    return plain_test(run)()


def plain_test(run):
    """:func:`plain` of robot `run` as a function of no argument, its run's parts looked up once
    (:func:`_parts`): called after each cycle of a turn, where :func:`plain`'s lookups cost 2-3 %
    of a moving robot's CPU (docs/cells.md "Speed")."""
    scheduler, team, monitor, net = _parts(run)
    if team is _Nothing and net is _Nothing:
        return lambda: scheduler.blocked is None and monitor.workspaces is None
    return lambda: scheduler.blocked is None and team.at is None and monitor.workspaces is None and not net.polling


class _Nothing:
    """A robot's RoboTeam part or network partners where it has none (:func:`_parts`): never
    at a synchronised motion, never polled."""
    at = None
    polling = False


def _parts(run) -> tuple:
    """What :func:`plain` and :func:`held_test` read of robot `run`: ``(scheduler, team,
    monitor, net)``, its run's for the whole run (interp/runtime/motions.py,
    robot/controller.py); ``team`` and ``net`` :class:`_Nothing` where it has no RoboTeam part
    or no network partner that polls."""
    rt = run.runtime
    ctl = rt.controller
    team = rt.motions.team if rt.motions.team is not None else _Nothing
    net = getattr(ctl, "network", None)
    return rt.scheduler, team, ctl.monitor, net if net is not None and hasattr(net, "polling") else _Nothing


def take_turns(live: list, turn: int, ended: dict, watch, pending: dict) -> list:
    """Each robot of `live` ((RobotRun, its cycles, its task), in the cell's order, all at one
    cycle) runs up to `turn` cycles (module docstring). `watch(item)` gives, for robot `item`,
    ``(wait, keep)``: ``wait(t, changed)``, the cell's WAIT FOR bookkeeping after a cycle that
    began at `t` (s), `changed` the wires that changed the robot's inputs for it (none here),
    called while the robot's task waits and after, as long as it returns True (the wait still
    counted), and ``keep``, None or the robot's interp/cellkeep.py ``Keeper``: the turn's cycles
    kept for the contact check (``begin`` and ``end`` around the turn; in a cycle ``pose_to(pose)``
    where the robot's compiled IPO cycle does not keep its pose itself, and ``note`` when its main
    runs changed). The loop calls nothing else of the cell's in a cycle (before 2026-11-29 two
    functions and the controller's ``cycle`` property a cycle, later the plain test; before
    2026-11-29 19:30 UTC a pose and a motion appended a cycle: docs/cells.md "Speed"). Returns
    the robots still running; `ended` gets each robot that ended: its last cycle; `pending` each
    robot that stopped at an offer to jump: the offer, unanswered (:func:`_turn`)."""
    until = live[0][0].runtime.controller.cycle + turn
    return [item for item in live if _plain_turn(item, until, ended, watch, pending)]


def _plain_turn(item, until: int, ended: dict, watch, pending: dict) -> int:
    """:func:`_turn` of robot `item` with no wire fed, :func:`plain` as its test and an offer to
    jump always left in `pending` (the robots of :func:`take_turns`), its steady cycles taken
    without a look. The robot's held run yields None after a cycle in which none of its tasks
    ran and its main run's motions stayed (interp/runtime/scheduler.py ``Scheduler.cycles``;
    :data:`~interp.runtime.scheduler.RAN` after the others): after such a cycle neither what
    :func:`plain` reads nor the robot's wait nor its motion request changed, so the turn looks
    at the robot only after the other cycles, where a look after every cycle could find
    something new. The steady cycles pass through ``filter`` and ``islice`` in C, no Python a
    cycle (since 2026-11-29 22:30 UTC; before, the turn's loop tested the offer, the wait, the
    motion and the plain test's parts after every cycle: 0.135 M instructions a simulated second of
    the bench's cell, docs/cells.md "Speed"). Where the robot's compiled IPO cycle does not keep its pose itself
    (the keeper's ``pose_to``) the turn is :func:`_turn`'s, a look a cycle. The same cycles,
    offers, WAIT FOR bookkeeping, kept cycles and ends as :func:`_turn`'s."""
    r, cycles, _ = item
    ctl = r.runtime.controller
    start = ctl.cycle
    if until <= start:
        return 1
    wait, keep = watch(item)
    if keep is not None:
        keep.begin(start + 1, until - start)
        if keep.pose_to is not None:
            return _turn(item, until, plain_test(r), ended, lambda _: (wait, keep), pending, begun=True)
        note, motion = keep.note, keep.motion
        # the motion request from the turn's first cycle on, as the main run stands now: a cycle
        # that changes it yields RAN, and the request after it is noted
        runs = ctl._runs
        note(0, motion())
    scheduler, team, monitor, net = _parts(r)
    fed: list = []              # no wire changes an input here
    out = 0
    looks = filter(None, islice(cycles, until - start))    # the cycles after which to look
    while True:
        got = next(looks, None)
        if got is None:
            out = 1 if ctl.cycle == until else 0    # the turn's cycles all ran, or the run ended
            break
        if got is not RAN:      # an offer, before the cycle's step: the robot stands in it, the cell answers
            pending[r.name] = got
            out = 2
            break
        # the time the cycle began at: the controller's time is its cycle times dt (robot/controller.py)
        wait((ctl.cycle - 1) * ctl.dt, fed)
        if keep is not None and ctl._runs is not runs:
            runs = ctl._runs
            note(ctl.cycle - start - 1, motion())
        if scheduler.blocked is not None or team.at is not None or monitor.workspaces is not None or net.polling:
            out = 1
            break
    if keep is not None:
        keep.end(ctl.cycle - start)
    if out:
        return out
    # the run ended (its generator too), in no step: its last cycle's state kept again, as the
    # cycle it stands at
    wait(ctl.time, fed)
    return _ended(r.name, ctl, keep, ended)


def _ended(name: str, ctl, keep, ended: dict) -> int:
    """Robot `name` ended in its turn (its controller `ctl`): its last cycle's state kept again
    through `keep` (interp/cellkeep.py ``Keeper``, or None) as the cycle it stands at, and
    that cycle into `ended`; 0 (:func:`_turn`'s answer)."""
    if keep is not None:
        keep.again(ctl.cycle)
    ended[name] = ctl.cycle
    return 0


def _turn(item, until: int, still, ended: dict, watch, pending: dict | None, feed=None, begun: bool = False) -> int:
    """Robot `item`'s turn (:func:`take_turns`): its cycles up to the cycle `until` (the
    controller's count), stopping after the first cycle after which ``still()`` is False or, with
    a dict `pending`, at an offer to jump: the offer goes into `pending` unanswered, the robot
    standing in that cycle (the cell answers it with the others' cycle, as cycle by cycle: it
    may jump; before 2026-11-29 a turn answered 0, and a jump every robot offered in that cycle
    came a cycle or more late: the trace's ``idle`` event later). Without `pending` an offer is
    answered 0 (an ordinary cycle: every robot that stops at offers ran the cycle without one).
    `feed`: None, or the changes of the robot's wired inputs its partners ahead made in their
    turns, ``[(cycle, [(wire, value), ...]), ...]`` in the order of the cycles: each set when the
    robot stands at that cycle, before it takes the next (:meth:`WiredTurns._feed`), and the wires
    that changed an input given to ``wait`` with the cycle that read them, as the cell's carry
    at a cycle boundary does. `begun`: the keeper's ``begin`` already called for this turn. 0
    when the robot ended (it goes into `ended` with its last cycle), 2 when it stopped at an
    offer, else 1."""
    r, cycles, task = item
    ctl = r.runtime.controller
    left = total = until - ctl.cycle    # each pass of the loop is one cycle (an offer answered 0 too)
    if left <= 0:
        return 1
    wait, keep = watch(item)
    step, send = cycles.__next__, cycles.send
    if keep is not None:
        if not begun:
            keep.begin(ctl.cycle + 1, left)
        pose_to, pose, note, motion = keep.pose_to, keep.pose, keep.note, keep.motion
    runs = _Nothing             # the main runs the last motion noted was asked at (:func:`_plain_turn`)
    counting = True             # the first cycle asks `wait` whether a wait is counted
    fed: list = []              # the wires that changed an input at this cycle's start
    feed = iter(feed) if feed else None
    nxt = next(feed) if feed is not None else None
    out = 0
    while True:
        now = ctl.time
        if nxt is not None and nxt[0] == until - left:
            fed = _set(ctl.io, nxt[1])
            nxt = next(feed, None)
        elif fed:
            fed = []
        try:
            offer = step()
            if offer is not None and offer is not RAN:
                if pending is not None:
                    pending[r.name] = offer
                    out = 2
                    break
                send(0)
        except StopIteration:
            break
        if counting or task.waiting is not None:
            counting = wait(now, fed)
        if keep is not None:
            if pose_to is not None:
                pose_to(pose)
            if ctl._runs is not runs:
                runs = ctl._runs
                note(total - left, motion())
        left -= 1
        if left <= 0 or not still():
            out = 1
            break
    if keep is not None:
        keep.end(total - left)
    if out:
        return out
    if counting or task.waiting is not None:
        wait(now, fed)
    return _ended(r.name, ctl, keep, ended)


def held_test(run):
    """Whether robot `run` is *held*: blocked in a wait only a partner can end (its scheduler's
    ``blocked``: nothing of its own controller can change, so neither can its outputs while its
    inputs stay), at no synchronised motion, monitoring no workspace, with no network partner
    polled; as a function of no argument (:func:`plain_test`)."""
    scheduler, team, monitor, net = _parts(run)
    return lambda: scheduler.blocked is not None and team.at is None and monitor.workspaces is None \
        and not net.polling


def wired(cell, runs) -> bool:
    """Whether `cell` with its `runs` is coupled by wires alone (no PLC, no zone, no debugger's
    hooks): its robots may take :class:`WiredTurns`."""
    return bool(cell.wires) and cell.plc is None and not cell.zones and \
        not any(r.runtime.stepping.watching for r in runs)


class WiredTurns:
    """Turns in a cell whose robots are wired (docs/cells.md "Wires in turns"). A turn is taken
    when no input changed at the cycle boundary before it and every running robot is plain (a
    *mover*) or held (:func:`held_test`), and no two movers reach each other along the wires
    (either through other robots: :attr:`reach`). The movers run in an order where a mover comes
    after every mover that reaches it, each up to `turn` cycles and no further than the cycle any
    mover reaching it stopped at, stopping after the first cycle that leaves it not plain or in
    which it offers a jump. Each mover's wired outputs are logged after every cycle that changes
    them (:attr:`logs`); a mover that reaches a robot that is not a mover of this turn (a held
    robot, one that ended, or itself) stops after the first such cycle (a partner reads it from
    the next cycle on), one that reaches movers alone runs on, each mover after it given the
    changes of its inputs cycle by cycle from the logs (its *feed*, set at the cycle boundary
    where the cell's carry sets them cycle by cycle; since 2026-11-29, before which every mover
    stopped at a change and a chain of moving robots ran 43 % of its cycles one by one). Then
    each held robot runs up to the cycle the first mover stopped at, stopping when it is no
    longer held: its outputs cannot change before one of its inputs does, and every input it
    reads stays until then (each robot that drives it is held or a mover whose wired outputs
    stayed). The robots behind are caught up cycle by cycle, a wire from a robot ahead carried
    with its source's logged value of the cycle caught up (:meth:`logged`; interp/robotcell.py
    ``run_cell``): every robot reads each input in each cycle as cycle by cycle."""

    def __init__(self, wires) -> None:
        #: robot -> the outputs a wire takes from it
        self.outputs: dict[str, tuple[int, ...]] = {}
        step: dict[str, set] = {}
        for w in wires:
            self.outputs[w.source] = tuple(sorted(set(self.outputs.get(w.source, ())) | {w.output}))
            step.setdefault(w.source, set()).add(w.target)
        #: robot -> the wires into it, in the cell file's order (the order the cell carries them)
        self.into: dict[str, list] = {}
        for w in wires:
            self.into.setdefault(w.target, []).append(w)
        #: robot -> the robots its outputs reach, along one wire or several (through any robot)
        self.reach: dict[str, frozenset] = {}
        for name in step:
            seen, todo = set(), list(step[name])
            while todo:
                n = todo.pop()
                if n not in seen:
                    seen.add(n)
                    todo.extend(step.get(n, ()))
            self.reach[name] = frozenset(seen)
        #: each mover of the last turn: ([cycle], [its wired outputs' values after that cycle]),
        #: from the cycle the turn began at (the values then) to the last that changed them
        self.logs: dict[str, tuple[list, list]] = {}
        self._tests: dict[str, tuple] = {}      # robot -> (plain test, held test)
        self._orders: dict[tuple, list | None] = {}     # movers -> their order (:meth:`_order`)

    def take(self, live: list, turn: int, ended: dict, watch, pending: dict) -> list | None:
        """The turns of `live` (as :func:`take_turns`'s, a mover stopping at an offer to jump
        left in `pending`; ``wait`` of `watch` called with the wires a feed changed, the second
        argument): the robots still running, or None when no turn can be taken now (nothing run)."""
        movers, held = [], []
        tests = self._tests
        for item in live:
            r = item[0]
            if r.name not in tests:
                tests[r.name] = (plain_test(r), held_test(r))
            moves, holds = tests[r.name]
            if moves():
                movers.append(item)
            elif holds():
                held.append(item)
            else:
                return None
        key = tuple(item[0].name for item in movers)
        if key not in self._orders:
            self._orders[key] = self._order(key)
        names = self._orders[key]
        if names is None:
            return None
        order = sorted(movers, key=lambda item: names.index(item[0].name))
        start = live[0][0].runtime.controller.cycle
        stops: dict[str, int] = {}          # each mover run: the cycle it stopped at
        going = set()
        logs = self.logs = {}
        moving = frozenset(key)
        reach = self.reach
        for item in order:
            r = item[0]
            name = r.name
            until = min([start + turn] + [c for a, c in stops.items() if name in reach.get(a, ())])
            still = tests[name][0]
            outs = self.outputs.get(name)
            ctl = r.runtime.controller
            if outs:
                log = logs[name] = ([start], [tuple(ctl.io.get_out(n) for n in outs)])
                still = _logging(still, ctl, outs, log, not reach[name] <= moving)
            if _turn(item, until, still, ended, watch, pending, self._feed(name, start)):
                going.add(id(item))
            stops[name] = ctl.cycle
        bound = min(stops.values())
        for item in held:
            if _turn(item, bound, tests[item[0].name][1], ended, watch, None):
                going.add(id(item))
        return [item for item in live if id(item) in going]

    def _feed(self, name: str, start: int) -> list | None:
        """The changes of robot `name`'s wired inputs that the movers run before it in this turn
        made after cycle `start` (:attr:`logs`), as :func:`_turn` takes them: ``[(cycle, [(wire,
        value), ...]), ...]``, the cycles in order, each cycle's wires in the cell file's order;
        None when there are none."""
        changes: dict[int, list] = {}       # cycle -> its (wire, value)s, in the wires' order
        for w in self.into.get(name, ()):
            log = self.logs.get(w.source)
            if log is None:
                continue
            at = self.outputs[w.source].index(w.output)
            cycles, values = log
            last = values[0][at]
            for c, v in zip(cycles[1:], values[1:]):
                if v[at] != last:
                    last = v[at]
                    changes.setdefault(c, []).append((w, last))
        return [(c, changes[c]) for c in sorted(changes)] or None

    def logged(self, wire, cycle: int):
        """The value of `wire`'s output after `cycle` as its source robot's log of the last turn
        holds it (:attr:`logs`), or None when its source has no log."""
        log = self.logs.get(wire.source)
        if log is None:
            return None
        cycles, values = log
        return values[bisect_right(cycles, cycle) - 1][self.outputs[wire.source].index(wire.output)]

    def _order(self, movers: tuple[str, ...]) -> list[str] | None:
        """The robots `movers`, each after every mover that reaches it; None when two reach each
        other (or there are none)."""
        left, order = list(movers), []
        while left:
            first = next((m for m in left if not any(m in self.reach.get(a, ()) for a in left if a != m)), None)
            if first is None:
                return None
            order.append(first)
            left.remove(first)
        return order or None


def _logging(still, ctl, outs: tuple[int, ...], log: tuple[list, list], stop: bool):
    """`still`, and, after each cycle of the robot whose controller is `ctl`: its outputs `outs`
    appended to `log` ((cycles, values)) with the cycle when they changed (read only when its I/O
    image's ``version`` moved); with `stop`, False after such a cycle (the turn ends there)."""
    io = ctl.io
    cycles, values = log
    seen = [io.version]

    def test() -> bool:
        v = io.version
        if v != seen[0]:
            seen[0] = v
            now = tuple([io.get_out(n) for n in outs])
            if now != values[-1]:
                cycles.append(ctl.cycle)
                values.append(now)
                if stop:
                    return False
        return still()
    return test


def _set(io, changes: list) -> list:
    """Each (wire, value) of `changes` set on its target's I/O image `io` where the input differs,
    as the cell's carry sets it (its source named by ``wire.label``); the wires that changed one."""
    changed = []
    for wire, value in changes:
        if io.get_in(wire.input) != value:
            io.set_in(wire.input, value, source=wire.label)
            changed.append(wire)
    return changed
