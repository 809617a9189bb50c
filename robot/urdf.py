"""URDF of a robot model (``krl robot export --format urdf``), for other tools (ROS, viewers).

The URDF has the joint layout of :class:`~robot.machine.MachineData` (robot-model.md §2-§3):
links ``base_link``, ``link_1`` .. ``link_6``, joints ``joint_a1`` .. ``joint_a6`` with
``q = radians(A_i)`` (KUKA's directions are in the joint axes), the fixed frames ``base``
(= ``$ROBROOT``) and ``tool0`` (= KUKA's flange frame), as the ROS-Industrial KUKA URDFs do.
No meshes and no inertias (the machine data hold none). Lengths in m, angles in rad.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

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
        el = ET.SubElement(robot, "joint", name=j.name, type="revolute")
        ET.SubElement(el, "parent", link=j.parent)
        ET.SubElement(el, "child", link=j.child)
        ET.SubElement(el, "origin", xyz=_v(v / 1000.0 for v in j.origin_mm), rpy=_v(j.origin_rpy_rad))
        ET.SubElement(el, "axis", xyz=_v(j.joint_axis))
        ET.SubElement(el, "limit", effort="0", lower=_v([math.radians(j.limit_deg[0])]),
                      upper=_v([math.radians(j.limit_deg[1])]),
                      velocity=_v([math.radians(j.max_speed_deg_s)]))
    el = ET.SubElement(robot, "joint", name="base_link-base", type="fixed")
    ET.SubElement(el, "parent", link="base_link")
    ET.SubElement(el, "child", link="base")
    ET.SubElement(el, "origin", xyz="0 0 0", rpy="0 0 0")
    el = ET.SubElement(robot, "joint", name="link_6-tool0", type="fixed")
    ET.SubElement(el, "parent", link=machine.joints[-1].child)
    ET.SubElement(el, "child", link="tool0")
    ET.SubElement(el, "origin", xyz=_v(v / 1000.0 for v in machine.flange_pos_mm),
                  rpy=_v(machine.flange_rpy_rad))
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


__all__ = ["build_urdf"]
