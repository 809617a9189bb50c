"""A motion planned again from the same start (robot/planrepeat.py, issue 86): the copy the
queue's memo gives is the segment a fresh plan makes, attribute by attribute and in what the
main run samples from it, and it shares nothing the main run could change with the kept one."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.frames import frame_to_matrix, matrix_to_frame
from robot.machine import load_machine
from robot.mada import load_robot
from robot.motion import MotionParams, MotionRequest, Trigger
from robot.motionqueue import MotionQueue
from robot.planner import plan
from robot.planrepeat import PlanRepeats
from robot.robotmodel import RobotModel

TOOL = (12.0, -3.0, 150.0, 0.0, 20.0, 0.0)
BASE = (900.0, -200.0, 10.0, 30.0, 0.0, 0.0)


def _same(a, b, path="", depth=0):
    """`a` and `b` hold the same values: arrays by dtype, shape and bytes, floats by their bits,
    containers item by item, objects by their attributes (the compiled path by identity)."""
    assert type(a) is type(b), path
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), path
    elif isinstance(a, float):
        assert a.hex() == b.hex() or (math.isnan(a) and math.isnan(b)), path
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{path}[{i}]", depth + 1)
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            _same(a[k], b[k], f"{path}.{k}", depth + 1)
    elif isinstance(a, RobotModel) or a is None or isinstance(a, (bool, int, str)):
        assert a is b or a == b, path
    elif hasattr(a, "__dict__") and depth < 4:
        _same(vars(a), vars(b), path, depth + 1)
    else:
        assert type(a) is type(b), path


def _requests(model: RobotModel, q0: np.ndarray) -> list[MotionRequest]:
    """PTPs (axis and Cartesian targets), single LINs (the compiled planning, with and without
    $TOOL and $BASE), a LIN that turns the orientation, a relative LIN and a CIRC, from `q0`."""
    plain = MotionParams()
    framed = MotionParams(tool=TOOL, base=BASE, vel_axis=(40.0,) * 6)
    out = [MotionRequest("PTP", {"A1": 20.0, "A2": -70.0, "A3": 95.0}, plain),
           MotionRequest("PTP", {"A1": -15.0}, framed)]
    for p in (plain, framed):
        f = matrix_to_frame(model.tcp(q0, _m(p.tool), np.linalg.inv(_m(p.base))))
        t = dict(zip("X Y Z A B C".split(), f))
        out.append(MotionRequest("LIN", {**t, "X": t["X"] + 120.0, "Z": t["Z"] - 150.0}, p,
                                 triggers=(Trigger(distance=1, delay_ms=-20.0, action="x"),
                                           Trigger(path_mm=-30.0, action="y"))))
        out.append(MotionRequest("LIN", {**t, "Y": t["Y"] + 80.0, "C": t["C"] + 15.0}, p))
        out.append(MotionRequest("PTP", {**t, "Z": t["Z"] + 60.0}, p))
        out.append(MotionRequest("CIRC", {**t, "X": t["X"] + 100.0, "Y": t["Y"] + 100.0}, p,
                                 aux={**t, "X": t["X"] + 50.0, "Y": t["Y"] + 120.0}))
    out.append(MotionRequest("LIN_REL", {"X": 50.0, "Z": -40.0}, plain))
    return out


def _m(frame):
    return frame_to_matrix(*frame)


@pytest.mark.parametrize("robot", [None, "kr180_r3200_pa5"])
def test_a_repeated_plan_is_a_fresh_plan(robot):
    """Each request planned with the memo (a miss, then two hits) equals the plan without it:
    every attribute (arrays by bytes), the limits and triggers, and the axes the main run samples
    every 12 ms along it; the robots: the KR 6 (OPW, compiled planning of a single LIN) and the
    five-axis palletizer of issue 86."""
    model = RobotModel(load_robot(robot) if robot else load_machine())
    q0 = np.array([10.0, -80.0, 100.0, 0.0, 35.0, 7.0]) if robot is None else \
        np.array([10.0, -80.0, 100.0, 0.0, 35.0, 7.0])[:len(model.axes.model_keys)]
    repeats = PlanRepeats()
    hits = 0
    for req in _requests(model, q0):
        try:
            fresh = plan(req, q0, model)
        except Exception as e:          # a target out of this robot's reach: the memo raises the same
            with pytest.raises(type(e)):
                plan(req, q0, model, repeats=repeats)
            continue
        for _ in range(3):
            got = plan(req, q0, model, repeats=repeats)
            _same(vars(got), vars(fresh), req.kind)
            assert got.limits == fresh.limits and got.triggers == fresh.triggers
            for tau in np.arange(0.0, fresh.T + 0.024, 0.024):
                assert got.axes(float(tau)).tobytes() == fresh.axes(float(tau)).tobytes(), (req.kind, tau)
            fresh = plan(req, q0, model)
        hits += 1
    assert hits >= 6


def test_a_copy_shares_nothing_the_main_run_changes():
    """A hit's arrays and lists are its own (changing them leaves the next hit as planned), and
    an array or list the plan holds twice is held twice by the copy too."""
    model = RobotModel(load_machine())
    q0 = np.array([10.0, -80.0, 100.0, 0.0, 35.0, 7.0])
    req = _requests(model, q0)[2]
    repeats = PlanRepeats()
    first = plan(req, q0, model, repeats=repeats)
    want = first.q1.tobytes()
    a = plan(req, q0, model, repeats=repeats)
    assert a._R is a.rots and a.q1 is not first.q1
    a.q1[:] = 0.0
    a.rots.append(None)
    a._last_q[:] = 1.0
    b = plan(req, q0, model, repeats=repeats)
    assert b.q1.tobytes() == want and len(b.rots) == 2 and b._last_q.tobytes() == q0.tobytes()


def test_the_key_tells_apart_what_planning_reads():
    """Another start, a signed zero in $TOOL, another target or kind, a relative target or another
    operating mode is another key; a spline block, #TCP and a linked $BASE are not kept."""
    model = RobotModel(load_machine())
    q0 = np.array([10.0, -80.0, 100.0, 0.0, 35.0, 7.0])
    r = PlanRepeats()
    base = MotionRequest("PTP", {"A1": 5.0}, MotionParams(tool=(0.0,) * 6))
    key = r.key(base, q0, model)
    q1 = q0.copy()
    q1[5] = np.nextafter(q1[5], 10.0)
    others = [r.key(base, q1, model),
              r.key(MotionRequest("PTP", {"A1": 5.0}, MotionParams(tool=(-0.0,) + (0.0,) * 5)), q0, model),
              r.key(MotionRequest("PTP", {"A1": 5.000000000000001}, base.params), q0, model),
              r.key(MotionRequest("LIN", {"A1": 5.0}, base.params), q0, model),
              r.key(MotionRequest("PTP_REL", {"A1": 5.0}, base.params), q0, model)]
    assert key is not None and all(k is not None and k != key for k in others)
    assert len(set(others)) == len(others)
    model_t1 = RobotModel(load_machine(), mode="T1")
    assert r.key(base, q0, model_t1) != key
    assert r.key(MotionRequest("PTP", {"A1": 5.0}, MotionParams(ipo_mode="TCP")), q0, model) is None
    assert r.key(MotionRequest("PTP", {"A1": 5.0}, MotionParams(base_kin="#EASYS")), q0, model) is None
    assert r.key(MotionRequest("SPLINE", {}, base.params), q0, model) is None


def test_the_queue_plans_a_cycle_once():
    """A queue planning a cycle of motions three times plans each motion once: the later cycles'
    segments are copies (the same axes at the end of each as the first cycle's)."""
    model = RobotModel(load_machine())
    q0 = np.array([10.0, -80.0, 100.0, 0.0, 35.0, 7.0])
    reqs = _requests(model, q0)[:4]
    queue = MotionQueue(model, q0, 5, strict_bco=False)
    ends = []
    for cycle in range(3):
        queue.plan_from(q0)
        ends.append([])
        for req in reqs:
            req = MotionRequest(req.kind, dict(req.target), req.params, aux=req.aux)
            queue.enqueue(req)
            ends[-1].append(queue.planned_axes().tobytes())
    assert ends[0] == ends[1] == ends[2]
    assert len(queue.repeats._segs) == len(reqs)
