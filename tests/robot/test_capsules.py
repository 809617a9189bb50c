"""The link capsules' radii sized from the robot's kinematics (robot/capsules.py, issue 64).

The MuJoCo model the collision check uses carries them (read back from MuJoCo's own model), for the
KR 6 R900 and the KR C2 KR 16-2 of robot/data, the radii worked out here by hand from the
documented rule and each robot's dimensions. The rule's constants are the fit of the
public collision meshes (tools/capsule_fit.py, read in place from ../shared/robots/descriptions;
about 4 s, make nightly)."""

from __future__ import annotations

import importlib.util
import math

import mujoco
import pytest

from robot.capsules import C, P, capsule_radii
from robot.machine import load_machine
from robot.mada import load_robot
from robot.mjcf import build_mjcf
from tests.conftest import REPO_ROOT, SHARED


def _by_hand(reach_mm: float) -> dict[str, float]:
    """docs/robot.md: r = C * (reach / 1 m) ** 0.7627, C base 215.28, arm 152.97, wrist 85.38 mm."""
    s = (reach_mm / 1000.0) ** 0.7627
    return {"base": 215.28 * s, "arm": 152.97 * s, "wrist": 85.38 * s}


def _geom_radii(machine) -> dict[str, float]:
    model = mujoco.MjModel.from_xml_string(build_mjcf(machine))
    return {model.geom(g).name: float(model.geom_size[g][0]) * 1000.0 for g in range(model.ngeom)}


@pytest.mark.parametrize("robot", ["kr6_r900", "kr16_2_krc2"])
def test_the_model_s_capsules_follow_the_reach(robot):
    if robot == "kr6_r900":
        m = load_machine()
        # robot-model.md §4: $LENGTH_A 25, $LENGTH_B 455, $TX3P3 X 420, Z 35
        reach = 25 + 455 + math.hypot(420, 35)
    else:
        m = load_robot(robot)
        # robot/data/kr16_2_krc2.dat: $LENGTH_A 260, $LENGTH_B 680, $TX3P3 X 670, Z -35
        reach = 260 + 680 + math.hypot(670, 35)
    want = _by_hand(reach)
    got = _geom_radii(m)
    assert got["base_geom"] == pytest.approx(want["base"], abs=1e-3)
    for i in range(1, 7):
        assert got[f"link_{i}_geom"] == pytest.approx(want["arm" if i <= 3 else "wrist"], abs=1e-3), i
    assert capsule_radii(reach) == pytest.approx(want)


def test_a_reach_that_is_not_positive_is_refused():
    with pytest.raises(ValueError, match="a positive reach was expected"):
        capsule_radii(0.0)


@pytest.mark.slow     # make nightly: loads three descriptions and their meshes (about 4 s)
def test_the_constants_are_the_fit_of_the_public_meshes():
    if not (SHARED / "robots" / "descriptions").is_dir():
        pytest.skip("../shared/robots/descriptions is not present")
    spec = importlib.util.spec_from_file_location("capsule_fit", REPO_ROOT / "tools" / "capsule_fit.py")
    fit = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fit)
    rows = [fit.measure(fit.DESCRIPTIONS / p) for p in fit.DEFAULT]
    assert [sorted(r) for _, r in rows] == [["arm", "base", "wrist"], ["arm", "wrist"], ["arm", "base", "wrist"]]
    p, c = fit.fit(rows)
    assert p == pytest.approx(P, abs=5e-4)
    assert c == pytest.approx(C, rel=1e-3)
