"""A seven-axis arm on both interpreters (issue 62, "the axis count from the model"): KUKA's LBR
iiwa 14 R820 as ROS-Industrial's kuka_experimental describes it (../shared/robots/descriptions,
read in place through ``--robot FILE.urdf``: robot/description.py), its joints J1..J7 carried in
E6AXIS as A1, A2, E1, A3..A6 (robot/axismap.py: the redundancy J3 as E1). A program moves it with
PTP to an E6AXIS and LIN, LIN_REL to Cartesian points, on the tree interpreter and the VM: the
traces are identical, E1 stays where the PTP put it through the LINs (robot/kinematics/
redundant.py holds it), ``$POS_ACT.E1`` carries it, and every IPO pose of the LINs, carried
through the description's own chain by yourdfpy (not the project's kinematics), lies on the
programmed straight line."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yourdfpy
from scipy.spatial.transform import Rotation

from interp.run import make_runtime, run_spec, RunSinks
from robot.mada import load_robot
from robot.trace import TraceWriter
from tests.interp.helpers import Run, write

IIWA = (Path(__file__).resolve().parents[2].parent / "shared" / "robots" / "descriptions" / "kuka_experimental"
        / "kuka_lbr_iiwa_support" / "urdf" / "lbr_iiwa_14_r820.urdf")

SRC = """
DEF iiwa()
  PTP {A1 0, A2 30, A3 -60, A4 0, A5 45, A6 0, E1 15}
  e1_ptp = $AXIS_ACT.E1
  p0 = $POS_ACT
  LIN {X 585, Y 121, Z 642, A -174.5, B 45.4, C 169.4}
  e1_lin = $AXIS_ACT.E1
  p1 = $POS_ACT
  LIN_REL {X 50, Z -80}
  p2 = $POS_ACT
  num_ax = $NUM_AX
  e1_max = $SOFTP_END[7]
END
"""
DAT = """
DEFDAT iiwa
  REAL e1_ptp, e1_lin, e1_max
  INT num_ax
  DECL E6POS p0, p1, p2
ENDDAT
"""
#: the PTP's E6AXIS as the joints J1..J7 (A1, A2, E1, A3, A4, A5, A6)
PTP_JOINTS = [0.0, 30.0, 15.0, -60.0, 0.0, 45.0, 0.0]


@pytest.fixture(scope="module")
def iiwa():
    if not IIWA.exists():
        pytest.skip("../shared/robots/descriptions (kuka_lbr_iiwa_support) is not present")
    return load_robot(IIWA)


@pytest.fixture(scope="module")
def description_flange():
    """The flange (tool0 in base_link, mm) of joints J1..J7 (deg) by the description's own chain."""
    urdf = yourdfpy.URDF.load(str(IIWA), build_scene_graph=False, load_meshes=False)
    chain = [urdf.joint_map[f"joint_a{i}"] for i in range(1, 8)]
    tool = np.asarray(urdf.joint_map["joint_a7-tool0"].origin, dtype=float)

    def flange(q_deg) -> np.ndarray:
        T = np.eye(4)
        for j, a in zip(chain, q_deg):
            R = np.eye(4)
            R[:3, :3] = Rotation.from_rotvec(np.asarray(j.axis, dtype=float) * np.radians(a)).as_matrix()
            T = T @ np.asarray(j.origin, dtype=float) @ R
        T = T @ tool
        T[:3, 3] *= 1000.0
        return T
    return flange


def _run(prog, machine, interp):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, max_sim_time=60.0, mujoco=False, check=False, interp=interp,
                         robot=machine), RunSinks(trace=tw))
    return Run(rt, rt.run(), tw)


def test_a_seven_axis_arm_runs_ptp_and_lin_on_tree_and_vm(tmp_path, iiwa, description_flange):
    prog = write(tmp_path, "iiwa.src", SRC)
    write(tmp_path, "iiwa.dat", DAT)
    runs = {i: _run(prog, iiwa, i) for i in ("tree", "vm")}
    for run in runs.values():
        assert run.result.reason == "completed", run.result
    tree, vm = runs["tree"], runs["vm"]
    poses = [(e["t"], e["axes"], e["tcp"]) for e in tree.events if e["kind"] == "pose"]
    assert poses == [(e["t"], e["axes"], e["tcp"]) for e in vm.events if e["kind"] == "pose"]
    assert [e for e in tree.events if e["kind"] == "motion"] == [e for e in vm.events if e["kind"] == "motion"]
    v = lambda name: tree.var("iiwa", name)      # noqa: E731
    assert v("num_ax") == 7
    assert v("e1_max") == pytest.approx(math.degrees(2.9668), abs=1e-9)   # J3's upper limit (the URDF's rad)
    # the PTP put J3 (E1) at 15; both LINs kept it there
    assert (v("e1_ptp"), v("e1_lin")) == (pytest.approx(15.0, abs=1e-9), pytest.approx(15.0, abs=1e-9))
    for p in ("p0", "p1", "p2"):
        assert v(p).f["E1"] == pytest.approx(15.0, abs=1e-9)
    motions = [e for e in tree.events if e["kind"] == "motion" and e["phase"] == "end"]
    ends = [e["t"] for e in motions]            # the END signal: the robot stands at the point
    assert len(ends) == 3

    def at(t):
        return next(q for tt, q, _ in poses if tt >= t - 1e-9)
    # the PTP's end: the programmed joints; its flange by the description's chain
    assert at(ends[0]) == pytest.approx(PTP_JOINTS, abs=1e-6)
    start = description_flange(PTP_JOINTS)[:3, 3]
    assert [v("p0").f[k] for k in "XYZ"] == pytest.approx(start.tolist(), abs=0.01)
    # the LINs: every IPO pose on the straight line to the programmed point, J3 held
    goal1 = np.array([585.0, 121.0, 642.0])
    goal2 = goal1 + np.array([50.0, 0.0, -80.0])
    for (t0, t1), (a, b) in zip(((ends[0], ends[1]), (ends[1], ends[2])), ((start, goal1), (goal1, goal2))):
        seg = [q for t, q, _ in poses if t0 - 1e-9 <= t <= t1 + 1e-9]
        assert len(seg) > 10
        d = (b - a) / np.linalg.norm(b - a)
        for q in seg:
            assert q[2] == pytest.approx(15.0, abs=1e-9)
            p = description_flange(q)[:3, 3]
            off = (p - a) - d * float((p - a) @ d)
            assert float(np.linalg.norm(off)) < 0.01
        assert description_flange(seg[-1])[:3, 3] == pytest.approx(b.tolist(), abs=0.01)
    # the LIN's orientation: the programmed A, B, C reached
    assert [v("p1").f[k] for k in "ABC"] == pytest.approx([-174.5, 45.4, 169.4], abs=1e-6)
