"""Reading the values of a ``$machine.dat`` (robot/datalist.py ``DataValue``: each value with
its file:line) for a robot model: the error every refusal raises (:class:`MachineDataError`,
naming file:line, the variable and the value) and the helpers that read numbers, arrays,
frames, DH structures and flags with it. robot/mada.py builds the model with them, and so does
each kinematic family that reads its own geometry (robot/kinematics/*.py ``geometry``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.spatial.transform import Rotation

from .frames import frame_to_matrix

if TYPE_CHECKING:
    from .datalist import DataValue


class MachineDataError(ValueError):
    """Machine data that cannot make a robot model; the message names file:line, the variable
    and the value it cannot take."""


def get(vals: dict[str, DataValue], name: str, where: str) -> DataValue:
    v = vals.get(name)
    if v is None or v.value is None or v.value == {}:
        raise MachineDataError(f"{where}: {name} is not set; cannot build the robot model")
    return v


def krl_value(v: Any) -> str:
    """A machine-data value as KRL writes it (TRUE, #STANDARD, 12.5, "text", {..})."""
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, (int, float)):
        return f"{v:g}"
    if isinstance(v, dict):
        return "{" + ",".join(f"{k} {krl_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, str) and not v.startswith("#"):
        return f'"{v}"'
    return str(v)


def num(v: Any, where: str, name: str = "") -> float:
    label = f"{name}={krl_value(v)}: " if name else ""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise MachineDataError(f"{where}: {label}a number was expected")
    if not math.isfinite(float(v)):
        raise MachineDataError(f"{where}: {label}the value is not finite")
    return float(v)


def axes(vals: dict[str, DataValue], name: str, where: str, n: int = 6,
          first: int = 1) -> tuple[list[float], DataValue]:
    dv = get(vals, name, where)
    if not isinstance(dv.value, dict):
        raise MachineDataError(f"{dv.where()}: {name} is not an array")
    out = []
    for i in range(first, first + n):
        if i not in dv.value:
            raise MachineDataError(f"{dv.where()}: {name}[{i}] is not set")
        out.append(num(dv.value[i], dv.where(i), f"{name}[{i}]"))
    return out, dv


def axis_dirs(vals: dict[str, DataValue], where: str, n: int) -> tuple[list[float], DataValue]:
    """``$AXIS_DIR[1..n]`` as floats, each 1 or -1 (MachineDataError naming the element otherwise)."""
    dirs = get(vals, "$AXIS_DIR", where)
    out = []
    for i in range(1, n + 1):
        d = dirs.value.get(i) if isinstance(dirs.value, dict) else None
        if d not in (1, -1) or isinstance(d, bool):
            raise MachineDataError(f"{dirs.where(i)}: $AXIS_DIR[{i}]={krl_value(d)}: 1 or -1 was expected")
        out.append(float(d))
    return out, dirs


def frame6(vals: dict[str, DataValue], name: str, where: str) -> tuple[tuple[float, ...], DataValue]:
    dv = get(vals, name, where)
    if not isinstance(dv.value, dict):
        raise MachineDataError(f"{dv.where()}: {name}={krl_value(dv.value)}: a FRAME was expected")
    return tuple(num(dv.value.get(k, 0.0), dv.where(), f"{name}.{k}") for k in "XYZABC"), dv


def frame(vals: dict[str, DataValue], name: str, where: str) -> tuple[np.ndarray, DataValue]:
    f, dv = frame6(vals, name, where)
    return frame_to_matrix(*f), dv


def tr(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def rot(axis: str, deg: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler(axis, deg, degrees=True).as_matrix()
    return T


def dh(dv: DataValue) -> tuple[np.ndarray, tuple[float, float, float]]:
    v = dv.value if isinstance(dv.value, dict) else {}
    try:
        a = num(v["DHART_A"], dv.where(), f"{dv.name}.DHART_A")
        d = num(v["DHART_D"], dv.where(), f"{dv.name}.DHART_D")
        alpha = num(v["DHART_ALPHA"], dv.where(), f"{dv.name}.DHART_ALPHA")
    except KeyError as exc:
        raise MachineDataError(f"{dv.where()}: {dv.name} lacks component {exc.args[0]}") from None
    return tr(z=d) @ tr(x=a) @ rot("x", alpha), (a, d, alpha)


def flag(vals: dict[str, DataValue], name: str) -> tuple[bool, DataValue | None]:
    dv = vals.get(name)
    if dv is None or dv.value is None:
        return False, None
    if not isinstance(dv.value, bool):
        raise MachineDataError(f"{dv.where()}: {name}={krl_value(dv.value)}: TRUE or FALSE was expected")
    return dv.value, dv


__all__ = ["MachineDataError", "axes", "axis_dirs", "dh", "flag", "frame", "frame6", "get", "krl_value", "num", "rot", "tr"]
