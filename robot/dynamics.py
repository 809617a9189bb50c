"""The arm's rigid-body dynamics with its load, evaluated with MuJoCo's inverse dynamics, and the
accelerations of a synchronised PTP they allow (issues 60 and 73).

A KR C4 plans a PTP with the *higher motion profile*: each axis accelerates as hard as its drive
can at that pose with that load, from the robot's dynamic model, and the axes are synchronised to
start and end together (reference §6.6: the leading axis sets the time, the others are slowed).
KUKA's machine-data handbook says it of ``$RAISE_TIME`` (the ramp-up time to the rated speed):
it is "Only used with non-KUKA kinematic systems with deactivated acceleration adaptation
($ADAP_ACC=#NONE) and deactivated higher motion profile ($OPT_MOVE=#NONE). With KUKA standard
robots, the accelerations are calculated according to the reach, the specified load and the mass
inertia" (KUKA, Operating Handbook KR C2 Machine Data, Maschinendaten 12.0400 en, §2.1.47, p. 31 of
91; easymanua.ls/kuka/kr-c2/manual/682418?p=31). The program override: "Program override is the
velocity of the robot during program execution. It is specified as a percentage of the programmed
velocity ... The program override refers to all motions of the robot system" (KUKA's mxAutomation
documentation, KRC_SetOverride, "Setting the program override (POV)",
infosys.beckhoff.com/content/1033/tf5120/13081546379.html): every speed of the same path times ov,
so its time over ov and its accelerations times ov² (the real recordings at 85 % show it: robot/limits.py
``ptp_axis_accelerations``). No KUKA page on the synchronisation itself was found in the stored
pages, nor one giving the KR 3's wrist torque limits.
The real KR 3 R540 shows it in its interpolator's commanded gear torques (``GearTorq_CmdIpo2/3``
of its KUKA Trace recordings, ../shared/real-traces): with the 3 kg payload A2 brakes at
1 560-1 620 °/s² with its commanded torque at −93.7 Nm, the same limit it reaches accelerating
(+92.5 Nm), where it accelerates at twice that rate (3 200-3 300 °/s²) because gravity helps
(PTP_away's three A2 runs, the measured axes' acceleration; docs/robot.md "The dynamic model").

:class:`ArmDynamics` builds a MuJoCo model of the arm from the joint chain (robot/kinematics/
joints.py; ``$ROBROOT`` gives gravity's direction) with the identified inertials of its links
(robot/identified.py ``dynamics``: masses, centres of mass, inertia tensors in the links' frames;
the motors' rotor inertias seen at the axes as MuJoCo's ``armature``), a body for ``$LOAD`` at
the flange (mass, centre of mass and principal inertias in the flange frame, KSS's LOAD structure)
and one for ``$LOAD_A3`` on link 3; ``mj_inverse`` gives the joint torques ``τ = M(q)·q̈ + g(q)``
(at rest: no velocity terms).

:meth:`ArmDynamics.ptp_bounds` gives, for a synchronised PTP from ``q0`` to ``q1`` (``u`` its
normalised path parameter, ``q̈ = Δq·ü``), the normalised acceleration each axis allows starting
(at ``q0``, at rest: ``|(M(q0)Δq)_i·ü + g_i(q0)| ≤ τ_i``) and braking (at ``q1``, at rest:
``|−(M(q1)Δq)_i·ü + g_i(q1)| ≤ τ_i``), with ``τ_i`` each drive's torque limit (``torque_nm``),
scaled by the axis' acceleration factor (``$ACC_AXIS``, the override's square: the plan is made at
100 % and the override scales its time). The acceleration and the braking are evaluated once per
motion (four ``mj_inverse`` calls), never per IPO cycle. Gravity appears in the limit: an axis
lifting its load starts slower and brakes faster. The velocity terms vanish at both instants.

Units: mm and deg at the interface; kg, m, rad inside. ``$LOAD``: (M kg, X, Y, Z mm, A, B, C deg,
JX, JY, JZ kg m²); M < 0 (KSS's "no load data") is the robot's default load: its machine data's
``$DEF_L_M``, ``$DEF_L_CM``, ``$DEF_L_J`` ("DEFAULTMASSE AM FLANSCH", the comment of every corpus
backup's ``$robcor.dat``, whose values are the models' rated payloads: KR 210 210 kg, KR 120 120 kg;
KUKA's mxAutomation library names ``$DEF_LA3_M/CM/J`` "Maximum permissible load on axis 3 for the
robot", infosys.beckhoff.com/content/1033/tf5120/13081516427.html, KRC_LDDconfig), else the rated
payload at the flange (``rated_payload_kg``; KUKA: undefined load data are taken as the maximum payload. No KUKA manual
page on it is in the project's stored pages; a KSS 8.3 case says the same, "When $LOAD is undefined
or set to default values, the KRC4 system assumes the maximum payload rating for the robot series":
industrialmonitordirect.com/blogs/knowledgebase/kuka-kr120-tool-overload-error-fix-bas-initmov-load-mismatch,
third-party, not KUKA's).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from .frames import frame_to_matrix
from .kinematics.joints import JointChain

#: gravity, m/s² (MuJoCo's default, -Z of $WORLD)
GRAVITY = 9.81
#: a LOAD of no mass: (M, X, Y, Z, A, B, C, JX, JY, JZ)
NO_LOAD = (0.0,) * 10


def _v(x: Sequence[float]) -> str:
    return " ".join(repr(float(a)) for a in x)


def _quat(R: np.ndarray) -> str:
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return _v((w, x, y, z))


def arm_mjcf(machine: Any, dynamics: dict[str, Any]) -> str:
    """The MJCF (str) of the arm's dynamic model: bodies ``link_1..n`` with the identified
    inertials, hinges along the chain's axes (``qpos = kuka_sign · rad(A_i)``) with the rotor
    inertias as armature, ``$ROBROOT``'s orientation on the base, bodies ``load`` (at the flange)
    and ``load_a3`` (on link 3) for the loads, set at run time (:meth:`ArmDynamics.set_load`)."""
    c = JointChain(machine)
    mass = np.asarray(dynamics["link_mass_kg"], dtype=float)
    com = np.asarray(dynamics["link_com_mm"], dtype=float) / 1000.0
    iner = np.asarray(dynamics["link_inertia_kg_m2"], dtype=float)
    rotor = np.asarray(dynamics["rotor_inertia_kg_m2"], dtype=float)
    R_root = frame_to_matrix(*machine.robroot_frame)[:3, :3]
    out = [f'<mujoco model="dynamics">', '<compiler angle="radian" inertiafromgeom="false"/>',
           f'<option gravity="0 0 {-GRAVITY!r}"/>', "<worldbody>", f'<body name="base" quat="{_quat(R_root)}">']
    for i in range(c.n):
        xx, yy, zz, xy, xz, yz = iner[i]
        out.append(f'<body name="link_{i + 1}" pos="{_v(c.origins[i] / 1000.0)}" quat="{_quat(c.R_origin[i])}">')
        out.append(f'<joint name="a{i + 1}" type="hinge" axis="{_v(c.axes[i])}" armature="{float(rotor[i])!r}"/>')
        out.append(f'<inertial pos="{_v(com[i])}" mass="{float(max(mass[i], 1e-6))!r}" '
                   f'fullinertia="{_v((max(xx, 1e-9), max(yy, 1e-9), max(zz, 1e-9), xy, xz, yz))}"/>')
        if i == 2:
            out.append('<body name="load_a3"/>')
    out.append(f'<body name="load" pos="{_v(c.p_flange / 1000.0)}" quat="{_quat(c.R_flange)}"/>')
    out += ["</body>"] * c.n
    out += ["</body>", "</worldbody>", "</mujoco>"]
    return "\n".join(out)


class ArmDynamics:
    """The dynamic model of `machine`'s arm from its ``dynamics`` (robot/identified.py):
    ``link_mass_kg`` (n,), ``link_com_mm`` (n, 3), ``link_inertia_kg_m2`` (n, 6: xx, yy, zz, xy,
    xz, yz about the centre of mass, in the link's frame), ``rotor_inertia_kg_m2`` (n,),
    ``torque_nm`` (n,) the drives' torque limits (None: none known), optional ``rated_payload_kg`` and
    ``capped_axes`` (the axes, 1-based, the planner also caps with their identified acceleration,
    robot/planner.py: those whose torque limit was measured and those with none known; an axis
    whose torque was derived from its acceleration is not capped again); a described model
    (robot/described_dynamics.py) adds ``sources`` (where each value comes from, for ``krl robot
    show``) and ``plan`` (False: shown, not planned with: robot/planner.py ``arm_dynamics``)."""

    def __init__(self, machine: Any, dynamics: dict[str, Any]) -> None:
        self.n = len(machine.joints)
        self.model = mujoco.MjModel.from_xml_string(arm_mjcf(machine, dynamics))
        self.data = mujoco.MjData(self.model)
        self.sign = np.array([j.kuka_sign for j in machine.joints], dtype=float)
        self.torque = np.array([np.inf if t is None else float(t) for t in dynamics["torque_nm"]], dtype=float)
        self.rated = float(dynamics.get("rated_payload_kg", 0.0))
        #: the load of ``$LOAD.M < 0``: the robot's default load (machine data ``$DEF_L_M``,
        #: ``$DEF_L_CM``, ``$DEF_L_J``: robot/mada.py ``default_load``), else the rated payload at the flange
        self.default_load = default_load_tuple(getattr(machine, "default_load", None), self.rated)
        #: the axes their identified acceleration caps too (``capped_axes``)
        self.capped = np.array([i + 1 in set(dynamics.get("capped_axes", ())) for i in range(self.n)], dtype=bool)
        self._load_body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, "load")
        self._a3_body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, "load_a3")
        self._loads: tuple = ()
        self.set_load(None, None)

    def _set_body(self, body: int, load: Sequence[float]) -> None:
        m = self.model
        mass = float(load[0])
        m.body_mass[body] = mass
        m.body_ipos[body] = np.asarray(load[1:4], dtype=float) / 1000.0
        R = frame_to_matrix(0.0, 0.0, 0.0, *load[4:7])[:3, :3]
        x, y, z, w = Rotation.from_matrix(R).as_quat()
        m.body_iquat[body] = (w, x, y, z)
        m.body_inertia[body] = [max(float(j), 0.0) for j in load[7:10]] if mass > 0 else (0.0, 0.0, 0.0)

    def set_load(self, load: Sequence[float] | None, load_a3: Sequence[float] | None) -> None:
        """`load` (``$LOAD``) at the flange and `load_a3` (``$LOAD_A3``) on link 3, each (M kg,
        X, Y, Z mm, A, B, C deg, JX, JY, JZ kg m²) or None. ``$LOAD`` of M < 0 or None is the
        robot's default load (:attr:`default_load`); ``$LOAD_A3`` of M <= 0 or None is none."""
        if load is None or float(load[0]) < 0:
            load = self.default_load
        if load_a3 is None or float(load_a3[0]) <= 0:
            load_a3 = NO_LOAD
        key = (tuple(load), tuple(load_a3))
        if key == self._loads:
            return
        self._set_body(self._load_body, load)
        self._set_body(self._a3_body, load_a3)
        self._loads = key

    def inverse(self, q_deg: np.ndarray, qdd: np.ndarray | None = None) -> np.ndarray:
        """The joint torques (n,) N m, in KUKA's axis directions, that hold the arm at rest at
        `q_deg` (deg) and accelerate it by `qdd` (rad/s², KUKA's directions; None: 0)."""
        d = self.data
        d.qpos[:] = self.sign * np.radians(np.asarray(q_deg, dtype=float)[:self.n])
        d.qvel[:] = 0.0
        d.qacc[:] = 0.0 if qdd is None else self.sign * np.asarray(qdd, dtype=float)[:self.n]
        mujoco.mj_inverse(self.model, d)
        return self.sign * d.qfrc_inverse

    def gravity(self, q_deg: np.ndarray) -> np.ndarray:
        """g(q) (n,) N m: the torques that hold the arm and its loads at `q_deg`."""
        return self.inverse(q_deg)

    def mass_matrix(self, q_deg: np.ndarray) -> np.ndarray:
        """M(q) (n, n) kg m², rotor inertias included, in KUKA's axis directions."""
        g = self.gravity(q_deg)
        return np.stack([self.inverse(q_deg, e) - g for e in np.eye(self.n)], axis=1)

    def ptp_bounds(self, q0: np.ndarray, q1: np.ndarray, factor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(starting, braking) normalised accelerations (1/s², (n,) each) each axis allows a
        synchronised PTP from `q0` to `q1` (deg) with the load set (:meth:`set_load`): the
        module's docstring; `factor` (n,) each axis' acceleration factor. inf for an axis that
        needs no torque; at least :data:`MIN_SHARE` of the limit where gravity takes the rest."""
        q0 = np.asarray(q0, dtype=float)[:self.n]
        q1 = np.asarray(q1, dtype=float)[:self.n]
        dq = np.radians(q1 - q0)
        g0, g1 = self.gravity(q0), self.gravity(q1)
        h0, h1 = self.inverse(q0, dq) - g0, self.inverse(q1, dq) - g1
        f = np.asarray(factor, dtype=float)[:self.n]
        return f * _bound(self.torque, h0, -np.sign(h0) * g0), f * _bound(self.torque, h1, np.sign(h1) * g1)


def default_load_tuple(default_load: dict[str, Any] | None, rated_kg: float) -> tuple[float, ...]:
    """The LOAD tuple (M, X, Y, Z, A, B, C, JX, JY, JZ) of a robot's default load (robot/mada.py
    ``default_load``: ``mass_kg``, ``cm_mm_deg``, ``inertia_kg_m2``), or `rated_kg` at the flange
    when the machine data give none."""
    d = default_load or {}
    if d.get("mass_kg") is None:
        return (float(rated_kg),) + NO_LOAD[1:]
    cm = dict(zip(LOAD_FRAME, d.get("cm_mm_deg") or ()))
    j = dict(zip(LOAD_INERTIA, d.get("inertia_kg_m2") or ()))
    return (float(d["mass_kg"]), *(float(cm.get(k, 0.0)) for k in LOAD_FRAME),
            *(float(j.get(k, 0.0)) for k in LOAD_INERTIA))


#: the components of a LOAD's centre-of-mass frame (CM) and of its inertias (J), in KSS's order
LOAD_FRAME = ("X", "Y", "Z", "A", "B", "C")
LOAD_INERTIA = ("X", "Y", "Z")


#: the least share of its torque limit an axis keeps for accelerating when gravity takes the rest
#: (a pose where gravity alone exceeds the limit is not one the robot can hold: no motion stalls)
MIN_SHARE = 0.01


def _bound(tau: np.ndarray, h: np.ndarray, grav: np.ndarray) -> np.ndarray:
    """``(τ + grav) / |h|`` (inf where ``h`` is 0; at least :data:`MIN_SHARE` of ``τ / |h|``)."""
    need = np.abs(h)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(need > 1e-12, np.maximum(tau + grav, MIN_SHARE * tau) / np.maximum(need, 1e-300), np.inf)


__all__ = ["ArmDynamics", "NO_LOAD", "arm_mjcf", "default_load_tuple"]
