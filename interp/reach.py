"""``krl check --reach PROGRAM``: the taught points a robot cannot reach and the motions that
collide with the cell, found without running the program (issue 64).

The program is loaded as ``krl run`` loads it (interp/run.py ``load_program``: its files, data
lists, no controller; the robot — ``--robot``, the cell file's, the backup's own, the KR 6 R900 — and the cell
file's ``geometry:``/``tool:``/``floor:``), and not run. Then:

* **Points**: every POS/E6POS/AXIS/E6AXIS of the program's own data list and of ``$config.dat``
  (XHOME..; a machine-data variable such as ``$H_POS_TOL`` is no point) (interp/scene.py
  ``taught_points``: a pose with the TOOL_DATA and BASE_DATA of its inline form's FDAT) that no
  configuration of the robot reaches within its software limits (any status, turn and ±360°
  variant), each named with its data list's file:line.
* **Motions**: each routine of the program's own module: its PTP/LIN/SPTP/SLIN statements whose target is a taught point, in the
  order they stand (control flow is not followed: a loop's motions are checked once, a branch's
  as if taken), from the previous one's end (HOME before the first): a PTP as the axes move it
  (linear in every axis), a LIN as the TCP moves (a straight line, the orientation turned
  evenly, the inverse kinematics from the previous sample), :data:`SAMPLES` poses each, checked
  with the cell's contacts (robot/collision.py). The first contact of a motion names both
  bodies, the motion's file:line and the TCP. CIRC and spline blocks are not sampled (a run
  checks them: robot/controller.py); a motion whose target is no taught point is skipped.

The run itself checks every IPO cycle (``krl run`` with the same cell file); this check is the
quick look before the robot moves.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from krl.ast import nodes as N
from robot.axismap import CART_KEYS as _CART
from robot.collision import CollisionChecker, motion_contact
from robot.errors import RobotError
from robot.frames import frame_to_matrix, inv_pos
from robot.mada import MachineDataError
from robot.planner import RobotModel
from robot.stimuli import StimulusError
from .run import global_value, load_program, run_spec
from .scene import module_points


#: poses sampled along each motion
SAMPLES = 24


@dataclass
class ReachReport:
    """What :func:`reach_check` found: lines of the problems (``file:line: ...``), the counts."""

    robot: str
    points: int = 0
    motions: int = 0
    problems: list[str] = field(default_factory=list)

    def lines(self) -> list[str]:
        return self.problems + [f"reach: {self.points} taught point(s) and {self.motions} motion(s) checked on "
                                f"{self.robot}; {len(self.problems)} problem(s)"]


#: what :func:`reach_check` raises for a program it cannot load: its robot's machine data, its cell
#: file, the files themselves
REACH_ERRORS = (MachineDataError, StimulusError, OSError, ValueError)


def reach_check(program: Path, robot=None, inputs=None) -> ReachReport:
    """The report of `program` (see the module docstring); `robot` and `inputs` as
    ``krl run --robot`` and ``--inputs`` take them (a cell file gives the geometry). The program
    is loaded (interp/run.py ``load_program``), no controller built."""
    spec = run_spec(program, inputs=inputs, robot=robot, mujoco=False, check=False)
    loaded = load_program(spec)
    machine = spec.robot
    geometry = spec.geometry if spec.geometry is not None else (spec.cell.geometry if spec.cell else None)
    reach = _Reach(RobotModel(machine), [j.limit_deg for j in machine.joints],
                   CollisionChecker(machine, geometry) if geometry is not None else None)
    report = ReachReport(machine.name)
    own = loaded.program.module_of(loaded.program.main_path)
    points = _taught(loaded, own, Path(program).stem)
    home = np.array(reach.model.axes.home, dtype=float)
    for name, (kind, v, tool, base, where) in points.items():
        report.points += 1
        _q, why = reach.pose_axes(kind, v, tool, base, home)
        if why is not None:
            report.problems.append(f"{where}: unreachable: {name} on {machine.name}: {why}")
    if own is not None and own.files.get("src") is not None:
        for r in own.routines.values():
            reach.motions(r, f"{own.files['src']}", points, home, report)
    return report


def _taught(loaded, own, main: str) -> dict[str, tuple]:
    """The taught points of the program `own` (its module) by name: (kind, value, tool, base,
    where: its data list's file:line), the program's own, else $config.dat's (XHOME..)."""
    def value_of(name):
        try:
            return global_value(loaded, main, name)
        except Exception:  # noqa: BLE001 - a name the program lacks
            return None
    tools, bases = value_of("TOOL_DATA"), value_of("BASE_DATA")
    points: dict[str, tuple] = {}
    basis = (Path(__file__).parent / "basis").resolve()
    for m in loaded.program.modules:
        if not m.files.get("dat") or m.datalist is None or basis in Path(m.files["dat"]).resolve().parents:
            continue                        # the project's stand-in system files teach no point
        if m is not own and m.datalist.name.upper() != "$CONFIG":
            continue                        # the program's own data list and $config.dat (XHOME..)
        if not m.loaded:
            loaded.program.ensure_loaded(m)
        decl = {}
        for d in m.datalist.items:
            for nm in getattr(d, "names", ()) or ():
                decl.setdefault(str(nm.name).upper(), d.span.line)
        for name, kind, v, tool, base in module_points(m, tools, bases):
            if name.startswith("$"):
                continue                    # machine data ($H_POS_TOL, $AXIS_HOME..) are no taught points
            if m is own or name not in points:
                points[name] = (kind, v, tool, base, f"{m.files['dat']}:{decl.get(name, 1)}")
    return points


class _Reach:
    """The robot `model` (robot/planner.py RobotModel) within its software `limits` (deg, KRL's
    axis order) and the cell's collision `checker` (robot/collision.py; None: no geometry)."""

    def __init__(self, model, limits, checker) -> None:
        self.model = model
        self.limits = limits
        self.checker = checker

    def within(self, q) -> bool:
        return all(any(lo - 1e-6 <= float(x) + k <= hi + 1e-6 for k in (-360.0, 0.0, 360.0))
                   for x, (lo, hi) in zip(q, self.limits))

    def pose_axes(self, kind, v, tool, base, ref):
        """The axes of a taught point (model vector) from `ref`, or a message why not."""
        f = v.f
        model = self.model
        if kind == "axes":
            amap = model.axes
            q = amap.from_components({k: float(x) for k, x in f.items() if isinstance(x, (int, float))})
            return (q, None) if self.within(q[:amap.n_robot]) else (None, "outside the software limits")
        T = frame_to_matrix(*(float(f[k]) for k in _CART))
        tool_T = frame_to_matrix(*tool) if tool else np.eye(4)
        base_T = frame_to_matrix(*base) if base else np.eye(4)
        world = base_T @ T @ inv_pos(tool_T)
        flange = inv_pos(model.robroot_T) @ world
        if not any(self.within(s) for s in model.kin.solutions(flange)):
            return None, "no configuration of this robot reaches it within its software limits"
        s = int(f["S"]) if isinstance(f.get("S"), (int, float)) else None
        t = int(f["T"]) if isinstance(f.get("T"), (int, float)) else None
        try:
            return model.ik(T, inv_pos(tool_T), base_T, s, t, ref), None
        except RobotError as exc:
            return None, f"with its S {s} and T {t}: {exc.message} (another S/T reaches it)"

    def motions(self, routine, src: str, points: dict, home, report: ReachReport) -> None:
        """Check the motions of `routine` (of the file `src`) to taught `points` in the order
        they stand, from `home`: counted in `report`, a collision added to its problems."""
        q_prev = home
        for node in routine.walk():
            if not isinstance(node, N.Motion) or node.kind not in ("PTP", "LIN", "SPTP", "SLIN"):
                continue
            if not isinstance(node.target, N.Name) or node.target.name.upper() not in points:
                continue
            kind, v, tool, base, _ = points[node.target.name.upper()]
            q1, _why = self.pose_axes(kind, v, tool, base, q_prev)
            report.motions += 1
            if q1 is None:
                continue
            if self.checker is not None:
                hit = motion_contact(node.kind, q_prev, q1, frame_to_matrix(*tool) if tool else np.eye(4),
                                     frame_to_matrix(*base) if base else np.eye(4), self.model, self.checker,
                                     SAMPLES)
                if hit is not None:
                    c, p = hit
                    report.problems.append(f"{src}:{node.span.line}: collision: {node.kind} {node.target.name}: "
                                           f"{c.a} touches {c.b}; TCP X {p[0]:.1f}, Y {p[1]:.1f}, Z {p[2]:.1f} mm "
                                           f"in $WORLD")
            q_prev = q1


__all__ = ["ReachReport", "SAMPLES", "reach_check"]
