"""``krl check --reach PROGRAM``: the taught points a robot cannot reach and the motions that
collide with the cell, found without running the program (issue 64).

The program is loaded as ``krl run`` loads it (interp/run.py ``make_runtime``: its files, data
lists, the robot — ``--robot``, the cell file's, the backup's own, the KR 6 R900 — and the cell
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
from robot.collision import motion_contact
from robot.errors import RobotError
from robot.frames import frame_to_matrix, inv_pos
from robot.mada import MachineDataError
from robot.stimuli import StimulusError
from .run import global_value, make_runtime, run_spec
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
    ``krl run --robot`` and ``--inputs`` take them (a cell file gives the geometry)."""

    rt, _ = make_runtime(run_spec(program, inputs=inputs, robot=robot, mujoco=False, check=False))
    ctl = rt.controller
    model = ctl.model
    report = ReachReport(ctl.machine.name)
    main = Path(program).stem

    def value_of(name):
        try:
            return global_value(rt, main, name)
        except Exception:  # noqa: BLE001 - a name the program lacks
            return None
    tools, bases = value_of("TOOL_DATA"), value_of("BASE_DATA")
    limits = [j.limit_deg for j in ctl.machine.joints]
    amap = model.axes

    def within(q) -> bool:
        return all(any(lo - 1e-6 <= float(x) + k <= hi + 1e-6 for k in (-360.0, 0.0, 360.0))
                   for x, (lo, hi) in zip(q, limits))

    # the taught points: name -> (kind, value, tool, base, where)
    points: dict[str, tuple] = {}           # by name: the program's own, else $config.dat's
    basis = (Path(__file__).parent / "basis").resolve()
    own = rt.program.module_of(rt.program.main_path)
    for m in rt.program.modules:
        if not m.files.get("dat") or m.datalist is None or basis in Path(m.files["dat"]).resolve().parents:
            continue                        # the project's stand-in system files teach no point
        if m is not own and m.datalist.name.upper() != "$CONFIG":
            continue                        # the program's own data list and $config.dat (XHOME..)
        if not m.loaded:
            rt.program.ensure_loaded(m)
        decl = {}
        for d in m.datalist.items:
            for nm in getattr(d, "names", ()) or ():
                decl.setdefault(str(nm.name).upper(), d.span.line)
        for name, kind, v, tool, base in module_points(m, tools, bases):
            if name.startswith("$"):
                continue                    # machine data ($H_POS_TOL, $AXIS_HOME..) are no taught points
            if m is own or name not in points:
                points[name] = (kind, v, tool, base, f"{m.files['dat']}:{decl.get(name, 1)}")

    def pose_axes(kind, v, tool, base, ref):
        """The axes of a taught point (model vector) from `ref`, or a message why not."""
        f = v.f
        if kind == "axes":
            q = amap.from_components({k: float(x) for k, x in f.items() if isinstance(x, (int, float))})
            return (q, None) if within(q[:amap.n_robot]) else (None, "outside the software limits")
        T = frame_to_matrix(*(float(f[k]) for k in _CART))
        tool_T = frame_to_matrix(*tool) if tool else np.eye(4)
        base_T = frame_to_matrix(*base) if base else np.eye(4)
        world = base_T @ T @ inv_pos(tool_T)
        flange = inv_pos(model.robroot_T) @ world
        if not any(within(s) for s in model.kin.solutions(flange)):
            return None, "no configuration of this robot reaches it within its software limits"
        s = int(f["S"]) if isinstance(f.get("S"), (int, float)) else None
        t = int(f["T"]) if isinstance(f.get("T"), (int, float)) else None
        try:
            return model.ik(T, inv_pos(tool_T), base_T, s, t, ref), None
        except RobotError as exc:
            return None, f"with its S {s} and T {t}: {exc.message} (another S/T reaches it)"

    home = np.array(amap.home, dtype=float)
    for name, (kind, v, tool, base, where) in points.items():
        report.points += 1
        _q, why = pose_axes(kind, v, tool, base, home)
        if why is not None:
            report.problems.append(f"{where}: unreachable: {name} on {ctl.machine.name}: {why}")

    checker = ctl.monitor.collision
    for m in [own] if own is not None else []:
        if m.files.get("src") is None:
            continue
        for r in m.routines.values():
            q_prev = home
            for node in r.walk():
                if not isinstance(node, N.Motion) or node.kind not in ("PTP", "LIN", "SPTP", "SLIN"):
                    continue
                if not isinstance(node.target, N.Name) or node.target.name.upper() not in points:
                    continue
                kind, v, tool, base, _ = points[node.target.name.upper()]
                q1, why = pose_axes(kind, v, tool, base, q_prev)
                report.motions += 1
                if q1 is None:
                    continue
                if checker is not None:
                    where = f"{m.files['src']}:{node.span.line}"
                    hit = motion_contact(node.kind, q_prev, q1, frame_to_matrix(*tool) if tool else np.eye(4),
                                         frame_to_matrix(*base) if base else np.eye(4), model, checker, SAMPLES)
                    if hit is not None:
                        c, p = hit
                        report.problems.append(f"{where}: collision: {node.kind} {node.target.name}: {c.a} touches "
                                               f"{c.b}; TCP X {p[0]:.1f}, Y {p[1]:.1f}, Z {p[2]:.1f} mm in $WORLD")
                q_prev = q1
    return report


__all__ = ["ReachReport", "SAMPLES", "reach_check"]
