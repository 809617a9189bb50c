"""Every catalogue robot's dynamic model and the source of each value (issue 73, item 3).

The expected values are typed here from the descriptions themselves, not read through the
project's catalogue:

* KR 150 R3100-2 (no recordings): kroshu/kuka_robot_descriptions
  kuka_quantec_support/urdf/kr150_r3100_2_macro.xacro at e2f6424383e5: link_1..6 ``<mass value>``
  363.07, 250.56, 199.93, 42.411794929, 16.991732133, 6.6 kg; joint_1..6 ``effort`` 7290, 8910,
  7538.74623365738, 2431.25052899853, 1460.56085236985, 892.539 N m. The gravity torque on A2 is
  computed by hand from the file's inertial origins and joint origins (a plain product of the
  URDF's rpy matrices written out below), not through robot/described_dynamics.py.
* KR 3 R540 (recordings): its link masses are the collision meshes' (../shared/robots/descriptions,
  read here with plain numpy and scipy's ConvexHull) at one density per group, scaled to the
  recorded torques: link 2 by one factor, links 3..6 by another (robot/kukatrace/identify.py).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from robot.catalogue import catalogue_lines, models
from robot.dynamics import ArmDynamics
from robot.mada import catalogue_robot
from robot.planner import arm_dynamics
from robot.show import show_lines

KR150_SOURCE = "kuka_quantec_support/urdf/kr150_r3100_2_macro.xacro@e2f64243"
KR150_MASS = (363.07, 250.56, 199.93, 42.411794929, 16.991732133, 6.6)
KR150_EFFORT = (7290.0, 8910.0, 7538.74623365738, 2431.25052899853, 1460.56085236985, 892.539)
#: the file's joint_1..6 origins (xyz m, rpy rad) and link_2..6 inertial origins (xyz m)
KR150_JOINTS = (((0.0, 0.0, 0.3056), (math.pi, 0.0, 0.0)), ((0.33, 0.072, -0.3394), (math.pi / 2, 0.0, 0.0)),
                ((1.35, 0.0, -0.103), (0.0, 0.0, 0.0)), ((1.028, -0.115, 0.175), (math.pi / 2, 0.0, -math.pi / 2)),
                ((0.0, 0.096, -0.392), (0.0, math.pi / 2, math.pi / 2)),
                ((0.1665, 0.0, -0.096), (math.pi / 2, 0.0, -math.pi / 2)))
KR150_COM = ((0.0287871760266615, 0.011875249400942, -0.23402828104773202),
             (0.577871168582376, -0.0013846982758620701, -0.125571679438059),
             (0.26233216625819, -0.07663387185514929, 0.137675034261992),
             (-7.5764465140740704e-06, 0.0192023882938968, -0.197888748752496),
             (0.062235569792816796, 0.00030314811620972, -0.0657532427101687), (0.0, 0.0, -0.0065))
KR3_MESHES = Path(__file__).resolve().parents[3] / "shared" / "robots" / "descriptions" / "kuka_experimental" / \
    "kuka_kr3_support" / "meshes" / "kr3r540" / "collision"


def _rows(lines: list[str]) -> dict[str, str]:
    return {ln.split()[0]: ln for ln in lines if ln.startswith("           A")}


def _rpy(r: float, p: float, y: float) -> np.ndarray:
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def test_kr150_show_lists_the_published_masses_and_torques_with_their_source():
    m = catalogue_robot("KR150R3100_2")
    lines = show_lines(m)
    rows = _rows(lines)
    for i, key in enumerate(("A1", "A2", "A3", "A4", "A5", "A6")):
        assert f"{KR150_MASS[i]:.3f}" in rows[key]
        assert f"{KR150_EFFORT[i]:.2f}" in rows[key]
        assert "published" in rows[key] and f"joint_{i + 1} effort" in rows[key]
    assert any(ln.startswith("dynamics ") and KR150_SOURCE in ln for ln in lines)
    text = "\n".join(lines)
    assert "none published: 0" in text                              # rotor inertias
    assert "rated payload 150 kg" in text and "payload in the model's name" in text


def _frames(joints) -> list:
    """Each joint's frame in the base (4×4), chaining the file's own joint origins (xyz, rpy)."""
    T = np.eye(4)
    frames = []
    for xyz, rpy in joints:
        step = np.eye(4)
        step[:3, :3] = _rpy(*rpy)
        step[:3, 3] = xyz
        T = T @ step
        frames.append(T)
    return frames


def test_kr150_gravity_on_a2_is_the_descriptions_by_hand():
    """At A = 0 (KUKA's zero: the upper arm and the forearm stretched forward, horizontal) the
    torque on A2 is the sum of m·g times each link's centre of mass' reach in front of the A2
    axis (links 2..6, their centres of mass put in the base by the file's own joint origins)."""
    frames = _frames(KR150_JOINTS)
    a2 = frames[1][:3, 3]
    assert a2[0] == pytest.approx(0.33) and a2[2] == pytest.approx(0.645)     # $LENGTH_A, $TIRORO.Z
    moment = 0.0
    for i in range(1, 6):
        p = frames[i][:3, :3] @ np.asarray(KR150_COM[i]) + frames[i][:3, 3]
        moment += KR150_MASS[i] * 9.81 * (p[0] - a2[0])
    m = catalogue_robot("KR150R3100_2")
    dyn = ArmDynamics(m, m.dynamics)
    dyn.set_load((0.0,) * 10, None)
    tau = dyn.gravity(np.zeros(6))
    assert abs(tau[1]) == pytest.approx(abs(moment), rel=1e-6)
    assert 5000 < abs(moment) < 8000       # some 600 kg m of arm in front of A2
    # with the rated 150 kg at the flange (3.3 m out: $LENGTH_A 330 + $LENGTH_B 1350 + $TX3P3.X
    # 1420 + $TFLWP.Z 215 mm) A2's gravity torque exceeds its published effort of 8910 N m: the
    # description cannot hold its own rated payload (it has no counterbalancing system), so the
    # planner does not use it
    held = abs(moment) + 150.0 * 9.81 * (0.330 + 1.350 + 1.420 + 0.215 - a2[0])
    assert held > KR150_EFFORT[1]
    assert m.dynamics["plan"] is False and arm_dynamics(m) is None
    assert any("not used for planning" in ln and "A2" in ln for ln in show_lines(m))


def test_a_heavier_load_slows_the_kr10_where_its_torque_binds():
    """The KR 10 R1100-2 (its description holds its rated payload: the planner uses it) with its
    rated 10 kg against no load: A2's starting acceleration from the stretched arm the model allows
    is less with the load."""
    m = catalogue_robot("KR10R1100_2")
    assert m.dynamics.get("plan", True) is True
    dyn = arm_dynamics(m)
    q0 = np.array([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])
    q1 = q0 + np.array([0.0, 30.0, 0.0, 0.0, 0.0, 0.0])
    got = {}
    for kg in (0.0, 10.0):
        dyn.set_load((kg, 0.0, 0.0, 100.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0), None)
        a_acc, _ = dyn.ptp_bounds(q0, q1, np.ones(6))
        got[kg] = a_acc[1]
    assert got[10.0] < got[0.0]


def _stl_volume(path: Path) -> float:
    raw = path.read_bytes()
    n = int.from_bytes(raw[80:84], "little")
    if 84 + 50 * n == len(raw):              # binary STL
        tri = np.frombuffer(raw[84:], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), count=n)["v"]
    else:                                    # ASCII STL
        pts = [list(map(float, ln.split()[1:4])) for ln in raw.decode("latin-1").splitlines() if ln.strip().startswith("vertex")]
        tri = np.asarray(pts).reshape(-1, 3, 3)
    tri = tri.astype(float)
    closed = float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)
    hull = ConvexHull(tri.reshape(-1, 3)).volume
    return closed, hull


@pytest.mark.skipif(not KR3_MESHES.is_dir(), reason="../shared/robots is not beside the checkout")
def test_kr3_show_lists_the_identified_model_scaled_from_the_meshes():
    m = catalogue_robot("KR3R540")
    lines = show_lines(m)
    assert any(ln.startswith("dynamics ") and "identified: kr3_r540.yaml" in ln for ln in lines)
    rows = _rows(lines)
    d = m.dynamics
    ratios = []
    for i, key in enumerate(("A1", "A2", "A3", "A4", "A5", "A6")):
        assert f"{d['link_mass_kg'][i]:.3f}" in rows[key]
        closed, hull = _stl_volume(KR3_MESHES / f"link_{i + 1}.stl")
        # the mesh's own volume where it is closed, its convex hull's where not (within 2 %)
        vol = min((closed, hull), key=lambda v: abs(d["link_mass_kg"][i] / (1000.0 * v) - 1.0 if v > 0 else 9e9))
        ratios.append(d["link_mass_kg"][i] / (1000.0 * vol))
    # links 3..6 share one scale (the recorded A3 torques), link 2 has its own
    assert max(ratios[2:]) == pytest.approx(min(ratios[2:]), rel=2e-3)
    assert ratios[1] != pytest.approx(ratios[2], rel=1e-2)


def test_a_model_without_published_inertials_says_so():
    lines = show_lines(catalogue_robot("KR10R1420"))
    got = [ln for ln in lines if ln.startswith("dynamics ")]
    assert len(got) == 1 and "none" in got[0] and "inertials" in got[0]
    assert catalogue_robot("KR10R1420").dynamics is None


#: kroshu/kuka_robot_descriptions kuka_quantec_support/urdf/kr120_r2700_2_macro.xacro at 4d5237ab (the
#: catalogue's source of the KR 120 R2700-2): joint_1..6 origins (xyz m, rpy rad), link_1..6 masses and
#: inertial origins (xyz m), joint efforts (N m), typed from the file
KR120_JOINTS = (((0.0, 0.0, 0.3056), (-3.1416, 0.0, 0.0)), ((0.33, 0.072, -0.3394), (1.5708, 0.0, 0.0)),
                ((1.15, 0.0, -0.103), (0.0, 0.0, 0.0)), ((0.828, -0.115, 0.175), (1.5708, 0.0, -1.5708)),
                ((0.0, 0.096, -0.392), (0.0, 1.5708, 1.5708)), ((0.1665, 0.0, -0.096), (1.5708, 0.0, -1.5708)))
KR120_MASS = (363.07, 232.06, 181.83, 42.4118, 16.9917, 6.6)
KR120_COM = ((0.0288, 0.0119, -0.234), (0.4869, -0.0019, -0.1176), (0.1908, -0.0745, 0.1325),
             (0.0, 0.0192, -0.1979), (0.0622, 0.0003, -0.0658), (0.0, 0.0, -0.0065))
KR120_EFFORT = (7290.0, 8910.0, 7759.4539, 2462.3921, 1491.6988, 908.4312)


def test_kr120_gravity_on_a2_is_the_descriptions_by_hand_and_it_holds_its_payload():
    """The KR 120 R2700-2 (the robot of a corpus backup's $TRAFONAME): at A = 0 the torque on A2 is
    the sum of m·g times each link's reach in front of the A2 axis (the file's own chain, by hand);
    with the rated 120 kg at the flange (2.915 m out: $LENGTH_A 330 + $LENGTH_B 1150 + $TX3P3.X
    1220 + $TFLWP.Z 215 mm) it stays below the published 8910 N m, so the planner uses the model,
    and `krl robot show` lists every value with its source."""
    frames = _frames(KR120_JOINTS)
    a2 = frames[1][:3, 3]
    moment = sum(KR120_MASS[i] * 9.81 * ((frames[i][:3, :3] @ np.asarray(KR120_COM[i]) + frames[i][:3, 3])[0] - a2[0])
                 for i in range(1, 6))
    m = catalogue_robot("KR120R2700_2")
    dyn = ArmDynamics(m, m.dynamics)
    dyn.set_load((0.0,) * 10, None)
    assert abs(dyn.gravity(np.zeros(6))[1]) == pytest.approx(abs(moment), rel=2e-4)
    held = abs(moment) + 120.0 * 9.81 * (0.330 + 1.150 + 1.220 + 0.215 - a2[0])
    assert held < KR120_EFFORT[1]
    assert m.dynamics.get("plan", True) is True and arm_dynamics(m) is not None
    rows = _rows(show_lines(m))
    for i, key in enumerate(("A1", "A2", "A3", "A4", "A5", "A6")):
        assert f"{KR120_MASS[i]:.3f}" in rows[key] and f"{KR120_EFFORT[i]:.2f}" in rows[key]
        assert f"published: kroshu/kuka_robot_descriptions kuka_quantec_support/urdf/kr120_r2700_2_macro.xacro@4d5237ab" in rows[key]


def test_every_catalogue_model_has_its_dynamic_model_or_says_why_not():
    """Issue 73 item 3: each model of `krl robot list` has a dynamics line: identified (the KR 3
    R540), described (a description's inertials), or none with the reason; a model without one
    says the same in `krl robot show`."""
    lines = [ln.strip() for ln in catalogue_lines() if ln.strip().startswith("dynamics ")]
    assert len(lines) == len(models())
    kinds = [ln.split()[1] for ln in lines]
    assert kinds.count("identified") == 1 and kinds.count("described:") == 3
    assert all(k in ("identified", "described:", "none:") for k in kinds)
    for key in models():
        m = catalogue_robot(key)
        if m.dynamics is None:
            why = m.provenance["dynamics"]
            assert why.startswith("none: ") and ("inertials" in why or "meshes" in why), key
        else:
            assert m.dynamics.get("sources") or m.provenance.get("dynamics", "").startswith("identified"), key
    kr6 = catalogue_robot("KR6R900SIXX").provenance["dynamics"]
    assert "link_2 and link_4 only" in kr6
