"""How a cell keeps each cycle of a robot's turn for its contact check (issue 89; docs/cells.md
"Speed"): the robot's pose after each cycle and the motion its main run executed, for
interp/cellcontacts.py ``ContactWatch.flush`` to check once every robot has passed the cycle.

Where the robot's arm plays its IPO cycle compiled (robot/ipocycle.py ``ArmCycle``), the pose is
kept by that very cycle: the arm's joint values copied into the next row of a block the turn gives
it (robot/readback.py ``keep_poses``), no Python a cycle; the block's rows go to the robot's kept
poses when the turn ends. Otherwise (no MuJoCo arm, actuated, external axes) the turn's loop keeps
each pose itself (:attr:`Keeper.pose_to`). The motion request is noted only when the controller's
main runs change (robot/controller.py replaces its ``_runs`` list, never changes one in place), and
spread over the cycles it stands for when the turn ends. Before 2026-11-29 19:30 UTC the loop
appended each cycle's pose (a ``bytearray`` grown through a memoryview) and its motion request
itself.
"""

from __future__ import annotations

import numpy as np


class Keeper:
    """The kept cycles of one robot `run` (interp/robotcell.py RobotRun) of a contact watch: its
    poses (`poses`: their bytes, one cycle after the other, each the scene's values of the robot
    as ``read()`` gives them now, float64), `motions` (the motion request of each kept cycle)
    and `marks` ((index of the first, its cycle) of each run of consecutive kept cycles), the
    lists interp/cellcontacts.py ``ContactWatch`` reads; `view`: the robot's values as a view of
    one slice of its arm's ``qpos``, from index `at` (None: they are not one, the loop keeps what
    ``read()`` gives).

    A turn calls :meth:`begin`, then after each cycle, in its loop, ``pose_to(pose)`` when
    :attr:`pose_to` is not None and ``note(i, motion())`` when the main runs changed (i: the
    cycles of the turn before this one), then :meth:`end` with the turn's cycles."""

    def __init__(self, run, poses: bytearray, motions: list, marks: list, read, view: np.ndarray | None,
                 at: int | None) -> None:
        ctl = run.runtime.controller
        self.poses, self.motions, self.marks = poses, motions, marks
        #: the robot's motion request now (robot/controller.py ``current_request``)
        self.motion = ctl.current_request
        self._actual = ctl.actual
        self._read = read
        self._at = at if view is not None else None
        self._block: np.ndarray | None = None
        self._armed = False
        self._changes: list = []
        # kept by the loop: the view's bytes appended (no object a cycle), or what read() gives
        self._loop = (poses.extend, memoryview(view)) if view is not None else \
            ((lambda _: poses.extend(read().tobytes())), None)
        self.pose_to, self.pose = self._loop

    def mark(self, cycle: int) -> None:
        """The next kept cycle is `cycle` (a new run of consecutive cycles when it does not
        follow the last kept one)."""
        marks, n = self.marks, len(self.motions)
        if not marks or marks[-1][1] + n - marks[-1][0] != cycle:
            marks.append((n, cycle))

    def begin(self, cycle: int, n: int) -> None:
        """A turn of at most `n` cycles whose first is `cycle`."""
        self.mark(cycle)
        self._changes = []
        if self._at is None:
            return
        block = self._block
        if block is None or len(block) < n:
            width = len(self._read())
            block = self._block = np.empty((max(n, 1), width))
        self._armed = self._actual.keep_poses(block, self._at)
        self.pose_to, self.pose = (None, None) if self._armed else self._loop

    def note(self, i: int, req) -> None:
        """The motion request `req` from the turn's cycle `i` (0: its first) on."""
        self._changes.append((i, req))

    def end(self, n: int) -> None:
        """The turn ran `n` cycles: their poses and motions kept. Raises RuntimeError when the
        compiled cycle kept another number of cycles (a cycle played outside a step, or a turn
        longer than it said)."""
        if self._armed:
            self._armed = False
            kept = self._actual.poses_kept()
            if kept != n or n > len(self._block):
                raise RuntimeError(f"a turn of {n} cycles kept {kept} poses in a block of {len(self._block)}")
            if n:
                self.poses.extend(memoryview(self._block[:n]).cast("B"))
        changes = self._changes
        for k, (i, req) in enumerate(changes):
            stop = changes[k + 1][0] if k + 1 < len(changes) else n
            self.motions.extend([req] * (stop - i))
        self._changes = []

    def again(self, cycle: int) -> None:
        """The robot's state now kept as cycle `cycle` (a robot that ended: its last cycle once
        more; a cycle taken one by one)."""
        self.mark(cycle)
        self.poses.extend(self._read().tobytes())
        self.motions.append(self.motion())
