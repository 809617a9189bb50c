"""The robot of a KRC backup, built from its machine data (``R1/Mada/$machine.dat``, and
``$robcor.dat`` for the default load), into the same :class:`~robot.machine.MachineData` as
the KR 6 R900 yaml, so kinematics, inverse kinematics, the MuJoCo model and the planner's
limits follow from the same numbers.

Sources: shared/docs/robot-model.md §4.3 (KUKA's chain rebuilt from ``$TIRORO``,
``$LENGTH_A``, ``$LENGTH_B``, ``$TX3P3``, ``$DH_4``, ``$DH_5``, ``$TFLWP``, ``$AXIS_DIR``),
§5 (speeds from ``$VEL_AXIS_MA`` and ``$RAT_MOT_AX``), §7 (``$ROBROOT``), §8 (status); KUKA's
KR C2 machine-data handbook "Maschinendaten 12.0400 en" (2005) §2.1.9 ``$ERSYSROOT``, §2.1.10
``$RAT_MOT_AX`` (linear axes: motor revolutions per 1000 mm), §2.1.47 ``$RAISE_TIME``, §2.2
the external axes (``$EX_AX_NUM``, ``$EX_KIN``, ``$ETn_AX``, ``$ETn_TA1KR`` ..
``$ETn_TFLA3``). The values are read through the project's KRL front end (robot/datalist.py).
KR C2 and KR C4 machine data use the same names; what a KR C2 file lacks (``$AXIS_JERK``)
is derived by the rules of :data:`RULES` and marked "derived" in
:attr:`MachineData.provenance` (``krl robot show``).

The chain is the robot's kinematic family's (robot/kinematics/families.py ``machine_geometry``:
the arm's of robot/kinematics/arm.py for ``$MAIN_AXIS=#NR``, the SCARA's for ``#CC``); it becomes
URDF-style joints (robot/chain.py: translation-only joint origins, KUKA's directions in the joint
axes, ``q = radians(A_i)``, a linear axis in mm), n of them. Reading the machine data never
builds the inverse kinematics: robot/kinematics/ chooses the closed form the chain has (or
the numeric solver) when a tool moves the robot, so ``krl cell init``, ``krl check``,
``krl graph`` and ``krl diff`` never need it. A value the model cannot take is refused with
:class:`MachineDataError` naming the variable, its value and its file:line.
"""

from __future__ import annotations

import math
import warnings
import weakref
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from krl.archive import ArchiveError, is_archive
from krl.backups import BackupsError, holds_archives, one_backup
from krl.project import backup_of, find_backups, machine_data_file

from . import catalogue
from .axismap import CART_KEYS, EXT_KEYS, ROBOT_KEYS
from .chain import chain_forward, chain_to_joints
from .datalist import DataListError, DataValue, read_data_list
from .frames import matrix_to_frame
from .heldcache import HeldCache
from .described_dynamics import description_dynamics
from .identified import apply_identified, identified_file
from .kinematics.families import machine_geometry
from .machine import (
    CartLimits, ExternalAxis, ExternalKinematic, JointData, MachineData, library_robots, load_machine,
)
from .madavalues import MachineDataError, krl_value
from .named import Named, named_robot
from .madavalues import axes as _axes
from .madavalues import flag as _flag
from .madavalues import frame as _frame
from .madavalues import frame6 as _frame6
from .madavalues import get as _get
from .madavalues import num as _num

#: ``$EX_KIN``'s external kinematic systems ET1..ET6 (KSS kinematic systems manual)
MAX_EXT_KINEMATICS = 6

#: The rules for values that machine data lack (docs/robot.md, "Robots from machine data"); those of
#: a family's geometry are the family's (robot/kinematics/arm.py RULES).
RULES = {
    "max_acc_deg_s2": "derived: sqrt(v_max * $AXIS_JERK[i]), the peak acceleration of a jerk-limited "
                      "ramp from rest to full axis speed without a constant-acceleration phase "
                      "(the KR C4 takes accelerations from its dynamic model, $ADAP_ACC)",
    "max_acc_raise_time": "derived: v_max / ($RAISE_TIME[i] + $DEF_FLT_PTP/2) ms, the time in which the "
                          "axis reaches its rated speed (KR C2 machine-data handbook §2.1.47)",
    "max_acc_default": "derived: v_max / 0.2 s ($AXIS_JERK and $RAISE_TIME not set; the ramp time of the "
                       "KR C4 robots of the corpus, 0.1-0.2 s)",
    "max_jerk": "derived: a_max / $DEF_FLT_PTP ms ($AXIS_JERK not set: the $DEF_FLT_PTP filter spreads "
                "the acceleration step over its length)",
    "ipo_cycle_s": "derived: 12 ms interpolation cycle of the KR C4 (robot-model.md §10)",
    "motion_defaults": "derived: KSS defaults of bas.src/$config.dat (robot/data/kr6_r900.yaml "
                       "motion_defaults)",
    "default_load": "derived: none given ($robcor.dat absent)",
    "external_speed": "derived: $VEL_AXIS_MA / |$RAT_MOT_AX.N / .D| * 6 deg/s (rotary) or * 1000/60 mm/s "
                      "(linear: N/D motor revolutions per 1000 mm, KR C2 machine-data handbook §2.1.10)",
    "ersysroot": "derived: $NULLFRAME ($ERSYSROOT not set)",
    "a5_led": "derived: A5 led by the parallelogram, the flange kept vertical ($NUM_AX=4 with "
              "$DEF_A4FIX=TRUE leaves A5 no drive, whatever $DEF_A5LINK says)",
    "easys_root": "derived: $WORLD (the root point of a BASE kinematic is MACHINE_DEF[].ROOT of "
                  "$config.dat, not machine data)",
}

#: ``$AXIS_TYPE`` values (KR C2 machine-data handbook §2.1.4): 1 linear, 3 rotary, 5 endless.
_AXIS_TYPES = {1: "linear", 3: "rotary", 5: "endless"}
#: ``$EX_KIN`` systems the model builds (the handbook §2.2.5).
_EX_SYSTEMS = ("#ERSYS", "#EASYS", "#EBSYS", "#ECSYS", "#EDSYS", "#EESYS", "#EFSYS")
#: The model's A4 limits when ``$DEF_A4FIX`` holds A4 at 0 (deg).
_FIXED = (0.0, 0.0)


def _structure(machine: dict[str, DataValue], source: str, prov: dict[str, str]) -> tuple[bool, bool]:
    """The robot's kinematic class and palletizer flags; refuses what the model does not build
    (the family's geometry checks ``$NUM_AX``)."""
    kin = machine.get("$KINCLASS")
    if kin is not None and kin.value not in (None, "#STANDARD"):
        raise MachineDataError(f"{kin.where()}: $KINCLASS={kin.value}: only the #STANDARD kinematic class "
                               f"(the KUKA arm of $TIRORO .. $TFLWP) is simulated")
    if kin is not None:
        prov["$KINCLASS"] = kin.where()
    a4fix, dv4 = _flag(machine, "$DEF_A4FIX")
    a5link, dv5 = _flag(machine, "$DEF_A5LINK")
    if a5link and not a4fix:
        assert dv5 is not None
        raise MachineDataError(f"{dv5.where()}: $DEF_A5LINK=TRUE with $DEF_A4FIX=FALSE: the parallelogram of "
                               f"the 4-axis palletizer needs A4 fixed at 0")
    for key, dv in (("$DEF_A4FIX", dv4), ("$DEF_A5LINK", dv5)):
        if dv is not None:
            prov[key] = dv.where()
    return a4fix, a5link


#: the ramp time (s) of an axis whose machine data give neither ``$AXIS_JERK`` nor ``$RAISE_TIME``
#: (``RULES["max_acc_default"]``)
DEFAULT_RAMP_S = 0.2


def default_dynamics(vmax: float, flt_ptp: float) -> tuple[float, float, dict[str, str]]:
    """(a_max, jerk, provenance) of an axis of speed `vmax` whose data give no acceleration (a robot
    description): :data:`RULES`' ``max_acc_default`` and ``max_jerk`` (`flt_ptp`: ``$DEF_FLT_PTP``, ms)."""
    acc = vmax / DEFAULT_RAMP_S
    return acc, _jerk(acc, flt_ptp), {"max_acc_deg_s2": RULES["max_acc_default"], "$AXIS_JERK": RULES["max_jerk"]}


def _jerk(acc: float, flt_ptp: float) -> float:
    """The jerk of an axis without ``$AXIS_JERK`` (``RULES["max_jerk"]``): the acceleration `acc`
    spread over the ``$DEF_FLT_PTP`` filter (ms; at least one 12 ms IPO cycle)."""
    return acc / (max(flt_ptp, 12.0) / 1000.0)


def _joint_limits(machine: dict[str, DataValue], source: str, prov: dict[str, str], a4fix: bool,
                  flt_ptp: float, kinds: tuple[str, ...]) -> list[tuple[tuple[float, float], float, float, float]]:
    """(limits, v_max, a_max, jerk, data limits) of A1..An (a linear axis in mm), with the rules of
    :data:`RULES` for what is missing. The limits are the model's: ``$DEF_A4FIX`` holds A4 at 0
    (:data:`_FIXED`); the data limits are the file's ``$SOFTN_END``/``$SOFTP_END`` where they differ
    (None otherwise), which KRL reads and ``krl robot show`` prints (issue 85)."""
    n = len(kinds)
    lo, dv_lo = _axes(machine, "$SOFTN_END", source, n)
    hi, dv_hi = _axes(machine, "$SOFTP_END", source, n)
    speeds, dv_rpm, ratios = _speeds(machine, source, range(1, n + 1), [k == "linear" for k in kinds])
    jerk = raise_t = None
    if "$AXIS_JERK" in machine and machine["$AXIS_JERK"].value:
        jerk, dv_jerk = _axes(machine, "$AXIS_JERK", source, n)
        prov["$AXIS_JERK"] = dv_jerk.where(1)
        prov["max_acc_deg_s2"] = RULES["max_acc_deg_s2"]
    elif "$RAISE_TIME" in machine and machine["$RAISE_TIME"].value:
        raise_t, dv_rt = _axes(machine, "$RAISE_TIME", source, n)
        prov["$RAISE_TIME"] = dv_rt.where(1)
        prov["max_acc_deg_s2"] = RULES["max_acc_raise_time"]
        prov["$AXIS_JERK"] = RULES["max_jerk"]
    else:
        prov["max_acc_deg_s2"] = RULES["max_acc_default"]
        prov["$AXIS_JERK"] = RULES["max_jerk"]
    out = []
    for i in range(n):
        vmax = speeds[i]
        if lo[i] > hi[i]:
            raise MachineDataError(f"{dv_lo.where(i + 1)}: $SOFTN_END[{i + 1}]={lo[i]:g} is above "
                                   f"$SOFTP_END[{i + 1}]={hi[i]:g}")
        if jerk is not None:
            if jerk[i] <= 0:
                raise MachineDataError(f"{machine['$AXIS_JERK'].where(i + 1)}: $AXIS_JERK[{i + 1}]={jerk[i]:g}: "
                                       f"a positive jerk was expected")
            acc, j = math.sqrt(vmax * jerk[i]), jerk[i]
        else:
            if raise_t is not None:
                ramp = (raise_t[i] + flt_ptp / 2.0) / 1000.0
                if ramp <= 0:
                    raise MachineDataError(f"{machine['$RAISE_TIME'].where(i + 1)}: $RAISE_TIME[{i + 1}]="
                                           f"{raise_t[i]:g}: a positive time was expected")
            else:
                ramp = DEFAULT_RAMP_S
            acc = vmax / ramp
            j = _jerk(acc, flt_ptp)
        limit, data = (lo[i], hi[i]), None
        if i == 3 and a4fix and limit != _FIXED:
            limit, data = _FIXED, limit
        out.append((limit, vmax, acc, j, data))
    prov["$SOFTN_END"], prov["$SOFTP_END"] = dv_lo.where(1), dv_hi.where(1)
    prov["$VEL_AXIS_MA"], prov["$RAT_MOT_AX"] = dv_rpm.where(1), ratios.where(1)
    prov["max_speed_deg_s"] = "derived: $VEL_AXIS_MA[i] / |$RAT_MOT_AX[i].N / .D| * 6 (robot-model.md §5)"
    return out


def _speeds(machine: dict[str, DataValue], source: str, indices, linear: list[bool]
            ) -> tuple[list[float], DataValue, DataValue]:
    """Axis speeds (deg/s, or mm/s for a linear axis) of the machine-data indices `indices`."""
    rpm_dv = _get(machine, "$VEL_AXIS_MA", source)
    ratios = _get(machine, "$RAT_MOT_AX", source)
    out = []
    for k, i in enumerate(indices):
        rpm = rpm_dv.value.get(i) if isinstance(rpm_dv.value, dict) else None
        if rpm is None:
            raise MachineDataError(f"{rpm_dv.where()}: $VEL_AXIS_MA[{i}] is not set")
        rpm = _num(rpm, rpm_dv.where(i), f"$VEL_AXIS_MA[{i}]")
        r = ratios.value.get(i) if isinstance(ratios.value, dict) else None
        if not isinstance(r, dict) or "N" not in r or "D" not in r:
            raise MachineDataError(f"{ratios.where(i)}: $RAT_MOT_AX[{i}] is not set")
        n = _num(r["N"], ratios.where(i), f"$RAT_MOT_AX[{i}].N")
        d = _num(r["D"], ratios.where(i), f"$RAT_MOT_AX[{i}].D")
        if n == 0 or d == 0:
            raise MachineDataError(f"{ratios.where(i)}: $RAT_MOT_AX[{i}]={{N {n:g},D {d:g}}}: a zero N or D")
        # robot-model.md §5; linear axes: N/D motor revolutions per 1000 mm (handbook §2.1.10)
        v = rpm / abs(n / d) * (1000.0 / 60.0 if linear[k] else 6.0)
        if v <= 0:
            raise MachineDataError(f"{rpm_dv.where(i)}: $VEL_AXIS_MA[{i}]={rpm:g}: a positive speed was expected")
        out.append(v)
    return out, rpm_dv, ratios


def _external(machine: dict[str, DataValue], source: str, prov: dict[str, str], flt_ptp: float,
              home: dict[str, float]) -> tuple[tuple[ExternalAxis, ...], tuple[ExternalKinematic, ...]]:
    """The external axes (``$EX_AX_NUM``) and kinematic systems (``$EX_KIN``, ``$ETn_*``)."""
    num = machine.get("$EX_AX_NUM")
    if num is None or not num.value:
        return (), ()
    n = num.value
    if isinstance(n, bool) or not isinstance(n, int) or not 0 <= n <= len(EXT_KEYS):
        raise MachineDataError(f"{num.where()}: $EX_AX_NUM={krl_value(n)}: 0..{len(EXT_KEYS)} external axes were expected")
    prov["$EX_AX_NUM"] = num.where()
    types = machine.get("$AXIS_TYPE")
    kinds = []
    for e in range(1, n + 1):
        t = types.value.get(6 + e) if types is not None and isinstance(types.value, dict) else None
        if t not in _AXIS_TYPES:
            where = types.where(6 + e) if types is not None else source
            raise MachineDataError(f"{where}: $AXIS_TYPE[{6 + e}]={krl_value(t)}: E{e} must be 1 (linear), 3 (rotary) "
                                   f"or 5 (endless)")
        kinds.append(_AXIS_TYPES[t])
    if types is not None:
        prov["$AXIS_TYPE"] = types.where(7)
    idx = list(range(7, 7 + n))
    lo, dv_lo = _axes(machine, "$SOFTN_END", source, n, 7)
    hi, _ = _axes(machine, "$SOFTP_END", source, n, 7)
    speeds, _, _ = _speeds(machine, source, idx, [k == "linear" for k in kinds])
    prov["E_speed"] = RULES["external_speed"]
    dirs = machine.get("$AXIS_DIR")
    axes = []
    for k, e in enumerate(range(1, n + 1)):
        d = dirs.value.get(6 + e, 1) if dirs is not None and isinstance(dirs.value, dict) else 1
        if d not in (1, -1, 0):
            raise MachineDataError(f"{dirs.where(6 + e)}: $AXIS_DIR[{6 + e}]={krl_value(d)}: 1 or -1 was expected")
        jerk_dv = machine.get("$AXIS_JERK")
        raise_dv = machine.get("$RAISE_TIME")
        if jerk_dv is not None and isinstance(jerk_dv.value, dict) and 6 + e in jerk_dv.value:
            j = _num(jerk_dv.value[6 + e], jerk_dv.where(6 + e), f"$AXIS_JERK[{6 + e}]")
            acc = math.sqrt(speeds[k] * j)
        else:
            rt = (_num(raise_dv.value[6 + e], raise_dv.where(6 + e), f"$RAISE_TIME[{6 + e}]")
                  if raise_dv is not None and isinstance(raise_dv.value, dict) and 6 + e in raise_dv.value
                  else None)
            acc = speeds[k] / ((rt + flt_ptp / 2.0) / 1000.0 if rt is not None else 0.2)
            j = _jerk(acc, flt_ptp)
        if lo[k] > hi[k]:
            raise MachineDataError(f"{dv_lo.where(6 + e)}: $SOFTN_END[{6 + e}]={lo[k]:g} is above "
                                   f"$SOFTP_END[{6 + e}]={hi[k]:g}")
        limit = (-math.inf, math.inf) if kinds[k] == "endless" else (lo[k], hi[k])
        axes.append(ExternalAxis(number=e, kind=kinds[k], limit=limit, max_speed=speeds[k], max_acc=acc,
                                 max_jerk=j, direction=-1 if d == -1 else 1, home=home.get(f"E{e}", 0.0)))
    ex = machine.get("$EX_KIN")
    systems: list[ExternalKinematic] = []
    if ex is not None and isinstance(ex.value, dict):
        prov["$EX_KIN"] = ex.where()
        used: set[int] = set()
        for t in range(1, MAX_EXT_KINEMATICS + 1):
            sysname = ex.value.get(f"ET{t}", "#NONE")
            if sysname in (None, "#NONE"):
                continue
            if sysname not in _EX_SYSTEMS:
                raise MachineDataError(f"{ex.where()}: $EX_KIN.ET{t}={sysname}: the simulator builds #ERSYS (a "
                                       f"ROBROOT kinematic) and #EASYS..#EFSYS (BASE kinematics)")
            systems.append(_et_system(machine, source, prov, t, sysname, n, used))
        if sum(s.robroot for s in systems) > 1:
            raise MachineDataError(f"{ex.where()}: $EX_KIN holds more than one #ERSYS")
    return tuple(axes), tuple(systems)


def _et_system(machine, source, prov, t: int, sysname: str, n_ext: int, used: set[int]) -> ExternalKinematic:
    name = f"$ET{t}_AX"
    dv = _get(machine, name, source)
    ax: list[int] = []
    for k in ("TR_A1", "TR_A2", "TR_A3"):
        v = dv.value.get(k, "#NONE") if isinstance(dv.value, dict) else "#NONE"
        if v in (None, "#NONE"):
            break
        e = int(v[2:]) if isinstance(v, str) and v[:2] == "#E" and v[2:].isdigit() else 0
        if not 1 <= e <= n_ext or e in used:
            raise MachineDataError(f"{dv.where()}: {name}.{k}={v}: an external axis #E1..#E{n_ext} "
                                   f"($EX_AX_NUM) not used by another transformation was expected")
        used.add(e)
        ax.append(e)
    if not ax:
        raise MachineDataError(f"{dv.where()}: {name}={{TR_A1 #NONE}}: $EX_KIN.ET{t}={sysname} moves no axis")
    prov[name] = dv.where()
    frames = []
    for key in ("TA1KR", "TA2A1", "TA3A2", "TFLA3"):
        var = f"$ET{t}_{key}"
        if var in machine and machine[var].value is not None:
            f, fdv = _frame6(machine, var, source)
            prov[var] = fdv.where()
        else:
            f = (0.0,) * 6
            if key in ("TA1KR", "TFLA3"):
                raise MachineDataError(f"{source}: {var} is not set; cannot build $EX_KIN.ET{t}")
        frames.append(f)
    root = (0.0,) * 6
    if sysname == "#ERSYS":
        if "$ERSYSROOT" in machine and machine["$ERSYSROOT"].value is not None:
            root, rdv = _frame6(machine, "$ERSYSROOT", source)
            prov["$ERSYSROOT"] = rdv.where()
        else:
            prov["$ERSYSROOT"] = RULES["ersysroot"]
    else:
        prov[f"ET{t} root"] = RULES["easys_root"]
    nm = machine.get(f"$ET{t}_NAME")
    label = str(nm.value).strip() if nm is not None and isinstance(nm.value, str) else ""
    return ExternalKinematic(index=t, system=sysname, name=label or f"ET{t}", axes=tuple(ax),
                             frames=tuple(frames), root=root)


def machine_from_values(machine: dict[str, DataValue], robcor: dict[str, DataValue] | None,
                        source: str) -> MachineData:
    """Build the robot model from read machine data (see the module docstring). Builds no
    inverse kinematics (robot/kinematics/ does, for the tools that move the robot). The kinematic
    chain is the robot's kinematic family's (robot/kinematics/families.py ``machine_geometry``).

    Args:
        machine: the values of ``$machine.dat`` (:func:`robot.datalist.read_data_list`).
        robcor: the values of ``$robcor.dat`` or None.
        source: the name shown for the machine data (e.g. the ``$machine.dat`` path).
    Raises:
        MachineDataError: a variable is missing or holds a value the model cannot take
            (file:line, the variable and its value).
    """
    prov: dict[str, str] = {}
    _require_robot_data(machine, source)
    a4fix, a5link = _structure(machine, source, prov)

    # the kinematic chain: the geometry of the robot's kinematic family (robot/kinematics/)
    geo = machine_geometry(machine, source, prov, a4fix, a5link)
    a5link = geo.a5link
    chain = geo.chain
    n = len(chain.axes)
    kinds = chain.kinds or ("rotary",) * n
    origins, jaxes, flange = chain_to_joints(chain.frames(), chain.local_axes())

    flt_ptp = _scalar(machine, "$DEF_FLT_PTP", load_machine().def_flt_ptp, prov)
    lims = _joint_limits(machine, source, prov, a4fix, flt_ptp, kinds)
    joints = _joints(n, lims, origins, jaxes, kinds)

    vel_ma = _cp(machine, "$VEL_MA", source, prov)
    acc_ma = _cp(machine, "$ACC_MA", source, prov)
    acc_ov = _cp(machine, "$ACC_OV", source, prov) if "$ACC_OV" in machine else acc_ma
    robroot_T, dv = _frame(machine, "$ROBROOT", source) if "$ROBROOT" in machine else (np.eye(4), None)
    robroot = tuple(float(v) for v in matrix_to_frame(robroot_T))
    prov["$ROBROOT"] = dv.where() if dv is not None else "derived: $NULLFRAME ($ROBROOT not set)"
    home, home_ext = _home(machine, prov)
    home = home[:n]
    mames = (tuple(_axes(machine, "$MAMES", source, n)[0]) if "$MAMES" in machine else home)
    if "$MAMES" in machine:
        prov["$MAMES"] = machine["$MAMES"].where(1)

    base = load_machine()
    apo = _axes(machine, "$APO_DIS_PTP", source, n)[0] if "$APO_DIS_PTP" in machine else list(base.apo_dis_ptp_deg)[:n]
    in_pos_ma = _axes(machine, "$IN_POS_MA", source, n)[0] if "$IN_POS_MA" in machine else list(base.in_pos_ma_deg)[:n]
    in_car = _scalar(machine, "$IN_POS_CAR", base.in_pos_car_mm, prov)
    in_ori = _scalar(machine, "$IN_POS_ORI", base.in_pos_ori_deg, prov)
    flt_cp = int(_scalar(machine, "$DEF_FLT_CP", base.def_flt_cp, prov))
    load = _load(robcor if robcor and "$DEF_L_M" in robcor else machine, prov)
    trafoname, name, main_axis = _names(machine, source, prov)
    ext_axes, ext_kin = _external(machine, source, prov, flt_ptp, home_ext)

    md = dict(base.motion_defaults)
    md["tool_data_1_mm_deg"] = [0.0] * len(CART_KEYS)
    (w, x, y, z), rpy = _flange_orientation(flange[:3, :3])
    model = MachineData(
        name=name, joints=tuple(joints), home_deg=tuple(home), mastering_deg=tuple(mames), opw=geo.opw,
        flange_quat_wxyz=(float(w), float(x), float(y), float(z)),
        flange_rpy_rad=tuple(float(v) for v in rpy),                     # type: ignore[arg-type]
        flange_pos_mm=tuple(float(v) for v in flange[:3, 3]),            # type: ignore[arg-type]
        robroot_frame=robroot, default_tool_frame=(0.0,) * 6,
        status_phi_deg=geo.status_phi_deg,
        vel_ma=vel_ma, acc_ma=acc_ma, acc_ov=acc_ov, apo_dis_ptp_deg=tuple(apo),
        in_pos_ma_deg=tuple(in_pos_ma), in_pos_car_mm=in_car, in_pos_ori_deg=in_ori,
        def_flt_ptp=int(flt_ptp), def_flt_cp=flt_cp, ipo_cycle_s=base.ipo_cycle_s,
        motion_defaults=md, default_load=load,
        reach_wrist_point_mm=geo.reach_mm,
        home_flange_pose=(0.0,) * 6, source=source,
        raw={"machine_data": {k: v.value for k, v in machine.items()}},
        trafoname=trafoname, provenance=prov, a4fix=a4fix, a5link=a5link, chain=chain,
        external_axes=ext_axes, external_kinematics=ext_kin, main_axis=main_axis)
    home_T = chain_forward(chain, model.home_deg)
    if a5link and abs(home_T[2, 2] + 1.0) > 1e-9:
        raise _a5link_home_error(prov, source, home)
    return replace(model, home_flange_pose=tuple(float(v) for v in matrix_to_frame(home_T)))


def _require_robot_data(machine: dict[str, DataValue], source: str) -> None:
    """Raise MachineDataError where none of the robot's own machine data is set (a controller's
    STEU/Mada file, or no $machine.dat at all)."""
    arm = ("$TRAFONAME", "$TIRORO", "$LENGTH_A", "$LENGTH_B", "$TX3P3", "$TFLWP")
    if not any(machine.get(k) is not None and machine[k].value not in (None, {}, "") for k in arm):
        steu = machine.get("$V_STEUMADA")
        what = (f"it is the controller's machine data ($V_STEUMADA={krl_value(steu.value)[:40]}, STEU/Mada); "
                f"the robot's is R1/Mada/$machine.dat" if steu is not None and steu.value else
                "it is not a robot's $machine.dat")
        raise MachineDataError(f"{source}: none of the robot's machine data ({', '.join(arm)}) is set: {what}")


def _joints(n: int, lims: list, origins: Any, jaxes: Any, kinds: tuple[str, ...]) -> list[JointData]:
    """The n joints A1..An: their limits (limit, speed, acceleration, jerk per axis), origins and
    axes (mm, unit vectors) and kinds."""
    joints = []
    for i in range(n):
        limit, vmax, acc, jerk, data = lims[i]
        joints.append(JointData(data_limit_deg=data,
            name=f"joint_a{i + 1}", axis=i + 1, limit_deg=limit, max_speed_deg_s=vmax,
            max_acc_deg_s2=acc, max_jerk_deg_s3=jerk,
            origin_mm=tuple(float(v) for v in origins[i]),       # type: ignore[arg-type]
            joint_axis=tuple(float(v) for v in jaxes[i]),        # type: ignore[arg-type]
            urdf_max_speed_deg_s=vmax, parent="base_link" if i == 0 else f"link_{i}",
            child=f"link_{i + 1}", kuka_sign=1, kind=kinds[i]))
    return joints


def _names(machine: dict[str, DataValue], source: str, prov: dict[str, str]) -> tuple[str, str, str]:
    """($TRAFONAME, the robot's name, $MAIN_AXIS) with their provenance (and the rules' of
    ``ipo_cycle_s`` and ``motion_defaults``) added to prov."""
    trafo = machine.get("$TRAFONAME")
    trafoname = str(trafo.value) if trafo is not None and isinstance(trafo.value, str) else ""
    if trafo is not None:
        prov["$TRAFONAME"] = trafo.where()
    name = trafoname.lstrip("#").strip() or Path(source).parent.name
    for key in ("ipo_cycle_s", "motion_defaults"):
        prov[key] = RULES[key]
    main = machine.get("$MAIN_AXIS")
    main_axis = str(main.value) if main is not None and isinstance(main.value, str) else "#NR"
    if main is not None:
        prov["$MAIN_AXIS"] = main.where()
    return trafoname, name, main_axis


def _flange_orientation(R: np.ndarray) -> tuple[tuple[float, float, float, float], np.ndarray]:
    """((w, x, y, z) quaternion, roll-pitch-yaw (rad)) of the flange rotation R (3x3)."""
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        rpy = Rotation.from_matrix(R).as_euler("xyz")
    return (w, x, y, z), rpy


def _a5link_home_error(prov: dict[str, str], source: str, home: list) -> MachineDataError:
    """The error of a palletizer with A5 led whose flange does not point straight down at HOME."""
    label = "$AXIS_HOME[1]" if "$AXIS_HOME[1]" in prov else "$H_POS"
    where = prov.get(label, prov.get("$DEF_A5LINK", source))
    return MachineDataError(
        f"{where}: {label}={{A2 {home[1]:g},A3 {home[2]:g},A5 {home[4]:g}}}: with A5 led "
        f"({'$NUM_AX=4' if 'a5_led' in prov else '$DEF_A5LINK'}) the "
        f"flange of this palletizer must point straight down at HOME (the parallelogram keeps it so)")


def _cp(vals, name, source, prov) -> CartLimits:
    dv = _get(vals, name, source)
    v = dv.value if isinstance(dv.value, dict) else {}
    try:
        out = CartLimits(_num(v["CP"], dv.where()), _num(v["ORI1"], dv.where()), _num(v["ORI2"], dv.where()))
    except KeyError as exc:
        raise MachineDataError(f"{dv.where()}: {name} lacks component {exc.args[0]}") from None
    prov[name] = dv.where()
    return out


def _scalar(vals, name, default, prov) -> float:
    dv = vals.get(name)
    if dv is None or dv.value is None:
        prov[name] = f"derived: {default} (KR 6 R900 value; {name} not set)"
        return float(default)
    prov[name] = dv.where()
    return _num(dv.value, dv.where())


def _home(vals, prov) -> tuple[tuple[float, ...], dict[str, float]]:
    """A1..A6 and E1..E6 (deg, mm) of the robot's HOME: the KR C4's ``$AXIS_HOME[1]``, else the
    home position ``$H_POS`` that KR C2 and KR C4 machine data both hold, else the derived
    {0, -90, 90, 0, 0, 0}."""
    dv = vals.get("$AXIS_HOME")
    v = dv.value.get(1) if dv is not None and isinstance(dv.value, dict) else None
    if isinstance(v, dict) and any(k.startswith("A") for k in v):
        label, where = "$AXIS_HOME[1]", dv.where(1)
    else:
        dv = vals.get("$H_POS")
        v = dv.value if dv is not None else None
        if not (isinstance(v, dict) and any(isinstance(k, str) and k.startswith("A") for k in v)):
            prov["home_deg"] = "derived: {0, -90, 90, 0, 0, 0} ($AXIS_HOME[1] and $H_POS not set)"
            return (0.0, -90.0, 90.0, 0.0, 0.0, 0.0), {}
        label, where = "$H_POS", dv.where()
    prov[label] = where
    ext = {k: _num(v[k], where, f"{label}.{k}") for k in EXT_KEYS if k in v}
    return tuple(_num(v.get(k, 0.0), where, f"{label}.{k}") for k in ROBOT_KEYS), ext


def _load(robcor, prov) -> dict[str, Any]:
    """The robot's default load ({mass_kg, cm_mm_deg, inertia_kg_m2}) from ``$DEF_L_M``,
    ``$DEF_L_CM``, ``$DEF_L_J`` of `robcor` (a ``$robcor.dat``'s values; the caller passes the
    machine data's own when they carry them: robot/data/kr3_r540.dat); {} without them."""
    if not robcor or "$DEF_L_M" not in robcor:
        prov["default_load"] = RULES["default_load"]
        return {}
    m = robcor["$DEF_L_M"]
    out: dict[str, Any] = {"mass_kg": _num(m.value, m.where())}
    prov["$DEF_L_M"] = m.where()
    cm = robcor.get("$DEF_L_CM")
    if cm is not None and isinstance(cm.value, dict):
        out["cm_mm_deg"] = [_num(cm.value.get(k, 0.0), cm.where()) for k in "XYZABC"]
        prov["$DEF_L_CM"] = cm.where()
    j = robcor.get("$DEF_L_J")
    if j is not None and isinstance(j.value, dict):
        out["inertia_kg_m2"] = [_num(j.value.get(k, 0.0), j.where()) for k in "XYZ"]
        prov["$DEF_L_J"] = j.where()
    return out


def load_mada(machine_dat: str | Path, shown: str | None = None) -> MachineData:
    """The robot model of a ``$machine.dat`` (and the ``$robcor.dat`` beside it, if any).

    ``shown``: the name used in places and ``source`` (default: the path). Raises
    :class:`MachineDataError` (also for a file that cannot be read or parsed).
    """
    p = Path(machine_dat)
    name = shown or str(p)
    try:
        st = p.stat()
        key = (str(p.resolve()), name, st.st_mtime_ns, st.st_size)
    except OSError as exc:
        raise MachineDataError(f"{name}: cannot be read ({exc.strerror})") from None
    got = _CACHE.get(key)
    if got is None:
        got = _load_mada(p, name)
        _CACHE.put(key, got)
    return got


#: Models already built in this process, by (path, name, mtime, size): the real-programs report
#: runs every program of a backup on the same robot. The 16 last used, and any other while
#: something holds it (a program model of a cached workspace: robot/heldcache.py).
_CACHE = HeldCache(16)


def _load_mada(p: Path, name: str) -> MachineData:
    try:
        values = read_data_list(p, name)
        rob = next((c for c in p.parent.iterdir() if c.name.lower() == "$robcor.dat" and c.is_file()), None) \
            if p.parent.is_dir() else None
        robcor = read_data_list(rob, str(Path(name).parent / rob.name)) if rob is not None else None
    except DataListError as exc:
        raise MachineDataError(str(exc)) from None
    machine = machine_from_values(values, robcor, name)
    ident = identified_file(p)          # a library robot whose recordings were analysed (issue 60)
    machine = apply_identified(machine, ident) if ident is not None else machine
    # the dynamic model the description of its $TRAFONAME's model publishes (issue 73), or why it
    # has none; machine data hold none. A 7-axis or other arm of another axis count keeps none
    model = catalogue.find(machine.trafoname) if machine.trafoname else None
    if model is None or (model.dynamics is not None and len(machine.joints) != len(model.dynamics["links"])):
        return machine
    return with_described_dynamics(machine, model)


def robot_of_backup(root: str | Path, shown: str | None = None) -> MachineData | None:
    """The robot of the backup rooted at `root` (krl.project.machine_data_file), or None when
    it has no machine data. ``shown``: the name of `root` in places (an archive's name).
    Raises :class:`MachineDataError` for machine data that cannot make a model."""
    f = machine_data_file(Path(root))
    if f is None:
        return None
    name = str(f) if shown is None else str(Path(shown) / f.relative_to(root))
    return load_mada(f, name)


class _Cited(DataValue):
    """A value of the catalogue: ``where()`` is its source (the description), not a file:line."""

    def __init__(self, name: str, value: Any, source: str) -> None:
        super().__init__(name, value, source, 0)

    def where(self, index: int | None = None) -> str:
        return self.file


def catalogue_robot(model: "catalogue.Model | str") -> MachineData:
    """The robot of a KUKA model of the catalogue (robot/catalogue.py; a Model or its name): the
    machine data of the project's library when they name the model (machine data win), else the
    catalogue entry's values built as machine data. Raises MachineDataError for an unknown name."""
    m = catalogue.lookup(model) if isinstance(model, str) else model
    lib = catalogue.library_machine_data(m)
    if lib is not None:
        return load_mada(lib)
    vals = catalogue.arm_values(f"#{m.key}", m.geometry_mm, m.limits_deg, m.speeds_deg_s, m.source,
                                f"catalogue: {m.name}")
    built = with_described_dynamics(build_cited(m.name, vals, m.source, f"catalogue: {m.name} ({m.source})"), m)
    if m.accelerations_deg_s2 is None:
        return built
    # the published accelerations replace the rule's; the jerk follows them by the same rule
    joints = tuple(replace(j, max_acc_deg_s2=a, max_jerk_deg_s3=_jerk(a, built.def_flt_ptp))
                   for j, a in zip(built.joints, m.accelerations_deg_s2))
    prov = dict(built.provenance, max_acc_deg_s2=f"{m.acc_source} (max_acceleration, rad/s2 as published: "
                                                 f"the worst-case ramp-up to full speed)")
    return replace(built, joints=joints, provenance=prov)


def with_described_dynamics(machine: MachineData, model: "catalogue.Model | None") -> MachineData:
    """`machine` with the dynamic model its catalogue `model`'s description publishes
    (robot/described_dynamics.py; issue 73), unchanged when it has one already (identified from
    recordings) or the description publishes none; ``provenance["dynamics"]`` says which."""
    if model is None or machine.dynamics is not None:
        return machine
    if model.dynamics is None:
        return replace(machine, provenance=dict(machine.provenance, dynamics=catalogue.no_model_reason(model)))
    dyn = description_dynamics(machine, model.dynamics, model.key, model.dyn_source)
    return replace(machine, dynamics=dyn, provenance=dict(machine.provenance, dynamics=f"described: {model.dyn_source}"))


def build_cited(name: str, vals: dict, source: str, shown: str) -> MachineData:
    """The model of machine-data values that each carry their source (robot/catalogue.py
    ``arm_values``: a catalogue entry, a URDF description): built by :func:`machine_from_values`,
    its provenance naming each value's source; the axis speeds are the description's."""
    built = machine_from_values({k: _Cited(k, v, src) for k, (v, src) in vals.items()}, None, shown)
    prov = {k: v for k, v in built.provenance.items() if k not in ("$VEL_AXIS_MA", "$RAT_MOT_AX")}
    prov["max_speed_deg_s"] = f"{source} (joint velocities)"
    return replace(built, name=name, provenance=prov)


def named_machine(named: Named, stand_in: MachineData | None = None) -> MachineData:
    """The robot driven for a backup without machine data that names `named` in its
    ``$config.dat`` (robot/named.py): the robot library's machine data of it, else the
    catalogue's model, else `stand_in` (default the KR 6 R900 of robot/machine.py
    ``load_machine``); its ``named`` says which robot the backup names, where, and whether this
    one stands in for it (issue 72). Raises MachineDataError as :func:`load_mada` does.
    The same robot named in the same place (and the same `stand_in`) gives the model made then
    (:data:`_NAMED`): each run of such a backup built a robot of its own, and a program model
    for it (interp/runtime/model.py keys a model by its robot: the variants sweep's flat
    MACHINE_DEF variant of khrzysio's KRC4_test built 40 models for its 40 runs)."""
    try:
        lib = (str(named.library), Path(named.library).stat().st_mtime_ns) if named.library is not None else None
    except OSError as exc:
        raise MachineDataError(f"{named.library}: cannot be read ({exc.strerror})") from None
    key = (named.name, named.where, named.model.key if named.model is not None else None, lib, id(stand_in))
    got = _NAMED.get(key)
    if got is not None and (stand_in is None or _STAND_INS.get(key) is stand_in):
        return got
    if named.library is not None:
        m = load_mada(named.library)
    elif named.model is not None:
        m = catalogue_robot(named.model)
    else:
        m = stand_in if stand_in is not None else load_machine()
    out = replace(m, named=named.note(m.name))
    _NAMED.put(key, out)
    if stand_in is not None:
        _STAND_INS[key] = stand_in
    return out


#: The robots :func:`named_machine` made in this process, by what names them and the stand-in's
#: identity, kept as :data:`_CACHE` keeps its models (robot/heldcache.py); the stand-in of each
#: (held weakly: while it lives its identity is not another object's)
_NAMED = HeldCache(16)
_STAND_INS: weakref.WeakValueDictionary = weakref.WeakValueDictionary()


def _named_in(roots, shown=None) -> MachineData | None:
    """The robot the first of the backup `roots` that names one in its ``$config.dat`` names
    (:func:`named_machine`), else None; `shown` (folder, name) maps a temporary folder's path
    back to the archive's name in the note."""
    for root in roots:
        named = named_robot(root)
        if named is not None:
            if shown is not None:
                named = replace(named, where=named.where.replace(str(shown[0]), str(shown[1]), 1))
            return named_machine(named)
    return None


def load_robot(path: str | Path) -> MachineData:
    """The robot model named by ``krl run --robot`` / ``krl robot show``: a robot YAML (the
    layout of robot/data/kr6_r900.yaml), a ``$machine.dat``, a KRC backup folder or a backup
    ``.zip`` (krl/archive.py checks and extracts it; a backup without machine data gives the
    robot its ``$config.dat`` names, :func:`named_machine`), a robot description (``.urdf``, ``.xacro``:
    robot/description.py), the name of a robot of the project's
    library (``kr180_r3200_pa``: robot/machine.py ``library_robots``), or a KUKA model's name
    (``"KR 150 R3100-2"``, ``KR150R3100_2``: robot/catalogue.py). Raises :class:`MachineDataError` with a
    clear message for anything else."""
    p = Path(path)
    if not p.exists():
        lib = library_robots()
        if str(path) in lib:                    # a robot of the project's library, by name
            p = lib[str(path)]
        else:
            model = catalogue.find(str(path))   # a KUKA model by name (robot/catalogue.py)
            if model is not None:
                return catalogue_robot(model)
            raise MachineDataError(f"{p}: no such file or folder, nor a KUKA model of the catalogue (`krl robot "
                                   f"list`), nor a robot of the library ({', '.join(lib)})")
    if p.is_file() and p.suffix.lower() in (".yaml", ".yml"):
        try:
            return load_machine(p)
        except (OSError, KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
            raise MachineDataError(f"{p}: not a robot YAML ({type(exc).__name__}: {exc})") from None
    if p.is_file() and p.suffix.lower() == ".dat":
        return load_mada(p)
    if p.is_file() and p.suffix.lower() in (".urdf", ".xacro"):
        # deferred: tools/startup_bench.py, krl run +306 ms at the top (2026-11-26)
        from .description import load_description  # noqa: PLC0415

        return load_description(p, build_cited, default_dynamics)
    if is_archive(p) or (p.is_dir() and holds_archives(p)):
        # a backup .zip, or a folder of controller archives holding one backup (krl/backups.py)
        try:
            with one_backup(p) as (part, root, _entries):
                shown = part.source if part.archive else str(p)
                found = robot_of_backup(root, part.shown(root) if part.archive else None)
                found = found or _named_in([Path(root)], (part.folder, shown) if part.archive else None)
                if found is not None:
                    return found
        except (ArchiveError, BackupsError) as exc:
            raise MachineDataError(str(exc)) from None
        raise MachineDataError(f"{p}: the backup holds no R1/Mada/$machine.dat")
    if p.is_dir():
        roots = [backup_of(p) or p, *find_backups(p)]
        for root in roots:
            found = robot_of_backup(root)
            if found is not None:
                return found
        found = _named_in(roots)       # no machine data: the robot its $config.dat names (issue 72)
        if found is not None:
            return found
        raise MachineDataError(f"{p}: no R1/Mada/$machine.dat in this folder")
    raise MachineDataError(f"{p}: not a robot YAML, $machine.dat, backup folder or backup .zip")


__all__ = ["MachineDataError", "RULES", "build_cited", "catalogue_robot", "chain_forward", "chain_to_joints", "load_mada", "load_robot",
           "machine_from_values", "named_machine", "robot_of_backup"]
