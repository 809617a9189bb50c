"""The bound that proves a cell's robots apart (issue 89, robot/cellbound.py): the KR 6 R900's
levers worked out by hand from its joint offsets, the travel of a turning axis, and no pose it
proves apart in which MuJoCo's own check (robot/cellscene.py ``touches``) finds two robots touching.

By hand (../shared/docs/robot-model.md §2: joint_a2 0.025 m past A1's body on X, A3 0.455, A4
0.035 on Z, A5 0.420, A6 0.080; every anchor at its body's origin): the farthest geom each axis
carries is link 6's sphere, at link 6's origin on A6's axis, so A1's lever is 0.025 + 0.455 +
0.035 + 0.420 + 0.080 = 1.015 m, A2's 0.990, A3's 0.535, A4's 0.500, A5's 0.080 and A6's 0.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from scipy.spatial.distance import cdist

from robot.cellbound import SAFETY_M
from robot.cellscene import CellScene, Placement
from robot.collision import CONTACT_MM
from robot.machine import load_machine

LEVERS = [1.015, 0.990, 0.535, 0.500, 0.080, 0.0]
HOME = [0, -90, 90, 0, 0, 0]


def _scene(d: float = 1150.0) -> CellScene:
    machine = load_machine()
    return CellScene([Placement("R1", machine), Placement("R2", machine, (d, 0, 0, 180, 0, 0))])


def _values(scene: CellScene, r1, r2) -> np.ndarray:
    """The scene's values (``copy_all``'s) of R1 at axes `r1`, R2 at `r2` (deg), placed there with
    its kinematics computed."""
    values = np.concatenate([scene.scale("R1") * np.asarray(r1, float), scene.scale("R2") * np.asarray(r2, float)])
    scene.copy_all(values)
    mujoco.mj_kinematics(scene.model, scene.data)
    return values


def test_the_levers_are_the_chains_offsets():
    bound = _scene().bound()
    assert np.allclose(bound.levers[:6, 0], LEVERS, atol=1e-9) and not bound.levers[:6, 1].any()
    assert np.allclose(bound.levers[6:, 1], LEVERS, atol=1e-9) and not bound.levers[6:, 0].any()


def test_a_turning_a1_is_proved_apart_until_its_travel_reaches_the_gap():
    """R1 turns A1 by 1 deg a cycle from HOME, R2 stands 2 m away: the travel after n cycles is
    n x 1.015 m x pi/180, and the poses are proved apart while it stays under the gap."""
    scene = _scene(2000.0)
    bound = scene.bound()
    ref = _values(scene, HOME, HOME)
    gap = float(bound.gaps(scene.data.geom_xpos)[0])
    poses = np.repeat(ref[None, :], 200, axis=0)
    poses[:, 0] += np.radians(np.arange(1, 201))       # A1: R1's first column (its sign aside)
    paths = bound.paths(ref, poses)
    assert np.allclose(paths[0], np.arange(1, 201) * 1.015 * math.pi / 180.0)
    assert bound.proved(paths, -1, [gap], 0) == math.ceil(gap / (1.015 * math.pi / 180.0)) - 1
    # from row 10 as the reference, 10 cycles less of travel left
    assert bound.proved(paths, 9, [gap], 10) == math.ceil(gap / (1.015 * math.pi / 180.0)) - 1 + 10


def test_no_pose_proved_apart_touches():
    """Random reference poses of two robots facing each other 900 mm apart and random poses
    near them: every pose the bound proves apart has no contact in MuJoCo's check; some are
    proved, some touch (the test is not empty)."""
    rng = np.random.default_rng(89)
    scene = _scene(900.0)
    bound = scene.bound()
    proved = touching = 0
    for _ in range(400):
        ref = _values(scene, *(HOME + rng.uniform(-60, 60, 6) for _ in range(2)))
        gaps = bound.gaps(scene.data.geom_xpos)
        pose = ref + rng.normal(0.0, rng.choice([0.01, 0.05, 0.2]), ref.shape)
        scene.copy_all(pose)
        if bound.proved(bound.paths(ref, pose[None, :]), -1, gaps, 0) == 1:
            proved += 1
            assert scene.touches() == []
        else:
            touching += bool(scene.touches())
    assert proved > 20 and touching > 20


def test_the_gaps_are_every_geom_pairs_least_clearance_to_the_bit():
    """Four robots 1.5 m apart in a row at random poses: each checked pair's gap is the least,
    over every geom of the one with every geom of the other, of their centres' distance less both
    bounding radii, the contact distance and the safety margin (scipy's ``cdist`` of the geoms'
    centres, as the bound measured it before 2026-11-29: the same value to the last bit)."""
    machine = load_machine()
    scene = CellScene([Placement(f"R{k + 1}", machine, (1500.0 * k, 0, 0, 0, 0, 0)) for k in range(4)])
    bound = scene.bound()
    assert scene.pairs == [(0, 1), (1, 2), (2, 3)]
    m, robot_of = scene.model, scene._robot_of
    rng = np.random.default_rng(15)
    for _ in range(200):
        scene.copy_all(np.concatenate([scene.scale(n) * (HOME + rng.uniform(-90, 90, 6)) for n in scene.names]))
        mujoco.mj_kinematics(m, scene.data)
        x = scene.data.geom_xpos
        want = []
        for a, b in scene.pairs:
            ga, gb = np.flatnonzero(robot_of == a), np.flatnonzero(robot_of == b)
            radii = m.geom_rbound[ga][:, None] + m.geom_rbound[gb][None, :] + CONTACT_MM / 1000.0 + SAFETY_M
            want.append((cdist(x[ga], x[gb]) - radii).min())
        assert bound.gaps(x).tolist() == want
