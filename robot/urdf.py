"""URDF of a robot model (``krl robot export --format urdf``), for other tools (ROS, viewers).

The URDF has the joint layout of :class:`~robot.machine.MachineData` (robot-model.md §2-§3):
links ``base_link``, ``link_1`` .. ``link_6``, joints ``joint_a1`` .. ``joint_a6`` with
``q = radians(A_i)`` (KUKA's directions are in the joint axes), the fixed frames ``base``
(= ``$ROBROOT``) and ``tool0`` (= KUKA's flange frame), as the ROS-Industrial KUKA URDFs do.
No meshes and no inertias (the machine data hold none). Lengths in m, angles in rad.

With external kinematics (robot/external.py) the root is a link ``world`` (``$WORLD``): a ROBROOT
kinematic (#ERSYS, a track) carries ``base_link`` through its joints ``joint_e<n>`` (prismatic
for a linear axis, revolute for a rotary one, in E's units: m or rad), a BASE kinematic
(#EASYS.., a turntable) is a branch ending in the link ``et<n>_flange``.
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET

import numpy as np
from scipy.spatial.transform import Rotation

from .frames import frame_to_matrix
from .machine import MachineData


def _v(values) -> str:
    return " ".join(repr(round(float(x), 12) + 0.0) for x in values)


def build_urdf(machine: MachineData) -> str:
    """URDF XML (str) of ``machine``; its name and source are in a comment-free ``name``
    attribute and the robot's links/joints only (no text of the machine data elsewhere)."""
    robot = ET.Element("robot", name=machine.name)
    for name in ("base_link", *(j.child for j in machine.joints), "base", "tool0"):
        ET.SubElement(robot, "link", name=name)
    for j in machine.joints:
        linear = j.kind == "linear"        # a SCARA's A3: prismatic, mm -> m
        si = (lambda v: v / 1000.0) if linear else math.radians
        el = ET.SubElement(robot, "joint", name=j.name, type="prismatic" if linear else "revolute")
        ET.SubElement(el, "parent", link=j.parent)
        ET.SubElement(el, "child", link=j.child)
        ET.SubElement(el, "origin", xyz=_v(v / 1000.0 for v in j.origin_mm), rpy=_v(j.origin_rpy_rad))
        ET.SubElement(el, "axis", xyz=_v(j.joint_axis))
        ET.SubElement(el, "limit", effort="0", lower=_v([si(j.limit_deg[0])]),
                      upper=_v([si(j.limit_deg[1])]),
                      velocity=_v([si(j.max_speed_deg_s)]))
    el = ET.SubElement(robot, "joint", name="base_link-base", type="fixed")
    ET.SubElement(el, "parent", link="base_link")
    ET.SubElement(el, "child", link="base")
    ET.SubElement(el, "origin", xyz="0 0 0", rpy="0 0 0")
    el = ET.SubElement(robot, "joint", name=f"{machine.joints[-1].child}-tool0", type="fixed")
    ET.SubElement(el, "parent", link=machine.joints[-1].child)
    ET.SubElement(el, "child", link="tool0")
    ET.SubElement(el, "origin", xyz=_v(v / 1000.0 for v in machine.flange_pos_mm),
                  rpy=_v(machine.flange_rpy_rad))
    if machine.external_kinematics:
        _external(robot, machine)
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


def _origin(el, T) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)      # B = ±90: any split of the angles is the rotation
        rpy = Rotation.from_matrix(T[:3, :3]).as_euler("xyz")
    ET.SubElement(el, "origin", xyz=_v(T[:3, 3] / 1000.0), rpy=_v(rpy))


def _fixed(robot, name: str, parent: str, child: str, T) -> None:
    el = ET.SubElement(robot, "joint", name=name, type="fixed")
    ET.SubElement(el, "parent", link=parent)
    ET.SubElement(el, "child", link=child)
    _origin(el, T)


def _external(robot, machine: MachineData) -> None:
    """The links and joints of the external kinematics (module docstring)."""
    axes = {e.number: e for e in machine.external_axes}
    ET.SubElement(robot, "link", name="world")
    for kin in machine.external_kinematics:
        parent = "world"
        pending = frame_to_matrix(*kin.root)
        for k, num in enumerate(kin.axes):
            e = axes[num]
            pending = pending @ frame_to_matrix(*kin.frames[k])
            link_in = f"et{kin.index}_link{k + 1}_in"
            ET.SubElement(robot, "link", name=link_in)
            _fixed(robot, f"{parent}-{link_in}", parent, link_in, pending)
            link_out = f"et{kin.index}_link{k + 1}"
            ET.SubElement(robot, "link", name=link_out)
            el = ET.SubElement(robot, "joint", name=f"joint_e{num}", type="prismatic" if e.linear else
                               ("continuous" if e.kind == "endless" else "revolute"))
            ET.SubElement(el, "parent", link=link_in)
            ET.SubElement(el, "child", link=link_out)
            ET.SubElement(el, "origin", xyz="0 0 0", rpy="0 0 0")
            ET.SubElement(el, "axis", xyz=f"0 0 {e.direction}")
            scale = 0.001 if e.linear else math.pi / 180.0
            if e.kind != "endless":
                ET.SubElement(el, "limit", effort="0", lower=_v([e.limit[0] * scale]), upper=_v([e.limit[1] * scale]),
                              velocity=_v([e.max_speed * scale]))
            parent, pending = link_out, np.eye(4)
        pending = pending @ frame_to_matrix(*kin.frames[3])
        if kin.robroot:
            _fixed(robot, f"{parent}-base_link", parent, "base_link", pending)
        else:
            ET.SubElement(robot, "link", name=f"et{kin.index}_flange")
            _fixed(robot, f"{parent}-et{kin.index}_flange", parent, f"et{kin.index}_flange", pending)
    if not any(k.robroot for k in machine.external_kinematics):
        _fixed(robot, "world-base_link", "world", "base_link", frame_to_matrix(*machine.robroot_frame))


__all__ = ["build_urdf"]
