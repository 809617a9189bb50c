"""MuJoCo model of a robot (:class:`~robot.machine.MachineData`: the KR 6 R900 yaml or a
backup's machine data), generated from its joints (robot-model.md §2, §11), with its external
kinematics (robot/external.py): a track's joint ``joint_e<n>`` carries ``base_link``, a
turntable is a body tree of its own ending in the site ``et<n>_flange``.

The body tree mirrors the URDF chain exactly (joint origins, axes, ranges), so
``qpos = kuka_sign * radians(A_i)`` (= radians(A_i) here, robot-model.md §3; a linear axis, a
SCARA's A3, is a slide joint with ``qpos = kuka_sign * A_i / 1000`` m) and the site ``tool0`` on
the last link is KUKA's flange frame (+Z out of the flange).
Geometry is capsules only, sized from the robot's reach (robot/capsules.py; a description's meshes
instead where it gave them); masses come from the geometry (density 1000 kg/m^3,
invented, robot-model.md §11: link masses are not published).

Two modes (argument ``actuated``):
  * replay (default): no actuators; :meth:`ArmModel.set_axes` writes ``qpos``
    and runs ``mj_kinematics`` (kinematic playback, exact).
  * actuated: per joint a ``position`` actuator (kp) and a separate ``velocity``
    actuator (kv), gravity-compensated links, stepped with
    :meth:`ArmModel.step_actuated` (robot-model.md §11, "Driving along a
    precomputed KRL joint trajectory").

Units at this interface: degrees and mm (MuJoCo itself uses rad and m).
"""

from __future__ import annotations

import ctypes
import glob
import math
import os
from collections.abc import Sequence
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np
from scipy.spatial.transform import Rotation

from .blas import numpy_cblas
from .capsules import capsule_radii, group_of
from .frames import as_matrix, frame_to_matrix, inv_pos
from .machine import MachineData, load_machine
import mujoco

#: Servo gains of the actuated mode (robot-model.md §11: kp 2e4 + kv 400 -> 0.175 deg max error).
DEFAULT_KP = 20000.0
DEFAULT_KV = 400.0
DEFAULT_TIMESTEP_S = 0.001


def _f(v: float) -> str:
    return repr(float(v))


def _vec(v: Sequence[float]) -> str:
    return " ".join(_f(x) for x in v)


def build_mjcf(machine: MachineData | None = None, actuated: bool = False, *,
               kp: float = DEFAULT_KP, kv: float = DEFAULT_KV,
               timestep: float = DEFAULT_TIMESTEP_S, cell: Any = None,
               exclude: Sequence[tuple[str, str]] = ()) -> str:
    """MJCF XML (str) of the arm from the machine data (robot-model.md §2, §11).

    Bodies ``base_link``, ``link_1`` .. ``link_n`` (n the robot's axis count); joints named as
    in the yaml (``joint_a1`` ..), hinges, a linear axis a slide; MuJoCo's world frame is
    ``$WORLD``: ``base_link`` and the site ``robroot`` sit at the machine data's ``$ROBROOT``;
    site ``tool0`` (KUKA flange) on ``link_n``; keyframe ``home``.

    Args:
        machine: machine data; default :func:`~robot.machine.load_machine`.
        actuated: False = kinematic replay model (no actuators); True = adds a
            ``position`` actuator ``a<i>`` (kp) and a ``velocity`` actuator
            ``v<i>`` (kv) per joint, with ``gravcomp`` on the links.
        kp, kv: servo gains (N·m/rad, N·m·s/rad) for the actuated mode.
        timestep: simulation time step, s.
        cell: the cell's geometry (robot/collision.py ``CellGeometry``) or None: with it the links
            take part in contacts, the cell's bodies and the floor are geoms of the world, the tool
            a body on the last link, and the meshes assets (robot/collision.py ``mesh_assets``).
        exclude: pairs of bodies whose contacts MuJoCo leaves out (``<contact><exclude>``).
    """
    m = machine if machine is not None else load_machine()
    joints = m.joints
    gravcomp = ' gravcomp="1"' if actuated else ""
    meshes = robot_meshes(m)
    lines = _mjcf_head(m, timestep, meshes, cell)
    lines.append("  <worldbody>")
    if cell is not None:
        lines += ["    " + g for g in cell.world_geoms()]
    ext_close, rr_attr = _external_bodies(lines, m)
    pad = "  " * ext_close
    lines.append(f'    {pad}<site name="robroot" {rr_attr} size="0.01" rgba="0 0 1 1"/>')
    lines.append(f'    {pad}<body name="base_link" {rr_attr}>')
    # the links' capsules sized from the robot's reach (robot/capsules.py), in metres
    radii = {g: r / 1000.0 for g, r in capsule_radii(m.reach_wrist_point_mm).items()}
    _base_geom(lines, m, meshes, radii, cell)
    indent = "      "
    for i in range(len(joints)):
        indent = _arm_link(lines, m, i, indent, meshes, radii, gravcomp)
    # KUKA flange frame (URDF tool0) on the last link
    fpos = np.array(m.flange_pos_mm) / 1000.0
    lines.append(f'{indent}<site name="tool0" pos="{_vec(fpos)}" quat="{_vec(m.flange_quat_wxyz)}" size="0.01" rgba="0 1 0 1"/>')
    if cell is not None:
        lines += [indent + g for g in cell.tool_geom(_vec(fpos), _vec(m.flange_quat_wxyz))]
    for _ in joints:
        indent = indent[:-2]
        lines.append(f"{indent}</body>")
    lines.append("    </body>")
    for k in range(ext_close, 0, -1):
        lines.append("    " + "  " * (k - 1) + "</body>")
    lines.append("  </worldbody>")
    _mjcf_tail(lines, m, actuated, kp, kv, exclude)
    return "\n".join(lines) + "\n"


def _mjcf_head(m: MachineData, timestep: float, meshes: dict[str, bytes], cell: Any) -> list[str]:
    """The model's first lines: compiler, option, defaults (links in contacts with a cell) and
    the mesh assets (the robot's and the cell's)."""
    contacts = 'contype="1" conaffinity="1"' if cell is not None else 'contype="0" conaffinity="0"'
    lines = [
        f"<mujoco model={quoteattr(m.name)}>",
        '  <compiler angle="radian" autolimits="true"/>',
        f'  <option timestep="{_f(timestep)}" integrator="implicitfast"/>',
        "  <default>",
        f'    <geom {contacts} rgba="1 0.45 0 1" density="1000"/>',
        '    <joint damping="0" armature="0.01"/>',
        "  </default>",
    ]
    assets = [f'    <mesh name="mesh_{link}" file="robot_{link}.stl"/>' for link in meshes]
    if cell is not None:
        cell_assets, _ = cell.mesh_assets()
        if cell_assets:
            assets.append(cell_assets)
    if assets:
        lines += ["  <asset>", *assets, "  </asset>"]
    return lines


def _external_bodies(lines: list[str], m: MachineData) -> tuple[int, str]:
    """The external kinematics' bodies into lines (robot/external.py): a ROBROOT kinematic
    (#ERSYS) carries base_link, a BASE kinematic (#EASYS..) is a body tree of its own; their
    joints are named joint_e<n>. Returns (the bodies left open for base_link, the placement of
    base_link and the site robroot: $ROBROOT in $WORLD, or the ERSYS flange's origin)."""
    # $ROBROOT in $WORLD (machine data; $NULLFRAME here): MuJoCo's world frame is $WORLD
    rr = frame_to_matrix(m.robroot_frame)
    rx, ry, rz, rw = Rotation.from_matrix(rr[:3, :3]).as_quat()
    rr_attr = f'pos="{_vec(rr[:3, 3] / 1000.0)}" quat="{_vec((rw, rx, ry, rz))}"'
    ext_close = 0
    ersys = next((k for k in m.external_kinematics if k.robroot), None)
    for kin in m.external_kinematics:
        if kin is ersys:
            continue
        n_open = _ext_bodies(lines, m, kin, "    ")
        lines.append("    " + "  " * n_open + f'<site name="et{kin.index}_flange" size="0.01" rgba="0 0 1 1"/>')
        lines.append("    " + "  " * n_open + '<geom type="cylinder" size="0.4 0.02" rgba="0.5 0.5 0.5 1"/>')
        for k in range(n_open, 0, -1):
            lines.append("    " + "  " * (k - 1) + "</body>")
    if ersys is not None:
        ext_close = _ext_bodies(lines, m, ersys, "    ")
        rr_attr = 'pos="0 0 0"'
    return ext_close, rr_attr


def _base_geom(lines: list[str], m: MachineData, meshes: dict[str, bytes], radii: dict[str, float],
               cell: Any) -> None:
    """base_link's geom: the description's mesh, else a column up to the A1 joint origin (a
    sphere where A1's origin is the base's: an LBR's description)."""
    o1 = np.array(m.joints[0].origin_mm) / 1000.0
    base_bits = ' contype="8" conaffinity="1"' if cell is not None else ""
    if "base_link" in meshes:        # the description's mesh (robot/description.py)
        lines.append(f'      <geom name="base_geom" type="mesh" mesh="mesh_base_link" rgba="0.2 0.2 0.2 1"{base_bits}/>')
    elif np.linalg.norm(o1) > 1e-6:
        lines.append(f'      <geom name="base_geom" type="capsule" size="{_f(radii["base"])}" fromto="0 0 0 {_vec(o1)}" '
                     f'rgba="0.2 0.2 0.2 1"{base_bits}/>')
    else:                            # A1's origin at the base's (an LBR's description): a sphere
        lines.append(f'      <geom name="base_geom" type="sphere" size="{_f(radii["base"])}" '
                     f'rgba="0.2 0.2 0.2 1"{base_bits}/>')


def _arm_link(lines: list[str], m: MachineData, i: int, indent: str, meshes: dict[str, bytes],
              radii: dict[str, float], gravcomp: str) -> str:
    """Link i + 1's body (left open), joint and geoms into lines; the indent within it."""
    joints = m.joints
    j = joints[i]
    pos = np.array(j.origin_mm) / 1000.0
    quat = ""
    if any(j.origin_rpy_rad):
        x, y, z, w = Rotation.from_euler("xyz", j.origin_rpy_rad).as_quat()
        quat = f' quat="{_vec((w, x, y, z))}"'
    linear = j.kind == "linear"
    lo, hi = ((v / 1000.0 if linear else math.radians(v)) for v in j.limit_deg)
    if j.kuka_sign < 0:
        lo, hi = -hi, -lo
    lines.append(f'{indent}<body name="{j.child or f"link_{i + 1}"}" pos="{_vec(pos)}"{quat}{gravcomp}>')
    indent += "  "
    lines.append(f'{indent}<joint name="{j.name}" type="{"slide" if linear else "hinge"}" '
                 f'axis="{_vec(j.joint_axis)}" range="{_f(lo)} {_f(hi)}"/>')
    # link geometry: capsule from this joint to the next joint origin (or to the flange)
    nxt = np.array(joints[i + 1].origin_mm) / 1000.0 if i + 1 < len(joints) else None
    radius = radii[group_of(i)]
    body = j.child or f"link_{i + 1}"
    if body in meshes:
        lines.append(f'{indent}<geom name="link_{i + 1}_geom" type="mesh" mesh="mesh_{body}"/>')
    elif nxt is not None and np.linalg.norm(nxt) > 1e-6:
        lines.append(f'{indent}<geom name="link_{i + 1}_geom" type="capsule" size="{_f(radius)}" fromto="0 0 0 {_vec(nxt)}"/>')
    else:
        lines.append(f'{indent}<geom name="link_{i + 1}_geom" type="sphere" size="{_f(radius)}"/>')
    if linear:
        # the moving shaft (a SCARA's quill): from the flange point up along the axis, as long
        # as the travel (the flange point: the joint origins after this one and the flange)
        bottom = (np.sum([np.array(jj.origin_mm) for jj in joints[i + 1:]], axis=0) + np.array(m.flange_pos_mm)) / 1000.0
        ax = np.array(j.joint_axis, dtype=float)
        top = bottom - ax * ((j.limit_deg[1] - j.limit_deg[0]) / 1000.0 + float(np.linalg.norm(bottom)))
        lines.append(f'{indent}<geom name="link_{i + 1}_shaft" type="capsule" size="0.02" '
                     f'fromto="{_vec(bottom)} {_vec(top)}" rgba="0.7 0.7 0.7 1"/>')
    return indent


def _mjcf_tail(lines: list[str], m: MachineData, actuated: bool, kp: float, kv: float,
               exclude: Sequence[tuple[str, str]]) -> None:
    """The actuators (actuated), the contact exclusions and the keyframe ``home`` into lines."""
    joints = m.joints
    if actuated:
        lines.append("  <actuator>")
        for i, j in enumerate(joints):
            lines.append(f'    <position name="a{i + 1}" joint="{j.name}" kp="{_f(kp)}" inheritrange="1"/>')
        for i, j in enumerate(joints):
            lines.append(f'    <velocity name="v{i + 1}" joint="{j.name}" kv="{_f(kv)}"/>')
        lines.append("  </actuator>")
    arm_home = [j.kuka_sign * (a / 1000.0 if j.kind == "linear" else math.radians(a)) for j, a in zip(joints, m.home_deg)]
    home = _ext_home(m, arm_home)
    if exclude:
        lines.append("  <contact>")
        lines += [f'    <exclude body1="{a}" body2="{b}"/>' for a, b in exclude]
        lines.append("  </contact>")
    lines.append("  <keyframe>")
    ctrl = ""
    if actuated:
        ctrl = f' ctrl="{_vec(arm_home + [0.0] * len(joints))}"'
    lines.append(f'    <key name="home" qpos="{_vec(home)}"{ctrl}/>')
    lines.append("  </keyframe>")
    lines.append("</mujoco>")


def robot_meshes(m: MachineData) -> dict[str, bytes]:
    """The robot's link meshes a description gave (robot/description.py: link name -> STL bytes in
    the link's frame, metres), {} for a robot of machine data."""
    raw = getattr(m, "raw", None) or {}
    meshes = raw.get("meshes") if isinstance(raw, dict) else None
    return dict(meshes) if isinstance(meshes, dict) else {}


def mjcf_assets(m: MachineData, cell: Any = None) -> dict[str, bytes]:
    """MuJoCo's assets of :func:`build_mjcf`'s model: the robot's meshes and the cell's."""
    out = {f"robot_{link}.stl": data for link, data in robot_meshes(m).items()}
    if cell is not None:
        out.update(cell.mesh_assets()[1])
    return out


def _ext_bodies(lines: list[str], m: MachineData, kin, indent: str) -> int:
    """Open the bodies of the external kinematic `kin` (robot/external.py's chain: root,
    TA1KR, axis, TA2A1, axis, ...; the axis along/about Z); returns how many were opened, the
    last one being the kinematic's flange (TFLA3)."""
    def attr(frame) -> str:
        T = frame_to_matrix(*frame)
        x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
        return f'pos="{_vec(T[:3, 3] / 1000.0)}" quat="{_vec((w, x, y, z))}"'

    axes = {e.number: e for e in m.external_axes}
    opened = 0
    lines.append(f'{indent}<body name="et{kin.index}_root" {attr(kin.root)}>')
    opened += 1
    for k, num in enumerate(kin.axes):
        e = axes[num]
        lines.append(f'{indent}{"  " * opened}<body name="et{kin.index}_link{k + 1}" {attr(kin.frames[k])}>')
        opened += 1
        jt = "slide" if e.linear else "hinge"
        scale = 0.001 if e.linear else math.pi / 180.0
        rng = ("" if e.kind == "endless" else
               f' range="{_f(e.limit[0] * scale)} {_f(e.limit[1] * scale)}"')
        lines.append(f'{indent}{"  " * opened}<joint name="joint_e{num}" type="{jt}" axis="0 0 {e.direction}"{rng}/>')
        lines.append(f'{indent}{"  " * opened}<geom type="box" size="0.15 0.15 0.05" rgba="0.3 0.3 0.6 1"/>')
    lines.append(f'{indent}{"  " * opened}<body name="et{kin.index}_flange" {attr(kin.frames[3])}>')
    return opened + 1


def _ext_home(m: MachineData, home: list[float]) -> list[float]:
    """The keyframe's qpos in MuJoCo's joint order: the bodies of the BASE kinematics come
    first, then the ROBROOT kinematic's joints, then the arm (see build_mjcf)."""
    axes = {e.number: e for e in m.external_axes}

    def val(num: int) -> float:
        e = axes[num]
        return e.home * (0.001 if e.linear else math.pi / 180.0)

    before = [val(n) for k in m.external_kinematics if not k.robroot for n in k.axes]
    ers = [val(n) for k in m.external_kinematics if k.robroot for n in k.axes]
    return before + ers + home


_BOTTOM_ROW = np.array([0.0, 0.0, 0.0, 1.0])


def _arm_cycle(arm: "ArmModel", cycles: Any) -> Any:
    """The ``ArmCycle`` of robot/ipocycle.py (`cycles`, compiled or as Python) for `arm`, or None
    (see :meth:`ArmModel.ipo_cycle`). Compiled, ``mj_kinematics`` is looked up in the MuJoCo
    library the ``mujoco`` package ships and has loaded (the same library: loading it again gives
    the loaded one), and its products use numpy's own ``cblas_dgemm`` where it gives numpy's."""
    if arm.actuated or len(arm._eadr) or arm._linear is not None:
        return None
    try:
        fn = _mj_kinematics_address(arm) if cycles.COMPILED else 0
        if cycles.COMPILED and not fn:
            return None
        qidx = list(range(arm._qidx.start, arm._qidx.stop)) if isinstance(arm._qidx, slice) \
            else [int(i) for i in arm._qidx]
        xmat, xpos = arm.data.site_xmat[arm._site], arm.data.site_xpos[arm._site]
        cyc = cycles.ArmCycle(arm._mj.mj_kinematics, fn, arm.model, arm.data, qidx, arm._sign.tolist(), xmat, xpos)
    except (OSError, AttributeError, TypeError, ValueError):
        return None
    gemm = _numpy_dgemm() if cycles.COMPILED else 0
    if gemm:
        cyc.use_gemm(gemm)
        if not _same_products(cyc):
            cyc.use_gemm(0)
    return cyc


def _mj_kinematics_address(arm: "ArmModel") -> int:
    """The address of ``mj_kinematics`` in the MuJoCo library the ``mujoco`` package ships, 0
    when it is not found. Raises OSError when the library does not load."""
    libs = sorted(glob.glob(os.path.join(os.path.dirname(arm._mj.__file__), "libmujoco*")))
    if not libs:
        return 0
    return ctypes.cast(ctypes.CDLL(libs[0]).mj_kinematics, ctypes.c_void_p).value or 0


def _numpy_dgemm() -> int:
    """The address of the ILP64 ``cblas_dgemm`` numpy's own BLAS exports (robot/blas.py), 0 when
    there is none at hand."""
    return numpy_cblas("dgemm")


def _same_products(cyc: Any) -> bool:
    """True when the compiled product gives numpy's ``A @ B @ C`` bit for bit on random 4x4
    matrices (with identities and signed zeros): the check that the BLAS found is the one
    numpy calls, the way numpy calls it."""
    rng = np.random.default_rng(39)
    out = np.empty((4, 4))
    for i in range(64):
        A, B, C = (rng.normal(0.0, 500.0, (4, 4)) for _ in range(3))
        if i % 4 == 0:
            A = np.eye(4)
        if i % 3 == 0:
            C = np.eye(4)
        if i % 5 == 0:
            B[rng.integers(0, 3), rng.integers(0, 4)] = -0.0
        if not cyc.product(A, B, C, out) or out.tobytes() != (A @ B @ C).tobytes():
            return False
    return True


class ArmModel:
    """The MuJoCo arm, driven in KUKA axis values (deg) and read back in mm.

    Attributes:
        machine, model (``mujoco.MjModel``), data (``mujoco.MjData``), xml, actuated.
    """

    def __init__(self, machine: MachineData | None = None, actuated: bool = False, cell: Any = None, **kw) -> None:

        self._mj = mujoco
        self.machine = machine if machine is not None else load_machine()
        self.actuated = actuated
        self.xml = build_mjcf(self.machine, actuated, cell=cell, **kw)
        assets = mjcf_assets(self.machine, cell)
        if assets:
            self.model = mujoco.MjModel.from_xml_string(self.xml, assets=assets)
        else:
            self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self._qadr = np.array([self.model.joint(j.name).qposadr[0] for j in self.machine.joints])
        self._dadr = np.array([self.model.joint(j.name).dofadr[0] for j in self.machine.joints])
        # the robot's n joints sit side by side in qpos (they do in build_mjcf's model): a slice
        # instead of a fancy index in the per-cycle replay
        n = self._n = len(self.machine.joints)
        q0 = int(self._qadr[0])
        self._qidx = slice(q0, q0 + n) if list(self._qadr) == list(range(q0, q0 + n)) else self._qadr
        self._sign = np.array([j.kuka_sign for j in self.machine.joints], dtype=float)
        #: which joints are linear (mm; a slide in m), None when all turn
        linear = np.array([j.kind == "linear" for j in self.machine.joints])
        self._linear = linear if linear.any() else None
        # external axes E1..En (joint_e<n>): qpos in m or rad, set from mm or deg
        ext = self.machine.external_axes
        self._eadr = np.array([self.model.joint(f"joint_e{e.number}").qposadr[0] for e in ext], dtype=int)
        self._escale = np.array([0.001 if e.linear else math.pi / 180.0 for e in ext])
        self._site = self.model.site("tool0").id
        # views into MjData of the flange site's rotation (3x3) and position (m), read each cycle
        self._site_views = (self.data.site_xmat[self._site].reshape(3, 3), self.data.site_xpos[self._site])
        self._robroot = frame_to_matrix(self.machine.robroot_frame)
        self._robroot_inv = inv_pos(self._robroot)
        self._robroot_null = bool(np.allclose(self._robroot, np.eye(4)))
        self._cycle: Any = None      # ipo_cycle's (module, its ArmCycle or False)
        self.set_axes(self.machine.home_deg)

    # ------------------------------------------------------------------ replay
    def set_axes(self, axes_deg: Sequence[float], vel_deg_s: Sequence[float] | None = None,
                 full: bool = False) -> None:
        """Kinematic playback: write ``qpos`` (and ``qvel``) from A1..An in deg (deg/s; a linear
        axis in mm, mm/s), then E1..En, and run ``mj_kinematics`` (``mj_forward`` with
        ``full=True``)."""
        d = self.data
        a = np.asarray(axes_deg, dtype=float)
        n = self._n
        d.qpos[self._qidx] = self._sign * self._si(a[:n])
        if len(self._eadr) and len(a) > n:
            d.qpos[self._eadr] = self._escale * a[n:n + len(self._eadr)]
        if vel_deg_s is not None:
            d.qvel[self._dadr] = self._sign * self._si(np.asarray(vel_deg_s, dtype=float)[:n])
        if full:
            self._mj.mj_forward(self.model, d)
        else:
            self._mj.mj_kinematics(self.model, d)

    def ipo_cycle(self, cycles: Any) -> Any:
        """The kinematic playback of one IPO cycle (``cycles``: robot/ipocycle.py compiled or as
        Python, as robot/kinematics/compiled.py ``pure_module`` gives it; its ``ArmCycle``:
        :meth:`set_axes`, :meth:`axes_deg` and :meth:`flange_pose_world` in one call, the same
        numbers; compiled, its ``product`` is numpy's ``A @ B @ C`` of 4x4 matrices when numpy's
        own BLAS is found and gives the same products), kept; None in actuated mode, with
        external or linear axes, or compiled without MuJoCo's library at hand (these methods run
        then)."""
        if self._cycle is None or self._cycle[0] is not cycles:
            self._cycle = (cycles, _arm_cycle(self, cycles) or False)
        return self._cycle[1] or None

    def _si(self, a: np.ndarray) -> np.ndarray:
        """Axis values in MuJoCo's units: deg -> rad (a linear axis: mm -> m)."""
        if self._linear is None:
            return np.radians(a)
        return np.where(self._linear, a / 1000.0, np.radians(a))

    def _kuka(self, v: np.ndarray) -> np.ndarray:
        """MuJoCo's joint values in KUKA's units: rad -> deg (a linear axis: m -> mm)."""
        if self._linear is None:
            return np.degrees(v)
        return np.where(self._linear, v * 1000.0, np.degrees(v))

    def axes_deg(self, qpos: np.ndarray | None = None) -> np.ndarray:
        """Current A1..An (deg; a linear axis in mm) read back from ``qpos``, then E1..En (mm,
        deg) when the robot has external axes; shape (n,) or (n + n_ext,). `qpos`: a recorded
        copy of the arm's ``qpos`` (shape (nq,)) read instead of its own (interp/cellcontacts.py
        reads a pose of a past cycle so)."""
        qpos = self.data.qpos if qpos is None else qpos
        q = self._kuka(self._sign * qpos[self._qidx])
        if len(self._eadr):
            q = np.concatenate([q, qpos[self._eadr] / self._escale])
        return q

    def flange_pose_world(self) -> np.ndarray:
        """KUKA flange frame (site ``tool0``) in ``$WORLD`` (MuJoCo world), 4x4, mm."""
        xmat, xpos = self._site_views
        T = np.empty((4, 4))
        T[:3, :3] = xmat
        T[:3, 3] = 1000.0 * xpos
        T[3] = _BOTTOM_ROW
        return T

    def flange_pose(self) -> np.ndarray:
        """KUKA flange frame (site ``tool0``) in ``$ROBROOT``, 4x4, mm; equals
        :meth:`robot.kinematics.Kinematics.forward` of :meth:`axes_deg`."""
        T = self.flange_pose_world()
        return T if self._robroot_null else self._robroot_inv @ T

    def tcp_pose(self, tool=None, base=None) -> np.ndarray:
        """``$POS_ACT`` read back from the simulation (``$IPO_MODE=#BASE``):
        ``INV_POS($BASE) : FLANGE_in_WORLD : $TOOL`` (robot-model.md §7), 4x4, mm.
        ``tool``/``base``: 4x4, (X, Y, Z, A, B, C) or None (= ``$NULLFRAME``)."""
        return inv_pos(as_matrix(base)) @ self.flange_pose_world() @ as_matrix(tool)

    # ------------------------------------------------------------------ actuated
    def step_actuated(self, targets_deg: Sequence[float], dt: float,
                      target_vel_deg_s: Sequence[float] | None = None) -> None:
        """Actuated mode only: hold ``ctrl`` = target axes (deg) and target speeds (deg/s,
        default 0) and advance the simulation by ``dt`` seconds (rounded to whole
        time steps, at least one). Raises RuntimeError in replay mode."""
        if not self.actuated:
            raise RuntimeError("step_actuated needs ArmModel(actuated=True)")
        n = len(self._qadr)
        d = self.data
        d.ctrl[:n] = self._sign * self._si(np.asarray(targets_deg, dtype=float)[:n])
        if target_vel_deg_s is None:
            d.ctrl[n:2 * n] = 0.0
        else:
            d.ctrl[n:2 * n] = self._sign * self._si(np.asarray(target_vel_deg_s, dtype=float)[:n])
        steps = max(1, int(round(dt / self.model.opt.timestep)))
        for _ in range(steps):
            self._mj.mj_step(self.model, d)

    def reset(self, axes_deg: Sequence[float] | None = None) -> None:
        """Reset the simulation state to ``axes_deg`` (default HOME), zero speed;
        in actuated mode the servo targets are set there too."""
        self._mj.mj_resetData(self.model, self.data)
        q = self.machine.home_deg if axes_deg is None else axes_deg
        if self.actuated:
            n = len(self._qadr)
            self.data.ctrl[:n] = self._sign * self._si(np.asarray(q, dtype=float)[:n])
        self.set_axes(q, full=True)
