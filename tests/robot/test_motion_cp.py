"""LIN / CIRC / spline paths (reference §6.2, §6.3, §6.7), checked on the traced TCP."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from robot.bench import run_motions
from robot.controller import Controller
from robot.errors import RobotError, WorkspaceError
from robot.frames import frame_to_matrix, matrix_to_frame
from robot.kinematics import Kinematics
from robot.machine import load_machine
from robot.motion import MotionParams, MotionRequest, SplineSegment
from robot.trace import TraceWriter

DT = 0.012
TOOL_DOWN = {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 90, "A6": 0}  # flange 445, 0, 810


def _run(reqs, **kw):
    tw = TraceWriter(keep=True)
    ctl = Controller(trace=tw, **kw)
    run_motions(ctl, reqs)
    return ctl, tw.events


def _poses(events, t0, t1):
    return [e for e in events if e["kind"] == "pose" and t0 - 1e-9 <= e["t"] <= t1 + 1e-9]


def _phases(events, mid):
    """The motion's phase times, and ``reached``: when its interpolation ended (an exact stop's
    END comes 24-36 ms later, robot/exactstop.py)."""
    ph = {e["phase"]: e["t"] for e in events if e["kind"] == "motion" and e["id"] == mid}
    ph["reached"] = next((e["reached"] for e in events if e["kind"] == "motion"
                          and e["id"] == mid and e["phase"] == "end"), None)
    return ph


def _dist_to_line(p, a, b):
    p, a, b = (np.asarray(v, float) for v in (p, a, b))
    d = (b - a) / np.linalg.norm(b - a)
    v = p - a
    return float(np.linalg.norm(v - (v @ d) * d))


def test_lin_is_straight_within_0_01_mm():
    P = MotionParams().with_(vel_cp=0.5)
    start = (445.0, 0.0, 810.0)
    end = (600.0, 250.0, 500.0)
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"X": end[0], "Y": end[1], "Z": end[2], "A": 150,
                                          "B": 10, "C": 170}, P)])
    ph = _phases(ev, 2)
    poses = _poses(ev, ph["start"], ph["end"])
    assert len(poses) > 50
    worst = max(_dist_to_line(e["tcp"][:3], start, end) for e in poses)
    assert worst < 0.01
    # the end pose is the programmed one (orientation compared as matrices)
    last = poses[-1]["tcp"]
    assert last[:3] == pytest.approx(end, abs=1e-6)
    R = frame_to_matrix(*last)[:3, :3]
    R_goal = frame_to_matrix(0, 0, 0, 150, 10, 170)[:3, :3]
    assert np.allclose(R, R_goal, atol=1e-9)


def test_lin_speed_respects_vel_cp():
    """Cruise speed equals $VEL.CP (0.25 m/s = 3 mm per IPO cycle), never more."""
    P = MotionParams().with_(vel_cp=0.25)
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"X": 445, "Y": 300, "Z": 810}, P)])
    ph = _phases(ev, 2)
    poses = _poses(ev, ph["start"], ph["end"])
    steps = [np.linalg.norm(np.subtract(b["tcp"][:3], a["tcp"][:3]))
             for a, b in zip(poses, poses[1:])]
    assert max(steps) == pytest.approx(0.25 * 1000 * DT, rel=1e-6)
    # duration by hand: L = 300 mm, v = 250 mm/s, a = 2300 mm/s² -> T = L/v + v/a
    T = 300 / 250 + 250 / 2300
    assert ph["reached"] - ph["start"] == pytest.approx(T, abs=1e-6)  # the trace keeps µs


def test_lin_ori_constant_keeps_start_orientation():
    P = MotionParams().with_(ori_type="#CONSTANT")
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"X": 500, "Y": 100, "Z": 700, "A": 90, "B": 0, "C": 180}, P)])
    ph = _phases(ev, 2)
    R0 = frame_to_matrix(0, 0, 0, 180, 0, 180)[:3, :3]
    for e in _poses(ev, ph["start"], ph["end"]):
        assert np.allclose(frame_to_matrix(*e["tcp"])[:3, :3], R0, atol=1e-9)


def test_lin_partial_and_relative():
    P = MotionParams()
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"Z": 700}, P),
                    MotionRequest("LIN_REL", {"X": 20, "Y": -10}, P)])
    pos = ctl.actual.pos_act()
    assert (pos["X"], pos["Y"], pos["Z"]) == pytest.approx((465, -10, 700), abs=1e-6)
    # LIN_REL #TOOL: tool-down flange has +Z pointing down, so Z+50 in the tool frame lowers
    ctl2, _ = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN_REL", {"Z": 50}, P, rel_frame="#TOOL")])
    assert ctl2.actual.pos_act()["Z"] == pytest.approx(760, abs=1e-6)


def test_lin_with_tool_and_base():
    """A target is the TCP ($TOOL) in $BASE (reference §6.4)."""
    tool = (0.0, 0.0, 100.0, 0.0, 0.0, 0.0)
    base = (500.0, 0.0, 0.0, 90.0, 0.0, 0.0)
    P = MotionParams().with_(tool=tool, base=base)
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"X": 10, "Y": 20, "Z": 500}, P)])
    pos = ctl.actual.pos_act()
    assert (pos["X"], pos["Y"], pos["Z"]) == pytest.approx((10, 20, 500), abs=1e-6)
    # cross-check through the world: TCP_world = BASE : POS
    T_world = frame_to_matrix(*base) @ frame_to_matrix(pos["X"], pos["Y"], pos["Z"], pos["A"], pos["B"], pos["C"])
    flange = ctl.model.kin.forward(ctl.actual.axis_act()) @ frame_to_matrix(*tool)
    assert np.allclose(T_world, flange, atol=1e-6)


def test_circ_stays_on_circle_and_passes_aux():
    P = MotionParams().with_(vel_cp=0.5)
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"X": 500, "Y": 100, "Z": 600}, P),
                    MotionRequest("CIRC", {"X": 500, "Y": -100, "Z": 600}, P,
                                  aux={"X": 600, "Y": 0, "Z": 600})])
    ph = _phases(ev, 3)
    poses = _poses(ev, ph["start"], ph["end"])
    # circle through (500,100), (600,0), (500,-100) in z = 600: centre (500, 0), r = 100
    r = [math.hypot(e["tcp"][0] - 500, e["tcp"][1]) for e in poses]
    assert max(abs(v - 100.0) for v in r) < 0.01
    assert max(abs(e["tcp"][2] - 600.0) for e in poses) < 0.01
    assert max(e["tcp"][0] for e in poses) == pytest.approx(600.0, abs=0.1)
    assert poses[-1]["tcp"][:3] == pytest.approx([500, -100, 600], abs=1e-6)


def test_circ_ca_sets_the_angle():
    """CA 270: start (500, 100) about centre (500, 0) via the aux side, 270° further."""
    P = MotionParams().with_(vel_cp=1.0)
    ctl, _ = _run([MotionRequest("PTP", TOOL_DOWN, P),
                   MotionRequest("LIN", {"X": 500, "Y": 100, "Z": 600}, P),
                   MotionRequest("CIRC", {"X": 500, "Y": -100, "Z": 600}, P,
                                 aux={"X": 600, "Y": 0, "Z": 600}, ca=270.0)])
    pos = ctl.actual.pos_act()
    assert (pos["X"], pos["Y"]) == pytest.approx((400.0, 0.0), abs=1e-6)


def test_lin_workspace_error_at_planning():
    ctl = Controller(mujoco=False)
    ctl.queue.enqueue(MotionRequest("PTP", TOOL_DOWN, MotionParams()))
    with pytest.raises(WorkspaceError):
        ctl.queue.enqueue(MotionRequest("LIN", {"X": 2000}, MotionParams()))


def test_spline_block_passes_through_spl_points():
    P = MotionParams().with_(vel_cp=0.5)
    pts = [(500, 100, 650), (550, 0, 600), (500, -100, 650)]
    segs = tuple(SplineSegment("SPL", {"X": x, "Y": y, "Z": z}) for x, y, z in pts)
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"X": 445, "Y": 150, "Z": 700}, P),
                    MotionRequest("SPLINE", {}, P, segments=segs)])
    ph = _phases(ev, 3)
    poses = _poses(ev, ph["start"], ph["end"])
    for p in pts:
        assert min(np.linalg.norm(np.subtract(e["tcp"][:3], p)) for e in poses) < 4.0
    assert poses[-1]["tcp"][:3] == pytest.approx(pts[-1], abs=1e-6)
    # one motion: the speed never drops to zero at the inner SPL points
    steps = [np.linalg.norm(np.subtract(b["tcp"][:3], a["tcp"][:3])) for a, b in zip(poses, poses[1:])]
    n = len(steps)
    assert min(steps[n // 5: 4 * n // 5]) > 1.0


def test_slin_and_sptp_behave_like_lin_and_ptp():
    P = MotionParams().with_(vel_cp=0.5)
    c1, e1 = _run([MotionRequest("PTP", TOOL_DOWN, P), MotionRequest("LIN", {"X": 550, "Y": 80}, P)])
    c2, e2 = _run([MotionRequest("SPTP", TOOL_DOWN, P), MotionRequest("SLIN", {"X": 550, "Y": 80}, P)])
    p1 = [e["tcp"] for e in e1 if e["kind"] == "pose"]
    p2 = [e["tcp"] for e in e2 if e["kind"] == "pose"]
    assert p1 == p2


def test_rotation_helper_consistency():
    """The orientation interpolation of a LIN equals scipy's Slerp at mid-path."""
    P = MotionParams().with_(vel_cp=0.5)
    ctl = Controller(mujoco=False)
    ctl.queue.enqueue(MotionRequest("PTP", TOOL_DOWN, P))
    ctl.queue.enqueue(MotionRequest("LIN", {"X": 500, "A": 120, "B": 20, "C": 160}, P))
    seg = ctl.queue.pending[1]
    R0 = Rotation.from_matrix(frame_to_matrix(0, 0, 0, 180, 0, 180)[:3, :3])
    R1 = Rotation.from_matrix(frame_to_matrix(0, 0, 0, 120, 20, 160)[:3, :3])
    mid = Slerp([0, 1], Rotation.concatenate([R0, R1]))([0.5])[0].as_matrix()
    assert np.allclose(seg.pose_u(0.5)[1], mid, atol=1e-12)


def test_lin_ori_joint_moves_wrist_axes_linearly_on_a_straight_path():
    P = MotionParams().with_(vel_cp=0.5, ori_type="#JOINT")
    start = (445.0, 0.0, 810.0)
    end = (550.0, 150.0, 650.0)
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"X": end[0], "Y": end[1], "Z": end[2], "A": 140,
                                          "B": 15, "C": 165}, P)])
    ph = _phases(ev, 2)
    poses = _poses(ev, ph["start"], ph["end"])
    assert max(_dist_to_line(e["tcp"][:3], start, end) for e in poses) < 0.01
    q0 = np.array(poses[0]["axes"])
    q1 = np.array(poses[-1]["axes"])
    L = np.linalg.norm(np.subtract(end, start))
    for e in poses:
        s = np.linalg.norm(np.subtract(e["tcp"][:3], start)) / L  # path fraction
        for i in (3, 4, 5):
            if abs(q1[i] - q0[i]) > 1.0:
                assert (e["axes"][i] - q0[i]) / (q1[i] - q0[i]) == pytest.approx(s, abs=1e-6)
    R = frame_to_matrix(*poses[-1]["tcp"])[:3, :3]
    assert np.allclose(R, frame_to_matrix(0, 0, 0, 140, 15, 165)[:3, :3], atol=1e-9)


def test_lin_through_wrist_singularity_is_an_error():
    """A LIN from A5 = +20° to the mirrored pose with A5 = -20° needs a status change
    (wrist flip): a CP motion may not do that (reference §6.5, §8.2)."""
    P = MotionParams().with_(vel_cp=0.3)
    ctl = Controller(mujoco=False)
    run_motions(ctl, [MotionRequest("PTP", {"A1": 0, "A2": -90, "A3": 90, "A4": 30, "A5": 20,
                                            "A6": 0}, P)])
    f = matrix_to_frame(ctl.model.kin.forward([0, -90, 90, 30, -20, 0]))
    with pytest.raises(RobotError, match="singularity"):
        ctl.queue.enqueue(MotionRequest("LIN", dict(zip("XYZABC", f)), P))


def test_circ_type_path_turns_the_tool_with_the_tangent():
    """$CIRC_TYPE #PATH: the orientation relative to the circle's tangent stays constant."""
    P = MotionParams().with_(vel_cp=0.5, circ_type="#PATH")
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"X": 500, "Y": 100, "Z": 600}, P),
                    MotionRequest("CIRC", {"X": 500, "Y": -100, "Z": 600}, P,
                                  aux={"X": 600, "Y": 0, "Z": 600})])
    ph = _phases(ev, 3)
    poses = _poses(ev, ph["start"], ph["end"])
    # centre (500, 0): the tool's x axis, expressed in the rotating radial frame, is constant
    rel = []
    for e in poses:
        R = frame_to_matrix(*e["tcp"])[:3, :3]
        phi = math.atan2(e["tcp"][1], e["tcp"][0] - 500.0)
        Rz = Rotation.from_euler("z", phi).as_matrix()
        rel.append(Rz.T @ R)
    for M in rel:
        assert np.allclose(M, rel[0], atol=1e-6)
    # the tool turned by the swept angle (180°) about the circle normal
    R0 = frame_to_matrix(*poses[0]["tcp"])[:3, :3]
    R1 = frame_to_matrix(*poses[-1]["tcp"])[:3, :3]
    assert np.degrees(Rotation.from_matrix(R0.T @ R1).magnitude()) == pytest.approx(180.0, abs=1e-6)


def test_lin_ori_joint_goes_to_the_targets_status_with_linear_wrist_axes():
    """$ORI_TYPE #JOINT (reference §6.7; issue 60): the wrist axes move linearly from the start's to
    the target's as its S and T give them, A5 through 0 (the real KR C4's LIN from S 6 to S 2,
    Linear_updated line 38), while the TCP stays on the straight line."""
    k = Kinematics(load_machine())
    q0 = np.array([0.0, -90.0, 90.0, 30.0, 40.0, 0.0])
    q1 = np.array([20.0, -80.0, 85.0, -20.0, -35.0, 10.0])
    f1 = matrix_to_frame(k.forward(q1))
    s1, t1 = k.status_turn(q1)
    assert s1 != k.status_turn(q0)[0]                       # the wrist flips: another status
    P = MotionParams().with_(ori_type="#JOINT", vel_cp=0.3)
    target = dict(zip("XYZABC", f1), S=s1, T=t1)
    ctl, ev = _run([MotionRequest("PTP", {f"A{i + 1}": float(v) for i, v in enumerate(q0)}, P),
                    MotionRequest("LIN", target, P)], mujoco=False)
    assert ctl.actual.axis_act()[:6] == pytest.approx(q1, abs=1e-6)
    ph = _phases(ev, 2)
    start, end = np.array(matrix_to_frame(k.forward(q0))[:3]), np.array(f1[:3])
    for e in _poses(ev, ph["start"], ph["end"]):
        q = np.array(e["axes"][:6])
        u = (q[4] - q0[4]) / (q1[4] - q0[4])
        assert q[3] == pytest.approx(q0[3] + u * (q1[3] - q0[3]), abs=1e-6)
        assert q[5] == pytest.approx(q0[5] + u * (q1[5] - q0[5]), abs=1e-6)
        assert _dist_to_line(e["tcp"][:3], start, end) < 0.01
