"""`krl robot show` and `krl robot export` (issue 22): the exported URDF and MJCF describe the
same robot as the model (forward kinematics compared), and show names parameters' sources."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest
from click.testing import CliRunner

from app import main
from robot.kinematics import Kinematics
from robot.mada import load_robot
from tests.robot.test_mada import urdf_forward

BACKUP = "khrzysio__KRC4_test"          # KR 120 R2700 extra HA


def test_show_prints_name_parameters_limits_reach(shared_corpus):
    res = CliRunner().invoke(main, ["robot", "show", str(shared_corpus / BACKUP)])
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert lines[0] == "robot      KR120R2700 EXTRA HA C4 FLR"
    # reach by hand: 350 + 1150 + |(1200, -41)|
    assert f"reach      {350 + 1150 + math.hypot(1200, 41):.1f} mm" in res.output
    assert "           A2     -140.0 ..    -5.0" in res.output
    mada = shared_corpus / BACKUP / "R1" / "Mada" / "$machine.dat"
    assert f"  {'$LENGTH_A':<22} {mada}:522" in lines
    assert any(line.startswith("  max_acc_deg_s2         derived: ") for line in lines)


def test_show_bad_path_is_a_clear_error(tmp_path):
    res = CliRunner().invoke(main, ["robot", "show", str(tmp_path)])
    assert res.exit_code == 2
    assert "no R1/Mada/$machine.dat" in res.output


def test_export_urdf_has_the_model_kinematics(tmp_path, shared_corpus):
    out = tmp_path / "r.urdf"
    res = CliRunner().invoke(main, ["robot", "export", str(shared_corpus / BACKUP), "--format", "urdf",
                                    "-o", str(out)])
    assert res.exit_code == 0, res.output
    root = ET.parse(out).getroot()
    joints = []
    for j in root.iter("joint"):
        if j.get("type") != "revolute":
            continue
        o = j.find("origin")
        joints.append((tuple(float(v) for v in o.get("xyz").split()),
                       tuple(float(v) for v in o.get("rpy").split()),
                       tuple(float(v) for v in j.find("axis").get("xyz").split())))
    tool = [j for j in root.iter("joint") if j.get("name") == "link_6-tool0"][0].find("origin")
    urdf = (joints, (tuple(float(v) for v in tool.get("xyz").split()),
                     tuple(float(v) for v in tool.get("rpy").split())))
    k = Kinematics(load_robot(shared_corpus / BACKUP))
    for q in np.random.default_rng(5).uniform(-120, 120, size=(10, 6)):
        np.testing.assert_allclose(urdf_forward(urdf, q), k.forward(q), atol=1e-6)


def test_export_mjcf_site_is_the_flange(tmp_path, shared_corpus):
    mujoco = pytest.importorskip("mujoco")
    out = tmp_path / "r.xml"
    res = CliRunner().invoke(main, ["robot", "export", str(shared_corpus / BACKUP), "--format", "mjcf",
                                    "-o", str(out)])
    assert res.exit_code == 0, res.output
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    k = Kinematics(load_robot(shared_corpus / BACKUP))
    q = np.array([20.0, -70.0, 60.0, 30.0, 40.0, -50.0])
    data.qpos[:6] = np.radians(q)
    mujoco.mj_kinematics(model, data)
    np.testing.assert_allclose(data.site("tool0").xpos * 1000.0, k.forward(q)[:3, 3], atol=1e-6)


def test_show_a_robot_of_the_library_by_name():
    res = CliRunner().invoke(main, ["robot", "show", "kr180_r3200_pa"])
    assert res.exit_code == 0, res.output
    assert res.output.splitlines()[0] == "robot      KR180R3200 PA C4 FLR"
    assert "palletizer $DEF_A4FIX=TRUE $DEF_A5LINK=TRUE" in res.output
    # reach to the A5 point by hand: 350 + 1350 + 1220
    assert "reach      2920.0 mm" in res.output
    res = CliRunner().invoke(main, ["robot", "show", "kr999"])
    assert res.exit_code == 2 and "nor a robot of the library (" in res.output
    assert "kr180_r3200_pa, " in res.output and "kr6_r900)" in res.output


@pytest.mark.parametrize("name", ["kr16_2_krc2", "kr180_r3200_pa", "kr180_r3200_pa5", "kr16_2_kl1500",
                                  "kr16_2_turntable", "kr16_2_positioner"])
def test_export_works_for_every_family(tmp_path, name):
    """`krl robot export` (the pendant renders the backup's robot from it) for every family of
    robot/data: the URDF is one tree and the MJCF loads in MuJoCo with a joint per axis."""
    m = load_robot(name)
    for fmt in ("urdf", "mjcf"):
        out = tmp_path / f"{name}.{fmt}"
        res = CliRunner().invoke(main, ["robot", "export", name, "--format", fmt, "-o", str(out)])
        assert res.exit_code == 0, res.output
        if fmt == "urdf":
            root = ET.parse(out).getroot()
            children = {j.find("child").get("link") for j in root.findall("joint")}
            assert len({ln.get("name") for ln in root.findall("link")} - children) == 1
        else:
            model = mujoco.MjModel.from_xml_path(str(out))
            assert model.njnt == 6 + len(m.external_axes)
