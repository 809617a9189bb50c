"""A conservative bound that proves, over a run of poses, each pair of a cell's robots apart or
still touching (issue 89; docs/cells.md "Speed"): the cycles of a turn that need no MuJoCo contact
check.

Each geom is a *segment* and a radius about it: a capsule its axis (MuJoCo's: the frame's Z, half
its length each way) and radius, a sphere its centre and radius, any other geom its centre and
bounding radius (``geom_rbound``: the geom lies in that sphere about its centre, whatever the
pose). At a *reference* pose the scene (robot/cellscene.py), its kinematics computed, places each
segment (``geom_xpos``, ``geom_xmat``) and each joint's anchor and axis (``xanchor``,
``xaxis``). The *gap* of two geoms of two robots that can touch (MuJoCo's contact bits, bodies not
welded together: its collision skips two bodies fixed to the world) is the
distance of their segments less both radii, the contact distance
(:data:`robot.collision.CONTACT_MM`) and :data:`SAFETY_M` (for two capsules or spheres: the
signed distance MuJoCo's check gives them, less the margins; before 2026-11-30 the distance of
the centres less both bounding radii: a 0.9 m link's capsule was a ball of 1 m); at the
reference, each joint's *lever* for a geom it carries (the geom's body is the joint's or below
it) is the larger distance of the segment's two ends from the joint's axis (a hinge), or 1 (a
slide, m per m). The loops are robot/cellproof.py's (compiled).

Soundness (why a pose this bound proves has MuJoCo's contacts as it says). Go from the reference
pose to another by moving the joints one after the other in MuJoCo's order (a body's parents
first, a body's joints in their order). When joint j moves, the joints before it have moved what
j carries rigidly (each joint's motion is a rotation or a translation of its body and everything
below it) and the joints after it stand at their reference values: so each point of the segment
stands at its reference distance from j's axis, at most the larger of the ends' (the distance
from a line is convex along a segment), and turning j by ``dq`` moves it along a circle's chord,
at most that distance times ``|dq|`` (a slide: by ``|dq|``). Summed over the joints (the triangle
inequality), each point of geom g's segment lies within ``D_g = sum_j |q_j - ref_j| lever_jg`` of
where it stood, for any pose, with no assumption of speed or path (the displacement from the
reference, not the travel along the cycles, counts). So the segments' distance has changed by at
most ``D_g + D_h`` either way:

* *apart*: two geoms whose gap exceeds ``D_g + D_h`` lie more than the contact distance apart
  (each within its radius of its segment): MuJoCo gives them no contact;
* *touching*: two capsules or spheres whose depth at the reference (the contact distance less
  their signed distance) exceeds ``D_g + D_h + 2 SAFETY_M`` still penetrate by more than the
  margin, and MuJoCo's check of them (its closed form of two capsules, spheres) gives the pair a
  contact.

A reference *holds touching* the robot pairs MuJoCo found touching at the last check that have
such a deep pair of geoms (:meth:`CellBound.held`, the deepest tested), the others apart (all
their geom pairs tested). A pose in which every test holds (:meth:`CellBound.proved`) is one in
which MuJoCo's check finds exactly the held pairs touching; the reference pose itself is when
every test holds with ``D`` 0 (``Reference.proves``). The levers are rounded up by
:data:`LEVER_SLACK_M2` under the square root (the rounding of ``|v|^2 - (v.a)^2``, about 1e-15
m^2 for the cell's sizes) and the rest of the float arithmetic stays far under :data:`SAFETY_M`.

Raises nothing; :func:`bound_of` returns None for a scene it cannot bound (a geom without a
bounding radius, a moving joint neither hinge nor slide).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from . import cellproof
from .collision import CONTACT_MM
from .kinematics.compiled import pure_module

#: what a proof keeps in hand beyond the contact distance (m): rounding of the sums above
SAFETY_M = 0.001
#: added to each squared lever (m^2) before its root: rounding of the squared distance from the axis
LEVER_SLACK_M2 = 1e-12


@dataclass
class Reference:
    """What a reference pose proves (module docstring): ``pose`` (the scene's values, columns),
    ``gaps`` (m, each checked geom pair's), ``levers`` (geoms, columns: each column's lever for
    each geom, 0 for a geom it does not carry); ``limits`` (m): what each geom pair's two
    displacement bounds summed must stay under in a later pose (a pair held apart: its gap; of
    a robot pair held touching, its deepest pair: its depth less twice :data:`SAFETY_M`, the
    others no limit); ``touching``: the robot pairs (indices) held touching; ``proves``: every
    limit positive (the pose itself proved: each robot pair apart or, held, touching)."""
    pose: np.ndarray
    gaps: np.ndarray
    levers: np.ndarray
    limits: np.ndarray
    touching: tuple
    proves: bool


#: the compiled loops (robot/cellproof.py, as Python without a build)
_LOOPS = pure_module(cellproof)


@dataclass
class CellBound:
    """The bound of one scene (module docstring). ``near``, ``far``: the geoms of each geom pair
    checked (every geom of the first robot of a checked robot pair with every geom of the second
    that can touch it), grouped by robot pair: ``groups`` maps each robot pair (indices) to
    (first, end) of its geom pairs; ``half``: each geom's segment half-length (m; a capsule's, 0
    for any other geom); ``exact``: each geom pair both capsules or spheres (its gap is the
    distance MuJoCo's check gives them, less the margins; 1, else 0); ``reach``: the pair's two
    radii (a capsule's or a sphere's, any other geom's bounding radius), the contact distance and
    :data:`SAFETY_M` (m); ``hinge``: (flat indices into a (geoms, columns) array, joints, geoms)
    of each hinge column and a geom its joint carries; ``slide``: the flat indices of each slide
    column and a geom it carries; ``ngeom``, ``columns``: the scene's geoms and the columns of
    its poses (``copy_all``'s)."""
    near: np.ndarray
    far: np.ndarray
    groups: dict
    half: np.ndarray
    exact: np.ndarray
    reach: np.ndarray
    hinge: tuple
    slide: np.ndarray
    ngeom: int
    columns: int

    def __post_init__(self) -> None:
        flat, joints, geoms = self.hinge
        # each geom's columns whose levers can be other than 0 (the joints that carry it: its own
        # robot's), from the first to the last
        geom, column = np.divmod(np.concatenate([flat, self.slide]).astype(np.intp), max(self.columns, 1))
        lo, hi = np.full(self.ngeom, self.columns, dtype=np.intp), np.zeros(self.ngeom, dtype=np.intp)
        np.minimum.at(lo, geom, column)
        np.maximum.at(hi, geom, column + 1)
        lo = np.minimum(lo, hi)         # a geom no column carries: an empty span
        # the compiled loops with this bound's arrays, given once (robot/cellproof.py ``Prover``)
        self._prover = _LOOPS.Prover(self.near, self.far, self.half, self.reach, flat, joints, geoms, self.slide,
                                     LEVER_SLACK_M2, lo, hi, np.empty(self.columns), np.empty(self.ngeom),
                                     np.empty(len(self.near), dtype=np.intp))

    def reference(self, pose: np.ndarray, data, touching=()) -> Reference:
        """The reference at `pose` (columns), the scene's MuJoCo `data` standing there with its
        kinematics computed (``geom_xpos``, ``geom_xmat``, ``xanchor``, ``xaxis``): each checked
        geom pair's gap, each geom's levers (robot/cellproof.py ``Prover.measure``); `touching`: the
        robot pairs (indices) touching at the last check, held touching where a pair of their
        geoms is deep enough (:meth:`held`)."""
        gaps = np.empty(len(self.near))
        levers = np.empty((self.ngeom, self.columns))
        self._prover.measure(data.geom_xpos, data.geom_xmat, data.xanchor, data.xaxis, gaps, levers.reshape(-1))
        return self.held(Reference(pose.copy(), gaps, levers, gaps, (), _LOOPS.least(gaps) > 0.0), touching)

    def held(self, ref: Reference, touching) -> Reference:
        """`ref` with the robot pairs of `touching` (indices, touching at the last check) held
        touching where one of their exact geom pairs (both capsules or spheres) is deeper than
        twice :data:`SAFETY_M` (the deepest then tested: it stays under the contact distance while
        its two displacement bounds stay under its depth less that; the pair's other geom pairs
        not tested), the other robot pairs held apart (their gaps)."""
        limits, held = ref.gaps, []
        for pair in touching:
            where = self.groups.get(pair)
            k = _LOOPS.deepest(ref.gaps, self.exact, where[0], where[1], 2.0 * SAFETY_M) if where else -1
            if k >= 0:
                if not held:
                    limits = ref.gaps.copy()
                limits[where[0]:where[1]] = np.inf
                limits[k] = -ref.gaps[k] - 2.0 * SAFETY_M
                held.append(pair)
        if not held and not ref.touching:
            return ref
        return Reference(ref.pose, ref.gaps, ref.levers, limits, tuple(held), _LOOPS.least(limits) > 0.0)

    def proved(self, ref: Reference, poses: np.ndarray, start: int) -> int:
        """The first row of `poses` (cycles, columns; float64, C-contiguous) from `start` on that
        `ref` leaves unproved (``len(poses)`` when it proves them all): in the rows from `start`
        to it each geom pair's two displacement bounds stay under its limit (each robot pair
        apart, or one `ref` holds touching still touching; robot/cellproof.py
        ``Prover.first_unproved``: windows of rows bounded at once, then row by row the pairs a
        window does not pass)."""
        if not ref.proves:
            return start
        return self._prover.first_unproved(ref.levers, ref.pose, poses, start, ref.limits)


def bound_of(model, robot_of: np.ndarray, columns: np.ndarray, pairs: list) -> CellBound | None:
    """The bound of the scene `model` (MuJoCo's) whose geom g belongs to robot ``robot_of[g]``,
    its poses given as the qpos values at addresses `columns`, for the robot `pairs` (index
    pairs); None when some geom or moving joint cannot be bounded (module docstring)."""
    if (model.geom_rbound <= 0).any():
        return None
    adr_joint = {int(model.jnt_qposadr[j]): j for j in range(model.njnt)}
    below = [_ancestors(model, int(b)) for b in model.geom_bodyid]
    hinge: tuple[list, list, list] = ([], [], [])
    slide: list = []
    for c, adr in enumerate(columns):
        j = adr_joint[int(adr)]
        kind, body = int(model.jnt_type[j]), int(model.jnt_bodyid[j])
        if kind not in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
            return None
        for g in range(model.ngeom):
            if body == 0 or body in below[g]:       # the geom is on the joint's body or below it
                if kind == int(mujoco.mjtJoint.mjJNT_HINGE):
                    for part, value in zip(hinge, (g * len(columns) + c, j, g)):
                        part.append(value)
                else:
                    slide.append(g * len(columns) + c)
    contype, affinity = model.geom_contype, model.geom_conaffinity
    capsule = model.geom_type == int(mujoco.mjtGeom.mjGEOM_CAPSULE)
    exact = capsule | (model.geom_type == int(mujoco.mjtGeom.mjGEOM_SPHERE))
    half = np.where(capsule, model.geom_size[:, 1], 0.0)
    radius = np.where(exact, model.geom_size[:, 0], model.geom_rbound)
    weld = model.body_weldid[model.geom_bodyid]
    near, far, groups = [], [], {}
    for a, b in pairs:
        first = len(near)
        for g in np.flatnonzero(robot_of == a):
            for h in np.flatnonzero(robot_of == b):
                # geoms that can touch: MuJoCo's contact bits, and bodies not welded together (its
                # collision skips those: two robots' bases, both fixed to the world, never touch
                # there; before 2026-11-30 04:25 UTC they were checked here, and a pair of robots
                # could have been held touching by its overlapping bases alone)
                if ((contype[g] & affinity[h]) or (contype[h] & affinity[g])) and weld[g] != weld[h]:
                    near.append(int(g))
                    far.append(int(h))
        groups[(int(a), int(b))] = (first, len(near))
    near_a, far_a = np.array(near, dtype=np.intp), np.array(far, dtype=np.intp)
    return CellBound(near_a, far_a, groups, half, (exact[near_a] & exact[far_a]).astype(np.uint8),
                     radius[near_a] + radius[far_a] + CONTACT_MM / 1000.0 + SAFETY_M,
                     tuple(np.array(p, dtype=np.intp) for p in hinge), np.array(slide, dtype=np.intp),
                     int(model.ngeom), len(columns))


def _ancestors(model, body: int) -> set[int]:
    """`body` and the bodies above it, the world (0) left out: a joint of one of these, or of
    the world, carries what `body` carries."""
    out = set()
    while body > 0:
        out.add(body)
        body = int(model.body_parentid[body])
    return out


__all__ = ["CellBound", "LEVER_SLACK_M2", "Reference", "SAFETY_M", "bound_of"]
