"""The registry of kinematic families: the one place a family is registered.

:data:`FAMILIES` in detection order: ``Kinematics`` (robot/kinematics/__init__.py) builds the
first family whose ``detect`` answers for the robot's machine data. A new family is one module
of robot/kinematics/ implementing :class:`~robot.kinematics.family.KinematicFamily` plus one
line here (docs/architecture.md, "Kinematic families: where to add one");
tests/robot/test_families.py checks that every family here has every operation.
"""

from __future__ import annotations

from .numeric import Numeric
from .opw import OPW
from .palletizer4 import Palletizer4
from .palletizer5 import Palletizer5

#: The families, most specific first; the numeric family takes any six-axis arm the others do not.
FAMILIES = (Palletizer4, Palletizer5, OPW, Numeric)

__all__ = ["FAMILIES"]
