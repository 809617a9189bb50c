"""One MuJoCo scene for a cell of several robots (issue 89; docs/cells.md): every robot's own model
(robot/mjcf.py ``build_mjcf``, the one a single run builds from its machine data, with its own cell
file's bodies and tool where it has them) placed in the cell's world, and the contacts between
the robots.

Each robot's model is attached (MuJoCo's ``MjSpec.attach``) under a frame at its ``base`` (X, Y,
Z mm, A, B, C deg: ``Rz(A)·Ry(B)·Rx(C)``, KUKA's order), its names prefixed ``NAME/``
(``R1/link_4``, ``R1/cell:table``). The base places the robot's ``$WORLD``, as
interp/cellzones.py places its TCP: a robot whose machine data give ``$ROBROOT`` stands at
``base : $ROBROOT``, and its cell file's bodies (given in its ``$WORLD``) at ``base : frame``.
Every robot keeps its own kinematics and its own MuJoCo arm for its read-back
(robot/readback.py); this scene only holds the robots side by side for the cell's check and view.
The robots' models (:class:`RobotModels`: each MJCF built once, one MuJoCo spec per distinct
model) serve both :func:`pairs_in_reach` and the scene.

**Contacts.** The scene reports a contact between two robots only: robot k's links, base and
tool carry the contact type bit ``1 << k`` and take contacts from every other robot's bit, so
a robot never touches itself here (its own links and its own cell are its single run's check,
robot/collision.py); a robot's cell bodies take contacts from every other robot and give none.
The floors are left out (each robot stands on its own). A contact is a signed distance below
:data:`robot.collision.CONTACT_MM` (MuJoCo's ``mj_collision`` after ``mj_kinematics``).

Limits: at most :data:`MAX_SCENE_ROBOTS` robots (the contact bits of MuJoCo's 32-bit masks; a
cell file has at most :data:`krl.limits.MAX_CELL_ROBOTS`). Raises ValueError past it and for a
robot named twice.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from .cellbound import CellBound, bound_of
from .collision import CONTACT_MM
from .frames import frame_to_matrix
from .mjcf import build_mjcf, mjcf_assets

#: robots one scene holds (one contact bit each in MuJoCo's int masks)
MAX_SCENE_ROBOTS = 30


@dataclass(frozen=True)
class Placement:
    """One robot of the scene: its ``name`` (the cell file's), its machine data
    (robot/machine.py MachineData), its ``base`` in the cell's world (X, Y, Z mm, A, B, C deg) and
    its own cell's bodies and tool (robot/collision.py CellGeometry, or None)."""
    name: str
    machine: Any
    base: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    geometry: Any = None


@dataclass(frozen=True)
class Touch:
    """Two robots' bodies touching: each ``(robot, body)`` (``link_4``, ``base``, ``tool``,
    ``cell:table`` of that robot's own cell) and the signed distance (mm, negative: overlap)."""
    first: tuple[str, str]
    second: tuple[str, str]
    distance_mm: float


class CellScene:
    """The cell's one MuJoCo scene (module docstring): :meth:`set_axes` places a robot's axes,
    :meth:`touches` gives the contacts between robots now.

    Attributes: ``model``, ``data`` (MuJoCo's), ``names`` (the robots' names in order)."""

    def __init__(self, placements: list[Placement], models: "RobotModels | None" = None) -> None:
        names = [p.name for p in placements]
        if len(names) > MAX_SCENE_ROBOTS:
            raise ValueError(f"{len(names)} robots in one scene, more than the limit of {MAX_SCENE_ROBOTS}")
        if len(set(names)) != len(names):
            raise ValueError("a robot is named twice in the scene")
        self.names = names
        models = models if models is not None else RobotModels(placements)
        spec = mujoco.MjSpec()
        # a robot's model is copied in by attach: robots of the same model attach one spec
        spec.copy_during_attach = True
        everyone = (1 << len(names)) - 1
        for k, p in enumerate(placements):
            child = _contact_bits(models.specs[k], 1 << k, everyone & ~(1 << k))
            spec.option.timestep, spec.option.integrator = child.option.timestep, child.option.integrator
            T = frame_to_matrix(*p.base)
            x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
            frame = spec.worldbody.add_frame(pos=T[:3, 3] / 1000.0, quat=[w, x, y, z])
            spec.attach(child, prefix=f"{p.name}/", frame=frame)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        self._spec, self._xml = spec, None
        self._axes = {p.name: _axis_map(self.model, p) for p in placements}
        #: every robot's axes' qpos addresses side by side, in the robots' order (copy_all)
        self._all = np.array([a for p in placements
                              for a in _addresses(self._axes[p.name][0], len(self._axes[p.name][2]))], dtype=int)
        self._labels = [_label(self.model, g) for g in range(self.model.ngeom)]
        #: each geom's robot (its index in names)
        self._robot_of = np.array([names.index(label[0]) for label in self._labels], dtype=int)
        self._robot_ids = self._robot_of.tolist()      # (the same, for a loop: :meth:`contacts`)
        for p in placements:
            self.set_axes(p.name, list(p.machine.home_all))
        mujoco.mj_kinematics(self.model, self.data)
        #: the pairs of robots (indices into names) whose bodies can meet in some pose
        self.pairs = _pairs_in_reach(self.model, names, self._robot_of, [frame_to_matrix(*p.base)[:3, 3] / 1000.0
                                                                   for p in placements])

    @property
    def xml(self) -> str:
        """The scene's MJCF (MuJoCo's ``MjSpec.to_xml``), written when first asked for (1.4 ms
        for four robots: a cell's run does not ask)."""
        if self._xml is None:
            self._xml = self._spec.to_xml()
        return self._xml

    def set_axes(self, name: str, axes: Any) -> None:
        """Robot `name` at `axes` (its model's order: A1..An deg, a linear axis mm, then E1..Em
        mm or deg; as robot/readback.py ``ReadBack.axes``); the scene's kinematics follow at the
        next :meth:`touches`."""
        adr, scale, buf = self._axes[name]
        np.multiply(scale, np.asarray(axes, dtype=float)[:len(buf)], out=buf)
        self.data.qpos[adr] = buf

    def scale(self, name: str) -> np.ndarray:
        """The factors from robot `name`'s axes as :meth:`set_axes` takes them (deg, mm) to the
        scene's joint values as :meth:`copy` takes them (rad, m; with the joint's sign)."""
        return self._axes[name][1]

    def bound(self) -> CellBound | None:
        """The bound that proves this scene's robots apart from a reference pose
        (robot/cellbound.py), its poses :meth:`copy_all`'s values; None when it cannot bound."""
        return bound_of(self.model, self._robot_of, self._all, self.pairs)

    def follow(self, name: str, arm) -> "np.ndarray | None":
        """The addresses in `arm`'s ``qpos`` (robot/mjcf.py ArmModel: robot `name`'s own MuJoCo arm,
        built by the same ``build_mjcf`` from the same machine data: the same joints, signs and
        units as this scene's copy of it) of robot `name`'s axes, in :meth:`set_axes`' order:
        ``copy(name, arm.data.qpos[addresses])`` places the robot as ``set_axes`` of its axes read
        back would, without the round trip through KUKA's units. None when a joint is missing."""
        adr, _scale, buf = self._axes[name]
        joint_at = {int(self.model.jnt_qposadr[j]): self.model.joint(j).name for j in range(self.model.njnt)}
        try:
            # the scene's joint R1/joint_a1 is the arm's joint_a1
            return np.array([int(arm.model.joint(joint_at[a].partition("/")[2]).qposadr[0])
                             for a in _addresses(adr, len(buf))], dtype=int)
        except (KeyError, ValueError):
            return None

    def copy(self, name: str, qpos: np.ndarray) -> None:
        """Robot `name` at the joint values `qpos` (MuJoCo's units, :meth:`follow`'s order)."""
        self.data.qpos[self._axes[name][0]] = qpos

    def copy_all(self, qpos: np.ndarray) -> None:
        """Every robot at the joint values `qpos`: each robot's :meth:`copy` values side by side,
        in the robots' order (one assignment)."""
        self.data.qpos[self._all] = qpos

    def place(self, qpos: np.ndarray) -> None:
        """Every robot at the joint values `qpos` (:meth:`copy_all`'s) and the scene's kinematics
        computed there (MuJoCo's ``mj_kinematics``: ``data.geom_xpos``, ``xanchor``, ``xaxis``),
        its contacts not (:meth:`contacts`)."""
        self.copy_all(qpos)
        mujoco.mj_kinematics(self.model, self.data)

    def touches(self) -> list[Touch]:
        """The contacts between two robots (module docstring) at the axes set: at most one per
        pair of robots (the deepest), in the order of the robots."""
        mujoco.mj_kinematics(self.model, self.data)
        return self.contacts()

    def contacts(self) -> list[Touch]:
        """:meth:`touches` with the kinematics already computed at the axes set (:meth:`place`)."""
        data = self.data
        mujoco.mj_collision(self.model, data)
        if not data.ncon:
            return []
        # the contacts read out once as lists, then a loop (since 2026-11-30): where robots touch
        # a cycle has a few contacts, and numpy's twenty calls on such short arrays cost more than
        # the loop (a hundred contacts where robots stand in one place: the loop about as long)
        con = data.contact
        deepest: dict = {}          # pair of robots -> (mm, first geom, second geom): the deepest contact
        robot_of = self._robot_ids
        for d, g, h in zip(con.dist.tolist(), con.geom1.tolist(), con.geom2.tolist()):
            d *= 1000.0
            if not d < CONTACT_MM:
                continue
            a, b = robot_of[g], robot_of[h]
            if a > b:
                a, b, g, h = b, a, h, g
            best = deepest.get((a, b))
            if best is None or d < best[0]:     # (the first of equally deep ones)
                deepest[(a, b)] = (d, g, h)
        labels = self._labels
        return [Touch(labels[g], labels[h], d) for _pair, (d, g, h) in sorted(deepest.items())]


class RobotModels:
    """Each robot of `placements`' own model (robot/mjcf.py ``build_mjcf``, with its cell's bodies
    and tool, without its floor, its keyframe gone), built once for :func:`pairs_in_reach` and the
    :class:`CellScene` both (before 2026-11-29 each built them again: for four KR 6, nine MJCF
    texts and five parses where four texts and one parse do). ``specs``: each placement's MuJoCo
    spec, one spec for the robots whose MJCF text and meshes are the same (the scene attaches a
    copy of it per robot); :meth:`alone`: a spec compiled alone, once."""

    def __init__(self, placements: list[Placement]) -> None:
        self.specs = []
        parsed: dict[str, tuple] = {}       # MJCF text -> (its assets, its spec): the first robot's
        for p in placements:
            xml, assets = _child_xml(p)
            hit = parsed.get(xml)
            if hit is None or hit[0] != assets:
                hit = (assets, _parsed(xml, assets))
                parsed.setdefault(xml, hit)
            self.specs.append(hit[1])
        self._alone: dict[int, Any] = {}

    def alone(self, k: int):
        """Placement `k`'s model compiled alone (MuJoCo's MjModel; one compile per distinct spec)."""
        spec = self.specs[k]
        if id(spec) not in self._alone:
            self._alone[id(spec)] = spec.compile()
        return self._alone[id(spec)]


def pairs_in_reach(placements: list[Placement], models: RobotModels | None = None) -> list[tuple[int, int]]:
    """The pairs of robots of `placements` (indices) whose bodies can touch in some pose: the
    :attr:`CellScene.pairs` the whole scene would give (the same bound, :func:`_pairs_in_reach`),
    from each distinct robot's model compiled alone (its machine data, cell bodies and tool: one
    compile per distinct model, not the scene of all), so that a cell whose robots stand out of
    each other's reach builds no scene (interp/cellcontacts.py). `models`: the robots' models
    (:class:`RobotModels`, built here when not given; the scene can take the same)."""
    models = models if models is not None else RobotModels(placements)
    radii: dict[int, float] = {}
    radius = []
    for k in range(len(placements)):
        if id(models.specs[k]) not in radii:
            model = models.alone(k)
            radii[id(models.specs[k])] = float(_reach_radii(model, np.zeros(model.ngeom, dtype=int), 1,
                                                            lambda b: float(np.linalg.norm(model.body_pos[b])),
                                                            lambda g: float(np.linalg.norm(model.geom_pos[g])))[0])
        radius.append(radii[id(models.specs[k])])
    return _pairs_apart(np.array(radius), [frame_to_matrix(*p.base)[:3, 3] / 1000.0 for p in placements])


def _pairs_in_reach(model, names: list[str], robot_of: np.ndarray, bases: list) -> list[tuple[int, int]]:
    """The pairs of robots whose bodies can touch in some pose: each robot's bodies lie, in every
    pose, within a sphere about its base (m) of radius the largest over its geoms of the chain's
    offsets from the base (``body_pos``, which a hinge does not change; a slide joint adds its
    range's largest value), the geom's offset in its body and its bounding radius
    (``geom_rbound``); a ball or free joint, or an unbounded slide, makes it unbounded. Two
    robots whose spheres, with CONTACT_MM, do not meet never touch: the scene's check of them is
    skipped (a conservative bound; the contacts of the pairs it keeps are MuJoCo's)."""
    def top(b: int) -> float:       # a robot's top body: its offset from its base
        k = names.index(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b).split("/", 1)[0])
        return float(np.linalg.norm(model.body_pos[b] - bases[k]))

    def fixed(g: int) -> float:     # a geom of the world (a robot's cell body): from its robot's base
        return float(np.linalg.norm(model.geom_pos[g] - bases[robot_of[g]]))
    return _pairs_apart(_reach_radii(model, robot_of, len(bases), top, fixed), bases)


def _reach_radii(model, robot_of: np.ndarray, n: int, top, fixed) -> np.ndarray:
    """Each of the `n` robots' reach radius about its base (m; :func:`_pairs_in_reach`): `robot_of`
    each geom's robot, `top(b)` the distance of top body `b` from its robot's base, `fixed(g)`
    that of geom `g` of the world body (a robot's cell body: the scene attaches it to the world,
    placed by the robot's base; measured from the world's origin, before 2026-11-28, a body
    behind a robot far from the origin could fall outside its sphere)."""
    reach = np.zeros(model.nbody)
    for b in range(1, model.nbody):          # parents come before their children in MuJoCo's order
        parent = model.body_parentid[b]
        step = float(np.linalg.norm(model.body_pos[b]))
        for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
            if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE:
                step += float(np.abs(model.jnt_range[j]).max()) if model.jnt_limited[j] else math.inf
            elif model.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE:
                step = math.inf
        if parent == 0:
            step += top(b) - float(np.linalg.norm(model.body_pos[b]))
        reach[b] = (reach[parent] if parent else 0.0) + step
    radius = np.zeros(n)
    for g in range(model.ngeom):
        body = model.geom_bodyid[g]
        bound = (reach[body] + float(np.linalg.norm(model.geom_pos[g])) if body else fixed(g)) + float(model.geom_rbound[g])
        radius[robot_of[g]] = max(radius[robot_of[g]], bound)
    return radius


def _pairs_apart(radius: np.ndarray, bases: list) -> list[tuple[int, int]]:
    """The pairs (i, j) whose reach spheres (`radius` about `bases`, m), with CONTACT_MM, meet."""
    margin = CONTACT_MM / 1000.0
    return [(i, j) for i in range(len(bases)) for j in range(i + 1, len(bases))
            if float(np.linalg.norm(np.asarray(bases[i]) - np.asarray(bases[j]))) < radius[i] + radius[j] + margin]


def _parsed(xml: str, assets: Any):
    """The MJCF text `xml` with its `assets` as a MuJoCo spec, its keyframe gone (the scene sets
    the axes itself)."""
    child = mujoco.MjSpec.from_string(xml, assets=assets) if assets else mujoco.MjSpec.from_string(xml)
    for key in list(child.keys):
        child.delete(key)
    return child


def _contact_bits(child, mine: int, others: int):
    """The robot's spec `child` (:func:`_parsed`), its geoms given the scene's contact bits
    (module docstring): `mine` on its own bodies, none on its cell's, `others` taken by all."""
    for g in child.geoms:
        if g.name.startswith("cell:"):
            g.contype, g.conaffinity = 0, others
        else:
            g.contype, g.conaffinity = mine, others
    return child


def _child_xml(p: Placement) -> tuple[str, Any]:
    """Robot `p`'s model (robot/mjcf.py ``build_mjcf``, with its cell's bodies and tool, without
    its floor) and its assets (meshes; None without)."""
    geometry = replace(p.geometry, floor=None) if p.geometry is not None else None
    return build_mjcf(p.machine, cell=geometry), mjcf_assets(p.machine, geometry)


def _axis_map(model, p: Placement) -> tuple:
    """The qpos addresses of robot `p`'s axes in the model's order (A1..An, E1..Em: a slice where
    they lie side by side), the factor of each from KUKA's units (deg, mm) to MuJoCo's (rad, m),
    with the joint's sign (robot/mjcf.py ``ArmModel.set_axes``), and a buffer for the values."""
    adr, scale = [], []
    for j in p.machine.joints:
        adr.append(int(model.joint(f"{p.name}/{j.name}").qposadr[0]))
        scale.append(j.kuka_sign * (0.001 if j.kind == "linear" else math.pi / 180.0))
    for e in p.machine.external_axes:
        adr.append(int(model.joint(f"{p.name}/joint_e{e.number}").qposadr[0]))
        scale.append(0.001 if e.linear else math.pi / 180.0)
    where = slice(adr[0], adr[0] + len(adr)) if adr == list(range(adr[0], adr[0] + len(adr))) else np.array(adr)
    return where, np.array(scale), np.empty(len(adr))


def _addresses(where, n: int) -> list[int]:
    """The qpos addresses of :func:`_axis_map`'s `where` (a slice or an array) of `n` axes."""
    return list(range(where.start, where.start + n)) if isinstance(where, slice) else [int(a) for a in where]


def _label(model, g: int) -> tuple[str, str]:
    """(robot, body) of geom `g`: ``base``, ``tool``, ``cell:NAME``, else the link's body name
    (robot/collision.py's names)."""
    name = model.geom(g).name
    robot, _, rest = name.partition("/")
    if rest == "base_geom":
        return robot, "base"
    if rest == "tool" or rest.startswith("cell:"):
        return robot, rest
    body = model.body(int(model.geom_bodyid[g])).name
    return body.partition("/")[0], body.partition("/")[2]


__all__ = ["CellScene", "MAX_SCENE_ROBOTS", "Placement", "RobotModels", "Touch", "pairs_in_reach"]
