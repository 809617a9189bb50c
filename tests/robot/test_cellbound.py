"""The bound that proves a cell's robots apart (issue 89, robot/cellbound.py): each joint's lever
for each geom at a reference pose against MuJoCo's own Jacobian (the speed of the geom's centre per
unit of the joint: for a hinge, the centre's distance from its axis), A1's worked out by hand from
the geom's centre, the displacement of a turning A1 against the gaps, and no pose it proves apart
in which MuJoCo's own check (robot/cellscene.py ``touches``) finds two robots touching.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from scipy.spatial.distance import cdist

from robot.cellbound import LEVER_SLACK_M2, SAFETY_M
from robot.cellscene import CellScene, Placement
from robot.collision import CONTACT_MM
from robot.machine import load_machine

HOME = [0, -90, 90, 0, 0, 0]


def _scene(d: float = 1150.0) -> CellScene:
    machine = load_machine()
    return CellScene([Placement("R1", machine), Placement("R2", machine, (d, 0, 0, 180, 0, 0))])


def _values(scene: CellScene, r1, r2) -> np.ndarray:
    """The scene's values (``copy_all``'s) of R1 at axes `r1`, R2 at `r2` (deg), placed there with
    its kinematics computed."""
    values = np.concatenate([scene.scale("R1") * np.asarray(r1, float), scene.scale("R2") * np.asarray(r2, float)])
    scene.place(values)
    return values


def test_each_lever_is_the_geom_centres_speed_per_radian_of_its_joint():
    """At random poses, each column's lever for each geom is the norm of MuJoCo's Jacobian of the
    geom's centre for that joint (``mj_jac``, after ``mj_comPos``; 0 for a geom the joint does not carry), to 1e-9 m
    beyond the slack; A1's for R1's wrist sphere (link 6), by hand, the distance of its centre
    from R1's A1 axis (vertical through R1's base at the origin): its centre's X, Y."""
    scene = _scene()
    bound = scene.bound()
    m, d = scene.model, scene.data
    rng = np.random.default_rng(7)
    wrist = m.geom("R1/link_6_geom").id
    for _ in range(20):
        q = _values(scene, HOME + rng.uniform(-60, 60, 6), HOME + rng.uniform(-60, 60, 6))
        ref = bound.reference(q, d)
        mujoco.mj_comPos(m, d)          # the joints' motion axes mj_jac reads
        for g in range(m.ngeom):
            jacp = np.zeros((3, m.nv))
            mujoco.mj_jac(m, d, jacp, None, d.geom_xpos[g], int(m.geom_bodyid[g]))
            speed = np.linalg.norm(jacp, axis=0)[[int(m.jnt_dofadr[m.jnt_qposadr.tolist().index(a)]) for a in scene._all]]
            carried = speed > 0
            assert np.allclose(ref.levers[g][carried], np.sqrt(speed[carried] ** 2 + LEVER_SLACK_M2), atol=1e-9)
            assert not ref.levers[g][~carried & (ref.levers[g] > 1e-5)].any()
        assert abs(ref.levers[wrist, 0] - math.hypot(*d.geom_xpos[wrist][:2])) < 1e-9


def test_a_turning_a1_is_proved_apart_until_its_displacement_reaches_a_gap():
    """R1 turns A1 by 1 deg a cycle from HOME, R2 stands 2 m away: after n cycles each of R1's
    geoms g has moved at most n deg times its A1 lever, so the poses are proved apart while every
    geom pair's gap exceeds it; R1 turning there and back by +-5 deg for 500 cycles stays proved
    (the displacement from the reference counts, not the 5,000 deg turned)."""
    scene = _scene(2000.0)
    bound = scene.bound()
    ref = bound.reference(_values(scene, HOME, HOME), scene.data)
    assert ref.apart
    poses = np.repeat(ref.pose[None, :], 200, axis=0)
    poses[:, 0] += np.radians(np.arange(1, 201))       # A1: R1's first column (its sign aside)
    lever = ref.levers[bound.near, 0]                   # R1's geoms are the pairs' near ones
    first = min(math.ceil(gap / (lev * math.pi / 180.0)) for gap, lev in zip(ref.gaps, lever) if lev > 1e-5)
    assert bound.proved(ref, poses, 0) == first - 1
    assert bound.proved(ref, poses, 10) == first - 1
    swing = np.repeat(ref.pose[None, :], 500, axis=0)
    swing[:, 0] += np.radians(5.0 * np.sin(np.arange(500)))
    assert 5 * math.pi / 180 * lever.max() < ref.gaps.min() and bound.proved(ref, swing, 0) == 500


def test_no_pose_proved_apart_touches():
    """Random reference poses of two robots facing each other 900 mm apart and random poses
    near them: every pose the bound proves apart has no contact in MuJoCo's check; some are
    proved, some touch (the test is not empty)."""
    rng = np.random.default_rng(89)
    scene = _scene(900.0)
    bound = scene.bound()
    proved = touching = 0
    for _ in range(400):
        ref = bound.reference(_values(scene, *(HOME + rng.uniform(-60, 60, 6) for _ in range(2))), scene.data)
        pose = ref.pose + rng.normal(0.0, rng.choice([0.01, 0.05, 0.2]), ref.pose.shape)
        scene.copy_all(pose)
        if bound.proved(ref, pose[None, :], 0) == 1:
            proved += 1
            assert scene.touches() == []
        else:
            touching += bool(scene.touches())
    assert proved > 20 and touching > 20


def test_the_gaps_are_every_geom_pairs_clearance_to_the_bit():
    """Four robots 1.5 m apart in a row at random poses: the checked geom pairs are every geom
    of one robot of a checked pair with every geom of the other, and each gap is their centres'
    distance less both bounding radii, the contact distance and the safety margin (scipy's
    ``cdist`` of the geoms' centres: the same value to the last bit)."""
    machine = load_machine()
    scene = CellScene([Placement(f"R{k + 1}", machine, (1500.0 * k, 0, 0, 0, 0, 0)) for k in range(4)])
    bound = scene.bound()
    assert scene.pairs == [(0, 1), (1, 2), (2, 3)]
    m, robot_of = scene.model, scene._robot_of
    want_pairs = [(g, h) for a, b in scene.pairs for g in np.flatnonzero(robot_of == a) for h in np.flatnonzero(robot_of == b)]
    assert list(zip(bound.near.tolist(), bound.far.tolist())) == want_pairs
    rng = np.random.default_rng(15)
    for _ in range(200):
        scene.place(np.concatenate([scene.scale(n) * (HOME + rng.uniform(-90, 90, 6)) for n in scene.names]))
        x = scene.data.geom_xpos
        want = [cdist(x[[g]], x[[h]])[0, 0] - (m.geom_rbound[g] + m.geom_rbound[h] + CONTACT_MM / 1000.0 + SAFETY_M)
                for g, h in want_pairs]
        assert bound.gaps(x).tolist() == want


def test_proved_is_the_first_row_in_which_a_geom_pair_reaches_its_gap():
    """Four robots 1.5 m apart, random references and random walks of 400 rows from each (steps
    of three sizes): ``proved`` from a random start is the first row from it in which some
    checked geom pair's two displacement bounds (each geom's levers times the columns'
    displacements from the reference, summed) reach the pair's gap, worked out here row by row
    and pair by pair; ``len(poses)`` when there is none. Walks proved through, stopped in the
    first window and stopped past it all occur (the windows and their doubling are exercised)."""
    machine = load_machine()
    scene = CellScene([Placement(f"R{k + 1}", machine, (1500.0 * k, 0, 0, 0, 0, 0)) for k in range(4)])
    bound = scene.bound()
    rng = np.random.default_rng(2211)
    seen = set()
    for _ in range(80):
        q = np.concatenate([scene.scale(n) * (HOME + rng.uniform(-60, 60, 6)) for n in scene.names])
        scene.place(q)
        ref = bound.reference(q, scene.data)
        if not ref.apart:
            continue
        poses = ref.pose + np.cumsum(rng.normal(0.0, rng.choice([0.0002, 0.001, 0.004]), (400, len(q))), axis=0)
        start = int(rng.integers(0, 50))
        want = len(poses)
        for r in range(start, len(poses)):
            moved = [float(np.dot(ref.levers[g], np.abs(poses[r] - ref.pose))) for g in range(scene.model.ngeom)]
            if any(moved[g] + moved[h] >= gap for g, h, gap in zip(bound.near, bound.far, ref.gaps)):
                want = r
                break
        assert bound.proved(ref, poses, start) == want
        seen.add("through" if want == len(poses) else "first window" if want < start + 64 else "past it")
    assert seen == {"through", "first window", "past it"}


def _deepest_by_arrays(scene: CellScene) -> list:
    """The deepest contact of each pair of robots, in the robots' order, from MuJoCo's contact
    arrays sorted with numpy (``contacts``' code before 2026-11-30): (first, second, mm)."""
    con = scene.data.contact
    dist = con.dist * 1000.0
    hit = dist < CONTACT_MM
    g1, g2, dist = con.geom1[hit], con.geom2[hit], dist[hit]
    r1, r2 = scene._robot_of[g1], scene._robot_of[g2]
    swap = r1 > r2
    g1, g2 = np.where(swap, g2, g1), np.where(swap, g1, g2)
    pair = np.minimum(r1, r2) * len(scene.names) + np.maximum(r1, r2)
    order = np.lexsort((dist, pair))
    first = np.ones(len(order), dtype=bool)
    first[1:] = pair[order[1:]] != pair[order[:-1]]
    return [(scene._labels[g1[k]], scene._labels[g2[k]], float(dist[k])) for k in order[first]]


def test_the_touches_are_each_pairs_deepest_contact_in_the_robots_order():
    """Three robots around one point, 0.7 m apart, at random poses: ``touches`` gives, for each pair of robots
    that MuJoCo finds penetrating, its deepest contact (bodies and mm, to the bit), the pairs in
    the robots' order, as the contact arrays sorted by numpy give them; some poses touch, some
    with more than one pair."""
    machine = load_machine()
    bases = [(0, 0, 0, 0, 0, 0), (700.0, 0, 0, 180.0, 0, 0), (350.0, 600.0, 0, -90.0, 0, 0)]
    scene = CellScene([Placement(f"R{k + 1}", machine, base) for k, base in enumerate(bases)])
    rng = np.random.default_rng(11)
    touching = several = 0
    for _ in range(300):
        scene.copy_all(np.concatenate([scene.scale(n) * (HOME + rng.uniform(-70, 70, 6)) for n in scene.names]))
        got = [(t.first, t.second, t.distance_mm) for t in scene.touches()]
        assert got == _deepest_by_arrays(scene)
        touching += bool(got)
        several += len(got) > 1
    assert touching > 30 and several > 5
