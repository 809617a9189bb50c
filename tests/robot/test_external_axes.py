"""External axes (issue 34): a track carrying the robot (#ERSYS) and a turntable carrying the
workpiece (#EASYS), from machine data written from KUKA's machine-data handbook
(robot/data/kr16_2_kl1500.dat, kr16_2_turntable.dat; robot/external.py).

Expected values by hand: the track's frames put the robot 450 mm up and E1 mm along +X of
$WORLD (TA1KR {Z 450, B 90} turns Z along the track, TFLA3 {B -90} turns it back); the
turntable's axis is vertical 1500 mm ahead and 400 mm up, so a point of the plate turns about
it by E1 (KUKA's A: counter-clockwise seen from above)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

from robot.errors import SoftLimitError
from robot.external import ExternalAxes
from robot.frames import frame_to_matrix, matrix_to_frame
from robot.kinematics import Kinematics
from robot.mada import MachineDataError, load_mada
from robot.machine import ROBOT_LIBRARY
from robot.mjcf import build_mjcf
from robot.urdf import build_urdf

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


# ---------------------------------------------------------------- motions with external axes
from robot.controller import Controller  # noqa: E402
from robot.bench import run_motions  # noqa: E402
from robot.limits import check_trace  # noqa: E402
from robot.motion import MotionParams, MotionRequest  # noqa: E402
from robot.trace import TraceWriter  # noqa: E402

AX = ("A1", "A2", "A3", "A4", "A5", "A6")


def _run(machine, reqs):
    tw = TraceWriter(keep=True)
    ctl = Controller(machine, trace=tw, mujoco=True)
    run_motions(ctl, reqs)
    poses = [e for e in tw.events if e["kind"] == "pose"]
    return ctl, tw, np.array([p["axes"] for p in poses]), np.array([p["tcp"] for p in poses])


def test_a_ptp_moves_the_track_synchronised_with_the_arm(track):
    P = MotionParams.initmov(track)
    start = dict(zip(AX, (0.0, -90.0, 90.0, 0.0, 45.0, 0.0)), E1=1000.0)
    end = dict(zip(AX, (40.0, -70.0, 80.0, 10.0, 60.0, 30.0)), E1=2500.0)
    ctl, tw, Q, _ = _run(track, [MotionRequest("PTP", start, P), MotionRequest("PTP", end, P)])
    assert Q.shape[1] == 7
    assert ctl.actual.axis_act()[6] == pytest.approx(2500.0, abs=1e-6)
    # synchronised: every axis covers the same fraction of its way in every cycle
    moving = Q[(Q[:, 6] > 1000.0 + 1e-6) & (Q[:, 6] < 2500.0 - 1e-6)]
    frac_e = (moving[:, 6] - 1000.0) / 1500.0
    frac_a1 = moving[:, 0] / 40.0
    np.testing.assert_allclose(frac_a1, frac_e, atol=1e-6)
    assert check_trace(tw.events, track).ok


def test_a_lin_on_the_track_keeps_the_tcp_on_its_line_in_the_world(track):
    P = MotionParams.initmov(track).with_(vel_cp=0.3)
    home = dict(zip(AX, (0.0, -90.0, 90.0, 0.0, 45.0, 0.0)), E1=1000.0)
    k, ext = Kinematics(track), ExternalAxes(track)
    q0 = np.array([0.0, -90.0, 90.0, 0.0, 45.0, 0.0])
    W0 = ext.world_flange(k.forward, q0, [1000.0])
    x0, y0, z0 = W0[:3, 3]
    a, b, c = matrix_to_frame(W0)[3:]
    target = {"X": x0 + 900.0, "Y": y0 + 200.0, "Z": z0 - 300.0, "A": a, "B": b, "C": c, "E1": 1800.0}
    ctl, tw, Q, tcp = _run(track, [MotionRequest("PTP", home, P), MotionRequest("LIN", target, P)])
    on = (Q[:, 6] > 1000.0 + 1e-6)
    p = tcp[on, :3]
    d = np.array([900.0, 200.0, -300.0])
    frac = (p - [x0, y0, z0]) @ d / (d @ d)
    off = (p - [x0, y0, z0]) - frac[:, None] * d
    assert np.abs(off).max() < 0.01                              # straight in $WORLD (= $BASE)
    np.testing.assert_allclose((Q[on, 6] - 1000.0) / 800.0, frac, atol=1e-4)   # E1 linear in the path
    assert ctl.actual.axis_act()[6] == pytest.approx(1800.0, abs=1e-6)
    rep = check_trace(tw.events, track)
    assert rep.ok, rep.summary()


def test_a_base_on_the_turntable_turns_with_it(table):
    """LIN in a $BASE linked to the table (EK): the TCP moves straight in the turning base."""
    k, ext = Kinematics(table), ExternalAxes(table)
    P = MotionParams.initmov(table).with_(vel_cp=0.2, base_kin="#EASYS")
    home = dict(zip(AX, (0.0, -80.0, 100.0, 0.0, 70.0, 0.0)), E1=0.0)
    p1 = {"X": -350.0, "Y": -100.0, "Z": 200.0, "A": 0.0, "B": 180.0, "C": 0.0}
    p2 = {"X": -250.0, "Y": 150.0, "Z": 250.0, "A": 0.0, "B": 180.0, "C": 0.0, "E1": 40.0}
    ctl, tw, Q, tcp = _run(table, [MotionRequest("PTP", home, P.with_(base_kin=None)),
                                    MotionRequest("PTP", p1, P), MotionRequest("LIN", p2, P)])
    assert ctl.actual.axis_act()[6] == pytest.approx(40.0, abs=1e-6)
    on = Q[:, 6] > 1e-6
    assert on.sum() > 20
    a, b = np.array([-350.0, -100.0, 200.0]), np.array([-250.0, 150.0, 250.0])
    for q in Q[on]:
        pt = (np.linalg.inv(ext.chain(table.external_kinematics[0], q[6:])) @ k.forward(q[:6]))[:3, 3]
        f = float((pt - a) @ (b - a) / ((b - a) @ (b - a)))
        assert np.linalg.norm(pt - (a + f * (b - a))) < 0.01
        assert q[6] == pytest.approx(40.0 * f, abs=1e-3)
    rep = check_trace(tw.events, table)
    assert rep.ok, rep.summary()


def test_an_external_axis_outside_its_limits_is_refused(track):
    ctl = Controller(track, mujoco=False)
    P = MotionParams.initmov(track)
    with pytest.raises(SoftLimitError, match=r"software limit switch \+E1"):
        ctl.queue.enqueue(MotionRequest("PTP", dict(zip(AX, (0.0, -90.0, 90.0, 0.0, 45.0, 0.0)), E1=5000.0), P))
