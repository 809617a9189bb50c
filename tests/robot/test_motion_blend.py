"""Approximate positioning (reference §6.8), checked on the traced TCP / axes."""

from __future__ import annotations

import numpy as np
import pytest

from robot.bench import run_motions, step_until
from robot.controller import MSG_APPROX_IMPOSSIBLE, Controller
from robot.errors import RobotError
from robot.frames import frame_to_matrix, rotation_angle_deg
from robot.limits import check_trace
from robot.motion import MotionParams, MotionRequest, SplineSegment
from robot.trace import TraceWriter

DT = 0.012
TOOL_DOWN = {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 90, "A6": 0}
P1 = (445.0, 200.0, 600.0)
P2 = (645.0, 200.0, 600.0)


def _run(reqs, wait_between=False, advance=None, **kw):
    tw = TraceWriter(keep=True)
    ctl = Controller(trace=tw, mujoco=False, **kw)
    if advance is not None:
        ctl.queue.set_advance(advance)
    run_motions(ctl, reqs, wait_between=wait_between)
    return ctl, tw.events


def _phases(events, mid):
    return {e["phase"]: e["t"] for e in events if e["kind"] == "motion" and e["id"] == mid}


def _pose_at(events, t):
    for e in events:
        if e["kind"] == "pose" and abs(e["t"] - t) < 1e-9:
            return e
    raise KeyError(t)


def _corner_program(cdis=30.0, v=0.5):
    P = MotionParams().with_(vel_cp=v, apo_cdis=cdis)
    return [MotionRequest("PTP", TOOL_DOWN, P),
            MotionRequest("LIN", dict(zip("XYZ", P1)), P, approx="C_DIS"),
            MotionRequest("LIN", dict(zip("XYZ", P2)), P)]


def test_c_dis_blend_starts_at_the_zone_and_stays_inside():
    cdis = 30.0
    ctl, ev = _run(_corner_program(cdis))
    ph = _phases(ev, 2)
    assert {"start", "blend_start", "blend_end", "end"} <= set(ph)
    # blend start: the first IPO cycle whose TCP is within C_DIS of the point
    p_bs = np.array(_pose_at(ev, ph["blend_start"])["tcp"][:3])
    p_before = np.array(_pose_at(ev, ph["blend_start"] - DT)["tcp"][:3])
    assert np.linalg.norm(p_bs - P1) <= cdis + 1e-9
    assert np.linalg.norm(p_before - P1) > cdis
    # the contour between blend start and blend end stays inside the sphere
    inside = [e for e in ev if e["kind"] == "pose" and ph["blend_start"] <= e["t"] < ph["blend_end"]]
    assert len(inside) > 3
    d = [np.linalg.norm(np.subtract(e["tcp"][:3], P1)) for e in inside]
    assert max(d) <= cdis + 1e-9
    # ... and really leaves the corner (approximated, not an exact stop)
    assert min(d) > 1.0
    # blend end: the TCP is back on the second line, about C_DIS past the point
    p_be = np.array(_pose_at(ev, ph["blend_end"])["tcp"][:3])
    assert abs(p_be[1] - 200.0) < 1e-6 and abs(p_be[2] - 600.0) < 1e-6
    assert cdis - 1e-6 <= p_be[0] - P1[0] <= cdis + 0.5 * 1000 * DT
    # no exact stop, no message
    assert not [e for e in ev if e["kind"] == "message"]


def test_c_dis_blend_is_faster_than_exact_stop():
    _, ev_blend = _run(_corner_program())
    prog = _corner_program()
    prog[1].approx = None
    _, ev_exact = _run(prog)
    assert _phases(ev_blend, 3)["end"] < _phases(ev_exact, 3)["end"] - 0.1


def test_c_dis_capped_at_half_segment():
    """C_DIS 500 on 200 mm segments: the zone shrinks to half the shorter segment."""
    ctl, ev = _run(_corner_program(cdis=500.0))
    ph = _phases(ev, 2)
    p_bs = np.array(_pose_at(ev, ph["blend_start"])["tcp"][:3])
    # first segment: (445, 0, 810) -> P1, length sqrt(200² + 210²) = 290 mm; second 200 mm
    assert np.linalg.norm(p_bs - P1) <= 100.0 + 1e-9
    inside = [e for e in ev if e["kind"] == "pose" and ph["blend_start"] <= e["t"] < ph["blend_end"]]
    assert max(np.linalg.norm(np.subtract(e["tcp"][:3], P1)) for e in inside) <= 100.0 + 1e-9


def test_velocity_continuous_through_blend():
    ctl, ev = _run(_corner_program(cdis=40.0))
    ph2, ph3 = _phases(ev, 2), _phases(ev, 3)
    poses = [e for e in ev if e["kind"] == "pose" and ph2["start"] <= e["t"] <= ph3["end"]]
    P = np.array([e["tcp"][:3] for e in poses])
    V = np.diff(P, axis=0) / DT
    A = np.linalg.norm(np.diff(V, axis=0), axis=1) / DT
    # bounded acceleration everywhere (no velocity jump): below 3 x $ACC.CP (2300 mm/s²)
    assert A.max() < 3 * 2300.0


def test_exact_stop_and_message_when_next_motion_unknown():
    """An advance-run stop between the motions (WAIT SEC 0): approximation impossible."""
    ctl, ev = _run(_corner_program(), wait_between=True)
    msgs = [e for e in ev if e["kind"] == "message"]
    assert [m["text"] for m in msgs] == [MSG_APPROX_IMPOSSIBLE]
    assert msgs[0]["id"] == 2
    ph = _phases(ev, 2)
    assert "blend_start" not in ph
    assert _pose_at(ev, ph["end"])["tcp"][:3] == pytest.approx(P1, abs=1e-9)
    # the message comes when the blend would have started, before the end
    assert msgs[0]["t"] < ph["end"]


def test_advance_zero_prevents_approximation():
    ctl, ev = _run(_corner_program(), advance=0)
    assert [e["text"] for e in ev if e["kind"] == "message"] == [MSG_APPROX_IMPOSSIBLE]
    assert "blend_start" not in _phases(ev, 2)


def test_c_ptp_blend_per_axis_distance():
    """PTP (A1 0->60, A2 -90->-70) C_PTP with CPTP 20 % of $APO_DIS_PTP 90° = 18°, then
    A2 -70->-50, A3 90->110: the blend starts when every axis is within its distance.
    (No axis reverses; the reversing case is the next test.)"""
    P = MotionParams().with_(apo_cptp=20.0)
    home = {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 0, "A6": 0}
    ctl, ev = _run([MotionRequest("PTP", home, P),
                    MotionRequest("PTP", dict(home, A1=60, A2=-70), P, approx="C_PTP"),
                    MotionRequest("PTP", dict(home, A1=60, A2=-50, A3=110), P)])
    ph = _phases(ev, 2)
    a_bs = _pose_at(ev, ph["blend_start"])["axes"]
    a_prev = _pose_at(ev, ph["blend_start"] - DT)["axes"]
    # every moving axis within its distance: A1 18° of 60, A2 18° of 20 -> capped 10°
    # (half of the A2 travel); fraction = min(18/60, 10/20) = 0.3 of the travel
    assert 60 - a_bs[0] <= 18.0 + 1e-9
    assert 60 - a_prev[0] > 18.0
    inside = [e["axes"] for e in ev if e["kind"] == "pose" and ph["blend_start"] <= e["t"] < ph["blend_end"]]
    assert max(abs(a[0] - 60) for a in inside) <= 18 + 1e-9
    # the corner is cut: A3 moves while A1 is still short of 60
    assert any(a[0] < 59.0 and a[2] > 91.0 for a in inside)


def test_c_ptp_blend_with_a_reversing_axis_keeps_the_acceleration_limit():
    """A2 -90->-70 then -70->-110 (A2 reverses): both PTPs accelerate A2 with its maximum
    394.7 deg/s² (A2 leads: 394.7/20 < 1241.4/60), overlapping them would need 2x that, so
    the next motion starts when the approximated one reaches its point (issue 15)."""
    P = MotionParams().with_(apo_cptp=20.0)
    home = {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 0, "A6": 0}
    ctl, ev = _run([MotionRequest("PTP", home, P),
                    MotionRequest("PTP", dict(home, A1=60, A2=-70), P, approx="C_PTP"),
                    MotionRequest("PTP", dict(home, A1=60, A2=-110), P)])
    ph = _phases(ev, 2)
    assert {"blend_start", "blend_end", "end"} <= set(ph)
    a2 = [e["axes"][1] for e in ev if e["kind"] == "pose"]
    assert max(a2) == pytest.approx(-70.0, abs=1e-6)
    rep = check_trace(ev, ctl.machine)
    assert rep.ok, [str(v) for v in rep.violations]


def test_c_vel_blend_starts_in_deceleration():
    P = MotionParams().with_(vel_cp=0.5, apo_cvel=50.0)
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", dict(zip("XYZ", P1)), P, approx="C_VEL"),
                    MotionRequest("LIN", dict(zip("XYZ", P2)), P)])
    ph = _phases(ev, 2)
    a = np.array(_pose_at(ev, ph["blend_start"] - DT)["tcp"][:3])
    b = np.array(_pose_at(ev, ph["blend_start"])["tcp"][:3])
    v = np.linalg.norm(b - a) / DT
    assert v <= 0.5 * 500 + 2300 * DT + 1e-6  # about 50 % of 500 mm/s
    assert v >= 0.5 * 500 - 2300 * DT


def test_lin_to_ptp_mixed_blend_runs():
    P = MotionParams().with_(vel_cp=0.5, apo_cdis=20.0)
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", dict(zip("XYZ", P1)), P, approx="C_DIS"),
                    MotionRequest("PTP", dict(TOOL_DOWN, A1=-30), P, approx="C_PTP"),
                    MotionRequest("LIN", {"X": 400, "Y": 0, "Z": 600}, P)])
    for mid in (2, 3):
        assert {"start", "blend_start", "blend_end", "end"} <= set(_phases(ev, mid))
    assert not [e for e in ev if e["kind"] in ("message", "error")]
    assert ctl.actual.pos_act()["X"] == pytest.approx(400, abs=1e-6)


def test_c_ori_blend_starts_at_remaining_orientation():
    """C_ORI 10°: the blend starts when the remaining orientation change is 10° or less."""
    P = MotionParams().with_(vel_cp=0.5, apo_cori=10.0)
    goal = (180.0 - 60.0, 0.0, 180.0)  # 60° about Z from the tool-down orientation
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", dict(zip("XYZABC", P1 + goal)), P, approx="C_ORI"),
                    MotionRequest("LIN", dict(zip("XYZ", P2)), P)])
    ph = _phases(ev, 2)
    R_goal = frame_to_matrix(0, 0, 0, *goal)

    def remaining(t):
        return rotation_angle_deg(frame_to_matrix(0, 0, 0, *_pose_at(ev, t)["tcp"][3:]), R_goal)

    assert remaining(ph["blend_start"]) <= 10.0 + 1e-6
    assert remaining(ph["blend_start"] - DT) > 10.0


def test_blend_overlaps_profiles_without_overspeed():
    """Equal accelerations: the overlapped profiles never exceed $VEL.CP (500 mm/s) and the
    blend ends when the approximated motion reaches its point."""
    ctl, ev = _run(_corner_program(cdis=30.0, v=0.5))
    ph2, ph3 = _phases(ev, 2), _phases(ev, 3)
    poses = [e for e in ev if e["kind"] == "pose" and ph2["start"] <= e["t"] <= ph3["end"]]
    P = np.array([e["tcp"][:3] for e in poses])
    speed = np.linalg.norm(np.diff(P, axis=0), axis=1) / DT
    assert speed.max() <= 500.0 * (1 + 1e-6)
    # the robot never stops in between
    inner = [e for e in poses if ph2["blend_start"] <= e["t"] <= ph2["blend_end"]]
    Pi = np.array([e["tcp"][:3] for e in inner])
    assert (np.linalg.norm(np.diff(Pi, axis=0), axis=1) / DT).min() > 100.0


def test_no_setpoint_jumps_through_mixed_blends():
    """Blends of every kind, including motions without TCP path: the axes never move more
    per IPO cycle than the axis maximum speed allows (+10 %)."""
    P = MotionParams().with_(vel_cp=0.5, apo_cdis=20.0)
    ctl, ev = _run([MotionRequest("PTP", TOOL_DOWN, P),
                    MotionRequest("LIN", {"A": 150}, P, approx="C_DIS"),
                    MotionRequest("LIN", {"X": 500, "Y": 100}, P, approx="C_DIS"),
                    MotionRequest("PTP", {"A6": 30}, P, approx="C_DIS"),
                    MotionRequest("PTP", {"A6": 60, "A1": -10}, P, approx="C_PTP"),
                    MotionRequest("CIRC", {"X": 500, "Y": -100}, P, aux={"X": 600, "Y": 0},
                                  approx="C_DIS"),
                    MotionRequest("SPLINE", {}, P, approx="C_SPL", segments=(
                        SplineSegment("SPL", {"X": 450, "Y": -50}),
                        SplineSegment("SPL", {"X": 420, "Y": 50, "Z": 700}))),
                    MotionRequest("SPTP", TOOL_DOWN, P)])
    assert not [e for e in ev if e["kind"] in ("error", "message")]
    ax = np.array([e["axes"] for e in ev if e["kind"] == "pose"])
    vmax = np.array(ctl.machine.max_speed_deg_s)
    assert np.all(np.abs(np.diff(ax, axis=0)).max(axis=0) <= 1.1 * vmax * DT)


def test_ptp_c_ptp_into_lin_keeps_the_axis_acceleration_at_the_blend_end():
    """Issue 22: a PTP C_PTP blended into a LIN reached 1.13x the A2 acceleration limit at the
    end of the blend (A2 reverses; the LIN's axis rates grow along its path). Now every
    axis stays within a_max (+10 % finite-difference tolerance of robot/limits.py)."""
    ax = ("A1", "A2", "A3", "A4", "A5", "A6")
    rows = [([33.9, -83.122, 113.28, 7.754, 34.821, 25.543], [427.081, 351.007, 529.874, -153.625, 9.044, -128.525],
             (64.571, 79.46, 1.481, 54.633)),
            ([21.749, -58.884, 104.513, -15.924, 97.861, 58.972], [167.609, -249.479, 1054.977, 25.055, 42.651, 104.46],
             (74.661, 81.934, 1.355, 55.002)),
            ([8.368, -113.709, 96.573, 42.816, 31.244, -21.003], [310.996, 265.445, 1073.105, -121.104, 57.751, -134.62],
             (68.144, 86.503, 0.724, 43.79))]
    reqs = [MotionRequest("PTP", dict(zip(ax, (0, -90, 90, 0, 60, 0))), MotionParams())]
    for qa, lin, (vax, cptp, vcp, cdis) in rows:
        P = MotionParams().with_(vel_axis=(vax,) * 6, apo_cptp=cptp, vel_cp=vcp, apo_cdis=cdis)
        reqs.append(MotionRequest("PTP", dict(zip(ax, qa)), P, approx="C_PTP"))
        reqs.append(MotionRequest("LIN", dict(zip("XYZABC", lin)), P))
    tw = TraceWriter(keep=True)
    ctl = Controller(trace=tw, mujoco=False)
    for req in reqs:
        while not ctl.can_enqueue():
            ctl.step()
        try:
            ctl.queue.enqueue(req)
        except RobotError:
            continue        # one LIN target is outside A5's limits: the advance run would stop there
    step_until(ctl, ctl.is_idle, max_cycles=100_000)
    rep = check_trace(tw.events, ctl.machine)
    assert rep.ok, rep.summary()
    assert sum(1 for e in tw.events if e["kind"] == "motion" and e["phase"] == "blend_start") >= 1
