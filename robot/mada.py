"""The robot of a KRC backup, built from its machine data (``R1/Mada/$machine.dat``, and
``$robcor.dat`` for the default load), into the same :class:`~robot.machine.MachineData` as
the KR 6 R900 yaml, so kinematics, inverse kinematics, the MuJoCo model and the planner's
limits follow from the same numbers.

Sources: shared/docs/robot-model.md §4.3 (KUKA's chain rebuilt from ``$TIRORO``,
``$LENGTH_A``, ``$LENGTH_B``, ``$TX3P3``, ``$DH_4``, ``$DH_5``, ``$TFLWP``, ``$AXIS_DIR``),
§5 (speeds from ``$VEL_AXIS_MA`` and ``$RAT_MOT_AX``), §7 (``$ROBROOT``), §8 (status). The
values are read through the project's KRL front end (robot/datalist.py). The same variables
exist in KR C2 and KR C4 machine data.

The chain (mm, deg; ``d_i = $AXIS_DIR[i]``)::

    FLANGE(A) = $TIRORO · Rz(d1·A1) · Tx($LENGTH_A) · Ry(d2·A2) · Tx($LENGTH_B) · Ry(d3·A3)
              · $TX3P3 · Rz(d4·A4) · DH($DH_4) · Rz(d5·A5) · DH($DH_5) · Rz(d6·A6) · $TFLWP

with ``DH({a, d, alpha}) = Tz(d) · Tx(a) · Rx(alpha)``. It is turned into URDF-style joints
(translation-only joint origins, KUKA's directions in the joint axes, ``q = radians(A_i)``)
by moving each fixed rotation past the following joints; the rotation left at the end is
the link_6 -> flange frame. The OPW parameters for the analytic IK (robot-model.md §4.2)
follow from the same variables and are checked against the chain when the model is built.

Values the machine data do not hold are derived by the rules of :data:`RULES` and marked
"derived" in :attr:`MachineData.provenance`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from .datalist import DataListError, DataValue, read_data_list
from .frames import frame_to_matrix, matrix_to_frame
from .machine import CartLimits, JointData, MachineData, OPWParams, load_machine

#: The rules for values that machine data lack (docs/robot.md, "Robots from machine data").
RULES = {
    "max_acc_deg_s2": "derived: sqrt(v_max * $AXIS_JERK[i]), the peak acceleration of a jerk-limited "
                      "ramp from rest to full axis speed without a constant-acceleration phase "
                      "(the KR C4 takes accelerations from its dynamic model, $ADAP_ACC)",
    "ipo_cycle_s": "derived: 12 ms interpolation cycle of the KR C4 (robot-model.md §10)",
    "motion_defaults": "derived: KSS defaults of bas.src/$config.dat (robot/data/kr6_r900.yaml "
                       "motion_defaults)",
    "status_phi_deg": "derived: atan2($TX3P3.Z, $TX3P3.X), A3 where the arm is stretched (robot-model.md §8)",
    "reach_wrist_point_mm": "derived: $LENGTH_A + $LENGTH_B + |($TX3P3.X, $TX3P3.Z)|",
    "opw": "derived: a1=$LENGTH_A, a2=-$TX3P3.Z, b=$TX3P3.Y, c1=$TIRORO.Z, c2=$LENGTH_B, "
           "c3=$TX3P3.X, c4=$TFLWP.Z (robot-model.md §4.2-4.3)",
    "default_load": "derived: none given ($robcor.dat absent)",
}

#: The axis directions for which the OPW solver's sign corrections are known
#: (robot-model.md §3: $AXIS_DIR = [-1, 1, 1, -1, -1, -1] <-> OPW signs [-1, 1, 1, -1, 1, -1]).
_OPW_SIGNS = (-1, 1, 1, -1, 1, -1)
_OPW_OFFSETS_DEG = (0.0, -90.0, 0.0, 0.0, 0.0, 0.0)
#: Largest disagreement (mm) allowed between the OPW model and the chain when a model is built.
_SELF_CHECK_MM = 1e-6


class MachineDataError(ValueError):
    """Machine data that cannot make a robot model; the message names file:line."""


def _get(vals: dict[str, DataValue], name: str, where: str) -> DataValue:
    v = vals.get(name)
    if v is None or v.value is None or v.value == {}:
        raise MachineDataError(f"{where}: {name} is not set; cannot build the robot model")
    return v


def _num(v: Any, where: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise MachineDataError(f"{where}: a number was expected, not {v!r}")
    if not math.isfinite(float(v)):
        raise MachineDataError(f"{where}: the value is not finite")
    return float(v)


def _axes(vals: dict[str, DataValue], name: str, where: str, n: int = 6) -> tuple[list[float], DataValue]:
    dv = _get(vals, name, where)
    if not isinstance(dv.value, dict):
        raise MachineDataError(f"{dv.where()}: {name} is not an array")
    out = []
    for i in range(1, n + 1):
        if i not in dv.value:
            raise MachineDataError(f"{dv.where()}: {name}[{i}] is not set")
        out.append(_num(dv.value[i], dv.where(i)))
    return out, dv


def _frame(vals: dict[str, DataValue], name: str, where: str) -> tuple[np.ndarray, DataValue]:
    dv = _get(vals, name, where)
    if not isinstance(dv.value, dict):
        raise MachineDataError(f"{dv.where()}: {name} is not a FRAME")
    comps = {k: _num(dv.value.get(k, 0.0), dv.where()) for k in "XYZABC"}
    return frame_to_matrix(comps["X"], comps["Y"], comps["Z"], comps["A"], comps["B"], comps["C"]), dv


def _tr(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def _rot(axis: str, deg: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler(axis, deg, degrees=True).as_matrix()
    return T


def _dh(dv: DataValue) -> np.ndarray:
    v = dv.value if isinstance(dv.value, dict) else {}
    try:
        a = _num(v["DHART_A"], dv.where())
        d = _num(v["DHART_D"], dv.where())
        alpha = _num(v["DHART_ALPHA"], dv.where())
    except KeyError as exc:
        raise MachineDataError(f"{dv.where()}: {dv.name} lacks component {exc.args[0]}") from None
    return _tr(z=d) @ _tr(x=a) @ _rot("x", alpha)


def chain_to_joints(fixed: list[np.ndarray], axes_local: list[np.ndarray]
                    ) -> tuple[list[np.ndarray], list[np.ndarray], np.ndarray]:
    """URDF-style joints of a serial chain ``F0 · Rot(u1, q1) · F1 · ... · Rot(u6, q6) · F6``.

    Args:
        fixed: seven 4x4 fixed transforms F0..F6 (mm).
        axes_local: six unit joint axes u1..u6 in the frame after F(i-1).
    Returns:
        (origins, axes, flange): joint origins (translations in the parent joint's frame,
        no rotation), joint axes in that frame, and the 4x4 link_6 -> flange transform.
        Each fixed rotation is moved past the joints that follow it
        (``R · Rot(u, q) = Rot(R u, q) · R``); a translation along a wrist axis (A4, A6) is
        moved to the joint origin where ROS-Industrial URDFs put it (it commutes with the
        rotation about that axis).
    """
    R = np.eye(3)
    origins: list[np.ndarray] = []
    axes: list[np.ndarray] = []
    for i in range(6):
        origins.append(R @ fixed[i][:3, 3])
        R = R @ fixed[i][:3, :3]
        axes.append(R @ axes_local[i])
    flange = np.eye(4)
    flange[:3, :3] = R @ fixed[6][:3, :3]
    flange[:3, 3] = R @ fixed[6][:3, 3]
    # A4: the part of its origin along its own axis goes to A5's origin
    a = axes[3]
    along = float(origins[3] @ a) * a
    origins[3] = origins[3] - along
    origins[4] = origins[4] + along
    # A6: the part of the flange offset along its axis goes to A6's origin
    a = axes[5]
    along = float(flange[:3, 3] @ a) * a
    origins[5] = origins[5] + along
    flange[:3, 3] = flange[:3, 3] - along
    clean = [np.round(v, 9) + 0.0 for v in origins]
    clean_axes = [np.where(np.abs(v) < 1e-12, 0.0, np.round(v, 12)) + 0.0 for v in axes]
    flange[np.abs(flange) < 1e-12] = 0.0
    return clean, clean_axes, flange


def machine_from_values(machine: dict[str, DataValue], robcor: dict[str, DataValue] | None,
                        source: str) -> MachineData:
    """Build the robot model from read machine data (see the module docstring).

    Args:
        machine: the values of ``$machine.dat`` (:func:`robot.datalist.read_data_list`).
        robcor: the values of ``$robcor.dat`` or None.
        source: the name shown for the machine data (e.g. the ``$machine.dat`` path).
    Raises:
        MachineDataError: a variable is missing or malformed, or the kinematics is not a
            6-axis KUKA arm of the standard class that the OPW solver covers (file:line).
    """
    prov: dict[str, str] = {}
    kin = machine.get("$KINCLASS")
    if kin is not None and kin.value not in (None, "#STANDARD"):
        raise MachineDataError(f"{kin.where()}: $KINCLASS {kin.value} is not simulated (only #STANDARD)")
    nax = machine.get("$NUM_AX")
    if nax is not None and isinstance(nax.value, int) and nax.value < 6:
        raise MachineDataError(f"{nax.where()}: $NUM_AX={nax.value}: only 6-axis robots are simulated")

    tiroro, dv = _frame(machine, "$TIRORO", source)
    prov["$TIRORO"] = dv.where()
    la = _get(machine, "$LENGTH_A", source)
    lb = _get(machine, "$LENGTH_B", source)
    length_a, length_b = _num(la.value, la.where()), _num(lb.value, lb.where())
    prov["$LENGTH_A"], prov["$LENGTH_B"] = la.where(), lb.where()
    tx3p3, dv = _frame(machine, "$TX3P3", source)
    prov["$TX3P3"] = dv.where()
    tflwp, dv = _frame(machine, "$TFLWP", source)
    prov["$TFLWP"] = dv.where()
    dh4 = _get(machine, "$DH_4", source)
    dh5 = _get(machine, "$DH_5", source)
    prov["$DH_4"], prov["$DH_5"] = dh4.where(), dh5.where()
    axis_dir, dv = _axes(machine, "$AXIS_DIR", source)
    prov["$AXIS_DIR"] = dv.where(1)
    if any(d not in (-1.0, 1.0) for d in axis_dir):
        raise MachineDataError(f"{dv.where(1)}: $AXIS_DIR[1..6] must be 1 or -1")

    fixed = [tiroro, _tr(x=length_a), _tr(x=length_b), tx3p3, _dh(dh4), _dh(dh5), tflwp]
    local = [np.array([0.0, 0.0, axis_dir[0]]), np.array([0.0, axis_dir[1], 0.0]),
             np.array([0.0, axis_dir[2], 0.0]), np.array([0.0, 0.0, axis_dir[3]]),
             np.array([0.0, 0.0, axis_dir[4]]), np.array([0.0, 0.0, axis_dir[5]])]
    origins, jaxes, flange = chain_to_joints(fixed, local)

    lo, dv_lo = _axes(machine, "$SOFTN_END", source)
    hi, dv_hi = _axes(machine, "$SOFTP_END", source)
    rpm, dv_rpm = _axes(machine, "$VEL_AXIS_MA", source)
    ratios = _get(machine, "$RAT_MOT_AX", source)
    jerk, dv_jerk = _axes(machine, "$AXIS_JERK", source)
    a4fix = bool(getattr(machine.get("$DEF_A4FIX"), "value", False))
    a5link = bool(getattr(machine.get("$DEF_A5LINK"), "value", False))
    joints = []
    for i in range(6):
        r = ratios.value.get(i + 1) if isinstance(ratios.value, dict) else None
        if not isinstance(r, dict) or "N" not in r or "D" not in r:
            raise MachineDataError(f"{ratios.where(i + 1)}: $RAT_MOT_AX[{i + 1}] is not set")
        n, d = _num(r["N"], ratios.where(i + 1)), _num(r["D"], ratios.where(i + 1))
        if n == 0 or d == 0:
            raise MachineDataError(f"{ratios.where(i + 1)}: $RAT_MOT_AX[{i + 1}] has a zero N or D")
        vmax = rpm[i] / abs(n / d) * 6.0          # robot-model.md §5
        if vmax <= 0 or jerk[i] <= 0 or lo[i] > hi[i]:
            raise MachineDataError(f"{dv_rpm.where(i + 1)}: axis A{i + 1} has no positive speed, "
                                   f"jerk or limit range")
        limit = (lo[i], hi[i])
        if i == 3 and a4fix:
            limit = (0.0, 0.0)
        joints.append(JointData(
            name=f"joint_a{i + 1}", axis=i + 1, limit_deg=limit, max_speed_deg_s=vmax,
            max_acc_deg_s2=math.sqrt(vmax * jerk[i]), max_jerk_deg_s3=jerk[i],
            origin_mm=tuple(float(v) for v in origins[i]),       # type: ignore[arg-type]
            joint_axis=tuple(float(v) for v in jaxes[i]),        # type: ignore[arg-type]
            urdf_max_speed_deg_s=vmax, parent="base_link" if i == 0 else f"link_{i}",
            child=f"link_{i + 1}", kuka_sign=1))
    prov["$SOFTN_END"], prov["$SOFTP_END"] = dv_lo.where(1), dv_hi.where(1)
    prov["$VEL_AXIS_MA"], prov["$RAT_MOT_AX"] = dv_rpm.where(1), ratios.where(1)
    prov["$AXIS_JERK"] = dv_jerk.where(1)
    prov["max_speed_deg_s"] = "derived: $VEL_AXIS_MA[i] / |$RAT_MOT_AX[i].N / .D| * 6 (robot-model.md §5)"
    prov["max_acc_deg_s2"] = RULES["max_acc_deg_s2"]
    for key in ("$DEF_A4FIX", "$DEF_A5LINK"):
        if key in machine:
            prov[key] = machine[key].where()

    # OPW parameters (robot-model.md §4.2) and the structure they require
    tx = {k: _num(machine["$TX3P3"].value.get(k, 0.0), prov["$TX3P3"]) for k in "XYZABC"}
    ti = {k: _num(machine["$TIRORO"].value.get(k, 0.0), prov["$TIRORO"]) for k in "XYZABC"}
    fl = {k: _num(machine["$TFLWP"].value.get(k, 0.0), prov["$TFLWP"]) for k in "XYZABC"}
    opw = OPWParams(a1=length_a, a2=-tx["Z"], b=tx["Y"], c1=ti["Z"], c2=length_b, c3=tx["X"],
                    c4=fl["Z"], offsets_deg=_OPW_OFFSETS_DEG, sign_corrections=_OPW_SIGNS)
    prov["opw"] = RULES["opw"]

    vel_ma = _cp(machine, "$VEL_MA", source, prov)
    acc_ma = _cp(machine, "$ACC_MA", source, prov)
    acc_ov = _cp(machine, "$ACC_OV", source, prov) if "$ACC_OV" in machine else acc_ma
    robroot_T, dv = _frame(machine, "$ROBROOT", source) if "$ROBROOT" in machine else (np.eye(4), None)
    robroot = tuple(float(v) for v in matrix_to_frame(robroot_T))
    prov["$ROBROOT"] = dv.where() if dv is not None else "derived: $NULLFRAME ($ROBROOT not set)"
    home = _e6axis(machine, "$AXIS_HOME", 1, prov)
    mames = (tuple(_axes(machine, "$MAMES", source)[0]) if "$MAMES" in machine else home)
    if "$MAMES" in machine:
        prov["$MAMES"] = machine["$MAMES"].where(1)

    base = load_machine()
    apo = _axes(machine, "$APO_DIS_PTP", source)[0] if "$APO_DIS_PTP" in machine else list(base.apo_dis_ptp_deg)
    in_pos_ma = _axes(machine, "$IN_POS_MA", source)[0] if "$IN_POS_MA" in machine else list(base.in_pos_ma_deg)
    in_car = _scalar(machine, "$IN_POS_CAR", base.in_pos_car_mm, prov)
    in_ori = _scalar(machine, "$IN_POS_ORI", base.in_pos_ori_deg, prov)
    flt_ptp = int(_scalar(machine, "$DEF_FLT_PTP", base.def_flt_ptp, prov))
    flt_cp = int(_scalar(machine, "$DEF_FLT_CP", base.def_flt_cp, prov))
    load = _load(robcor, prov)
    trafo = machine.get("$TRAFONAME")
    trafoname = str(trafo.value) if trafo is not None and isinstance(trafo.value, str) else ""
    if trafo is not None:
        prov["$TRAFONAME"] = trafo.where()
    name = trafoname.lstrip("#").strip() or Path(source).parent.name
    for key in ("ipo_cycle_s", "motion_defaults", "status_phi_deg", "reach_wrist_point_mm"):
        prov[key] = RULES[key]

    md = dict(base.motion_defaults)
    md["tool_data_1_mm_deg"] = [0.0] * 6
    R = flange[:3, :3]
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    import warnings  # noqa: PLC0415

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        rpy = Rotation.from_matrix(R).as_euler("xyz")
    model = MachineData(
        name=name, joints=tuple(joints), home_deg=tuple(home), mastering_deg=tuple(mames), opw=opw,
        flange_quat_wxyz=(float(w), float(x), float(y), float(z)),
        flange_rpy_rad=tuple(float(v) for v in rpy),                     # type: ignore[arg-type]
        flange_pos_mm=tuple(float(v) for v in flange[:3, 3]),            # type: ignore[arg-type]
        robroot_frame=robroot, default_tool_frame=(0.0,) * 6,
        status_phi_deg=math.degrees(math.atan2(tx["Z"], tx["X"])),
        vel_ma=vel_ma, acc_ma=acc_ma, acc_ov=acc_ov, apo_dis_ptp_deg=tuple(apo),
        in_pos_ma_deg=tuple(in_pos_ma), in_pos_car_mm=in_car, in_pos_ori_deg=in_ori,
        def_flt_ptp=flt_ptp, def_flt_cp=flt_cp, ipo_cycle_s=base.ipo_cycle_s,
        motion_defaults=md, default_load=load,
        reach_wrist_point_mm=length_a + length_b + math.hypot(tx["X"], tx["Z"]),
        home_flange_pose=(0.0,) * 6, source=source,
        raw={"machine_data": {k: v.value for k, v in machine.items()}},
        trafoname=trafoname, provenance=prov, a4fix=a4fix, a5link=a5link)
    _self_check(model, fixed, local, prov)
    from dataclasses import replace  # noqa: PLC0415

    from .kinematics import Kinematics  # noqa: PLC0415

    home_pose = matrix_to_frame(Kinematics(model).forward(model.home_deg))
    return replace(model, home_flange_pose=tuple(float(v) for v in home_pose))


def chain_forward(fixed: list[np.ndarray], local: list[np.ndarray], axes_deg) -> np.ndarray:
    """The flange frame of the machine-data chain itself (4x4, mm), for checks."""
    T = fixed[0].copy()
    for i in range(6):
        J = np.eye(4)
        J[:3, :3] = Rotation.from_rotvec(local[i] * math.radians(float(axes_deg[i]))).as_matrix()
        T = T @ J @ fixed[i + 1]
    return T


def _self_check(model: MachineData, fixed, local, prov) -> None:
    """The URDF-style joints and the OPW solver must reproduce the chain; else the robot's
    structure is not one the simulator covers (MachineDataError naming ``$TX3P3``)."""
    from .kinematics import Kinematics  # noqa: PLC0415

    k = Kinematics(model)
    rng = np.random.default_rng(0)
    lo = np.array([max(j.limit_deg[0], -170.0) for j in model.joints])
    hi = np.array([min(j.limit_deg[1], 170.0) for j in model.joints])
    home = np.array(model.home_deg, dtype=float)
    if model.a5link and abs(k.forward(home)[2, 2] + 1.0) > 1e-9:
        raise MachineDataError(f"{prov.get('$DEF_A5LINK', prov['$TX3P3'])}: $DEF_A5LINK: the flange of "
                               f"this palletizer does not point straight down at $AXIS_HOME[1]")
    for q in rng.uniform(lo, hi, size=(4, 6)):
        if model.a5link:
            # the parallelogram: A4 = 0 and A2 + A3 + A5 as at HOME (the flange stays vertical)
            q[3] = 0.0
            q[4] = home[4] + home[1] + home[2] - q[1] - q[2]
        T = chain_forward(fixed, local, q)
        if np.abs(k.forward(q) - T).max() > _SELF_CHECK_MM:
            raise MachineDataError(f"{prov['$TX3P3']}: internal chain does not close")
        sols = k.solutions(T)
        if not sols or min(np.abs(k.forward(s) - T).max() for s in sols) > _SELF_CHECK_MM:
            raise MachineDataError(
                f"{prov['$TX3P3']}: this arm ($TIRORO, $TX3P3, $DH_4/$DH_5, $TFLWP, $AXIS_DIR) is not "
                f"of the standard KUKA structure that the inverse kinematics covers")


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


def _e6axis(vals, name, index, prov) -> tuple[float, ...]:
    dv = vals.get(name)
    v = dv.value.get(index) if dv is not None and isinstance(dv.value, dict) else None
    if not isinstance(v, dict):
        prov["home_deg"] = "derived: {0, -90, 90, 0, 0, 0} ($AXIS_HOME[1] not set)"
        return (0.0, -90.0, 90.0, 0.0, 0.0, 0.0)
    prov[f"{name}[{index}]"] = dv.where(index)
    return tuple(_num(v.get(f"A{i}", 0.0), dv.where(index)) for i in range(1, 7))


def _load(robcor, prov) -> dict[str, Any]:
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
        if len(_CACHE) >= 16:
            _CACHE.clear()
        _CACHE[key] = got
    return got


#: Models already built in this process, by (path, name, mtime, size): the real-programs report
#: runs every program of a backup on the same robot.
_CACHE: dict[tuple, MachineData] = {}


def _load_mada(p: Path, name: str) -> MachineData:
    try:
        values = read_data_list(p, name)
        rob = next((c for c in p.parent.iterdir() if c.name.lower() == "$robcor.dat" and c.is_file()), None) \
            if p.parent.is_dir() else None
        robcor = read_data_list(rob, str(Path(name).parent / rob.name)) if rob is not None else None
    except DataListError as exc:
        raise MachineDataError(str(exc)) from None
    return machine_from_values(values, robcor, name)


def robot_of_backup(root: str | Path, shown: str | None = None) -> MachineData | None:
    """The robot of the backup rooted at `root` (krl.project.machine_data_file), or None when
    it has no machine data. ``shown``: the name of `root` in places (an archive's name).
    Raises :class:`MachineDataError` for machine data that cannot make a model."""
    from krl.project import machine_data_file  # noqa: PLC0415

    f = machine_data_file(Path(root))
    if f is None:
        return None
    name = str(f) if shown is None else str(Path(shown) / f.relative_to(root))
    return load_mada(f, name)


def load_robot(path: str | Path) -> MachineData:
    """The robot model named by ``krl run --robot`` / ``krl robot show``: a robot YAML (the
    layout of robot/data/kr6_r900.yaml), a ``$machine.dat``, a KRC backup folder or a backup
    ``.zip`` (krl/archive.py checks and extracts it), or the name of a robot of the project's
    library (``kr180_r3200_pa``: robot/machine.py ``library_robots``). Raises :class:`MachineDataError` with a
    clear message for anything else."""
    from krl.archive import ArchiveError, backup_source, is_archive  # noqa: PLC0415
    from krl.project import backup_of, find_backups  # noqa: PLC0415

    p = Path(path)
    if not p.exists():
        from .machine import library_robots  # noqa: PLC0415

        lib = library_robots()
        if str(path) in lib:                    # a robot of the project's library, by name
            p = lib[str(path)]
        else:
            raise MachineDataError(f"{p}: no such file or folder, nor a robot of the library "
                                   f"({', '.join(lib)})")
    if p.is_file() and p.suffix.lower() in (".yaml", ".yml"):
        try:
            return load_machine(p)
        except (OSError, KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
            raise MachineDataError(f"{p}: not a robot YAML ({type(exc).__name__}: {exc})") from None
    if p.is_file() and p.suffix.lower() == ".dat":
        return load_mada(p)
    if is_archive(p):
        try:
            with backup_source(p) as (folder, _shown):
                roots = find_backups(folder)
                for root in roots or [folder]:
                    found = robot_of_backup(root, str(p / root.relative_to(folder)))
                    if found is not None:
                        return found
        except ArchiveError as exc:
            raise MachineDataError(str(exc)) from None
        raise MachineDataError(f"{p}: the backup holds no R1/Mada/$machine.dat")
    if p.is_dir():
        for root in [backup_of(p) or p, *find_backups(p)]:
            found = robot_of_backup(root)
            if found is not None:
                return found
        raise MachineDataError(f"{p}: no R1/Mada/$machine.dat in this folder")
    raise MachineDataError(f"{p}: not a robot YAML, $machine.dat, backup folder or backup .zip")


__all__ = ["MachineDataError", "RULES", "chain_forward", "chain_to_joints", "load_mada", "load_robot",
           "machine_from_values", "robot_of_backup"]
