"""A PTP's time from the robot's dynamics with the load the program sets (issue 73).

A KRL program runs on the simulated KR 3 R540 (robot/data/identified/kr3_r540.yaml: its dynamic
model) twice, changing only ``LOAD_DATA`` (0.661 kg, the tool of the real recordings, against the
KR 3's rated 3 kg), or only the pose the same axis moves from (the arm stretched against folded).
The expected planned durations are computed here by hand from MuJoCo's mass matrix
(``mj_fullM``) and bias forces (``qfrc_bias`` at rest: gravity) of the robot's model with the load
body set as KSS's LOAD describes it, the drives' torque limits and the trapezoid with a starting
and a braking rate: not through robot/dynamics.py's ``ptp_bounds`` or the planner. The run's
planned duration is its motion's end of interpolation less its START (robot/kukatrace/model.py).

The identified friction (``ptp_friction``) is left out of the robot here, so that the time law is
the plain trapezoid the hand computation gives; tests/interp/test_tracebench.py measures the
whole model against the real robot.
"""

from __future__ import annotations

import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from interp.tracebench import _config_dat, run_program
from robot.dynamics import arm_mjcf
from robot.frames import frame_to_matrix
from robot.kinematics import Kinematics
from robot.mada import load_robot
from robot.show import show_lines

TOOL14 = (31.665, -26.938, 117.128, -3.1214, -61.128, 2.4598)
LIGHT = {"m": 0.661, "cm": {"x": 12.18, "y": 2.33, "z": 48.63}, "j": {"x": 0.00098, "y": 0.0008, "z": 0.0004}}
RATED = {"m": 3.0, "cm": {"x": 60.0, "y": 0.0, "z": 80.0}, "j": {"x": 0.045, "y": 0.045, "z": 0.045}}


@pytest.fixture(scope="module")
def robot():
    m = load_robot("kr3_r540")
    assert m.dynamics is not None and m.dynamics.get("capped_axes")
    return replace(m, ptp_friction=())


def _program(tmp_path, name: str, start: dict, move: dict, load: dict):
    folder = tmp_path / name
    folder.mkdir()
    axes = lambda d: ", ".join(f"{k} {v}" for k, v in d.items())  # noqa: E731
    (folder / f"{name}.src").write_text(
        f"DEF {name}()\n  BAS(#INITMOV, 0)\n"
        + "".join(f"  $VEL_AXIS[{i}] = 100\n  $ACC_AXIS[{i}] = 100\n" for i in range(1, 7))
        + f"  PTP {{{axes(start)}}}\n  PTP {{{axes(move)}}}\nEND\n", encoding="latin-1")
    (folder / "$config.dat").write_text(_config_dat(TOOL14, load), encoding="latin-1")
    return folder / f"{name}.src"


def _planned(robot, src, interp: str) -> float:
    """The second motion's planned duration (end of interpolation - START, s) of `src`'s run."""
    view = run_program(src, 1.0, interp, robot)
    m = [mo for seg in view.segments for mo in seg.motions][-1]
    return m.reached - m.start


def _expected(robot, q0: np.ndarray, q1: np.ndarray, load: dict) -> float:
    """The planned duration (s) of the synchronised PTP q0 -> q1 (deg) at 100 %, by hand."""
    dyn = robot.dynamics
    model = mujoco.MjModel.from_xml_string(arm_mjcf(robot, dyn))
    data = mujoco.MjData(model)
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "load")
    model.body_mass[b] = load["m"]
    model.body_ipos[b] = [load["cm"][k] / 1000.0 for k in "xyz"]
    model.body_iquat[b] = (1.0, 0.0, 0.0, 0.0)          # A, B, C 0: the flange's axes
    model.body_inertia[b] = [load["j"][k] for k in "xyz"]
    sign = np.array([j.kuka_sign for j in robot.joints], dtype=float)
    S = np.diag(sign)

    kin = Kinematics(robot)
    R_root = frame_to_matrix(*robot.robroot_frame)[:3, :3]

    def mass_and_gravity(q):
        data.qpos[:] = sign * np.radians(q)
        data.qvel[:] = 0.0
        mujoco.mj_forward(model, data)
        # the load body is KUKA's flange frame (the kinematics' FLANGE(A1..An), not the MJCF's chain)
        T = kin.forward(q)
        assert data.xpos[b] == pytest.approx(R_root @ T[:3, 3] / 1000.0, abs=1e-9)
        assert data.xmat[b].reshape(3, 3) == pytest.approx(R_root @ T[:3, :3], abs=1e-9)
        M = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, M)
        return S @ M @ S, sign * data.qfrc_bias

    dq_deg = q1 - q0
    dq = np.radians(dq_deg)
    (M0, g0), (M1, g1) = mass_and_gravity(q0), mass_and_gravity(q1)
    h0, h1 = M0 @ dq, M1 @ dq
    tau = np.array([math.inf if t is None else t for t in dyn["torque_nm"]])
    moving = np.abs(dq_deg) > 1e-9
    start, brake = [], []
    for i in range(len(dq)):
        if abs(h0[i]) > 1e-12:
            start.append((tau[i] - np.sign(h0[i]) * g0[i]) / abs(h0[i]))
        if abs(h1[i]) > 1e-12:
            brake.append((tau[i] + np.sign(h1[i]) * g1[i]) / abs(h1[i]))
        if moving[i] and i + 1 in dyn["capped_axes"]:
            cap = robot.joints[i].max_acc_deg_s2 / abs(dq_deg[i])
            start.append(cap)
            brake.append(cap)
    A, D = min(start), min(brake)
    V = min(j.max_speed_deg_s / abs(d) for j, d, mv in zip(robot.joints, dq_deg, moving) if mv)
    if V * V / (2 * A) + V * V / (2 * D) <= 1.0:
        return 1.0 / V + V / (2 * A) + V / (2 * D)
    vp = math.sqrt(2 * A * D / (A + D))
    return vp / A + vp / D


@pytest.mark.parametrize("interp", ["vm", "tree"])
def test_a_heavier_load_makes_a2_slower_as_the_dynamics_say(robot, tmp_path, interp):
    # PTP_away's A2 motion: A2 -80 -> -35 with the arm stretched (A1 40, A3 70)
    start = {"A1": 40, "A2": -80, "A3": 70, "A4": 0, "A5": 0, "A6": 0}
    q0 = np.array([40.0, -80.0, 70.0, 0.0, 0.0, 0.0])
    q1 = q0 + np.array([0.0, 45.0, 0.0, 0.0, 0.0, 0.0])
    got = {}
    for label, load in (("light", LIGHT), ("rated", RATED)):
        src = _program(tmp_path, f"a2{label}", start, {"A2": -35}, load)
        got[label] = _planned(robot, src, interp)
        assert got[label] == pytest.approx(_expected(robot, q0, q1, load), abs=1e-6)
    # the 3 kg payload costs A2 more than a tenth of its time here (gravity takes its torque braking)
    assert got["rated"] > 1.10 * got["light"]


def test_the_same_a1_motion_is_slower_with_the_arm_stretched(robot, tmp_path):
    # A1 by -60 deg with the rated load, the arm folded (HOME's A2 -110, A3 110) or stretched
    # (A2 -35, A3 0): its inertia about A1 decides
    got, want = {}, {}
    for label, a2, a3 in (("close", -110, 110), ("away", -35, 0)):
        start = {"A1": 30, "A2": a2, "A3": a3, "A4": 0, "A5": 0, "A6": 0}
        src = _program(tmp_path, f"a1{label}", start, {"A1": -30}, RATED)
        got[label] = _planned(robot, src, "vm")
        q0 = np.array([30.0, a2, a3, 0.0, 0.0, 0.0])
        want[label] = _expected(robot, q0, q0 + np.array([-60.0, 0, 0, 0, 0, 0]), RATED)
        assert got[label] == pytest.approx(want[label], abs=1e-6)
    assert got["away"] > got["close"]


def test_robot_show_gives_each_dynamic_value_with_its_source():
    m = load_robot("kr3_r540")
    lines = show_lines(m)
    rows = {ln.split()[0]: ln for ln in lines if ln.startswith("           A")}
    d = m.dynamics
    for i, key in enumerate(("A1", "A2", "A3", "A4", "A5", "A6")):
        row = rows[key]
        assert f"{d['link_mass_kg'][i]:.3f}" in row
        t = d["torque_nm"][i]
        if t is None:
            assert "none known" in row
        elif i + 1 in d["capped_axes"]:
            assert f"{t:.2f}" in row and "measured" in row
        else:
            assert f"{t:.2f}" in row and "derived" in row
    assert any(ln.startswith("dynamics ") and "kr3_r540.yaml" in ln for ln in lines)
    # a robot without recordings has no dynamic model to show
    assert not any(ln.startswith("dynamics ") for ln in show_lines(load_robot("kr6_r900")))


@pytest.mark.parametrize("interp", ["vm", "tree"])
def test_a_program_without_load_data_gets_the_robots_default_load(robot, tmp_path, interp):
    """BAS(#INITMOV, 0) selects TOOL 0, whose load is the BASIS's DEF_LOAD_DATA: undefined (M -1),
    so the planner takes the robot's own default load, $DEF_L_M/$DEF_L_CM/$DEF_L_J (KUKA's
    $robcor.dat, "DEFAULTMASSE AM FLANSCH"): for the KR 3 R540 the load its real controller
    reports for TOOL 0 (PTP_away's PROG.TXT: RATED here), not the KR 6's 6 kg the BASIS used to
    give every robot (the A2 motion below was planned at 0.412 s with it, 0.288 s with 3 kg)."""
    folder = tmp_path / "noload"
    folder.mkdir()
    (folder / "noload.src").write_text(
        "DEF noload()\n  BAS(#INITMOV, 0)\n"
        + "".join(f"  $VEL_AXIS[{i}] = 100\n  $ACC_AXIS[{i}] = 100\n" for i in range(1, 7))
        + "  PTP {A1 40, A2 -80, A3 70, A4 0, A5 0, A6 0}\n  PTP {A2 -35}\nEND\n", encoding="latin-1")
    q0 = np.array([40.0, -80.0, 70.0, 0.0, 0.0, 0.0])
    q1 = q0 + np.array([0.0, 45.0, 0.0, 0.0, 0.0, 0.0])
    got = _planned(robot, folder / "noload.src", interp)
    assert got == pytest.approx(_expected(robot, q0, q1, RATED), abs=1e-6)
    six = {"m": 6.0, "cm": RATED["cm"], "j": RATED["j"]}
    assert got < _expected(robot, q0, q1, six) - 0.01
