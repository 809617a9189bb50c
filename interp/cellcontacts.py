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

Since no robot's run depends on it, robots taking turns (interp/cellturns.py) are checked after
the turn: :meth:`ContactWatch.record` keeps each robot's pose and motion of each cycle (the
cycles counted, each cycle's time its cycle times ``dt``), :meth:`ContactWatch.flush` checks the
kept cycles in order once every robot has passed them, the same checks as cycle by cycle. There,
a run of cycles that robot/cellbound.py's bound proves (each geom's displacement from a reference
pose, bounded by its segment's distance from each joint's axis there, under the gap between two
geoms then; or, for a pair of robots touching at the last check, under the depth of their
deepest pair of capsules) needs no MuJoCo check: it would find the pairs held touching touching
(no new collision) and no other; a reference is measured by the scene's kinematics, and its
contacts asked of MuJoCo only when its own tests do not prove it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import reduce

import numpy as np

from interp.cellkeep import Keeper
from interp.cellzones import motion_of
from robot.cellscene import CellScene, Placement, RobotModels, pairs_in_reach


#: kept cycles checked by MuJoCo alone after a fresh reference proved not even the next
CLOSE_CYCLES = 8


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
        self._open: set[tuple[str, str]] = set()
        placements = [Placement(r.name, r.runtime.controller.machine, bases[r.name], _geometry(r)) for r in runs]
        # no two robots within reach of each other: none can ever touch, and no scene is built
        # (robot/cellscene.py ``pairs_in_reach``: each distinct robot's model alone, 2 ms where the
        # scene of four KR 6 takes 10); the robots' models built once for both (RobotModels)
        models = RobotModels(placements) if len(runs) > 1 else None
        self.scene = CellScene(placements, models) if models is not None and pairs_in_reach(placements, models) else None
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
        self._index = {r.name: k for k, r in enumerate(runs)}
        # what a robot's pose read (_read) is multiplied by for the scene: 1 for an arm's joint
        # values, the scene's factors from KUKA's units (robot/cellscene.py ``set_axes``) else
        self._scale = [1.0 if feed is not None else self.scene.scale(name)
                       for feed, (name, _) in zip(self._feeds, self._actuals)]
        # the bound that proves the robots apart or touching in a run of kept cycles (robot/cellbound.py; built
        # at the first flush: False till then), its reference (robot/cellbound.py ``Reference``:
        # the pose, its gaps, levers and tests), whether measured at the row before, the rows left to
        # check by MuJoCo alone; :attr:`proved`: the kept cycles it spared MuJoCo's contacts (a
        # reference its own tests prove among them); :attr:`checks`: MuJoCo's contact checks
        self._bound = False
        self._ref = None
        self._close, self._wait, self._fresh = 0, CLOSE_CYCLES, False
        self.proved = 0
        #: per robot, the cycles a turn ran and :meth:`flush` has not checked yet: its poses as
        #: :meth:`_read` gives them, their bytes one after the other, and the motion requests, one
        #: a kept cycle; and the cycles they stand for, as (index of the first, its cycle) of each
        #: run of consecutive cycles (the controller's time is the cycle times ``dt``:
        #: robot/controller.py). Before 2026-11-29 each kept cycle was a tuple (time, the pose's
        #: bytes, motion) (docs/cells.md "Speed")
        self._poses: list[bytearray] = [bytearray() for _ in runs]
        self._motions: list[list] = [[] for _ in runs]
        self._marks: list[list] = [[] for _ in runs]
        self._keepers: dict[str, Keeper] = {}

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
            self._touches(t, self.scene.touches(), self._run_motion, self._run_axes)
            return
        self._at(t, np.concatenate([self._read(k) * self._scale[k] for k in range(len(self.runs))]),
                 self._run_motion, self._run_axes)

    def after(self, t: float, kept: bool, ahead: bool) -> None:
        """After the cell's cycle ending at `t` (s): :meth:`check` it, or, when the cycle was
        taken in a turn or catching up (`kept`: its poses kept by :meth:`record`), once no robot is
        `ahead` of it, :meth:`flush` the kept cycles."""
        if self.scene is None:
            return
        if not kept:
            self.check(t)
        elif not ahead:
            self.flush()

    def record(self, run) -> None:
        """Robot `run` (one of :attr:`runs`) has taken an IPO cycle (or ended) in a turn
        (interp/cellturns.py), the others not yet: its pose and motion now are kept for
        :meth:`flush` as its controller's cycle's (a later cycle of the same robot replaces none;
        a second record of the same cycle stands for it there): its :meth:`keeper`'s ``again``."""
        self.keeper(run).again(run.runtime.controller.cycle)

    def keeper(self, run) -> Keeper:
        """How the cycles of robot `run` are kept (interp/cellkeep.py; one for the whole run): a
        turn's (interp/cellturns.py) and, one cycle at a time, :meth:`record`'s. A second record
        of the same cycle (a robot that ended) is kept beside the first, :meth:`flush` reading
        the last of them."""
        keeper = self._keepers.get(run.name)
        if keeper is None:
            k = self._index[run.name]
            view = self._views[k] if self._views is not None else None
            keeper = self._keepers[run.name] = Keeper(run, self._poses[k], self._motions[k], self._marks[k],
                                                      lambda: self._read(k), view,
                                                      self._feeds[k][2][0] if view is not None else None)
        return keeper

    def flush(self) -> None:
        """The checks of the cycles :meth:`record` kept, in the order of the cycles, as
        :meth:`check` would have made them after each (every robot at that cycle's pose: its pose
        kept for it, or the last before it of a robot that ended; the time the latest robot's at
        that cycle): the same collisions, times, bodies, axes and motions. Call when every
        running robot stands at the same cycle (the kept ones are then all complete)."""
        if self.scene is None or not any(self._motions):
            return
        # (the lists stay: the keepers hold them; the poses are read where they lie, then cleared)
        motions = [m[:] for m in self._motions]
        kept = [_kept_cycles(m, len(n)) for m, n in zip(self._marks, motions)]
        for lists in (self._motions, self._marks):
            for part in lists:
                part.clear()
        cycles = np.arange(min(c[0] for c in kept if len(c)), max(c[-1] for c in kept if len(c)) + 1)
        every = np.arange(len(cycles))
        # each cycle's time on each controller's dt (robot/controller.py: its cycle times dt, the
        # same product; one array for the robots that kept every cycle on the same dt)
        at_dt: dict[float, np.ndarray] = {}
        columns, times, rows, raws = [], [], [], []
        block, width = None, 0
        for k, pose in enumerate(self._poses):
            n = len(motions[k])
            if not n:       # ended before these cycles: where it stands now
                raw, now = self._read(k), self.runs[k].runtime.controller.time
                columns.append(np.broadcast_to(raw * self._scale[k], (len(cycles), len(raw))))
                width += len(raw)
                times.append(np.full(len(cycles), now))
                rows.append(None)
                raws.append(None)
                continue
            # a view of the keeper's buffer (before 2026-11-29 20:20 UTC its bytes copied first)
            block = np.frombuffer(pose).reshape(n, -1)
            dt = self.runs[k].runtime.controller.dt
            if n == len(cycles) and (kept[k] == cycles).all():
                at = every      # each cycle kept once, in order: the rows as they are
                if dt not in at_dt:
                    at_dt[dt] = cycles.astype(float) * dt
                times.append(at_dt[dt])
            else:
                # each cycle's last record (a robot that ended records its last cycle twice: the later stands)
                at = np.maximum(np.searchsorted(kept[k], cycles, side="right") - 1, 0)
                block = block[at]
                times.append(kept[k][at].astype(float) * dt)
            scale = self._scale[k]
            plain = type(scale) is float and scale == 1.0
            columns.append(block if plain else block * scale)
            # robot k's values as kept, row by row (for _axis_act): the joined rows' columns where
            # they are these, else a copy
            raws.append((width, width + block.shape[1]) if plain else block.copy() if at is every else block)
            width += block.shape[1]
            rows.append(at)
        joined = np.concatenate(columns, axis=1)
        columns = block = None      # no view of a keeper's buffer left: it can be cleared
        for part in self._poses:
            part.clear()

        def raw(k: int, j: int) -> np.ndarray:
            where = raws[k]
            return joined[j, where[0]:where[1]] if type(where) is tuple else where[j]
        self._replay(joined, times[0] if all(t is times[0] for t in times) else reduce(np.maximum, times),
                     lambda k, j: _motion(motions[k][rows[k][j]]) if rows[k] is not None else motion_of(self.runs[k]),
                     lambda k, j: self._axis_act(k, raw(k, j)) if rows[k] is not None else self._run_axes(k))

    def _replay(self, poses: np.ndarray, t: np.ndarray, motion, axes) -> None:
        """The checks of `poses` (cycles, the scene's values) after the cycles ending at `t` (s),
        in order; `motion(k, j)`, `axes(k, j)`: robot k's at row j. A run of rows the bound
        (robot/cellbound.py) proves from the reference, a pose measured before, needs no check:
        the pairs the reference holds touching touch there and no other, as the check would
        say (since 2026-11-30; apart only before); the row after such a run, the
        first the reference leaves unproved, is taken as the next reference without asking the
        bound again. A reference is measured by the scene's kinematics alone (robot/cellscene.py
        ``place``) and needs MuJoCo's contacts only when its own tests do not prove it
        (since 2026-11-29 20:00 UTC; MuJoCo's whole check before, the gaps measured after it).
        When a fresh reference proves not even the next row, the robots are close: the next rows
        are checked by MuJoCo alone, :data:`CLOSE_CYCLES` and twice as many each time again, up
        to 64 times that."""
        if self._bound is False:
            self._bound = self.scene.bound()
        bound = self._bound
        j = 0
        unproved = -1           # the row the reference is known not to prove (the end of its last proof)
        while j < len(poses):
            if bound is not None and self._ref is not None and not self._close:
                end = bound.proved(self._ref, poses, j) if j != unproved else j
                if end > j:
                    # the pairs the reference holds touching touch there, no other pair does; the
                    # next check computes (the scene is not at these poses)
                    self._open, self._key, self._fresh, self._wait = self._held(), b"", False, CLOSE_CYCLES
                    self.proved += end - j
                    j = unproved = end
                    continue
                if self._fresh:
                    self._close, self._wait = self._wait, min(2 * self._wait, 64 * CLOSE_CYCLES)
            if bound is None or self._close:
                self._at(float(t[j]), poses[j], lambda k, j=j: motion(k, j), lambda k, j=j: axes(k, j))
                if bound is not None:
                    self._fresh = False
                    self._close -= 1
            else:
                self._measure(bound, float(t[j]), poses[j], lambda k, j=j: motion(k, j), lambda k, j=j: axes(k, j))
            j += 1

    def _measure(self, bound, t: float, q: np.ndarray, motion, axes) -> None:
        """A new reference at the scene's joint values `q` after the cycle at `t` (the bound's,
        robot/cellbound.py ``reference``, holding touching the pairs touching at the last check
        where it can), and that pose's contacts: the pairs it holds touching when its own tests
        prove it, else MuJoCo's (unless no robot moved since the last check), the reference then
        holding touching the pairs MuJoCo found."""
        key = q.tobytes()
        if key != self._key:
            self._key = key
            self.scene.place(q)
            self._ref = bound.reference(q, self.scene.data, self._touching())
            if self._ref.proves:
                self._open = self._held()
                self.proved += 1
            else:
                self._touches(t, self.scene.contacts(), motion, axes)
                self._ref = bound.held(self._ref, self._touching())
        else:                   # the scene stands there, its kinematics computed
            self._ref = bound.reference(q, self.scene.data, self._touching())
        self._fresh = True

    def _touching(self) -> list[tuple[int, int]]:
        """The pairs of robots touching at the last check (indices, in the robots' order)."""
        return sorted((self._index[a], self._index[b]) for a, b in self._open)

    def _held(self) -> set[tuple[str, str]]:
        """The pairs of robots (names) the reference holds touching."""
        return {(self.runs[a].name, self.runs[b].name) for a, b in self._ref.touching}

    def _at(self, t: float, q: np.ndarray, motion, axes) -> None:
        """Every robot at the scene's joint values `q` (:meth:`CellScene.copy_all`'s) after the
        cycle at `t`: checked unless no robot moved since the last check."""
        key = q.tobytes()
        if key == self._key:
            return
        self._key = key
        self.scene.copy_all(q)
        self._touches(t, self.scene.touches(), motion, axes)

    def _read(self, k: int) -> np.ndarray:
        """Robot `k`'s pose now: its arm's joint values (MuJoCo's units: the scene's) where it
        has a feed, else its axes read back (its model's order, deg and mm: times ``_scale``)."""
        if self._views is not None:
            return self._views[k].copy()
        feed = self._feeds[k]
        if feed is not None:
            return feed[1][feed[2]]
        return self._actuals[k][1].axes()[:len(self._scale[k])]

    def _axis_act(self, k: int, raw: np.ndarray) -> list[float]:
        """Robot `k`'s ``$AXIS_ACT`` (KRL's order) at the pose `raw` :meth:`_read` gave: what its
        read-back (robot/readback.py ``axis_act``) gave then."""
        actual = self._actuals[k][1]
        feed = self._feeds[k]
        if feed is not None:
            full = feed[1].copy()
            full[feed[2]] = raw
            raw = actual.arm().axes_deg(full)
        return [float(v) for v in actual.model.to_krl(raw)]

    def _run_motion(self, k: int) -> str | None:
        return motion_of(self.runs[k])

    def _run_axes(self, k: int) -> list[float]:
        return [float(v) for v in self.runs[k].runtime.controller.actual.axis_act()]

    def _touches(self, t: float, touches: list, motion, axes) -> None:
        """The scene's contacts now, `touches` (robot/cellscene.py ``touches``): a collision
        begins for each pair that did not touch before; `motion(k)`, `axes(k)`: robot k's motion
        (file:line or None) and ``$AXIS_ACT`` then."""
        self.checks += 1
        now = set()
        for touch in touches:
            pair = (touch.first[0], touch.second[0])
            now.add(pair)
            if pair not in self._open:
                a, b = self._index[pair[0]], self._index[pair[1]]
                self.collisions.append(Collision(
                    t, (*touch.first, motion(a)), (*touch.second, motion(b)),
                    {pair[0]: axes(a), pair[1]: axes(b)}, touch.distance_mm))
        self._open = now


def _kept_cycles(marks: list, n: int) -> np.ndarray:
    """The cycle of each of `n` kept cycles whose runs of consecutive cycles `marks` gives
    ((index of the first, its cycle), ...: interp/cellkeep.py ``Keeper``)."""
    if not n:
        return np.zeros(0, dtype=np.int64)
    ends = [i for i, _ in marks[1:]] + [n]
    return np.concatenate([np.arange(c, c + e - i, dtype=np.int64) for (i, c), e in zip(marks, ends)])


def _motion(req) -> str | None:
    """A motion request's ``file:line`` (interp/cellzones.py ``motion_of`` of the request kept)."""
    return None if req is None or req.line is None else f"{req.file}:{req.line}"


def _geometry(run):
    """The bodies and tool of robot `run`'s own cell file (robot/collision.py CellGeometry, as its
    controller checks them), or None."""
    checker = run.runtime.controller.monitor.collision
    return getattr(checker, "cell", None)

