"""The MuJoCo model: FK equals the MuJoCo site pose of tool0 (robot-model.md §11-§12),
and the optional position+velocity servos follow a joint trajectory."""

from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from robot.kinematics import Kinematics  # noqa: E402
from robot.machine import load_machine  # noqa: E402
from robot.mjcf import ArmModel, build_mjcf  # noqa: E402

LIMITS = np.array([[-170, 170], [-190, 45], [-120, 156], [-185, 185], [-120, 120], [-350, 350]], dtype=float)


@pytest.fixture(scope="module")
def arm() -> ArmModel:
    return ArmModel(load_machine())


def test_mjcf_structure_matches_urdf_chain():
    root = ET.fromstring(build_mjcf(load_machine()))
    joints = {j.get("name"): j for j in root.find("worldbody").iter("joint")}
    assert list(joints) == [f"joint_a{i}" for i in range(1, 7)]
    # robot-model.md §2 table: axes and origins
    axes = ["0 0 -1", "0 1 0", "0 1 0", "-1 0 0", "0 1 0", "-1 0 0"]
    origins = [(0, 0, 0.4), (0.025, 0, 0), (0.455, 0, 0), (0, 0, 0.035), (0.42, 0, 0), (0.08, 0, 0)]
    bodies = {b.get("name"): b for b in root.iter("body")}
    for i in range(6):
        assert [float(v) for v in joints[f"joint_a{i + 1}"].get("axis").split()] == \
            [float(v) for v in axes[i].split()]
        np.testing.assert_allclose([float(v) for v in bodies[f"link_{i + 1}"].get("pos").split()], origins[i])
    lo, hi = (float(v) for v in joints["joint_a2"].get("range").split())
    assert (math.degrees(lo), math.degrees(hi)) == pytest.approx((-190, 45))
    site = [s for s in root.iter("site") if s.get("name") == "tool0"][0]
    np.testing.assert_allclose([float(v) for v in site.get("quat").split()],
                               [0.7071067811865476, 0, 0.7071067811865476, 0], atol=1e-12)
    assert root.find("actuator") is None


def test_home_site_pose(arm):
    # robot-model.md §11/§12: HOME flange at (525, 0, 890) mm, R = Ry(90), quat (0.7071, 0, 0.7071, 0)
    arm.set_axes((0, -90, 90, 0, 0, 0))
    T = arm.flange_pose()
    np.testing.assert_allclose(T[:3, 3], [525, 0, 890], atol=1e-9)
    np.testing.assert_allclose(T[:3, :3], [[0, 0, 1], [0, 1, 0], [-1, 0, 0]], atol=1e-12)
    q4 = np.zeros(4)
    mujoco.mju_mat2Quat(q4, arm.data.site("tool0").xmat)
    np.testing.assert_allclose(q4, [math.sqrt(0.5), 0, math.sqrt(0.5), 0], atol=1e-12)
    np.testing.assert_allclose(arm.axes_deg(), (0, -90, 90, 0, 0, 0), atol=1e-12)


def test_fk_equals_mujoco_site(arm):
    kin = Kinematics(arm.machine)
    rng = np.random.default_rng(31)
    for q in rng.uniform(LIMITS[:, 0], LIMITS[:, 1], size=(300, 6)):
        arm.set_axes(q)
        np.testing.assert_allclose(arm.axes_deg(), q, atol=1e-9)
        np.testing.assert_allclose(arm.flange_pose(), kin.forward(q), atol=1e-6)


def test_home_keyframe(arm):
    m, d = arm.model, mujoco.MjData(arm.model)
    mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
    np.testing.assert_allclose(np.degrees(d.qpos), (0, -90, 90, 0, 0, 0), atol=1e-12)


def test_actuated_mode_tracks_a_ptp_like_move():
    arm = ArmModel(load_machine(), actuated=True)
    assert arm.model.nu == 12
    assert arm.model.actuator("a1").gainprm[0] == pytest.approx(20000)
    np.testing.assert_allclose(arm.model.actuator("a2").ctrlrange, np.radians([-190, 45]))
    start = np.array([0, -90, 90, 0, 0, 0], dtype=float)
    goal = np.array([30, -60, 100, 40, -50, 120], dtype=float)
    arm.reset(start)
    dt, dur = 0.012, 1.2
    worst = 0.0
    for i in range(1, int(dur / dt) + 1):
        s = min(1.0, i * dt / dur)
        pos = start + (goal - start) * (3 * s * s - 2 * s ** 3)  # smoothstep
        vel = (goal - start) * (6 * s - 6 * s * s) / dur
        arm.step_actuated(pos, dt, vel)
        worst = max(worst, float(np.abs(arm.axes_deg() - pos).max()))
    for _ in range(20):
        arm.step_actuated(goal, dt)
    np.testing.assert_allclose(arm.axes_deg(), goal, atol=0.05)
    assert worst < 1.0


def test_step_actuated_needs_actuated_model(arm):
    with pytest.raises(RuntimeError):
        arm.step_actuated((0, -90, 90, 0, 0, 0), 0.012)


def test_tcp_pose_read_back_worked_example(arm):
    # robot-model.md §7: tool-down pose, $TOOL {Z 225}, $BASE {X 500, A 90} -> {X 0, Y 55, Z 585, A 90, B 0, C 180}
    arm.set_axes((0, -90, 90, 0, 90, 0))
    P = arm.tcp_pose(tool=(0, 0, 225, 0, 0, 0), base=(500, 0, 0, 90, 0, 0))
    np.testing.assert_allclose(P[:3, 3], [0, 55, 585], atol=1e-9)
    np.testing.assert_allclose(P[:3, :3], [[0, 1, 0], [1, 0, 0], [0, 0, -1]], atol=1e-12)


def test_robroot_places_the_base():
    m = dataclasses.replace(load_machine(), robroot_frame=(1000.0, 200.0, 0.0, 90.0, 0.0, 0.0))
    arm = ArmModel(m)
    kin = Kinematics(m)
    q = (10, -80, 95, 5, 30, -20)
    arm.set_axes(q)
    np.testing.assert_allclose(arm.flange_pose(), kin.forward(q), atol=1e-6)
    np.testing.assert_allclose(arm.tcp_pose(), kin.tcp_pose(q, robroot=m.robroot_frame), atol=1e-6)
