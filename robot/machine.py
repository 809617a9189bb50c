"""The robot model's data (:class:`MachineData`) and the default robot, the KR 6 R900 sixx of
``robot/data/kr6_r900.yaml``.

:class:`MachineData` is the one model of a robot whatever its source: the yaml (read here by
:func:`load_machine`; a copy of ``shared/robots/kr6_r900.yaml``, robot-model.md §1-§5, §10) or
a KUKA ``$machine.dat`` (robot/mada.py), with its external axes E1..E6
(:class:`ExternalAxis`) and external kinematics (:class:`ExternalKinematic`). Every number
used by the kinematics, the MJCF builder and the planner comes from it, nothing is
hard-coded a second time in the code.

Units: lengths in mm (the yaml geometry is in metres and is converted here),
angles in degrees unless a name says otherwise.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from .axismap import CART_KEYS
from .heldcache import HeldCache

DEFAULT_MACHINE_FILE = Path(__file__).with_name("data") / "kr6_r900.yaml"
#: The project's robot library: robot YAMLs and machine data (``*.dat``) that a cell file names
#: by their stem (``robot: kr180_r3200_pa``, robot/stimuli.py).
ROBOT_LIBRARY = DEFAULT_MACHINE_FILE.parent


def library_robots() -> dict[str, Path]:
    """The robots of :data:`ROBOT_LIBRARY`: file stem -> path (``.yaml`` and ``.dat`` files)."""
    return {p.stem: p for p in sorted(ROBOT_LIBRARY.iterdir())
            if p.is_file() and p.suffix in (".yaml", ".dat")}


@dataclass(frozen=True)
class JointData:
    """One robot axis (robot-model.md §2, §5).

    Attributes:
        name: URDF joint name, e.g. ``"joint_a1"``.
        axis: KUKA axis number 1..6.
        limit_deg: ``($SOFTN_END, $SOFTP_END)`` in degrees.
        max_speed_deg_s: axis maximum speed in deg/s, computed like the controller
            does from ``$VEL_AXIS_MA`` [rpm] / |``$RAT_MOT_AX``| * 6 (robot-model.md §5;
            e.g. 381.18 for A4; the URDF rounds it to 381).
        max_acc_deg_s2: simulation default axis acceleration in deg/s^2 (kroshu
            worst-case value, robot-model.md §5 [uncertain]).
        max_jerk_deg_s3: ``$AXIS_JERK`` in deg/s^3.
        origin_mm: URDF joint origin relative to the parent link, mm.
        joint_axis: URDF joint axis unit vector (KUKA directions built in, §3).
        urdf_max_speed_deg_s: the URDF velocity limit (deg/s), for reference.
        parent, child: URDF link names.
        origin_rpy_rad: URDF joint origin rotation (roll, pitch, yaw), rad.
        kuka_sign: ``q_urdf_rad = kuka_sign * radians(A_i)`` (yaml ``angle_mapping``, +1 here).
        kind: ``"rotary"`` (deg) or ``"linear"`` (``$AXIS_TYPE`` 1: mm, moving along
            ``joint_axis``; a SCARA's A3); the limits, speed, acceleration and jerk are then in
            mm, mm/s, mm/s^2 and mm/s^3.
        data_limit_deg: the machine data's ``($SOFTN_END, $SOFTP_END)`` when the model holds
            the axis within other limits (`limit_deg`): a palletizer's A4, which ``$DEF_A4FIX``
            holds at 0 (robot/mada.py); None when `limit_deg` is the data's. KRL reads these
            (the controller's ``$SOFTN_END`` is the machine data's value, reference §8.2).
    """

    name: str
    axis: int
    limit_deg: tuple[float, float]
    max_speed_deg_s: float
    max_acc_deg_s2: float
    max_jerk_deg_s3: float
    origin_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    joint_axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    urdf_max_speed_deg_s: float = 0.0
    parent: str = ""
    child: str = ""
    kuka_sign: int = 1
    origin_rpy_rad: tuple[float, float, float] = (0.0, 0.0, 0.0)
    kind: str = "rotary"
    data_limit_deg: tuple[float, float] | None = None

    @property
    def data_limits(self) -> tuple[float, float]:
        """(``$SOFTN_END``, ``$SOFTP_END``) of this axis as the machine data give them, deg: what
        KRL reads and ``krl robot show`` prints (:attr:`limit_deg` where the data hold no other)."""
        return self.data_limit_deg if self.data_limit_deg is not None else self.limit_deg

    @property
    def softn_end(self) -> float:
        """``$SOFTN_END`` of this axis, deg (the machine data's)."""
        return self.data_limits[0]

    @property
    def softp_end(self) -> float:
        """``$SOFTP_END`` of this axis, deg (the machine data's)."""
        return self.data_limits[1]


class CartLimits(NamedTuple):
    """A KRL ``CP`` structure (``$VEL_MA``, ``$ACC_MA``, ...): ``cp`` in m/s (or m/s^2),
    ``ori1``/``ori2`` in deg/s (or deg/s^2). Also indexable by name
    (``lim["cp"]``, ``lim["ori1"]``) or position."""

    cp: float
    ori1: float
    ori2: float

    def __getitem__(self, key):  # type: ignore[override]
        if isinstance(key, str):
            k = key.lower().split("_")[0]
            return getattr(self, k)
        return tuple.__getitem__(self, key)


@dataclass(frozen=True)
class OPWParams:
    """OPW kinematic parameters (robot-model.md §4.2), lengths in **mm**.

    ``offsets_deg`` and ``sign_corrections`` follow the OPW convention
    ``q_opw = sign * A - offset``.
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    offsets_deg: tuple[float, ...]
    sign_corrections: tuple[int, ...]


@dataclass(frozen=True)
class ExternalAxis:
    """An external axis E1..E6 (``$EX_AX_NUM``; machine-data index 6 + number).

    Attributes:
        number: 1..6 (E1..E6).
        kind: ``"linear"`` (``$AXIS_TYPE`` 1; mm), ``"rotary"`` (3; deg) or ``"endless"``
            (5; deg, no soft limits).
        limit: ``($SOFTN_END, $SOFTP_END)`` in mm or deg.
        max_speed: mm/s or deg/s (``$VEL_AXIS_MA`` and ``$RAT_MOT_AX``, robot/mada.py).
        max_acc: mm/s^2 or deg/s^2 (derived, robot/mada.py ``RULES``).
        direction: ``$AXIS_DIR`` (+1 or -1).
        home: the value in ``$AXIS_HOME[1]``.
    """

    number: int
    kind: str
    limit: tuple[float, float]
    max_speed: float
    max_acc: float
    max_jerk: float
    direction: int = 1
    home: float = 0.0

    @property
    def name(self) -> str:
        return f"E{self.number}"

    @property
    def linear(self) -> bool:
        return self.kind == "linear"


@dataclass(frozen=True)
class ExternalKinematic:
    """An external kinematic system ETn of ``$EX_KIN`` (KR C2 machine-data handbook
    "Maschinendaten 12.0400" §2.2.5-§2.2.11): ``system`` ``"#ERSYS"`` (the ROBROOT kinematic:
    a track carrying the robot) or ``"#EASYS"``..``"#EFSYS"`` (a BASE kinematic: a turntable or
    positioner carrying the workpiece); ``axes`` the E numbers of ``$ETn_AX`` (TR_A1..TR_A3);
    ``frames`` ``$ETn_TA1KR``, ``$ETn_TA2A1``, ``$ETn_TA3A2``, ``$ETn_TFLA3`` (X, Y, Z, A, B, C);
    ``root`` the kinematic's root point in ``$WORLD`` (``$ERSYSROOT`` for #ERSYS). Its flange is
    ``root : TA1KR : Ax(E_a) : TA2A1 : Ax(E_b) : TA3A2 : Ax(E_c) : TFLA3`` with each axis moving
    along or about the Z axis of the frame before it (robot/external.py)."""

    index: int
    system: str
    name: str
    axes: tuple[int, ...]
    frames: tuple[tuple[float, ...], ...]
    root: tuple[float, ...] = (0.0,) * 6

    @property
    def robroot(self) -> bool:
        """True for the ROBROOT kinematic (#ERSYS)."""
        return self.system == "#ERSYS"


@dataclass(frozen=True)
class MachineData:
    """All machine data of the robot (robot-model.md; loaded by :func:`load_machine`).

    Attributes:
        name: robot name, ``"KR 6 R900 sixx"`` (from machine data: ``$TRAFONAME`` without
            its ``#``, robot/mada.py).
        joints: the robot's axes A1..An (:class:`JointData`; n = :attr:`n_axes`: six for the arms,
            four for a SCARA).
        home_deg: ``$AXIS_HOME[1]`` / XHOME, deg.
        mastering_deg: ``$MAMES``, deg.
        opw: :class:`OPWParams` (mm).
        flange_quat_wxyz: rotation link_6 -> KUKA flange (URDF ``tool0``), (w, x, y, z),
            composed from the yaml ``fixed_frames`` chain link_6 -> flange -> tool0.
        flange_rpy_rad: the same rotation as URDF rpy.
        flange_pos_mm: position of the KUKA flange in link_6, mm.
        robroot_frame: ``$ROBROOT`` as (X, Y, Z, A, B, C) mm/deg.
        default_tool_frame: ``TOOL_DATA[1]`` as (X, Y, Z, A, B, C) mm/deg (bas.src INITMOV).
        status_phi_deg: S bit 1 switching angle of A3 (robot-model.md §8).
        vel_ma: ``$VEL_MA`` (cp m/s, ori1/ori2 deg/s).
        acc_ma: ``$ACC_MA`` (cp m/s^2, ori1/ori2 deg/s^2).
        acc_ov: ``$ACC_OV``.
        apo_dis_ptp_deg: ``$APO_DIS_PTP[1..6]``, deg.
        in_pos_ma_deg, in_pos_car_mm, in_pos_ori_deg: ``$IN_POS_*``.
        def_flt_ptp, def_flt_cp: ``$DEF_FLT_PTP``/``$DEF_FLT_CP``.
        ipo_cycle_s: interpolation cycle, 0.012 s.
        motion_defaults: the yaml ``motion_defaults`` mapping ($config.dat / bas.src).
        default_load: the yaml ``default_load`` mapping ($robcor.dat).
        reach_wrist_point_mm: derived reach, mm.
        raw: the whole parsed yaml document.
    """

    name: str
    joints: tuple[JointData, ...]
    home_deg: tuple[float, ...]
    mastering_deg: tuple[float, ...]
    opw: OPWParams
    flange_quat_wxyz: tuple[float, float, float, float]
    flange_rpy_rad: tuple[float, float, float]
    flange_pos_mm: tuple[float, float, float]
    robroot_frame: tuple[float, ...]
    default_tool_frame: tuple[float, ...]
    status_phi_deg: float
    vel_ma: CartLimits
    acc_ma: CartLimits
    acc_ov: CartLimits
    apo_dis_ptp_deg: tuple[float, ...]
    in_pos_ma_deg: tuple[float, ...]
    in_pos_car_mm: float
    in_pos_ori_deg: float
    def_flt_ptp: int
    def_flt_cp: int
    ipo_cycle_s: float
    motion_defaults: dict[str, Any] = field(compare=False)
    default_load: dict[str, Any] = field(compare=False)
    reach_wrist_point_mm: float = field()
    home_flange_pose: tuple[float, ...] = field()
    source: str = ""
    raw: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)
    #: ``$TRAFONAME`` of the machine data ("" for the yaml robot).
    trafoname: str = ""
    #: for a backup without machine data that names its robot in ``$config.dat``
    #: (robot/named.py): the robot it names, where, and whether this one stands in for it; else ""
    named: str = field(default="", compare=False)
    #: parameter name -> where its value came from: ``"file:line"`` or ``"derived: rule"``
    #: (robot/mada.py; empty for the yaml robot, whose sources are the yaml's comments).
    provenance: dict[str, str] = field(default_factory=dict, repr=False, compare=False)
    #: palletizer flags ``$DEF_A4FIX`` (A4 fixed at 0) and ``$DEF_A5LINK`` (A5 led by a
    #: parallelogram; 4-axis palletizer), False for the yaml robot.
    a4fix: bool = False
    a5link: bool = False
    #: the kinematic chain of the machine data (robot/chain.py ``Chain``); None for the yaml robot
    chain: Any = field(default=None, compare=False, repr=False)
    #: external axes E1..E6 (``$EX_AX_NUM``) and external kinematic systems (``$EX_KIN``)
    external_axes: tuple[ExternalAxis, ...] = ()
    external_kinematics: tuple[ExternalKinematic, ...] = ()
    #: ``$MAIN_AXIS``: the main axes' kind (``#NR`` articulated arm, ``#CC`` SCARA, ``#SS``
    #: gantry; KR C2 machine-data handbook §2.1.145); ``#NR`` for the yaml robot
    main_axis: str = "#NR"
    #: the distance (deg) below which a PTP at reduced ``$VEL_AXIS`` does not ramp to its speed, per
    #: axis (robot/limits.py ``ptp_axis_accelerations``): identified from a robot's KUKA Trace
    #: recordings (robot/identified.py); () for a robot without: no such bound
    ptp_ramp_deg: tuple[float, ...] = ()
    #: the short-ramp law of a synchronised PTP (robot/planner.py ``short_ramp_scale``): a PTP at a
    #: reduced ``$VEL_AXIS`` (a leading axis below 100 %) whose dynamics would ramp to its speed in
    #: less than ``ptp_short_ramp_below_s`` (s, at 100 % override)
    #: ramps in ``ptp_short_ramp_s2 / t`` instead (s²); identified from a robot's KUKA Trace
    #: recordings (robot/kukatrace/identify.py ``fit_short_ramp``), 0: no such law
    ptp_short_ramp_s2: float = 0.0
    ptp_short_ramp_below_s: float = 0.0
    #: the acceleration (deg/s²) an axis loses per deg/s of its speed while it accelerates in a PTP,
    #: and gains while it brakes (its friction over its inertia, 1/s; robot/profiles.py
    #: ``FrictionProfile``): identified from a robot's KUKA Trace recordings (robot/identified.py);
    #: () for a robot without: the trapezoid
    ptp_friction: tuple[float, ...] = ()
    #: the IPO cycles over which the controller's setpoints are averaged (in axis space) before the
    #: robot's measured axes follow them: the actual-value model ``krl trace compare`` puts a
    #: simulated run's setpoints through (robot/kukatrace/actual.py); identified from a robot's
    #: recordings (robot/identified.py), 1 (none) for a robot without
    actual_filter_cycles: int = 1
    #: the IPO cycles of that average for a PTP's setpoints (KSS holds a PTP filter beside the CP
    #: one, ``$DEF_FLT_PTP`` and ``$DEF_FLT_CP``; robot/actualvalue.py), identified from a robot's
    #: recordings (robot/kukatrace/identify.py ``fit_filter_ptp``); None: ``actual_filter_cycles``
    actual_filter_cycles_ptp: int | None = None
    #: the drives' following error behind the averaged setpoints (robot/kukatrace/actual.py
    #: ``following_error``: ``inertia_s2``, ``coulomb_deg``, ``viscous_s`` per axis and
    #: ``coulomb_speed_deg_s``), identified from a robot's recordings (robot/identified.py), or None
    actual_following: dict[str, Any] | None = field(default=None, compare=False, repr=False)
    #: the IPO cycles the measured axes lag that model by (a dead time: robot/actualvalue.py),
    #: identified from a robot's recordings (robot/identified.py), 0 for a robot without
    actual_dead_cycles: int = 0
    #: the settling lag of one axis' actual value while it brakes (robot/actualvalue.py, robot/settlelag.py):
    #: ``axis`` (1-based), ``below_deg_s``, ``cycles_per_kg_m2``; identified from a robot's recordings
    #: (robot/kukatrace/identify.py ``fit_settle_lag``), None for a robot without
    actual_settle_lag: dict[str, Any] | None = field(default=None, compare=False, repr=False)
    #: the arm's identified dynamic model (robot/dynamics.py ``ArmDynamics``: link masses, centres of
    #: mass and inertias, rotor inertias, the drives' torque limits, the capped axes, the rated
    #: payload), or None: a PTP's accelerations are then the axes' own (robot/limits.py)
    dynamics: dict[str, Any] | None = field(default=None, compare=False, repr=False)

    @property
    def n_axes(self) -> int:
        """The robot's axis count: A1..An (``len(joints)``; six for the arms and palletizers,
        four for a SCARA); the external axes E1..E6 are not counted."""
        return len(self.joints)

    @property
    def limits_deg(self) -> tuple[tuple[float, float], ...]:
        """(``$SOFTN_END``, ``$SOFTP_END``) per axis, deg."""
        return tuple(j.limit_deg for j in self.joints)

    @property
    def softn_end(self) -> tuple[float, ...]:
        return tuple(j.limit_deg[0] for j in self.joints)

    @property
    def softp_end(self) -> tuple[float, ...]:
        return tuple(j.limit_deg[1] for j in self.joints)

    @property
    def max_speed_deg_s(self) -> tuple[float, ...]:
        return tuple(j.max_speed_deg_s for j in self.joints)

    @property
    def max_acc_deg_s2(self) -> tuple[float, ...]:
        return tuple(j.max_acc_deg_s2 for j in self.joints)

    @property
    def max_jerk_deg_s3(self) -> tuple[float, ...]:
        return tuple(j.max_jerk_deg_s3 for j in self.joints)

    @property
    def def_advance(self) -> int:
        """``$ADVANCE`` at boot: the machine data's ``def_advance`` (3 when it gives none)."""
        return int(self.motion_defaults.get("def_advance", 3))

    @property
    def n_ext(self) -> int:
        """The number of external axes E1..En."""
        return len(self.external_axes)

    @property
    def all_max_speed(self) -> tuple[float, ...]:
        """Axis speeds of A1..An (deg/s, a linear axis mm/s) and then E1..En (mm/s or deg/s):
        the planner's axes."""
        return self.max_speed_deg_s + tuple(e.max_speed for e in self.external_axes)

    @property
    def all_max_acc(self) -> tuple[float, ...]:
        """Axis accelerations of A1..An and E1..En (deg/s^2, mm/s^2)."""
        return self.max_acc_deg_s2 + tuple(e.max_acc for e in self.external_axes)

    @property
    def home_all(self) -> tuple[float, ...]:
        """``$AXIS_HOME[1]``: A1..An and E1..En."""
        return tuple(self.home_deg) + tuple(e.home for e in self.external_axes)


def _floats(seq) -> tuple[float, ...]:
    return tuple(float(v) for v in seq)


def _cart(d: dict[str, Any]) -> CartLimits:
    def pick(prefix: str) -> float:
        for k, v in d.items():
            if k.split("_")[0] == prefix:
                return float(v)
        raise KeyError(prefix)

    return CartLimits(pick("cp"), pick("ori1"), pick("ori2"))


def _yaml_joints(doc: dict, md: dict) -> list[JointData]:
    """The joints of the machine data yaml `doc` (its kinematics section `md`): the maximum speed
    from the motor speed and gear ratio where given (robot-model.md §5), else the yaml's."""
    rpm = md.get("vel_axis_ma_rpm")
    ratios = md.get("rat_mot_ax_n_d")
    joints = []
    for i, j in enumerate(doc["joints"]):
        if rpm is not None and ratios is not None:
            n, d = ratios[i]
            vmax = float(rpm[i]) / abs(float(n) / float(d)) * 6.0  # robot-model.md §5
        else:
            vmax = float(j["max_speed_deg_s"])
        joints.append(JointData(
            name=j["name"],
            axis=int(str(j.get("kuka_axis", f"A{i + 1}")).lstrip("Aa")),
            limit_deg=(float(j["limit_deg"][0]), float(j["limit_deg"][1])),
            max_speed_deg_s=vmax,
            max_acc_deg_s2=math.degrees(float(j["max_acc_rad_s2"])),
            max_jerk_deg_s3=float(j["max_jerk_deg_s3"]),
            origin_mm=tuple(1000.0 * float(v) for v in j["origin_xyz_m"]),  # type: ignore[arg-type]
            joint_axis=_floats(j["axis"]),  # type: ignore[arg-type]
            urdf_max_speed_deg_s=float(j["max_speed_deg_s"]),
            parent=j.get("parent", ""),
            child=j.get("child", ""),
            kuka_sign=int(j.get("kuka_sign", 1)),
            origin_rpy_rad=_floats(j.get("origin_rpy_rad", [0.0, 0.0, 0.0])),  # type: ignore[arg-type]
        ))
    return joints


def _yaml_flange(doc: dict) -> tuple[tuple[float, float, float, float], np.ndarray, np.ndarray]:
    """((w, x, y, z), roll-pitch-yaw rad, position mm) of the KUKA flange of the yaml `doc`:
    link_6 -> flange -> tool0 through its fixed frames."""
    frames = {f["name"]: f for f in doc["fixed_frames"]}
    # link_6 -> KUKA flange (URDF tool0) = (link_6 -> flange) * (flange -> tool0)
    fl_pos = np.zeros(3)
    fl_rot = Rotation.identity()
    chain = []
    name = "tool0"
    while name in frames:
        chain.append(frames[name])
        name = frames[name].get("parent", "")
    for f in reversed(chain):
        fl_pos = fl_pos + fl_rot.apply(1000.0 * np.asarray(f["origin_xyz_m"], dtype=float))
        fl_rot = fl_rot * Rotation.from_euler("xyz", f["origin_rpy_rad"])
    x, y, z, w = fl_rot.as_quat()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # pitch = 90 deg: gimbal lock, any split is fine
        fl_rpy = fl_rot.as_euler("xyz")
    return (w, x, y, z), fl_rpy, fl_pos


def load_machine(path: str | Path | None = None) -> MachineData:
    """Read the machine data yaml (default: ``robot/data/kr6_r900.yaml``).

    Returns a frozen :class:`MachineData`; geometry converted to mm, accelerations
    to deg/s^2. Raises ``FileNotFoundError``/``KeyError`` for a missing file or key.
    A file read before in this process (same resolved path, size and modification time) gives
    the model made then (:data:`_CACHE`, as robot/mada.py ``load_mada`` keeps a ``$machine.dat``'s).
    """
    p = Path(path) if path is not None else DEFAULT_MACHINE_FILE
    st = p.stat()
    key = (str(p.resolve()), str(p), st.st_mtime_ns, st.st_size)
    got = _CACHE.get(key)
    if got is None:
        got = _load_machine(p)
        _CACHE.put(key, got)
    return got


#: Models already read in this process, by (resolved path, path, mtime, size): every run of a
#: process (a conformance or audit worker, the tests) builds its robot from the same yaml, whose
#: read was 0.02 s of CPU per run (YAML's constructors), a quarter of a small program's run.
#: MachineData is frozen and its dicts are never written (a variant is made with
#: ``dataclasses.replace``, robot/description.py). The 16 last used, and any other while
#: something holds it (a program model: robot/heldcache.py).
_CACHE = HeldCache(16)


def _load_machine(p: Path) -> MachineData:
    # libyaml's parser where PyYAML has it (the same safe constructors; 0.3 s of a start-up)
    doc = yaml.load(p.read_text(encoding="utf-8"), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    md = doc["machine_data_kinematics"]
    joints = _yaml_joints(doc, md)
    (w, x, y, z), fl_rpy, fl_pos = _yaml_flange(doc)
    o = doc["opw"]
    opw = OPWParams(
        a1=1000.0 * o["a1"], a2=1000.0 * o["a2"], b=1000.0 * o["b"],
        c1=1000.0 * o["c1"], c2=1000.0 * o["c2"], c3=1000.0 * o["c3"], c4=1000.0 * o["c4"],
        offsets_deg=tuple(math.degrees(v) for v in o["offsets_rad"]),
        sign_corrections=tuple(int(s) for s in o["sign_corrections"]),
    )
    mdf = doc.get("motion_defaults", {})
    return MachineData(
        name=str(doc["robot"]),
        joints=tuple(joints),
        home_deg=_floats(doc["home_deg"]),
        mastering_deg=_floats(doc.get("mastering_mames_deg", doc["home_deg"])),
        opw=opw,
        flange_quat_wxyz=(float(w), float(x), float(y), float(z)),
        flange_rpy_rad=_floats(fl_rpy),  # type: ignore[arg-type]
        flange_pos_mm=_floats(fl_pos),  # type: ignore[arg-type]
        robroot_frame=_floats(doc.get("robroot_mm_deg", [0.0] * len(CART_KEYS))),
        default_tool_frame=_floats(mdf.get("tool_data_1_mm_deg", [0.0] * len(CART_KEYS))),
        status_phi_deg=float(doc["status_bit1_phi_deg"]),
        vel_ma=_cart(md["vel_ma"]),
        acc_ma=_cart(md["acc_ma"]),
        acc_ov=_cart(md["acc_ov"]),
        apo_dis_ptp_deg=_floats(md["apo_dis_ptp_deg"]),
        in_pos_ma_deg=_floats(md["in_pos_ma_deg"]),
        in_pos_car_mm=float(md["in_pos_car_mm"]),
        in_pos_ori_deg=float(md["in_pos_ori_deg"]),
        def_flt_ptp=int(md["def_flt_ptp"]),
        def_flt_cp=int(md["def_flt_cp"]),
        ipo_cycle_s=float(doc.get("ipo_cycle_s", 0.012)),
        motion_defaults=dict(mdf),
        default_load=dict(doc.get("default_load", {})),
        reach_wrist_point_mm=float(doc["reach_wrist_point_mm"]),
        home_flange_pose=_floats(doc["home_flange_pose_mm_deg"]),
        source=str(p),
        raw=doc,
    )
