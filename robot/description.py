"""A robot description (URDF, or a xacro file with its package tree) as the robot model:
``krl run --robot kr6r900sixx.xacro``, ``krl robot show FILE.urdf`` (issue 64).

Read with maintained libraries: ``xacro`` expands a ``.xacro`` (its ``$(find PKG)`` answered by the
description's own tree: the nearest folder above the file that holds a folder ``PKG``; ROS's package
index is not needed), ``yourdfpy`` parses the URDF, ``trimesh`` loads each link's mesh (its collision
mesh, else its visual one: STL, or COLLADA through pycollada). The chain ``base_link`` .. ``tool0``
must be KUKA's articulated arm (six revolute joints, ``q = radians(A_i)`` as both public KUKA
description repositories define it: robot-model.md §3): its geometry at A = 0 is read in the terms of
KUKA's machine data (``$TIRORO.Z``, ``$LENGTH_A``, ``$LENGTH_B``, ``$TX3P3.X/.Z``, ``$TFLWP.Z``, as
robot/catalogue.py's entries are), robot/mada.py builds the model from them, and the model's forward
kinematics must reproduce the description's own chain at 20 random poses within 0.01 mm, or the file
is refused (MachineDataError naming what differs). Limits and speeds are the joints'. A mesh file
the tree lacks (../shared holds some descriptions without their meshes) leaves its link a capsule;
``krl robot show`` lists the meshes read and those missing.

The meshes are kept in ``MachineData.raw["meshes"]``: link name (``base_link``, ``link_1`` ..) ->
STL bytes (binary, metres) in the model's link frame (robot/mjcf.py's bodies, robot/urdf.py's links):
MuJoCo's link geoms (collision against the cell) and the pendant's 3D view draw them instead of the
capsules.

Untrusted input (docs/security.md): a description of at most :data:`MAX_DESCRIPTION_BYTES`; a mesh a
file of the description's tree (``package://PKG/...`` or a relative path; no other path) of at most
robot/collision.py ``MAX_MESH_BYTES``, at most :data:`MAX_MESH_FACES` triangles once loaded.
"""

from __future__ import annotations

import io
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from scipy.spatial.transform import Rotation

from .axismap import REDUNDANT_SLOTS, ROBOT_KEYS
from .catalogue import arm_values
from .frames import matrix_to_frame
from .kinematics import Kinematics
from .machine import JointData, load_machine
from .madavalues import MachineDataError
import xacro
import xacro.substitution_args as subst
import trimesh
from .collision import MAX_MESH_BYTES
import yourdfpy

MAX_DESCRIPTION_BYTES = 4 * 1024 * 1024
MAX_MESH_FACES = 400_000
#: the largest difference (mm) between the model's flange and the description's at the check's poses
FK_TOLERANCE_MM = 0.01
SUFFIXES = (".urdf", ".xacro")


def _tree_root(path: Path, pkg: str) -> Path | None:
    """The folder that holds the package `pkg` above `path` (its own tree), or None."""
    for d in path.resolve().parents:
        cand = d / pkg
        if cand.is_dir():
            return cand
    return None


def _urdf_text(path: Path) -> str:
    if path.stat().st_size > MAX_DESCRIPTION_BYTES:
        raise MachineDataError(f"{path}: larger than the limit of {MAX_DESCRIPTION_BYTES} bytes")
    if path.suffix.lower() != ".xacro":
        return path.read_text(encoding="utf-8")

    def find(pkg: str) -> str:
        found = _tree_root(path, pkg)
        if found is None:
            raise MachineDataError(f"{path}: $(find {pkg}): no folder {pkg} above the file")
        return str(found)
    old = subst._eval_find         # ROS's package index answers $(find) in xacro; here the tree does
    subst._eval_find = find
    try:
        return xacro.process_file(str(path)).toxml()
    except MachineDataError:
        raise
    except Exception as exc:  # noqa: BLE001 - xacro's errors name the file and the problem
        raise MachineDataError(f"{path}: xacro: {exc}") from None
    finally:
        subst._eval_find = old


def _chain(urdf: Any, where: str) -> tuple[list, np.ndarray, list[str]]:
    """(revolute joints base_link -> tool0 as (origin 4x4 m, axis, lower, upper, velocity), the
    fixed transform from the last joint to tool0 (m), the link A1 turns on and the link after each
    joint)."""
    by_child = {j.child: j for j in urdf.joint_map.values()}
    tip = next((n for n in ("tool0", "flange") if n in urdf.link_map), None)
    if tip is None:
        raise MachineDataError(f"{where}: no link tool0 (KUKA's flange frame in the ROS-Industrial descriptions)")
    seq, link = [], tip
    while link in by_child:
        seq.append(by_child[link])
        link = by_child[link].parent
    seq.reverse()
    joints, fixed, links = [], np.eye(4), []
    for j in seq:
        origin = np.asarray(j.origin if j.origin is not None else np.eye(4), dtype=float)
        if j.type in ("revolute", "continuous"):
            if joints and not np.allclose(fixed, np.eye(4)):
                origin = fixed @ origin
            fixed = np.eye(4)
            lim = j.limit
            joints.append((origin, np.asarray(j.axis, dtype=float), lim.lower, lim.upper, lim.velocity))
            links.append(j.child)
        elif j.type == "fixed":
            if joints:                        # a fixed frame before A1 (world -> base_link) is $ROBROOT's
                fixed = fixed @ origin
        else:
            raise MachineDataError(f"{where}: joint {j.name} is {j.type}: an arm of six revolute joints was expected")
    if len(joints) not in (len(ROBOT_KEYS), len(REDUNDANT_SLOTS)):
        raise MachineDataError(f"{where}: {len(joints)} revolute joints between the root and {tip}: six (an arm) "
                               f"or seven (a redundant arm) were expected")
    first = next(j for j in seq if j.type in ("revolute", "continuous"))
    return joints, fixed, [first.parent] + links


def _forward(joints, tool: np.ndarray, axes_deg) -> np.ndarray:
    T = np.eye(4)
    frames = []
    for (origin, axis, *_), a in zip(joints, axes_deg):
        J = np.eye(4)
        J[:3, :3] = Rotation.from_rotvec(axis * math.radians(a)).as_matrix()
        T = T @ origin @ J
        frames.append(T.copy())
    out = T @ tool
    out[:3, 3] *= 1000.0
    return out, frames


def _geometry(joints, tool, where: str) -> dict[str, float]:
    """KUKA's arm parameters (mm) of the chain at A = 0 (robot/data/catalogue.yaml's header)."""
    T = np.eye(4)
    pts, dirs = [], []
    for origin, axis, *_ in joints:
        T = T @ origin
        pts.append(T[:3, 3] * 1000.0)
        dirs.append(T[:3, :3] @ axis)
    flange = (T @ tool)[:3, 3] * 1000.0
    want = [(0, 0, -1), (0, 1, 0), (0, 1, 0), (-1, 0, 0), (0, 1, 0), (-1, 0, 0)]
    for i, (d, w) in enumerate(zip(dirs, want)):
        if not np.allclose(d, w, atol=1e-6):
            raise MachineDataError(f"{where}: joint {i + 1} turns about {np.round(d, 6).tolist()} at A = 0, not "
                                   f"KUKA's {list(w)} (robot-model.md section 3: not KUKA's angles)")
    p2, p3, p4, p5 = pts[1], pts[2], pts[3], pts[4]
    return {"TIRORO_Z": p2[2], "LENGTH_A": p2[0], "LENGTH_B": p3[0] - p2[0], "TX3P3_X": p5[0] - p3[0],
            "TX3P3_Z": p4[2] - p3[2], "TFLWP_Z": flange[0] - p5[0]}


def _meshes(urdf: Any, path: Path, joints, links: list[str], machine, missing: list[str]) -> dict[str, bytes]:
    """The links' meshes as STL (m) in the model's link frames (see the module docstring); a mesh
    file the tree lacks is listed in `missing` (its link keeps its capsule)."""

    out: dict[str, bytes] = {}
    # the description's link frames at A = 0, and the model's (translation-only joint origins)
    urdf_T = [np.eye(4)]
    T = np.eye(4)
    for origin, *_ in joints:
        T = T @ origin
        urdf_T.append(T.copy())
    ours = [np.eye(4)]
    acc = np.zeros(3)
    for j in machine.joints:
        acc = acc + np.asarray(j.origin_mm) / 1000.0
        M = np.eye(4)
        M[:3, 3] = acc
        ours.append(M)
    for k, (link_name, our_name) in enumerate(zip(links, ["base_link"] + [f"link_{i + 1}" for i in range(len(joints))])):
        link = urdf.link_map.get(link_name)
        if link is None:
            continue
        shapes = [c for c in link.collisions if c.geometry is not None and c.geometry.mesh is not None] or \
                 [v for v in link.visuals if v.geometry is not None and v.geometry.mesh is not None]
        parts = []
        for s in shapes:
            fname = s.geometry.mesh.filename
            try:
                f = _mesh_file(fname, path)
            except FileNotFoundError:
                missing.append(f"{our_name}: {fname}")   # the link keeps its capsule
                continue
            if f.stat().st_size > MAX_MESH_BYTES:
                raise MachineDataError(f"{path}: mesh {fname}: larger than the limit of {MAX_MESH_BYTES} bytes")
            try:
                mesh = trimesh.load(str(f), force="mesh")
            except Exception as exc:  # noqa: BLE001 - trimesh's errors name the problem
                raise MachineDataError(f"{path}: mesh {fname}: {exc}") from None
            if len(mesh.faces) > MAX_MESH_FACES:
                raise MachineDataError(f"{path}: mesh {fname}: {len(mesh.faces)} triangles, more than {MAX_MESH_FACES}")
            scale = s.geometry.mesh.scale
            if scale is not None:
                mesh.apply_scale(np.asarray(scale, dtype=float))
            origin = np.asarray(s.origin if s.origin is not None else np.eye(4), dtype=float)
            mesh.apply_transform(np.linalg.inv(ours[k]) @ urdf_T[k] @ origin)
            parts.append(mesh)
        if parts:
            whole = trimesh.util.concatenate(parts) if len(parts) > 1 else parts[0]
            out[our_name] = whole.export(file_type="stl")
    return out


def _mesh_file(fname: str, path: Path) -> Path:
    """A mesh's file: ``package://PKG/rel`` in the description's tree, or a path relative to the
    description; refused outside that tree."""
    if fname.startswith("package://"):
        pkg, _, rel = fname[len("package://"):].partition("/")
        root = _tree_root(path, pkg)
        if root is None:
            raise MachineDataError(f"{path}: mesh {fname}: no folder {pkg} above the description")
        f, top = root / rel, root.parent
    elif "://" in fname or fname.startswith("/"):
        raise MachineDataError(f"{path}: mesh {fname}: a package:// or relative path was expected")
    else:
        f, top = path.parent / fname, path.parent
    try:
        f = f.resolve(strict=True)
    except OSError:
        raise FileNotFoundError(fname) from None
    if not f.is_relative_to(top.resolve()) or not f.is_file():
        raise MachineDataError(f"{path}: mesh {fname}: outside the description's tree")
    return f


def _redundant_machine(name: str, joints, tool: np.ndarray, where: str, dynamics: Any) -> Any:
    """The model of a seven-axis arm's description (KUKA's LBR iiwa): its joints as the description
    gives them (origins, axes, limits, speeds; robot/kinematics/redundant.py solves it), its flange
    the description's ``tool0``. What a description does not give is stated in the provenance: each
    axis's acceleration and jerk by robot/mada.py's rules for machine data without them, and the
    Cartesian limits, approximation and in-position values of robot/data/kr6_r900.yaml (J3, the
    redundancy, takes A3's). HOME is the description's zero (the LBR's upright position); no meshes
    are read (the links are capsules)."""
    base = load_machine()
    n = len(joints)

    def per_axis(vals) -> tuple[float, ...]:
        """A six-axis value per joint: A1..A6's by the joint's E6AXIS component, J3 (E1) A3's."""
        return tuple(float(vals[ROBOT_KEYS.index(k if k in ROBOT_KEYS else "A3")]) for k in REDUNDANT_SLOTS)

    out = []
    for i, (origin, axis, lo, hi, vel) in enumerate(joints):
        vmax = math.degrees(float(vel))
        acc, jerk, rules = dynamics(vmax, float(base.def_flt_ptp))
        rpy = Rotation.from_matrix(origin[:3, :3]).as_euler("xyz")
        out.append(JointData(
            name=f"joint_a{i + 1}", axis=i + 1, limit_deg=(math.degrees(lo), math.degrees(hi)),
            max_speed_deg_s=vmax, max_acc_deg_s2=acc, max_jerk_deg_s3=jerk,
            origin_mm=tuple(float(v) * 1000.0 for v in origin[:3, 3]),     # type: ignore[arg-type]
            joint_axis=tuple(float(v) for v in axis),                        # type: ignore[arg-type]
            urdf_max_speed_deg_s=vmax, parent="base_link" if i == 0 else f"link_{i}", child=f"link_{i + 1}",
            origin_rpy_rad=tuple(float(v) for v in rpy)))                  # type: ignore[arg-type]
    x, y, z, w = Rotation.from_matrix(tool[:3, :3]).as_quat()
    prov = {"joints": f"{where}: origins, axes, limits, velocities", **rules,
            "family": "robot/kinematics/redundant.py (seven revolute joints; J3 carried as E1)",
            "cartesian limits, $APO_DIS_PTP, $IN_POS_MA": "robot/data/kr6_r900.yaml (J3 takes A3's)",
            "home": "derived: the description's zero"}
    zero = (0.0,) * n
    probe = replace(base, joints=tuple(out), home_deg=zero, mastering_deg=zero, chain=None,
                    flange_quat_wxyz=(float(w), float(x), float(y), float(z)),
                    flange_rpy_rad=tuple(float(v) for v in Rotation.from_matrix(tool[:3, :3]).as_euler("xyz")),
                    flange_pos_mm=tuple(float(v) * 1000.0 for v in tool[:3, 3]),
                    robroot_frame=(0.0,) * 6, apo_dis_ptp_deg=per_axis(base.apo_dis_ptp_deg),
                    in_pos_ma_deg=per_axis(base.in_pos_ma_deg), ptp_ramp_deg=(), ptp_friction=(),
                    dynamics=None, external_axes=(), external_kinematics=(), name=name, source=where,
                    trafoname="", raw={"family": "redundant"}, provenance=prov)
    kin = Kinematics(probe)
    flange = kin.forward(zero)
    wrist = kin.joints.joint_point(zero, len(ROBOT_KEYS) - 1)
    return replace(probe, reach_wrist_point_mm=float(np.linalg.norm(wrist - kin.joints.joint_point(zero, 1))),
                   home_flange_pose=tuple(float(v) for v in matrix_to_frame(flange)))


def load_description(path: str | Path, build: Any, dynamics: Any) -> Any:
    """The robot model (robot/machine.py ``MachineData``) of a URDF or xacro description (see the
    module docstring); `build` is robot/mada.py ``build_cited`` (the model of cited machine-data
    values; passed in, as robot/mada.py reads descriptions through this module). Raises
    MachineDataError for a file that cannot be read, a chain that is not KUKA's arm, or a mesh it
    cannot take. `dynamics` is robot/mada.py ``default_dynamics`` (an axis's acceleration and jerk
    by the machine-data rules), which a seven-axis arm's joints need."""

    p = Path(path)
    where = str(p)
    try:
        text = _urdf_text(p)
        urdf = yourdfpy.URDF.load(io.StringIO(text), build_scene_graph=False, load_meshes=False)
    except MachineDataError:
        raise
    except Exception as exc:  # noqa: BLE001 - the parser's errors name the problem
        raise MachineDataError(f"{where}: not a URDF robot description ({type(exc).__name__}: {exc})") from None
    joints, tool, links = _chain(urdf, where)
    name = urdf.robot.name if getattr(urdf, "robot", None) is not None else p.stem
    if len(joints) == len(REDUNDANT_SLOTS):
        return _redundant_machine(name, joints, tool, where, dynamics)
    g = _geometry(joints, tool, where)
    lims = [(math.degrees(lo), math.degrees(hi)) for _, _, lo, hi, _ in joints]
    speeds = [math.degrees(v) for *_, v in joints]
    machine = build(name, arm_values(f"#{name}", g, lims, speeds, where, where), where, where)
    rng = np.random.default_rng(64)
    kin = Kinematics(machine)
    lo = np.array([a for a, _ in lims])
    hi = np.array([b for _, b in lims])
    worst = max(float(np.abs(kin.forward(q) - _forward(joints, tool, q)[0]).max())
                for q in rng.uniform(lo, hi, size=(20, 6)))
    if worst > FK_TOLERANCE_MM:
        raise MachineDataError(f"{where}: the description's chain is not KUKA's standard arm (its flange differs by "
                               f"{worst:.3f} mm from the arm of its geometry at A = 0)")
    missing: list[str] = []
    meshes = _meshes(urdf, p, joints, links, machine, missing)
    prov = dict(machine.provenance)
    prov["meshes"] = (f"{where}: {', '.join(meshes) or 'none'}"
                      + (f"; not in its tree (capsules drawn): {'; '.join(missing)}" if missing else ""))
    return replace(machine, raw={**machine.raw, "meshes": meshes}, provenance=prov)


__all__ = ["FK_TOLERANCE_MM", "MAX_DESCRIPTION_BYTES", "MAX_MESH_FACES", "SUFFIXES", "load_description"]
