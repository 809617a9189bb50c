"""Simulated KR 6 R900 sixx controller: machine data, frames, kinematics (and MuJoCo model
in robot.mjcf, imported lazily because it needs mujoco)."""

from .errors import RobotError, SoftLimitError, WorkspaceError
from .frames import compose, frame_to_matrix, inv_pos, matrix_to_frame
from .kinematics import Kinematics
from .machine import JointData, MachineData, load_machine

__all__ = [
    "RobotError", "SoftLimitError", "WorkspaceError",
    "compose", "frame_to_matrix", "inv_pos", "matrix_to_frame",
    "Kinematics", "JointData", "MachineData", "load_machine",
]
