"""The dynamic model of a catalogue robot from its public description (issue 73, item 3).

robot/dynamics.py ``ArmDynamics`` takes a robot's ``dynamics`` mapping (robot/identified.py names
its keys). For the KR 3 R540 it is identified from real recordings (robot/data/identified/). For a
model of the catalogue (robot/data/catalogue.yaml) whose description publishes link inertials
(kroshu/kuka_robot_descriptions, KUKA's own ROS 2 descriptions: ``<inertial>`` with mass, centre of
mass and principal inertias, and each joint's ``effort`` limit), the entry's ``dynamics`` holds
them as the description gives them (its link frames, its joint origins), and
:func:`description_dynamics` turns them into the mapping in the joint chain's link frames
(robot/kinematics/joints.py): both chains are evaluated at A = 0, where the description's
``base_link`` is ``$ROBROOT`` ("base and tool0 are defined to be identical to the frames on the
controller", kroshu's README) and its joint angles are KUKA's axis angles.

What each value is, and its source (``sources``, printed by ``krl robot show``):

* link masses, centres of mass, inertia tensors: the description's ``<inertial>`` (cited);
* torque limits: the description's joint ``effort`` (published, cited);
* rotor inertias: none published: 0 (the motors' inertias are not in the description);
* rated payload (the load of ``$LOAD.M < 0``): the payload in the model's name (KR 150: 150 kg);
* capped axes: every axis; the published axis accelerations (kroshu's joint-limits files, "the
  worst-case ramp-up", robot/data/catalogue.yaml) still cap each axis, so the model only slows a
  PTP whose load or pose needs more torque than the drive has: without the rotor inertias the
  model alone would accelerate faster than the real arm.

A described model whose drives cannot hold the rated payload against gravity somewhere in the
workspace (:func:`unheld_axes`: the KR 150 R3100-2's A2, whose description has no counterbalancing
system) is shown but not used for planning (``plan: False``; robot/planner.py ``arm_dynamics``).

A model whose descriptions hold no inertials (kuka_experimental's xacros: none, or placeholders of
2 kg and 0.01 kg m² per link) has no dynamic model: its PTPs are planned with the axis
accelerations alone, and ``krl robot show`` says so (robot/catalogue.py ``no_model_reason``).

Units: the description's m, rad, kg, kg m², N m; the mapping's mm (centres of mass) and kg m².
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from .dynamics import ArmDynamics
from .kinematics.joints import JointChain

#: the poses of the held-payload check (:func:`unheld_axes`): this many A2 and A3 angles across
#: their software limits (the other axes at 0)
HOLD_GRID = 9


def _frame(xyz: Any, rpy: Any) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()       # URDF rpy: Rz(y) Ry(p) Rx(r)
    T[:3, 3] = xyz
    return T


def description_frames(joint_origins: Any) -> list[np.ndarray]:
    """The description's link_1..n frames (4x4, m) in its ``base_link`` at joint angles 0:
    the product of the joint origins (``[[x, y, z], [r, p, y]]`` each, m and rad)."""
    T = np.eye(4)
    out = []
    for xyz, rpy in joint_origins:
        T = T @ _frame(xyz, rpy)
        out.append(T)
    return out


def chain_frames(machine: Any) -> list[np.ndarray]:
    """The joint chain's link frames (4x4, m) in ``$ROBROOT`` at A = 0 (robot/dynamics.py's
    bodies ``link_1..n``)."""
    c = JointChain(machine)
    T = np.eye(4)
    out = []
    for i in range(c.n):
        T = T @ _frame(c.origins[i] / 1000.0, (0.0, 0.0, 0.0))
        T[:3, :3] = T[:3, :3] @ c.R_origin[i]
        out.append(T.copy())
    return out


def rated_payload_kg(model_key: str) -> float:
    """The rated payload (kg) in a model's name: ``KR150R3100_2`` 150, ``KR6R900SIXX`` 6."""
    m = re.match(r"KR(\d+)", model_key)
    return float(m.group(1)) if m else 0.0


def description_dynamics(machine: Any, entry: dict[str, Any], model_key: str, source: str) -> dict[str, Any]:
    """The ``dynamics`` mapping (robot/dynamics.py ``ArmDynamics``) of `machine` from a catalogue
    entry's ``dynamics`` (`entry`: ``joint_origins``, ``links``, ``effort_nm``; `source` the cited
    description), with ``sources`` saying where each value comes from. Raises ValueError when the
    entry's axis count is not the robot's."""
    n = len(machine.joints)
    links, joints, effort = entry["links"], entry["joint_origins"], entry["effort_nm"]
    if not (len(links) == len(joints) == len(effort) == n):
        raise ValueError(f"{source}: {len(links)} links, {len(joints)} joints, {len(effort)} efforts for {n} axes")
    theirs, ours = description_frames(joints), chain_frames(machine)
    mass, com, inertia = [], [], []
    for (m, xyz, rpy, principal), T, C in zip(links, theirs, ours):
        p_w = T[:3, :3] @ np.asarray(xyz, dtype=float) + T[:3, 3]
        R_w = T[:3, :3] @ Rotation.from_euler("xyz", rpy).as_matrix()
        I_w = R_w @ np.diag(np.asarray(principal, dtype=float)) @ R_w.T
        Rc = C[:3, :3]
        I_c = Rc.T @ I_w @ Rc
        mass.append(float(m))
        com.append([float(v) * 1000.0 for v in Rc.T @ (p_w - C[:3, 3])])
        inertia.append([float(I_c[0, 0]), float(I_c[1, 1]), float(I_c[2, 2]),
                        float(I_c[0, 1]), float(I_c[0, 2]), float(I_c[1, 2])])
    rated = rated_payload_kg(model_key)
    out = {
        "link_mass_kg": mass, "link_com_mm": com, "link_inertia_kg_m2": inertia,
        "rotor_inertia_kg_m2": [0.0] * n, "torque_nm": [float(t) for t in effort],
        "rated_payload_kg": rated, "capped_axes": list(range(1, n + 1)),
        "sources": {
            "links": f"published: {source} (<inertial> of link_1..{n}: mass, centre of mass, principal inertias)",
            "torque": [f"published: {source} (joint_{i + 1} effort)" for i in range(n)],
            "rotor": "none published: 0 (the description holds no motor inertias)",
            "rated": f"derived: the payload in the model's name ({model_key}: {rated:g} kg)",
            "capped": "every axis: the published axis accelerations (worst-case ramp-up) cap what the torques allow",
        },
    }
    unheld = unheld_axes(machine, out)
    if unheld:
        out["plan"] = False
        out["sources"]["plan"] = (
            "not used for planning: the drives cannot hold the rated payload against gravity at some poses ("
            + ", ".join(f"A{i + 1} {g:.0f} > {t:.0f} N m" for i, g, t in unheld)
            + "): the description lacks what holds the arm (a counterbalancing system of A2?); PTPs are planned "
              "with the axis accelerations alone")
    else:
        out["sources"]["plan"] = "used for planning: the drives hold the rated payload at every pose checked"
    return out


def unheld_axes(machine: Any, dyn: dict[str, Any]) -> list[tuple[int, float, float]]:
    """The axes (index, largest gravity torque N m, torque limit N m) whose gravity torque with the
    rated payload at the flange exceeds their torque limit somewhere on a grid of
    :data:`HOLD_GRID` x :data:`HOLD_GRID` A2/A3 poses within the software limits: a model whose
    drives cannot hold the arm misses what holds it (a real robot holds its rated payload at every
    pose of its workspace). [] when every axis holds it."""
    arm = ArmDynamics(machine, {**dyn, "torque_nm": [None] * len(machine.joints)})
    arm.set_load(None, None)
    worst = np.zeros(arm.n)
    q = np.zeros(arm.n)
    j2, j3 = machine.joints[1], machine.joints[2]
    for a2 in np.linspace(j2.softn_end, j2.softp_end, HOLD_GRID):
        for a3 in np.linspace(j3.softn_end, j3.softp_end, HOLD_GRID):
            q[1], q[2] = a2, a3
            worst = np.maximum(worst, np.abs(arm.gravity(q)))
    tau = dyn["torque_nm"]
    return [(i, float(worst[i]), float(tau[i])) for i in range(arm.n) if tau[i] is not None and worst[i] > float(tau[i])]


__all__ = ["HOLD_GRID", "chain_frames", "description_dynamics", "description_frames",
           "rated_payload_kg", "unheld_axes"]
