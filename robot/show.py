"""``krl robot show``: the robot model as text (name, parameters and their sources, limits,
reach). Every text that came from a file (names, paths) passes krl.terminal.printable."""

from __future__ import annotations

import math

from krl.terminal import printable

from .axismap import AxisMap
from .kinematics import Kinematics
from .machine import MachineData

#: Parameters shown with their source, in this order (those the model has).
_PARAMS = ("$TRAFONAME", "$KINCLASS", "$MAIN_AXIS", "$NUM_AX", "$AXIS_SEQ", "$TIRORO", "$LENGTH_A", "$LENGTH_B", "$TX3P3", "$DH_4",
           "$DH_5", "$TFLWP", "$AXIS_DIR", "$SOFTN_END", "$SOFTP_END", "$VEL_AXIS_MA", "$RAT_MOT_AX",
           "$RAISE_TIME", "$AXIS_JERK", "$VEL_MA", "$ACC_MA", "$ACC_OV", "$ROBROOT", "$DEF_A4FIX",
           "$DEF_A5LINK", "a5_led", "$AXIS_HOME[1]", "$H_POS", "home_deg", "$MAMES", "$IN_POS_CAR", "$IN_POS_ORI",
           "$DEF_FLT_PTP", "$DEF_FLT_CP", "$DEF_L_M", "max_speed_deg_s", "max_acc_deg_s2", "opw",
           "status_phi_deg", "reach_wrist_point_mm", "ipo_cycle_s", "motion_defaults", "default_load",
           "$EX_AX_NUM", "$AXIS_TYPE", "E_speed", "$EX_KIN", "$ERSYSROOT", "meshes", "joints", "family",
           "cartesian limits, $APO_DIS_PTP, $IN_POS_MA", "home", "dynamics")

def _fmt(values, nd: int = 3) -> str:
    return ", ".join(f"{float(v):.{nd}f}".rstrip("0").rstrip(".") for v in values)


def show_lines(m: MachineData) -> list[str]:
    """The lines printed by ``krl robot show`` for the model ``m`` (mm, deg, s)."""
    out = [f"robot      {printable(m.name)}",
           f"source     {printable(m.source)}"]
    if m.named:                      # a backup without machine data that names its robot (robot/named.py)
        out.append(f"named      {printable(m.named)}")
    if m.trafoname:
        out.append(f"$TRAFONAME {printable(m.trafoname)}")
    k = Kinematics(m)
    out += k.impl.describe()         # the family's own lines (robot/kinematics/<family>.py)
    out.append(f"inverse    {k.impl.title}")
    zero = k.forward([0.0] * k.n_axes)[:3, 3]
    out.append(f"reach      {m.reach_wrist_point_mm:.1f} mm to the wrist point; flange at A=0: "
               f"({_fmt(zero, 1)}) mm")
    out.append(f"home       A = ({_fmt(m.home_deg)}) deg; flange X,Y,Z,A,B,C = ({_fmt(m.home_flange_pose, 1)})")
    out.append(f"$ROBROOT   ({_fmt(m.robroot_frame)})")
    out.append(f"$VEL_MA    CP {m.vel_ma.cp:g} m/s, ORI1 {m.vel_ma.ori1:g}, ORI2 {m.vel_ma.ori2:g} deg/s; "
               f"$ACC_MA CP {m.acc_ma.cp:g} m/s2")
    if m.a4fix or m.a5link:
        led = "a5_led" in m.provenance     # $NUM_AX=4: A5 led although $DEF_A5LINK is FALSE
        out.append(f"palletizer $DEF_A4FIX={str(m.a4fix).upper()} $DEF_A5LINK={str(m.a5link and not led).upper()}"
                   + (" (A5 led: $NUM_AX=4)" if led else ""))
    acc_d = "*" if m.provenance.get("max_acc_deg_s2", "").startswith("derived") else " "
    jerk_d = "*" if m.provenance.get("$AXIS_JERK", "").startswith("derived") else " "
    out.append("axes       axis   limits (deg)         v max (deg/s)  a max (deg/s2)  jerk (deg/s3)")
    amap = AxisMap.of(m)                 # each axis by its E6AXIS component (a seven-axis arm's J3: E1)
    for key, j in zip(amap.robot_keys, m.joints):
        lo, hi = j.data_limits              # the machine data's; the model may hold the axis (A4FIX)
        held = (f"   held at {j.limit_deg[0]:g} by $DEF_A4FIX" if j.data_limit_deg is not None else "")
        out.append(f"           {key}   {lo:8.1f} .. {hi:7.1f}   {j.max_speed_deg_s:12.2f}"
                   f"  {j.max_acc_deg_s2:13.1f}{acc_d}  {j.max_jerk_deg_s3:12.1f}{jerk_d}"
                   + ("   linear (mm)" if getattr(j, "kind", "rotary") == "linear" else "") + held)
    for key, e in zip(amap.ext_keys, m.external_axes):
        u = "mm" if e.linear else "deg"
        lim = "endless" if e.kind == "endless" else f"{e.limit[0]:8.1f} .. {e.limit[1]:7.1f}"
        out.append(f"           {key}   {lim:<20} {e.max_speed:12.2f}  {e.max_acc:13.1f}   "
                   f"{e.max_jerk:12.1f}   {e.kind} ({u})")
    if "*" in acc_d + jerk_d:
        out.append("           * derived by a rule (below), the machine data hold no value")
    for s in m.external_kinematics:
        kind = "ROBROOT kinematic (the robot rides on it)" if s.robroot else "BASE kinematic (it carries the workpiece)"
        out.append(f"ET{s.index}        {s.system} {kind}: {printable(s.name)}, axes "
                   f"{', '.join(f'E{e}' for e in s.axes)}; root ({_fmt(s.root)})")
    out += _dynamics_lines(m, amap)
    if m.provenance:
        out.append("parameters (source file:line, or the rule that derived the value)")
        for key in _PARAMS:
            if key in m.provenance:
                out.append(f"  {key:<22} {printable(m.provenance[key])}")
    else:
        out.append("parameters from the robot YAML; each number's source is in its comments")
    return out


def _dynamics_lines(m: MachineData, amap: AxisMap) -> list[str]:
    """The dynamic model's values per axis with the source of each (robot/dynamics.py; issue 73):
    the link's mass, centre of mass (mm, the link's frame) and inertia (kg m2: xx yy zz about the
    centre of mass), the rotor inertia, the drive's torque limit and where each comes from:
    identified from recordings (robot/identified.py: measured, or derived from the identified
    acceleration, or none known), or a description's published values (``sources``,
    robot/described_dynamics.py). A robot without a dynamic model: the reason, when known."""
    d = m.dynamics
    if not d:
        why = m.provenance.get("dynamics")
        return [f"dynamics   {printable(why)}"] if why else []
    capped = set(d.get("capped_axes", ()))
    srcs = d.get("sources") or {}
    src = printable(m.provenance.get("dynamics", "the robot's dynamics"))
    out = [f"dynamics   {src}",
           "           axis  mass (kg)  centre of mass (mm)      inertia xx yy zz (kg m2)       rotor (kg m2)"
           "  torque limit (N m)  source of the torque"]
    for i, key in enumerate(amap.robot_keys[:len(d["torque_nm"])]):
        t = d["torque_nm"][i]
        if srcs.get("torque"):
            why, ts = srcs["torque"][i], "-" if t is None else f"{float(t):.2f}"
        elif t is None:
            why, ts = "none known: its identified acceleration caps it", "-"
        elif i + 1 in capped:
            why, ts = "measured: the recordings' commanded gear torque", f"{float(t):.2f}"
        else:
            why, ts = "derived: gives its identified acceleration at its recorded poses", f"{float(t):.2f}"
        com = " ".join(f"{float(v):7.1f}" for v in d["link_com_mm"][i])
        iner = " ".join(f"{float(v):9.4g}" for v in d["link_inertia_kg_m2"][i][:3])
        out.append(f"           {key}   {float(d['link_mass_kg'][i]):9.3f}  {com}  {iner}  "
                   f"{float(d['rotor_inertia_kg_m2'][i]):13.4g}  {ts:>18}  {printable(why)}")
    for label, k in (("links (mass, centre of mass, inertia)", "links"), ("rotor inertias", "rotor"),
                     ("rated payload", "rated"), ("acceleration caps", "capped"), ("planning", "plan")):
        if k in srcs:
            out.append(f"           {label}: {printable(srcs[k])}")
    if "rated_payload_kg" in d:
        out.append(f"           rated payload {float(d['rated_payload_kg']):g} kg (the load of $LOAD.M < 0)")
    return out


__all__ = ["show_lines"]
