"""A conservative bound that proves a cell's robots apart over a run of poses (issue 89;
docs/cells.md "Speed"): the cycles of a turn that need no MuJoCo contact check.

At a *reference* pose the scene (robot/cellscene.py), its kinematics computed, gives each geom's
centre (``geom_xpos``) and bounding radius (``geom_rbound``: the geom lies in that sphere about its
centre, whatever the pose), and each joint's anchor and axis (``xanchor``, ``xaxis``). The *gap*
of two geoms of two robots that can touch (MuJoCo's contact bits) is the distance of their
centres less both radii, the contact distance (:data:`robot.collision.CONTACT_MM`) and
:data:`SAFETY_M`; at the reference, each joint's *lever* for a geom it carries (the geom's body is
the joint's or below it) is the distance of the geom's centre from the joint's axis (a hinge), or
1 (a slide, m per m).

Soundness (why a pose this bound proves apart has no contact in MuJoCo's check). Go from the
reference pose to another by moving the joints one after the other in MuJoCo's order (a body's
parents first, a body's joints in their order). When joint j moves, the joints before it have
moved what j carries rigidly (each joint's motion is a rotation or a translation of its body and
everything below it) and the joints after it stand at their reference values: so the geom's
centre stands at its reference distance from j's axis, and turning j by ``dq`` moves it along a
circle's chord, at most that distance times ``|dq|`` (a slide: by ``|dq|``). Summed over the
joints (the triangle inequality), geom g's centre lies within ``D_g = sum_j |q_j - ref_j|
lever_jg`` of where it stood, for any pose, with no assumption of speed or path (the displacement
from the reference, not the travel along the cycles, counts: before 2026-11-29 20:00 UTC the
travel summed along the cycles, times each joint's largest lever over every pose of its robot, for
each robot as a whole). The geom lies in its sphere about that centre, so two geoms whose gap
exceeds ``D_g + D_h`` lie more than the contact distance apart: MuJoCo gives them no contact.
A pose whose every checked geom pair is so apart (:meth:`CellBound.proved`) is one in which
MuJoCo's check finds no two robots touching; the reference pose itself is when every gap is
positive (``D`` 0). The levers are rounded up by :data:`LEVER_SLACK_M2` under the square root
(the rounding of ``|v|^2 - (v.a)^2``, about 1e-15 m^2 for the cell's sizes) and the rest of the
float arithmetic stays far under :data:`SAFETY_M`.

Raises nothing; :func:`bound_of` returns None for a scene it cannot bound (a geom without a
bounding radius, a moving joint neither hinge nor slide).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from .collision import CONTACT_MM

#: what a proof keeps in hand beyond the contact distance (m): rounding of the sums above
SAFETY_M = 0.001
#: added to each squared lever (m^2) before its root: rounding of the squared distance from the axis
LEVER_SLACK_M2 = 1e-12
#: the rows :meth:`CellBound.proved` looks at first, doubled while they are all proved
WINDOW = 64


@dataclass
class Reference:
    """What a reference pose proves (module docstring): ``pose`` (the scene's values, columns),
    ``gaps`` (m, each checked geom pair's), ``levers`` (geoms, columns: each column's lever for
    each geom, 0 for a geom it does not carry), ``apart``: every gap positive (the pose itself
    has no contact between robots)."""
    pose: np.ndarray
    gaps: np.ndarray
    levers: np.ndarray
    apart: bool


#: sums a row of three (a matrix product: one call where ``sum(axis=1)`` costs three times more)
_XYZ = np.ones(3)


@dataclass
class CellBound:
    """The bound of one scene (module docstring). ``near``, ``far``: the geoms of each geom pair
    checked (every geom of the first robot of a checked robot pair with every geom of the second
    that can touch it); ``reach``: the pair's two radii, the contact distance and
    :data:`SAFETY_M` (m); ``hinge``: (flat indices into a (geoms, columns) array, joints, geoms)
    of each hinge column and a geom its joint carries; ``slide``: the flat indices of each slide
    column and a geom it carries; ``ngeom``, ``columns``: the scene's geoms and the columns of
    its poses (``copy_all``'s)."""
    near: np.ndarray
    far: np.ndarray
    reach: np.ndarray
    hinge: tuple
    slide: np.ndarray
    ngeom: int
    columns: int

    def gaps(self, xpos: np.ndarray) -> np.ndarray:
        """Each checked geom pair's gap (m) with the geoms' centres `xpos` (ngeom, 3); each
        distance summed over X, Y, Z in that order as scipy's ``cdist`` sums it."""
        d = xpos.take(self.near, axis=0)
        d -= xpos.take(self.far, axis=0)
        d *= d
        s = d[:, 0] + d[:, 1]
        s += d[:, 2]
        np.sqrt(s, out=s)
        s -= self.reach
        return s

    def reference(self, pose: np.ndarray, data) -> Reference:
        """The reference at `pose` (columns), the scene's MuJoCo `data` standing there with its
        kinematics computed (``geom_xpos``, ``xanchor``, ``xaxis``)."""
        gaps = self.gaps(data.geom_xpos)
        flat, joints, geoms = self.hinge
        v = data.geom_xpos.take(geoms, axis=0)
        v -= data.xanchor.take(joints, axis=0)
        along = (v * data.xaxis.take(joints, axis=0)) @ _XYZ
        v *= v
        r2 = v @ _XYZ
        along *= along
        r2 -= along
        np.maximum(r2, 0.0, out=r2)
        r2 += LEVER_SLACK_M2
        levers = np.zeros((self.ngeom, self.columns))
        levers.put(flat, np.sqrt(r2, out=r2))
        if len(self.slide):
            levers.put(self.slide, 1.0)
        return Reference(pose.copy(), gaps, levers, bool((gaps > 0.0).all()))

    def proved(self, ref: Reference, poses: np.ndarray, start: int) -> int:
        """The first row of `poses` (cycles, columns) from `start` on that `ref` leaves unproved
        (``len(poses)`` when it proves them all): the rows from `start` to it have every checked
        geom pair apart. Looks at :data:`WINDOW` rows first, doubled while they are all proved; in
        a window, the pairs that its largest displacement of each column proves are not looked
        at row by row."""
        if not ref.apart:
            return start
        n, j, width = len(poses), start, WINDOW
        near, far, gaps = self.near, self.far, ref.gaps
        while j < n:
            stop = min(n, j + width)
            d = poses[j:stop] - ref.pose
            np.abs(d, out=d)
            top = ref.levers @ d.max(axis=0)        # each geom's displacement bound over the window
            over = top.take(near) + top.take(far) >= gaps
            if over.any():
                each = ref.levers @ d.T             # (geoms, rows)
                bad = (each.take(near[over], axis=0) + each.take(far[over], axis=0) >= gaps[over, None]).any(axis=0)
                if bad.any():
                    return j + int(bad.argmax())
            j, width = stop, 2 * width
        return n


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
    contype, affinity, radius = model.geom_contype, model.geom_conaffinity, model.geom_rbound
    near, far = [], []
    for a, b in pairs:
        for g in np.flatnonzero(robot_of == a):
            for h in np.flatnonzero(robot_of == b):
                # geoms that can touch (MuJoCo's contact bits; the others never give a contact)
                if (contype[g] & affinity[h]) or (contype[h] & affinity[g]):
                    near.append(int(g))
                    far.append(int(h))
    near_a, far_a = np.array(near, dtype=np.intp), np.array(far, dtype=np.intp)
    return CellBound(near_a, far_a, radius[near_a] + radius[far_a] + CONTACT_MM / 1000.0 + SAFETY_M,
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


__all__ = ["CellBound", "LEVER_SLACK_M2", "Reference", "SAFETY_M", "WINDOW", "bound_of"]
