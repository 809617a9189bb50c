"""The simulator against the real KR 3 R540 (issue 60): interp/tracebench.py runs every program of
the training half of ../shared/real-traces and compares it with the real recordings, beside
OfficeLite's recordings of the same programs.

The limits are the issue's (what OfficeLite reached against the real robot on the held-out half):
motion time |error| median <= 1.5 %, p90 <= 5 %, max <= 10 %; the exact-stop pause within 12 ms of the
real one; the largest LIN path deviation <= 0.28 mm, CIRC <= 1.48 mm. On the recordings OfficeLite
also has, the simulator's path deviations are no worse than OfficeLite's.

``make test`` runs three of the five programs (the acceleration runs, the circles, the LINs: 29 of the
62 recordings, about 2.7 s of CPU); ``make nightly`` all of them (about 3.7 s).

**A fit is not a model (issue 73).** ``make nightly`` also runs ``interp.tracebench.cross``: the
parameters identified once per program with that program left out, each program predicted
(robot/kukatrace/identify.py; several minutes of CPU). Its limits are what the model reaches, not
all of the issue's (``CROSS_LIMITS``, each with the issue's beside it). ``make test`` checks the step
of it that carries the payload: the drives' torque limits and the links' masses identified from the
0.661 kg recordings (PTP_vel_test, at 85 % override) predict what the 3 kg recordings (PTP_away, at
100 %: their commanded torques are the limits themselves) show.
"""

from __future__ import annotations

import pytest

import numpy as np

from interp.tracebench import (LIMITS, MESHES, ROBOT, ROBOT_LIBRARY, bench, cross, figures, map_rows,
                               pose_motion_time, real_recordings, rows_summary, settled_floor, settled_split,
                               summary)
from robot.dynamics import ArmDynamics
from robot.kukatrace.compare import MotionComparison
from robot.kukatrace.identify import _rest_samples, bare, dynamic_model, link_inertials, torque_limits
from robot.kukatrace.model import Motion, Segment
from robot.mada import load_mada

SAMPLE = ("PTP_acc_test", "Circular", "movement_test_lin")


@pytest.fixture(scope="module")
def fig(real_traces):
    rows = [r for program in SAMPLE for r in bench(real_traces, only=program)]
    assert len(rows) == 24 + 3 + 2               # their recordings of the training half (MAP.csv)
    return figures(rows)


@pytest.mark.slow
def test_every_recording_within_the_issues_limits(real_traces):
    rows = bench(real_traces)
    assert len(rows) == len(map_rows(real_traces))        # every recording of the training half (MAP.csv)
    f = figures(rows)
    assert f["sim"]["motions"] == _recorded_motions(real_traces)      # every real motion matched
    _within_limits(f["sim"])
    assert f["sim"]["circ_mm"] <= LIMITS["circ_mm"]
    # issue 88: the motion time from the poses no worse than OfficeLite's on its motions at the p90
    # and the max (2026-11-28: 5.44 / 10.26 % against 6.44 / 20.00 %; the median 0.96 against 0.82)
    for key in ("settled_p90_pct", "settled_max_pct"):
        assert f["sim_on_officelite_set"][key] <= f["officelite"][key], key


def _recorded_motions(real_traces, program: str | None = None) -> int:
    """The real motions of the training half (of `program`), as MAP.csv's ``n_motions`` counts them."""
    return sum(int(r["n_motions"]) for r in map_rows(real_traces) if program in (None, r["program"]))


def _within_limits(s):
    assert s["time_median_pct"] <= LIMITS["time_median_pct"]
    assert s["time_p90_pct"] <= LIMITS["time_p90_pct"]
    assert s["time_max_pct"] <= LIMITS["time_max_pct"]
    assert abs(s["pause_run_s"] - s["pause_real_s"]) <= LIMITS["pause_s"]


def test_motion_times_and_pause_within_the_issues_limits(fig):
    s = fig["sim"]
    assert s["motions"] == 72 + 3 + 7             # every real motion of the sample matched
    _within_limits(s)


def test_circ_path_within_the_limit_and_no_worse_than_officelite(fig):
    assert fig["sim"]["circ_mm"] <= LIMITS["circ_mm"]
    so, ol = fig["sim_on_officelite_set"], fig["officelite"]
    assert so["circ_mm"] <= ol["circ_mm"]
    assert so["lin_mm"] <= ol["lin_mm"]


def test_lin_path_within_the_issues_limit(fig):
    assert fig["sim"]["lin_mm"] <= LIMITS["lin_mm"]


#: The motion time from the poses (leaving rest -> settled, $IN_POS_MA; issue 73's target median
#: 2 %, p90 6 %) on the sample, what the model reaches (2026-11-28, issue 88: a PTP's setpoints
#: averaged over their own 5 cycles, the CP ones over 4): 0.00 / 5.56 / 7.69 %, 82 motions (1.94 /
#: 5.00 / 11.11 % with every row over 4, 2026-11-27); OfficeLite on its 43 of them 1.47 / 4.17 /
#: 5.56 %, the simulator on those 1.54 / 4.91 / 6.00 %. Every recording: 0.35 / 5.88 / 10.26 %
#: (2.17 / 5.88 / 12.82 % before), OfficeLite's 103 motions 0.82 / 6.44 / 20.00 %, the simulator on
#: those 0.96 / 5.44 / 10.26 % (1.72 / 5.82 / 12.82 % before).
SETTLED_LIMITS = {"settled_median_pct": 0.5, "settled_p90_pct": 5.6, "settled_max_pct": 8.0}


def test_settled_motion_time_beside_the_planned(fig):
    s = fig["sim"]
    assert s["settled_motions"] == 72 + 3 + 7
    for key, lim in SETTLED_LIMITS.items():
        assert s[key] <= lim, key
    assert fig["sim_on_officelite_set"]["settled_median_pct"] <= 2.0      # the issue's, on OL's set


def test_the_model_settles_when_the_robot_does(fig):
    """When the robot has settled after each motion's START (what `krl run`'s summary counts to):
    the real robot's measured axes lag its setpoints by 36-48 ms (../shared/real-traces README,
    "Act" values), so a model without that dead time settles 3-4 IPO cycles early (36 ms median,
    48 ms p90 on the sample before it had one). With the dead time identified on the LINs and CIRCs
    the sample's 72 PTPs, which it was not identified on, are inside, within one 12 ms sample in
    the median and two at the 90th percentile (0 / 12 ms, 2026-11-27)."""
    s = fig["sim"]
    assert s["settled_end_median_ms"] <= 12.0 + 1e-6
    assert s["settled_end_p90_ms"] <= 24.0 + 1e-6


def test_pose_motion_time_by_hand():
    """A1 leaves its 0.1° window around the START pose at the third sample (0.15° away) and stays
    within 0.1° of the end pose from the seventh (0.05° short, then there): 4 samples of 12 ms."""
    t = 0.012 * np.arange(10)
    a1 = np.array([0.0, 0.05, 0.15, 1.0, 5.0, 9.8, 9.95, 10.0, 10.0, 10.0])
    axes = np.zeros((10, 6))
    axes[:, 0] = a1
    window = np.array([0.1, 0.1, 0.1, 0.5, 0.5, 0.5])
    assert pose_motion_time(t, axes, 0.0, t[-1], window) == pytest.approx(0.048)
    assert pose_motion_time(t, np.zeros((10, 6)), 0.0, t[-1], window) is None       # never left rest


def _one_ptp(a1: list[float], reached: float | None) -> Segment:
    """A segment of one PTP of A1 from START 0 over the samples `a1` (deg, one per 12 ms cycle)."""
    t = 0.012 * np.arange(len(a1))
    axes = np.zeros((len(a1), 6))
    axes[:, 0] = a1
    return Segment("s", "", 0.0, float(t[-1]), [Motion("PTP", 1, "f", 0.0, end=reached, reached=reached)], t, axes)


def test_settled_error_split_into_the_plans_and_the_drives_part_by_hand():
    """Issue 88: the run leaves A1's 0.1° window at 24 ms and is within 0.1° of its end from 72 ms
    (48 ms); the recording at 12 and 48 ms (36 ms): settled +12 ms. With the run's interpolation
    ending at 60 ms and the recording's planned end at 48 ms the plan is 12 ms longer: the plan's part
    12/36 = 33.3 %, the drive's 0 ms; with both planned ends at 60 ms the plan's part is 0 and the
    drive's +12 ms; a motion without a planned end is left out."""
    run = [0.0, 0.0, 0.5, 3.0, 7.0, 9.5, 10.0, 10.0, 10.0, 10.0]
    rec = [0.0, 0.5, 3.0, 7.0, 9.95, 10.0, 10.0, 10.0, 10.0, 10.0]
    m = [MotionComparison(0, 0, "PTP", 1, 1, 0.0, 0.0, None, None, None, None, None, None, None)]
    window = np.array([0.1, 0.1, 0.1, 0.5, 0.5, 0.5])
    a = _one_ptp(run, 0.060)
    plan, drive = settled_split(a, _one_ptp(rec, 0.048), m, a.axes, window)
    assert plan == [pytest.approx(100.0 * 12 / 36)] and drive == [pytest.approx(0.0, abs=1e-9)]
    plan, drive = settled_split(a, _one_ptp(rec, 0.060), m, a.axes, window)
    assert plan == [pytest.approx(0.0, abs=1e-9)] and drive == [pytest.approx(12.0)]
    assert settled_split(a, _one_ptp(rec, None), m, a.axes, window) == ([], [])
    got = summary([], plan_part=[33.3, -10.0, 0.0], drive_part=[12.0, -24.0, 0.0])
    assert got["plan_part_median_pct"] == pytest.approx(10.0) and got["plan_part_max_pct"] == pytest.approx(33.3)
    assert got["drive_part_median_ms"] == pytest.approx(0.0)



def test_settled_floor_moves_the_real_settled_sample_by_the_plan_by_hand():
    """Issue 88: the floor of the settled error, what a drive settling exactly as the real one would
    give with the run's plan. The recording leaves A1's window at 12 ms and settles from 48 ms (36 ms);
    its crossing lies in the sample before, taken at its middle (42 ms). A plan 12 ms longer moves it
    to 54 ms, settled from the 60 ms sample: +12/36 = +33.3 %; 7 ms longer: 49 ms, the 60 ms sample,
    +33.3 %; 5 ms longer: 47 ms, still the 48 ms sample, 0 %; 7 ms shorter: 35 ms, the 36 ms sample,
    -33.3 %; the same plan: 0 %; a motion without a planned end is left out."""
    rec = [0.0, 0.5, 3.0, 7.0, 9.95, 10.0, 10.0, 10.0, 10.0, 10.0]
    m = [MotionComparison(0, 0, "PTP", 1, 1, 0.0, 0.0, None, None, None, None, None, None, None)]
    window = np.array([0.1, 0.1, 0.1, 0.5, 0.5, 0.5])
    b = _one_ptp(rec, 0.048)
    for reached, want in ((0.060, 100 / 3), (0.055, 100 / 3), (0.053, 0.0), (0.041, -100 / 3), (0.048, 0.0)):
        a = _one_ptp(rec, reached)
        assert settled_floor(a, b, m, window, 0.012) == [pytest.approx(want, abs=1e-9)], reached
    assert settled_floor(_one_ptp(rec, None), b, m, window, 0.012) == []
    got = summary([], floor_part=[33.3, -10.0, 0.0])
    assert got["floor_median_pct"] == pytest.approx(10.0) and got["floor_max_pct"] == pytest.approx(33.3)

#: What the cross-validation reaches (2026-11-27, `python -m interp.tracebench --cross`), held as its
#: limits, with issue 73's targets: over every program left out in turn, motion time |error|
#: median 0.00 % (issue: 1.5, met), p90 6.32 % (issue: 5, not met), max 11.34 % (issue: 10, not
#: met). It was 7.37 / 65.0 % while a ramp distance could be fitted on runs that do not show one
#: (with PTP_vel_test left out, A3's came from PTP_away's 3 kg runs, 11.5 deg, and its 10 % runs
#: were 57-65 % off; robot/kukatrace/identify.py ``ramp_shown`` now fits none there). What is left
#: is that fold's 10 % runs without any ramp distance (A6 -11.3 %, the A3 30 deg run -9 %): no other
#: program has a reduced-speed run that shows one; and PTP_acc_test's 10 % $ACC_AXIS wrist runs (A5
#: -10.2 %, A4 -7.0 %), the only runs that show the speed-dependent acceleration (docs/robot.md "Why
#: the held-out p90 and max are missed", checked per motion again on 2026-11-27: the same figures,
#: no model change reaches them). The pause 91 ms (real 90, issue: within 12 ms),
#: LIN 0.269 mm (0.28), CIRC 0.965 mm (1.48) meet the issue's. PTP_away (3 kg) predicted from the
#: 0.661 kg recordings: median 0.00 %, p90 5.56 %, max 6.67 % (issue: 1.5, 5, 10). Fitted on every
#: program: 0.00, 3.85, 6.67 %. With PTP_away's 10 % runs (2026-11-28, 178 motions, issue 88): 0.00 /
#: 6.25 / 11.34 %; PTP_away left out 0.00 / 5.47 / 6.67 % (9.68 % with every moving axis' ramp bound);
#: fitted 0.00 / 4.00 / 6.67 %. With the shortest ramp time shown for an axis without one (issue 88,
#: robot/kukatrace/identify.py ``ramp_fallback``; 2026-11-28): 0.00 / 5.98 / 11.34 -> 0.00 / 5.67 /
#: 10.17 % (PTP_vel_test left out 6.33 / 11.34 -> 5.67 / 10.08 %; the max is now PTP_acc_test's A5 at
#: 10 % $ACC_AXIS), fitted the same. With the short-ramp law (issue 88, robot/planner.py
#: ``short_ramp_scale``, replacing the ramp distances; 2026-11-28): 0.00 / 4.05 / 10.17 % (PTP_vel_test
#: left out 0.00 / 3.22 / 4.00 %; the max PTP_acc_test's A5 at 10 % $ACC_AXIS), fitted 0.00 / 3.70 / 6.67 %.
#: With the wrist's friction from its drive where no PTP at a reduced $ACC_AXIS shows it (issue 88,
#: robot/kukatrace/identify.py ``drive_friction``; 2026-11-29): 0.00 / 3.85 / 9.26 % (PTP_acc_test left
#: out 0.00 / 5.62 / 10.17 -> 0.00 / 4.51 / 9.26 %, the max its A4 at 10 % $ACC_AXIS), fitted the same.
CROSS_LIMITS = {"time_median_pct": 1.5, "time_p90_pct": 4.5, "time_max_pct": 10.0, "pause_s": 0.012,
                "lin_mm": 0.28, "circ_mm": 1.48}
PTP_AWAY_LIMITS = {"time_median_pct": 1.5, "time_p90_pct": 6.0, "time_max_pct": 10.0}
#: The motion time from the poses (leaving rest -> settled) cross-validated (2026-11-27, with the
#: dead time, each fold's identified on its own LINs and CIRCs): median 3.23 % (issue: 2, not met),
#: p90 7.38 % (issue: 6, not met), max 12.82 % (3.28 / 7.14 / 12.82 % before the dead time, which
#: moves a motion's span ends by a sample; 3.33 / 9.74 / 56.14 % with the ramp fitted on PTP_away);
#: fitted on every program 2.70 / 5.88 / 12.82 %. Held as what the model reaches: the metric counts
#: 12 ms samples, and the actual-value model has not the measured axes' slow last degrees, which no
#: LIN or CIRC identifies (docs/robot.md "Why the settled median is missed", "The dead time"). When
#: the robot has settled after START: |error| median 12 ms, p90 48 ms (the held-out planned times'
#: errors carry over: PTP_vel_test's 10 % runs up to 252 ms); fitted 12 / 23 ms.
#: With PTP_away's 10 % runs (2026-11-28, 178 motions; issue 88's leading-axis ramp bound): 3.23 / 7.53 /
#: 12.82 %, the p90 up by its six new motions (PTP_away left out: 3.52 / 10.50 / 12.82 %). With a PTP's
#: own average (issue 88, 5 cycles in every fold, robot/kukatrace/identify.py ``fit_filter_ptp``):
#: 2.37 / 7.14 / 11.54 % (OfficeLite on its 103 motions 0.82 / 6.44 / 20.00 %, the simulator on those
#: 2.56 / 7.14 / 11.54 %); PTP_away left out 1.17 / 7.26 / 10.26 %; settled after START p90 36 ms.
#: With ``ramp_fallback`` (2026-11-28): 2.19 / 7.14 / 11.54 %. With the short-ramp law (issue 88,
#: 2026-11-28): 1.04 / 6.38 / 11.54 % (on OfficeLite's 103 motions 1.72 / 5.86 / 11.54 %, OfficeLite's
#: own 0.82 / 6.44 / 20.00 %). With the settling lag on A1 (2026-11-28): 0.00 / 5.88 / 11.54 %; with the
#: wrist's friction from its drive (2026-11-29): 0.00 / 5.88 / 10.26 % (on OfficeLite's 103 motions
#: 1.47 / 5.73 / 11.54 -> 1.35 / 5.44 / 10.26 %).
CROSS_SETTLED_LIMITS = {"settled_median_pct": 1.2, "settled_p90_pct": 6.5, "settled_max_pct": 10.3,
                        "settled_end_median_ms": 12.0 + 1e-6}


@pytest.mark.slow
def test_cross_validated_figures(real_traces):
    result = cross(real_traces)
    assert len(result["cross"]) == len(map_rows(real_traces))
    c = rows_summary(result["cross"])
    assert c["motions"] == c["settled_motions"] == _recorded_motions(real_traces)
    for key, lim in CROSS_SETTLED_LIMITS.items():
        assert c[key] <= lim, key
    for key in ("time_median_pct", "time_p90_pct", "time_max_pct", "lin_mm", "circ_mm"):
        assert c[key] <= CROSS_LIMITS[key], key
    assert abs(c["pause_run_s"] - c["pause_real_s"]) <= CROSS_LIMITS["pause_s"]
    away = summary([m for r in result["cross"] if r.program == "PTP_away" for m in r.sim])
    assert away["motions"] == _recorded_motions(real_traces, "PTP_away")
    for key, lim in PTP_AWAY_LIMITS.items():
        assert away[key] <= lim, key
    f = summary([m for r in result["fitted"] for m in r.sim])
    _within_limits(f)


def test_the_light_loads_torques_predict_the_rated_loads(real_traces):
    base = bare(load_mada(ROBOT_LIBRARY / f"{ROBOT}.dat"))
    if not (MESHES / "link_1.stl").exists():
        pytest.skip("the KR 3 R540's meshes (../shared/robots) are not present")
    light = real_recordings(real_traces, {"PTP_vel_test"})     # 0.661 kg, 85 % override
    heavy = real_recordings(real_traces, {"PTP_away"})         # 3 kg, 100 %
    dyn, measured, _ = dynamic_model(base, link_inertials(MESHES), light, None)
    assert measured == {1, 2}                                  # A2 and A3 have torque channels
    arm = ArmDynamics(base, dyn)
    # at 100 % override the commanded torques are the planned ones: their largest is the limit
    seen = torque_limits(arm, heavy)
    for i in (1, 2):
        assert dyn["torque_nm"][i] == pytest.approx(seen[i], rel=0.05)
    # the 3 kg payload's gravity at rest, from the masses identified with 0.661 kg
    err = []
    for q, tau, load in _rest_samples(heavy):
        arm.set_load(load, None)
        g = arm.gravity(q)
        err += [t - g[i] for i, t in tau.items()]
    assert float(np.sqrt(np.mean(np.square(err)))) < 4.0      # N m, against 20..45 N m held
