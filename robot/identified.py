"""Motion parameters identified from a robot's KUKA Trace recordings (issue 60), applied to its model.

A KR C4's machine data hold no axis accelerations: the controller takes them from its dynamic
model. For a robot of the project's library whose real recordings were analysed,
``robot/data/identified/<stem>.yaml`` (written by ``python tools/identify_kr3.py --write``, never
by hand) holds what the recordings show, each value with its method and residual:

* ``ptp.acc_deg_s2``: the axis accelerations a PTP is planned with at 100 % ``$ACC_AXIS``;
* ``ptp.ramp_deg``: the distances below which a PTP at reduced ``$VEL_AXIS`` does not ramp
  (robot/limits.py ``ptp_axis_accelerations``; 0: none);
* ``ptp.short_ramp_s2``, ``ptp.short_ramp_below_s``: the short-ramp law of a synchronised PTP
  (robot/planner.py ``short_ramp_scale``);
* ``ptp.friction_per_s``: the acceleration an axis loses per unit of its speed while it
  accelerates, and gains while it brakes (robot/profiles.py ``FrictionProfile``);
* ``actual.filter_cycles``: the IPO cycles over which the setpoints are averaged before the
  measured axes follow them (robot/kukatrace/actual.py);
* ``actual.filter_cycles_ptp``: those cycles for a PTP's setpoints (the controller's PTP filter,
  ``$DEF_FLT_PTP``, beside its CP one; robot/actualvalue.py);
* ``actual.following_error``: the drives' following error behind those averaged setpoints, per
  axis ``inertia_s2``, ``coulomb_deg``, ``viscous_s`` and one ``coulomb_speed_deg_s``
  (robot/kukatrace/actual.py ``following_error``);
* ``actual.dead_time_cycles``: the IPO cycles the measured axes lag that model by (a dead time:
  robot/actualvalue.py);
* ``actual.settle_lag``: ``{axis, below_deg_s, cycles_per_kg_m2}``, a first-order lag of one axis'
  actual value while it brakes below that speed, τ that factor times the axis' inertia at the
  motion's end pose times the IPO cycle (robot/actualvalue.py, robot/settlelag.py);
* ``dynamics``: the arm's dynamic model for a synchronised PTP's accelerations (robot/dynamics.py):
  the links' inertials, rotor inertias, the drives' torque limits (null: none known), the axes
  their identified acceleration caps, the rated payload.

:func:`apply_identified` puts them into the :class:`~robot.machine.MachineData` that machine data
alone make (robot/mada.py ``load_mada``, for a ``.dat`` of the library with such a file), and
names the file in ``provenance`` (``krl robot show``). docs/robot.md "The KR 3 R540" lists the
values with their method and residual.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import yaml

from .madavalues import MachineDataError

#: the folder of the identified parameters, beside the library's robots
IDENTIFIED = Path(__file__).with_name("data") / "identified"


def identified_file(machine_dat: Path) -> Path | None:
    """The identified parameters of the library robot `machine_dat` (its stem's yaml in
    :data:`IDENTIFIED`), or None: none, or a file outside the library."""
    try:
        if machine_dat.resolve().parent != IDENTIFIED.parent.resolve():
            return None
    except OSError:
        return None
    f = IDENTIFIED / f"{machine_dat.stem}.yaml"
    return f if f.is_file() else None


def read_identified(path: Path) -> dict[str, Any]:
    """The identified parameters of `path`: ``{"acc": (n,), "ramp": (n,), "friction": (n,), "short_k": s²,
    "short_below": s,
    "filter": cycles, "filter_ptp": cycles, "following": {...}, "dead": cycles, "settle": {...}, "dynamics": {...}}`` (deg/s², deg, 1/s,
    an INT, the following error's keys, an INT), each missing when the file has none. Raises MachineDataError naming
    the file and the key."""
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    except (OSError, yaml.YAMLError) as exc:
        raise MachineDataError(f"{path}: cannot be read as identified parameters ({exc})") from None
    out: dict[str, Any] = {}
    n = (doc.get("actual") or {}).get("filter_cycles")
    if n is not None:
        if not isinstance(n, int) or not 1 <= n <= 100:
            raise MachineDataError(f"{path}: actual.filter_cycles: an INT 1..100 was expected")
        out["filter"] = n
    n = (doc.get("actual") or {}).get("filter_cycles_ptp")
    if n is not None:
        if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= 100:
            raise MachineDataError(f"{path}: actual.filter_cycles_ptp: an INT 1..100 was expected")
        out["filter_ptp"] = n
    lag = (doc.get("actual") or {}).get("settle_lag")
    if lag is not None:
        out["settle"] = _settle_lag(path, lag)
    dead = (doc.get("actual") or {}).get("dead_time_cycles")
    if dead is not None:
        if not isinstance(dead, int) or isinstance(dead, bool) or not 0 <= dead <= 100:
            raise MachineDataError(f"{path}: actual.dead_time_cycles: an INT 0..100 was expected")
        out["dead"] = dead
    fe = (doc.get("actual") or {}).get("following_error")
    if fe is not None:
        out["following"] = _following(path, fe)
    dyn = doc.get("dynamics")
    if dyn is not None:
        keys = ("link_mass_kg", "link_com_mm", "link_inertia_kg_m2", "rotor_inertia_kg_m2", "torque_nm")
        missing = [k for k in keys if k not in dyn]
        if missing:
            raise MachineDataError(f"{path}: dynamics lacks {', '.join(missing)}")
        out["dynamics"] = {k: dyn[k] for k in keys}
        for k in ("capped_axes", "rated_payload_kg"):
            if k in dyn:
                out["dynamics"][k] = dyn[k]
    ptp = doc.get("ptp") or {}
    for key, name in (("acc_deg_s2", "acc"), ("ramp_deg", "ramp"), ("friction_per_s", "friction")):
        v = ptp.get(key)
        if v is None:
            continue
        low = 1e-300 if name == "acc" else 0
        if not isinstance(v, list) or not all(isinstance(x, (int, float)) and x >= low for x in v):
            kind = "positive" if name == "acc" else "non-negative"
            raise MachineDataError(f"{path}: ptp.{key}: a list of {kind} numbers was expected")
        out[name] = tuple(float(x) for x in v)
    for key, name in (("short_ramp_s2", "short_k"), ("short_ramp_below_s", "short_below")):
        v = ptp.get(key)
        if v is None:
            continue
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not 0 <= v <= 1:
            raise MachineDataError(f"{path}: ptp.{key}: a number 0..1 was expected")
        out[name] = float(v)
    return out


def _settle_lag(path: Path, lag: Any) -> dict[str, Any]:
    """The ``actual.settle_lag`` mapping of `path`, checked: ``axis`` a positive INT (one of the
    robot's: :func:`apply_identified`), ``below_deg_s`` and ``cycles_per_kg_m2`` positive numbers."""
    if not isinstance(lag, dict):
        raise MachineDataError(f"{path}: actual.settle_lag: a mapping was expected")
    axis = lag.get("axis")
    if not isinstance(axis, int) or isinstance(axis, bool) or axis < 1:
        raise MachineDataError(f"{path}: actual.settle_lag.axis: a positive INT was expected")
    out: dict[str, Any] = {"axis": axis}
    for key in ("below_deg_s", "cycles_per_kg_m2"):
        v = lag.get(key)
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not v > 0:
            raise MachineDataError(f"{path}: actual.settle_lag.{key}: a positive number was expected")
        out[key] = float(v)
    return out


def _following(path: Path, fe: Any) -> dict[str, Any]:
    """The ``actual.following_error`` mapping of `path`, checked: lists of numbers (``inertia_s2``
    and ``coulomb_deg`` non-negative, ``viscous_s`` any sign) and a positive ``coulomb_speed_deg_s``."""
    if not isinstance(fe, dict):
        raise MachineDataError(f"{path}: actual.following_error: a mapping was expected")
    out: dict[str, Any] = {}
    for key, low in (("inertia_s2", 0.0), ("coulomb_deg", 0.0), ("viscous_s", -float("inf"))):
        v = fe.get(key)
        if not isinstance(v, list) or not all(isinstance(x, (int, float)) and x >= low for x in v):
            raise MachineDataError(f"{path}: actual.following_error.{key}: a list of numbers was expected"
                                   + (" (none negative)" if low == 0.0 else ""))
        out[key] = tuple(float(x) for x in v)
    v0 = fe.get("coulomb_speed_deg_s")
    if not isinstance(v0, (int, float)) or not v0 > 0:
        raise MachineDataError(f"{path}: actual.following_error.coulomb_speed_deg_s: a positive number was expected")
    out["coulomb_speed_deg_s"] = float(v0)
    return out


def apply_identified(machine: Any, path: Path) -> Any:
    """`machine` with the parameters of `path` (:func:`read_identified`): the joints'
    ``max_acc_deg_s2``, ``ptp_ramp_deg``, ``ptp_friction``, ``ptp_short_ramp_s2``,
    ``ptp_short_ramp_below_s``, ``actual_filter_cycles``,
    ``actual_filter_cycles_ptp``,
    ``actual_following``, ``actual_dead_cycles``, ``actual_settle_lag``, ``dynamics``, and their provenance. Raises MachineDataError when the
    file gives another axis count than the robot's."""
    got = read_identified(path)
    n = len(machine.joints)
    for key, v in got.items():
        if key == "following":
            if any(len(v[k]) != n for k in ("inertia_s2", "coulomb_deg", "viscous_s")):
                raise MachineDataError(f"{path}: actual.following_error: not {n} values per key for the axes of {machine.name}")
        elif key == "settle":
            if v["axis"] > n:
                raise MachineDataError(f"{path}: actual.settle_lag.axis: {v['axis']}, {machine.name} has {n} axes")
        elif key not in ("filter", "filter_ptp", "dead", "dynamics", "short_k", "short_below") and len(v) != n:
            raise MachineDataError(f"{path}: {len(v)} values for the {n} axes of {machine.name}")
    prov = dict(machine.provenance)
    joints = machine.joints
    if "acc" in got:
        joints = tuple(replace(j, max_acc_deg_s2=a) for j, a in zip(joints, got["acc"]))
    from_recordings = f"identified: {path.name} (tools/identify_kr3.py, the real KUKA Trace recordings)"
    for key, field in (("acc", "max_acc_deg_s2"), ("ramp", "ptp_ramp_deg"), ("friction", "ptp_friction"),
                       ("filter", "actual_filter_cycles"), ("filter_ptp", "actual_filter_cycles_ptp"),
                       ("following", "actual_following"),
                       ("dead", "actual_dead_cycles"), ("settle", "actual_settle_lag"), ("short_k", "ptp_short_ramp_s2"),
                       ("short_below", "ptp_short_ramp_below_s")):
        if key in got:
            prov[field] = from_recordings
    if "dynamics" in got:
        prov["dynamics"] = (f"identified: {path.name} (tools/identify_kr3.py: link inertias from the collision meshes scaled to "
                            "the recorded gear torques, torque limits and rotor inertias from the recordings)")
    return replace(machine, joints=joints, ptp_ramp_deg=got.get("ramp", machine.ptp_ramp_deg),
                   ptp_friction=got.get("friction", machine.ptp_friction),
                   ptp_short_ramp_s2=got.get("short_k", machine.ptp_short_ramp_s2),
                   ptp_short_ramp_below_s=got.get("short_below", machine.ptp_short_ramp_below_s),
                   actual_filter_cycles=got.get("filter", machine.actual_filter_cycles),
                   actual_filter_cycles_ptp=got.get("filter_ptp", machine.actual_filter_cycles_ptp),
                   actual_following=got.get("following", machine.actual_following),
                   actual_dead_cycles=got.get("dead", machine.actual_dead_cycles),
                   actual_settle_lag=got.get("settle", machine.actual_settle_lag),
                   dynamics=got.get("dynamics", machine.dynamics), provenance=prov)


__all__ = ["IDENTIFIED", "apply_identified", "identified_file", "read_identified"]
