"""A KR C2 robot from its machine data (robot/data/kr16_2_krc2.dat; issue 34): a KR C2 file has no
$AXIS_JERK, no $ACC_OV and no $AXIS_HOME; the model derives them by the rules of robot/mada.py
and `krl robot show` marks them derived.

Expected values come from outside the code under test:
- forward kinematics: the published URDF of the same robot, ros-industrial/kuka_experimental
  kuka_kr16_support/urdf/kr16_2_macro.xacro (joint origins copied below);
- the derived accelerations by hand from the KR C2 handbook's rule (Maschinendaten 12.0400 §2.1.47:
  $RAISE_TIME + $FILTER/2 ms to rated speed, $FILTER = $DEF_FLT_PTP) and the file's numbers;
- inverse kinematics must give back the axes that forward kinematics started from.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from click.testing import CliRunner

from app import main
from robot.errors import SoftLimitError, WorkspaceError
from robot.frames import frame_to_matrix, matrix_to_frame
from robot.kinematics import Kinematics
from robot.mada import MachineDataError, load_mada
from robot.machine import ROBOT_LIBRARY
from tests.robot.test_mada import urdf_forward

KR16 = ROBOT_LIBRARY / "kr16_2_krc2.dat"
# ros-industrial/kuka_experimental kuka_kr16_support/urdf/kr16_2_macro.xacro: joint origins (m), no
# rotations, axes -Z, +Y, +Y, -X, +Y, -X; tool0 0.158 m after link_6, rotated rpy (0, 90 deg, 0)
URDF_KR16_2 = (
    [((0, 0, 0.675), (0, 0, 0), (0, 0, -1)), ((0.26, 0, 0), (0, 0, 0), (0, 1, 0)),
     ((0.68, 0, 0), (0, 0, 0), (0, 1, 0)), ((0.67, 0, -0.035), (0, 0, 0), (-1, 0, 0)),
     ((0, 0, 0), (0, 0, 0), (0, 1, 0)), ((0, 0, 0), (0, 0, 0), (-1, 0, 0))],
    ((0.158, 0, 0), (0, math.pi / 2, 0)))
# the same file's limits (deg) and speeds (deg/s)
URDF_LIMITS = ((-185, 185), (-155, 35), (-130, 154), (-350, 350), (-130, 130), (-350, 350))
URDF_SPEEDS = (156, 156, 156, 330, 330, 615)


@pytest.fixture(scope="module")
def kr16():
    return load_mada(KR16)


def test_forward_kinematics_matches_the_published_kr16_2(kr16):
    k = Kinematics(kr16)
    rng = np.random.default_rng(11)
    lo, hi = np.array(kr16.softn_end), np.array(kr16.softp_end)
    for q in [np.zeros(6), np.array(kr16.home_deg)] + list(rng.uniform(lo, hi, size=(30, 6))):
        A, B = k.forward(q), urdf_forward(URDF_KR16_2, q)
        assert np.abs(A[:3, 3] - B[:3, 3]).max() < 0.05, q
        assert np.abs(A[:3, :3] - B[:3, :3]).max() < 1e-9, q


def test_limits_and_speeds_are_the_published_ones(kr16):
    assert kr16.limits_deg == tuple((float(a), float(b)) for a, b in URDF_LIMITS)
    assert kr16.max_speed_deg_s == pytest.approx(URDF_SPEEDS, abs=1e-9)


def test_kr_c2_values_the_file_lacks_are_derived(kr16):
    # $RAISE_TIME[1] = 250 ms, $DEF_FLT_PTP = 96 ms: 156 deg/s reached in 0.298 s
    assert kr16.joints[0].max_acc_deg_s2 == pytest.approx(156 / 0.298)
    assert kr16.joints[5].max_acc_deg_s2 == pytest.approx(615 / 0.148)
    # no $AXIS_JERK: the acceleration spread over the 96 ms filter
    assert kr16.joints[0].max_jerk_deg_s3 == pytest.approx(156 / 0.298 / 0.096)
    assert kr16.home_deg == (0.0, -90.0, 90.0, 0.0, 0.0, 0.0)
    assert kr16.acc_ov == kr16.acc_ma
    for key in ("max_acc_deg_s2", "$AXIS_JERK", "home_deg"):
        assert kr16.provenance[key].startswith("derived:"), key
    assert "$RAISE_TIME" in kr16.provenance["max_acc_deg_s2"]


def test_robot_show_marks_the_derived_values():
    res = CliRunner().invoke(main, ["robot", "show", str(KR16)])
    assert res.exit_code == 0, res.output
    rows = [ln for ln in res.output.splitlines() if ln.strip().startswith("A1 ")]
    assert rows and rows[0].count("*") == 2          # acceleration and jerk of A1
    assert "* derived by a rule" in res.output
    assert "inverse    analytic (OPW" in res.output
    assert "$AXIS_JERK             derived:" in res.output


def test_without_raise_time_the_documented_default_ramp(tmp_path):
    text = KR16.read_text(encoding="utf-8")
    start, end = text.index("REAL $RAISE_TIME[12]"), text.index("DECL CP $VEL_MA")
    p = tmp_path / "$machine.dat"
    p.write_text(text[:start] + text[end:], encoding="utf-8")
    m = load_mada(p)
    assert m.joints[0].max_acc_deg_s2 == pytest.approx(156 / 0.2)
    assert "0.2 s" in m.provenance["max_acc_deg_s2"]


def test_inverse_kinematics_round_trip_every_status(kr16):
    k = Kinematics(kr16)
    assert k.family == "opw"
    rng = np.random.default_rng(5)
    lo = np.maximum(np.array(kr16.softn_end), -170.0) + 1.0
    hi = np.minimum(np.array(kr16.softp_end), 170.0) - 1.0
    seen, n = set(), 0
    for q in rng.uniform(lo, hi, size=(60, 6)):
        if abs(q[4]) < 1.0:
            continue
        T = k.forward(q)
        s, t = k.status_turn(q)
        seen.add(s)
        np.testing.assert_allclose(k.inverse(T, s, t, reference_deg=q), q, atol=1e-7)
        n += 1
    assert n > 40 and len(seen) >= 4


def test_errors_are_those_of_every_robot(kr16):
    k = Kinematics(kr16)
    with pytest.raises(WorkspaceError, match="workspace error"):
        k.inverse(frame_to_matrix(3000.0, 0.0, 500.0, 0.0, 90.0, 0.0))
    q = np.array([10.0, -60.0, 100.0, 20.0, 40.0, 30.0])
    with pytest.raises(SoftLimitError, match="A1"):
        k.inverse(k.forward(q), 2, 1, reference_deg=q)   # T bit 0: A1 < 0, only -350 would do


def test_a_kinclass_the_model_does_not_build_is_refused_naming_it(tmp_path):
    text = KR16.read_text(encoding="utf-8").replace("$KINCLASS=#STANDARD", "$KINCLASS=#DELTA_KIN")
    p = tmp_path / "$machine.dat"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(MachineDataError, match=r"\$machine\.dat:15: \$KINCLASS=#DELTA_KIN"):
        load_mada(p)


def test_home_from_h_pos_when_axis_home_is_absent(tmp_path):
    """KR C2 machine data give the home position in $H_POS (E6AXIS); the model's HOME takes it,
    naming its line, and a run starts there."""
    line = "E6AXIS $H_POS={A1 10.0,A2 -80.0,A3 95.0,A4 5.0,A5 30.0,A6 -20.0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}"
    text = KR16.read_text(encoding="utf-8").replace("ENDDAT", line + "\nENDDAT")
    p = tmp_path / "$machine.dat"
    p.write_text(text, encoding="utf-8")
    m = load_mada(p)
    assert m.home_deg == (10.0, -80.0, 95.0, 5.0, 30.0, -20.0)
    n = text.splitlines().index(line) + 1
    assert m.provenance["$H_POS"] == f"{p}:{n}" and "home_deg" not in m.provenance
    # the HOME flange pose is the forward kinematics of those axes
    assert np.allclose(m.home_flange_pose, matrix_to_frame(Kinematics(m).forward(m.home_deg)), atol=1e-9)
