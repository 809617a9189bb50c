"""The KR 3 R540 of robot/data/kr3_r540.dat (issue 60): the robot of the real KUKA Trace recordings.

Expected values come from outside the code under test:
- forward kinematics, axis ranges and speeds: the published URDF of the robot,
  ros-industrial/kuka_experimental kuka_kr3_support/urdf/kr3r540_macro.xacro (numbers copied below;
  its package.xml: the limits and speeds of KUKA's "Spez KR 3 AGILUS V3");
- the real robot itself: every sample of its KUKA Trace recordings gives its axes and the TCP of
  the recorded tool (PROG.TXT's TOOL), which the forward kinematics must reproduce.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.frames import frame_to_matrix
from robot.identified import apply_identified, read_identified
from robot.kinematics import Kinematics
from robot.kukatrace.recording import read_recording
from robot.mada import load_robot
from robot.madavalues import MachineDataError
from tests.robot.test_mada import urdf_forward

# kr3r540_macro.xacro: joint origins (m), no rotations, axes -Z, +Y, +Y, -X, +Y, -X; flange at link_6,
# tool0 rotated rpy (0, 90 deg, 0)
URDF_KR3 = (
    [((0, 0, 0.345), (0, 0, 0), (0, 0, -1)), ((0.020, 0, 0), (0, 0, 0), (0, 1, 0)),
     ((0.260, 0, 0), (0, 0, 0), (0, 1, 0)), ((0, 0, 0.020), (0, 0, 0), (-1, 0, 0)),
     ((0.260, 0, 0), (0, 0, 0), (0, 1, 0)), ((0.075, 0, 0), (0, 0, 0), (-1, 0, 0))],
    ((0, 0, 0), (0, math.pi / 2, 0)))
URDF_LIMITS = ((-170, 170), (-170, 50), (-110, 155), (-175, 175), (-120, 120), (-350, 350))
URDF_SPEEDS = (530, 529, 538, 600, 600, 800)


@pytest.fixture(scope="module")
def kr3():
    m = load_robot("kr3_r540")
    return m, Kinematics(m)


def test_ranges_speeds_and_name(kr3):
    m, _ = kr3
    assert m.trafoname == "#KR3R540 C4SR"        # PROG.TXT's ROBOT TYPE
    assert [j.limit_deg for j in m.joints] == [tuple(map(float, lim)) for lim in URDF_LIMITS]
    assert [j.max_speed_deg_s for j in m.joints] == pytest.approx(URDF_SPEEDS)
    assert tuple(m.home_deg) == (0.0, -110.0, 110.0, 0.0, 0.0, 0.0)


def test_forward_kinematics_is_the_urdfs(kr3):
    _, k = kr3
    rng = np.random.default_rng(3)
    lo = np.array([a for a, _ in URDF_LIMITS], dtype=float)
    hi = np.array([b for _, b in URDF_LIMITS], dtype=float)
    for q in [np.zeros(6), np.array([0, -110, 110, 0, 0, 0.0])] + list(rng.uniform(lo, hi, (40, 6))):
        assert np.allclose(k.forward(q), urdf_forward(URDF_KR3, q), atol=1e-6)
    assert k.family == "opw"
    q = np.array([30.0, -60, 80, 40, 50, 60])
    assert np.allclose(k.inverse(k.forward(q), *k.status_turn(q)), q, atol=1e-6)


def test_forward_kinematics_gives_the_recorded_tcp(kr3, real_traces):
    """On every recording of the real robot: the recorded axes through the model and the recorded
    tool give the recorded TCP (samples after the first motion's START: up to it, the TCP may still be
    in the previous program's tool)."""
    _, k = kr3
    errors = []
    for prog in sorted((real_traces / "Traces_Real").glob("*/*_PROG.TXT")):
        rec = read_recording(prog)
        m0 = rec.motions[0]
        tool = frame_to_matrix(*m0.tool)
        rows = np.flatnonzero(rec.t > m0.start + 1e-6)[::10]
        F = k.forward_many(rec.axes[rows]) @ tool
        errors += np.linalg.norm(F[:, :3, 3] - rec.tcp[rows, :3], axis=1).tolist()
    assert len(errors) > 900              # every 10th sample of 53 recordings
    assert max(errors) < 0.01          # mm: the recording's TCP is the model's to its float precision


def test_the_identified_parameters_are_applied(kr3, tmp_path):
    """robot/data/identified/kr3_r540.yaml (tools/identify_kr3.py) goes into the library robot, each
    value's provenance naming it; a broken file is refused naming the file and the key."""
    m, _ = kr3
    assert len(m.ptp_ramp_deg) == len(m.ptp_friction) == 6 and m.actual_filter_cycles >= 1
    assert m.dynamics is not None and len(m.dynamics["torque_nm"]) == 6
    assert all(len(m.actual_following[k]) == 6 for k in ("inertia_s2", "coulomb_deg", "viscous_s"))
    assert m.actual_dead_cycles == 3      # the measured axes leave rest 36 ms after the model (docs/robot.md)
    for key in ("max_acc_deg_s2", "ptp_ramp_deg", "ptp_friction", "dynamics", "actual_filter_cycles",
                "actual_following", "actual_dead_cycles"):
        assert "kr3_r540.yaml" in m.provenance[key]
    bad = tmp_path / "x.yaml"
    bad.write_text("ptp:\n  friction_per_s: [1, -2, 0, 0, 0, 0]\n", encoding="utf-8")
    with pytest.raises(MachineDataError, match=r"x\.yaml: ptp\.friction_per_s"):
        read_identified(bad)
    bad.write_text("ptp:\n  acc_deg_s2: [1, 2]\n", encoding="utf-8")
    with pytest.raises(MachineDataError, match="2 values for the 6 axes"):
        apply_identified(m, bad)
    follow = "actual:\n  following_error:\n    inertia_s2: [{}]\n    coulomb_deg: [0, 0]\n    viscous_s: [0, 0]\n" \
             "    coulomb_speed_deg_s: {}\n"
    bad.write_text(follow.format("0.00001, -0.00001", 2), encoding="utf-8")
    with pytest.raises(MachineDataError, match=r"x\.yaml: actual\.following_error\.inertia_s2"):
        read_identified(bad)
    bad.write_text(follow.format("0.00001, 0.00001", 0), encoding="utf-8")
    with pytest.raises(MachineDataError, match=r"following_error\.coulomb_speed_deg_s"):
        read_identified(bad)
    bad.write_text(follow.format("0.00001, 0.00001", 2), encoding="utf-8")
    with pytest.raises(MachineDataError, match="not 6 values per key"):
        apply_identified(m, bad)
    for dead in ("-1", "2.5", "true"):
        bad.write_text(f"actual:\n  dead_time_cycles: {dead}\n", encoding="utf-8")
        with pytest.raises(MachineDataError, match=r"x\.yaml: actual\.dead_time_cycles"):
            read_identified(bad)
