"""The one mapping between a robot model's axes and KRL's E6AXIS/E6POS components.

A robot model (robot/machine.py ``MachineData``) has its own axes J1..Jn (n = ``n_axes``: six for
the arms and palletizers, four for a SCARA, seven for a redundant arm such as KUKA's LBR iiwa) and
m external axes (``$EX_AX_NUM``). The planner, the controller and the MuJoCo model work on the
*model vector* ``(J1..Jn, external 1..m)``; KRL sees the components of E6AXIS and E6POS, ``A1..A6``
and ``E1..E6`` (reference §4.2; KUKA's ``$AXIS_ACT``, ``$AXIS_INT``, ``$POS_ACT.E1``, an E6POS
target's ``E1``). :attr:`AxisMap.slots` names the component of each model axis:

* up to six: ``A1..An``, then the external axes ``E1..Em``; a robot with fewer than six axes has 0
  in the A components it does not have (a SCARA's A5, A6);
* n = 7 (:data:`REDUNDANT_SLOTS`): ``A1, A2, E1, A3, A4, A5, A6``, then the external axes
  ``E2..E(m+1)``. The third joint of a seven-axis arm is its redundancy: it turns the elbow's
  plane about the shoulder-wrist line and is the one joint the Cartesian inverse kinematics leaves
  unaffected (KUKA's LBR iiwa: "a LBR iiwa 7 which owns a redundancy axis J3 ... only the joints
  J1, J2 and J4 - J7 are used from the IK. J3 remains unaffected", and a taught frame always
  carries the redundancy angle: robot-forum.com "automatically Redundancy usage", 2018). E6AXIS
  has no seventh A component, so the redundancy angle is carried as the first free component,
  E1, and the six joints the inverse solves keep KUKA's six-axis names A1..A6. docs/robot.md
  ("Seven-axis arms") records this decision; the numeric inverse that holds E1 is
  robot/kinematics/redundant.py.

The *KRL vector* is ``(A1..A6, E1..Ek)``: index 0..5 the A components, 6 + i the component
E(i+1); k is the highest E component the model uses (:attr:`AxisMap.krl_size` = 6 + k). A
component no model axis fills is 0 there.

:class:`AxisMap` is built once per model (:meth:`AxisMap.of`) and is the only place that knows
which component of E6AXIS an axis of the model is: the controller's read-back, the system
variables the program reads (interp/runtime/sysvars.py), the start pose (interp/scene.py), the
planner's targets, RSI, the trace and the pendant take their axis names and positions from it.

Units: deg for rotary axes, mm for linear ones (a track, a SCARA's A3), as KRL gives them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

#: E6AXIS's robot components, in order (reference §4.2)
ROBOT_KEYS = ("A1", "A2", "A3", "A4", "A5", "A6")
#: E6AXIS's and E6POS's external components, in order
EXT_KEYS = ("E1", "E2", "E3", "E4", "E5", "E6")
#: every component of E6AXIS, in KRL's order
E6AXIS_KEYS = ROBOT_KEYS + EXT_KEYS
#: the Cartesian components of POS/E6POS/FRAME
CART_KEYS = ("X", "Y", "Z", "A", "B", "C")
#: the E6AXIS components of a seven-axis arm's joints J1..J7: the redundancy (J3) as E1
REDUNDANT_SLOTS = ("A1", "A2", "E1", "A3", "A4", "A5", "A6")
#: the robot axis counts a map takes: 1..6 in A1..A6, 7 with :data:`REDUNDANT_SLOTS`
MAX_ROBOT_AXES = len(REDUNDANT_SLOTS)


def robot_slots(n: int) -> tuple[str, ...]:
    """The E6AXIS components of a robot's own n axes (module docstring); ValueError past 7."""
    if n == MAX_ROBOT_AXES:
        return REDUNDANT_SLOTS
    if not 1 <= n <= len(ROBOT_KEYS):
        raise ValueError(f"{n} robot axes: E6AXIS holds A1..A6, or a seven-axis arm's J3 as E1")
    return ROBOT_KEYS[:n]


@dataclass(frozen=True)
class AxisMap:
    """Where each axis of a robot model sits in KRL's E6AXIS/E6POS (see the module docstring).

    Attributes:
        n_robot: the robot's own axes J1..Jn (1..7).
        n_ext: the external axes (0..6, fewer when the robot's own axes use an E component).
        linear: per model axis, True for a linear axis (mm).
        home: ``$AXIS_HOME[1]`` as a model vector (the value a component takes when nothing
            gives it).
        slots: the E6AXIS component of each model axis (``"A1"``, .., ``"E1"``, ..).
    """

    n_robot: int
    n_ext: int
    linear: tuple[bool, ...]
    home: tuple[float, ...]
    slots: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not self.slots:
            slots = robot_slots(self.n_robot)
            free = [k for k in EXT_KEYS if k not in slots]
            if self.n_ext > len(free):
                raise ValueError(f"{self.n_robot} robot axes and {self.n_ext} external axes: "
                                 f"E6AXIS holds {len(free)} more E components")
            object.__setattr__(self, "slots", slots + tuple(free[:self.n_ext]))
        index = tuple(E6AXIS_KEYS.index(k) for k in self.slots)
        object.__setattr__(self, "_index", np.array(index, dtype=int))
        object.__setattr__(self, "_identity", index == tuple(range(len(index))) and self.n_robot == len(ROBOT_KEYS))

    @classmethod
    def of(cls, machine: Any) -> AxisMap:
        """The map of a robot model (robot/machine.py ``MachineData``); ValueError for more axes
        than E6AXIS holds."""
        joints = machine.joints
        ext = tuple(getattr(machine, "external_axes", ()))
        linear = tuple(getattr(j, "kind", "rotary") == "linear" for j in joints) + tuple(e.linear for e in ext)
        home = tuple(float(v) for v in machine.home_deg)[:len(joints)] + tuple(float(e.home) for e in ext)
        return cls(len(joints), len(ext), linear, home)

    # ------------------------------------------------------------------ names
    @property
    def size(self) -> int:
        """The length of a model vector: n + m."""
        return self.n_robot + self.n_ext

    @property
    def krl_index(self) -> tuple[int, ...]:
        """The KRL-vector index of each model axis (0..5 = A1..A6, 6 + i = E(i+1))."""
        return tuple(int(i) for i in self._index)

    @property
    def krl_size(self) -> int:
        """The length of a KRL vector: 6 + the highest E component used."""
        return max(len(ROBOT_KEYS), int(self._index.max()) + 1)

    @property
    def model_keys(self) -> tuple[str, ...]:
        """The E6AXIS component of each model axis, e.g. ``("A1", .., "A6", "E1")``."""
        return self.slots

    @property
    def robot_keys(self) -> tuple[str, ...]:
        """The E6AXIS components of the robot's own axes (A1..An, or :data:`REDUNDANT_SLOTS`)."""
        return self.slots[:self.n_robot]

    @property
    def ext_keys(self) -> tuple[str, ...]:
        """The E6AXIS components of the external axes (``("E1", .., "Em")``; from E2 on a
        seven-axis arm)."""
        return self.slots[self.n_robot:]

    def unit(self, key: str) -> str:
        """``"mm"`` or ``"deg"`` for the component `key` of this robot (KeyError for one it
        does not have)."""
        return "mm" if self.linear[self.model_keys.index(key)] else "deg"

    # ------------------------------------------------------------------ vectors
    def to_krl(self, q: Sequence[float]) -> np.ndarray:
        """The model vector `q` as a KRL vector (A1..A6, E1..Ek), shape (:attr:`krl_size`,);
        `q` itself (no copy) when the model's order is KRL's (six axes, then E1..Em)."""
        q = np.asarray(q, dtype=float)
        if self._identity:
            return q
        index = self._index[:len(q)]
        out = np.zeros(max(len(ROBOT_KEYS), int(index.max()) + 1))
        out[index] = q
        return out

    def from_krl(self, v: Sequence[float], fill: Sequence[float] | None = None) -> np.ndarray:
        """A model vector from a KRL vector (A1..A6, then E1..; a component past its end takes
        `fill`'s value, a model vector, default :attr:`home`); the A components the robot does
        not have are dropped."""
        v = np.asarray(v, dtype=float)
        if self._identity and len(v) >= self.size:
            return v[:self.size]
        have = self._index < len(v)
        if have.all():
            return v[self._index]
        out = np.asarray(self.home if fill is None else fill, dtype=float).copy()
        out[have] = v[self._index[have]]
        return out

    def components(self, q: Sequence[float]) -> dict[str, float]:
        """Every E6AXIS component (A1..A6, E1..E6) of the model vector `q`: the robot's and
        external axes' values, 0 for the components the robot does not have."""
        out = dict.fromkeys(E6AXIS_KEYS, 0.0)
        for k, v in zip(self.model_keys, q):
            out[k] = float(v)
        return out

    def krl_components(self, v: Sequence[float]) -> dict[str, float]:
        """Every E6AXIS component of a KRL vector `v` (A1..A6, E1..; missing ones 0)."""
        out = dict.fromkeys(E6AXIS_KEYS, 0.0)
        for k, x in zip(E6AXIS_KEYS, v):
            out[k] = float(x)
        return out

    def from_components(self, comps: Mapping[str, Any], fill: Sequence[float] | None = None) -> np.ndarray:
        """A model vector from E6AXIS components (upper-case keys; those the model does not have
        are ignored); a component `comps` lacks takes `fill`'s (a model vector; default
        :attr:`home`)."""
        base = self.home if fill is None else fill
        return np.array([float(comps[k]) if k in comps else float(base[i])
                         for i, k in enumerate(self.model_keys)])

    def e_components(self, q: Sequence[float]) -> dict[str, float]:
        """The E components the model vector `q` fills: its external axes and a seven-axis arm's
        redundancy (``{"E1": .., ..}``; E6POS carries them beside X..C, S and T)."""
        return {k: float(v) for k, v in zip(self.slots, q) if k in EXT_KEYS}

    def external(self, q: Sequence[float]) -> dict[str, float]:
        """The external axes of the model vector `q`: ``{"E1": .., "Em": ..}``."""
        return {k: float(q[self.n_robot + i]) for i, k in enumerate(self.ext_keys)}

    def robot_part(self, q: Sequence[float]) -> np.ndarray:
        """J1..Jn of the model vector `q`."""
        return np.asarray(q, dtype=float)[:self.n_robot]

    def ext_part(self, q: Sequence[float]) -> np.ndarray:
        """The external axes of the model vector `q`."""
        return np.asarray(q, dtype=float)[self.n_robot:self.n_robot + self.n_ext]


__all__ = ["AxisMap", "CART_KEYS", "E6AXIS_KEYS", "EXT_KEYS", "MAX_ROBOT_AXES", "REDUNDANT_SLOTS", "ROBOT_KEYS",
           "robot_slots"]
