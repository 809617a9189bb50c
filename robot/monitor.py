"""The main run's monitoring at each IPO cycle (robot/controller.py's ``Controller.monitor``):
the axis speed of the setpoint (a CP path through a singularity), the robot against its cell
(robot/collision.py) and KUKA's workspace monitoring (robot/workspace.py; KSS 8.3 Operating and
Programming Instructions for System Integrators, "Workspace monitoring").

:class:`Monitor` holds the largest axis step per cycle (``CP_SPEED_LIMIT_FACTOR`` x each axis's
maximum speed x the IPO cycle: deg or mm, the model's axis order), the collision checker (None
without a cell's geometry) and the workspace monitor (None while no workspace can be active).
It finds what is wrong; the controller stops the robot (its ``_fault``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import steplimit
from .errors import RobotError
from .kinematics.compiled import pure_module
from .robotmodel import RobotModel

#: Factor on the axis maximum speed above which an interpolated CP setpoint is rejected.
CP_SPEED_LIMIT_FACTOR = 1.5


class Monitor:
    """The checks of each IPO cycle (module docstring).

    Args:
        model: the robot model (its axes' maximum speeds).
        dt: the IPO cycle (s).
        collision: robot/collision.py ``CollisionChecker`` or None.
        workspaces: robot/workspace.py ``WorkspaceMonitor`` or None.
    """

    def __init__(self, model: RobotModel, dt: float, collision: Any = None, workspaces: Any = None) -> None:
        self.model = model
        self.dt = dt
        self.collision = collision
        self.workspaces = workspaces
        self._speed_ok = pure_module(steplimit).speed_ok   # robot/steplimit.py, compiled where built
        self._step_lim: list[float] | None = None   # largest axis step per cycle

    def watch_workspaces(self, monitor) -> None:
        """KUKA's workspace monitoring from now on (robot/workspace.py ``WorkspaceMonitor``): a
        program that names ``$WORKSPACE``/``$AXWORKSPACE`` while it runs (interp/runtime/sysvars.py)."""
        self.workspaces = monitor

    def check_speed(self, q: np.ndarray, q_prev: np.ndarray) -> None:
        """Reject a setpoint `q` that would move an axis from `q_prev` faster than
        ``CP_SPEED_LIMIT_FACTOR`` x its maximum speed (a CP path through a singularity): raises
        RobotError naming the axis (its component, robot/axismap.py ``model_keys``)."""
        if q is q_prev:        # at rest: the main run kept the last setpoint
            return
        lim = self._step_lim
        if lim is None:
            lim = self._step_lim = (CP_SPEED_LIMIT_FACTOR * self.model.v_max * self.dt + 1e-9).tolist()
        qs = q.tolist() if type(q) is np.ndarray else np.asarray(q, dtype=float).tolist()
        qp = q_prev.tolist()
        if self._speed_ok(qs, qp, lim):
            return
        step = [abs(a - b) for a, b in zip(qs, qp)]
        for d, m in zip(step, lim):
            if d > m:
                i = max(range(len(step)), key=lambda j: step[j] / lim[j])
                name = self.model.axes.model_keys[i]
                raise RobotError(f"speed limit exceeded {name}: CP path through a singularity")

    def collision_error(self, q: np.ndarray, tcp_world: np.ndarray, line: int | None) -> RobotError | None:
        """The robot at setpoint `q` against its cell (MuJoCo's contacts of the links, the tool,
        the cell's bodies and the floor): None without a contact, else the main-run error naming
        both bodies, the motion's `line` and the TCP `tcp_world` (mm, ``$WORLD``)."""
        c = self.collision.check(q)
        if c is None:
            return None
        p = tcp_world
        at = f" at the motion of line {line}" if line is not None else ""
        return RobotError(f"collision: {c.a} touches {c.b}{at}; TCP X {p[0]:.1f}, Y {p[1]:.1f}, "
                          f"Z {p[2]:.1f} mm in $WORLD")

    def workspaces_cycle(self, tcp_world: np.ndarray, qa: np.ndarray) -> tuple[list, str | None]:
        """KUKA's workspace monitoring at this IPO cycle: the TCP of the main run's ``$TOOL`` in
        ``$WORLD`` (`tcp_world`, mm) and the axes read back (`qa`, model order). Returns the state
        signals that changed, ``[(name, value)]``, and the message of a STOP workspace violated
        (None: none)."""
        return self.workspaces.cycle(tcp_world, self.model.axes.components(qa))


__all__ = ["Monitor"]
