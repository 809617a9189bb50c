"""A conservative bound that proves a cell's robots apart over a run of poses (issue 89;
docs/cells.md "Speed"): the cycles of a turn that need no MuJoCo contact check.

At a *reference* pose the scene (robot/cellscene.py) gives each geom's centre (``geom_xpos``)
and bounding radius (``geom_rbound``: the geom lies in that sphere), so the *gap* of two robots
is the least distance between two of their spheres that can touch (MuJoCo's contact bits), less
both radii. From the reference to another pose each joint turns by ``|dq|``; a point carried by
a hinge moves by at most its distance from the joint's anchor times ``|dq|`` (the chord is shorter
than the arc), and that distance is at most the joint's *lever*: the anchor's offset in its body,
the offsets of the bodies down the chain (``body_pos``, each with twice its own joints' anchor
offsets: a hinge away from its body's origin moves that origin) and the geom's offset in its body,
whatever the other joints; a slide moves what it carries by ``|dq|`` (m). Moving the joints one
after the other from the reference to the pose, robot k's geoms move at most
``D_k = sum_j |dq_j| lever_j`` (its static cell bodies not at all); two robots whose gap exceeds
``D_a + D_b`` and :data:`SAFETY_M` touch in no geom at that pose: the pose's MuJoCo check would
give no contact between them. Nothing assumes a speed: every pose is bounded from its own joint
values.

Raises nothing; :func:`bound_of` returns None for a scene it cannot bound (a geom without a
bounding radius, a joint neither hinge nor slide, an unlimited slide).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from .collision import CONTACT_MM

#: what a proof keeps in hand beyond the contact distance (m): rounding of the sums above
SAFETY_M = 0.001


@dataclass
class CellBound:
    """The bound of one scene (module docstring). ``levers``: (columns, robots), column j's lever
    (m per rad, 1 for a slide) in its robot's column, 0 elsewhere; the columns are the scene's
    ``copy_all`` values. ``first``, ``second``: the robot pairs checked (two index arrays);
    ``near``, ``far``: the geoms of each checked pair's two robots, every geom of the first with
    every geom of the second, the pairs one after the other (each pair's block begins at its
    ``blocks`` entry); ``reach``: the sums of their two radii and the contact distance (inf
    where two geoms cannot touch)."""
    levers: np.ndarray
    first: np.ndarray
    second: np.ndarray
    near: np.ndarray
    far: np.ndarray
    blocks: np.ndarray
    reach: np.ndarray

    def gaps(self, xpos: np.ndarray) -> np.ndarray:
        """Each pair's gap (m) with the geoms' centres `xpos` (ngeom, 3) of the reference pose.

        Only the checked pairs' geoms are measured (before 2026-11-29 every geom with every other:
        28 x 28 for four KR 6 where a chain's three pairs need three 7 x 7 blocks, 23 -> 17 us of
        CPU a reference), each distance summed over X, Y, Z in that order as scipy's ``cdist``
        sums it, so each gap is the one measured before, to the last bit."""
        # (``take``: the rows fancy indexing gives, 20k instructions a reference less; 2026-11-29)
        d = xpos.take(self.near, axis=0)
        d -= xpos.take(self.far, axis=0)
        d *= d
        s = d[:, 0] + d[:, 1]
        s += d[:, 2]
        np.sqrt(s, out=s)
        s -= self.reach
        return np.minimum.reduceat(s, self.blocks)

    def paths(self, ref: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """Each pair's bound of the two robots' travel along `poses` (cycles, columns) from the
        pose `ref` (columns), (pairs, cycles) and non-decreasing along each row: ``D_a + D_b``
        of each step from one pose to the next, summed (the travel to a pose bounds its distance
        from any pose before it: :meth:`proved` tests a run of poses with one search a pair)."""
        step = np.abs(np.diff(poses, axis=0, prepend=ref[None, :])) @ self.levers
        np.cumsum(step, axis=0, out=step)
        # (``take``: the columns fancy indexing gives, by a simpler loop; 2026-11-29)
        return np.ascontiguousarray((step.take(self.first, axis=1) + step.take(self.second, axis=1)).T)

    def proved(self, paths: np.ndarray, ref: int, gaps: np.ndarray, start: int) -> int:
        """The first cycle from `start` on that :meth:`paths` leaves unproved: the poses from
        `start` to it are apart, their travel from the reference pose (cycle `ref` of `paths`,
        -1 before the first) under every pair's `gaps`."""
        end = paths.shape[1]
        for k, row in enumerate(paths):
            end = min(end, int(row.searchsorted((row[ref] if ref >= 0 else 0.0) + gaps[k])))
            if end <= start:
                return start
        return end


def bound_of(model, robot_of: np.ndarray, columns: np.ndarray, pairs: list) -> CellBound | None:
    """The bound of the scene `model` (MuJoCo's) whose geom g belongs to robot ``robot_of[g]``,
    its poses given as the qpos values at addresses `columns`, for the robot `pairs` (index
    pairs); None when some geom or joint cannot be bounded (module docstring)."""
    if (model.geom_rbound <= 0).any():
        return None
    chain = _chains(model)
    if chain is None:
        return None
    adr_joint = {int(model.jnt_qposadr[j]): j for j in range(model.njnt)}
    robots = int(robot_of.max()) + 1
    levers = np.zeros((len(columns), robots))
    # each geom's body and the bodies above it (the joints of these carry it), its offset in its
    # body and each body's chain, as Python values once (before 2026-11-29 read from MuJoCo's
    # arrays per joint and geom: 2.4 ms for four KR 6; the same sums, in the same order)
    geom_body = model.geom_bodyid.tolist()
    above = [_ancestors(model, b) for b in geom_body]
    offset = [float(np.linalg.norm(model.geom_pos[g])) for g in range(model.ngeom)]
    chains = chain.tolist()
    for c, adr in enumerate(columns):
        j = adr_joint[int(adr)]
        body = int(model.jnt_bodyid[j])
        # the geoms this joint carries: on its body or below it
        carried = [g for g in range(model.ngeom) if body == 0 or body in above[g]]
        if not carried:
            continue
        k = int(robot_of[carried[0]])
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE:
            levers[c, k] = 1.0
        else:
            anchor = float(np.linalg.norm(model.jnt_pos[j]))
            levers[c, k] = max(anchor + chains[geom_body[g]] - chains[body] + offset[g] for g in carried)
    order = np.argsort(robot_of, kind="stable")
    owner = robot_of[order]
    starts = np.searchsorted(owner, np.arange(robots))
    if (np.diff(np.append(starts, len(owner))) == 0).any():
        return None         # a robot without a geom (reduceat needs every block non-empty)
    radius = model.geom_rbound[order]
    contype, affinity = model.geom_contype[order], model.geom_conaffinity[order]
    touch = ((contype[:, None] & affinity[None, :]) | (contype[None, :] & affinity[:, None])) != 0
    reach = np.where(touch, radius[:, None] + radius[None, :] + CONTACT_MM / 1000.0 + SAFETY_M, np.inf)
    first = np.array([a for a, _ in pairs], dtype=int)
    second = np.array([b for _, b in pairs], dtype=int)
    # each checked pair's block of geom pairs (every geom of the first robot with every one of the second)
    ends = np.append(starts[1:], len(order))
    near, far, sums = [], [], []
    for a, b in pairs:
        rows, cols = np.meshgrid(np.arange(starts[a], ends[a]), np.arange(starts[b], ends[b]), indexing="ij")
        near.append(order[rows.ravel()])
        far.append(order[cols.ravel()])
        sums.append(reach[rows.ravel(), cols.ravel()])
    blocks = np.cumsum([0] + [len(n) for n in near]).astype(np.intp)[:-1]
    return CellBound(levers, first, second, _joined(near, int), _joined(far, int), blocks, _joined(sums, float))


def _joined(parts: list, dtype) -> np.ndarray:
    """`parts` (arrays) one after the other (an empty array of `dtype` for none)."""
    return np.concatenate(parts) if parts else np.zeros(0, dtype=dtype)


def _chains(model) -> np.ndarray | None:
    """Each body's chain length (m) from the world: the sum over it and its ancestors of
    ``|body_pos|``, twice its hinges' anchor offsets and its slides' largest travel; None for a
    joint neither hinge nor slide, or an unlimited slide."""
    chain = np.zeros(model.nbody)
    for b in range(1, model.nbody):
        step = float(np.linalg.norm(model.body_pos[b]))
        for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
                step += 2.0 * float(np.linalg.norm(model.jnt_pos[j]))
            elif model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE and model.jnt_limited[j]:
                step += float(np.abs(model.jnt_range[j]).max()) + 2.0 * float(np.linalg.norm(model.jnt_pos[j]))
            else:
                return None
        chain[b] = chain[model.body_parentid[b]] + step
    return chain


def _ancestors(model, body: int) -> set[int]:
    """`body` and the bodies above it, the world (0) left out: a joint of one of these, or of
    the world, carries what `body` carries."""
    out = set()
    while body > 0:
        out.add(body)
        body = int(model.body_parentid[body])
    return out


__all__ = ["CellBound", "SAFETY_M", "bound_of"]
