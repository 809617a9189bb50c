"""External axes (issue 34): a track carrying the robot (#ERSYS) and a turntable carrying the
workpiece (#EASYS), from machine data written from KUKA's machine-data handbook
(robot/data/kr16_2_kl1500.dat, kr16_2_turntable.dat; robot/external.py).

Expected values by hand: the track's frames put the robot 450 mm up and E1 mm along +X of
$WORLD (TA1KR {Z 450, B 90} turns Z along the track, TFLA3 {B -90} turns it back); the
turntable's axis is vertical 1500 mm ahead and 400 mm up, so a point of the plate turns about
it by E1 (KUKA's A: counter-clockwise seen from above)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.external import ExternalAxes
from robot.frames import frame_to_matrix
from robot.kinematics import Kinematics
from robot.mada import MachineDataError, load_mada
from robot.machine import ROBOT_LIBRARY

TRACK = ROBOT_LIBRARY / "kr16_2_kl1500.dat"
TABLE = ROBOT_LIBRARY / "kr16_2_turntable.dat"


@pytest.fixture(scope="module")
def track():
    return load_mada(TRACK)


@pytest.fixture(scope="module")
def table():
    return load_mada(TABLE)


def test_the_track_is_read_as_the_handbook_defines_it(track):
    (e1,) = track.external_axes
    assert (e1.name, e1.kind, e1.limit) == ("E1", "linear", (-10.0, 4000.0))
    assert e1.max_speed == pytest.approx(3000 / 50 * 1000 / 60)      # motor turns per 1000 mm
    assert e1.home == 1000.0
    (et,) = track.external_kinematics
    assert et.robroot and et.axes == (1,) and et.name == "KL1500"


@pytest.mark.parametrize("e", [0.0, 1000.0, 3333.3])
def test_the_track_carries_the_robot(track, e):
    ext = ExternalAxes(track)
    np.testing.assert_allclose(ext.robroot([e]), frame_to_matrix(e, 0.0, 450.0, 0.0, 0.0, 0.0), atol=1e-9)


def test_track_forward_inverse_round_trip(track):
    k, ext = Kinematics(track), ExternalAxes(track)
    rng = np.random.default_rng(2)
    n = 0
    for _ in range(40):
        q = rng.uniform([-170, -150, -120, -300, -120, -300], [170, 30, 150, 300, 120, 300])
        if abs(q[4]) < 1.0:
            continue
        e = [rng.uniform(0.0, 4000.0)]
        W = ext.world_flange(k.forward, q, e)
        s, t = k.status_turn(q)
        q2 = k.inverse(ext.flange_in_robroot(W, e), s, t, reference_deg=q)
        np.testing.assert_allclose(q2, q, atol=1e-7)
        n += 1
    assert n > 30


def test_a_world_target_is_reached_from_anywhere_on_the_track(track):
    """The same world pose from two track positions: different arm axes, the same flange."""
    k, ext = Kinematics(track), ExternalAxes(track)
    W = frame_to_matrix(2500.0, 200.0, 1500.0, 0.0, 90.0, 0.0)
    qa = k.inverse(ext.flange_in_robroot(W, [1500.0]))
    qb = k.inverse(ext.flange_in_robroot(W, [1700.0]))
    assert not np.allclose(qa, qb)
    for q, e in ((qa, [1500.0]), (qb, [1700.0])):
        np.testing.assert_allclose(ext.world_flange(k.forward, q, e), W, atol=1e-7)


def test_the_turntable_carries_the_workpiece(table):
    ext = ExternalAxes(table)
    offset = frame_to_matrix(200.0, 0.0, 0.0, 0.0, 0.0, 0.0)     # a base 200 mm out on the plate
    for e in (0.0, 30.0, -135.0):
        B = ext.base("#EASYS", offset, [e])
        a = math.radians(e)
        np.testing.assert_allclose(B[:3, 3], [1500 + 200 * math.cos(a), 200 * math.sin(a), 400.0], atol=1e-9)


def test_turntable_forward_inverse_round_trip(table):
    """A point fixed on the plate, the plate turned: the arm follows (IK in the turned base)."""
    k, ext = Kinematics(table), ExternalAxes(table)
    offset = frame_to_matrix(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    P = frame_to_matrix(-300.0, 100.0, 150.0, 0.0, 180.0, 0.0)   # on the plate, tool down
    q_prev = np.array(table.home_deg)
    for e in np.linspace(-60.0, 60.0, 9):
        F = ext.base("#EASYS", offset, [e]) @ P                  # the target in $WORLD = $ROBROOT
        q = k.inverse(F, reference_deg=q_prev)
        np.testing.assert_allclose(k.forward(q), F, atol=1e-7)
        q_prev = q


def test_mujoco_model_moves_the_external_axes(track, table):
    import mujoco

    from robot.mjcf import build_mjcf

    for m in (track, table):
        model = mujoco.MjModel.from_xml_string(build_mjcf(m))
        data = mujoco.MjData(model)
        k, ext = Kinematics(m), ExternalAxes(m)
        q, e = np.array([20.0, -70.0, 60.0, 30.0, 40.0, -50.0]), [700.0 if m is track else 40.0]
        data.qpos[model.joint("joint_e1").qposadr[0]] = e[0] / 1000.0 if m is track else math.radians(e[0])
        for i in range(6):
            data.qpos[model.joint(f"joint_a{i + 1}").qposadr[0]] = math.radians(q[i])
        mujoco.mj_kinematics(model, data)
        np.testing.assert_allclose(data.site("tool0").xpos * 1000.0, ext.world_flange(k.forward, q, e)[:3, 3],
                                   atol=1e-6)
        if m is table:
            np.testing.assert_allclose(data.site("et1_flange").xpos * 1000.0,
                                       ext.chain(m.external_kinematics[0], e)[:3, 3], atol=1e-6)


def test_urdf_export_has_the_external_joint(track, table):
    import xml.etree.ElementTree as ET

    from robot.urdf import build_urdf

    for m, jtype in ((track, "prismatic"), (table, "revolute")):
        root = ET.fromstring(build_urdf(m))
        joints = {j.get("name"): j for j in root.findall("joint")}
        assert joints["joint_e1"].get("type") == jtype
        children = {j.find("child").get("link") for j in joints.values()}
        links = {ln.get("name") for ln in root.findall("link")}
        assert links - children == {"world"}                       # one tree, rooted in $WORLD


def test_a_refusal_names_the_external_variable(tmp_path):
    text = TRACK.read_text(encoding="utf-8").replace("ET1 #ERSYS", "ET1 #EXSYS")
    p = tmp_path / "$machine.dat"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(MachineDataError, match=r"\$EX_KIN.ET1=#EXSYS"):
        load_mada(p)
    text = TRACK.read_text(encoding="utf-8").replace("$AXIS_TYPE[7]=1", "$AXIS_TYPE[7]=2")
    p.write_text(text, encoding="utf-8")
    with pytest.raises(MachineDataError, match=r"\$AXIS_TYPE\[7\]=2"):
        load_mada(p)
