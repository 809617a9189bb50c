"""The simulated KUKA controller and its robot: the robot model of any machine data (the KR 6
R900 of robot/data by default, a backup's own $machine.dat through robot.mada), frames,
kinematics with their external axes, the planner and main run, and the MuJoCo model
(robot.mjcf, imported lazily because it needs mujoco)."""

import importlib

# The process's policy on Python's garbage collector (krl/collector.py sets the collector's
# thresholds when it is imported): a process that runs the simulator alone (``python -m
# robot.bench``) runs under it as the `krl` command does (`krl bench` gives the same figure).
from krl import collector as _collector  # noqa: F401

# The names below load their module on first use (PEP 562): `krl` commands that do not move
# the arm (parse, check, recover) never import numpy and scipy.
_EXPORTS = {
    "RobotError": ".errors", "SoftLimitError": ".errors", "WorkspaceError": ".errors",
    "compose": ".frames", "frame_to_matrix": ".frames", "inv_pos": ".frames", "matrix_to_frame": ".frames",
    "Kinematics": ".kinematics", "JointData": ".machine", "MachineData": ".machine", "load_machine": ".machine",
}

__all__ = list(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value
