"""Identify the KR 3 R540's motion parameters and the KR C4's timing from the real KUKA Trace
recordings of ../shared/real-traces (issues 60 and 73). Anyone can rerun it; it reads the recordings in
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
3. *The dynamic model and the PTP parameters* (robot/kukatrace/identify.py ``identify``, which
   ``python -m interp.tracebench --cross`` runs once per program left out; issue 73): the links'
   masses scaled to the commanded gear torques of A2/A3 at rest, the torque limits of A2/A3 from
   those torques in motion with the override undone, the accelerations ``A_i`` and friction
   ``c_i`` by least squares of log(planned duration) over the single-axis PTPs at 100 %
   ``$VEL_AXIS`` (of the velocity runs, the acceleration runs at 10 % and 100 % ``$ACC_AXIS`` and
   PTP_away's), planned with the dynamic model and each motion's LOAD; A1's torque from ``A_1``;
   then the short-ramp law of a synchronised PTP at a reduced speed (``fit_short_ramp``, issue 88:
   K and θ for every axis) on every PTP, ``A_i`` and ``c_i`` again on every single-axis run under
   it, the rotor inertias on the multi-axis PTPs of the velocity runs and the law once more.
   **Checked** on the PTPs not
   fitted (the acceleration runs at 50 and 70 %, the other multi-axis PTPs). Issue 60's CP check
   (LIN/CIRC durations against ``d/v + v/a``) and the friction's check on the measured a(v) are
   no longer printed: their figures stand in docs/robot.md.
5. *Actual-value average* (robot/kukatrace/actual.py): the LIN and CIRC programs run on the robot
   identified above; N cycles of the average the one whose largest LIN path deviation is least.
6. *Following error* (robot/kukatrace/actual.py ``following_error``): per axis ``m q'' + c
   tanh(q'/v0) + k q'`` behind the averaged setpoints, least squares in axis space of the measured
   axes less the averaged setpoints (shifted by each motion's best lag) over the 3 CIRCs and the 5
   LINs; cross-validated by program with ``python -m interp.tracebench --cross``. Beside it the
   friction ``k/m`` of the drives whose Coulomb term ``c`` > 0 (robot/kukatrace/identify.py
   ``drive_friction``): what an axis without a PTP at a reduced ``$ACC_AXIS`` is planned with
   (step 3 again; with every program here each axis has one, so it is printed, not used).
7. *Dead time* (robot/kukatrace/identify.py ``fit_dead_time``): per LIN and CIRC, how much later
   after START the measured axes leave their ``$IN_POS_MA`` window than the model of steps 5-6;
   the median over the 8 motions, in whole IPO cycles.
8. *A PTP's average* (robot/kukatrace/identify.py ``fit_filter_ptp``; issue 88): the cycles a
   PTP's setpoints are averaged over (KSS's ``$DEF_FLT_PTP`` beside ``$DEF_FLT_CP``), from the CP
   average up by 0..6, the count whose motion times from the poses (leaving rest -> settled in
   ``$IN_POS_MA``) of the exact-stop PTPs are off by the least mean |error|.
9. *A settling lag on A1* (robot/kukatrace/identify.py ``fit_settle_lag``; issue 88): a first-order
   lag of A1's actual value while it brakes below a speed, τ a factor times A1's inertia at the
   motion's end pose with its LOAD (robot/settlelag.py); of a grid of speeds and factors, the one
   whose motion times from the poses of the exact-stop PTPs are off by the least mean |error|
   among those that keep the largest LIN and CIRC path deviation as without it.
"""

from __future__ import annotations

import argparse
import json
import sys
from datetime import date
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(HERE))

from interp import tracebench as B  # noqa: E402
from robot.exactstop import END_DELAY_CYCLES, RESTART_CYCLES, end_signal  # noqa: E402
from robot.identified import IDENTIFIED  # noqa: E402
from robot.kukatrace.identify import drive_friction, figures, path_figures, worst  # noqa: E402
from robot.kukatrace.recording import IPO_CYCLE_S  # noqa: E402
from robot.mada import load_mada  # noqa: E402
from robot.machine import ROBOT_LIBRARY  # noqa: E402

TRACES = HERE.parent / "shared" / "real-traces"
ROBOT = ROBOT_LIBRARY / "kr3_r540.dat"
CYCLE = IPO_CYCLE_S


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
    recs = B.real_recordings(args.traces)
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
    print("\n2. axis speeds: cruise at 10 % $VEL_AXIS / (0.10 x override), against the data sheet's")
    sheet = [j.max_speed_deg_s for j in base.joints]
    for i in range(len(base.joints)):
        vals = []
        for _row, rec, ov in recs:
            if rec.name != f"A{i + 1}_PTP_10_po85":
                continue
            for m in rec.motions[1:]:
                sel = (rec.t > m.start) & (rec.t < m.end)
                v = np.abs(np.gradient(rec.axes[sel, i], rec.t[sel]))
                vals.append(float(np.median(v[v > 0.5 * v.max()])) / (0.10 * ov))
        print(f"   A{i + 1}: {np.mean(vals):7.1f} deg/s measured ({len(vals)} moves), data sheet {sheet[i]:.0f}")

    # 3.-6. the dynamic model, the PTP parameters, the actual-value model (robot/kukatrace/identify.py)
    got = B.identified(args.traces, {row["program"] for row, _rec, _ov in recs}, rated_kg=B.RATED_PAYLOAD_KG)
    dyn, ptp, res = got.params["dynamics"], got.params["ptp"], got.residuals
    print("\n3. dynamic model: link masses scaled to the commanded gear torques of A2/A3 at rest "
          f"(scales {res['scales']}, n {res['n']}, rms {res['rms_nm']:.2f} N m, max {res['max_nm']:.2f} N m); "
          f"torque limits {res['torque_limits_nm']} N m")
    print("   rotor inertias (kg m2) " + ", ".join(f"{r:.4g}" for r in dyn["rotor_inertia_kg_m2"])
          + "; torques (N m) " + ", ".join("-" if t is None else f"{t:.4g}" for t in dyn["torque_nm"]))
    print("   axis   A_i (deg/s2)   R_i (deg)   c_i (1/s)")
    for i in range(len(base.joints)):
        print(f"   A{i + 1}   {ptp['acc_deg_s2'][i]:12.0f}   {ptp['ramp_deg'][i]:9.2f}   {ptp['friction_per_s'][i]:9.2f}")
    law = res.get("short_ramp") or {}
    print(f"   the short-ramp law (robot/kukatrace/identify.py fit_short_ramp): a PTP at a reduced $VEL_AXIS whose "
          f"axes would ramp in t < {1000 * ptp['short_ramp_below_s']:.1f} ms ramps in K / t, K {1e6 * ptp['short_ramp_s2']:.1f} "
          f"ms² ({law.get('under_law', 0)} of the {law.get('n', 0)} PTPs at a reduced $VEL_AXIS with t < 30 ms under it)")
    results = {k: v for k, v in res.items() if k.startswith(("fit:", "check:"))}
    for label, (ep, et) in results.items():
        print(f"   {label}: planned duration {figures(ep)}; motion time {figures(et)}")
    cycles, table, pairs = res["actual"]
    print("\n5. actual-value model: the setpoints averaged over N cycles, the largest path deviation (mm)")
    for n, fig in table.items():
        mark = "  <- fitted on the LINs" if n == cycles else ""
        print(f"   N {n:2}: LIN {worst(fig, 'LIN'):.3f}, CIRC {worst(fig, 'CIRC'):.3f} (not fitted){mark}")
    path_res = [{"set": "fit: the 5 LINs", "largest_path_deviation_mm": round(worst(table[cycles], "LIN"), 3),
                 "setpoints_alone_mm": round(worst(table[1], "LIN"), 3)},
                {"set": "check: the 3 CIRCs", "largest_path_deviation_mm": round(worst(table[cycles], "CIRC"), 3),
                 "setpoints_alone_mm": round(worst(table[1], "CIRC"), 3)}]
    following = got.params["actual"]["following_error"]
    full = path_figures(pairs, cycles, following)
    print("\n6. the drives' following error m q'' + c tanh(q'/v0) + k q' behind the averaged setpoints,")
    print(f"   fitted in axis space on the 3 CIRCs and the 5 LINs: v0 {following['coulomb_speed_deg_s']} deg/s; "
          f"LIN {worst(table[cycles], 'LIN'):.3f} -> {worst(full, 'LIN'):.3f} mm, "
          f"CIRC {worst(table[cycles], 'CIRC'):.3f} -> {worst(full, 'CIRC'):.3f} mm "
          "(cross-validated by program: python -m interp.tracebench --cross)")
    drive = drive_friction(following)
    print("   the drives' friction k/m where a Coulomb term shows one (robot/kukatrace/identify.py drive_friction; "
          "taken only for an axis without a PTP at a reduced $ACC_AXIS): "
          + ", ".join(f"A{i + 1} {drive[i]:.2f} (fitted {got.params['ptp']['friction_per_s'][i]:.2f})"
                      for i in range(len(drive)) if drive[i] > 0) + " 1/s")
    follow_res = [{"set": "fit: the 3 CIRCs and the 5 LINs", "largest_lin_mm": round(worst(full, "LIN"), 3),
                   "largest_circ_mm": round(worst(full, "CIRC"), 3),
                   "without_mm": [round(worst(table[cycles], "LIN"), 3), round(worst(table[cycles], "CIRC"), 3)]}]
    dead, delays = got.params["actual"]["dead_time_cycles"], res["dead_time"]
    print(f"\n7. dead time: the measured axes leave rest later than the model by {sorted(round(d * 1000) for d in delays)} ms "
          f"(LINs and CIRCs): median {dead} IPO cycles")
    dead_res = [{"set": "fit: the 3 CIRCs and the 5 LINs", "departure_delays_ms": sorted(round(d * 1000) for d in delays)}]
    n_ptp, ptp_costs = got.params["actual"]["filter_cycles_ptp"], res["filter_ptp"]
    print(f"\n8. a PTP's average: {n_ptp} IPO cycles (the exact-stop PTPs' motion time from the poses, mean |error| "
          + ", ".join(f"{k}: {v:.2f} %" for k, v in ptp_costs.items()) + ")")
    lag, lag_costs = got.params["actual"]["settle_lag"], res["settle_lag"]
    tried = {k: v for k, v in lag_costs.items() if k != "path_mm"}
    print(f"\n9. a settling lag on A1: {lag} (the exact-stop PTPs' motion time from the poses, mean |error| "
          + ", ".join(f"{k}: {v:.2f} %" for k, v in tried.items()) + "; the others move a LIN's or CIRC's path)")
    acc, ramp, fric = ptp["acc_deg_s2"], ptp["ramp_deg"], ptp["friction_per_s"]

    if args.write:
        out = IDENTIFIED / "kr3_r540.yaml"
        out.parent.mkdir(parents=True, exist_ok=True)
        lines = ["# The KR 3 R540's PTP parameters identified from its real KUKA Trace recordings (issue 60).",
                 f"# Written by `python tools/identify_kr3.py --write` on {date.today().isoformat()}: do not edit",
                 "# by hand. Method: that script's docstring; robot/identified.py applies them to kr3_r540.dat.",
                 "ptp:",
                 "  # axis accelerations at 100 % $ACC_AXIS, deg/s2",
                 f"  acc_deg_s2: [{', '.join(f'{a:.0f}' for a in acc)}]",
                 "  # at reduced $VEL_AXIS a PTP ramps over at least this distance, deg (0: none; the law below)",
                 f"  ramp_deg: [{', '.join(f'{r:.3f}' for r in ramp)}]",
                 "  # the short-ramp law: a PTP at a reduced $VEL_AXIS whose axes would ramp to its speed in",
                 "  # t < short_ramp_below_s (s, at 100 % override) ramps in short_ramp_s2 / t instead",
                 "  # (robot/planner.py short_ramp_scale)",
                 f"  short_ramp_s2: {ptp['short_ramp_s2']:.4e}",
                 f"  short_ramp_below_s: {ptp['short_ramp_below_s']:.5f}",
                 "  # the acceleration an axis loses per deg/s of its speed (gains braking), 1/s",
                 f"  friction_per_s: [{', '.join(f'{c:.3f}' for c in fric)}]",
                 "  residuals:"]
        for label, (ep, et) in results.items():
            lines.append("    - " + json.dumps({"set": label, "planned_duration": figures(ep), "motion_time": figures(et)}))
        if dyn is not None:
            lines += ["dynamics:", "  # links 1..6 from kuka_experimental's kr3r540 collision meshes, masses scaled to the",
                      "  # commanded gear torques of A2/A3 at rest; torque limits of A2/A3 from those torques in motion,",
                      "  # A1's from its acceleration, the wrist's none (capped by their acceleration); rotor inertias",
                      "  # from the multi-axis PTPs; rated payload: the load PTP_away's recordings show for TOOL 0",
                      "  # (robot/kukatrace/identify.py, robot/dynamics.py)"]
            lines += [f"  {k}: {json.dumps(v)}" for k, v in dyn.items()]
            lines += [f"  residuals: {json.dumps({'gravity_at_rest': {k: res[k] for k in ('n', 'rms_nm', 'max_nm', 'scales')}})}"]
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
        lines += ["  # the measured axes lag that model by this many IPO cycles: the median delay with which they",
                  "  # leave rest after START on the LINs and CIRCs (robot/kukatrace/identify.py fit_dead_time)",
                  f"  dead_time_cycles: {dead}", "  dead_time_residuals:"]
        lines += ["    - " + json.dumps(r) for r in dead_res]
        lines += ["  # a PTP's setpoints are averaged over this many IPO cycles (the controller's PTP filter beside",
                  "  # its CP one): the count whose motion times from the poses (leaving rest -> settled in",
                  "  # $IN_POS_MA) of the exact-stop PTPs come closest (robot/kukatrace/identify.py fit_filter_ptp)",
                  f"  filter_cycles_ptp: {n_ptp}", "  filter_cycles_ptp_residuals:",
                  "    - " + json.dumps({"set": "fit: the exact-stop PTPs", "mean_abs_error_pct_by_cycles":
                                         {str(k): round(v, 2) for k, v in ptp_costs.items()}})]
        if lag:
            lines += ["  # A1's actual value lags by tau = cycles_per_kg_m2 x A1's inertia at the motion's end pose",
                      "  # (with its LOAD) x the IPO cycle while it brakes below below_deg_s: the lag whose motion",
                      "  # times from the poses of the exact-stop PTPs come closest with the CP paths held",
                      "  # (robot/kukatrace/identify.py fit_settle_lag, robot/settlelag.py)",
                      f"  settle_lag: {json.dumps(lag)}", "  settle_lag_residuals:",
                      "    - " + json.dumps({"set": "fit: the exact-stop PTPs", "mean_abs_error_pct_by_speed_and_factor":
                                             {(k if isinstance(k, str) else f"{k[0]:g} deg/s x {k[1]:g}"): round(v, 3)
                                              for k, v in tried.items()}})]
        out.write_text("\n".join(lines) + "\n", encoding="utf-8")
        print(f"\nwrote {out.relative_to(HERE)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
