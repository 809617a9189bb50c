"""The robot of a backup, built from its machine data (robot/mada.py, issue 22).

Expected values come from outside the code under test:
- the zero pose and HOME flange positions are computed here by hand from the lengths of the
  backup's ``$machine.dat`` (robot-model.md §4.3: at A = 0 the arm is stretched forward);
- the ROS-Industrial URDFs of the same robots give the joint origins (numbers copied below
  with their repository and path); forward kinematics from those numbers must agree with ours;
- inverse kinematics must give back the axes that forward kinematics started from.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robot.datalist import DataListError, read_data_list
from robot.kinematics import Kinematics
from robot.mada import MachineDataError, load_mada, load_robot

#: The three corpus backups with machine data: folder below the corpus, $machine.dat path,
#: $TRAFONAME, and the lengths read by hand from the file (mm):
#: ($TIRORO.Z, $LENGTH_A, $LENGTH_B, $TX3P3.X, $TX3P3.Z, $TFLWP.Z).
BACKUPS = {
    "KR210R2700_2": ("HugoDanielson__ChinaMilling", "KRC/R1/Mada/$machine.dat", "#KR210R2700_2 C4 FLR",
                     (645.0, 330.0, 1150.0, 1220.0, 115.0, 215.0)),
    "KR120R2700_EXTRA_HA": ("khrzysio__KRC4_test", "R1/Mada/$machine.dat", "#KR120R2700 EXTRA HA C4 FLR",
                            (675.0, 350.0, 1150.0, 1200.0, -41.0, 215.0)),
    "KR120R2700_2": ("rawpython__kukaKRLmagic", "R1/Mada/$machine.dat", "#KR120R2700_2 C4 FLR",
                     (645.0, 330.0, 1150.0, 1220.0, 115.0, 215.0)),
}

PI = math.pi
# URDF joints as (origin xyz m, origin rpy rad, axis), q_urdf = radians(A_i), then link_6 -> tool0
# (= KUKA flange, per both repositories' comments).
# kroshu/kuka_robot_descriptions kuka_quantec_support/urdf/kr210_r2700_2_macro.xacro
URDF_KR210_R2700_2 = (
    [((0, 0, 0), (-PI, 0, 0), (0, 0, 1)), ((0.33, 0, -0.645), (PI / 2, 0, 0), (0, 0, 1)),
     ((1.15, 0, 0), (0, 0, -PI / 2), (0, 0, 1)), ((0.115, 0, 0), (PI / 2, 0, 0), (0, 0, 1)),
     ((0, 0, -1.22), (-PI / 2, 0, 0), (0, 0, 1)), ((0, 0, 0), (PI / 2, 0, 0), (0, 0, 1))],
    ((0, 0, -0.215), (0, PI, 0)))
# kroshu/kuka_robot_descriptions kuka_quantec_support/urdf/kr120_r2700_2_macro.xacro
# (angles rounded to 4 decimals in the file: agreement to 0.05 mm over 2.9 m)
URDF_KR120_R2700_2 = (
    [((0, 0, 0.3056), (-3.1416, 0, 0), (0, 0, 1)), ((0.33, 0.072, -0.3394), (1.5708, 0, 0), (0, 0, 1)),
     ((1.15, 0, -0.103), (0, 0, 0), (0, 0, 1)), ((0.828, -0.115, 0.175), (1.5708, 0, -1.5708), (0, 0, 1)),
     ((0, 0.096, -0.392), (0, 1.5708, 1.5708), (0, 0, 1)), ((0.1665, 0, -0.096), (1.5708, 0, -1.5708), (0, 0, 1))],
    ((0, 0, -0.0485), (3.1416, 0, 3.1416)))
# ros-industrial/kuka_experimental kuka_kr210_support/urdf/kr210r2700extra_macro.xacro
# (the KR 210 R2700 extra shares its kinematics with the KR 120 R2700 extra HA)
URDF_KR210_R2700_EXTRA = (
    [((0, 0, 0.675), (0, 0, 0), (0, 0, -1)), ((0.350, 0, 0), (0, 0, 0), (0, 1, 0)),
     ((1.150, 0, 0), (0, 0, 0), (0, 1, 0)), ((0, 0, -0.041), (0, 0, 0), (-1, 0, 0)),
     ((1.200, 0, 0), (0, 0, 0), (0, 1, 0)), ((0.215, 0, 0), (0, 0, 0), (-1, 0, 0))],
    ((0, 0, 0), (0, PI / 2, 0)))

# kroshu/kuka_robot_descriptions kuka_quantec_support/urdf/kr210_r2700_extra_macro.xacro (KUKA's own
# ROS 2 description of the same R2700 extra arm): joints about their local Z
URDF_KR210_R2700_EXTRA_KROSHU = (
    [((0, 0, 0.302), (PI, 0, 0), (0, 0, 1)), ((0.35, 0, -0.373), (PI / 2, 0, 0), (0, 0, 1)),
     ((1.15, 0, 0), (0, 0, 0), (0, 0, 1)), ((0.9, 0.041, 0), (PI / 2, 0, -PI / 2), (0, 0, 1)),
     ((0, 0, -0.3), (0, PI / 2, PI / 2), (0, 0, 1)), ((0.215, 0, 0), (PI / 2, 0, -PI / 2), (0, 0, 1))],
    ((0, 0, 0), (PI, 0, PI)))

URDFS = {"KR210R2700_2": [(URDF_KR210_R2700_2, 1e-6)],
         "KR120R2700_2": [(URDF_KR120_R2700_2, 0.05)],
         "KR120R2700_EXTRA_HA": [(URDF_KR210_R2700_EXTRA, 1e-6), (URDF_KR210_R2700_EXTRA_KROSHU, 1e-6)]}


def urdf_forward(urdf, axes_deg) -> np.ndarray:
    """Flange frame (4x4, mm) of a URDF chain: origin, then rotation about the joint axis."""
    joints, (txyz, trpy) = urdf
    T = np.eye(4)
    for (xyz, rpy, axis), a in zip(joints, axes_deg):
        F = np.eye(4)
        F[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
        F[:3, 3] = np.array(xyz, dtype=float) * 1000.0
        J = np.eye(4)
        J[:3, :3] = Rotation.from_rotvec(np.array(axis, dtype=float) * math.radians(a)).as_matrix()
        T = T @ F @ J
    F = np.eye(4)
    F[:3, :3] = Rotation.from_euler("xyz", trpy).as_matrix()
    F[:3, 3] = np.array(txyz, dtype=float) * 1000.0
    return T @ F


@pytest.fixture(scope="module", params=sorted(BACKUPS))
def backup(request, shared_corpus):
    key = request.param
    folder, rel, trafo, lengths = BACKUPS[key]
    m = load_robot(shared_corpus / folder)
    return key, m, shared_corpus / folder / rel, trafo, lengths


def test_model_names_its_robot_and_sources(backup):
    key, m, path, trafo, _ = backup
    assert m.trafoname == trafo
    assert m.name == trafo.lstrip("#")
    assert m.source == str(path)
    # every machine-data parameter names its file:line; the line holds the variable
    lines = path.read_text(encoding="latin-1").splitlines()
    for var in ("$TIRORO", "$LENGTH_A", "$LENGTH_B", "$TX3P3", "$TFLWP", "$DH_4", "$DH_5", "$TRAFONAME"):
        where = m.provenance[var]
        file, line = where.rsplit(":", 1)
        assert file == str(path)
        assert var in lines[int(line) - 1], (var, where)
    assert m.provenance["max_acc_deg_s2"].startswith("derived:")
    assert not m.a4fix and not m.a5link


def test_zero_and_home_pose_by_hand(backup):
    _, m, _, _, (c1, a1, c2, x3, z3, c4) = backup
    k = Kinematics(m)
    # A = 0: arm stretched forward along X; the flange faces +X (its Z axis), the wrist is z3 above A3
    T = k.forward([0, 0, 0, 0, 0, 0])
    np.testing.assert_allclose(T[:3, 3], [a1 + c2 + x3 + c4, 0.0, c1 + z3], atol=1e-9)
    np.testing.assert_allclose(T[:3, 2], [1.0, 0.0, 0.0], atol=1e-12)
    # HOME {0, -90, 90, 0, 0, 0}: upper arm vertical, forearm forward
    T = k.forward(m.home_deg)
    np.testing.assert_allclose(T[:3, 3], [a1 + x3 + c4, 0.0, c1 + c2 + z3], atol=1e-9)
    assert m.reach_wrist_point_mm == pytest.approx(a1 + c2 + math.hypot(x3, z3))


def test_forward_kinematics_matches_ros_industrial_urdf(backup):
    key, m, *_ = backup
    k = Kinematics(m)
    rng = np.random.default_rng(7)
    lo = np.array(m.softn_end)
    hi = np.array(m.softp_end)
    for urdf, tol in URDFS[key]:
        for q in [np.zeros(6), np.array(m.home_deg)] + list(rng.uniform(lo, hi, size=(20, 6))):
            A, B = k.forward(q), urdf_forward(urdf, q)
            assert np.abs(A[:3, 3] - B[:3, 3]).max() < min(tol, 0.05), q
            assert np.abs(A[:3, :3] - B[:3, :3]).max() < 1e-4, q


def test_inverse_kinematics_round_trip(backup):
    _, m, *_ = backup
    k = Kinematics(m)
    rng = np.random.default_rng(3)
    lo = np.maximum(np.array(m.softn_end), -170.0) + 1.0
    hi = np.minimum(np.array(m.softp_end), 170.0) - 1.0
    n = 0
    for q in rng.uniform(lo, hi, size=(40, 6)):
        if abs(q[4]) < 1.0:
            continue                       # the wrist singularity leaves A4/A6 free
        T = k.forward(q)
        s, t = k.status_turn(q)
        q2 = k.inverse(T, status=s, turn=t, reference_deg=q)
        np.testing.assert_allclose(q2, q, atol=1e-7)
        np.testing.assert_allclose(k.forward(q2), T, atol=1e-7)
        n += 1
    assert n > 30


def test_limits_and_speeds_from_machine_data(shared_corpus):
    m = load_robot(shared_corpus / "HugoDanielson__ChinaMilling")
    # $SOFTN_END/$SOFTP_END[1..6] of the file
    assert m.limits_deg == ((-185.0, 185.0), (-140.0, -5.0), (-120.0, 168.0), (-350.0, 350.0),
                            (-125.0, 125.0), (-350.0, 350.0))
    # A1: $VEL_AXIS_MA[1] = 5000 rpm, $RAT_MOT_AX[1] = -1798/7: 5000 / (1798/7) * 6 deg/s
    assert m.joints[0].max_speed_deg_s == pytest.approx(5000 / (1798 / 7) * 6)
    assert m.joints[0].max_jerk_deg_s3 == pytest.approx(10429.6797)
    # derived acceleration: sqrt(v * jerk)
    assert m.joints[0].max_acc_deg_s2 == pytest.approx(math.sqrt(5000 / (1798 / 7) * 6 * 10429.6797))
    assert m.vel_ma.cp == 3.0 and m.acc_ma.cp == 10.0
    assert m.default_load["mass_kg"] > 0.0


def test_kr6_yaml_model_is_unchanged():
    m = load_robot(Path(__file__).resolve().parents[2] / "robot" / "data" / "kr6_r900.yaml")
    assert m.name == "KR 6 R900 sixx"
    np.testing.assert_allclose(Kinematics(m).forward(m.home_deg)[:3, 3], [525.0, 0.0, 890.0], atol=1e-9)


def _write_mada(tmp_path: Path, shared_corpus: Path, edit) -> Path:
    src = shared_corpus / "khrzysio__KRC4_test" / "R1" / "Mada" / "$machine.dat"
    dst = tmp_path / "R1" / "Mada"
    dst.mkdir(parents=True)
    text = src.read_text(encoding="latin-1")
    (dst / "$machine.dat").write_text(edit(text), encoding="latin-1")
    return dst / "$machine.dat"


def test_missing_and_bad_values_name_file_and_line(tmp_path, shared_corpus):
    p = _write_mada(tmp_path, shared_corpus, lambda t: t.replace("REAL $LENGTH_B=1150.00", "REAL $LENGTH_B"))
    with pytest.raises(MachineDataError, match=r"\$LENGTH_B is not set"):
        load_mada(p)
    p2 = _write_mada(tmp_path / "b", shared_corpus,
                     lambda t: t.replace("REAL $LENGTH_A=350.000", "REAL $LENGTH_A=350.0+1"))
    with pytest.raises(MachineDataError, match=r"\$machine\.dat:522:21: `\+` after the end of the statement"):
        load_mada(p2)                      # a syntax error: file:line:col and message of krl check
    p2 = _write_mada(tmp_path / "b2", shared_corpus,
                     lambda t: t.replace("REAL $LENGTH_A=350.000", "REAL $LENGTH_A=TRUE"))
    with pytest.raises(MachineDataError, match=r"\$machine\.dat:522: \$LENGTH_A=TRUE: a number was expected"):
        load_mada(p2)
    p3 = _write_mada(tmp_path / "c", shared_corpus,
                     lambda t: t.replace("DECL KINCLASS $KINCLASS=#STANDARD", "DECL KINCLASS $KINCLASS=#SPECIAL"))
    with pytest.raises(MachineDataError, match=r"\$machine\.dat:455: \$KINCLASS=#SPECIAL: only the #STANDARD"):
        load_mada(p3)
    p4 = _write_mada(tmp_path / "d", shared_corpus, lambda t: t.replace("$AXIS_DIR[3]=1", "$AXIS_DIR[3]=0"))
    with pytest.raises(MachineDataError, match=r"\$AXIS_DIR\[3\]=0: 1 or -1 was expected"):
        load_mada(p4)


def test_palletizer_flag_fixes_a4(tmp_path, shared_corpus):
    p = _write_mada(tmp_path, shared_corpus, lambda t: t.replace("BOOL $DEF_A4FIX=FALSE", "BOOL $DEF_A4FIX=TRUE"))
    m = load_mada(p)
    assert m.a4fix and m.joints[3].limit_deg == (0.0, 0.0)


def test_data_list_reader_rejects_a_routine_file(tmp_path):
    p = tmp_path / "x.dat"
    p.write_text("DEF x()\nEND\n", encoding="ascii")
    with pytest.raises(DataListError, match="not a data list"):
        read_data_list(p)


def test_backup_zip_and_machine_dat_give_the_same_robot(tmp_path, shared_corpus):
    folder = shared_corpus / "rawpython__kukaKRLmagic"
    a = load_robot(folder / "R1" / "Mada" / "$machine.dat")
    archive = shutil.make_archive(str(tmp_path / "backup"), "zip", folder, "R1/Mada")
    b = load_robot(archive)
    assert a.opw == b.opw and a.joints == b.joints
    assert b.source.startswith(archive)


def test_every_machine_data_file_of_the_corpus(shared_corpus):
    """Every ``$machine.dat`` of the corpus, found by walking it: a robot's (R1/Mada) builds the
    model that BACKUPS describes; the controller's (STEU/Mada: signals, ``$V_STEUMADA``, no arm)
    is refused with a message that says so and names the robot's file."""
    files = sorted(p for p in shared_corpus.rglob("*") if p.name.lower() == "$machine.dat" and p.is_file())
    robots, controllers = [], []
    for f in files:
        head = f.read_text(encoding="latin-1")
        if "$V_STEUMADA" in head and "$TIRORO" not in head:
            with pytest.raises(MachineDataError, match=r"none of the robot's machine data .* is set: it is the "
                               r"controller's machine data \(\$V_STEUMADA=.*R1/Mada/\$machine\.dat"):
                load_mada(f)
            controllers.append(f)
        else:
            robots.append(str(f.relative_to(shared_corpus)))
            assert load_mada(f).trafoname
    assert sorted(robots) == sorted(f"{folder}/{rel}" for folder, rel, *_ in BACKUPS.values())
    assert len(controllers) == len(robots)
