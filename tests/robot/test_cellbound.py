"""The bound that proves a cell's robots apart (issue 89, robot/cellbound.py): each joint's lever
for each geom at a reference pose against MuJoCo's own Jacobian (the speed of the geom's centre per
unit of the joint: for a hinge, the centre's distance from its axis), A1's worked out by hand from
the geom's centre, the displacement of a turning A1 against the gaps, and no pose it proves apart
in which MuJoCo's own check (robot/cellscene.py ``touches``) finds two robots touching.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np

from scipy.spatial.distance import cdist

from robot import cellproof
from robot.cellbound import LEVER_SLACK_M2, SAFETY_M
from robot.cellscene import CellScene, Placement
from robot.collision import CONTACT_MM
from robot.kinematics.compiled import pure_module
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


def test_each_lever_is_the_fastest_end_of_the_geoms_segment_per_radian_of_its_joint():
    """At random poses, each column's lever for each geom is the larger norm of MuJoCo's Jacobian
    of the two ends of the geom's segment (a capsule's axis, a sphere's centre) for that joint
    (``mj_jac``, after ``mj_comPos``; 0 for a geom the joint does not carry), to 1e-9 m beyond
    the slack; A1's for R1's wrist sphere (link 6), by hand, the distance of its centre from
    R1's A1 axis (vertical through R1's base at the origin): its centre's X, Y."""
    scene = _scene()
    bound = scene.bound()
    m, d = scene.model, scene.data
    rng = np.random.default_rng(7)
    wrist = m.geom("R1/link_6_geom").id
    assert m.geom_type[wrist] == mujoco.mjtGeom.mjGEOM_SPHERE
    columns = [int(m.jnt_dofadr[m.jnt_qposadr.tolist().index(a)]) for a in scene._all]
    for _ in range(20):
        q = _values(scene, HOME + rng.uniform(-60, 60, 6), HOME + rng.uniform(-60, 60, 6))
        ref = bound.reference(q, d)
        mujoco.mj_comPos(m, d)          # the joints' motion axes mj_jac reads
        for g in range(m.ngeom):
            speeds = []
            for sign in (1.0, -1.0):
                # the segment's end: MuJoCo's capsule lies along its frame's Z, half its length (size[1]) each way
                end = d.geom_xpos[g] + sign * (m.geom_size[g][1] if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE else 0.0) \
                    * d.geom_xmat[g].reshape(3, 3)[:, 2]
                jacp = np.zeros((3, m.nv))
                mujoco.mj_jac(m, d, jacp, None, end, int(m.geom_bodyid[g]))
                speeds.append(np.linalg.norm(jacp, axis=0)[columns])
            speed = np.maximum(*speeds)
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
    assert ref.proves and ref.touching == ()
    poses = np.repeat(ref.pose[None, :], 200, axis=0)
    poses[:, 0] += np.radians(np.arange(1, 201))       # A1: R1's first column (its sign aside)
    lever = ref.levers[bound.near, 0]                   # R1's geoms are the pairs' near ones
    first = min(math.ceil(gap / (lev * math.pi / 180.0)) for gap, lev in zip(ref.gaps, lever) if lev > 1e-5)
    assert bound.proved(ref, poses, 0) == first - 1
    assert bound.proved(ref, poses, 10) == first - 1
    swing = np.repeat(ref.pose[None, :], 500, axis=0)
    swing[:, 0] += np.radians(5.0 * np.sin(np.arange(500)))
    assert 5 * math.pi / 180 * lever.max() < ref.gaps.min() and bound.proved(ref, swing, 0) == 500


def test_every_pose_proved_has_the_touches_the_reference_holds():
    """Random reference poses of two robots facing each other 900 mm apart, the pairs MuJoCo
    finds touching there given to the reference, and random poses near them: in every pose the
    bound proves, MuJoCo's check finds exactly the pairs the reference holds touching (none
    where it holds none); poses proved apart, proved touching and touching unproved all occur
    (the test is not empty)."""
    rng = np.random.default_rng(89)
    scene = _scene(900.0)
    bound = scene.bound()
    seen = {"apart": 0, "touching": 0, "unproved touching": 0}
    for _ in range(600):
        q = _values(scene, *(HOME + rng.uniform(-60, 60, 6) for _ in range(2)))
        touching = [(0, 1)] if scene.contacts() else []
        ref = bound.reference(q, scene.data, touching)
        pose = ref.pose + rng.normal(0.0, rng.choice([0.005, 0.02, 0.05, 0.2]), ref.pose.shape)
        scene.copy_all(pose)
        now = [(0, 1)] if scene.touches() else []
        if bound.proved(ref, pose[None, :], 0) == 1:
            assert now == list(ref.touching)
            seen["touching" if now else "apart"] += 1
        else:
            seen["unproved touching"] += bool(now)
    assert min(seen.values()) > 20, seen


def test_the_gaps_are_every_geom_pairs_distance_in_mujoco_less_the_margins():
    """Four robots 1.5 m apart in a row at random poses: the checked geom pairs are every geom
    of one robot of a checked pair with every geom of the other but the two bases, and each gap is the signed
    distance MuJoCo gives the two geoms (capsules and spheres: ``mj_geomDistance``) less the
    contact distance and the safety margin, to 1e-9 m; so too for two robots 900 mm apart,
    whose geoms penetrate in some poses (some distances negative)."""
    machine = load_machine()
    scene = CellScene([Placement(f"R{k + 1}", machine, (1500.0 * k, 0, 0, 0, 0, 0)) for k in range(4)])
    bound = scene.bound()
    assert scene.pairs == [(0, 1), (1, 2), (2, 3)]
    robot_of, labels = scene._robot_of, scene._labels
    # (the two bases, both fixed to the world, never touch in MuJoCo's collision: not checked)
    want_pairs = [(g, h) for a, b in scene.pairs for g in np.flatnonzero(robot_of == a) for h in np.flatnonzero(robot_of == b)
                  if not labels[g][1] == labels[h][1] == "base"]
    assert list(zip(bound.near.tolist(), bound.far.tolist())) == want_pairs and bound.exact.all()
    rng = np.random.default_rng(15)
    penetrating = 0
    # and two robots 900 mm apart, whose geoms often penetrate (a negative distance)
    close = _scene(900.0)
    for scene, bound, want_pairs in ((scene, bound, want_pairs),
                                     (close, close.bound(), list(zip(close.bound().near, close.bound().far)))):
        for _ in range(200):
            scene.place(np.concatenate([scene.scale(n) * (HOME + rng.uniform(-90, 90, 6)) for n in scene.names]))
            got = bound.reference(np.zeros(bound.columns), scene.data).gaps
            want = np.array([mujoco.mj_geomDistance(scene.model, scene.data, g, h, 10.0, None) for g, h in want_pairs])
            assert np.abs(got - (want - CONTACT_MM / 1000.0 - SAFETY_M)).max() < 1e-9
            penetrating += int((want < 0).sum())
    assert penetrating > 20


def test_segment_distance_is_the_least_distance_of_two_segments():
    """Random segments, parallel ones, points and crossing ones: robot/cellproof.py's
    ``segment_distance`` (the form in use) is the least distance MuJoCo gives two capsules of a
    tiny radius on them (``mj_geomDistance`` plus both radii), to 1e-12 m; and never more than
    the least over 401 x 401 points sampled along each (a least distance, not an estimate)."""
    rng = np.random.default_rng(5)
    n = 600
    p1, q1, p2, q2 = (rng.normal(size=(n, 3)) for _ in range(4))
    q1[:150] = p1[:150] + (q2[:150] - p2[:150]) * rng.uniform(-2, 2, (150, 1))     # parallel
    q1[150:250] = p1[150:250]                                                       # a point
    q2[200:300] = p2[200:300]                                                       # a point (both, 200-250)
    mid = (p2[300:350] + q2[300:350]) / 2                                           # crossing
    p1[300:350], q1[300:350] = 2 * mid - q1[300:350], q1[300:350]
    loops = pure_module(cellproof)
    got = np.array([loops.segment_distance(*p1[i], *(q1[i] - p1[i]), *p2[i], *(q2[i] - p2[i])) for i in range(n)])
    u = np.linspace(0.0, 1.0, 401)
    for i in range(0, n, 3):
        a = p1[i] + np.outer(u, q1[i] - p1[i])
        b = p2[i] + np.outer(u, q2[i] - p2[i])
        assert got[i] <= cdist(a, b).min() + 1e-12
    assert got[300:350].max() < 1e-12
    for i in range(n):
        assert abs(got[i] - _mujoco_segments(p1[i], q1[i], p2[i], q2[i])) < 1e-12


def _mujoco_segments(p1, q1, p2, q2) -> float:
    """The least distance of segments p1-q1 and p2-q2 by MuJoCo: two capsules (or spheres where
    a segment is a point) of a tiny radius on them, ``mj_geomDistance`` plus both radii."""
    spec = mujoco.MjSpec()
    for p, q in ((p1, q1), (p2, q2)):
        if np.linalg.norm(q - p) > 1e-9:
            spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[1e-6, 0, 0], fromto=[*p, *q])
        else:
            spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[1e-6, 0, 0], pos=p)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return mujoco.mj_geomDistance(model, data, 0, 1, 100.0, None) + 2e-6


def test_a_touching_pair_is_held_by_its_deepest_pair_of_geoms_in_mujoco():
    """Three robots, R1 and R2 0.7 m apart, R3 1.4 m beyond R2, at random poses: a reference given
    the robot pairs MuJoCo finds touching holds each of them touching by its deepest pair of geoms
    by MuJoCo's distances (``mj_geomDistance``): that pair's limit is the contact distance less
    the safety margin less its distance, the pair's other geom pairs untested (no limit), every
    other geom pair's limit its gap; a pair found touching by less than twice the margin is not
    held (its gaps stand, some negative: the reference proves nothing)."""
    machine = load_machine()
    scene = CellScene([Placement("R1", machine), Placement("R2", machine, (700.0, 0, 0, 180.0, 0, 0)),
                       Placement("R3", machine, (2100.0, 0, 0, 0, 0, 0))])
    bound = scene.bound()
    rng = np.random.default_rng(31)
    held = 0
    for _ in range(150):
        q = np.concatenate([scene.scale(n) * (HOME + rng.uniform(-70, 70, 6)) for n in scene.names])
        scene.place(q)
        touching = sorted({(scene.names.index(t.first[0]), scene.names.index(t.second[0])) for t in scene.contacts()})
        ref = bound.reference(q, scene.data, touching)
        want = ref.gaps.copy()
        kept = []
        for pair in touching:
            first, end = bound.groups[pair]
            dist = [mujoco.mj_geomDistance(scene.model, scene.data, int(bound.near[k]), int(bound.far[k]), 10.0, None)
                    for k in range(first, end)]
            k = first + int(np.argmin(dist))
            depth = CONTACT_MM / 1000.0 - SAFETY_M - min(dist)
            if depth > 0.0:
                want[first:end] = np.inf
                want[k] = depth
                kept.append(pair)
        assert list(ref.touching) == kept
        assert np.allclose(ref.limits, want, atol=1e-9, rtol=0) and (np.isinf(ref.limits) == np.isinf(want)).all()
        assert ref.proves == bool((want > 0).all())
        held += len(kept)
    assert held > 20


def test_a_held_pair_is_one_mujoco_reports_and_bases_fixed_to_the_world_are_not_checked():
    """Two robots 250 mm apart, side by side, their bases (both fixed to the world) overlapping:
    MuJoCo's collision never reports the two bases (``mj_geomDistance`` gives them -148 mm at
    home, no contact), and the bound checks no geom pair MuJoCo skips; at random poses the pair
    of geoms that holds the robots touching is always one MuJoCo reports touching there (before:
    the bases, 148 mm deep, could hold the robots touching with their arms apart)."""
    machine = load_machine()
    scene = CellScene([Placement("R1", machine), Placement("R2", machine, (250.0, 0, 0, 0, 0, 0))])
    bound = scene.bound()
    m = scene.model
    bases = (m.geom("R1/base_geom").id, m.geom("R2/base_geom").id)
    q = _values(scene, HOME, HOME)
    assert mujoco.mj_geomDistance(m, scene.data, *bases, 10.0, None) < -0.1
    assert bases not in set(zip(bound.near.tolist(), bound.far.tolist()))
    rng = np.random.default_rng(250)
    held = 0
    for _ in range(200):
        q = _values(scene, *(HOME + rng.uniform(-170, 170, 6) * [1, .5, .5, 1, .5, 1] for _ in range(2)))
        mujoco.mj_collision(m, scene.data)
        reported = {tuple(sorted((int(c.geom1), int(c.geom2)))) for c in scene.data.contact if c.dist < CONTACT_MM / 1000.0}
        ref = bound.reference(q, scene.data, [(0, 1)] if reported else [])
        if ref.touching:
            first, end = bound.groups[(0, 1)]
            k = first + int(np.flatnonzero(np.isfinite(ref.limits[first:end]))[0])
            assert (int(bound.near[k]), int(bound.far[k])) in reported
            held += 1
    assert held > 20


def test_proved_is_the_first_row_in_which_a_geom_pair_reaches_its_gap():
    """Four robots 1.5 m apart, random references and random walks of 400 rows from each (steps
    of three sizes): ``proved`` from a random start is the first row from it in which some
    checked geom pair's two displacement bounds (each geom's levers times the columns'
    displacements from the reference, summed) reach the pair's limit, worked out here row by row
    and pair by pair; ``len(poses)`` when there is none. Each walk twice: with the gaps as limits
    (many pairs over a window: each geom's bound once a row) and with the nearest pair's limit,
    the others none (a held pair: that pair's two bounds a row). Walks proved through, stopped in
    the first window and stopped past it all occur (the windows and their doubling are
    exercised)."""
    machine = load_machine()
    scene = CellScene([Placement(f"R{k + 1}", machine, (1500.0 * k, 0, 0, 0, 0, 0)) for k in range(4)])
    bound = scene.bound()
    rng = np.random.default_rng(2211)
    seen = set()
    for _ in range(80):
        q = np.concatenate([scene.scale(n) * (HOME + rng.uniform(-60, 60, 6)) for n in scene.names])
        scene.place(q)
        ref = bound.reference(q, scene.data)
        if not ref.proves:
            continue
        poses = ref.pose + np.cumsum(rng.normal(0.0, rng.choice([0.0002, 0.001, 0.004, 0.016]), (400, len(q))), axis=0)
        start = int(rng.integers(0, 50))
        one = np.full(len(ref.limits), np.inf)
        k = int(np.argmin(ref.limits))
        one[k] = ref.limits[k]
        for limits in (ref.limits, one):
            want = len(poses)
            for r in range(start, len(poses)):
                moved = [float(np.dot(ref.levers[g], np.abs(poses[r] - ref.pose))) for g in range(scene.model.ngeom)]
                if any(moved[g] + moved[h] >= gap for g, h, gap in zip(bound.near, bound.far, limits)):
                    want = r
                    break
            assert bound.proved(dataclasses.replace(ref, limits=limits), poses, start) == want
            seen.add(("gaps" if limits is ref.limits else "one",
                      "through" if want == len(poses) else "first window" if want < start + 64 else "past it"))
    assert seen == {(a, b) for a in ("gaps", "one") for b in ("through", "first window", "past it")}, seen


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
