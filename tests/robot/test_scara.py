"""The KUKA SCARA (robot/kinematics/scara.py; robot/data/kr6_r500_z200.dat, issue 47): machine data
with a linear axis, forward and inverse kinematics, status and turn, the MuJoCo model, and a KRL
program with PTP and LIN on both interpreters. The expected values are worked out by hand from the
machine data's numbers (arms 225 + 275 mm, the arms' plane 400 mm up, the flange 150 mm below it
at A3 = 0 and turned C 180, every axis positive clockwise seen from above, A3 positive down)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from app import main
from robot.bench import run_motions
from robot.controller import Controller
from robot.errors import SoftLimitError, WorkspaceError
from robot.frames import frame_to_matrix, matrix_to_frame
from robot.kinematics import Kinematics
from robot.limits import check_trace
from robot.mada import MachineDataError, load_robot
from robot.machine import ROBOT_LIBRARY
from robot.mjcf import ArmModel, build_mjcf
from robot.motion import MotionParams, MotionRequest
from robot.trace import TraceWriter, read_trace

REPO = Path(__file__).resolve().parents[2]
PROGRAM = REPO / "examples" / "scara" / "pick_place.src"


@pytest.fixture(scope="module")
def scara():
    return load_robot("kr6_r500_z200")


@pytest.fixture(scope="module")
def kin(scara):
    return Kinematics(scara)


def _by_hand(a1, a2, a3, a4):
    """The flange (X, Y, Z mm; its turn about the vertical, deg) of the module docstring's SCARA."""
    t1, t12 = math.radians(-a1), math.radians(-a1 - a2)
    x = 225 * math.cos(t1) + 275 * math.cos(t12)
    y = 225 * math.sin(t1) + 275 * math.sin(t12)
    return x, y, 400.0 - a3 - 150.0, -a1 - a2 - a4


def test_the_machine_data_make_a_four_axis_scara(scara, kin):
    assert scara.n_axes == 4 and scara.main_axis == "#CC"
    assert [j.kind for j in scara.joints] == ["rotary", "rotary", "linear", "rotary"]
    assert [j.limit_deg for j in scara.joints] == [(-132.0, 132.0), (-145.0, 145.0), (0.0, 200.0), (-355.0, 355.0)]
    # speed = rpm / |N/D| * 6 deg/s, a linear axis rpm / |N/D| * 1000/60 mm/s
    assert scara.max_speed_deg_s == pytest.approx((4200 / 60 * 6, 4800 / 40 * 6, 4000 / 60 * 1000 / 60, 6000 / 15 * 6))
    assert scara.reach_wrist_point_mm == 500.0
    assert kin.family == "scara" and kin.n_axes == 4
    assert "kr6_r500_z200" in {p.stem for p in ROBOT_LIBRARY.iterdir()}


@pytest.mark.parametrize("q", [(0, 0, 0, 0), (0, 90, 0, 0), (30, -60, 50, 45), (-120, 140, 200, -300), (90, -145, 10, 355)])
def test_forward_kinematics_by_hand(kin, q):
    x, y, z, turn = _by_hand(*q)
    X, Y, Z, A, B, C = matrix_to_frame(kin.forward(q))
    assert (X, Y, Z) == pytest.approx((x, y, z), abs=1e-9)
    assert B == pytest.approx(0.0, abs=1e-9) and abs(C) == pytest.approx(180.0)    # the flange looks down
    assert math.remainder(A - turn, 360.0) == pytest.approx(0.0, abs=1e-9)


def test_status_and_turn_by_hand(kin):
    assert kin.status_turn([0, 90, 0, 0]) == (2, 0)             # A2 >= 0: bit 1; nothing negative
    assert kin.status_turn([10, -30, 50, -20]) == (0, 0b1010)  # A2 < 0; A2 and A4 negative
    assert kin.status_turn([-5, 0, 0, 0]) == (2, 1)             # A2 = 0 counts as >= 0
    # the quill behind the A1 axis: 225 + 275 cos(145 deg) = -0.27 mm < 0 -> bit 0
    assert kin.status_turn([0, 145, 0, 0]) == (3, 0)
    assert kin.status_turn([0, 144, 0, 0]) == (2, 0)


def test_inverse_gives_back_every_configuration_with_its_status_and_turn(kin):
    rng = np.random.default_rng(47)
    for _ in range(2000):
        q = rng.uniform(kin._lo, kin._hi)
        s, t = kin.status_turn(q)
        assert np.abs(kin.inverse(kin.forward(q), s, t, rng.uniform(kin._lo, kin._hi)) - q).max() < 1e-6
        # the nearest solution without S/T: the reference's own elbow side and turns
        assert np.abs(kin.inverse(kin.forward(q), None, None, q) - q).max() < 1e-6


def test_the_two_elbows_are_the_two_statuses(kin):
    T = frame_to_matrix(380, 120, 150, 0, 0, 180)
    q0, q2 = kin.inverse(T, 0), kin.inverse(T, 2)
    assert q0[1] < 0 <= q2[1] and q0[1] == pytest.approx(-q2[1])
    assert q0[2] == q2[2] == pytest.approx(100.0)                # 400 - 150 - 150
    for q in (q0, q2):
        assert np.abs(kin.forward(q) - T).max() < 1e-9
    assert len(kin.solutions(T)) == 2


def test_a_tilted_target_keeps_only_its_turn_about_the_vertical(kin):
    T = frame_to_matrix(380, 120, 150, 20, 5, 175)
    q = kin.inverse(T, 2)
    X, Y, Z, A, B, C = matrix_to_frame(kin.forward(q))
    assert (X, Y, Z) == pytest.approx((380, 120, 150), abs=1e-9) and B == pytest.approx(0.0, abs=1e-9)


def test_errors_out_of_reach_and_past_the_stroke(kin):
    with pytest.raises(WorkspaceError):
        kin.inverse(frame_to_matrix(520, 0, 150, 0, 0, 180))          # beyond 225 + 275
    with pytest.raises(WorkspaceError):
        kin.inverse(frame_to_matrix(30, 0, 150, 0, 0, 180))           # inside 275 - 225
    with pytest.raises(SoftLimitError) as e:
        kin.inverse(frame_to_matrix(380, 120, 30, 0, 0, 180), 2)      # A3 = 220 mm > 200
    assert "+A3" in str(e.value)
    with pytest.raises(SoftLimitError):
        kin.check_soft_limits([0, 0, -1, 0])


def test_the_mujoco_model_is_the_kinematics(scara, kin):
    xml = build_mjcf(scara)
    assert '<joint name="joint_a3" type="slide"' in xml and xml.count('type="hinge"') == 3
    arm = ArmModel(scara)
    rng = np.random.default_rng(48)
    for _ in range(300):
        q = rng.uniform(kin._lo, kin._hi)
        arm.set_axes(q)
        assert np.abs(arm.flange_pose() - kin.forward(q)).max() < 1e-9
        assert np.abs(arm.axes_deg() - q).max() < 1e-9


def test_the_urdf_export_has_a_prismatic_a3(tmp_path):
    out = tmp_path / "scara.urdf"
    res = CliRunner().invoke(main, ["robot", "export", "kr6_r500_z200", "--format", "urdf", "-o", str(out)])
    assert res.exit_code == 0, res.output
    text = out.read_text()
    assert 'name="joint_a3" type="prismatic"' in text and 'lower="0.0" upper="0.2"' in text
    assert 'name="link_4-tool0"' in text


def test_robot_show_names_the_family_and_the_linear_axis():
    res = CliRunner().invoke(main, ["robot", "show", "kr6_r500_z200"])
    assert res.exit_code == 0, res.output
    assert "SCARA arms 225 + 275 mm" in res.output and "linear (mm)" in res.output
    assert "$MAIN_AXIS" in res.output and "$AXIS_SEQ" in res.output


def test_machine_data_of_another_axis_order_are_refused(tmp_path):
    text = (ROBOT_LIBRARY / "kr6_r500_z200.dat").read_text(encoding="latin-1")
    bad = tmp_path / "$machine.dat"
    bad.write_text(text.replace("$AXIS_SEQ[1]=3", "$AXIS_SEQ[1]=1"), encoding="latin-1")
    with pytest.raises(MachineDataError, match=r"\$AXIS_SEQ\[1\]=1"):
        load_robot(str(bad))
    bad.write_text(text.replace("INT $NUM_AX=4", "INT $NUM_AX=6"), encoding="latin-1")
    with pytest.raises(MachineDataError, match=r"\$NUM_AX=6"):
        load_robot(str(bad))


def _run(interp: str, trace: Path):
    return CliRunner().invoke(main, ["run", str(PROGRAM), "--robot", "kr6_r500_z200", "--interp", interp,
                                     "--trace", str(trace), "--max-sim-time", "60"])


def test_the_scara_runs_ptp_and_lin_on_both_interpreters_within_its_limits(tmp_path, scara):
    tree, vm = tmp_path / "tree.jsonl", tmp_path / "vm.jsonl"
    for interp, path in (("tree", tree), ("vm", vm)):
        res = _run(interp, path)
        assert res.exit_code == 0, res.output
        assert "completed" in res.output and "LIN 8, PTP 7" in res.output
    assert tree.read_bytes() == vm.read_bytes()
    events = list(read_trace(str(tree)))
    assert events[0]["kind"] == "robot" and events[0]["name"] == "KR6 R500 Z200 C4 SCARA"
    poses = [e for e in events if e["kind"] == "pose"]
    Q = np.array([e["axes"] for e in poses])
    assert Q.shape[1] == 4                                        # A1..A4: the robot's axes
    lo, hi = np.array(scara.softn_end), np.array(scara.softp_end)
    assert (Q >= lo - 1e-6).all() and (Q <= hi + 1e-6).all()
    report = check_trace(events)
    assert not report.violations and report.axis_speed_ratio <= 1.03 and report.axis_acc_ratio <= 1.1
    # the LIN down to the pick point: the TCP straight down at X 380, Y 120 (pick_place.dat) from
    # where the approximation of the PTP before it ends (C_PTP) to Z 20
    down = [e["tcp"] for e in poses if abs(e["tcp"][0] - 380) < 1e-3 and abs(e["tcp"][1] - 120) < 1e-3]
    zs = sorted({round(p[2], 3) for p in down})
    assert zs[0] == pytest.approx(20.0) and 140.0 < zs[-1] <= 150.0 and len(zs) > 10
    assert all(abs(p[4]) < 1e-6 and abs(abs(p[5]) - 180.0) < 1e-6 for p in down)


def test_random_ptp_and_lin_sequences_keep_the_scaras_limits(scara, kin):
    """Random PTP moves between configurations on one elbow side and LIN moves to poses near
    them (approximated or exact), on the controller: the trace keeps the axis speeds and
    accelerations of the machine data, the path speed, and the soft limits."""
    rng = np.random.default_rng(50)
    P = MotionParams.initmov(scara)
    lo, hi = np.array([-110.0, 25.0, 10.0, -300.0]), np.array([110.0, 130.0, 190.0, 300.0])
    for _ in range(5):
        tw = TraceWriter(keep=True)
        ctl = Controller(scara, trace=tw, mujoco=False)
        reqs = []
        for _ in range(6):
            q = rng.uniform(lo, hi)
            reqs.append(MotionRequest("PTP", dict(zip(("A1", "A2", "A3", "A4"), q.tolist())),
                                      P.with_(vel_axis=(float(rng.uniform(30.0, 100.0)),) * 6),
                                      approx=rng.choice([None, "C_PTP"])))
            q2 = np.clip(q + rng.uniform([-15.0, -15.0, -60.0, -40.0], [15.0, 15.0, 60.0, 40.0]), lo, hi)
            pose = dict(zip("XYZABC", matrix_to_frame(kin.forward(q2))))
            reqs.append(MotionRequest("LIN", pose, P.with_(vel_cp=float(rng.uniform(0.2, 2.0))),
                                      approx=rng.choice([None, "C_DIS"])))
        run_motions(ctl, reqs)
        events = tw.events
        assert not [e for e in events if e["kind"] == "error"]
        Q = np.array([e["axes"] for e in events if e["kind"] == "pose"])
        assert len(Q) > 300 and sum(e["kind"] == "motion" and e.get("phase") == "end" for e in events) == 12
        assert (Q >= np.array(scara.softn_end) - 1e-6).all() and (Q <= np.array(scara.softp_end) + 1e-6).all()
        report = check_trace(events, scara)
        assert not report.violations, report.violations[:3]
