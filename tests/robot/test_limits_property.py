"""Property (issue 15): whatever motion sequence a program asks for — PTP, LIN, CIRC, SPTP,
SPLINE blocks with SPL/SLIN/SCIRC, every approximation kind, random targets within reach,
random $VEL/$OV_PRO/$APO, T1 or AUT — the trace keeps the limits: path speed <= $VEL.CP ·
$OV_PRO (3 %), PTP axes <= $VEL_AXIS · v_max (3 %), every axis <= machine speed (3 %) and
acceleration (10 %, finite differences), TCP/flange <= 250 mm/s in T1. Checked from the pose
events with robot/limits.py. Motions the planner refuses (unreachable, singular) are left
out, as an advance run would stop there.

It runs on the KR 6 R900 and on two large robots built from corpus machine data (issue 22):
the KR 210 R2700-2 and the KR 120 R2700 extra HA (robot/mada.py); their targets are the same
axis ranges, so their paths are three times longer. Issue 34 adds the hand-written machine data
of robot/data: a KR C2 robot (KR 16-2), the 4- and 5-axis palletizers (A4 = 0; the 4-axis one's
A5 linked, A2 + A3 + A5 = 90 deg) and the KR 16-2 on a track (E1 along it) and with a turntable
(E1 turning); their targets carry E1, which moves with every motion. Long runs: the nightly
profile multiplies the examples (tests/budget.py)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pathlib import Path

from robot.bench import step_until
from robot.controller import Controller
from robot.errors import RobotError
from robot.frames import matrix_to_frame
from robot.limits import check_trace
from robot.machine import load_machine
from robot.mada import load_robot
from robot.motion import MotionParams, MotionRequest, SplineSegment
from robot.trace import TraceWriter
from tests.budget import examples

#: robot -> corpus folder, "lib:NAME" for a robot of robot/data, or None for the yaml KR 6 R900
ROBOTS = {"KR 6 R900": None, "KR210R2700_2": "HugoDanielson__ChinaMilling",
          "KR120R2700_EXTRA_HA": "khrzysio__KRC4_test", "KR16-2 KR C2": "lib:kr16_2_krc2",
          "KR180 PA 4-axis": "lib:kr180_r3200_pa", "KR180 PA 5-axis": "lib:kr180_r3200_pa5",
          "KR16-2 track": "lib:kr16_2_kl1500", "KR16-2 turntable": "lib:kr16_2_turntable"}
#: the range of E1 in the targets of a robot with an external axis (mm or deg)
E_RANGE = {"kr16_2_kl1500": (300.0, 3500.0), "kr16_2_turntable": (-120.0, 120.0)}
HOME = (0.0, -90.0, 90.0, 0.0, 60.0, 0.0)
# a comfortable part of the workspace: wrist away from A5 = 0, arm not stretched
RANGES = ((-70, 70), (-115, -55), (60, 125), (-60, 60), (25, 105), (-90, 90))

axes_st = st.tuples(*[st.floats(lo, hi, allow_nan=False) for lo, hi in RANGES])
approx_st = st.sampled_from([None, "C_PTP", "C_DIS", "C_VEL", "C_ORI", "C_SPL"])


@st.composite
def params_st(draw):
    return MotionParams().with_(
        vel_cp=draw(st.floats(0.1, 2.0)), ov_pro=draw(st.sampled_from([30.0, 100.0])),
        vel_axis=(draw(st.floats(10.0, 100.0)),) * 6,
        apo_cdis=draw(st.floats(1.0, 120.0)), apo_cptp=draw(st.floats(1.0, 100.0)),
        apo_cvel=draw(st.floats(10.0, 100.0)), apo_cori=draw(st.floats(1.0, 30.0)),
        ori_type=draw(st.sampled_from(["VAR", "VAR", "CONSTANT"])))


@st.composite
def step_st(draw):
    kind = draw(st.sampled_from(["PTP", "SPTP", "LIN", "CIRC", "SPLINE"]))
    step = {"kind": kind, "q": draw(axes_st), "approx": draw(approx_st), "params": draw(params_st()),
            "bulge": draw(st.floats(-120.0, 120.0)), "e": draw(st.floats(0.0, 1.0))}
    if kind == "SPLINE":
        step["segs"] = draw(st.lists(st.tuples(st.sampled_from(["SPL", "SLIN", "SCIRC"]), axes_st,
                                               st.floats(-80.0, 80.0)), min_size=2, max_size=5))
    return step


def _load(request, name):
    folder = ROBOTS[name]
    if folder is None:
        return load_machine()
    if folder.startswith("lib:"):
        return load_robot(folder[4:])
    return load_robot(request.getfixturevalue("shared_corpus") / folder)


@pytest.fixture(scope="module", params=sorted(k for k, v in ROBOTS.items() if not (v or "").startswith("lib:")))
def robot(request):
    return _load(request, request.param)


@pytest.fixture(scope="module", params=sorted(k for k, v in ROBOTS.items() if (v or "").startswith("lib:")))
def library_robot(request):
    return _load(request, request.param)


def _shape(machine, q, e_frac=0.5):
    """Axes of the robot's family from a drawn 6-tuple: A4 = 0 on a palletizer, A5 linked on
    the 4-axis one; E1 from its range (`e_frac` in 0..1) when the robot has one."""
    q = list(q)
    if machine.a4fix:
        q[3] = 0.0
    if machine.a5link:
        h = machine.home_deg
        q[4] = h[1] + h[2] + h[4] - q[1] - q[2]
    for e in machine.external_axes:
        lo, hi = E_RANGE[Path(machine.source).stem]
        q.append(lo + e_frac * (hi - lo))
    return np.asarray(q, dtype=float)


def _pose(kin, q):
    """The TCP pose of axes `q` (A1..A6 and E1..) in $WORLD: `kin` is the controller's
    planner model (robot/planner.py RobotModel), which puts a track's robot where E1 is."""
    I = np.eye(4)
    return matrix_to_frame(kin.tcp(np.asarray(q, dtype=float), I, I))


def _cart(kin, q):
    out = dict(zip("XYZABC", _pose(kin, q)))
    for i, v in enumerate(np.asarray(q, dtype=float)[6:]):
        out[f"E{i + 1}"] = float(v)
    return out


AXES = ("A1", "A2", "A3", "A4", "A5", "A6", "E1", "E2", "E3", "E4", "E5", "E6")


def _aux(p0, p1, bulge):
    """An auxiliary point: the chord's midpoint pushed sideways by ``bulge`` mm (horizontal)."""
    a, b = np.asarray(p0[:3]), np.asarray(p1[:3])
    d = b - a
    n = np.array([-d[1], d[0], 0.0])
    if np.linalg.norm(n) < 1e-3 or np.linalg.norm(d) < 5.0:
        return None
    m = 0.5 * (a + b) + bulge * n / np.linalg.norm(n)
    return {"X": float(m[0]), "Y": float(m[1]), "Z": float(m[2])}


def _requests(kin, steps):
    m = kin.machine
    home = _shape(m, HOME)
    cur = _pose(kin, home)
    out = [MotionRequest("PTP", dict(zip(AXES, home)), MotionParams())]
    for s in steps:
        P, q, k = s["params"], _shape(m, s["q"], s["e"]), s["kind"]
        ax = s["approx"]
        if k in ("PTP", "SPTP"):
            out.append(MotionRequest(k, dict(zip(AXES, q)), P, approx=ax,
                                     approx2=ax and "C_DIS"))
            cur = _pose(kin, q)
        elif k == "LIN":
            out.append(MotionRequest("LIN", _cart(kin, q), P, approx=ax))
            cur = _pose(kin, q)
        elif k == "CIRC":
            end = _pose(kin, q)
            aux = _aux(cur, end, s["bulge"])
            if aux is None:
                continue
            out.append(MotionRequest("CIRC", _cart(kin, q), P, approx=ax, aux=aux))
            cur = end
        else:
            segs = []
            for kind, qs, bulge in s["segs"]:
                qs = _shape(m, qs, s["e"])
                end = _pose(kin, qs)
                if kind == "SCIRC":
                    aux = _aux(cur, end, bulge)
                    if aux is None:
                        kind, aux = "SLIN", None
                    segs.append(SplineSegment(kind, _cart(kin, qs), aux=aux))
                else:
                    segs.append(SplineSegment(kind, _cart(kin, qs)))
                cur = end
            out.append(MotionRequest("SPLINE", {}, P, approx=ax, segments=tuple(segs)))
    return out


@settings(max_examples=examples(10), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(steps=st.lists(step_st(), min_size=1, max_size=5), mode=st.sampled_from(["AUT", "AUT", "T1"]))
def test_every_trace_keeps_the_limits(robot, steps, mode):
    _keeps_the_limits(robot, steps, mode)


@settings(max_examples=examples(3), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(steps=st.lists(step_st(), min_size=1, max_size=5), mode=st.sampled_from(["AUT", "AUT", "T1"]))
def test_every_trace_keeps_the_limits_on_the_library_robots(library_robot, steps, mode):
    _keeps_the_limits(library_robot, steps, mode)


@pytest.mark.slow
@settings(max_examples=examples(30), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(steps=st.lists(step_st(), min_size=1, max_size=5), mode=st.sampled_from(["AUT", "AUT", "T1"]))
def test_long_run_on_the_library_robots(library_robot, steps, mode):
    """The nightly's long run on the hand-written machine data (make nightly)."""
    _keeps_the_limits(library_robot, steps, mode)


def _keeps_the_limits(robot, steps, mode):
    tw = TraceWriter(keep=True)
    ctl = Controller(robot, trace=tw, mujoco=False, mode_op=mode)
    planned = 0
    for req in _requests(ctl.model, steps):
        while not ctl.can_enqueue():
            ctl.step()
        try:
            ctl.queue.enqueue(req)
            planned += 1
        except RobotError:
            continue  # the advance run would stop at this motion
        if ctl.time > 120.0:
            break
    step_until(ctl, ctl.is_idle, max_cycles=200_000)
    rep = check_trace(tw.events, robot)
    assert rep.ok, f"{rep.summary()}\n" + "\n".join(str(v) for v in rep.violations[:10])


def test_a_fixed_sequence_moves_every_library_robot(library_robot):
    """The property run is not vacuous on the library robots: a fixed PTP, LIN, CIRC and SPLINE
    sequence plans on each (no motion refused), moves it, and keeps the limits."""
    P = MotionParams().with_(vel_cp=0.5)
    q1, q2, q3 = (30.0, -80.0, 100.0, 20.0, 60.0, 10.0), (-20.0, -70.0, 90.0, -15.0, 50.0, -30.0), \
        (10.0, -95.0, 110.0, 0.0, 70.0, 45.0)
    steps = [{"kind": "PTP", "q": q1, "approx": None, "params": P, "bulge": 0.0, "e": 0.2},
             {"kind": "LIN", "q": q2, "approx": "C_DIS", "params": P, "bulge": 0.0, "e": 0.6},
             {"kind": "CIRC", "q": q3, "approx": None, "params": P, "bulge": 60.0, "e": 0.9},
             {"kind": "SPLINE", "q": q1, "approx": None, "params": P, "bulge": 0.0, "e": 0.3,
              "segs": [("SPL", q2, 0.0), ("SLIN", q1, 0.0)]}]
    tw = TraceWriter(keep=True)
    ctl = Controller(library_robot, trace=tw, mujoco=False)
    reqs = _requests(ctl.model, steps)
    assert len(reqs) == 5
    for req in reqs:
        while not ctl.can_enqueue():
            ctl.step()
        ctl.queue.enqueue(req)                   # every motion plans
    step_until(ctl, ctl.is_idle, max_cycles=200_000)
    assert ctl.last_error is None
    assert np.abs(ctl.actual.axis_act()[:3] - np.array(q1[:3])).max() < 1e-6 or library_robot.a5link
    rep = check_trace(tw.events, library_robot)
    assert rep.ok, rep.summary()


@pytest.mark.parametrize("approx", ["C_VEL", "C_ORI"])
def test_a_blend_from_an_orientation_the_palletizer_cannot_take(approx):
    """Regression (found by the property above on the KR 180 R3200 PA5): a CIRC with
    ``$ORI_TYPE #CONSTANT`` keeps its start orientation while A1 turns, which a 5-axis
    palletizer cannot (A4 = 0: the tilt out of the arm plane is dropped), so its planned end
    orientation lies 29 deg from the one the robot reaches there. The Cartesian blend into the
    next CIRC overlapped the planned orientations and ended off the next motion's own setpoint:
    A2 jumped to 6.2x a_max in the cycle the blend ended (C_VEL), and C_ORI's longer blend
    stopped with "speed limit exceeded A5". Expected, from the limits alone: every motion
    plans, the program runs to its end without a fault, and the trace keeps the limits."""
    machine = _load(None, "KR180 PA 5-axis")
    steps = [{"kind": "PTP", "q": (-48.5, -84.2, 82.9, 20.3, 25.9, 0.0), "approx": None,
              "params": MotionParams(), "bulge": 0.0, "e": 0.0},
             {"kind": "CIRC", "q": (-16.2, -60.0, 113.5, 60.0, 79.6, 40.8), "approx": approx,
              "params": MotionParams().with_(vel_cp=1.0, ori_type="CONSTANT"), "bulge": -47.7, "e": 0.0},
             {"kind": "CIRC", "q": (0.0, -73.0, 116.8, 12.8, 89.5, -40.8), "approx": None,
              "params": MotionParams().with_(vel_cp=1.0), "bulge": 80.7, "e": 0.0}]
    tw = TraceWriter(keep=True)
    ctl = Controller(machine, trace=tw, mujoco=False, mode_op="AUT")
    reqs = _requests(ctl.model, steps)
    assert [r.kind for r in reqs] == ["PTP", "PTP", "CIRC", "CIRC"]
    for req in reqs:
        while not ctl.can_enqueue():
            ctl.step()
        ctl.queue.enqueue(req)                   # every motion plans
    step_until(ctl, ctl.is_idle, max_cycles=200_000)
    phases = [(ev["id"], ev["phase"]) for ev in tw.events if ev.get("kind") == "motion"]
    assert (3, "blend_start") in phases    # the CIRC #CONSTANT is approximated
    assert ctl.last_error is None
    assert not [ev for ev in tw.events if ev.get("kind") == "error"]
    rep = check_trace(tw.events, machine)
    assert rep.ok, f"{rep.summary()}\n" + "\n".join(str(v) for v in rep.violations[:10])
    # the planner plans within a_max (up to the second difference's own error): the jump was 6.2x
    assert rep.axis_acc_ratio <= 1.02
