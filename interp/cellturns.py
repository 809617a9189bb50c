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
offer answered 0: an ordinary cycle, as the cell answers an offer not every robot makes). Every
cycle of a robot before its turn's last was plain, so the cell (interp/robotcell.py ``run_cell``)
then catches the robots behind up, cycle by cycle, reading a robot that is ahead as plain: the
deadlock test, the release of synchronised motions and the workspaces' conflicts of each cycle
are those of the cycle-by-cycle run, and each robot's own run (its trace, its I/O, its end) is
the same, since nothing else reaches it (tests/interp/test_robotcell_turns.py).
"""

from __future__ import annotations

#: IPO cycles of one robot's turn (12.3 s; docs/cells.md "Speed": 16 recovered little of the cost, 256
#: about half, 1,024 about all, in one measure each)
TURN_CYCLES = 1024


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
    (its scheduler, RoboTeam part, monitor and network partners are its run's for the whole run:
    interp/runtime/motions.py, robot/controller.py): called after each cycle of a turn, where
    :func:`plain`'s lookups cost 2-3 % of a moving robot's CPU (docs/cells.md "Speed")."""
    rt = run.runtime
    scheduler, team, monitor = rt.scheduler, rt.motions.team, rt.controller.monitor
    net = getattr(rt.controller, "network", None)
    if team is None and net is None:
        return lambda: scheduler.blocked is None and monitor.workspaces is None
    return lambda: scheduler.blocked is None and (team is None or team.at is None) and \
        monitor.workspaces is None and not getattr(net, "polling", False)


def take_turns(live: list, turn: int, ended: dict, watch) -> list:
    """Each robot of `live` ((RobotRun, its cycles, its task), in the cell's order, all at one
    cycle) runs up to `turn` cycles (module docstring). `watch(item)` gives, for robot `item`,
    ``(wait, keep)``: ``wait(t)``, the cell's WAIT FOR bookkeeping after a cycle that began at
    `t` (s), called while the robot's task waits and after, as long as it returns True (the wait
    still counted), and ``keep``, None or ``(push, pose, motion)``: the cycle kept for the contact
    check as ``push((time s, pose(), motion()))`` (interp/cellcontacts.py ``ContactWatch.keeper``).
    The loop calls nothing else of the cell's in a cycle (before 2026-11-29 two functions and the
    controller's ``cycle`` property a cycle: docs/cells.md "Speed"). Returns the robots still
    running; `ended` gets each robot that ended: its last cycle."""
    going = []
    until = live[0][0].runtime.controller.cycle + turn
    for item in live:
        r, cycles, task = item
        ctl = r.runtime.controller
        wait, keep = watch(item)
        still = plain_test(r)
        step, send = cycles.__next__, cycles.send
        push, pose, motion = keep if keep is not None else (None, None, None)
        counting = True         # the first cycle asks `wait` whether a wait is counted
        left = until - ctl.cycle  # each pass of the loop is one cycle (an offer answered 0 too)
        while True:
            now = ctl.time
            try:
                offer = step()
                if offer is not None:
                    send(0)
            except StopIteration:
                if counting or task.waiting is not None:
                    wait(now)
                if push is not None:
                    push((ctl.time, pose(), motion()))
                ended[r.name] = ctl.cycle
                break
            if counting or task.waiting is not None:
                counting = wait(now)
            if push is not None:
                push((ctl.time, pose(), motion()))
            left -= 1
            if offer is not None or left <= 0 or not still():
                going.append(item)
                break
    return going
