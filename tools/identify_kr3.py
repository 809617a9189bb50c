"""Identify the KR 3 R540's motion parameters and the KR C4's timing from the real KUKA Trace
recordings of ../shared/real-traces (issue 60). Anyone can rerun it; it reads the recordings in
place and writes nothing unless asked.

    python tools/identify_kr3.py [--traces DIR] [--write]

Every figure is printed with the method that produced it and its residual; docs/robot.md ("The KR
3 R540", "PTP timing") quotes them. ``--write`` writes the identified PTP parameters to
robot/data/identified/kr3_r540.yaml, which robot/identified.py applies to robot/data/kr3_r540.dat.

**Data.** The real recordings of the training half (MAP.csv ``split`` = training): their PROG.TXT
motions (START, planned end ENDTIME at 100 % override, END; the axis percentages and frames the
controller reports) and KRCIpo samples. A PTP's axis distances are measured: the axes at the next
START (the last motion: the last sample) less those at its START. The program override is the one the END signals
allow (robot/kukatrace/model.py ``recording_override``: 85 % for every ``_po85`` recording).

**Method.**

1. *Controller timing* (robot/exactstop.py): the END rule and the restart after END are checked
   on every real motion; counts of exceptions are printed. The start lag is the first sample
   after START whose axes moved more than 0.01° from the axes at START.
2. *Axis speeds*: the cruise of each single-axis PTP at 10 % ``$VEL_AXIS`` (the median speed
   over the samples faster than half the peak) divided by 0.10 x the override, against the
   data sheet's.
3. *PTP accelerations* ``A_i``, *ramp distances* ``R_i`` (robot/limits.py
   ``ptp_axis_accelerations``) and *friction* ``c_i`` (robot/profiles.py ``FrictionProfile``):
   least squares (soft L1) of log(planned duration) over the **single-axis PTPs of the velocity
   runs** (PTP_vel_test: ``$VEL_AXIS`` 10/50/70/100 %, ``$ACC_AXIS`` 100 %) **and of the
   acceleration runs at 10 % and 100 %** ``$ACC_AXIS`` (six recordings per axis), the planned
   duration being ``robot.planner.ptp_profile``'s exactly as the simulator plans. **Checked** on
   recordings not fitted: the single-axis PTPs of the acceleration runs at 50 % and 70 % and the
   multi-axis PTPs (every recording's first motion, HOME to the axis's start pose: those of the
   velocity runs fit the rotor inertias, the others check them); ``c_i`` also against the slope
   of the measured acceleration over the measured speed at 10 % (another signal than the times).
   The residual is the planned duration's error and the motion time's (END - START, through the
   END rule).
4. *CP*: each LIN's and CIRC's planned duration against ``d/v + v/a`` (``2 sqrt(d/a)`` when the
   speed is not reached) with ``$VEL.CP`` and ``$ACC.CP`` of PROG.TXT; a LIN's length from its
   points, a CIRC's (CA 360: it ends where it starts) from the measured TCP path.
5. *Actual-value average* (robot/kukatrace/actual.py): the LIN and CIRC programs run on the robot
   identified above; N cycles of the average the one whose largest LIN path deviation is least.
6. *Following error* (robot/kukatrace/actual.py ``following_error``): per axis ``m q'' + c
   tanh(q'/v0) + k q'`` behind the averaged setpoints, least squares in axis space of the measured
   axes less the averaged setpoints (shifted by each motion's best lag) over the 3 CIRCs and the 5
   LINs; cross-validated by leaving out each LIN recording and each LIN (printed, and written with
   the parameters).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from dataclasses import replace
from datetime import date
import tempfile
from pathlib import Path

import numpy as np
import trimesh
from scipy.optimize import least_squares, lsq_linear

HERE = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(HERE))

from interp import tracebench as B  # noqa: E402
from robot.dynamics import Inertia  # noqa: E402
from robot.exactstop import END_DELAY_CYCLES, RESTART_CYCLES, end_signal  # noqa: E402
from robot.identified import IDENTIFIED  # noqa: E402
from robot.kukatrace.actual import actual_tcp, average  # noqa: E402
from robot.kukatrace.compare import compare_segments, match_motions, motion_span, pair_segments  # noqa: E402
from robot.kukatrace.model import load_run, recording_override  # noqa: E402
from robot.kukatrace.recording import IPO_CYCLE_S, read_recording  # noqa: E402
from robot.mada import load_mada  # noqa: E402
from robot.machine import ROBOT_LIBRARY  # noqa: E402
from robot.motion import MotionParams  # noqa: E402
from robot.planner import ptp_profile  # noqa: E402

TRACES = HERE.parent / "shared" / "real-traces"
ROBOT = ROBOT_LIBRARY / "kr3_r540.dat"
CYCLE = IPO_CYCLE_S


def real_recordings(traces: Path):
    """(MAP row, Recording, override fraction) of each real recording of the training half."""
    with (traces / "MAP.csv").open(newline="", encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f) if r["split"] == "training"]
    for row in rows:
        rec = read_recording(traces / row["real_folder"] / f"WINDOWS-V37DJA1 - 8101392_{row['trace_name']}")
        ov, _ = recording_override(rec)
        yield row, rec, ov


def _at(rec, t: float) -> np.ndarray:
    return rec.axes[int(np.argmin(np.abs(rec.t - t)))]


def ptp_motions(recs):
    """Every PTP of `recs` as a dict: program, name, index, dq (deg), vel and acc % (6), planned
    duration (s), START, END, override. The axis distances are the measured axes at the next
    motion's START (the last motion: the last sample; both 60 ms after END, the robot arrived to
    0.1°) less those at the motion's START: the targets' axes cannot all be had from PROG.TXT's
    Cartesian points (at A5 = 0 only A4 + A6 is defined)."""
    out = []
    for row, rec, ov in recs:
        for k, m in enumerate(rec.motions):
            if m.kind != "PTP":
                continue
            nxt = rec.motions[k + 1].start if k + 1 < len(rec.motions) else rec.t[-1]
            out.append({"program": row["program"], "name": rec.name, "k": k, "q0": _at(rec, m.start).copy(),
                        "dq": _at(rec, nxt) - _at(rec, m.start),
                        "vel": [m.velocities.get(f"a{i}", 100.0) for i in range(1, 7)],
                        "acc": [m.accelerations.get(f"a{i}", 100.0) for i in range(1, 7)],
                        "plan": m.endtime - m.start, "start": m.start, "end": m.end, "ov": ov})
    return out


def planned(machine, mot) -> float:
    """The simulator's planned duration (s, at 100 % override) of PTP `mot` on `machine`."""
    p = replace(MotionParams.initmov(machine), vel_axis=tuple(mot["vel"]), acc_axis=tuple(mot["acc"]), ov_pro=100.0)
    return ptp_profile(mot["dq"], p, machine, q0=mot["q0"]).t_total


def with_params(machine, acc, ramp, friction, dynamics=None):
    joints = tuple(replace(j, max_acc_deg_s2=float(a)) for j, a in zip(machine.joints, acc))
    return replace(machine, joints=joints, ptp_ramp_deg=tuple(float(r) for r in ramp),
                   ptp_friction=tuple(float(c) for c in friction), dynamics=dynamics)


MESHES = HERE.parent / "shared" / "robots" / "descriptions" / "kuka_experimental" / "kuka_kr3_support" / "meshes" / "kr3r540" / "collision"
#: kg/m³ given to the collision meshes: only the ratios of the links' inertias matter, as the
#: torques and rotor inertias are identified against them
DENSITY = 1000.0


def link_inertials(meshes: Path) -> dict[str, list]:
    """Mass (kg), centre of mass (mm) and inertia about it (kg m², xx yy zz xy xz yz) of link_1..6
    from the collision meshes (uniform density :data:`DENSITY`; a mesh that is not closed by its
    convex hull). Their frames are the URDF's link frames, which are the joint chain's of
    robot/data/kr3_r540.dat (tests/robot/test_kr3.py)."""
    mass, com, inertia = [], [], []
    for i in range(1, 7):
        mesh = trimesh.load(meshes / f"link_{i}.stl")
        if not mesh.is_watertight:
            mesh = mesh.convex_hull
        mesh.density = DENSITY
        I = mesh.moment_inertia            # about the centre of mass, kg m²
        mass.append(round(float(mesh.mass), 4))
        com.append([round(float(x) * 1000.0, 2) for x in mesh.center_mass])
        inertia.append([round(float(x), 7) for x in (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])])
    return {"link_mass_kg": mass, "link_com_mm": com, "link_inertia_kg_m2": inertia}


def fit_dynamics(fitted, mots, single, meshes: Path):
    """The dynamics of robot/dynamics.py: the links' inertias from the meshes; the rotor inertias,
    one value for A1..A3 and one for A4..A6, the best point of a grid (0 and 1e-3..1, 0 and
    1e-4..0.1 kg m², log-spaced, 32 x 32) for the sum of |log(planned duration)| errors over the **multi-axis PTPs
    of the velocity runs**; each axis' torque so that it gives, at the mean inertia of the poses
    the axis was identified at alone, the acceleration identified there. Returns (dynamics, the
    machine with them)."""
    links = link_inertials(meshes)
    probe = Inertia(fitted, {**links, "rotor_inertia_kg_m2": [0.0] * 6, "torque_nm": [1.0] * 6})
    m_test = np.zeros(6)
    for i in range(6):
        poses = [m["q0"] + 0.5 * m["dq"] for m in single if int(np.argmax(np.abs(m["dq"]))) == i]
        m_test[i] = float(np.mean([probe.mass_matrix(q)[i, i] for q in poses]))
    acc = np.array([j.max_acc_deg_s2 for j in fitted.joints])
    train = [m for m in mots if m["program"] == "PTP_vel_test" and not single_axis(m)]

    def dynamics(rotor):
        torque = np.radians(acc) * (m_test + rotor)
        return {**links, "rotor_inertia_kg_m2": [round(float(r), 6) for r in rotor],
                "torque_nm": [round(float(t), 4) for t in torque]}

    def cost(rotor):
        mach = replace(fitted, dynamics=dynamics(rotor))
        return float(np.sum([abs(math.log(planned(mach, m) / m["plan"])) for m in train]))

    # two values, one for the main axes and one for the wrist (the data cannot tell six apart);
    # the durations are piecewise in them (a minimum over axes), so a grid, not a gradient
    grid = [(jm, jw) for jm in [0.0, *np.geomspace(1e-3, 1.0, 31)] for jw in [0.0, *np.geomspace(1e-4, 0.1, 31)]]
    jm, jw = min(grid, key=lambda g: cost(np.array([g[0]] * 3 + [g[1]] * 3)))
    dyn = dynamics(np.array([jm] * 3 + [jw] * 3))
    return dyn, replace(fitted, dynamics=dyn)


def motion_time(mot, plan: float) -> float:
    """END - START the controller gives a PTP planned to last `plan` s (robot/exactstop.py)."""
    return end_signal(mot["start"] + plan / mot["ov"], CYCLE) - mot["start"]


def errors(machine, mots):
    """(planned-duration errors, motion-time errors) in % of the real ones."""
    ep, et = [], []
    for m in mots:
        p = planned(machine, m)
        ep.append(100 * (p / m["plan"] - 1))
        et.append(100 * (motion_time(m, p) / (m["end"] - m["start"]) - 1))
    return np.array(ep), np.array(et)


def figures(e: np.ndarray) -> str:
    a = np.abs(e)
    return f"n {len(a)}, |error| median {np.median(a):.2f} %, p90 {np.percentile(a, 90):.2f} %, max {a.max():.2f} %"


def single_axis(m) -> bool:
    return int(np.sum(np.abs(m["dq"]) > 0.5)) == 1


def fit_axes(base, train) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A_i, R_i, c_i) fitted axis by axis (a single-axis PTP depends on its axis' three
    parameters only): the best point of a grid (A 1 000..200 000 deg/s², R 0.1..30 deg,
    log-spaced; c 0, 2, 5, 10 1/s), then least squares (soft L1, scale 2 %) of log(planned
    duration) from there, c within 0..30 1/s."""
    acc, ramp, fric = np.full(6, 10000.0), np.full(6, 2.0), np.zeros(6)
    for i in range(6):
        mine = [m for m in train if int(np.argmax(np.abs(m["dq"]))) == i]
        if not mine:
            continue

        def res(x, i=i, mine=mine):
            a, r, c = acc.copy(), ramp.copy(), fric.copy()
            a[i], r[i], c[i] = math.exp(x[0]), math.exp(x[1]), x[2]
            mach = with_params(base, a, r, c)
            return [math.log(planned(mach, m) / m["plan"]) for m in mine]

        grid = [(la, lr, c) for la in np.linspace(math.log(1e3), math.log(2e5), 24)
                for lr in np.linspace(math.log(0.1), math.log(30.0), 16) for c in (0.0, 2.0, 5.0, 10.0)]
        x0 = min(grid, key=lambda x: float(np.sum(np.abs(res(x)))))
        sol = least_squares(res, x0, loss="soft_l1", f_scale=0.02,
                            bounds=([math.log(500.0), math.log(0.01), 0.0], [math.log(5e5), math.log(100.0), 30.0]))
        acc[i], ramp[i], fric[i] = math.exp(sol.x[0]), math.exp(sol.x[1]), sol.x[2]
    return acc, ramp, fric


def friction_slopes(recs) -> dict[int, list[float]]:
    """Per axis, the friction the samples show (1/s, at 100 % override): the slope of the
    measured acceleration against the measured speed while each single-axis PTP at 10 %
    ``$ACC_AXIS`` accelerates (from 20 % to 90 % of its peak speed; the recording's override
    ``ov`` undone: ``-slope · ov / ov²``), a check of the fitted ``c_i`` on another signal than
    the motion times."""
    out: dict[int, list[float]] = {}
    for _row, rec, ov in recs:
        if "_PTP_ACC_10_" not in rec.name:
            continue
        i = int(rec.name[1]) - 1
        for m in rec.motions[1:]:
            sel = (rec.t >= m.start) & (rec.t <= m.end)
            t, q = rec.t[sel], rec.axes[sel, i]
            v = np.gradient(q, t) * np.sign(q[-1] - q[0])
            a = np.gradient(v, t)
            k = int(np.argmax(v))
            ph = (np.arange(len(v)) < k) & (v > 0.2 * v[k]) & (v < 0.9 * v[k])
            if ph.sum() >= 5:
                slope = float(np.polyfit(v[ph], a[ph], 1)[0])
                out.setdefault(i, []).append(-slope / ov)
    return out


def simulate_cp(traces: Path, machine) -> list[tuple[str, object, object, object]]:
    """The LIN and CIRC programs run on `machine` (the robot with the parameters identified above;
    interp/tracebench.py, every recorded point as recorded): (recording name, run, run's segment,
    recording's segment) of each paired segment."""
    rows = B.map_rows(traces)
    pairs = []
    with tempfile.TemporaryDirectory(prefix="krl-identify-") as tmp:
        for program in ("movement_test_lin", "Circular"):
            mine = [r for r in rows if r["program"] == program]
            real = {r["trace_name"]: read_recording(traces / r["real_folder"] / f"{B.REAL_PREFIX}{r['trace_name']}")
                    for r in mine}
            src = B.prepare(traces, program, list(real.values()), Path(tmp))
            run = B.run_program(src, recording_override(next(iter(real.values())))[0], robot=machine)
            for r in mine:
                pairs += [(r["trace_name"], run, a, b)
                          for a, b in pair_segments(run, load_run(real[r["trace_name"]].prog_path))]
    return pairs


def path_figures(pairs, n: int, following: dict) -> dict[tuple[str, str, int], float]:
    """The path deviation (mm) of each LIN and CIRC, keyed (kind, recording, motion index), of the
    runs' setpoints averaged over `n` cycles less the `following` error (``{}``: none)."""
    out: dict[tuple[str, str, int], float] = {}
    for name, run, a, b in pairs:
        for m in compare_segments(a, b, actual_tcp(run, a, n, following=following)).motions:
            if m.kind in ("LIN", "CIRC") and m.path_deviation is not None:
                out[(m.kind, name, m.run_index)] = m.path_deviation
    return out


def worst(fig: dict, kind: str) -> float:
    """The largest path deviation (mm) of the motions of `kind` in `fig` (:func:`path_figures`)."""
    return max(v for key, v in fig.items() if key[0] == kind)


def fit_filter(pairs) -> tuple[int, list[dict]]:
    """The cycles of the actual-value average (robot/kukatrace/actual.py): the average of N = 1..10
    cycles puts the runs' setpoints (:func:`simulate_cp`) through, without the following error; N is
    the one whose largest LIN path deviation from the real robot's path is least (fitted on the 5
    LINs), checked on the 3 CIRCs (not fitted). Returns (N, residuals)."""
    table = {n: path_figures(pairs, n, {}) for n in range(1, 11)}
    best = min(table, key=lambda n: worst(table[n], "LIN"))
    print("\n5. actual-value model: the setpoints averaged over N cycles, the largest path deviation (mm)")
    for n, fig in table.items():
        mark = "  <- fitted on the LINs" if n == best else ""
        print(f"   N {n:2}: LIN {worst(fig, 'LIN'):.3f}, CIRC {worst(fig, 'CIRC'):.3f} (not fitted){mark}")
    res = [{"set": "fit: the 5 LINs", "largest_path_deviation_mm": round(worst(table[best], "LIN"), 3),
            "setpoints_alone_mm": round(worst(table[1], "LIN"), 3)},
           {"set": "check: the 3 CIRCs", "largest_path_deviation_mm": round(worst(table[best], "CIRC"), 3),
            "setpoints_alone_mm": round(worst(table[1], "CIRC"), 3)}]
    return best, res


#: the grid of the Coulomb term's smoothing speed v0 (deg/s), chosen by the fit's own residual
COULOMB_SPEEDS = (0.5, 1.0, 2.0, 5.0, 10.0)
#: the shifts (s) tried between a run's motion and the recording's (the measured axes lag START)
LAGS = np.arange(0.0, 0.08, 0.001)


def motion_residuals(pairs, n: int) -> list[dict]:
    """Per LIN and CIRC motion: the measured axes less the runs' setpoints averaged over `n` cycles,
    on the recording's samples from START to the next START, the setpoints shifted by the lag
    (``LAGS``) whose rms over the motion (50 ms off either end) is least; with the averaged
    setpoints' speed and acceleration there (deg, deg/s, deg/s²). Keys: recording, index, kind,
    r, v, a (each (N, 6))."""
    out = []
    for name, _run, a, b in pairs:
        qa = average(a.axes[:, :6], n)
        va = np.gradient(qa, CYCLE, axis=0)
        for k, j in match_motions(a, b)[0]:
            ma, mb = a.motions[k], b.motions[j]
            if ma.kind not in ("LIN", "CIRC"):
                continue
            ia, ib = a.window(*motion_span(a, k)), b.window(*motion_span(b, j))
            ta, tb = a.t[ia] - ma.start, b.t[ib] - mb.start
            best = None
            for lag in LAGS:
                r = np.stack([b.axes[ib, i] - np.interp(tb - lag, ta, qa[ia, i]) for i in range(6)], 1)
                on = (tb - lag > 0.05) & (tb - lag < ta[-1] - 0.05)
                e = float(np.sqrt(np.mean(r[on] ** 2)))
                if best is None or e < best[0]:
                    best = (e, lag, r)
            _e, lag, r = best
            v = np.stack([np.interp(tb - lag, ta, va[ia, i]) for i in range(6)], 1)
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
        p, cost = np.zeros((6, 3)), 0.0
        for i in range(6):
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


def identify_following(pairs, n: int) -> tuple[dict, list[dict]]:
    """6. The drives' following error, identified on the 3 CIRCs and the 5 LINs
    (:func:`fit_following`), then cross-validated: leaving out each LIN recording, and each LIN,
    the left-out LINs measured with the parameters of the rest. Returns (parameters, residuals)."""
    samples = motion_residuals(pairs, n)
    lins = [(s["recording"], s["index"]) for s in samples if s["kind"] == "LIN"]
    before = path_figures(pairs, n, {})
    params, _cost = fit_following(samples)
    full = path_figures(pairs, n, params)
    print("\n6. the drives' following error m q'' + c tanh(q'/v0) + k q' behind the averaged setpoints,")
    print(f"   fitted in axis space on the 3 CIRCs and the 5 LINs: v0 {params['coulomb_speed_deg_s']} deg/s")
    for i in range(6):
        print(f"   A{i + 1}: m {params['inertia_s2'][i]:.3g} s2, c {params['coulomb_deg'][i]:.4f} deg, "
              f"k {1000 * params['viscous_s'][i]:.3f} ms")

    def row(fig):
        return ", ".join(f"{fig[('LIN', *key)]:.3f}" for key in lins)

    print(f"   LINs {row(before)} -> {row(full)}: largest {worst(before, 'LIN'):.3f} -> {worst(full, 'LIN'):.3f} mm; "
          f"CIRC {worst(before, 'CIRC'):.3f} -> {worst(full, 'CIRC'):.3f} mm")
    res = [{"set": "fit: the 3 CIRCs and the 5 LINs", "largest_lin_mm": round(worst(full, "LIN"), 3),
            "largest_circ_mm": round(worst(full, "CIRC"), 3), "without_mm": [round(worst(before, "LIN"), 3),
                                                                              round(worst(before, "CIRC"), 3)]}]
    folds = [(f"leave out {name}", [key for key in lins if key[0] == name]) for name in dict.fromkeys(k[0] for k in lins)]
    folds += [(f"leave out {name} LIN {k}", [(name, k)]) for name, k in lins]
    print("   cross-validation: fitted without the left-out LINs, measured on them (mm; without the model)")
    for label, out in folds:
        p, _ = fit_following([s for s in samples if (s["recording"], s["index"]) not in out])
        fig = path_figures(pairs, n, p)
        got = [round(fig[("LIN", *key)], 3) for key in out]
        was = [round(before[("LIN", *key)], 3) for key in out]
        print(f"   {label}: {', '.join(map(str, got))} ({', '.join(map(str, was))}); CIRC {worst(fig, 'CIRC'):.3f}")
        res.append({"set": f"check: {label}", "left_out_lin_mm": got, "without_mm": was,
                    "largest_circ_mm": round(worst(fig, "CIRC"), 3)})
    return params, res


def _decimal(x: float) -> str:
    """`x` in fixed point (YAML 1.1 reads an exponent without a point, "5e-05", as a string)."""
    text = f"{x:.9f}".rstrip("0")
    return text + "0" if text.endswith(".") else text


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--traces", type=Path, default=TRACES)
    ap.add_argument("--write", action="store_true", help="write robot/data/identified/kr3_r540.yaml")
    args = ap.parse_args(argv)
    if not (args.traces / "MAP.csv").exists():
        print(f"no recordings at {args.traces} (MAP.csv)", file=sys.stderr)
        return 2
    base = load_mada(ROBOT)
    recs = list(real_recordings(args.traces))
    print(f"{len(recs)} real recordings of the training half, robot {base.name}")

    # 1. controller timing
    n = bad_end = bad_restart = 0
    lags, pauses = [], []
    for _row, rec, ov in recs:
        for a, b in zip(rec.motions, rec.motions[1:] + [None]):
            n += 1
            t_f = a.start + (a.endtime - a.start) / ov
            bad_end += abs(a.end - end_signal(t_f, CYCLE)) > 1e-6
            if b is not None and b.start - a.end < 1.0:
                bad_restart += abs(b.start - a.end - RESTART_CYCLES * CYCLE) > 1e-6
                pauses.append(b.start - t_f)
            i0 = int(np.argmin(np.abs(rec.t - a.start)))
            moved = np.flatnonzero(np.max(np.abs(rec.axes[i0:] - rec.axes[i0]), axis=1) > 0.01)
            if len(moved):
                lags.append(rec.t[i0 + moved[0]] - a.start)
    print("\n1. controller timing (robot/exactstop.py)")
    print(f"   END = (floor(t_f / 12 ms) + {END_DELAY_CYCLES}) x 12 ms: {n - bad_end} of {n} motions, {bad_end} exceptions")
    print(f"   next START = END + {RESTART_CYCLES} cycles ({RESTART_CYCLES * 12} ms): {len(pauses) - bad_restart} of "
          f"{len(pauses)} consecutive motions, {bad_restart} exceptions")
    pa = 1000 * np.array(pauses)
    print(f"   exact-stop pause (START - end of interpolation): median {np.median(pa):.1f} ms, "
          f"mean {pa.mean():.1f} ms, {pa.min():.0f}..{pa.max():.0f} ms (n {len(pa)})")
    la = 1000 * np.array(lags)
    print(f"   start lag (first measured move > 0.01 deg after START): {la.min():.0f}..{la.max():.0f} ms, "
          f"median {np.median(la):.0f} ms (n {len(la)}; not simulated: the trace's poses are setpoints)")

    # 2. axis speeds
    mots = ptp_motions(recs)
    print("\n2. axis speeds: cruise at 10 % $VEL_AXIS / (0.10 x override), against the data sheet's")
    sheet = [j.max_speed_deg_s for j in base.joints]
    for i in range(6):
        vals = []
        for _row, rec, ov in recs:
            if rec.name != f"A{i + 1}_PTP_10_po85":
                continue
            for m in rec.motions[1:]:
                sel = (rec.t > m.start) & (rec.t < m.end)
                v = np.abs(np.gradient(rec.axes[sel, i], rec.t[sel]))
                vals.append(float(np.median(v[v > 0.5 * v.max()])) / (0.10 * ov))
        print(f"   A{i + 1}: {np.mean(vals):7.1f} deg/s measured ({len(vals)} moves), data sheet {sheet[i]:.0f}")

    # 3. PTP accelerations, ramp distances and friction
    def acc_pct(m) -> float:
        return m["acc"][int(np.argmax(np.abs(m["dq"])))]

    train = [m for m in mots if single_axis(m) and (m["program"] == "PTP_vel_test" or acc_pct(m) in (10.0, 100.0))]
    check_acc = [m for m in mots if m["program"] == "PTP_acc_test" and single_axis(m) and acc_pct(m) in (50.0, 70.0)]
    check_multi = [m for m in mots if not single_axis(m)]

    acc, ramp, fric = fit_axes(base, train)
    fitted = with_params(base, acc, ramp, fric)
    dyn = None
    if (MESHES / "link_1.stl").exists():
        dyn, fitted = fit_dynamics(fitted, mots, train, MESHES)
    slopes = friction_slopes(recs)
    print("\n3. PTP: fitted on the single-axis PTPs of the velocity runs and of the acceleration runs at 10 % and")
    print("   100 % $ACC_AXIS; checked on those at 50 % and 70 % (other recordings) and on the multi-axis PTPs")
    print("   axis   A_i (deg/s2)   R_i (deg)   c_i (1/s)   c from the samples' a(v) at 10 % (1/s, check)")
    for i in range(6):
        sl = ", ".join(f"{x:.2f}" for x in slopes.get(i, []))
        print(f"   A{i + 1}   {acc[i]:12.0f}   {ramp[i]:9.2f}   {fric[i]:9.2f}   {sl}")
    results = {}
    fit_multi = [m for m in check_multi if m["program"] == "PTP_vel_test"]
    check_multi = [m for m in check_multi if m["program"] != "PTP_vel_test"]
    if dyn is not None:
        print("   rotor inertias (kg m2) " + ", ".join(f"{r:.4g}" for r in dyn["rotor_inertia_kg_m2"])
              + "; torques (N m) " + ", ".join(f"{t:.3g}" for t in dyn["torque_nm"]))
    for label, sel in (("fit: single axis, velocity runs and acceleration runs at 10 and 100 %", train),
                       ("fit: velocity runs, multi-axis (rotor inertias)", fit_multi),
                       ("check: acceleration runs at 50 and 70 %, single axis", check_acc),
                       ("check: multi-axis PTPs of the acceleration and LIN runs", check_multi)):
        ep, et = errors(fitted, sel)
        results[label] = (ep, et)
        print(f"   {label}: planned duration {figures(ep)}; motion time {figures(et)}")

    # 4. CP
    print("\n4. CP: planned duration against d/v + v/a (2 sqrt(d/a) below the speed), $VEL.CP/$ACC.CP of PROG.TXT")
    for _row, rec, _ov in recs:
        prev = dict(zip("xyz", rec.tcp[int(np.argmin(np.abs(rec.t - rec.motions[0].start))), :3]))
        for m in rec.motions:
            if m.kind in ("LIN", "CIRC") and prev is not None:
                a = np.array([prev[c] for c in "xyz"])
                b = np.array([m.point[c] for c in "xyz"])
                if m.kind == "LIN":
                    d = float(np.linalg.norm(b - a))
                else:
                    # a CIRC of CA 360 ends where it started: PROG.TXT's point does not give the
                    # circle; its length is that of the measured TCP path from START to the next
                    sel = (rec.t >= m.start) & (rec.t <= rec.t[-1])
                    d = float(np.sum(np.linalg.norm(np.diff(rec.tcp[sel, :3], axis=0), axis=1)))
                v, acc_cp = m.velocities["cp"], m.accelerations["cp"]
                t = d / v + v / acc_cp if d >= v * v / acc_cp else 2 * math.sqrt(d / acc_cp)
                print(f"   {rec.name:16} {m.kind:4} line {m.line}: d {d:7.1f} mm, planned {m.endtime - m.start:.4f} s, "
                      f"model {t:.4f} s ({1000 * (t - (m.endtime - m.start)):+.1f} ms)")
            prev = m.point

    # 5. the actual-value model, 6. the following error
    pairs = simulate_cp(args.traces, fitted)
    cycles, path_res = fit_filter(pairs)
    following, follow_res = identify_following(pairs, cycles)

    if args.write:
        out = IDENTIFIED / "kr3_r540.yaml"
        out.parent.mkdir(parents=True, exist_ok=True)
        lines = ["# The KR 3 R540's PTP parameters identified from its real KUKA Trace recordings (issue 60).",
                 f"# Written by `python tools/identify_kr3.py --write` on {date.today().isoformat()}: do not edit",
                 "# by hand. Method: that script's docstring; robot/identified.py applies them to kr3_r540.dat.",
                 "ptp:",
                 "  # axis accelerations at 100 % $ACC_AXIS, deg/s2",
                 f"  acc_deg_s2: [{', '.join(f'{a:.0f}' for a in acc)}]",
                 "  # at reduced $VEL_AXIS a PTP ramps over at least this distance, deg",
                 f"  ramp_deg: [{', '.join(f'{r:.3f}' for r in ramp)}]",
                 "  # the acceleration an axis loses per deg/s of its speed (gains braking), 1/s",
                 f"  friction_per_s: [{', '.join(f'{c:.3f}' for c in fric)}]",
                 "  residuals:"]
        for label, (ep, et) in results.items():
            lines.append("    - " + json.dumps({"set": label, "planned_duration": figures(ep), "motion_time": figures(et)}))
        if dyn is not None:
            lines += ["dynamics:", "  # links 1..6 from kuka_experimental's kr3r540 collision meshes (uniform density; the",
                      "  # rotor inertias and the torques are identified against their ratios), robot/dynamics.py"]
            lines += [f"  {k}: {json.dumps(v)}" for k, v in dyn.items()]
        lines += ["actual:", "  # the setpoints are averaged over this many IPO cycles (in axis space) before the",
                  "  # measured axes follow them (robot/kukatrace/actual.py)", f"  filter_cycles: {cycles}",
                  "  residuals:"]
        lines += ["    - " + json.dumps(r) for r in path_res]
        lines += ["  # the drives' following error behind the averaged setpoints, per axis deg:",
                  "  # m q'' + c tanh(q'/v0) + k q' (robot/kukatrace/actual.py following_error)",
                  "  following_error:"]
        lines += [f"    {k}: [{', '.join(map(_decimal, v))}]" if isinstance(v, list) else f"    {k}: {v}"
                  for k, v in following.items()]
        lines += ["    residuals:"] + ["      - " + json.dumps(r) for r in follow_res]
        out.write_text("\n".join(lines) + "\n", encoding="utf-8")
        print(f"\nwrote {out.relative_to(HERE)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
