"""Two robots of a cell touching each other (issue 89; docs/cells.md): the cell's one MuJoCo scene
(robot/cellscene.py: every robot's own model at its ``base``, with its own cell's bodies) checked
after the IPO cycles in which a robot moved.

After every cycle the :class:`ContactWatch` reads each robot's axes back (its own MuJoCo arm's
joint values, copied into the scene as they are: robot/cellscene.py ``follow``; without MuJoCo
robot/readback.py ``ReadBack.axes``, the setpoint); when no robot's axes changed since
the last check nothing is computed (the contacts of the last check stand). Otherwise the scene
takes the axes that changed and MuJoCo gives its contacts between robots. A pair of robots whose
bodies touch, and did not at the check before, begins a :class:`Collision`: the time, both robots,
their bodies, their axes and the motion each robot's main run was executing (file:line; "at rest"
when none). One collision is reported per contact episode (until the pair is apart again), as
interp/cellzones.py reports a zone's conflict.

A collision is reported, not stopped (a decision, as for the zones): each simulated controller
checks its own robot against its own cell (robot/collision.py) and its own workspaces
(robot/workspace.py), and a real controller knows no other robot's body; the cell answers the
commissioning engineer's question "do these two meet", which the summary and the cell's JSON
result answer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from interp.cellzones import motion_of
from robot.cellscene import CellScene, Placement, pairs_in_reach


@dataclass(frozen=True)
class Collision:
    """Two robots' bodies touching from ``time`` (s): for each, ``(robot, body, motion)`` with the
    motion its main run executed then (``file:line``, or None at rest); ``axes``: each robot's
    axes then (KRL's order: A1..A6 deg, then E1..; robot/readback.py ``axis_act``); the signed
    distance of the deepest contact (mm)."""
    time: float
    first: tuple[str, str, str | None]
    second: tuple[str, str, str | None]
    axes: dict[str, list[float]]
    distance_mm: float

    def __str__(self) -> str:
        def who(r):
            return f"{r[0]} {r[1]} ({r[2] if r[2] else 'at rest'})"
        return f"{who(self.first)} touches {who(self.second)} at {self.time:.3f} s"

    def as_json(self) -> dict:
        """The collision as the cell's JSON result gives it (docs/schemas/cell-result.schema.json)."""
        return {"time": round(self.time, 6), "distance_mm": round(self.distance_mm, 3),
                "robots": [{"robot": r[0], "body": r[1], "motion": r[2], "axes": [round(v, 4) for v in self.axes[r[0]]]}
                           for r in (self.first, self.second)]}


class ContactWatch:
    """The cell's scene and its robots' runs (interp/robotcell.py RobotRun: ``name``,
    ``runtime``), checked after each IPO cycle (:meth:`check`); :attr:`collisions` in the order
    they began. ``bases``: each robot's base in the cell's world (X, Y, Z mm, A, B, C deg)."""

    def __init__(self, runs: list, bases: dict[str, tuple]) -> None:
        self.runs = runs
        self.collisions: list[Collision] = []
        self.checks = 0
        self._last: dict[str, bytes] = {}
        self._open: set[tuple[str, str]] = set()
        placements = [Placement(r.name, r.runtime.controller.machine, bases[r.name], _geometry(r)) for r in runs]
        # no two robots within reach of each other: none can ever touch, and no scene is built
        # (robot/cellscene.py ``pairs_in_reach``: each distinct robot's model alone, 2 ms where the
        # scene of four KR 6 takes 10)
        self.scene = CellScene(placements) if len(runs) > 1 and pairs_in_reach(placements) else None
        if self.scene is not None and not self.scene.pairs:
            self.scene = None
        self._actuals = [(r.name, r.runtime.controller.actual) for r in runs]
        # each robot's axes read straight from its own MuJoCo arm where it has one (what its
        # read-back gives, robot/readback.py ``axes``, in MuJoCo's units: robot/cellscene.py
        # ``follow``): (name, that arm's qpos, the addresses), else None (its read-back's axes)
        self._feeds = [self._feed(name, actual) for name, actual in self._actuals] if self.scene is not None else []
        # where every robot's axes lie side by side in its arm's qpos: views of MuJoCo's arrays
        # (they stay valid), gathered into one buffer each cycle by one call
        self._views = [f[1][f[2][0]:f[2][0] + len(f[2])] for f in self._feeds] \
            if self._feeds and all(f is not None and (np.diff(f[2]) == 1).all() for f in self._feeds) else None
        self._now = np.empty(sum(len(v) for v in self._views)) if self._views else None
        self._key = b""

    def _feed(self, name: str, actual):
        arm = actual.arm()
        index = self.scene.follow(name, arm) if arm is not None else None
        return (name, arm.data.qpos, index) if index is not None else None

    def check(self, t: float) -> None:
        """After the IPO cycle at `t` (s): a collision begins for each pair of robots whose bodies
        touch now and did not at the check before; nothing is computed when no robot moved."""
        if self.scene is None:
            return
        if self._views is not None:
            # one gather and one comparison for the cell (before: one per robot, 4 x 3 numpy
            # calls a cycle for four robots)
            np.concatenate(self._views, out=self._now)
            key = self._now.tobytes()
            if key == self._key:
                return
            self._key = key
            self.scene.copy_all(self._now)
            self._touches(t)
            return
        moved = False
        last, scene = self._last, self.scene
        for feed, (name, actual) in zip(self._feeds, self._actuals):
            if feed is not None:
                q = feed[1][feed[2]]
                key = q.tobytes()
                if last.get(name) != key:
                    last[name] = key
                    scene.copy(name, q)
                    moved = True
                continue
            q = actual.axes()
            key = q.tobytes()
            if last.get(name) != key:
                last[name] = key
                scene.set_axes(name, q)
                moved = True
        if moved:
            self._touches(t)

    def _touches(self, t: float) -> None:
        """The scene's contacts now: a collision begins for each pair that did not touch before."""
        self.checks += 1
        now = set()
        by_name = None
        for touch in self.scene.touches():
            pair = (touch.first[0], touch.second[0])
            now.add(pair)
            if pair not in self._open:
                by_name = by_name or {r.name: r for r in self.runs}
                a, b = by_name[pair[0]], by_name[pair[1]]
                self.collisions.append(Collision(
                    t, (*touch.first, motion_of(a)), (*touch.second, motion_of(b)),
                    {r.name: [float(v) for v in r.runtime.controller.actual.axis_act()] for r in (a, b)},
                    touch.distance_mm))
        self._open = now


def _geometry(run):
    """The bodies and tool of robot `run`'s own cell file (robot/collision.py CellGeometry, as its
    controller checks them), or None."""
    checker = run.runtime.controller.monitor.collision
    return getattr(checker, "cell", None)

