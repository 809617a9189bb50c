"""The registry of kinematic families: the one place a family is registered.

:data:`FAMILIES` in detection order: ``Kinematics`` (robot/kinematics/__init__.py) builds the
first family whose ``detect`` answers for the robot's machine data. A new family is one module
of robot/kinematics/ implementing :class:`~robot.kinematics.family.KinematicFamily` plus one
line here (docs/architecture.md, "Kinematic families: where to add one");
tests/robot/test_families.py checks that every family here has every operation.
"""

from __future__ import annotations

from typing import Any

from ..madavalues import MachineDataError
from .family import Geometry
from .numeric import Numeric
from .opw import OPW
from .palletizer4 import Palletizer4
from .palletizer5 import Palletizer5
from .redundant import Redundant
from .scara import Scara

#: The families, most specific first; the numeric family takes any six-axis arm the others do not,
#: the redundant family a seven-axis arm (from a robot description: robot/description.py).
FAMILIES = (Palletizer4, Palletizer5, Scara, OPW, Numeric, Redundant)


def machine_geometry(values: dict[str, Any], source: str, prov: dict[str, str], a4fix: bool,
                     a5link: bool) -> Geometry:
    """The kinematic chain of a ``$machine.dat`` (robot/mada.py): the first family's answer
    (``geometry``). Raises robot.madavalues.MachineDataError, also when no family builds the
    main axes the machine data name (``$MAIN_AXIS``)."""
    for fam in FAMILIES:
        geo = fam.geometry(values, source, prov, a4fix, a5link)
        if geo is not None:
            return geo
    main = values.get("$MAIN_AXIS")
    where = main.where() if main is not None else source
    raise MachineDataError(f"{where}: $MAIN_AXIS={main.value if main is not None else '?'}: no kinematic family "
                           f"of robot/kinematics/families.py builds these main axes")


__all__ = ["FAMILIES", "machine_geometry"]
