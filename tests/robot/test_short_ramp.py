"""The short-ramp law of a synchronised PTP (issue 88; robot/planner.py ``short_ramp_scale``).

A PTP whose axes would ramp to its speed in ``t`` < θ (s, at 100 % override) ramps in ``K / t``
instead; the others ramp as their dynamics allow. The times below are worked by hand from the
trapezoid ``T = d/v + t_ramp`` of the leading axis; the law's constants are given here, not the
identified ones; a KRL program runs the same motion on both interpreters. The identification (robot/kukatrace/identify.py ``fit_short_ramp``) is checked on
PTPs planned under a law it is not told: it finds that law's K and a θ between the ramp times the
law does and does not act on. The law acts at a reduced speed only (a leading axis below 100 %
``$VEL_AXIS``) and is identified on those PTPs alone: a PTP at 100 % whose ramp is as short ramps
as its axes allow.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from interp.tracebench import run_program
from robot.kukatrace.identify import fit_short_ramp
from robot.mada import load_robot
from robot.motion import MotionParams
from robot.planner import ptp_profile, ptp_ramp_time, short_ramp_scale

K, THETA = 4.5e-4, 0.0145


@pytest.fixture(scope="module")
def arm():
    """The KR 3 R540 without its dynamic model, friction or ramp distances (its joints' accelerations
    alone) under the law (K, θ) above."""
    m = load_robot("kr3_r540")
    return replace(m, dynamics=None, ptp_friction=(), ptp_ramp_deg=(), ptp_short_ramp_s2=K, ptp_short_ramp_below_s=THETA)


def _params(machine, vel, ov=100.0):
    return replace(MotionParams.initmov(machine), vel_axis=(vel,) * 6, acc_axis=(100.0,) * 6, ov_pro=ov)


def test_the_scale():
    m = type("M", (), {"ptp_short_ramp_s2": K, "ptp_short_ramp_below_s": THETA})()
    assert short_ramp_scale(0.010, m) == pytest.approx(0.010 ** 2 / 4.5e-4)      # 0.2222: ramp 45 ms
    assert short_ramp_scale(0.020, m) == 1.0                                        # above θ
    assert short_ramp_scale(0.0, m) == 1.0
    assert short_ramp_scale(0.010, type("N", (), {})()) == 1.0                      # a robot without the law


def test_a6_at_10_percent_ramps_in_k_over_t(arm):
    # A6 170 deg at 80 deg/s; its acceleration a6: t = 80/a6 (< θ), the ramp K/t, T = 170/80 + K/t
    a6 = arm.joints[5].max_acc_deg_s2
    t = 80.0 / a6
    assert t < THETA
    p = _params(arm, 10.0)
    dq = np.array([0, 0, 0, 0, 0, 170.0])
    assert ptp_ramp_time(dq, p, arm) == pytest.approx(t, rel=1e-9)
    assert ptp_profile(dq, p, arm).t_total == pytest.approx(170 / 80 + K / t, rel=1e-9)


def test_a_long_ramp_is_the_dynamics(arm):
    # A1 90 deg at 100 %: t = 530/a1, well above θ: T = 90/530 + 530/a1
    a1 = arm.joints[0].max_acc_deg_s2
    assert 530.0 / a1 > THETA
    assert ptp_profile(np.array([90.0, 0, 0, 0, 0, 0]), _params(arm, 100.0), arm).t_total == \
        pytest.approx(90 / 530 + 530 / a1, rel=1e-9)


def test_the_override_scales_the_plan_in_time(arm):
    # at 85 % override the plan is the 100 % one over 0.85 (t is taken at 100 %)
    a6 = arm.joints[5].max_acc_deg_s2
    dq = np.array([0, 0, 0, 0, 0, 170.0])
    assert ptp_profile(dq, _params(arm, 10.0, 85.0), arm).t_total == \
        pytest.approx((170 / 80 + K / (80.0 / a6)) / 0.85, rel=1e-9)


def test_the_synchronised_motion_decides(arm):
    # A6 170 deg leads at 10 % (2.125 s) with A5 100 deg slowed to it (47.06 deg/s): every axis
    # ramps in the same time, the longer of 80/a6 and 47.06/a5; that t decides, T = 2.125 + K/t
    a5, a6 = arm.joints[4].max_acc_deg_s2, arm.joints[5].max_acc_deg_s2
    t = max(80.0 / a6, (100 / 2.125) / a5)
    dq = np.array([0, 0, 0, 0, 100.0, 170.0])
    assert ptp_ramp_time(dq, _params(arm, 10.0), arm) == pytest.approx(t, rel=1e-9)
    assert ptp_profile(dq, _params(arm, 10.0), arm).t_total == pytest.approx(170 / 80 + K / t, rel=1e-9)



def _wrist_runs(truth, planned) -> list[dict]:
    """Single-axis PTPs of 150 deg on A4, A5 and A6 at 10, 50, 70 and 100 % of `truth`'s speed, as
    the identification reads them: each motion's axes, speeds, planned duration (``planned(dq,
    params, vel, axis index)``, s) and ramp time (s)."""
    mots = []
    for i in (3, 4, 5):
        for vel in (10.0, 50.0, 70.0, 100.0):
            dq = np.zeros(6)
            dq[i] = 150.0
            m = {"dq": dq, "q0": np.zeros(6), "vel": [vel] * 6, "acc": [100.0] * 6, "load": None}
            p = _params(truth, vel)
            m["plan"] = planned(dq, p, vel, i)
            m["t"] = ptp_ramp_time(dq, p, truth)
            mots.append(m)
    return mots

def test_the_identification_finds_the_law():
    # single-axis PTPs of A4..A6 at 10..100 % planned under a law (K 3.0e-4 s², θ 14 ms) the fit
    # is not told; A6 at 70 % ramps in 560/a6 (13.4 ms at 41 822 deg/s²) and is under it
    truth = replace(load_robot("kr3_r540"), dynamics=None, ptp_friction=(), ptp_ramp_deg=(),
                    ptp_short_ramp_s2=3.0e-4, ptp_short_ramp_below_s=0.014)
    mots = _wrist_runs(truth, lambda dq, p, vel, i: ptp_profile(dq, p, truth).t_total)
    machine = replace(truth, ptp_short_ramp_s2=0.0, ptp_short_ramp_below_s=0.0)
    k, below, _res = fit_short_ramp(machine, mots)
    assert k == pytest.approx(3.0e-4, rel=0.01)
    under = max(m["t"] for m in mots if m["t"] < 0.014)
    over = min(m["t"] for m in mots if m["t"] >= 0.014)
    assert under < below < over


@pytest.mark.parametrize("interp", ["vm", "tree"])
def test_a_program_at_10_percent_runs_the_law(arm, tmp_path, interp):
    # the same A6 move as above, programmed in KRL and run: its planned duration (end of
    # interpolation - START) is 170/80 + K/t, t = 80/a6; at 100 % $VEL_AXIS 170/800 + 800/a6
    a6 = arm.joints[5].max_acc_deg_s2
    src = tmp_path / "shortramp.src"
    src.write_text("DEF shortramp()\n  BAS(#INITMOV, 0)\n"
                   + "".join(f"  $VEL_AXIS[{i}] = 10\n  $ACC_AXIS[{i}] = 100\n" for i in range(1, 7))
                   + "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}\n  PTP {A6 170}\n"
                   + "  $VEL_AXIS[6] = 100\n  PTP {A6 0}\nEND\n", encoding="latin-1")
    view = run_program(src, 1.0, interp, arm)
    motions = [mo for seg in view.segments for mo in seg.motions]
    slow, fast = motions[-2], motions[-1]
    assert slow.reached - slow.start == pytest.approx(170 / 80 + K / (80.0 / a6), abs=0.013)
    assert fast.reached - fast.start == pytest.approx(170 / 800 + 800 / a6, abs=0.013)


def _fast_wrist(machine, a6: float = 80000.0):
    """`machine` with A6's acceleration raised so that its ramp at 100 % $VEL_AXIS, 800/a6 s, is
    below θ (10 ms at 80 000 deg/s²)."""
    joints = tuple(replace(j, max_acc_deg_s2=a6) if i == 5 else j for i, j in enumerate(machine.joints))
    return replace(machine, joints=joints)


def test_full_speed_is_not_under_the_law(arm):
    # A6 170 deg at 100 %: t = 800/80 000 = 10 ms < θ, but no axis runs below 100 % $VEL_AXIS:
    # the axis' own trapezoid, T = 170/800 + 0.010 = 0.2225 s (under the law it would be
    # 0.2125 + K/t = 0.2575 s); at 10 % the same axis is under it: T = 170/80 + K/0.001 = 2.575 s
    fast = _fast_wrist(arm)
    dq = np.array([0, 0, 0, 0, 0, 170.0])
    assert ptp_ramp_time(dq, _params(fast, 100.0), fast) == pytest.approx(0.010, rel=1e-9)
    assert ptp_profile(dq, _params(fast, 100.0), fast).t_total == pytest.approx(0.2225, rel=1e-9)
    assert ptp_profile(dq, _params(fast, 10.0), fast).t_total == pytest.approx(2.125 + K / 0.001, rel=1e-9)


@pytest.mark.parametrize("interp", ["vm", "tree"])
def test_a_program_at_full_speed_runs_without_the_law(arm, tmp_path, interp):
    # the move above in KRL: END - START is its planned 0.2225 s to the IPO cycle (0.2575 s under the law)
    src = tmp_path / "fullspeed.src"
    src.write_text("DEF fullspeed()\n  BAS(#INITMOV, 0)\n"
                   + "".join(f"  $VEL_AXIS[{i}] = 100\n  $ACC_AXIS[{i}] = 100\n" for i in range(1, 7))
                   + "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}\n  PTP {A6 170}\nEND\n", encoding="latin-1")
    view = run_program(src, 1.0, interp, _fast_wrist(arm))
    last = [mo for seg in view.segments for mo in seg.motions][-1]
    assert last.reached - last.start == pytest.approx(0.2225, abs=0.013)


def test_the_law_is_identified_on_reduced_speeds_alone():
    # as above (K 3.0e-4 s², θ 14 ms), with A6 at 80 000 deg/s²: its 100 % run ramps in 10 ms,
    # between the ramps under the law (A6 at 10-70 %: 1-7 ms; A4 at 10 and 50 %: 2.4, 12.1 ms) and
    # without (A4, A5 at 70 %: 16.9, 25.2 ms), and is planned without it: a fit that took it for a
    # PTP under the law would put θ below 10 ms or K off. The 100 % runs' durations by hand, the
    # trapezoid 150/v + v/a; the others planned under the law by the planner
    truth = _fast_wrist(replace(load_robot("kr3_r540"), dynamics=None, ptp_friction=(), ptp_ramp_deg=(),
                                ptp_short_ramp_s2=3.0e-4, ptp_short_ramp_below_s=0.014))
    def planned(dq, p, vel, i):
        v, a = truth.joints[i].max_speed_deg_s, truth.joints[i].max_acc_deg_s2
        return 150.0 / v + v / a if vel == 100.0 else ptp_profile(dq, p, truth).t_total
    mots = _wrist_runs(truth, planned)
    assert any(m["t"] < 0.014 and m["vel"][0] == 100.0 for m in mots)
    k, below, _res = fit_short_ramp(replace(truth, ptp_short_ramp_s2=0.0, ptp_short_ramp_below_s=0.0), mots)
    assert k == pytest.approx(3.0e-4, rel=0.01)
    reduced = [m["t"] for m in mots if m["vel"][0] < 100.0]
    assert max(t for t in reduced if t < 0.014) < below < min(t for t in reduced if t >= 0.014)
