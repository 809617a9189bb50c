"""External kinematics: a track carrying the robot, a turntable or positioner carrying the
workpiece (``$EX_KIN``; :class:`~robot.machine.ExternalKinematic`).

Source: KUKA's KR C2 machine-data handbook "Maschinendaten 12.0400 en" §2.1.9 (``$ERSYSROOT``:
with a ROBROOT kinematic, ``$ROBROOT`` is ignored and the robot's base moves with the external
axes, read as ``$ROBROOT_C``) and §2.2.5-§2.2.11 (``$EX_KIN``, ``$ETn_AX``, ``$ETn_TA1KR``,
``$ETn_TA2A1``, ``$ETn_TA3A2``, ``$ETn_TFLA3``); the transformation chain of an external
kinematic as KUKA's machine data define it, each axis moving along (linear, ``$AXIS_TYPE`` 1) or
turning about (rotary 3, endless 5) the Z axis of the frame before it (robot-forum, "Robot Pick
n Place RoboDK", answer quoting R1/$machine.dat)::

    ETn(E) = root : $ETn_TA1KR : Ax(E_a) : $ETn_TA2A1 : Ax(E_b) : $ETn_TA3A2 : Ax(E_c) : $ETn_TFLA3

with ``Ax(e) = Tz(d·e)`` (mm) or ``Rz(d·e)`` (deg), ``d = $AXIS_DIR[6 + n]``; the frames after
the last axis used are skipped except ``TFLA3``. ``root`` is ``$ERSYSROOT`` for the ROBROOT
kinematic (#ERSYS) and ``$WORLD`` for a BASE kinematic (#EASYS..#EFSYS: its root point is
``MACHINE_DEF[].ROOT`` of ``$config.dat``, not machine data; decision).

``ETn(E)`` (``$ROBROOT_C`` every IPO cycle of a robot on a track, a linked ``$BASE`` on a
turntable) is robot/ipocycle.py's ``ExternalChain`` compiled where it is built and gives this
module's numpy products bit for bit on 16 axis values (checked once per kinematic and root, at
most :data:`CHAINS`), else the numpy code here.

* #ERSYS: ``$ROBROOT_C(E) = ETn(E)``, so ``FLANGE_world = ETn(E) : FLANGE(A)``.
* #EASYS..#EFSYS: a ``$BASE`` linked to the kinematic (KSS ``EK(ROOT, #EASYS, offset)``) is
  ``$BASE_C(E) = ETn(E) : offset``: the workpiece turns with the table.

Units: mm and deg; frames 4x4.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from . import ipocycle
from .blas import numpy_cblas
from .frames import frame_to_matrix, inv_pos
from .kinematics.compiled import pure_module
from .machine import ExternalKinematic, MachineData


#: Compiled chains an :class:`ExternalAxes` keeps (a kinematic on its own root, and on each root
#: ``EK`` gave it: MACHINE_DEF's few entries); a chain past them runs the numpy code
CHAINS = 16


def _axis(kind: str, direction: int, value: float) -> np.ndarray:
    if kind == "linear":
        T = np.eye(4)
        T[2, 3] = direction * value
        return T
    return frame_to_matrix(0.0, 0.0, 0.0, direction * value, 0.0, 0.0)


class ExternalAxes:
    """The external axes of a robot model: values E1..E6 and the frames they move."""

    def __init__(self, machine: MachineData) -> None:
        self.machine = machine
        self.axes = {e.number: e for e in machine.external_axes}
        self.n = len(machine.external_axes)
        self.robroot_kin: ExternalKinematic | None = next(
            (k for k in machine.external_kinematics if k.robroot), None)
        self.base_kins = {k.system: k for k in machine.external_kinematics if not k.robroot}
        self._robroot_T = frame_to_matrix(*machine.robroot_frame)
        #: the compiled chain (robot/ipocycle.py ExternalChain) of each kinematic and root (None: its
        #: own), False where not used; at most CHAINS, then the numpy code
        self._c: dict[tuple, Any] = {}

    def values(self, e: Sequence[float] | dict[str, float] | None) -> np.ndarray:
        """E1..En as an array (missing: 0)."""
        if e is None:
            return np.zeros(self.n)
        if isinstance(e, dict):
            return np.array([float(e.get(f"E{i}", 0.0)) for i in range(1, self.n + 1)])
        return np.asarray(e, dtype=float)[: self.n]

    def chain(self, kin: ExternalKinematic, e: Sequence[float], root: Sequence[float] | None = None) -> np.ndarray:
        """``ETn(E)``: the flange of the external kinematic `kin` in ``$WORLD`` (4x4, mm); `root`
        (X..C) replaces the kinematic's root (``EK``'s ``MACHINE_DEF[].ROOT``)."""
        ev = self.values(e)
        key = (kin.system, None if root is None else tuple(float(v) for v in root))
        c = self._c.get(key)
        if c is None and len(self._c) < CHAINS:
            c = self._c[key] = self._compiled(kin, root)
        if c and ev.shape[0] >= c.need:
            out = np.empty((4, 4))
            c.chain(ev, out)
            return out
        return self._chain_py(kin, ev, root)

    def _chain_py(self, kin: ExternalKinematic, ev: np.ndarray, root: Sequence[float] | None) -> np.ndarray:
        """:meth:`chain` in numpy (the reference)."""
        T = frame_to_matrix(*(kin.root if root is None else root))
        links = (kin.frames[0], kin.frames[1], kin.frames[2])
        for k, num in enumerate(kin.axes):
            ax = self.axes[num]
            T = T @ frame_to_matrix(*links[k]) @ _axis(ax.kind, ax.direction, float(ev[num - 1]))
        return T @ frame_to_matrix(*kin.frames[3])

    def _compiled(self, kin: ExternalKinematic, root: Sequence[float] | None = None) -> Any:
        """robot/ipocycle.py's ``ExternalChain`` of `kin` (on `root`, as :meth:`chain`) compiled, when it is built and current
        (robot/kinematics/compiled.py ``pure_module``), numpy's BLAS is at hand and it gives
        :meth:`_chain_py` bit for bit on 16 axis values (zeros, signed zeros, wide and small
        values); else False."""
        mod = pure_module(ipocycle)
        gemm = numpy_cblas("dgemm")
        if not mod.COMPILED or not gemm:
            return False
        m = len(kin.axes)
        frames = [frame_to_matrix(*(kin.root if root is None else root))] + [frame_to_matrix(*kin.frames[k]) for k in range(m)] + [
            frame_to_matrix(*kin.frames[3])]
        c = mod.ExternalChain(gemm, np.array(frames), [self.axes[num].kind == "linear" for num in kin.axes],
                              [float(self.axes[num].direction) for num in kin.axes], [num - 1 for num in kin.axes])
        rng = np.random.default_rng(86)
        out = np.empty((4, 4))
        for i in range(16):
            ev = rng.uniform(-400.0, 400.0, max(self.n, c.need)) * (1e-5 if i % 4 == 1 else 1.0)
            if i % 3 == 0:
                ev[:] = -0.0 if i % 2 else 0.0
            c.chain(ev, out)
            if out.tobytes() != self._chain_py(kin, ev, root).tobytes():
                return False
        return c

    def robroot(self, e: Sequence[float]) -> np.ndarray:
        """``$ROBROOT_C``: the robot's base in ``$WORLD`` at the external axes `e` (4x4, mm);
        the static ``$ROBROOT`` without a ROBROOT kinematic."""
        if self.robroot_kin is None:
            return self._robroot_T
        return self.chain(self.robroot_kin, e)

    def base(self, system: str, offset: np.ndarray, e: Sequence[float]) -> np.ndarray:
        """``$BASE_C`` of a ``$BASE`` linked to the BASE kinematic `system` (#EASYS..) with the
        measured `offset` (4x4): ``ETn(E) : offset``."""
        kin = self.base_kins.get(system)
        if kin is None:
            raise KeyError(f"no external kinematic {system} in $EX_KIN")
        return self.chain(kin, e) @ offset

    def world_flange(self, kin_forward, axes_deg: Sequence[float], e: Sequence[float]) -> np.ndarray:
        """The flange in ``$WORLD``: ``$ROBROOT_C(E) : FLANGE(A)``; `kin_forward` is
        robot.kinematics ``Kinematics.forward``."""
        return self.robroot(e) @ kin_forward(axes_deg)

    def flange_in_robroot(self, world_T: np.ndarray, e: Sequence[float]) -> np.ndarray:
        """A flange pose in ``$WORLD`` expressed in the robot's base at `e` (for the inverse)."""
        return inv_pos(self.robroot(e)) @ world_T


__all__ = ["ExternalAxes"]
