"""Collision and reach against the cell (issue 64): the cell file's ``geometry:`` and ``tool:``
keys, and the check of the robot's links, its tool, the cell's bodies and the floor with MuJoCo's
own contacts at every IPO cycle.

The cell file (robot/stimuli.py) describes the cell in ``$WORLD``, mm and degrees::

    geometry:
      - {name: table, box: [800, 600, 40], frame: [900, 0, 380, 0, 0, 0]}      # sizes, centre
      - {name: post, cylinder: [60, 900], frame: [600, -500, 450, 0, 0, 0]}    # radius, height
      - {name: fixture, mesh: fixture.stl, frame: [700, 300, 400, 0, 0, 90]}   # STL beside the file
    tool: {box: [80, 80, 200], frame: [0, 0, 100, 0, 0, 0]}                    # on the flange
    floor: true            # the floor, a plane at Z 0 of $WORLD (the default); a number: its Z (mm); false: none

A box's ``frame`` is its centre (KUKA's X, Y, Z, A, B, C: ``Rz(A)·Ry(B)·Rx(C)``), a cylinder's its
centre with the axis along its Z, a mesh's the origin of the STL's coordinates (in mm). The tool's
frame is in the flange frame. The robot's links are the capsules of its MuJoCo model
(robot/mjcf.py: from joint to joint, their radii from the robot's reach, robot/capsules.py: the KR 6
R900's 141 mm on A1..A3, 79 mm on the wrist, its base column 199 mm), or a description's meshes.

**Contacts checked** (MuJoCo's ``mj_collision`` after ``mj_kinematics``, a contact whose distance
is below :data:`CONTACT_MM`): each link and the tool against each cell body and the floor, the base
column against the cell bodies (it stands on the floor), and link against link except the pairs
MuJoCo filters (a body and its parent) and the pairs already touching at the robot's HOME (the
capsules of neighbouring links overlap at the joints; a pose the robot is delivered in is not a
collision). The first contact found names both bodies (robot/controller.py stops the robot there).

Untrusted input (docs/security.md): at most :data:`MAX_CELL_BODIES` bodies, sizes within
:data:`MAX_SIZE_MM`, a mesh a file of the cell file's folder (no other path) of at most
:data:`MAX_MESH_BYTES`, read here and handed to MuJoCo as bytes.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from .frames import inv_pos

#: limits of a cell file's geometry (docs/security.md)
MAX_CELL_BODIES = 256
MAX_SIZE_MM = 100_000.0
MAX_MESH_BYTES = 16 * 1024 * 1024
#: a contact closer than this (mm, MuJoCo's signed distance) is a collision
CONTACT_MM = 0.0
_NAME = re.compile(r"^[A-Za-z0-9_.\- ]{1,64}$")


class GeometryError(ValueError):
    """A ``geometry:``/``tool:`` entry the model cannot take (the message names it)."""


@dataclass(frozen=True)
class Body:
    """One body of the cell (or the tool): ``shape`` box (sizes X, Y, Z mm), cylinder (radius,
    height mm) or mesh (``mesh``: the STL's bytes), at ``frame`` (X, Y, Z, A, B, C)."""

    name: str
    shape: str
    size: tuple[float, ...]
    frame: tuple[float, ...]
    mesh: bytes = b""


@dataclass(frozen=True)
class CellGeometry:
    """The cell's bodies in ``$WORLD``, the tool on the flange (or None) and the floor: None (no
    floor) or its Z in ``$WORLD`` (mm)."""

    bodies: tuple[Body, ...] = ()
    tool: Body | None = None
    floor: float | None = 0.0

    @property
    def empty(self) -> bool:
        return not self.bodies and self.tool is None

    # the MJCF fragments robot/mjcf.py ``build_mjcf(cell=...)`` places (it calls these: no import)
    def mesh_assets(self) -> tuple[str, dict[str, bytes]]:
        return mesh_assets(self)

    def world_geoms(self) -> list[str]:
        return world_geoms(self)

    def tool_geom(self, flange_pos: str, flange_quat: str) -> list[str]:
        return tool_geom(self, flange_pos, flange_quat)


def _numbers(v: Any, n: int, what: str) -> tuple[float, ...]:
    if not isinstance(v, (list, tuple)) or len(v) != n or not all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v):
        raise GeometryError(f"{what} must be a list of {n} numbers")
    return tuple(float(x) for x in v)


def parse_body(item: Any, what: str, folder: Path | None, default_name: str) -> Body:
    """One body of ``geometry:`` (or the ``tool:``) from the cell file; `folder`: the cell file's
    folder, where a mesh must lie. Raises GeometryError naming `what`."""
    if not isinstance(item, dict):
        raise GeometryError(f"{what} must be a mapping (name, box/cylinder/mesh, frame)")
    unknown = sorted(set(item) - {"name", "box", "cylinder", "mesh", "frame"})
    if unknown:
        raise GeometryError(f"{what}: unknown key {unknown[0]!r} (name, box, cylinder, mesh, frame)")
    name = str(item.get("name", default_name))
    if not _NAME.match(name):
        raise GeometryError(f"{what}: name {name[:40]!r}: letters, digits, '_', '.', '-', ' ', at most 64")
    shapes = [k for k in ("box", "cylinder", "mesh") if k in item]
    if len(shapes) != 1:
        raise GeometryError(f"{what}: exactly one of box, cylinder, mesh")
    frame = _numbers(item.get("frame", [0, 0, 0, 0, 0, 0]), 6, f"{what}: frame")
    if max(abs(x) for x in frame[:3]) > MAX_SIZE_MM:
        raise GeometryError(f"{what}: frame beyond {MAX_SIZE_MM:g} mm")
    shape = shapes[0]
    if shape == "mesh":
        rel = item["mesh"]
        if not isinstance(rel, str) or folder is None:
            raise GeometryError(f"{what}: mesh must name an STL file beside the cell file")
        p = (folder / rel)
        try:
            p = p.resolve(strict=True)
            inside = p.is_relative_to(folder.resolve())
        except OSError:
            raise GeometryError(f"{what}: mesh {rel!r}: no such file beside the cell file") from None
        if not inside or not p.is_file() or p.suffix.lower() != ".stl":
            raise GeometryError(f"{what}: mesh {rel!r}: an .stl file of the cell file's folder was expected")
        if p.stat().st_size > MAX_MESH_BYTES:
            raise GeometryError(f"{what}: mesh {rel!r}: larger than the limit of {MAX_MESH_BYTES} bytes")
        return Body(name, "mesh", (), frame, p.read_bytes())
    size = _numbers(item[shape], 3 if shape == "box" else 2, f"{what}: {shape}")
    if not all(0.0 < x <= MAX_SIZE_MM for x in size):
        raise GeometryError(f"{what}: {shape} sizes must be above 0 and at most {MAX_SIZE_MM:g} mm")
    return Body(name, shape, size, frame)


def parse_geometry(bodies: Any, tool: Any, floor: Any, folder: Path | None) -> CellGeometry:
    """The cell file's ``geometry:`` (a list), ``tool:`` (a mapping) and ``floor:`` (bool)."""
    out = []
    if bodies is not None:
        if not isinstance(bodies, list):
            raise GeometryError("'geometry' must be a list of bodies")
        if len(bodies) > MAX_CELL_BODIES:
            raise GeometryError(f"'geometry': {len(bodies)} bodies, more than the limit of {MAX_CELL_BODIES}")
        for i, item in enumerate(bodies):
            out.append(parse_body(item, f"geometry body {i + 1}", folder, f"body{i + 1}"))
        names = [b.name for b in out]
        dup = next((n for n in names if names.count(n) > 1), None)
        if dup is not None:
            raise GeometryError(f"'geometry': two bodies are named {dup!r}")
    t = parse_body(tool, "'tool'", folder, "tool") if tool is not None else None
    if floor is None or floor is True:
        z: float | None = 0.0
    elif floor is False:
        z = None
    elif isinstance(floor, (int, float)) and math.isfinite(floor) and abs(floor) <= MAX_SIZE_MM:
        z = float(floor)
    else:
        raise GeometryError(f"'floor' must be true, false or its Z in $WORLD (mm, within {MAX_SIZE_MM:g})")
    return CellGeometry(tuple(out), t, z)


# ------------------------------------------------------------------ MJCF fragments (robot/mjcf.py)
def _quat(frame) -> str:
    a, b, c = (math.radians(v) for v in frame[3:])
    x, y, z, w = Rotation.from_euler("ZYX", [a, b, c]).as_quat()
    return " ".join(repr(float(v)) for v in (w, x, y, z))


def _geom(body: Body, name: str, contype: int, conaffinity: int, rgba: str) -> str:
    pos = " ".join(repr(v / 1000.0) for v in body.frame[:3])
    if body.shape == "box":
        size = " ".join(repr(v / 2000.0) for v in body.size)
        kind = f'type="box" size="{size}"'
    elif body.shape == "cylinder":
        kind = f'type="cylinder" size="{body.size[0] / 1000.0!r} {body.size[1] / 2000.0!r}"'
    else:
        kind = f'type="mesh" mesh="{name}"'
    return (f'<geom name="{name}" {kind} pos="{pos}" quat="{_quat(body.frame)}" contype="{contype}" '
            f'conaffinity="{conaffinity}" rgba="{rgba}"/>')


#: contact bits: robot links (1), the base column (8); cell bodies and the floor only receive
ROBOT_BITS = (1, 1)
BASE_BITS = (8, 1)
CELL_BITS = (0, 1 | 8)
FLOOR_BITS = (0, 1)


def mesh_assets(cell: CellGeometry) -> tuple[str, dict[str, bytes]]:
    """The ``<asset>`` lines and MuJoCo's assets (file name -> bytes) of the cell's meshes."""
    lines, assets = [], {}
    for i, b in enumerate(list(cell.bodies) + ([cell.tool] if cell.tool is not None else [])):
        if b.shape == "mesh":
            fname = f"cellmesh{i}.stl"
            assets[fname] = b.mesh
            lines.append(f'    <mesh name="{_geom_name(b, i, cell)}" file="{fname}" scale="0.001 0.001 0.001"/>')
    return "\n".join(lines), assets


def _geom_name(b: Body, i: int, cell: CellGeometry) -> str:
    return "tool" if b is cell.tool else f"cell:{b.name}"


def world_geoms(cell: CellGeometry) -> list[str]:
    """The ``<geom>`` lines of the cell's bodies and the floor (in ``<worldbody>``)."""
    out = []
    if cell.floor is not None:
        out.append(f'<geom name="floor" type="plane" size="0 0 1" pos="0 0 {cell.floor / 1000.0!r}" '
                   f'contype="{FLOOR_BITS[0]}" conaffinity="{FLOOR_BITS[1]}" rgba="0.8 0.8 0.8 0.3"/>')
    for i, b in enumerate(cell.bodies):
        out.append(_geom(b, _geom_name(b, i, cell), *CELL_BITS, "0.4 0.6 0.4 0.6"))
    return out


def tool_geom(cell: CellGeometry, flange_pos: str, flange_quat: str) -> list[str]:
    """The tool's body on the last link: the flange frame (the site ``tool0``'s pos/quat), the
    tool's geom in it."""
    if cell.tool is None:
        return []
    return [f'<body name="tool" pos="{flange_pos}" quat="{flange_quat}">',
            "  " + _geom(cell.tool, "tool", *ROBOT_BITS, "0.7 0.7 0.2 0.8"), "</body>"]


# ------------------------------------------------------------------ the check
@dataclass
class Contact:
    """A collision: the two bodies (``link_3``, ``tool``, ``cell:table``, ``floor``, ``base``) and
    the signed distance (mm)."""

    a: str
    b: str
    distance_mm: float


@dataclass
class CollisionChecker:
    """MuJoCo's contacts of the robot in its cell at given axes (see the module docstring).

    Built from the robot model and the cell (robot/mjcf.py ``ArmModel(cell=...)``); the pairs
    touching at HOME are excluded once, at construction."""

    machine: Any
    cell: CellGeometry
    arm: Any = None
    excluded: set = field(default_factory=set)

    def __post_init__(self) -> None:
        # deferred: tools/startup_bench.py, krl check --reach +91 ms at the top (2026-11-26)
        from .mjcf import ArmModel  # noqa: PLC0415

        self.arm = ArmModel(self.machine, cell=self.cell)
        self._names = [self._body_label(self.arm.model, g) for g in range(self.arm.model.ngeom)]
        self.arm.set_axes(self.machine.home_all)
        self.excluded = {frozenset((c.a, c.b)) for c in self._contacts()
                         if not ({c.a, c.b} & {"floor"} or any(x.startswith("cell:") for x in (c.a, c.b)))}
        if self.excluded:
            # the pairs touching at HOME never make contacts (MuJoCo's <exclude>): a check costs
            # mj_collision alone while nothing touches
            body = {"base": "base_link"}
            pairs = sorted(tuple(sorted(body.get(x, x) for x in p)) for p in self.excluded)
            self.arm = ArmModel(self.machine, cell=self.cell, exclude=pairs)
            self._names = [self._body_label(self.arm.model, g) for g in range(self.arm.model.ngeom)]
        self._last: bytes | None = None

    @staticmethod
    def _body_label(m, g: int) -> str:
        name = m.geom(g).name
        if name in ("floor", "tool") or name.startswith("cell:"):
            return name
        if name == "base_geom":
            return "base"
        body = m.body(int(m.geom_bodyid[g])).name
        return body

    def _contacts(self) -> list[Contact]:
        mj = self.arm._mj
        d = self.arm.data
        mj.mj_collision(self.arm.model, d)
        out = []
        for i in range(d.ncon):
            c = d.contact[i]
            if c.dist * 1000.0 < CONTACT_MM:
                out.append(Contact(self._names[c.geom1], self._names[c.geom2], float(c.dist) * 1000.0))
        return out

    def check(self, axes: np.ndarray) -> Contact | None:
        """The first collision at the model axes `axes` (A1..An, E1..Em), or None (also for the
        axes of the last call without a collision: a robot at rest is not checked again)."""
        key = axes.tobytes() if isinstance(axes, np.ndarray) else None
        if key is not None and key == self._last:
            return None
        self.arm.set_axes(axes)
        for c in self._contacts():
            if c.a != c.b and frozenset((c.a, c.b)) not in self.excluded:
                self._last = None
                return c
        self._last = key
        return None


def motion_contact(kind: str, q0: np.ndarray, q1: np.ndarray, tool_T: np.ndarray, base_T: np.ndarray, model: Any,
                   checker: CollisionChecker, samples: int) -> tuple[Contact, np.ndarray] | None:
    """The first contact along one motion from the axes `q0` to `q1` (model vectors), sampled at
    `samples` poses: a PTP linear in every axis, a LIN a straight TCP line with the orientation
    turned evenly (the inverse kinematics from the previous sample; robot/planner.py
    ``RobotModel``); with the TCP in ``$WORLD`` (mm). None without a contact, or when the line
    leaves the robot's reach (a run says why)."""
    base_inv = inv_pos(base_T)
    if kind in ("PTP", "SPTP"):
        qs = [q0 + (q1 - q0) * u for u in np.linspace(0.0, 1.0, samples + 1)[1:]]
    else:
        T0 = model.tcp(q0, tool_T, base_inv)
        T1 = model.tcp(q1, tool_T, base_inv)
        slerp = Slerp([0.0, 1.0], Rotation.from_matrix([T0[:3, :3], T1[:3, :3]]))
        qs, ref = [], q0
        for u in np.linspace(0.0, 1.0, samples + 1)[1:]:
            T = np.eye(4)
            T[:3, :3] = slerp([u]).as_matrix()[0]
            T[:3, 3] = T0[:3, 3] + (T1[:3, 3] - T0[:3, 3]) * u
            try:
                ref = model.ik(T, inv_pos(tool_T), base_T, None, None, ref)
            except Exception:  # noqa: BLE001 - robot/errors.py's: a pose of the line out of reach
                return None
            qs.append(ref)
    for q in qs:
        c = checker.check(np.asarray(q, dtype=float))
        if c is not None:
            return c, (base_T @ model.tcp(q, tool_T, base_inv))[:3, 3]
    return None


__all__ = ["Body", "CellGeometry", "CollisionChecker", "Contact", "GeometryError", "MAX_CELL_BODIES",
           "MAX_MESH_BYTES", "MAX_SIZE_MM", "motion_contact", "parse_body", "parse_geometry"]
