"""The controller protocol: advance run queue, triggers, BRAKE, WAIT, I/O, stimuli, errors
(reference §5.8, §5.12-§5.18, §6.10)."""

from __future__ import annotations

import ast
import inspect
import math

import numpy as np
import pytest

import robot.controller as controller_module
from robot.bench import run_motions, step_until, wait_idle, wait_sec
from robot.controller import Controller, ErrorEvent, TriggerEvent
from robot.errors import RobotError, WorkspaceError
from robot.frames import matrix_to_frame
from robot.motion import MotionParams, MotionRequest, SplineSegment, Trigger
from robot.stimuli import parse_stimuli, load_cell
from robot.trace import TraceWriter

DT = 0.012
TOOL_DOWN = {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 90, "A6": 0}
HOME = {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 0, "A6": 0}


def _ctl(**kw):
    tw = TraceWriter(keep=True)
    return Controller(trace=tw, mujoco=False, **kw), tw


def _phases(events, mid):
    """The motion's phase times, and ``reached``: the IPO cycle in which its interpolation
    ended (an exact stop's END comes 24-36 ms later, robot/exactstop.py)."""
    ph = {e["phase"]: e["t"] for e in events if e["kind"] == "motion" and e["id"] == mid}
    for e in events:
        if e["kind"] == "motion" and e["id"] == mid and e.get("reached") is not None:
            ph["reached"] = math.ceil(e["reached"] / DT - 1e-6) * DT
    return ph


def _trig_times(events):
    return [(e["id"], e["index"], e["t"]) for e in events if e["kind"] == "trigger"]


# ------------------------------------------------------------------ advance run
def test_queue_blocks_at_advance():
    ctl, _ = _ctl()
    ctl.queue.set_advance(2)
    P = MotionParams()
    ctl.queue.enqueue(MotionRequest("PTP", HOME, P))
    assert ctl.can_enqueue()
    ctl.queue.enqueue(MotionRequest("PTP", {"A1": 30}, P))
    assert not ctl.can_enqueue()  # two motions wait: the advance run blocks
    ctl.step()  # the main run takes motion 1
    assert ctl.can_enqueue()
    ctl.queue.enqueue(MotionRequest("PTP", {"A1": -30}, P))
    assert not ctl.can_enqueue()
    assert not ctl.is_idle()
    wait_idle(ctl)
    assert ctl.is_idle() and ctl.can_enqueue()


def test_advance_zero_only_when_idle():
    ctl, _ = _ctl()
    ctl.queue.set_advance(0)
    ctl.queue.enqueue(MotionRequest("PTP", HOME, MotionParams()))
    assert not ctl.can_enqueue()
    wait_idle(ctl)
    assert ctl.can_enqueue()


def test_wait_sec_runs_on_simulated_time():
    ctl, _ = _ctl()
    assert ctl.cycles_for(0.012) == 1
    assert ctl.cycles_for(0) == 0
    wait_sec(ctl, 0.5)
    assert ctl.cycle == 42  # ceil(0.5 / 0.012)
    assert ctl.time == pytest.approx(0.504)


# ------------------------------------------------------------------ triggers
def _lin_with(triggers, v=0.25, approx=None, extra=()):
    P = MotionParams().with_(vel_cp=v)
    return [MotionRequest("PTP", TOOL_DOWN, P),
            MotionRequest("LIN", {"X": 445, "Y": 300, "Z": 810}, P, approx=approx,
                          triggers=tuple(triggers)), *extra]


def test_trigger_distance0_delay20_fires_20ms_after_start():
    ctl, tw = _ctl()
    events = run_motions(ctl, _lin_with([Trigger(distance=0, delay_ms=20, action="A")]))
    ph = _phases(tw.events, 2)
    (mid, idx, t), = _trig_times(tw.events)
    assert mid == 2 and idx == 0
    assert abs((t - ph["start"]) - 0.020) <= DT + 1e-9
    te = [e for e in events if isinstance(e, TriggerEvent)]
    assert te[0].trigger.action == "A"


def test_trigger_distance1_at_end_and_negative_delay():
    ctl, tw = _ctl()
    run_motions(ctl, _lin_with([Trigger(distance=1, delay_ms=0),
                                Trigger(distance=1, delay_ms=-100)]))
    ph = _phases(tw.events, 2)
    times = {idx: t for _, idx, t in _trig_times(tw.events)}
    # DISTANCE=1 of an exact stop: the cycle the robot reaches the end point, before END
    assert times[0] == pytest.approx(ph["reached"], abs=1e-9)
    assert ph["reached"] < ph["end"]
    assert abs((ph["reached"] - times[1]) - 0.100) <= DT + 1e-9


def test_trigger_distance1_in_blend_middle():
    P = MotionParams().with_(vel_cp=0.25, apo_cdis=30.0)
    nxt = (MotionRequest("LIN", {"X": 600, "Y": 300, "Z": 810}, P),)
    ctl, tw = _ctl()
    run_motions(ctl, _lin_with([Trigger(distance=1, delay_ms=0)], approx="C_DIS", extra=nxt))
    ph = _phases(tw.events, 2)
    (_, _, t), = _trig_times(tw.events)
    mid = 0.5 * (ph["blend_start"] + ph["blend_end"])
    assert abs(t - mid) <= DT + 1e-9


def test_trigger_path_before_end_and_onstart():
    """PATH=-50: 50 mm before the end point; PATH=30 ONSTART: 30 mm after the start."""
    ctl, tw = _ctl()
    run_motions(ctl, _lin_with([Trigger(path_mm=-50.0), Trigger(path_mm=30.0, onstart=True)]))
    times = {idx: t for _, idx, t in _trig_times(tw.events)}
    poses = {round(e["t"], 6): e["tcp"] for e in tw.events if e["kind"] == "pose"}
    step = 0.25 * 1000 * DT  # 3 mm per cycle at cruise speed
    y_end = poses[round(times[0], 6)][1]
    assert 250.0 <= y_end <= 250.0 + step + 1e-6
    y_start = poses[round(times[1], 6)][1]
    assert 30.0 <= y_start <= 30.0 + step + 1e-6


def test_trigger_path_not_for_ptp():
    ctl, _ = _ctl()
    ctl.queue.enqueue(MotionRequest("PTP", HOME, MotionParams()))
    with pytest.raises(RobotError):
        ctl.queue.enqueue(MotionRequest("PTP", {"A1": 10}, MotionParams(),
                                  triggers=(Trigger(path_mm=-5.0),)))


def test_pending_trigger_keeps_controller_busy():
    """A positive DELAY after an exact stop still fires; is_idle waits for it."""
    ctl, tw = _ctl()
    run_motions(ctl, _lin_with([Trigger(distance=1, delay_ms=200)]))
    ph = _phases(tw.events, 2)
    (_, _, t), = _trig_times(tw.events)
    assert abs(t - ph["reached"] - 0.2) <= DT + 1e-9


# ------------------------------------------------------------------ BRAKE
def _brake_run(fast):
    P = MotionParams().with_(vel_cp=1.0)
    ctl, tw = _ctl()
    ctl.queue.enqueue(MotionRequest("PTP", TOOL_DOWN, P))
    ctl.queue.enqueue(MotionRequest("LIN", {"X": 445, "Y": 400, "Z": 600}, P))
    while not ctl.time >= 1.0:
        ctl.step()
    p0 = ctl.actual.pos_act()
    t0 = ctl.time
    ctl.brake(fast)
    step_until(ctl, lambda: not ctl.is_braking())
    p1 = ctl.actual.pos_act()
    return ctl, tw, t0, p0, p1


def test_brake_f_stops_harder_than_brake_and_on_path():
    c1, tw1, t01, a1, b1 = _brake_run(False)
    c2, tw2, t02, a2, b2 = _brake_run(True)
    d_normal = np.hypot(b1["Y"] - a1["Y"], b1["Z"] - a1["Z"])
    d_fast = np.hypot(b2["Y"] - a2["Y"], b2["Z"] - a2["Z"])
    assert d_fast < d_normal
    assert (c2.time - t02) < (c1.time - t01)
    # stands still and stays on the straight line (445, 0, 810) -> (445, 400, 600)
    for tw in (tw1, tw2):
        a, b = np.array([445.0, 0, 810]), np.array([445.0, 400, 600])
        d = (b - a) / np.linalg.norm(b - a)
        for e in tw.events:
            if e["kind"] == "pose" and e["t"] > 0.3:
                v = np.array(e["tcp"][:3]) - a
                assert np.linalg.norm(v - (v @ d) * d) < 0.01
    assert c1.is_idle()  # the braked motion is suspended (interrupt level)


def test_brake_then_release_continues_to_the_end():
    ctl, tw, *_ = _brake_run(False)
    wait_sec(ctl, 0.1)
    ctl.release()
    assert not ctl.is_idle()
    wait_idle(ctl)
    p = ctl.actual.pos_act()
    assert (p["X"], p["Y"], p["Z"]) == pytest.approx((445, 400, 600), abs=1e-6)
    assert [e["phase"] for e in tw.events if e["kind"] == "motion" and e["id"] == 2][-1] == "end"


def test_release_plans_the_next_motion_from_the_end_of_the_held_chain():
    """After a release without a motion of the interrupt level, the advance run plans on
    from the end point of the last motion planned before the BRAKE (not from the standstill
    point): the next PTP starts where the robot then stands and ends at its target."""
    ctl, tw = _ctl()
    P = MotionParams()
    ctl.queue.enqueue(MotionRequest("PTP", HOME, P))
    wait_idle(ctl)
    ctl.queue.enqueue(MotionRequest("PTP", {"A1": 150}, P))
    step_until(ctl, lambda: ctl.time >= 0.3)
    ctl.brake()
    step_until(ctl, lambda: not ctl.is_braking())
    assert ctl.queue.planned_axes()[0] < 150 - 1.0        # interrupt level: from the standstill point
    wait_sec(ctl, 0.1)
    ctl.release()
    assert ctl.queue.planned_axes() == pytest.approx([150, -90, 90, 0, 0, 0], abs=1e-9)
    ctl.queue.enqueue(MotionRequest("PTP", {"A1": 0}, P))
    wait_idle(ctl)
    assert ctl.last_error is None
    assert ctl.actual.axis_setpoint() == pytest.approx([0, -90, 90, 0, 0, 0], abs=1e-9)
    assert [e["phase"] for e in tw.events if e["kind"] == "motion" and e["id"] == 2] == ["start", "end"]


@pytest.mark.parametrize("fast", [False, True])
@pytest.mark.parametrize("cycles", [2, 5, 10, 20])
def test_release_ramps_up_within_the_axis_accelerations(fast, cycles):
    """The path speed ramps back up after a release without any axis exceeding its machine
    acceleration (second differences of the setpoints), also when the motion was braked
    while it accelerated (the ramp's own term adds to the profile's acceleration then)."""
    ctl, tw = _ctl()
    P = MotionParams()
    ctl.queue.enqueue(MotionRequest("PTP", HOME, P))
    wait_idle(ctl)
    ctl.queue.enqueue(MotionRequest("PTP", {"A1": 160, "A2": -60}, P))
    for _ in range(cycles):
        ctl.step()
    ctl.brake(fast)
    step_until(ctl, lambda: not ctl.is_braking())
    ctl.step()
    t_rel = ctl.time
    ctl.release()
    wait_idle(ctl)
    assert ctl.actual.axis_setpoint() == pytest.approx([160, -60, 90, 0, 0, 0], abs=1e-9)
    poses = [(e["t"], e["axes"]) for e in tw.events if e["kind"] == "pose" and e["t"] >= t_rel - 2 * DT - 1e-9]
    Q = np.array([q for _, q in poses])
    acc = np.abs(Q[2:] - 2 * Q[1:-1] + Q[:-2]) / DT ** 2
    a_max = np.asarray(ctl.machine.max_acc_deg_s2, dtype=float)
    # the trace rounds axes to 1e-6 deg: a second difference is exact to ~0.014 deg/s²
    assert np.all(acc <= a_max * (1 + 1e-4)), (acc / a_max).max()
    v = np.abs(np.diff(Q, axis=0)) / DT
    assert np.all(v <= np.asarray(ctl.machine.max_speed_deg_s) * (1 + 1e-4))


def test_brake_then_resume_discards_motions():
    ctl, tw, _, _, stop = _brake_run(True)
    ctl.cancel_pending()
    assert ctl.is_idle()
    ctl.queue.enqueue(MotionRequest("LIN_REL", {"Z": 50}, MotionParams()))
    wait_idle(ctl)
    p = ctl.actual.pos_act()
    assert p["Z"] == pytest.approx(stop["Z"] + 50, abs=1e-6)
    assert p["Y"] == pytest.approx(stop["Y"], abs=1e-6)


def test_motion_in_interrupt_after_brake_then_release_replans():
    ctl, tw, _, _, stop = _brake_run(False)
    ctl.queue.enqueue(MotionRequest("LIN_REL", {"X": 30}, MotionParams()))
    wait_idle(ctl)
    ctl.release()
    wait_idle(ctl)
    p = ctl.actual.pos_act()
    assert (p["X"], p["Y"], p["Z"]) == pytest.approx((445, 400, 600), abs=1e-6)


# ------------------------------------------------------------------ I/O
def test_outputs_pulse_and_timers_logged():
    ctl, tw = _ctl()
    ctl.io.set_out(3, True)
    ctl.io.set_out(3, True)  # no change, no event
    ctl.signals.pulse(4, True, 0.1)
    ctl.io.set_timer_stop(1, False)
    wait_sec(ctl, 0.2)
    ios = [(e["signal"], e["value"]) for e in tw.events if e["kind"] == "io"]
    assert ios == [("$OUT[3]", True), ("$OUT[4]", True), ("$OUT[4]", False)]
    off = [e["t"] for e in tw.events if e["kind"] == "io" and e["value"] is False][0]
    assert off == pytest.approx(0.108)  # first IPO cycle at or after 0.1 s
    assert ctl.io.get_timer(1) == 17 * 12
    assert ctl.io.get_in(1025) is True


def test_stimuli_at_time_and_on_motion():
    stim = parse_stimuli({"stimuli": [
        {"at": 0.05, "set": {"$IN[3]": True}},
        {"when": {"motion": 2, "phase": "start"}, "set": {"$IN[4]": True}, "delay": 0.024},
        {"when": {"motion": 2, "reached": 5.0}, "set": {"$ANIN[1]": 0.5}},
    ]})
    tw = TraceWriter(keep=True)
    ctl = Controller(trace=tw, mujoco=False, stimuli=stim)
    run_motions(ctl, _lin_with([]))
    ev = {e["signal"]: e["t"] for e in tw.events if e["kind"] == "io"}
    assert ev["$IN[3]"] == pytest.approx(0.06)
    ph = _phases(tw.events, 2)
    assert ev["$IN[4]"] == pytest.approx(ph["start"] + 0.024)
    assert ph["start"] < ev["$ANIN[1]"] <= ph["end"]
    assert ctl.io.get_anin(1) == 0.5
    y_at = [e["tcp"][1] for e in tw.events if e["kind"] == "pose" and abs(e["t"] - ev["$ANIN[1]"]) < 1e-9][0]
    assert y_at >= 295.0


def test_stimuli_from_yaml_file(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text("stimuli:\n  - at: 0.024\n    set: {\"$IN[7]\": true}\n")
    ctl = Controller(mujoco=False, stimuli=load_cell(f))     # the one loader; the controller reads no YAML
    ctl.step()
    assert not ctl.io.get_in(7)
    ctl.step()
    assert ctl.io.get_in(7)


# ------------------------------------------------------------------ errors, read-back
def test_error_in_main_run_stops_and_reports(monkeypatch):
    ctl, tw = _ctl()
    P = MotionParams().with_(vel_cp=0.5)
    ctl.queue.enqueue(MotionRequest("PTP", TOOL_DOWN, P))
    ctl.queue.enqueue(MotionRequest("LIN", {"Y": 200}, P))
    ctl.queue.enqueue(MotionRequest("LIN", {"Y": 0}, P))
    seg = ctl.queue.pending[1]
    calls = {"n": 0}
    orig = seg.ik

    def failing(p, R, ref):
        calls["n"] += 1
        if calls["n"] > 10:
            raise WorkspaceError("workspace error: target not reachable")
        return orig(p, R, ref)

    monkeypatch.setattr(seg, "ik", failing)
    # the batched solve declines a chain with an error and the cycle solves alone, raising it
    monkeypatch.setattr(seg, "ik_chain", lambda poses, ref: None)
    # and the cycle poses and solves in Python (not robot/cartpath.py's CartPath compiled), through ik
    monkeypatch.setattr(seg, "_c_path", False)
    events = wait_idle(ctl)
    errs = [e for e in events if isinstance(e, ErrorEvent)]
    assert len(errs) == 1 and errs[0].id == 2
    assert ctl.is_idle() and len(ctl.queue) == 0
    assert [e["text"] for e in tw.events if e["kind"] == "error"] == ["workspace error: target not reachable"]


def test_axis_act_and_pos_act_from_mujoco():
    ctl = Controller()
    run_motions(ctl, [MotionRequest("PTP", TOOL_DOWN, MotionParams())])
    assert list(ctl.actual.axis_act()) == pytest.approx([0, -90, 90, 0, 90, 0], abs=1e-9)
    p = ctl.actual.pos_act()
    assert (p["X"], p["Y"], p["Z"]) == pytest.approx((445, 0, 810), abs=1e-6)
    p_tool = ctl.actual.pos_act(tool=(0, 0, 225, 0, 0, 0), base=(500, 0, 0, 90, 0, 0))
    # robot-model.md §7 worked example: {X 0, Y 55, Z 585, A 90, B 0, C 180}
    assert (p_tool["X"], p_tool["Y"], p_tool["Z"]) == pytest.approx((0, 55, 585), abs=1e-6)
    ctl.step()  # one cycle at rest
    assert ctl.actual.vel_act() == pytest.approx(0.0, abs=1e-9)


def test_triggers_inside_spline_block_refer_to_their_segment():
    P = MotionParams().with_(vel_cp=0.5)
    segs = (SplineSegment("SLIN", {"X": 445, "Y": 100, "Z": 810}),
            SplineSegment("SLIN", {"X": 545, "Y": 100, "Z": 810},
                          triggers=(Trigger(distance=0, delay_ms=0, line=7),
                                    Trigger(path_mm=-20.0, line=8))),
            SplineSegment("SPL", {"X": 600, "Y": 0, "Z": 760}))
    ctl, tw = _ctl()
    run_motions(ctl, [MotionRequest("PTP", TOOL_DOWN, P),
                      MotionRequest("SPLINE", {}, P, segments=segs)])
    poses = {round(e["t"], 6): e["tcp"] for e in tw.events if e["kind"] == "pose"}
    fired = {e["line"]: e["t"] for e in tw.events if e["kind"] == "trigger"}
    step = 0.5 * 1000 * DT
    x7 = poses[round(fired[7], 6)]
    assert x7[1] == pytest.approx(100.0, abs=1e-6) and 445.0 <= x7[0] <= 445.0 + step
    x8 = poses[round(fired[8], 6)]
    assert 525.0 <= x8[0] <= 525.0 + step


def test_actuated_mode_follows_setpoints():
    ctl = Controller(actuated=True)
    run_motions(ctl, [MotionRequest("PTP", TOOL_DOWN, MotionParams().with_(vel_axis=(50.0,) * 6))])
    wait_sec(ctl, 0.2)
    assert np.max(np.abs(ctl.actual.axis_act() - ctl.actual.axis_setpoint())) < 0.5


def test_trigger_distance1_negative_delay_before_blend_middle():
    P = MotionParams().with_(vel_cp=0.25, apo_cdis=30.0)
    nxt = (MotionRequest("LIN", {"X": 600, "Y": 300, "Z": 810}, P),)
    ctl, tw = _ctl()
    run_motions(ctl, _lin_with([Trigger(distance=1, delay_ms=-50)], approx="C_DIS", extra=nxt))
    ph = _phases(tw.events, 2)
    (_, _, t), = _trig_times(tw.events)
    mid = 0.5 * (ph["blend_start"] + ph["blend_end"])
    assert abs((mid - t) - 0.050) <= DT + 1e-9


def test_resume_keeps_motions_of_the_interrupt_routine():
    """BRAKE; LIN_REL (in the routine); RESUME: the routine's motion still runs, the
    interrupted ones are gone."""
    ctl, tw, _, _, stop = _brake_run(True)
    assert ctl.axis_ret() is not None
    ctl.queue.enqueue(MotionRequest("LIN_REL", {"Z": 40}, MotionParams()))
    ctl.cancel_pending()
    wait_idle(ctl)
    p = ctl.actual.pos_act()
    assert (p["Y"], p["Z"]) == pytest.approx((stop["Y"], stop["Z"] + 40), abs=1e-6)
    ctl.queue.enqueue(MotionRequest("LIN_REL", {"Z": 10}, MotionParams()))
    wait_idle(ctl)
    assert ctl.actual.pos_act()["Z"] == pytest.approx(stop["Z"] + 50, abs=1e-6)


def test_public_state_queries():
    ctl, _ = _ctl()
    assert not ctl.signals.may_change()
    ctl.signals.pulse(2, True, 0.05)
    assert ctl.signals.may_change()
    wait_sec(ctl, 0.06)
    assert not ctl.signals.may_change()
    ctl.io.set_timer_stop(3, False)
    assert ctl.signals.may_change()
    c2, _, *_ = _brake_run(False)
    assert c2.is_suspended()
    c2.cancel_pending()
    assert not c2.is_suspended()


# ------------------------------------------------------------------ a target out of the robot's limits
def _lin_to_pose_of(ctl, axes):
    pose = matrix_to_frame(ctl.model.kin.forward(axes))      # $TOOL = $BASE = $NULLFRAME
    return MotionRequest("LIN", dict(zip("XYZABC", pose)), MotionParams())


def test_target_outside_limits_is_the_target_no_configuration_reaches():
    """KR 6 R900: A5 within -120..120. The pose of {0,-90,90,0,125,0} has 8 analytic
    configurations whose A5 is +-125, +-145.7, +-143.0, +-134.9: none within the limits. The
    pose of {..., A5 119} is reachable (that very configuration); the pose of
    {30,-60,100,0,-130,0} too, by another one (A1 -150, A5 116.8)."""
    ctl, _ = _ctl()
    assert ctl.queue.target_outside_limits(_lin_to_pose_of(ctl, [0, -90, 90, 0, 125, 0]))
    assert not ctl.queue.target_outside_limits(_lin_to_pose_of(ctl, [0, -90, 90, 0, 119, 0]))
    assert not ctl.queue.target_outside_limits(_lin_to_pose_of(ctl, [30, -60, 100, 0, -130, 0]))
    far = MotionRequest("LIN", {"X": 5000, "Y": 0, "Z": 0, "A": 0, "B": 0, "C": 0}, MotionParams())
    assert ctl.queue.target_outside_limits(far)                      # out of reach
    assert not ctl.queue.target_outside_limits(MotionRequest("PTP", {"A1": 500}, MotionParams()))  # axis target
    assert not ctl.queue.target_outside_limits(MotionRequest("LIN", {"X": 5000}, MotionParams()))  # partial



def test_the_controller_is_below_40_methods():
    """Issue 62 ("Split the grab-bags"): Controller keeps the main run and its protocol with the
    interpreters; the motion queue (robot/motionqueue.py), the I/O side (robot/signals.py), the
    read-back (robot/readback.py), the monitoring (robot/monitor.py) and the event log
    (robot/events.py) are components. Every function defined in the class body counts (a
    property's getter and setter are two); 78 before the split."""
    tree = ast.parse(inspect.getsource(controller_module))
    cls = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Controller")
    defs = [n.name for n in cls.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
    assert len(defs) < 40, (len(defs), defs)
    assert {"step", "can_enqueue", "is_idle", "brake", "release", "cancel_pending"} <= set(defs)
    ctl = Controller(mujoco=False)
    assert ctl.queue.pending is ctl._pending and ctl.signals.io is ctl.io and ctl.log.trace is ctl.trace
