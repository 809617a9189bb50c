"""KUKA.RoboTeam's synchronised motions, the cell's side (issue 89 item 4; docs/cells.md "RoboTeam
synchronisation"): which robots waiting at a synchronised motion (interp/runtime/teamsync.py) the
cell releases after an IPO cycle.

The team: robot k of the cell file (1-based, in the order it names them) is robot k of a
``$SYNC_LIST`` (bit k-1). A robot waiting at a motion with ``$SYNC_ID`` X is released when each
of its partners (teamsync.py ``TeamSync.partners``: the robots its list names, itself aside, and
aside the ones the cell does not have or its machine data's ``$SIMULATED_COOP_ROBOTS`` marks
simulated) waits at a motion with the same X. Every robot
released after one cycle queues its motion in the next, so they start in the same IPO cycle. A
robot that never reaches its motion keeps the others waiting; when nothing else can change, the
cell's deadlock test ends them naming each wait (``SYNC "X" at file:line``).
"""

from __future__ import annotations


def join_team(runs) -> list:
    """Number `runs` (interp/robotcell.py RobotRun, the cell file's order) as the team: robot k
    of the file is robot k of a ``$SYNC_LIST``; their teams (interp/runtime/teamsync.py
    TeamSync), in that order, for :func:`release_synced`. Raises ValueError past 32 robots."""
    for k, r in enumerate(runs, 1):
        r.runtime.motions.team.join(k, len(runs))
    return [r.runtime.motions.team for r in runs]


def release_synced(runs, teams: list | None = None, ahead=()) -> list:
    """After an IPO cycle of every robot of `runs` (`teams`: :func:`join_team`'s): release each
    robot whose synchronised motion every partner has reached (module docstring); the runs
    released. Nothing is built while no robot waits at one (every cycle of a cell asks).
    `ahead`: the names of robots already past this cycle (interp/cellturns.py), waiting at none
    in it."""
    if teams is None:
        teams = [r.runtime.motions.team for r in runs]
    for t in teams:
        if t.at is not None and not t.released:
            break
    else:
        return []
    teams = dict(enumerate(teams, 1))
    at = {k: t.at for k, t in teams.items()
          if t.at is not None and not t.released and runs[k - 1].name not in ahead}
    ready = []
    for k, point in at.items():
        if all(n in at and at[n].id == point.id for n in teams[k].partners(point)):
            ready.append(k)
    for k in ready:
        teams[k].release()
    return [runs[k - 1] for k in ready]
