"""The robots' own workspaces across a cell of several robots (issue 89; docs/cells.md).

Each robot monitors its own cartesian workspaces (``$WORKSPACE[1..8]``: its backup's
``STEU/Mada/$custom.dat`` or its program's assignments, a box in its own ``$WORLD``;
robot/workspace.py), whose signal ``$WORKSTATEn`` is set while its TCP is inside a box of an
inside mode. Two robots sharing a region each configure it as a workspace of their own, and "if
Robot 1 occupies PLACE_BOX, Robot 2 cannot enter that workspace" (industrialmonitordirect.com,
"KUKA KR C4 Dual Robot Workspace Collision Prevention KSS 8.5"): the exclusion is the cell's
wiring (a $WORKSTATE routed to the other robot's input, an interlock in the programs), which no
controller checks for another. After every IPO cycle the :class:`WorkspaceWatch` places every
occupied box of every robot in the cell's world (its ``base``: ``$ROBROOT``) and records a
:class:`interp.cellzones.Conflict` when two robots occupy boxes of their own that overlap there
(once per entry; the zone named ``R1 $WORKSPACE[1], R2 $WORKSPACE[2]``), with the motion each
robot's main run was executing (file:line). Reported, not stopped, as the cell's zones are: each
robot's own STOP modes stop it on their own (robot/workspace.py).

Decisions (docs/cells.md): only inside modes occupy a box (an ``#OUTSIDE`` box is the region its
robot may stay in: two robots' permitted regions overlap in every shared cell); axis workspaces
(``$AXWORKSPACE``) have no place in the world and are not compared; two boxes overlap when they
share a point (closed boxes, the separating-axis test of two oriented boxes).
"""

from __future__ import annotations

import numpy as np

from interp.cellzones import Conflict, motion_of
from robot.frames import frame_to_matrix, inv_pos

#: a separating axis must clear the boxes by this much (mm): touching boxes overlap
_EPS = 1e-6


def boxes_overlap(a: tuple, b: tuple) -> bool:
    """Whether two oriented boxes share a point. A box is ``(centre, axes, half)``: its centre
    (3, mm), its axes as the columns of a 3x3 rotation, its half extents along them (3, mm).
    The separating-axis theorem for two boxes (Gottschalk, Lin, Manocha, "OBBTree", SIGGRAPH
    1996): disjoint exactly when one of the 15 axes (each box's 3 face normals, the 9 cross
    products of their edges) separates their projections."""
    (ca, ra, ha), (cb, rb, hb) = a, b
    d = cb - ca
    axes = [ra[:, i] for i in range(3)] + [rb[:, i] for i in range(3)]
    axes += [np.cross(ra[:, i], rb[:, j]) for i in range(3) for j in range(3)]
    for n in axes:
        if float(n @ n) < 1e-12:          # parallel edges: covered by the face normals
            continue
        ra_n = float(np.sum(ha * np.abs(ra.T @ n)))
        rb_n = float(np.sum(hb * np.abs(rb.T @ n)))
        if abs(float(d @ n)) > ra_n + rb_n + _EPS * float(np.sqrt(n @ n)):
            return False
    return True


def placed(box, base_T: np.ndarray) -> tuple:
    """A robot's workspace box (robot/workspace.py CartBox, in its ``$WORLD``) in the cell's
    world, its robot at `base_T` (4x4): ``(centre, axes, half)`` for :func:`boxes_overlap`."""
    m = base_T @ inv_pos(box.to_box)
    return (m[:3, :3] @ ((box.lo + box.hi) / 2.0) + m[:3, 3], m[:3, :3], (box.hi - box.lo) / 2.0)


class WorkspaceWatch:
    """The robots' own workspaces of a cell's runs (interp/robotcell.py RobotRun), each robot at
    its base (``{name: (X, Y, Z, A, B, C)}``), checked after each IPO cycle (:meth:`check`);
    :attr:`conflicts` in the order they began."""

    def __init__(self, runs: list, bases: dict[str, tuple]) -> None:
        self.runs = runs
        self.bases = {name: frame_to_matrix(*b) for name, b in bases.items()}
        self.conflicts: list[Conflict] = []
        self._open: set[tuple] = set()
        self._placed: dict[tuple, tuple] = {}
        # each robot's monitor (its workspaces appear when its program names one)
        self._monitors = [(r, r.runtime.controller.monitor) for r in runs]

    def _occupied(self, run) -> list[tuple[int, tuple]]:
        mon = run.runtime.controller.monitor.workspaces
        if mon is None:
            return []
        out = []
        for n, box in mon.occupied():
            key = (run.name, n)       # the monitor keeps one box object per definition
            got = self._placed.get(key)
            if got is None or got[0] is not box:
                got = self._placed[key] = (box, placed(box, self.bases[run.name]))
            out.append((n, got[1]))
        return out

    def check(self, t: float, ahead=()) -> None:
        """After the IPO cycle at `t` (s): a conflict begins for each pair of robots occupying
        workspaces of their own that overlap in the cell's world and did not the cycle before.
        `ahead`: the names of robots already past this cycle (interp/cellturns.py), monitoring
        none in it."""
        for _, m in self._monitors:
            if m.workspaces is not None:
                break
        else:
            if not self._open:
                return      # no robot monitors a workspace (every cycle of most cells asks)
        occupied = [(r, o) for r, o in ((r, self._occupied(r)) for r, m in self._monitors
                                        if m.workspaces is not None and r.name not in ahead) if o]
        if len(occupied) < 2 and not self._open:
            return
        now = set()
        for i, (a, boxes_a) in enumerate(occupied):
            for b, boxes_b in occupied[i + 1:]:
                for na, pa in boxes_a:
                    for nb, pb in boxes_b:
                        if not boxes_overlap(pa, pb):
                            continue
                        key = (a.name, na, b.name, nb)
                        now.add(key)
                        if key not in self._open:
                            self.conflicts.append(Conflict(f"{a.name} $WORKSPACE[{na}], {b.name} $WORKSPACE[{nb}]",
                                                           t, (a.name, motion_of(a)), (b.name, motion_of(b))))
        self._open = now
