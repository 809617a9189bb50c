"""The catalogue of KUKA robots by model name (issue 64; robot/catalogue.py, robot/data/catalogue.yaml).

Each model's forward kinematics, built from the catalogue's machine-data values by the project's own
model (robot/mada.py, robot/kinematics), agrees with its published description within 0.1 mm at 20
random poses. The description's chain is computed here independently, with plain numpy: for the
kuka_experimental models from the xacro files of ../shared/robots/descriptions (expanded by the
xacro package, joints read from the URDF; skipped cleanly when ../shared is absent), for the models
only kroshu's kuka_robot_descriptions describes from the joint origins transcribed below with their
file and commit (no local copy of that repository exists). Also: every spelling of a name resolves,
an unknown one is refused naming close models, `krl robot list` lists every model with its source,
and machine data of the project's library naming a model win over its description.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import xacro
import xacro.substitution_args
from click.testing import CliRunner
from scipy.spatial.transform import Rotation

from app import main
from robot import catalogue
from robot.kinematics import Kinematics
from robot.mada import catalogue_robot
from robot.madavalues import MachineDataError

DESCRIPTIONS = Path(__file__).resolve().parents[3] / "shared" / "robots" / "descriptions" / "kuka_experimental"

PI = math.pi
_R, _RM, _X90, _XM90, _ZM90 = (PI, 0, 0), (-PI, 0, 0), (PI / 2, 0, 0), (-PI / 2, 0, 0), (0, 0, -PI / 2)
_Z = (0, 0, 1)


def _rpy_form(a1, c1, c2, w, c3, c4):
    """kroshu's "rpy" files (e.g. kr210_r3100_2_macro.xacro): joint_1 (0 0 0) rpy (-pi 0 0); joint_2
    (a1 0 -c1) rpy (pi/2 0 0); joint_3 (c2 0 0) rpy (0 0 -pi/2); joint_4 (w 0 0) rpy (pi/2 0 0);
    joint_5 (0 0 -c3) rpy (-pi/2 0 0); joint_6 (0 0 0) rpy (pi/2 0 0); tool0 (0 0 -c4) rpy (0 pi 0);
    every axis 0 0 1 (m)."""
    return ([((0, 0, 0), _RM, _Z), ((a1, 0, -c1), _X90, _Z), ((c2, 0, 0), _ZM90, _Z), ((w, 0, 0), _X90, _Z),
             ((0, 0, -c3), _XM90, _Z), ((0, 0, 0), _X90, _Z)], ((0, 0, -c4), (0, PI, 0)))


def _cad_form(j1z, j2, j3, j4, j5, j6, tz):
    """kroshu's "CAD" files (e.g. kr150_r3100_2_macro.xacro): joint_1 (0 0 j1z) rpy (pi 0 0), joint_2
    rpy (pi/2 0 0), joint_3 rpy 0, joint_4 rpy (pi/2 0 -pi/2), joint_5 rpy (0 pi/2 pi/2), joint_6
    rpy (pi/2 0 -pi/2), with the xyz given; tool0 (0 0 tz) rpy (pi 0 pi); every axis 0 0 1 (m)."""
    return ([((0, 0, j1z), _R, _Z), (j2, _X90, _Z), (j3, (0, 0, 0), _Z), (j4, (PI / 2, 0, -PI / 2), _Z),
             (j5, (0, PI / 2, PI / 2), _Z), (j6, (PI / 2, 0, -PI / 2), _Z)], ((0, 0, tz), (PI, 0, PI)))


#: kroshu/kuka_robot_descriptions, file@commit: the joint origins as the file gives them (m, rad)
KROSHU = {
    "KR120R3100_2": ("kuka_quantec_support/urdf/kr120_r3100_2_macro.xacro@6619f32d", _cad_form(
        0.3056, (0.33, 0.072, -0.3394), (1.35, 0, -0.103), (1.028, -0.115, 0.175), (0, 0.096, -0.392),
        (0.1665, 0, -0.096), -0.0485)),
    "KR120R2700_2": ("kuka_quantec_support/urdf/kr120_r2700_2_macro.xacro@4d5237ab (angles rounded to 4 "
                     "decimals in the file)",
                     ([((0, 0, 0.3056), (-3.1416, 0, 0), _Z), ((0.33, 0.072, -0.3394), (1.5708, 0, 0), _Z),
                       ((1.15, 0, -0.103), (0, 0, 0), _Z), ((0.828, -0.115, 0.175), (1.5708, 0, -1.5708), _Z),
                       ((0, 0.096, -0.392), (0, 1.5708, 1.5708), _Z), ((0.1665, 0, -0.096), (1.5708, 0, -1.5708), _Z)],
                      ((0, 0, -0.0485), (3.1416, 0, 3.1416)))),
    "KR240R2900_2": ("kuka_quantec_support/urdf/kr240_r2900_2_macro.xacro@c9069bf8", _cad_form(
        0.3056, (0.33, 0.072, -0.3394), (1.35, 0, -0.103), (0.828, -0.115, 0.175), (0, 0.1065, -0.392),
        (0.1695, 0, -0.1065), -0.0705)),
    "KR300R2700_2": ("kuka_quantec_support/urdf/kr300_r2700_2_macro.xacro@3c17904b", _cad_form(
        0.3056, (0.33, 0.072, -0.3394), (1.15, 0, -0.103), (0.828, -0.115, 0.175), (0, 0.1065, -0.392),
        (0.1695, 0, -0.1065), -0.0705)),
    "KR210R3100_2": ("kuka_quantec_support/urdf/kr210_r3100_2_macro.xacro@04e1135b",
                     _rpy_form(0.33, 0.645, 1.35, 0.115, 1.42, 0.240)),
    "KR210R2700_2": ("kuka_quantec_support/urdf/kr210_r2700_2_macro.xacro@062e13cb",
                     _rpy_form(0.33, 0.645, 1.15, 0.115, 1.22, 0.215)),
    "KR210R2700EXTRA": ("kuka_quantec_support/urdf/kr210_r2700_extra_macro.xacro@d913c020",
                        ([((0, 0, 0.302), _R, _Z), ((0.35, 0, -0.373), _X90, _Z), ((1.15, 0, 0), (0, 0, 0), _Z),
                          ((0.9, 0.041, 0), (PI / 2, 0, -PI / 2), _Z), ((0, 0, -0.3), (0, PI / 2, PI / 2), _Z),
                          ((0.215, 0, 0), (PI / 2, 0, -PI / 2), _Z)], ((0, 0, 0), (PI, 0, PI)))),
    "KR240R3330": ("kuka_fortec_support/urdf/kr240_r3330_macro.xacro@0ed7f310", _cad_form(
        0.4, (0.5, 0, -0.645), (1.3, 0, 0), (1.064, 0.055, 0), (0, 0, -0.461), (0.29, 0, 0), 0.0)),
    "KR360R2830": ("kuka_fortec_support/urdf/kr360_r2830_macro.xacro@01c953b0", _cad_form(
        0.4, (0.5, 0, -0.645), (1.3, 0, 0), (0.564, 0.055, 0), (0, 0, -0.461), (0.29, 0, 0), 0.0)),
    "KR560R3100_2": ("kuka_fortec_support/urdf/kr560_r3100_2_macro.xacro@04e1135b",
                     _rpy_form(0.5, 0.86, 1.55, 0.18, 1.0345, 0.305)),
    "KR10R1100_2": ("kuka_agilus_support/urdf/kr10_r1100_2_macro.xacro@0017e66c",
                    _rpy_form(0.025, 0.4, 0.56, 0.025, 0.515, 0.09)),
    "KR16R2010_2": ("kuka_cybertech_support/urdf/kr16_r2010_2_macro.xacro@04e1135b",
                    _rpy_form(0.16, 0.52, 0.98, 0.15, 0.86, 0.153)),
    "KR20R1810_2": ("kuka_cybertech_support/urdf/kr20_r1810_2_macro.xacro@019fc0df", _cad_form(
        0.3127, (0.16, 0, -0.2073), (0.78, 0, 0), (0.427, -0.15, 0), (0, 0, -0.433), (0.153, 0, 0), 0.0)),
    "KR6R700_2": ("kuka_agilus_support/urdf/kr6_r700_2_macro.xacro@070f1555", _cad_form(
        0.208, (0.025, -0.0907, -0.192), (0.335, 0, -0.0042), (0.141, -0.025, -0.0865), (0, 0.0505, -0.224),
        (0.0615, 0, -0.0505), -0.0285)),
    # the kroshu description of a model kuka_experimental also describes: both are compared
    "KR150R3100_2": ("kuka_quantec_support/urdf/kr150_r3100_2_macro.xacro@062e13cb", _cad_form(
        0.3056, (0.33, 0.072, -0.3394), (1.35, 0, -0.103), (1.028, -0.115, 0.175), (0, 0.096, -0.392),
        (0.1665, 0, -0.096), -0.0485)),
}

#: ros-industrial/kuka_experimental (../shared/robots/descriptions): model -> (macro file, macro name)
EXPERIMENTAL = {
    "KR3R540": ("kuka_kr3_support/urdf/kr3r540_macro.xacro", "kuka_kr3r540"),
    "KR6R700SIXX": ("kuka_kr6_support/urdf/kr6r700sixx_macro.xacro", "kuka_kr6r700sixx"),
    "KR6R900SIXX": ("kuka_kr6_support/urdf/kr6r900sixx_macro.xacro", "kuka_kr6r900sixx"),
    "KR6R900_2": ("kuka_kr6_support/urdf/kr6r900_2_macro.xacro", "kuka_kr6r900_2"),
    "KR10R900_2": ("kuka_kr10_support/urdf/kr10r900_2_macro.xacro", "kuka_kr10r900_2"),
    "KR10R1100SIXX": ("kuka_kr10_support/urdf/kr10r1100sixx_macro.xacro", "kuka_kr10r1100sixx"),
    "KR10R1420": ("kuka_kr10_support/urdf/kr10r1420_macro.xacro", "kuka_kr10r1420"),
    "KR16_2": ("kuka_kr16_support/urdf/kr16_2_macro.xacro", "kuka_kr16_2"),
    "KR120R2500PRO": ("kuka_kr120_support/urdf/kr120r2500pro_macro.xacro", "kuka_kr120r2500pro"),
    "KR150_2": ("kuka_kr150_support/urdf/kr150_2_macro.xacro", "kuka_kr150_2"),
    "KR150R3100_2": ("kuka_kr150_support/urdf/kr150r3100_2_macro.xacro", "kuka_kr150r3100_2"),
}


def _frame(xyz, rpy) -> np.ndarray:
    F = np.eye(4)
    F[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
    F[:3, 3] = np.asarray(xyz, dtype=float) * 1000.0
    return F


def chain_forward(chain, axes_deg) -> np.ndarray:
    """The flange (tool0, 4x4 mm) of a description's chain: each joint's origin, then its rotation
    about its axis by A_i (q_urdf = radians(A_i), both repositories' convention); the fixed frames
    to tool0 as (xyz, rpy) or a 4x4 matrix (mm)."""
    joints, tool = chain
    T = np.eye(4)
    for (xyz, rpy, axis), a in zip(joints, axes_deg):
        J = np.eye(4)
        J[:3, :3] = Rotation.from_rotvec(np.asarray(axis, dtype=float) * math.radians(a)).as_matrix()
        T = T @ _frame(xyz, rpy) @ J
    return T @ (tool if isinstance(tool, np.ndarray) else _frame(*tool))


def experimental_chain(macro: str, name: str):
    """The chain base_link .. tool0 of a kuka_experimental macro, expanded by xacro (``$(find pkg)``
    answered by the description tree's own package folder), read with ElementTree."""
    old = xacro.substitution_args._eval_find
    xacro.substitution_args._eval_find = lambda pkg: str(DESCRIPTIONS / pkg)
    try:
        doc = xacro.parse(f'<robot xmlns:xacro="http://wiki.ros.org/xacro" name="r"><xacro:include '
                          f'filename="{DESCRIPTIONS / macro}"/><xacro:{name} prefix=""/></robot>')
        xacro.process_doc(doc)
    finally:
        xacro.substitution_args._eval_find = old
    root = ET.fromstring(doc.toxml())
    by_child = {j.find("child").get("link"): j for j in root.iter("joint")}
    seq, link = [], "tool0"
    while link in by_child:
        seq.append(by_child[link])
        link = by_child[link].find("parent").get("link")
    joints, fixed = [], np.eye(4)
    for j in reversed(seq):
        o = j.find("origin")
        xyz = [float(v) for v in o.get("xyz", "0 0 0").split()] if o is not None else [0, 0, 0]
        rpy = [float(v) for v in o.get("rpy", "0 0 0").split()] if o is not None else [0, 0, 0]
        if j.get("type") == "fixed":
            fixed = fixed @ _frame(xyz, rpy)
        else:
            assert not joints or np.allclose(fixed, np.eye(4)), "a fixed joint between two axes"
            joints.append((xyz, rpy, [float(v) for v in j.find("axis").get("xyz").split()]))
    return joints, fixed


def _compare(key: str, chain) -> float:
    m = catalogue_robot(key)
    k = Kinematics(m)
    rng = np.random.default_rng(64)
    lo = np.array([a for a, _ in m.limits_deg])
    hi = np.array([b for _, b in m.limits_deg])
    worst = 0.0
    for q in rng.uniform(lo, hi, size=(20, 6)):
        worst = max(worst, float(np.abs(k.forward(q) - chain_forward(chain, q)).max()))
    return worst


def test_the_catalogue_holds_at_least_25_models_each_compared_here():
    keys = set(catalogue.models())
    assert len(keys) >= 25
    assert keys == set(KROSHU) | set(EXPERIMENTAL), keys ^ (set(KROSHU) | set(EXPERIMENTAL))


@pytest.mark.parametrize("key", sorted(KROSHU))
def test_forward_kinematics_agrees_with_kroshus_description(key):
    src, chain = KROSHU[key]
    assert catalogue.models()[key].source.startswith("kroshu/kuka_robot_descriptions") or key == "KR150R3100_2"
    # rotation entries are unitless, positions mm: 0.1 mm over the reach bounds both
    assert _compare(key, chain) < 0.1, src


@pytest.mark.parametrize("key", sorted(EXPERIMENTAL))
def test_forward_kinematics_agrees_with_kuka_experimental(key):
    if not DESCRIPTIONS.is_dir():
        pytest.skip("../shared/robots/descriptions is not present")
    macro, name = EXPERIMENTAL[key]
    assert _compare(key, experimental_chain(macro, name)) < 0.1, macro


def test_limits_and_speeds_are_the_descriptions():
    """KR 150 R3100-2 by hand from kuka_experimental kr150r3100_2_macro.xacro: A1 +-185, A2 -140..-5,
    A3 -120..168, A4 +-350, A5 +-125, A6 +-350 deg; 105, 107, 114, 190, 180, 260 deg/s."""
    m = catalogue_robot("KR 150 R3100-2")
    assert [j.limit_deg for j in m.joints] == [(-185, 185), (-140, -5), (-120, 168), (-350, 350), (-125, 125),
                                               (-350, 350)]
    assert [round(j.max_speed_deg_s, 9) for j in m.joints] == [105, 107, 114, 190, 180, 260]
    assert m.provenance["max_speed_deg_s"].startswith("ros-industrial/kuka_experimental kuka_kr150_support")
    # the accelerations are KUKA's own published ones for the model (kroshu's joint-limits file)
    assert m.provenance["max_acc_deg_s2"].startswith(
        "kroshu/kuka_robot_descriptions kuka_quantec_support/config/kr150_r3100_2_joint_limits.yaml@062e13cb")
    # the zero pose by hand: flange at a1 + c2 + x3 + c4 ahead, c1 + z3 high
    np.testing.assert_allclose(Kinematics(m).forward([0] * 6)[:3, 3], [330 + 1350 + 1420 + 215, 0, 645 + 115],
                               atol=1e-9)


#: kroshu's joint-limits files (kroshu/kuka_robot_descriptions, the file and the commit read, transcribed
#: here by hand): max_velocity (rad/s) and max_acceleration (rad/s2) of joint_1..joint_6
JOINT_LIMITS = {
    "KR 210 R2700-2": ("kuka_quantec_support/config/kr210_r2700_2_joint_limits.yaml@00525ef0",
                       [2.0384, 1.9451, 1.95476, 3.12413, 3.00196, 3.83972],
                       [1.98271, 1.26288, 2.56508, 7.03857, 1.76397, 1.87268]),
    "KR 6 R900 sixx": ("kuka_agilus_support/config/kr6_r900_sixx_joint_limits.yaml@9825092e",
                       [6.283185, 5.23599, 6.283185, 6.64970, 6.77188, 10.73377],
                       [21.666156, 6.889457, 31.415926, 133.055688, 135.557707, 268.382564]),
    "KR 560 R3100-2": ("kuka_fortec_support/config/kr560_r3100_2_joint_limits.yaml@520102ac",
                       [1.5708, 1.3962, 1.3090, 1.5708, 1.5708, 2.2689],
                       [1.1500, 0.9308, 1.5038, 1.5816, 1.6486, 2.1579]),
}


@pytest.mark.parametrize("name", sorted(JOINT_LIMITS))
def test_accelerations_are_the_published_ones_where_published(name):
    """The model's axis accelerations are its joint-limits file's (the file's velocities are the
    model's axis speeds: it is that model's file), the jerk follows them by the machine-data rule."""
    path, vel, acc = JOINT_LIMITS[name]
    m = catalogue_robot(name)
    assert [j.max_speed_deg_s for j in m.joints] == pytest.approx([math.degrees(v) for v in vel], abs=0.01)
    assert [j.max_acc_deg_s2 for j in m.joints] == pytest.approx([math.degrees(a) for a in acc], rel=1e-12)
    assert m.provenance["max_acc_deg_s2"].startswith(f"kroshu/kuka_robot_descriptions {path} (max_acceleration")
    # $AXIS_JERK's rule: a / $DEF_FLT_PTP (the KR 6 R900's 96 ms: no machine data give another)
    assert [j.max_jerk_deg_s3 for j in m.joints] == pytest.approx([math.degrees(a) / 0.096 for a in acc], rel=1e-12)


def test_accelerations_are_derived_where_no_file_publishes_them():
    """kroshu publishes no joint-limits file of the KR 10 R1420: v / 0.2 s (robot/mada.py's rule), its
    speeds by hand from kuka_experimental kr10r1420_macro.xacro."""
    m = catalogue_robot("KR 10 R1420")
    assert catalogue.lookup("KR 10 R1420").accelerations_deg_s2 is None
    assert [j.max_acc_deg_s2 for j in m.joints] == pytest.approx([v / 0.2 for v in (220, 210, 270, 381, 311, 492)])
    assert m.provenance["max_acc_deg_s2"].startswith("derived: v_max / 0.2 s")


@pytest.mark.parametrize("spelling", ["KR 150 R3100-2", "KR150R3100_2", "#KR150R3100_2 C4 FLR", "kr150_r3100_2",
                                      "kr 150 r3100-2"])
def test_every_spelling_of_a_name_resolves(spelling):
    assert catalogue.lookup(spelling).key == "KR150R3100_2"


def test_an_unknown_model_is_refused_naming_close_ones():
    with pytest.raises(MachineDataError, match="no KUKA model of that name.*KR 150 R3100-2"):
        catalogue.lookup("KR 150 R3100-3")
    res = CliRunner().invoke(main, ["robot", "show", "KR 999 R1"])
    assert res.exit_code == 2 and "no such file or folder, nor a KUKA model" in res.output


def test_krl_robot_list_shows_every_model_with_its_source():
    res = CliRunner().invoke(main, ["robot", "list"])
    assert res.exit_code == 0, res.output
    out = res.output.splitlines()
    assert out[0].startswith(f"{len(catalogue.models())} KUKA robots")
    for m in catalogue.models().values():
        i = next(i for i, line in enumerate(out) if line.startswith(f"{m.name} "))
        acc = out[i + 4]
        if m.accelerations_deg_s2 is None:
            assert acc == "    accel  derived: v / 0.2 s (no joint-limits file publishes them)"
        else:
            assert acc.startswith("    accel  ") and acc.endswith(f"(worst-case ramp-up), source {m.acc_source}")
        assert out[i + 5].startswith(f"    source {m.source}")


def test_krl_robot_show_and_run_take_a_model_name(tmp_path):
    res = CliRunner().invoke(main, ["robot", "show", "KR210R2700_2"])
    assert res.exit_code == 0 and res.output.startswith("robot      KR 210 R2700-2\n"), res.output
    prog = tmp_path / "far.src"
    # 2.5 m out: a KR 210 R2700-2 reaches it, the KR 6 R900 of a run without --robot does not
    prog.write_text("DEF far()\n  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}\n"
                    "  PTP {X 2500, Y 0, Z 1200, A 0, B 60, C 0}\nEND\n", encoding="ascii")
    ok = CliRunner().invoke(main, ["run", str(prog), "--robot", "KR 210 R2700-2"])
    assert ok.exit_code == 0 and "robot      KR 210 R2700-2" in ok.output, ok.output
    bad = CliRunner().invoke(main, ["run", str(prog)])
    assert "not reachable" in bad.output


def test_machine_data_of_the_library_win_over_the_description(tmp_path, monkeypatch):
    """A robot/data machine-data file naming the model (issue 60's KR 3 R540, when it lands) is the
    model's robot: here a copy of the KR 16-2's with its $TRAFONAME renamed."""
    src = Path(catalogue.__file__).with_name("data") / "kr16_2_krc2.dat"
    dat = tmp_path / "kr3_r540.dat"
    dat.write_text(src.read_text(encoding="latin-1").replace('"#KR16_2 ZH16_2"', '"#KR3R540 C4SR FLR"'),
                   encoding="latin-1")
    monkeypatch.setattr(catalogue, "library_robots", lambda: {"kr3_r540": dat})
    m = catalogue_robot("KR 3 R540")
    assert m.source == str(dat) and m.trafoname == "#KR3R540 C4SR FLR"
    assert any("machine data win: robot/data/kr3_r540.dat" in line for line in catalogue.catalogue_lines())
