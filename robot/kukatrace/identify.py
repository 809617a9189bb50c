"""A robot's motion parameters identified from its real KUKA Trace recordings (issues 60 and 73),
on any subset of the recorded programs: the method of ``tools/identify_kr3.py`` (which prints
and writes what this module returns) and of ``python -m interp.tracebench --cross`` (which
identifies once per program with that program left out and predicts it).

:func:`identify` takes the real recordings (interp/tracebench.py ``real_recordings``: MAP row,
Recording, override), the robot's machine data, the links' inertials (:func:`link_inertials`) and a
function that runs the LIN and CIRC programs on a machine (the interpreters live above this
package: interp/tracebench.py gives it), and returns an :class:`Identified`: the machine with the
parameters applied, the parameters in the layout of robot/data/identified/<robot>.yaml and the
residuals of each step. What each step takes from the recordings:

1. *Dynamic model* (robot/dynamics.py): the links' masses scaled so that the model's gravity
   torques of A2 and A3 equal the interpolator's commanded gear torques (``GearTorq_CmdIpo2/3``)
   at the start of every motion, where the robot stands (least squares, one scale for link 2 and
   one for links 3..6; each motion's ``LOAD`` from PROG.TXT); the drives' gear-torque limits of
   A2 and A3 from the commanded torques while they move: ``g + (τ_cmd − g)/ov²`` is the torque
   the motion was planned with at 100 % override (the override scales its time, so its inertial
   torques by ov²), its largest magnitude over the motions the limit (:func:`torque_limits`).
2. *PTP accelerations* ``A_i`` and *friction* ``c_i``: least squares (soft L1) of log(planned
   duration) over the single-axis PTPs (the velocity runs, and the acceleration runs at 10 % and
   100 % ``$ACC_AXIS``), planned as the simulator plans with the dynamic model on
   (:func:`fit_axes`; a friction only with a PTP at a reduced ``$ACC_AXIS``; an axis without one
   takes the friction its drive shows in step 4's following error, :func:`drive_friction`, and
   steps 2-3 run again with it, when the set has LINs or CIRCs): first on those at
   100 % ``$VEL_AXIS``, then on all of them under the short-ramp law of step 3. For an axis
   without a torque channel (A1, A4..A6) the torque is then the one that gives ``A_i`` at the
   poses it was identified at (its acceleration is the torque's, at any pose and load); A2 and A3
   keep their measured torque limits and ``A_i`` caps them.
3. *The short-ramp law* (robot/planner.py ``short_ramp_scale``; issue 88): one K and θ for the
   robot from every PTP at a reduced ``$VEL_AXIS``, where the law acts (:func:`fit_short_ramp`), between the two fits of step 2 and again after
   the *rotor inertias*: one value for the main axes A1..A3, one for the wrist, the best of a grid
   over the multi-axis PTPs (:func:`fit_rotors`).
4. *Actual-value average*, *following error* and *dead time* (robot/actualvalue.py) on the LINs
   and CIRCs of the set (:func:`fit_filter`, :func:`fit_following`, :func:`fit_dead_time`).
5. *PTP average* (:func:`fit_filter_ptp`): the cycles a PTP's setpoints are averaged over (the
   controller's PTP filter beside its CP one), on the exact-stop PTPs of the set, run on the robot
   of steps 1-4: the count whose motion times from the poses come closest to the recordings'.

Which recordings each step uses is given by its docstring; with a program left out, a step whose
recordings all belong to it falls back to what is there (said in the residuals).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from scipy.optimize import least_squares, lsq_linear, minimize_scalar

from ..exactstop import end_signal
from ..dynamics import NO_LOAD, ArmDynamics
from ..motion import MotionParams
from ..planner import arm_dynamics, ptp_profile, ptp_ramp_time
from ..actualvalue import actual_axes, ptp_rows_of
from ..settlelag import segment_taus
from .actual import actual_tcp, average
from .compare import compare_segments, match_motions, motion_span
from ..axismap import ROBOT_KEYS
from .recording import IPO_CYCLE_S

CYCLE = IPO_CYCLE_S
#: the robot axes a KUKA Trace recording holds (AxisPos_Act1..n, robot/axismap.py)
AXES = len(ROBOT_KEYS)
#: kg/m³ given to the collision meshes before the masses are scaled to the measured torques
DENSITY = 1000.0
#: the grid of the Coulomb term's smoothing speed v0 (deg/s), chosen by the fit's own residual
COULOMB_SPEEDS = (0.5, 1.0, 2.0, 5.0, 10.0)
#: the shifts (s) tried between a run's motion and the recording's (the measured axes lag START)
LAGS = np.arange(0.0, 0.08, 0.001)
#: the wrist's axes (0-based): capped by their identified acceleration, without a torque limit
WRIST = (3, 4, 5)
#: the torque channels of a KR C4 KUKA Trace (axis index 0-based -> column)
TORQUE_COLUMNS = {1: "GearTorq_CmdIpo2", 2: "GearTorq_CmdIpo3"}


@dataclass
class Identified:
    """What :func:`identify` found: ``machine`` (the MachineData with the parameters),
    ``params`` (the yaml's layout: ptp, dynamics, actual), ``residuals`` (label -> text)."""

    machine: Any
    params: dict[str, Any]
    residuals: dict[str, Any] = field(default_factory=dict)


def bare(machine) -> Any:
    """`machine` without anything identified (robot/identified.py): no ramp distances, friction,
    dynamics, actual-value average, following error or dead time; what :func:`identify` starts from."""
    return replace(machine, ptp_ramp_deg=(), ptp_friction=(), dynamics=None, actual_filter_cycles=1,
                   actual_following=None, actual_dead_cycles=0)


def _at(rec, t: float) -> np.ndarray:
    return rec.axes[int(np.argmin(np.abs(rec.t - t)))]


def load_of(m) -> dict[str, Any] | None:
    """A PROG.TXT motion's LOAD as robot/dynamics.py takes it (m kg, cm mm/deg, j kg m²)."""
    return m.load if m.load else None


def ptp_motions(recs) -> list[dict[str, Any]]:
    """Every PTP of `recs` as a dict: program, name, index, q0 and dq (deg; dq measured: the axes
    at the next motion's START, the last motion: the last sample, less those at its START), vel
    and acc % (6), planned duration (s), START, END, override, load."""
    out = []
    for row, rec, ov in recs:
        for k, m in enumerate(rec.motions):
            if m.kind != "PTP":
                continue
            nxt = rec.motions[k + 1].start if k + 1 < len(rec.motions) else rec.t[-1]
            out.append({"program": row["program"], "name": rec.name, "k": k, "q0": _at(rec, m.start).copy(),
                        "dq": _at(rec, nxt) - _at(rec, m.start),
                        "vel": [m.velocities.get(f"a{i}", 100.0) for i in range(1, AXES + 1)],
                        "acc": [m.accelerations.get(f"a{i}", 100.0) for i in range(1, AXES + 1)],
                        "plan": m.endtime - m.start, "start": m.start, "end": m.end, "ov": ov,
                        "load": load_of(m)})
    return out


def _params(machine, mot) -> MotionParams:
    """The motion parameters of PTP `mot` at 100 % override (its plan's)."""
    return replace(MotionParams.initmov(machine), vel_axis=tuple(mot["vel"]), acc_axis=tuple(mot["acc"]), ov_pro=100.0,
                   load=load_tuple(mot.get("load")))


def planned(machine, mot) -> float:
    """The simulator's planned duration (s, at 100 % override) of PTP `mot` on `machine`."""
    return ptp_profile(mot["dq"], _params(machine, mot), machine, q0=mot["q0"]).t_total


def load_tuple(load: dict[str, Any] | None) -> tuple[float, ...] | None:
    """PROG.TXT's LOAD as MotionParams.load: (M, X, Y, Z, A, B, C, JX, JY, JZ)."""
    if not load:
        return None
    cm, j = load.get("cm") or {}, load.get("j") or {}
    return (float(load.get("m", -1.0)), *(float(cm.get(k, 0.0)) for k in "xyzabc"),
            *(float(j.get(k, 0.0)) for k in "xyz"))


def with_params(machine, acc, ramp, friction, dynamics=None):
    joints = tuple(replace(j, max_acc_deg_s2=float(a)) for j, a in zip(machine.joints, acc))
    return replace(machine, joints=joints, ptp_ramp_deg=tuple(float(r) for r in ramp),
                   ptp_friction=tuple(float(c) for c in friction), dynamics=dynamics)


def motion_time(mot, plan: float) -> float:
    """END - START the controller gives a PTP planned to last `plan` s (robot/exactstop.py)."""
    return end_signal(mot["start"] + plan / mot["ov"], CYCLE) - mot["start"]


def errors(machine, mots) -> tuple[np.ndarray, np.ndarray]:
    """(planned-duration errors, motion-time errors) in % of the real ones."""
    ep, et = [], []
    for m in mots:
        p = planned(machine, m)
        ep.append(100 * (p / m["plan"] - 1))
        et.append(100 * (motion_time(m, p) / (m["end"] - m["start"]) - 1))
    return np.array(ep), np.array(et)


def figures(e: np.ndarray) -> str:
    a = np.abs(e)
    if not len(a):
        return "n 0"
    return f"n {len(a)}, |error| median {np.median(a):.2f} %, p90 {np.percentile(a, 90):.2f} %, max {a.max():.2f} %"


def single_axis(m) -> bool:
    return int(np.sum(np.abs(m["dq"]) > 0.5)) == 1


def main_axis(m) -> int:
    return int(np.argmax(np.abs(m["dq"])))


def acc_pct(m) -> float:
    return m["acc"][main_axis(m)]


def link_inertials(meshes: Path) -> dict[str, list]:
    """Mass (kg), centre of mass (mm) and inertia about it (kg m², xx yy zz xy xz yz) of link_1..6
    from the collision meshes (uniform density :data:`DENSITY`; a mesh that is not closed by its
    convex hull). Their frames are the URDF's link frames, which are the joint chain's of
    robot/data/kr3_r540.dat (tests/robot/test_kr3.py)."""
    mass, com, inertia = [], [], []
    for i in range(1, AXES + 1):
        mesh = trimesh.load(meshes / f"link_{i}.stl")
        if not mesh.is_watertight:
            mesh = mesh.convex_hull
        mesh.density = DENSITY
        I = mesh.moment_inertia            # about the centre of mass, kg m²
        mass.append(round(float(mesh.mass), 4))
        com.append([round(float(x) * 1000.0, 2) for x in mesh.center_mass])
        inertia.append([round(float(x), 7) for x in (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])])
    return {"link_mass_kg": mass, "link_com_mm": com, "link_inertia_kg_m2": inertia}


def fit_axes(base, train, hook: Callable[[int, float], None] | None = None,
             friction: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A_i, R_i, c_i) fitted axis by axis (a single-axis PTP depends on its axis' three
    parameters only): the best point of a grid (the largest A_i of equal costs; A 1 000..200 000 deg/s², R 0.1..30 deg,
    log-spaced; c 0, 2, 5, 10 1/s), then least squares (soft L1, scale 2 %) of log(planned
    duration) from there, c within 0..30 1/s. A parameter the axis' PTPs cannot show is not fitted
    (:func:`_shown`): R_i 0 (no ramp bound) without a PTP at a reduced ``$VEL_AXIS``, c_i 0
    without one at a reduced ``$ACC_AXIS`` (then `friction[i]` when given: the drive's,
    :func:`drive_friction`, with A_i fitted beside it). An axis without a PTP in `train` keeps
    10 000 deg/s², 2 deg, 0. `hook(i, A_i)` is called before each evaluation (the dynamic model's
    torque of an axis without a measured limit follows its acceleration)."""
    acc, ramp, fric = np.full(AXES, 10000.0), np.zeros(AXES), np.zeros(AXES)
    dyn = getattr(base, "dynamics", None)
    lo, hi = np.array([math.log(500.0), math.log(0.01), 0.0]), np.array([math.log(5e5), math.log(100.0), 30.0])
    for i in range(AXES):
        mine = [m for m in train if main_axis(m) == i]
        if not mine:
            continue
        free = _shown(mine, i, float(base.joints[i].max_speed_deg_s))
        c0 = float(friction[i]) if friction is not None and not free[2] else 0.0

        def full(x, free=free, c0=c0):
            y = np.array([0.0, -np.inf, c0])
            y[free] = x
            return y

        def res(x, i=i, mine=mine):
            a, r, c = acc.copy(), ramp.copy(), fric.copy()
            y = full(x)
            a[i], r[i], c[i] = math.exp(y[0]), math.exp(y[1]), y[2]
            if hook is not None:
                hook(i, a[i])
            mach = with_params(base, a, r, c, dyn)
            return [math.log(planned(mach, m) / m["plan"]) for m in mine]

        grid = [np.array((la, lr, c))[free] for la in np.linspace(math.log(1e3), math.log(2e5), 24)
                for lr in (np.linspace(math.log(0.1), math.log(30.0), 16) if free[1] else (0.0,))
                for c in ((0.0, 2.0, 5.0, 10.0) if free[2] else (0.0,))]
        # among equal costs the largest A_i: an acceleration cap none of the axis' runs shows is
        # none (A2's runs are its torque's; a low cap that ties there binds a synchronised PTP)
        x0 = min(grid, key=lambda x: (round(float(np.sum(np.abs(res(x)))), 9), -float(x[0])))
        sol = least_squares(res, x0, loss="soft_l1", f_scale=0.02, bounds=(lo[free], hi[free]))
        y = full(sol.x)
        acc[i], ramp[i], fric[i] = math.exp(y[0]), math.exp(y[1]), y[2]
        if hook is not None:
            hook(i, acc[i])
    return acc, ramp, fric


def _shown(mine: list[dict], i: int, v_max: float) -> np.ndarray:
    """Which of (A_i, R_i, c_i) axis i's single-axis PTPs `mine` can show: A always; R never (a
    PTP at a reduced ``$VEL_AXIS`` follows the short-ramp law of the synchronised motion,
    :func:`fit_short_ramp`, not a distance of the axis); c (the friction, which takes a share of
    the acceleration that grows as the acceleration falls) only with a PTP below 100 %
    ``$ACC_AXIS``. Otherwise the parameter trades against A_i on the data it has and predicts
    nothing (``--cross``: with PTP_vel_test left out, A5's R went to 10.6 deg and its 10 % runs
    took 2.5 times as long)."""
    return np.array([True, False, any(m["acc"][i] < 100.0 for m in mine)])


#: the longest dynamic ramp time (s) of a PTP the short-ramp law is fitted on (:func:`fit_short_ramp`)
SHORT_RAMP_MAX_S = 0.03
#: the grid of the law's K (s²) before it is refined
SHORT_RAMP_K_GRID = tuple(float(k) for k in np.geomspace(1e-4, 2e-3, 27))


def reduced_speed(m: dict) -> bool:
    """True when PTP `m` (:func:`ptp_motions`'s dict) moves an axis at a ``$VEL_AXIS`` below 100 %
    (every axis of a recorded PTP has the same ``$VEL_AXIS``; robot/planner.py asks the leading axes)."""
    return any(v < 100.0 for v, d in zip(m["vel"], m["dq"]) if abs(d) > 1e-9)


def fit_short_ramp(machine, mots: list[dict]) -> tuple[float, float, dict[str, Any]]:
    """The short-ramp law (robot/planner.py ``short_ramp_scale``: a synchronised PTP whose axes would
    ramp to its speed in ``t`` < θ ramps in ``K / t``) that plans the PTPs `mots` (:func:`ptp_motions`'s
    dicts, single- and multi-axis) on `machine` closest: (K s², θ s, residuals). The PTPs at a
    reduced ``$VEL_AXIS`` (:func:`reduced_speed`: the law acts there alone) whose dynamic ramp ``t``
    (robot/planner.py ``ptp_ramp_time``) is below :data:`SHORT_RAMP_MAX_S` are sorted by ``t``; for each K of :data:`SHORT_RAMP_K_GRID` and each split of that order (the law for
    the first j), the summed |log(planned / recorded duration)|; the best split's θ the midpoint of
    ``t`` between its last PTP under the law and its first without, K then refined on the PTPs under
    it. (0, 0) when no split beats no law. Issue 88: the law holds across the programs of
    ../shared/real-traces (docs/robot.md "The short-ramp law"); a run at 100 % identifies its axis'
    acceleration (:func:`fit_axes`), and taken for the law too it let the two trade (with
    PTP_vel_test left out A4's 100 % runs went under the law at 38 191 deg/s², K 360 ms²: docs/robot.md
    "The short-ramp law where it is shown")."""
    law_off = replace(machine, ptp_short_ramp_s2=0.0, ptp_short_ramp_below_s=0.0)
    cand = sorted(((ptp_ramp_time(m["dq"], _params(law_off, m), law_off, q0=m["q0"]), k) for k, m in enumerate(mots)),
                  key=lambda x: x[0])
    cand = [(t, mots[k]) for t, k in cand if t < SHORT_RAMP_MAX_S and reduced_speed(mots[k])]
    if not cand:
        return 0.0, 0.0, {"n": 0}

    def errs(k: float) -> np.ndarray:
        mach = replace(machine, ptp_short_ramp_s2=k, ptp_short_ramp_below_s=math.inf) if k > 0 else law_off
        return np.array([abs(math.log(planned(mach, m) / m["plan"])) for _t, m in cand])

    off = errs(0.0)
    rest = np.concatenate([np.cumsum(off[::-1])[::-1], [0.0]])        # rest[j] = sum(off[j:])
    best = (float(rest[0]), 0, 0.0)
    for k in SHORT_RAMP_K_GRID:
        on = np.concatenate([[0.0], np.cumsum(errs(k))])               # on[j] = sum(errs[:j])
        j = int(np.argmin(on + rest))
        if on[j] + rest[j] < best[0] - 1e-12:
            best = (float(on[j] + rest[j]), j, k)
    _cost, j, k = best
    times = [t for t, _m in cand]
    if j == 0:
        return 0.0, 0.0, {"n": len(cand), "under_law": 0}
    sol = minimize_scalar(lambda lk: float(np.sum(errs(math.exp(lk))[:j])),
                          bounds=(math.log(k) - 0.15, math.log(k) + 0.15), method="bounded",
                          options={"xatol": 1e-3})
    k = math.exp(float(sol.x))
    below = (times[j - 1] + times[j]) / 2.0 if j < len(times) else SHORT_RAMP_MAX_S
    return k, below, {"n": len(cand), "under_law": j, "ramp_times_ms": [round(1000 * t, 1) for t in times]}


def scaled_links(links: dict[str, list], scales: np.ndarray) -> dict[str, list]:
    """`links` with link i's mass and inertia times ``scales[i]`` (its centre of mass kept)."""
    return {"link_mass_kg": [round(float(m * k), 4) for m, k in zip(links["link_mass_kg"], scales)],
            "link_com_mm": links["link_com_mm"],
            "link_inertia_kg_m2": [[float(f"{x * k:.6g}") for x in I] for I, k in zip(links["link_inertia_kg_m2"], scales)]}


#: the links each mass scale of :func:`mass_scales` multiplies: the base and the rocker (A1, A2),
#: the arm from A3 on
SCALE_GROUPS = ((0, 1), (2, 3, 4, 5))


def _rest_samples(recs) -> list[tuple[np.ndarray, dict[int, float], Any]]:
    """(axes deg, {axis index: commanded gear torque N m}, LOAD) at each motion's START, where the
    robot stands (60 ms after the previous END, or at the trace's start), of the recordings with
    torque channels."""
    out = []
    for _row, rec, _ov in recs:
        cols = {i: rec.columns[c] for i, c in TORQUE_COLUMNS.items() if c in rec.columns}
        if not cols:
            continue
        for m in rec.motions:
            k = int(np.argmin(np.abs(rec.t - m.start)))
            out.append((rec.axes[k], {i: float(c[k]) for i, c in cols.items()}, load_tuple(load_of(m))))
    return out


def mass_scales(base, links: dict[str, list], recs) -> tuple[np.ndarray, dict[str, Any]]:
    """The links' masses scaled to the robot (step 1 of the module's docstring): least squares of
    the commanded gear torques of A2 and A3 at rest (:func:`_rest_samples`) less the model's
    gravity of each motion's LOAD, over the gravity torques of the link groups of
    :data:`SCALE_GROUPS`. Returns (a scale per link, {"n", "rms_nm", "max_nm", "scales"})."""
    def part(keep: tuple[int, ...]) -> Any:
        masses = [m if i in keep else 0.0 for i, m in enumerate(links["link_mass_kg"])]
        return ArmDynamics(base, {**links, "link_mass_kg": masses, "rotor_inertia_kg_m2": [0.0] * AXES,
                                  "torque_nm": [1.0] * AXES})

    parts = [part(g) for g in SCALE_GROUPS]
    for pt in parts:                       # the links' gravity alone (no default load at the flange)
        pt.set_load(NO_LOAD, None)
    load = part(())
    X, y = [], []
    for q, tau, ld in _rest_samples(recs):
        load.set_load(ld if ld is not None else NO_LOAD, None)
        g_load = load.gravity(q)
        g_parts = [pt.gravity(q) for pt in parts]
        for i, t in tau.items():
            X.append([g[i] for g in g_parts])
            y.append(t - g_load[i])
    X, y = np.array(X), np.array(y)
    k, *_ = np.linalg.lstsq(X, y, rcond=None)
    r = y - X @ k
    scales = np.ones(len(links["link_mass_kg"]))
    for s, group in zip(k, SCALE_GROUPS):
        scales[list(group)] = s
    return scales, {"n": len(y), "rms_nm": float(np.sqrt(np.mean(r ** 2))), "max_nm": float(np.max(np.abs(r))),
                    "scales": [round(float(s), 4) for s in k]}


def torque_limits(dyn: Any, recs) -> dict[int, float]:
    """The drives' gear-torque limits of the axes with a torque channel (step 1 of the module's
    docstring): the largest ``|g(q) + (τ_cmd − g(q)) / ov²|`` over the samples of every PTP from
    its START to its END, ``g`` the model's gravity (`dyn`, an ArmDynamics) with the motion's LOAD
    at the measured axes, ``ov`` the recording's override. {axis index: N m}."""
    best: dict[int, float] = {}
    for _row, rec, ov in recs:
        cols = {i: rec.columns[c] for i, c in TORQUE_COLUMNS.items() if c in rec.columns}
        for m in rec.motions:
            if m.kind != "PTP" or not cols or m.end is None:
                continue
            dyn.set_load(load_tuple(load_of(m)), None)
            for k in np.flatnonzero((rec.t >= m.start) & (rec.t <= m.end)):
                g = dyn.gravity(rec.axes[k])
                for i, c in cols.items():
                    best[i] = max(best.get(i, 0.0), abs(g[i] + (float(c[k]) - g[i]) / ov ** 2))
    return best


class _Torques:
    """The torque of each axis without a measured limit, from its identified acceleration: the
    mean over its single-axis PTPs (`single`) of ``rad(A_i)·M_ii + s·g_i`` at the start (and
    ``− s·g_i`` at the end), which makes the dynamic model give ``A_i`` at those poses with those
    loads (step 2 of the module's docstring)."""

    def __init__(self, dyn: Any, single: list[dict]) -> None:
        self.dyn, self.single = dyn, single
        self.refresh()

    def refresh(self) -> None:
        """The poses' inertias and gravity again (after the rotor inertias changed)."""
        self.terms: dict[int, tuple[float, float]] = {}
        n = self.dyn.n
        for i in range(n):
            mine = [m for m in self.single if main_axis(m) == i]
            h, g = [], []
            for m in mine:
                self.dyn.set_load(load_tuple(m.get("load")), None)
                s = float(np.sign(m["dq"][i]))
                for q, sg in ((m["q0"], s), (m["q0"] + m["dq"], -s)):
                    e = np.zeros(n)
                    e[i] = 1.0
                    gq = self.dyn.gravity(q)
                    h.append(float(self.dyn.inverse(q, e)[i] - gq[i]))
                    g.append(sg * float(gq[i]))
            if mine:
                self.terms[i] = (float(np.mean(h)), float(np.mean(g)))

    def torque(self, i: int, acc_deg_s2: float) -> float:
        h, g = self.terms.get(i, (1.0, 0.0))
        return math.radians(acc_deg_s2) * h + g


def fit_rotors(fitted, train_multi, torques: _Torques, capped: set[int]):
    """The rotor inertias (step 3 of the module's docstring): one value for A1..A3, one for
    A4..A6, the best point of a grid (0 and 1e-4..0.1, 0 and 1e-5..0.01 kg m², log-spaced,
    24 x 24) for the sum of |log(planned duration)| errors over `train_multi`; the torques of the
    axes not in `capped` follow the rotors (:class:`_Torques`). Returns the rotor inertias."""
    dyn = fitted.dynamics
    arm = torques.dyn
    acc = [j.max_acc_deg_s2 for j in fitted.joints]

    def apply(rotor: np.ndarray) -> None:
        arm.model.dof_armature[:] = rotor
        torques.refresh()
        for i in range(arm.n):
            if i not in capped and i not in WRIST:
                arm.torque[i] = torques.torque(i, acc[i])

    def cost(rotor: np.ndarray) -> float:
        apply(rotor)
        return float(np.sum([abs(math.log(planned(fitted, m) / m["plan"])) for m in train_multi]))

    grid = [(jm, jw) for jm in [0.0, *np.geomspace(1e-4, 0.1, 23)] for jw in [0.0, *np.geomspace(1e-5, 0.01, 23)]]
    main = np.array([i not in WRIST for i in range(arm.n)])
    jm, jw = min(grid, key=lambda g: cost(np.where(main, g[0], g[1])))
    rotor = np.where(main, jm, jw)
    apply(rotor)
    dyn["rotor_inertia_kg_m2"] = [float(f"{r:.4g}") for r in rotor]
    dyn["torque_nm"] = [round(float(t), 4) if np.isfinite(t) else None for t in arm.torque]
    return rotor


def path_figures(pairs, n: int, following: dict) -> dict[tuple[str, str, int], float]:
    """The path deviation (mm) of each LIN and CIRC, keyed (kind, recording, motion index), of the
    runs' setpoints averaged over `n` cycles less the `following` error (``{}``: none), without a
    dead time (the path is geometric; the dead time is identified after, :func:`fit_dead_time`)."""
    out: dict[tuple[str, str, int], float] = {}
    for name, run, a, b in pairs:
        for m in compare_segments(a, b, actual_tcp(run, a, n, following=following, dead=0, ptp_cycles=None)).motions:
            if m.kind in ("LIN", "CIRC") and m.path_deviation is not None:
                out[(m.kind, name, m.run_index)] = m.path_deviation
    return out


def worst(fig: dict, kind: str) -> float | None:
    """The largest path deviation (mm) of the motions of `kind` in `fig` (:func:`path_figures`)."""
    got = [v for key, v in fig.items() if key[0] == kind]
    return max(got) if got else None


def fit_filter(pairs) -> tuple[int, dict[int, dict]]:
    """The cycles of the actual-value average (robot/kukatrace/actual.py): the average of N = 1..10
    cycles puts the runs' setpoints through, without the following error; N is the one whose
    largest LIN path deviation from the real robot's path is least (the CIRCs' when there is no
    LIN). Returns (N, the path figures of every N)."""
    table = {n: path_figures(pairs, n, {}) for n in range(1, 11)}
    kind = "LIN" if any(k[0] == "LIN" for k in table[1]) else "CIRC"
    return min(table, key=lambda n: worst(table[n], kind)), table


def motion_residuals(pairs, n: int) -> list[dict]:
    """Per LIN and CIRC motion: the measured axes less the runs' setpoints averaged over `n` cycles,
    on the recording's samples from START to the next START, the setpoints shifted by the lag
    (``LAGS``) whose rms over the motion (50 ms off either end) is least; with the averaged
    setpoints' speed and acceleration there (deg, deg/s, deg/s²). Keys: recording, index, kind,
    r, v, a (each (N, 6))."""
    out = []
    for name, _run, a, b in pairs:
        qa = average(a.axes[:, :AXES], n)
        va = np.gradient(qa, CYCLE, axis=0)
        for k, j in match_motions(a, b)[0]:
            ma, mb = a.motions[k], b.motions[j]
            if ma.kind not in ("LIN", "CIRC"):
                continue
            ia, ib = a.window(*motion_span(a, k)), b.window(*motion_span(b, j))
            ta, tb = a.t[ia] - ma.start, b.t[ib] - mb.start
            best = None
            for lag in LAGS:
                r = np.stack([b.axes[ib, i] - np.interp(tb - lag, ta, qa[ia, i]) for i in range(AXES)], 1)
                on = (tb - lag > 0.05) & (tb - lag < ta[-1] - 0.05)
                e = float(np.sqrt(np.mean(r[on] ** 2)))
                if best is None or e < best[0]:
                    best = (e, lag, r)
            _e, lag, r = best
            v = np.stack([np.interp(tb - lag, ta, va[ia, i]) for i in range(AXES)], 1)
            out.append({"recording": name, "index": k, "kind": ma.kind, "r": r, "v": v,
                        "a": np.gradient(v, CYCLE, axis=0)})
    return out


def fit_following(samples: list[dict]) -> tuple[dict, float]:
    """The following error (robot/kukatrace/actual.py ``following_error``) that explains the
    residuals of `samples` (:func:`motion_residuals`) best: per axis, bounded least squares
    (m, c >= 0; k either sign: relative to the lag already shifted out) of ``r = -(m a + c
    tanh(v/v0) + k v)``, v0 from :data:`COULOMB_SPEEDS` by the summed squared residual.
    Returns (parameters, that residual in deg²)."""
    best = None
    for v0 in COULOMB_SPEEDS:
        p, cost = np.zeros((AXES, 3)), 0.0
        for i in range(AXES):
            X = np.vstack([np.stack([-s["a"][:, i], -np.tanh(s["v"][:, i] / v0), -s["v"][:, i]], 1) for s in samples])
            y = np.concatenate([s["r"][:, i] for s in samples])
            got = lsq_linear(X, y, bounds=([0, 0, -np.inf], [np.inf] * 3))
            p[i], cost = got.x, cost + 2 * got.cost
        if best is None or cost < best[1]:
            best = ({"inertia_s2": [float(f"{x:.4g}") for x in p[:, 0]],
                     "coulomb_deg": [round(float(x), 5) for x in p[:, 1]],
                     "viscous_s": [float(f"{x:.4g}") for x in p[:, 2]],
                     "coulomb_speed_deg_s": v0}, cost)
    return best


def departure(t: np.ndarray, axes: np.ndarray, t0: float, t1: float, window: np.ndarray) -> float | None:
    """The first time (s) in [`t0`, `t1`] at which an axis of `axes` (N, n) deg, sampled at `t`
    (N,) s, is farther than its `window` (deg, ``$IN_POS_MA``) from the pose at `t0`: where a
    motion from rest leaves it; None when none does."""
    k = np.flatnonzero((t >= t0 - 1e-9) & (t <= t1 + 1e-9))
    if len(k) < 2:
        return None
    q = axes[k][:, :len(window)]
    away = np.flatnonzero(np.any(np.abs(q - q[0]) > window, axis=1))
    return float(t[k[away[0]]]) if len(away) else None


def pose_times(t: np.ndarray, axes: np.ndarray, t0: float, t1: float,
               window: np.ndarray) -> tuple[float, float] | None:
    """(left rest, settled) of one motion (issue 73's motion time from the poses, "leaving rest ->
    settled"): the first sample time (s) after `t0` (its START) at which an axis of `axes` (N, n)
    deg, sampled at `t` (N,) s, is farther than its `window` (deg, ``$IN_POS_MA``) from the pose at
    START, and the first from which every axis stays within its window of the pose at `t1` (the
    next START, or the segment's end). None when the axes do not leave rest or do not settle."""
    k = np.flatnonzero((t >= t0 - 1e-9) & (t <= t1 + 1e-9))
    if len(k) < 2:
        return None
    q = axes[k][:, :len(window)]
    away = np.flatnonzero(np.any(np.abs(q - q[0]) > window, axis=1))
    if len(away) == 0:
        return None
    out = np.flatnonzero(np.any(np.abs(q - q[-1]) > window, axis=1))
    settled = out[-1] + 1 if len(out) else 0
    if settled >= len(k) or settled <= away[0]:
        return None
    return float(t[k[away[0]]]), float(t[k[settled]])


#: how many IPO cycles longer than the CP average :func:`fit_filter_ptp` tries for a PTP's
PTP_FILTER_EXTRA = 6


def fit_filter_ptp(pairs, n: int, following: dict, dead: int, window: np.ndarray) -> tuple[int, dict[int, float]]:
    """The IPO cycles of a PTP's average (``MachineData.actual_filter_cycles_ptp``: KSS filters a
    PTP's setpoints with ``$DEF_FLT_PTP``, a CP motion's with ``$DEF_FLT_CP``; robot/actualvalue.py):
    of `n` (the CP average, :func:`fit_filter`) .. `n` + :data:`PTP_FILTER_EXTRA`, the one whose
    motion times from the poses (:func:`pose_times`, the actual-value model with the `following`
    error and `dead` cycles against the recording's measured axes) of the exact-stop PTPs of
    `pairs` (identify's ``run_cp``) are off by the least mean |error| (%); the shorter on a tie.
    Returns (cycles, the mean |error| of each tried)."""
    cost: dict[int, float] = {}
    for m_ptp in range(n, n + PTP_FILTER_EXTRA + 1):
        errs = _exact_ptp_errors(pairs, window, lambda a: actual_axes(
            a.axes[:, :AXES], n, following or None, CYCLE, dead=dead, ptp_rows=ptp_rows_of(a.t, a.motions),
            ptp_cycles=m_ptp))
        if errs:
            cost[m_ptp] = float(np.mean(errs))
    return (min(cost, key=lambda c: (round(cost[c], 9), c)) if cost else n), cost


#: the settling lag's speeds (deg/s) and factors (IPO cycles of τ per kg m² of the axis' inertia)
#: :func:`fit_settle_lag` tries; the lagged axis (1-based)
SETTLE_SPEEDS = (5.0, 20.0, 50.0)
SETTLE_FACTORS = (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0)
SETTLE_AXIS = 1
#: how much larger (mm) a LIN's or CIRC's path deviation may get with the lag than without it
SETTLE_PATH_TOL_MM = 0.0005


def _ptp_pose_errors(pairs, machine, window: np.ndarray) -> list[float]:
    """The |error| (%) of the motion times from the poses (:func:`pose_times`) of the exact-stop PTPs
    of `pairs`, the runs' setpoints through `machine`'s actual-value model (its settling lag with each
    motion's LOAD, robot/settlelag.py) against the recordings' measured axes."""
    return _exact_ptp_errors(pairs, window, lambda a: actual_axes(
        a.axes[:, :AXES], machine.actual_filter_cycles, machine.actual_following or None, CYCLE,
        dead=machine.actual_dead_cycles, ptp_rows=ptp_rows_of(a.t, a.motions),
        ptp_cycles=machine.actual_filter_cycles_ptp, lag=machine.actual_settle_lag,
        taus=segment_taus(machine, a) if machine.actual_settle_lag else None))


def _exact_ptp_errors(pairs, window: np.ndarray, actual) -> list[float]:
    """The |error| (%) of the motion times from the poses (:func:`pose_times`) of the exact-stop PTPs
    of `pairs`: `actual(run)` (the run's actual axes, an array like its ``axes``) against the
    recording's measured axes."""
    errs = []
    for _name, _run, a, b in pairs:
        act = actual(a)
        for k, j in match_motions(a, b)[0]:
            if a.motions[k].kind != "PTP" or not a.motions[k].exact_stop:
                continue
            sa = pose_times(a.t, act, *motion_span(a, k), window)
            sb = pose_times(b.t, b.axes, *motion_span(b, j), window)
            if sa is not None and sb is not None and sb[1] > sb[0]:
                errs.append(abs((sa[1] - sa[0]) / (sb[1] - sb[0]) - 1.0) * 100.0)
    return errs


def _cp_worst(pairs, machine) -> dict[str, float]:
    """The largest path deviation (mm) of the LINs and of the CIRCs of `pairs` through `machine`'s
    actual-value model, its settling lag included."""
    worst_of: dict[str, float] = {}
    m = machine
    for _name, run, a, b in pairs:
        taus = segment_taus(m, a) if m.actual_settle_lag else None
        tcp = actual_tcp(run, a, m.actual_filter_cycles, m.actual_following or {}, m.actual_dead_cycles,
                         m.actual_filter_cycles_ptp, m.actual_settle_lag, taus)
        for got in compare_segments(a, b, tcp).motions:
            if got.kind in ("LIN", "CIRC") and got.path_deviation is not None:
                worst_of[got.kind] = max(worst_of.get(got.kind, 0.0), got.path_deviation)
    return worst_of


def fit_settle_lag(ptp_pairs, cp_pairs, machine, window: np.ndarray) -> tuple[dict | None, dict]:
    """The settling lag (``MachineData.actual_settle_lag``, robot/actualvalue.py) of `machine` (the
    actual-value model of steps 4-5): of :data:`SETTLE_SPEEDS` × :data:`SETTLE_FACTORS` on
    :data:`SETTLE_AXIS`, and none, the one whose motion times from the poses of the exact-stop PTPs of
    `ptp_pairs` are off by the least mean |error| (%), among those that keep the largest LIN and
    CIRC path deviation of `cp_pairs` within :data:`SETTLE_PATH_TOL_MM` of the model's without a lag
    (the drives follow the CP motions as the model does); on a tie the slower speed, then the smaller
    factor. Returns (the lag or None, {(speed, factor) or "none": mean |error|, "path_mm": ...})."""
    base = replace(machine, actual_settle_lag=None)
    cost: dict[Any, Any] = {"none": float(np.mean(_ptp_pose_errors(ptp_pairs, base, window)))}
    held = _cp_worst(cp_pairs, base)
    cost["path_mm"] = {"none": held}
    best, best_cost = None, cost["none"]
    for speed in SETTLE_SPEEDS:
        for factor in SETTLE_FACTORS:
            lag = {"axis": SETTLE_AXIS, "below_deg_s": speed, "cycles_per_kg_m2": factor}
            m = replace(machine, actual_settle_lag=lag)
            path = _cp_worst(cp_pairs, m)
            cost["path_mm"][(speed, factor)] = path
            if any(path.get(k, 0.0) > v + SETTLE_PATH_TOL_MM for k, v in held.items()):
                continue
            c = float(np.mean(_ptp_pose_errors(ptp_pairs, m, window)))
            cost[(speed, factor)] = c
            if round(c, 9) < round(best_cost, 9):
                best, best_cost = lag, c
    return best, cost


def fit_dead_time(pairs, n: int, following: dict, window: np.ndarray) -> tuple[int, list[float]]:
    """The dead time (IPO cycles) by which the measured axes lag the actual-value model (the
    setpoints averaged over `n` cycles less the `following` error, robot/actualvalue.py): per LIN
    and CIRC exact stop of `pairs` (identify's ``run_cp``), how much later after its START the
    recording's axes leave the `window` (deg, ``$IN_POS_MA``) around the START pose than the
    model's (both sampled every IPO cycle); the median over the motions, in whole cycles. The
    duration from leaving rest to settling does not depend on it: the summary's settled end does.
    Returns (cycles, the delays in s)."""
    delays = []
    for _name, _run, a, b in pairs:
        act = actual_axes(a.axes[:, :AXES], n, following or None, CYCLE)
        for k, j in match_motions(a, b)[0]:
            if a.motions[k].kind not in ("LIN", "CIRC"):
                continue
            ta, tb = motion_span(a, k), motion_span(b, j)
            da, db = departure(a.t, act, *ta, window), departure(b.t, b.axes, *tb, window)
            if da is not None and db is not None:
                delays.append((db - tb[0]) - (da - ta[0]))
    return (max(0, int(round(float(np.median(delays)) / CYCLE))) if delays else 0), delays


def ptp_sets(mots) -> dict[str, list[dict]]:
    """The PTPs of `mots` by role: ``train`` (single-axis, of the velocity runs or at 10 or 100 %
    ``$ACC_AXIS``), ``check_acc`` (single-axis at 50 or 70 %), ``fit_multi`` (multi-axis of the
    velocity runs; without them, every multi-axis PTP), ``check_multi`` (the other multi-axis)."""
    train = [m for m in mots if single_axis(m) and (m["program"] == "PTP_vel_test" or acc_pct(m) in (10.0, 100.0))]
    check_acc = [m for m in mots if single_axis(m) and m not in train]
    multi = [m for m in mots if not single_axis(m)]
    fit_multi = [m for m in multi if m["program"] == "PTP_vel_test"] or multi
    return {"train": train, "check_acc": check_acc, "fit_multi": fit_multi,
            "check_multi": [m for m in multi if m not in fit_multi]}


def dynamic_model(base, links: dict | None, recs, rated_kg: float | None) -> tuple[dict | None, set[int], dict]:
    """Step 1 of the module's docstring: the dynamics mapping (robot/dynamics.py) with the links'
    masses scaled to the recorded torques and the measured torque limits (the others 1 N m until
    step 2), the set of axes with a measured limit, and the residuals. (None, set(), {}) without
    `links`."""
    if links is None:
        return None, set(), {}
    scales, res = mass_scales(base, links, recs)
    dyn: dict[str, Any] = {**scaled_links(links, scales), "rotor_inertia_kg_m2": [0.0] * AXES, "torque_nm": [1.0] * AXES}
    if rated_kg is not None:
        dyn["rated_payload_kg"] = rated_kg
    limits = torque_limits(ArmDynamics(base, dyn), recs)
    # the wrist's drives: no recording shows their limit (no torque channel; OfficeLite's wrist
    # PTPs with a 45 times heavier inertia take only 25 % longer): no limit, their acceleration caps
    dyn["torque_nm"] = [round(float(limits[i]), 2) if i in limits else None for i in range(AXES)]
    dyn["capped_axes"] = sorted({i + 1 for i in limits} | {i + 1 for i in WRIST})
    res["torque_limits_nm"] = {f"A{i + 1}": round(float(t), 2) for i, t in sorted(limits.items())}
    return dyn, set(limits), res


def _has_ptp(recs, program: str) -> bool:
    """True when a recording of `program` in `recs` holds a PTP."""
    return any(row["program"] == program and any(m.kind == "PTP" for m in rec.motions) for row, rec, _ov in recs)


def _fit_ptp(machine0, mots: list[dict], sets: dict[str, list[dict]], dyn: dict | None, hook, torques, capped: set[int],
             res: dict[str, Any], friction: np.ndarray | None = None) -> tuple[Any, dict[str, Any]]:
    """Steps 2 and 3 of the module's docstring on `machine0` (the bare robot with the dynamic model
    `dyn`): the machine with the PTP parameters and their yaml layout; the residuals into `res`.
    `friction`: :func:`fit_axes`'s, the drives' friction of the axes the PTPs do not show it on."""
    # the dynamics first on the runs at 100 % $VEL_AXIS (the short-ramp law acts at a reduced speed),
    # then the law on every PTP, the dynamics again on every single-axis run under it, the rotor
    # inertias on the multi-axis ones, and the law once more on that robot
    full_speed = [m for m in sets["train"] if m["vel"][main_axis(m)] >= 100.0]
    acc, ramp, fric = fit_axes(machine0, full_speed or sets["train"], hook, friction)
    k, below, _ = fit_short_ramp(with_params(machine0, acc, ramp, fric, dyn), mots)
    machine0 = replace(machine0, ptp_short_ramp_s2=k, ptp_short_ramp_below_s=below)
    acc, ramp, fric = fit_axes(machine0, sets["train"], hook, friction)
    fitted = with_params(machine0, acc, ramp, fric, dyn)
    if dyn is not None:
        fit_rotors(fitted, sets["fit_multi"], torques, capped)
    k, below, res["short_ramp"] = fit_short_ramp(fitted, mots)
    fitted = replace(fitted, ptp_short_ramp_s2=k, ptp_short_ramp_below_s=below)
    for label, key in (("fit: single axis, velocity runs and acceleration runs at 10 and 100 %", "train"),
                       ("fit: multi-axis (rotor inertias)", "fit_multi"),
                       ("check: acceleration runs at 50 and 70 %, single axis", "check_acc"),
                       ("check: other multi-axis PTPs", "check_multi")):
        res[label] = errors(fitted, sets[key])
    return fitted, {"acc_deg_s2": acc.tolist(), "ramp_deg": ramp.tolist(), "friction_per_s": fric.tolist(),
                    "short_ramp_s2": k, "short_ramp_below_s": below}


def drive_friction(following: dict) -> np.ndarray:
    """The friction (1/s, robot/planner.py ``ptp_friction``: the acceleration an axis loses per
    deg/s of its speed) each axis' drive shows in its following error (:func:`fit_following`, on
    the LINs and CIRCs): a drive that lags by the torque it needs over its gain K, ``e = (J q'' +
    F tanh(q'/v0) + b q') / K``, has ``m = J/K`` and ``k = b/K``, so ``k/m = b/J`` is the viscous
    friction over the inertia the planner loses acceleration to. Only where the drive shows a
    friction at all (its Coulomb term ``c = F/K`` > 0: the wrist's drives on the KR 3 R540); an
    axis whose Coulomb term is 0 gets 0 (its ``k`` is the lag's left over from each motion's shift,
    either sign, not a friction). Issue 88: the planner's friction shows only at a reduced
    ``$ACC_AXIS``, which one program holds (docs/robot.md "The wrist's friction from its drive")."""
    m = np.asarray(following["inertia_s2"], dtype=float)
    c = np.asarray(following["coulomb_deg"], dtype=float)
    k = np.asarray(following["viscous_s"], dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where((c > 0.0) & (m > 0.0) & (k > 0.0), k / m, 0.0)


def _unshown(sets: dict[str, list[dict]], base) -> set[int]:
    """The axes with single-axis PTPs in ``sets["train"]`` none of which shows their friction (:func:`_shown`)."""
    out = set()
    for i in range(AXES):
        mine = [m for m in sets["train"] if main_axis(m) == i]
        if mine and not _shown(mine, i, float(base.joints[i].max_speed_deg_s))[2]:
            out.add(i)
    return out


def identify(base, recs, links: dict | None, run_cp: Callable[[Any, Iterable[str]], list] | None,
             rated_kg: float | None = None) -> Identified:
    """The parameters of the module's docstring from `recs` (interp/tracebench.py ``real_recordings``,
    any subset of programs) for the robot `base` (:func:`bare` machine data); `links` the links' inertials
    (:func:`link_inertials`; None: no dynamic model), `rated_kg` the robot's rated payload (the
    load of M -1); `run_cp(machine, programs)` the (recording name, run, run's segment,
    recording's segment) of each LIN/CIRC program of `programs` run on `machine` (None: no
    actual-value model). An axis none of whose PTPs is at a reduced ``$ACC_AXIS`` takes its drive's
    friction (:func:`drive_friction`) when the LINs and CIRCs show one: the PTP parameters are
    identified again with it and the CP steps run on that robot."""
    mots = ptp_motions(recs)
    sets = ptp_sets(mots)
    dyn, capped, res = dynamic_model(base, links, recs, rated_kg)
    machine0 = replace(base, dynamics=dyn)
    arm = arm_dynamics(machine0)
    torques = _Torques(arm, sets["train"]) if arm is not None else None

    def hook(i: int, a: float) -> None:
        if torques is not None and i not in capped and i not in WRIST:
            arm.torque[i] = torques.torque(i, a)

    fitted, ptp = _fit_ptp(machine0, mots, sets, dyn, hook, torques, capped, res)
    params: dict[str, Any] = {"ptp": ptp, "dynamics": dyn}
    programs = {row["program"] for row, _rec, _ov in recs}
    cp = [p for p in ("movement_test_lin", "Circular") if p in programs]
    if run_cp is not None and cp:
        pairs = run_cp(fitted, cp)
        cycles, table = fit_filter(pairs)
        following, _ = fit_following(motion_residuals(pairs, cycles))
        drive = drive_friction(following)
        if any(drive[i] > 0.0 for i in _unshown(sets, base)):
            fitted, params["ptp"] = _fit_ptp(machine0, mots, sets, dyn, hook, torques, capped, res, drive)
            res["drive_friction"] = {f"A{i + 1}": round(float(drive[i]), 3) for i in sorted(_unshown(sets, base))}
            pairs = run_cp(fitted, cp)
            cycles, table = fit_filter(pairs)
            following, _ = fit_following(motion_residuals(pairs, cycles))
        window = np.asarray(base.in_pos_ma_deg[:AXES], dtype=float)
        dead, delays = fit_dead_time(pairs, cycles, following, window)
        ptp_programs = sorted(p for p in programs if p not in cp and _has_ptp(recs, p))
        ptp_pairs = run_cp(fitted, ptp_programs) if ptp_programs else []
        n_ptp, costs = fit_filter_ptp(pairs + ptp_pairs, cycles, following, dead, window)
        fitted = replace(fitted, actual_filter_cycles=cycles, actual_following=following, actual_dead_cycles=dead,
                         actual_filter_cycles_ptp=n_ptp)
        lag, res["settle_lag"] = fit_settle_lag(pairs + ptp_pairs, pairs, fitted, window)
        fitted = replace(fitted, actual_settle_lag=lag)
        params["actual"] = {"filter_cycles": cycles, "following_error": following, "dead_time_cycles": dead,
                            "filter_cycles_ptp": n_ptp, "settle_lag": lag}
        res["actual"] = (cycles, table, pairs)
        res["dead_time"] = delays
        res["filter_ptp"] = costs
    return Identified(fitted, params, res)
