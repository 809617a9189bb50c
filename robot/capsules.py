"""The radii of the robot's link capsules (robot/mjcf.py: the MuJoCo bodies the collision check uses,
robot/collision.py; the pendant draws the same), sized from the robot's kinematics (issue 64).

A robot of machine data has no link shapes: its links are capsules from joint to joint. Their radius
grows with the robot's size, as KUKA's arms do, by one rule for every model::

    r_group = C[group] * (reach / 1 m) ** P        (mm)

with ``reach`` the robot's reach to the wrist point (``MachineData.reach_wrist_point_mm``:
``$LENGTH_A + $LENGTH_B + |($TX3P3.X, $TX3P3.Z)|``) and three groups: ``base`` (the column from the
robot's foot to the A1 origin), ``arm`` (the capsules of A1..A3: the carousel offset, the upper arm,
the elbow offset) and ``wrist`` (A4..A6: the forearm, the wrist to the flange, the flange).

**Source.** The public collision meshes of three KUKA models, read in place from
../shared/robots/descriptions (ROS-Industrial kuka_experimental at e78bbd15: the KR 3 R540's seven,
the KR 6 R900 sixx's link_2 and link_4, the KR 150 R3100-2's seven; no KUKA data sheet gives link
cross-sections): at A = 0 every vertex of each mesh's convex hull is given to the nearest capsule
axis of the model; a group's radius is the 90th percentile of those vertices' distances to their
axis (a capsule that holds 90 % of the housing's outline: KUKA's housings have flanges and motors
that stick out, a capsule of the largest distance would be far too fat elsewhere). The groups'
radii, mm (reach 541, 901, 3105 mm): base 121, -, 568 (the KR 6's base mesh is not published);
arm 98, 130, 382; wrist 53, 97, 167. One exponent for all groups and a factor per group, fitted
by least squares on the logarithms (``tools/capsule_fit.py`` prints the table and the fit; the
nightly test tests/robot/test_capsules.py checks these constants against it): P 0.7627, C base
215.28, arm 152.97, wrist 85.38 mm. The fit is within 22 % of every measured radius (the KR 150's
wrist 203 for 167, the KR 6's 79 for 97: its wrist housing's mesh is not published). Before (until issue 64's follow-up), every
robot had 60 mm on A1..A3 and 45 mm on the wrist: a KR 150's arm was a broom handle.

The payload class is not a separate term: in the three models it follows the reach (3, 6, 150 kg),
and machine data hold no payload. A robot with a description's meshes collides with its meshes
(robot/description.py), not with these capsules.
"""

from __future__ import annotations

#: the exponent of the reach (fitted: module docstring)
P = 0.7627
#: the radius at 1 m reach per group, mm (fitted: module docstring)
C = {"base": 215.28, "arm": 152.97, "wrist": 85.38}


def capsule_radii(reach_mm: float) -> dict[str, float]:
    """The capsule radius of each group (``base``, ``arm``, ``wrist``), mm, for a robot whose reach to
    the wrist point is `reach_mm` (mm, > 0; ValueError otherwise)."""
    if not reach_mm > 0.0:
        raise ValueError(f"reach {reach_mm!r} mm: a positive reach was expected")
    scale = (reach_mm / 1000.0) ** P
    return {g: c * scale for g, c in C.items()}


def group_of(axis_index: int) -> str:
    """The group of the capsule of the link after axis `axis_index` (0-based: 0..2 ``arm``,
    3.. ``wrist``)."""
    return "arm" if axis_index < 3 else "wrist"


__all__ = ["C", "P", "capsule_radii", "group_of"]
