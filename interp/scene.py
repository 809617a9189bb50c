"""Set the scene of a run (issue 34, "Set the scene"): where the robot stands when the program
starts, and which robot a backup without machine data runs on when the cell answers by itself.

* :func:`start_axes` — ``krl run --start AXIS_OR_POINT`` / a cell file's ``start:``: an
  E6AXIS literal or a point of the program (``XHOME``), checked by the project's expression
  parser (robot/stimuli.py ``parse_start``).
* :func:`choose_robot` — ``krl run --inputs auto`` on a backup that has no machine data of its
  own (a flat export without ``R1/Mada``): the robot of the project's library that reaches the
  points the backup teaches, instead of the KR 6 R900 that reaches none of a palletizer's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from interp.runtime.values import Arr, Struct
from krl.limits import MAX_CHOICE_POINTS
from krl.ast import nodes as N
from robot.stimuli import StartError, parse_start
from krl.files import spelled, spelled_within
from krl.project import backup_of, machine_data_file
from robot.frames import frame_to_matrix, inv_pos
from robot.robotmodel import RobotModel
from robot.machine import library_robots, load_machine
from robot.mada import MachineDataError, load_robot

#: the components of a Cartesian point and of an axis point
_CART = ("X", "Y", "Z", "A", "B", "C")
_AXES = ("A1", "A2", "A3", "A4", "A5", "A6")


def start_axes(model, value_of: Callable[[str], object], text: str) -> np.ndarray:
    """The axes (KRL's order: A1..A6, E1..Em; deg, mm) the robot of `model` (robot/planner.py
    RobotModel) starts at for the start position `text`
    (robot/stimuli.py ``parse_start``): an axis literal as given (missing axes, external ones
    included: those of ``$AXIS_HOME[1]``); a point of the program (`value_of(name)`: its data list, then
    ``$config.dat``, e.g. ``XHOME``) that is an AXIS/E6AXIS as it is, a POS/E6POS (TCP in the
    world: null ``$TOOL`` and ``$BASE``) through the robot's inverse kinematics with its S and
    T. Raises :class:`robot.stimuli.StartError` for a point the program does not have, a pose
    the robot cannot take, or axes outside its software limits."""

    expr = parse_start(text)
    if isinstance(expr, N.Name):
        value = value_of(expr.name)
        if not isinstance(value, Struct):
            raise StartError(f"start {text}: no point {expr.name} in the program's data lists or $config.dat")
        comps = {k: v for k, v in value.f.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
    else:
        comps = {}
        for it in expr.items:
            v = it.value
            sign = -1 if isinstance(v, N.Unary) and v.op == "-" else 1
            if isinstance(v, N.Unary):
                v = v.operand
            comps[it.name.upper()] = sign * v.value
    # the model's axes (robot/axismap.py): a component the start does not give takes
    # $AXIS_HOME[1]'s; the external axes E1..Em the robot has are the start's too (XHOME's E1)
    amap = model.axes
    home = np.array(amap.home, dtype=float)
    ext = {k: comps[k] for k in amap.ext_keys if k in comps}
    if any(k in comps for k in _AXES):
        q = amap.from_components(comps)
    elif all(k in comps for k in _CART):

        T_world = frame_to_matrix(*(float(comps[k]) for k in _CART))
        try:
            q = model.ik(T_world, None, None, int(comps["S"]) if "S" in comps else None,
                                    int(comps["T"]) if "T" in comps else None,
                                    amap.from_components(ext, fill=home))
        except Exception as exc:  # noqa: BLE001 - a robot error names the reason
            raise StartError(f"start {text}: {getattr(exc, 'message', exc)}") from None
    else:
        raise StartError(f"start {text}: neither the axes A1..A6 nor X, Y, Z, A, B, C")
    try:
        model.check_limits(q)
    except Exception as exc:  # noqa: BLE001
        raise StartError(f"start {text}: {getattr(exc, 'message', exc)}") from None
    return amap.to_krl(np.asarray(q, dtype=float))


# ---------------------------------------------------------------------- the robot choice
@dataclass
class Choice:
    """The robot :func:`choose_robot` chose: its machine data, the points it reaches of those
    looked at, and why."""

    machine: object
    reached: int
    points: int

    @property
    def note(self) -> str:
        return (f"chosen by --inputs auto: the backup has no machine data; of the project's robots it "
                f"reaches the most of the backup's {self.points} taught points ({self.reached})")


_CHOICES: dict = {}


def chosen(program: Path, workspace=None) -> Choice | None:
    """The choice :func:`choose_robot` made for the backup of `program`, if it made one."""

    root = backup_of(spelled_within(program, workspace), spelled(workspace) if workspace else None)
    return _CHOICES.get(root) if root is not None else None


def taught_points(loaded, value_of: Callable[[str], object]) -> list[tuple[str, object, object, object]]:
    """``(kind, value, tool, base)`` of the points the backup's data lists teach, as the program
    `loaded` (a run's or a tool's copy of its model, interp/runtime/model.py RunData) holds them: kind ``"axes"`` (an
    AXIS/E6AXIS value) or ``"pose"`` (a POS/E6POS, with the
    TOOL_DATA and BASE_DATA frames of its inline form's FDAT: ``XP1`` with ``FP1``, KUKA's
    naming of inline forms; without one, null frames). `value_of(name)` reads a global
    (``TOOL_DATA``, ``BASE_DATA`` of ``$config.dat``). Values that are not set are skipped."""
    tools = value_of("TOOL_DATA")
    bases = value_of("BASE_DATA")
    out: list = []
    for m in loaded.program.modules:
        if not m.loaded:
            loaded.program.ensure_loaded(m)
        for _name, kind, v, tool, base in module_points(m, tools, bases):
            out.append((kind, v, tool, base))
            if len(out) >= MAX_CHOICE_POINTS:
                return out
    return out


def module_points(m, tools, bases):
    """``(name, kind, value, tool, base)`` of each point the data list of the loaded module `m`
    teaches (see :func:`taught_points`; `tools`/`bases`: ``TOOL_DATA``/``BASE_DATA``)."""
    data = m.data
    for name, ref in data.items():
        try:
            v = ref.peek()
        except Exception:  # noqa: BLE001 - a value that cannot be read is no point
            continue
        if not isinstance(v, Struct):
            continue
        f = v.f
        if all(isinstance(f.get(k), (int, float)) for k in _AXES):
            yield name, "axes", v, None, None
        elif all(isinstance(f.get(k), (int, float)) for k in _CART) and ("S" in f or "T" in f):
            tool = base = None
            fdat = data.get("F" + name[1:]) if name.startswith("X") else None
            fv = fdat.peek() if fdat is not None else None
            if isinstance(fv, Struct):
                tool = _frame_at(tools, fv.f.get("TOOL_NO"))
                base = _frame_at(bases, fv.f.get("BASE_NO"))
            yield name, "pose", v, tool, base


def _frame_at(arr, n):
    if not isinstance(arr, Arr) or not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= len(arr.data):
        return None
    v = arr.data[n - 1]
    if isinstance(v, Struct) and all(isinstance(v.f.get(k), (int, float)) for k in _CART):
        return tuple(float(v.f[k]) for k in _CART)
    return None


def reaches(machine, points) -> int:
    """How many of `points` (:func:`taught_points`) the robot of `machine` can take: an axis
    point within its software limits; a pose for which some configuration of its inverse
    kinematics (any status and turn, ±360° variants) lies within them."""

    model = RobotModel(machine)
    limits = [j.limit_deg for j in machine.joints]

    def within(q) -> bool:
        return all(any(lo - 1e-6 <= float(x) + k <= hi + 1e-6 for k in (-360.0, 0.0, 360.0))
                   for x, (lo, hi) in zip(q, limits))

    n = 0
    rr_inv = inv_pos(model.robroot_T)
    for kind, v, tool, base in points:
        f = v.f
        if kind == "axes":
            n += within([f[k] for k in _AXES])
            continue
        T = frame_to_matrix(*(float(f[k]) for k in _CART))
        if base is not None:
            T = frame_to_matrix(*base) @ T
        if tool is not None:
            T = T @ inv_pos(frame_to_matrix(*tool))
        try:
            sols = model.kin.solutions(rr_inv @ T)
        except Exception:  # noqa: BLE001 - a pose the kinematics refuses is not reached
            continue
        n += any(within(q) for q in sols)
    return n


def choose_robot(program: Path, probe: Callable[[], tuple], workspace=None) -> Choice | None:
    """The robot of the project's library (robot/machine.py ``library_robots``) for a run of
    `program` with ``--inputs auto`` when its backup has no machine data: the one that reaches
    the most of the backup's taught points (:func:`taught_points`, :func:`reaches`); the KR 6
    R900 (the default) wins a tie, then the library's order. `probe()` gives ``(loaded,
    value_of)``: the program loaded on the default robot and a reader of its globals. None
    outside a backup, for a backup with its own machine data, or when no robot reaches more
    than the default. One choice per backup and process."""

    root = backup_of(spelled_within(program, workspace), spelled(workspace) if workspace else None)
    if root is None or machine_data_file(root) is not None:
        return None
    if root in _CHOICES:
        return _CHOICES[root]
    loaded, value_of = probe()
    points = taught_points(loaded, value_of)
    best = None
    default = reaches(load_machine(), points)
    for name, path in library_robots().items():
        try:
            machine = load_robot(path)
        except MachineDataError:
            continue
        n = reaches(machine, points)
        if n > default and (best is None or n > best.reached):
            best = Choice(machine, n, len(points))
    _CHOICES[root] = best
    return best
