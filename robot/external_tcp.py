"""``$IPO_MODE = #TCP``: the external TCP (reference §6.4; robot-model.md §7).

Laser, glue and deburring cells hold the tool fixed in the cell and carry the workpiece on
the flange. KUKA's BASIS keeps the frames where it always does (``BAS(#TOOL, n)`` sets
``$TOOL = TOOL_DATA[n]``, ``BAS(#BASE, n)`` sets ``$BASE = BASE_DATA[n]``), and the fixed tool
is measured as a base ("external TCP"), the workpiece on the flange as a tool. So with
``#TCP``:

* ``$TOOL`` is the workpiece frame relative to the flange,
* ``$BASE`` is the fixed tool (its TCP) in WORLD,
* a Cartesian target P is the pose of the fixed tool in the workpiece frame:
  ``$ROBROOT : FLANGE(q) : $TOOL : P = $BASE``, hence
  ``P = INV_POS($ROBROOT : FLANGE(q) : $TOOL) : $BASE`` and, for the inverse kinematics,
  ``FLANGE = INV_POS($ROBROOT) : $BASE : INV_POS(P) : INV_POS($TOOL)``.

That is the ``#BASE`` chain (``INV_POS($BASE) : $ROBROOT : FLANGE(q) : $TOOL``) inverted, so
:class:`ExternalTcpModel` wraps a planner model and inverts the pose on the way in and out:
the planner interpolates P (a LIN moves the fixed tool on a straight line over the
workpiece) and every IPO cycle solves the flange from it. (The reference's sentence on #TCP
names the two frames the other way round; the text above follows KUKA's BASIS, where the
fixed tool is a base — docs/robot.md.)
"""

from __future__ import annotations

import numpy as np

from .frames import inv_pos


def external_tcp(model):
    """The planner model for ``$IPO_MODE = #TCP`` motions of ``model`` (a
    :class:`robot.planner.RobotModel`), made once per model."""
    ext = getattr(model, "_external_tcp", None)
    if ext is None:
        ext = model._external_tcp = ExternalTcpModel(model)
    return ext


def _inv_many(T: np.ndarray) -> np.ndarray:
    """Inverse of a stack of rigid transforms (n, 4, 4)."""
    R = T[:, :3, :3]
    Rt = np.transpose(R, (0, 2, 1))
    out = np.zeros_like(T)
    out[:, :3, :3] = Rt
    out[:, :3, 3] = -np.einsum("nij,nj->ni", Rt, T[:, :3, 3])
    out[:, 3, 3] = 1.0
    return out


class ExternalTcpModel:
    """A planner model whose "TCP in $BASE" is the fixed tool ``$BASE`` in the workpiece
    frame ``$TOOL`` (see the module text); everything else is the wrapped model's."""

    def __init__(self, inner) -> None:
        self.inner = inner

    def __getattr__(self, name: str):
        return getattr(self.inner, name)

    def tcp(self, q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """P = INV_POS($ROBROOT : FLANGE(q) : $TOOL) : $BASE (4x4, mm)."""
        return inv_pos(self.inner.tcp(q, tool_T, base_inv_T))

    def ik(self, T_p: np.ndarray, tool_inv_T: np.ndarray, base_T: np.ndarray,
           status: int | None, turn: int | None, ref: np.ndarray) -> np.ndarray:
        """Axes for the pose P of the fixed tool in the workpiece frame."""
        return self.inner.ik(inv_pos(T_p), tool_inv_T, base_T, status, turn, ref)

    def tcp_pos_many(self, Q: np.ndarray, tool_T: np.ndarray, base_inv_T: np.ndarray) -> np.ndarray:
        """Positions (n, 3) of P for axis rows Q (n, 6)."""
        F = self.inner.kin.forward_many(Q)
        if not self.inner._robroot_is_null:
            F = self.inner.robroot_T @ F
        return _inv_many(base_inv_T @ F @ tool_T)[:, :3, 3]

    def solve_position(self, p, wrist, ref, tool_T, base_inv_T):
        """``$ORI_TYPE #JOINT`` with an external TCP: the wrapped model's Newton iteration
        on this model's positions."""
        return type(self.inner).solve_position(self, p, wrist, ref, tool_T, base_inv_T)
