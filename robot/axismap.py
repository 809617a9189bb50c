"""The one mapping between a robot model's axes and KRL's E6AXIS/E6POS components.

A robot model (robot/machine.py ``MachineData``) has its own axes A1..An (n = ``n_axes``: six for
the arms and palletizers, four for a SCARA) and m external axes E1..Em (``$EX_AX_NUM``). The
planner, the controller and the MuJoCo model work on the *model vector* ``(A1..An, E1..Em)``;
KRL sees the components of E6AXIS and E6POS, ``A1..A6`` and ``E1..E6`` (reference §4.2;
KUKA's ``$AXIS_ACT``, ``$AXIS_INT``, ``$POS_ACT.E1``, an E6POS target's ``E1``). The *KRL
vector* is ``(A1..A6, E1..Em)``: a robot with fewer than six axes has 0 in the A components
it does not have; an E component above m is 0.

:class:`AxisMap` is built once per model (:meth:`AxisMap.of`) and is the only place that knows
which component of E6AXIS an axis of the model is: the controller's read-back, the system
variables the program reads (interp/runtime/sysvars.py), the start pose (interp/scene.py), the
planner's targets, the trace and the pendant take their axis names and positions from it.

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


@dataclass(frozen=True)
class AxisMap:
    """Where each axis of a robot model sits in KRL's E6AXIS/E6POS (see the module docstring).

    Attributes:
        n_robot: the robot's own axes A1..An (1..6).
        n_ext: the external axes E1..Em (0..6).
        linear: per model axis (A1..An, E1..Em), True for a linear axis (mm).
        home: ``$AXIS_HOME[1]`` as a model vector (the value a component takes when nothing
            gives it).
    """

    n_robot: int
    n_ext: int
    linear: tuple[bool, ...]
    home: tuple[float, ...]

    @classmethod
    def of(cls, machine: Any) -> AxisMap:
        """The map of a robot model (robot/machine.py ``MachineData``)."""
        joints = machine.joints
        ext = tuple(getattr(machine, "external_axes", ()))
        linear = tuple(getattr(j, "kind", "rotary") == "linear" for j in joints) + tuple(e.linear for e in ext)
        home = tuple(float(v) for v in machine.home_deg)[:len(joints)] + tuple(float(e.home) for e in ext)
        if not 1 <= len(joints) <= 6 or len(ext) > 6:
            raise ValueError(f"{len(joints)} robot axes and {len(ext)} external axes: E6AXIS holds 6 and 6")
        return cls(len(joints), len(ext), linear, home)

    # ------------------------------------------------------------------ names
    @property
    def size(self) -> int:
        """The length of a model vector: n + m."""
        return self.n_robot + self.n_ext

    @property
    def krl_size(self) -> int:
        """The length of a KRL vector: 6 + m."""
        return 6 + self.n_ext

    @property
    def model_keys(self) -> tuple[str, ...]:
        """The E6AXIS component of each model axis: ``("A1", .., "An", "E1", .., "Em")``."""
        return ROBOT_KEYS[:self.n_robot] + EXT_KEYS[:self.n_ext]

    @property
    def ext_keys(self) -> tuple[str, ...]:
        """``("E1", .., "Em")``."""
        return EXT_KEYS[:self.n_ext]

    def unit(self, key: str) -> str:
        """``"mm"`` or ``"deg"`` for the component `key` of this robot (KeyError for one it
        does not have)."""
        return "mm" if self.linear[self.model_keys.index(key)] else "deg"

    # ------------------------------------------------------------------ vectors
    def to_krl(self, q: Sequence[float]) -> np.ndarray:
        """The model vector `q` (A1..An, E1..Em) as a KRL vector (A1..A6, E1..Em), shape (6 + m,);
        `q` itself (no copy) when the robot has six axes."""
        q = np.asarray(q, dtype=float)
        if self.n_robot == 6:
            return q
        out = np.zeros(6 + len(q) - self.n_robot)
        out[:self.n_robot] = q[:self.n_robot]
        out[6:] = q[self.n_robot:]
        return out

    def from_krl(self, v: Sequence[float]) -> np.ndarray:
        """A model vector from a KRL vector (A1..A6, then E1..; fewer E than m: the others from
        :attr:`home`); the A components the robot does not have are dropped."""
        v = np.asarray(v, dtype=float)
        if not self.n_ext:
            return v[:self.n_robot]
        e = v[6:6 + self.n_ext]
        return np.concatenate([v[:self.n_robot], e, np.asarray(self.home[self.n_robot + len(e):], dtype=float)])

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
        """A model vector from E6AXIS components (upper-case keys; A(n+1)..A6 and E above m are
        ignored); a component `comps` lacks takes `fill`'s (a model vector; default :attr:`home`)."""
        base = self.home if fill is None else fill
        return np.array([float(comps[k]) if k in comps else float(base[i])
                         for i, k in enumerate(self.model_keys)])

    def external(self, q: Sequence[float]) -> dict[str, float]:
        """The external axes of the model vector `q`: ``{"E1": .., "Em": ..}``."""
        return {k: float(q[self.n_robot + i]) for i, k in enumerate(self.ext_keys)}

    def robot_part(self, q: Sequence[float]) -> np.ndarray:
        """A1..An of the model vector `q`."""
        return np.asarray(q, dtype=float)[:self.n_robot]

    def ext_part(self, q: Sequence[float]) -> np.ndarray:
        """E1..Em of the model vector `q`."""
        return np.asarray(q, dtype=float)[self.n_robot:self.n_robot + self.n_ext]


__all__ = ["AxisMap", "CART_KEYS", "E6AXIS_KEYS", "EXT_KEYS", "ROBOT_KEYS"]
