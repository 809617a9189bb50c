"""The IPO cycle's read-back and timers (issue 86; robot/readback.py ``ReadBack.cycle``, robot/io.py
``IOImage.tick_timers``): the TCP of a cycle and the last cycle's TCP position are made when first
asked for, from what that cycle read back (MuJoCo's flange and the frames then in force), and the
running timers are found again only when a stop flag is written or the flags' list is replaced.

Expected values: a reader that asks for the TCP at every cycle (what the read-back gave before it
was lazy: the same calls at the same cycle) against one that asks late or never, bit for bit; the
TCP against ``INV_POS($BASE) : FLANGE : $TOOL`` (reference §6.4) made here with numpy from MuJoCo's
flange site; the timers' counts by hand (12 ms per cycle, reference §5.15)."""

from __future__ import annotations

import numpy as np
import pytest

from robot import ipocycle
from robot.frames import frame_to_matrix, inv_pos
from robot.io import IOImage
from robot.kinematics.compiled import pure_module
from robot.machine import load_machine
from robot.readback import ReadBack
from robot.robotmodel import RobotModel

#: setpoints of a few IPO cycles (A1..A6 deg): a PTP-like sweep of every axis
SETPOINTS = [np.array([0.0, -90.0, 90.0, 0.0, 30.0, 0.0]) + k * np.array([0.7, 0.3, -0.4, 1.1, -0.5, 2.0])
             for k in range(8)]
TOOL = frame_to_matrix(10.0, -20.0, 225.0, 0.0, 30.0, 0.0)
BASE = frame_to_matrix(500.0, 100.0, 0.0, 90.0, 0.0, 0.0)
TOOL2 = frame_to_matrix(0.0, 0.0, 125.0, 0.0, 0.0, 0.0)


@pytest.fixture(scope="module")
def model():
    return RobotModel(load_machine())


def _reader(model, mujoco):
    rb = ReadBack(model, SETPOINTS[0].copy(), actuated=False, mujoco=mujoco, cycles=pure_module(ipocycle), dt=0.012)
    rb.set_frames(TOOL, BASE, inv_pos(BASE))
    return rb


@pytest.mark.parametrize("mujoco", [True, False], ids=["mujoco", "no-mujoco"])
def test_a_tcp_asked_for_late_is_the_one_of_its_cycle(model, mujoco):
    eager, lazy = _reader(model, mujoco), _reader(model, mujoco)
    seen, prevs = [], []
    for k in range(1, len(SETPOINTS)):
        if k == 4:      # the next motion's frames: from this cycle on
            for rb in (eager, lazy):
                rb.set_frames(TOOL2, np.eye(4), np.eye(4))
        qa_e = eager.cycle(SETPOINTS[k], SETPOINTS[k - 1])
        qa_l = lazy.cycle(SETPOINTS[k], SETPOINTS[k - 1])
        assert qa_e.tobytes() == qa_l.tobytes()
        seen.append(eager.tcp.copy())
        prevs.append(eager.tcp_prev.copy())
        if mujoco:      # the TCP from MuJoCo's flange site of this cycle, by numpy
            arm = eager.arm()
            expect = eager.base_inv_T @ arm.flange_pose_world() @ eager.tool_T
            np.testing.assert_allclose(eager.tcp, expect, rtol=0, atol=1e-9)
        if k in (3, 6):     # the lazy reader asks now and then: this cycle's TCP, the last one's position
            assert lazy.tcp.tobytes() == seen[-1].tobytes()
            assert lazy.tcp_prev.tobytes() == prevs[-1].tobytes()
    assert lazy.tcp_prev.tobytes() == prevs[-1].tobytes()         # the last position asked for first
    assert lazy.tcp.tobytes() == seen[-1].tobytes()
    for k in range(1, len(seen)):       # each cycle's last position: the cycle before's TCP
        assert prevs[k].tobytes() == seen[k - 1][:3, 3].tobytes()


def test_frames_set_after_a_cycle_leave_its_tcp_alone(model):
    rb, ref = _reader(model, True), _reader(model, True)
    rb.cycle(SETPOINTS[1], SETPOINTS[0])
    ref.cycle(SETPOINTS[1], SETPOINTS[0])
    expect = ref.tcp.copy()
    rb.set_frames(TOOL2, np.eye(4), np.eye(4))      # the next motion starts after the cycle
    assert rb.tcp.tobytes() == expect.tobytes()
    assert not np.allclose(expect, ref.tcp_of(SETPOINTS[1], TOOL2, np.eye(4)))   # other frames: another TCP


def test_vel_act_is_the_tcp_step_over_the_cycle(model):
    rb = _reader(model, True)
    rb.cycle(SETPOINTS[1], SETPOINTS[0])
    p1 = rb.tcp[:3, 3].copy()
    rb.cycle(SETPOINTS[2], SETPOINTS[1])
    p2 = rb.tcp[:3, 3].copy()
    assert rb.vel_act() == float(np.linalg.norm(p2 - p1)) / 0.012 / 1000.0


def test_running_timers_follow_stop_writes_presets_and_a_replaced_list():
    io = IOImage()
    io.set_timer_stop(3, False)
    io.tick_timers(12)
    io.set_out(1, True)                 # another write (a new version): the same timers run
    io.tick_timers(12)
    assert io.timer_ms[3] == 24 and sum(io.timer_ms) == 24
    io.set_timer(3, -100)               # a preset of a running timer: it counts on from there
    io.tick_timers(12)
    assert io.timer_ms[3] == -88
    stop = [True] * 65
    stop[7] = False
    io.timer_stop = stop                # the image copied whole (interp/runtime/model.py): its flags count
    io.tick_timers(12)
    assert (io.timer_ms[3], io.timer_ms[7]) == (-88, 12)
    io.set_timer_stop(7, True)
    io.set_timer_stop(64, False)
    io.tick_timers(12)
    io.tick_timers(12)
    assert (io.timer_ms[3], io.timer_ms[7], io.timer_ms[64]) == (-88, 12, 24)
