"""What the advance run hands to the main run: motion requests (reference §6.1-§6.3, §6.10).

An interpreter builds one :class:`MotionRequest` per motion statement (or SPLINE block) and
passes it to :meth:`robot.controller.Controller.enqueue`. A request is plain data:

* ``kind``: ``PTP``, ``LIN``, ``CIRC``, ``SPTP``, ``SLIN``, ``SCIRC`` or ``SPLINE``;
  ``relative=True`` for the ``_REL`` forms (``rel_frame`` ``"BASE"`` or ``"TOOL"``);
* ``target``: dict of named components, upper-case KRL names: ``A1``..``A6`` (an AXIS /
  E6AXIS target, deg) or ``X``, ``Y``, ``Z`` (mm), ``A``, ``B``, ``C`` (deg), ``S``, ``T``
  (a POS / E6POS / FRAME target in the motion's ``$BASE`` for its ``$TOOL``). Partial
  aggregates are fine: missing components keep the start position's values (§6.3); for
  ``_REL`` they are 0. External axes ``E1``..``E6`` move the robot's external axes
  (robot/axismap.py); those it does not have are ignored.
* ``aux`` (CIRC/SCIRC auxiliary point, same form), ``ca`` (circular angle, deg);
* ``approx``: ``C_PTP``, ``C_DIS``, ``C_VEL``, ``C_ORI``, ``C_SPL`` or None (exact stop);
  ``approx2`` the second keyword of ``PTP P C_PTP C_DIS`` (used for PTP -> CP blends);
* ``params``: :class:`MotionParams`, a snapshot of the motion system variables at
  planning time (advance run);
* ``triggers``: the TRIGGERs (:class:`Trigger`) that precede the statement;
* ``segments``: for ``SPLINE`` the block's :class:`SplineSegment` list;
* ``file``/``line``: source position, for the trace and for errors.

Units: mm, deg, s, m/s (``$VEL.CP``), m/s^2 (``$ACC.CP``), % (``$VEL_AXIS``, ``$ACC_AXIS``,
``$OV_PRO``, ``$APO.CPTP``, ``$APO.CVEL``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

from .axismap import CART_KEYS, EXT_KEYS
from .axismap import ROBOT_KEYS as AXIS_KEYS

KINDS = ("PTP", "LIN", "CIRC", "SPTP", "SLIN", "SCIRC", "SPLINE")
APPROX = ("C_PTP", "C_DIS", "C_VEL", "C_ORI", "C_SPL")
Frame6 = tuple[float, float, float, float, float, float]
NULLFRAME: Frame6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def _enum(v: str) -> str:
    return str(v).strip().lstrip("#").upper()


@dataclass(frozen=True)
class MotionParams:
    """Snapshot of the motion system variables (reference §7.3), taken by the advance run.

    Attributes:
        vel_cp: ``$VEL.CP`` m/s. vel_ori1, vel_ori2: ``$VEL.ORI1/ORI2`` deg/s.
        acc_cp: ``$ACC.CP`` m/s^2. acc_ori1, acc_ori2: ``$ACC.ORI1/ORI2`` deg/s^2.
        vel_axis, acc_axis: ``$VEL_AXIS[1..6]``, ``$ACC_AXIS[1..6]`` in % of machine data.
        apo_cptp (%), apo_cdis (mm), apo_cvel (%), apo_cori (deg): ``$APO``.
        tool, base: ``$TOOL``, ``$BASE`` as (X, Y, Z, A, B, C) mm/deg.
        ori_type: ``VAR``, ``CONSTANT`` or ``JOINT`` (``$ORI_TYPE``, '#' optional).
        circ_type: ``BASE`` or ``PATH`` (``$CIRC_TYPE``).
        ov_pro: ``$OV_PRO`` %.
        ipo_mode: ``BASE`` or ``TCP`` (external TCP, robot/external_tcp.py).
        base_kin: the BASE kinematic ``$BASE`` is linked to (``"#EASYS"`` .. ``"#EFSYS"``,
            KSS ``EK``; robot/external.py): the base turns with its external axes; None: fixed.
        base_root: with `base_kin`, the kinematic's root in ``$WORLD`` (``EK``'s first argument,
            ``MACHINE_DEF[].ROOT``; None: ``$WORLD``): ``$BASE_C(E) = root : ETn(E) : base``.
        load, load_a3: ``$LOAD`` (the payload on the flange) and ``$LOAD_A3`` (the supplementary
            load on axis 3) as (M kg, CM X, Y, Z mm, A, B, C deg, J X, Y, Z kg m²), KSS's LOAD
            structure; None when not set (robot/dynamics.py takes M < 0 or None as the rated
            payload, issue 73).
    """

    vel_cp: float = 2.0
    vel_ori1: float = 200.0
    vel_ori2: float = 200.0
    acc_cp: float = 2.3
    acc_ori1: float = 100.0
    acc_ori2: float = 100.0
    vel_axis: tuple[float, ...] = (100.0,) * 6
    acc_axis: tuple[float, ...] = (100.0,) * 6
    apo_cptp: float = 50.0
    apo_cdis: float = 3.0
    apo_cvel: float = 100.0
    apo_cori: float = 5.0
    tool: Frame6 = NULLFRAME
    base: Frame6 = NULLFRAME
    ori_type: str = "VAR"
    circ_type: str = "BASE"
    ov_pro: float = 100.0
    ipo_mode: str = "BASE"
    base_kin: str | None = None
    base_root: Frame6 | None = None
    load: tuple[float, ...] | None = None
    load_a3: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "ori_type", _enum(self.ori_type))
        object.__setattr__(self, "circ_type", _enum(self.circ_type))
        object.__setattr__(self, "ipo_mode", _enum(self.ipo_mode))
        object.__setattr__(self, "vel_axis", tuple(float(v) for v in self.vel_axis))
        object.__setattr__(self, "acc_axis", tuple(float(v) for v in self.acc_axis))
        object.__setattr__(self, "tool", tuple(float(v) for v in self.tool))
        object.__setattr__(self, "base", tuple(float(v) for v in self.base))

    @staticmethod
    def initmov(machine: Any = None, *, tool: Frame6 | None = None) -> "MotionParams":
        """The values after ``BAS(#INITMOV,0)`` (reference §6.9, robot-model.md §10):
        ``$VEL_AXIS`` 100 %, ``$ACC_AXIS`` 100 % (``$ADAP_ACC=#STEP2``), ``$VEL.CP`` 2.0 m/s,
        ``$ACC.CP`` 2.3 m/s^2, ORI 200 deg/s / 100 deg/s^2, ``$APO`` {CPTP 50, CDIS 3, CVEL 100,
        CORI 5}, ``$BASE`` = ``$WORLD``. ``$TOOL`` is ``tool`` (default ``$NULLFRAME``; BASIS
        would use ``TOOL_DATA[1]``)."""
        d: dict[str, Any] = dict(getattr(machine, "motion_defaults", {}) or {})
        return MotionParams(
            vel_cp=float(d.get("def_vel_cp_m_s", 2.0)),
            vel_ori1=float(d.get("def_vel_ori1_deg_s", 200.0)),
            vel_ori2=float(d.get("def_vel_ori2_deg_s", 200.0)),
            acc_cp=float(d.get("def_acc_cp_m_s2", 2.3)),
            acc_ori1=float(d.get("def_acc_ori1_deg_s2", 100.0)),
            acc_ori2=float(d.get("def_acc_ori2_deg_s2", 100.0)),
            vel_axis=(float(d.get("def_vel_ptp_pct", 100.0)),) * 6,
            acc_axis=(100.0,) * 6,
            apo_cptp=float(d.get("def_apo_cptp_pct", 50.0)),
            apo_cdis=float(d.get("def_apo_cdis_mm", 3.0)),
            apo_cvel=float(d.get("def_apo_cvel_pct", 100.0)),
            apo_cori=float(d.get("def_apo_cori_deg", 5.0)),
            tool=tool if tool is not None else NULLFRAME,
        )

    @staticmethod
    def from_sysvars(values: Any, default: "MotionParams | None" = None) -> "MotionParams":
        """Build a snapshot from KRL system-variable values (reference §6.10, §7.3).

        ``values`` maps names (case-insensitive, ``$`` optional) to values: ``$VEL`` and
        ``$ACC`` as mappings with CP/ORI1/ORI2, ``$VEL_AXIS``/``$ACC_AXIS`` as 6-sequences
        (or mappings 1..6), ``$APO`` as a mapping with CVEL/CPTP/CDIS/CORI, ``$TOOL``/
        ``$BASE`` as mappings X..C or 6-sequences, ``$ORI_TYPE``/``$CIRC_TYPE``/``$IPO_MODE``
        as enum names, ``$OV_PRO`` as a number. Missing names (or missing components) keep
        the values of ``default`` (INITMOV values if None)."""
        d = default or MotionParams()
        v = {str(k).upper().lstrip("$"): x for k, x in dict(values).items()}

        def comp(m: Any, key: str, old: float) -> float:
            if m is None:
                return old
            m = {str(k).upper(): x for k, x in dict(m).items()}
            return float(m[key]) if m.get(key) is not None else old

        def six(x: Any, old: tuple[float, ...], keys: tuple[str, ...]) -> tuple[float, ...]:
            if x is None:
                return old
            if hasattr(x, "items"):
                m = {str(k).upper(): y for k, y in x.items()}
                return tuple(float(m[k]) if m.get(k) is not None else old[i]
                             for i, k in enumerate(keys))
            return tuple(float(y) for y in list(x)[:len(keys)])

        vel, acc, apo = v.get("VEL"), v.get("ACC"), v.get("APO")
        return MotionParams(
            vel_cp=comp(vel, "CP", d.vel_cp), vel_ori1=comp(vel, "ORI1", d.vel_ori1),
            vel_ori2=comp(vel, "ORI2", d.vel_ori2),
            acc_cp=comp(acc, "CP", d.acc_cp), acc_ori1=comp(acc, "ORI1", d.acc_ori1),
            acc_ori2=comp(acc, "ORI2", d.acc_ori2),
            vel_axis=six(v.get("VEL_AXIS"), d.vel_axis, ("1", "2", "3", "4", "5", "6")),
            acc_axis=six(v.get("ACC_AXIS"), d.acc_axis, ("1", "2", "3", "4", "5", "6")),
            apo_cptp=comp(apo, "CPTP", d.apo_cptp), apo_cdis=comp(apo, "CDIS", d.apo_cdis),
            apo_cvel=comp(apo, "CVEL", d.apo_cvel), apo_cori=comp(apo, "CORI", d.apo_cori),
            tool=six(v.get("TOOL"), d.tool, ("X", "Y", "Z", "A", "B", "C")),  # type: ignore[arg-type]
            base=six(v.get("BASE"), d.base, ("X", "Y", "Z", "A", "B", "C")),  # type: ignore[arg-type]
            ori_type=str(v.get("ORI_TYPE") or d.ori_type),
            circ_type=str(v.get("CIRC_TYPE") or d.circ_type),
            ov_pro=float(v["OV_PRO"]) if v.get("OV_PRO") is not None else d.ov_pro,
            ipo_mode=str(v.get("IPO_MODE") or d.ipo_mode),
        )

    def with_(self, **changes: Any) -> "MotionParams":
        """A copy with some fields changed (e.g. for a spline ``WITH`` clause)."""
        return replace(self, **changes)


@dataclass(frozen=True)
class Trigger:
    """A path-synchronous TRIGGER (reference §5.18).

    Attributes:
        distance: 0 (start point) or 1 (end point) for ``WHEN DISTANCE=``; None for PATH.
        path_mm: ``WHEN PATH=`` shift in mm (negative = before the reference point).
        onstart: ``ONSTART``: the PATH reference is the start point instead of the end point.
        delay_ms: ``DELAY=`` in ms (negative = earlier).
        action: opaque object of the interpreter (the statement to run when it fires;
            arguments were already evaluated in the advance run).
        prio: ``PRIO=`` value or None.
        line: source line of the TRIGGER statement.
    """

    distance: int | None = None
    path_mm: float | None = None
    onstart: bool = False
    delay_ms: float = 0.0
    action: Any = None
    prio: int | None = None
    line: int | None = None

    def __post_init__(self) -> None:
        if (self.distance is None) == (self.path_mm is None):
            raise ValueError("a TRIGGER needs exactly one of distance (0/1) or path_mm")
        if self.distance is not None and self.distance not in (0, 1):
            raise ValueError("TRIGGER WHEN DISTANCE must be 0 or 1")


@dataclass(frozen=True)
class CondStop:
    """A conditional stop, ``STOP WHEN PATH = path_mm [ONSTART] IF condition`` (KSS 8.3 and later;
    docs/robot.md, "Conditional stop"). It travels among the next motion's (spline segment's)
    ``triggers``: the planner places its stop point as a TRIGGER WHEN PATH's switching point,
    `path_mm` from the end point (the start point with `onstart`; negative: before it).

    Attributes:
        path_mm: the shift of the stop point along the path (mm).
        onstart: the reference is the start point.
        condition: opaque to the robot: a zero-argument callable of the interpreter, True when
            the robot is to stop; the main run calls it at the braking point and, once it
            brakes or stands, at every IPO cycle.
        line: source line of the statement.
    """

    path_mm: float
    onstart: bool = False
    condition: Any = None
    line: int | None = None


@dataclass(frozen=True)
class SplineSegment:
    """One segment of a SPLINE block (reference §6.2): ``kind`` ``SPL``, ``SLIN`` or
    ``SCIRC``; target/aux as in :class:`MotionRequest`; ``params`` overrides the block's
    params (a ``WITH`` clause) or None; ``triggers`` attached to this segment."""

    kind: str
    target: dict[str, float]
    aux: dict[str, float] | None = None
    ca: float | None = None
    params: MotionParams | None = None
    triggers: tuple[Trigger, ...] = ()
    line: int | None = None


@dataclass
class MotionRequest:
    """A motion statement as planned by the advance run (see the module docstring)."""

    kind: str
    target: dict[str, float] = field(default_factory=dict)
    params: MotionParams = field(default_factory=MotionParams)
    approx: str | None = None
    approx2: str | None = None
    aux: dict[str, float] | None = None
    ca: float | None = None
    relative: bool = False
    rel_frame: str = "BASE"
    triggers: tuple[Trigger, ...] = ()
    segments: tuple[SplineSegment, ...] = ()
    file: str | None = None
    line: int | None = None
    id: int = 0  # set by Controller.enqueue

    def __post_init__(self) -> None:
        k = self.kind.upper()
        if k.endswith("_REL"):
            k = k[:-4]
            self.relative = True
        if k not in KINDS:
            raise ValueError(f"unknown motion kind {self.kind!r}")
        self.kind = k
        self.target = {str(key).upper(): v for key, v in (self.target or {}).items()}
        if self.aux is not None:
            self.aux = {str(key).upper(): v for key, v in self.aux.items()}
        for a in ("approx", "approx2"):
            v = getattr(self, a)
            if v is not None:
                v = _enum(v)
                if v not in APPROX:
                    raise ValueError(f"unknown approximation {v!r}")
                setattr(self, a, v)
        self.rel_frame = _enum(self.rel_frame)
        self.triggers = tuple(self.triggers)
        self.segments = tuple(self.segments)

    @property
    def type_name(self) -> str:
        """The statement name for the trace, e.g. ``LIN_REL``."""
        return self.kind + ("_REL" if self.relative else "")

    @property
    def is_axis_target(self) -> bool:
        """True for an AXIS/E6AXIS target (any of A1..A6 given)."""
        return any(k in self.target for k in AXIS_KEYS)

