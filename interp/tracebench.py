"""The simulator against the real KR 3 R540, beside OfficeLite against it (issue 60):
``python -m interp.tracebench [--traces DIR] [--interp vm|tree] [--only TEXT] [--json OUT]``.

For every recording of the training half of ../shared/real-traces (its MAP.csv) the program that
made it runs on the simulator, and ``krl trace compare``'s measures (robot/kukatrace/compare.py)
compare the run's segment with the real recording; the OfficeLite recording of the same program,
where there is one, is compared with the real one the same way. The table gives, for both:

* motion time (END - START) |error| median, 90th percentile and maximum over the matched motions;
* the motion time from the poses (issue 73: leaving rest -> settled, each axis' ``$IN_POS_MA``
  window; :func:`pose_motion_time`), a recording's on its measured axes, a run's on the axes of its
  robot's actual-value model (robot/actualvalue.py), |error| median, p90 and maximum;
* when the robot has settled after each motion's START (the end of that motion time; what ``krl
  run``'s summary counts to), |error| median and p90 in ms;
* that settled error split in two (issue 88, :func:`settled_split`): the plan's part (the planned
  durations' difference over the real settled time, %: the settled error a drive like the real
  one would leave) and the drive's part (ms, signed: what the actual-value model adds or loses);
* the settled error's floor (issue 88, :func:`settled_floor`): the settled error a drive settling
  exactly as the real one would give with the run's plan, sampled every 12 ms as the recordings are
  (what no actual-value model can beat with that plan);
* the exact-stop pause (median START - the previous motion's end of interpolation);
* the largest path deviation of a LIN and of a CIRC (mm);

and, for a like-for-like view, the simulator's figures on the recordings OfficeLite also has.

**The runs.** Each program (``KRL Programs/NAME.src`` and ``.dat``) is copied to a temporary
folder with what the real controller held and the folder lacks (nothing of it is written into the
project): a ``$config.dat`` whose ``TOOL_DATA`` and ``LOAD_DATA`` hold the tool and load the
recordings' PROG.TXT give (the same for every motion of a program), and, in the program's data
list, the recorded coordinates of each E6POS point a recorded PTP or LIN went to (PROG.TXT's
``POINT NAME`` and ``POINT COORDINATES``; movement_test_lin.dat was edited after its recordings:
the README). The robot is robot/data/kr3_r540.dat; the program override ``$OV_PRO`` is the one
the real recordings' END signals give (85 % for the ``_po85`` programs, robot/kukatrace/model.py).
The run's trace is kept in memory.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import re
import shutil
import sys
import tempfile
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np

from interp.run import make_runtime, run_spec, RunSinks
from robot.kukatrace.actual import actual_tcp
from robot.actualvalue import actual_axes, ptp_rows_of
from robot.kukatrace.compare import MotionComparison, compare, compare_segments, match_motions, motion_span, pair_segments
from robot.kukatrace.identify import bare, identify, link_inertials, load_of, load_tuple, pose_times
from robot.kukatrace.model import RunView, Segment, load_run, recording_override, run_view
from robot.kukatrace.recording import Recording, read_recording
from robot.machine import ROBOT_LIBRARY
from robot.mada import load_mada, load_robot
from robot.settlelag import segment_taus
from robot.trace import TraceWriter

TRACES = Path(__file__).resolve().parents[2] / "shared" / "real-traces"
ROBOT = "kr3_r540"
#: the KR 3 R540's rated payload, kg (KUKA's data sheet; the default load the real controller reports
#: for TOOL 0 in PTP_away's recordings: m 3.0, cm {60, 0, 80} mm, J 0.045 kg m²)
RATED_PAYLOAD_KG = 3.0
#: the KR 3 R540's collision meshes (kuka_experimental, ../shared/robots): its links' inertials
MESHES = (TRACES.parent / "robots" / "descriptions" / "kuka_experimental" / "kuka_kr3_support" / "meshes"
          / "kr3r540" / "collision")
REAL_PREFIX = "WINDOWS-V37DJA1 - 8101392_"
OL_PREFIX = "KukaOL - 0_"
#: the issue's limits: what OfficeLite reached against the real robot on the held-out half (motion
#: time |error| %, the pause's distance to the real one in s, path deviations in mm)
LIMITS = {"time_median_pct": 1.5, "time_p90_pct": 5.0, "time_max_pct": 10.0, "pause_s": 0.012,
          "lin_mm": 0.28, "circ_mm": 1.48, "settled_median_pct": 2.0, "settled_p90_pct": 6.0}

#: the tables' rows (label, summary key, scale, format; the issue's limit beside each is
#: :func:`limit_text`'s, from :data:`LIMITS`): one list for the plain table and --cross's, which
#: alone prints the real pause beside the simulated one
FIGURE_ROWS = (("motion time |error| median (%)", "time_median_pct", 1, "{:.2f}"),
               ("motion time |error| p90 (%)", "time_p90_pct", 1, "{:.2f}"),
               ("motion time |error| max (%)", "time_max_pct", 1, "{:.2f}"),
               ("settled motion time |error| median (%)", "settled_median_pct", 1, "{:.2f}"),
               ("settled motion time |error| p90 (%)", "settled_p90_pct", 1, "{:.2f}"),
               ("settled motion time |error| max (%)", "settled_max_pct", 1, "{:.2f}"),
               ("settled after START |error| median (ms)", "settled_end_median_ms", 1, "{:.0f}"),
               ("settled after START |error| p90 (ms)", "settled_end_p90_ms", 1, "{:.0f}"),
               ("settled: plan's part |error| median (%)", "plan_part_median_pct", 1, "{:.2f}"),
               ("settled: plan's part |error| p90 (%)", "plan_part_p90_pct", 1, "{:.2f}"),
               ("settled: plan's part |error| max (%)", "plan_part_max_pct", 1, "{:.2f}"),
               ("settled: drive's part median (ms)", "drive_part_median_ms", 1, "{:+.1f}"),
               ("settled: drive's part |error| p90 (ms)", "drive_part_p90_ms", 1, "{:.1f}"),
               ("settled: floor (real drive) median (%)", "floor_median_pct", 1, "{:.2f}"),
               ("settled: floor (real drive) p90 (%)", "floor_p90_pct", 1, "{:.2f}"),
               ("settled: floor (real drive) max (%)", "floor_max_pct", 1, "{:.2f}"),
               ("exact-stop pause (ms)", "pause_run_s", 1000, "{:.0f}"),
               ("real exact-stop pause (ms)", "pause_real_s", 1000, "{:.0f}"),
               ("LIN path deviation max (mm)", "lin_mm", 1, "{:.3f}"),
               ("CIRC path deviation max (mm)", "circ_mm", 1, "{:.3f}"))


def limit_text(key: str) -> str:
    """The issue's limit of the figure `key` as the tables print it ("" without one)."""
    if key == "pause_run_s":
        return f"real +- {1000 * LIMITS['pause_s']:.0f}"
    return str(LIMITS[key]) if key in LIMITS else ""


@dataclass
class Row:
    """One recording: its MAP row, the simulator's and OfficeLite's matched motions, and the
    simulator's and OfficeLite's settled motion time errors (%) and settled end errors (ms)
    (:func:`settled_errors`), and the simulator's settled errors split into the plan's part (%)
    and the drive's (ms) (:func:`settled_split`), and their floor (%, :func:`settled_floor`)."""

    program: str
    name: str
    sim: list[MotionComparison] = field(default_factory=list)
    ol: list[MotionComparison] | None = None
    sim_settled: list[float] = field(default_factory=list)
    ol_settled: list[float] | None = None
    sim_settled_end: list[float] = field(default_factory=list)
    ol_settled_end: list[float] | None = None
    sim_plan_part: list[float] = field(default_factory=list)
    sim_drive_part: list[float] = field(default_factory=list)
    sim_floor: list[float] = field(default_factory=list)


def pose_motion_time(t: np.ndarray, axes: np.ndarray, t0: float, t1: float, window: np.ndarray) -> float | None:
    """The motion time (s) from the poses of one motion (issue 73: "leaving rest -> settled"):
    from the first sample after `t0` (its START) at which an axis is farther than its `window`
    (deg, ``$IN_POS_MA``) from the pose at START, to the first sample from which every axis stays
    within its window of the pose at `t1` (the next START, or the segment's end); `t` (N,) s and
    `axes` (N, n) deg the samples (measured, or the model's actual axes). None when the axes do not
    leave rest."""
    got = pose_times(t, axes, t0, t1, window)
    return None if got is None else got[1] - got[0]


def settled_errors(run: Segment, rec: Segment, motions: list[MotionComparison], run_axes: np.ndarray,
                   window: np.ndarray) -> tuple[list[float], list[float]]:
    """The settled motion time errors (%, RUN - REC over REC's: :func:`pose_motion_time`) of each
    matched exact-stop motion with a time on both sides, and their settled end errors (ms: RUN's
    settled sample after its START less REC's, :func:`pose_times`); `run_axes` RUN's actual axes
    (the actual-value model's, robot/actualvalue.py; a recording's own)."""
    pct, end = [], []
    for m in motions:
        ta, tb = motion_span(run, m.run_index), motion_span(rec, m.rec_index)
        a = pose_times(run.t, run_axes, *ta, window)
        b = pose_times(rec.t, rec.axes, *tb, window)
        if a is not None and b is not None and b[1] > b[0]:
            pct.append(100.0 * ((a[1] - a[0]) - (b[1] - b[0])) / (b[1] - b[0]))
            end.append(1000.0 * ((a[1] - ta[0]) - (b[1] - tb[0])))
    return pct, end


def settled_split(run: Segment, rec: Segment, motions: list[MotionComparison], run_axes: np.ndarray,
                  window: np.ndarray) -> tuple[list[float], list[float]]:
    """The settled motion time error of each matched exact-stop motion (:func:`settled_errors`)
    split in two (issue 88): the **plan's part** (%), the planned durations' difference (RUN's end
    of interpolation less REC's, each after its START: a recording's ``reached`` is PROG.TXT's
    ENDTIME over the override, robot/kukatrace/model.py) over REC's settled motion time, which is
    what the settled error would be with a drive that settles as the real one does; and the
    **drive's part** (ms, signed), the settled durations' difference less the planned durations':
    what the actual-value model (`run_axes`, robot/actualvalue.py) adds or loses against the real
    drives, sampling included. Motions without a planned end on either side are left out."""
    plan, drive = [], []
    for m in motions:
        ta, tb = motion_span(run, m.run_index), motion_span(rec, m.rec_index)
        ra, rb = run.motions[m.run_index].reached, rec.motions[m.rec_index].reached
        a = pose_times(run.t, run_axes, *ta, window)
        b = pose_times(rec.t, rec.axes, *tb, window)
        if a is None or b is None or b[1] <= b[0] or ra is None or rb is None:
            continue
        planned = (ra - ta[0]) - (rb - tb[0])
        plan.append(100.0 * planned / (b[1] - b[0]))
        drive.append(1000.0 * (((a[1] - a[0]) - (b[1] - b[0])) - planned))
    return plan, drive


def settled_floor(run: Segment, rec: Segment, motions: list[MotionComparison], window: np.ndarray,
                  dt: float) -> list[float]:
    """The settled motion time error (%) of each matched exact-stop motion with a planned end on
    both sides that a drive settling exactly as the real one would give with RUN's plan (issue 88):
    REC's settled sample (:func:`pose_times` on its measured axes, sampled every `dt` s) moved by the
    planned durations' difference (:func:`settled_split`), the crossing it stands for taken in the
    middle of the sample before it and counted from the first sample at or after it, REC's leaving
    rest kept; over REC's settled motion time. What no actual-value model can beat with that plan:
    the settled figures' floor (docs/robot.md "The settled median: the drive or the plan")."""
    out = []
    for m in motions:
        ta, tb = motion_span(run, m.run_index), motion_span(rec, m.rec_index)
        ra, rb = run.motions[m.run_index].reached, rec.motions[m.rec_index].reached
        b = pose_times(rec.t, rec.axes, *tb, window)
        if b is None or b[1] <= b[0] or ra is None or rb is None:
            continue
        planned = (ra - ta[0]) - (rb - tb[0])
        moved = dt * math.ceil((planned - dt / 2) / dt - 1e-9)
        out.append(100.0 * moved / (b[1] - b[0]))
    return out


def map_rows(traces: Path) -> list[dict[str, str]]:
    with (traces / "MAP.csv").open(newline="", encoding="utf-8") as f:
        return [r for r in csv.DictReader(f) if r["split"] == "training"]


def _config_dat(tool: tuple[float, ...], load: dict[str, Any] | None) -> str:
    """A ``$config.dat`` with every TOOL_DATA and LOAD_DATA element and DEF_LOAD_DATA set to the
    recorded tool and load (the programs select one tool; which number the recording does not say;
    PTP_away runs with TOOL 0, whose load is the controller's default)."""
    x = dict(zip("XYZABC", tool))
    tool_s = "{" + ",".join(f"{k} {v!r}" for k, v in x.items()) + "}"
    if load:
        cm = load.get("cm") or {}
        j = load.get("j") or {}
        load_s = (f"{{M {load.get('m', -1.0)!r},CM {{" + ",".join(f"{k.upper()} {float(cm.get(k, 0.0))!r}" for k in "xyzabc")
                  + "},J {" + ",".join(f"{k.upper()} {float(j.get(k, 0.0))!r}" for k in "xyz") + "}}")
    else:
        load_s = "{M -1.0,CM {X 0.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0},J {X 0.0,Y 0.0,Z 0.0}}"
    lines = ["DEFDAT $CONFIG", "DECL FRAME TOOL_DATA[16]"]
    lines += [f"TOOL_DATA[{i}]={tool_s}" for i in range(1, 17)]
    lines += ["DECL LOAD LOAD_DATA[16]"] + [f"LOAD_DATA[{i}]={load_s}" for i in range(1, 17)]
    # the load of TOOL 0 (BAS's SLOAD): the real controller's default load ($DEF_L_M, $DEF_L_CM,
    # $DEF_L_J), which PTP_away's recordings show as their LOAD (3 kg); the project's BASIS has the
    # KR 6's
    lines += [f"DECL LOAD DEF_LOAD_DATA={load_s}"]
    return "\n".join(lines + ["ENDDAT", ""])


_E6POS = re.compile(r"^(\s*DECL\s+E6POS\s+)(\w+)(\s*=\s*)\{[^}]*\}(.*)$", re.I)


def _recorded_points(dat: str, recs: list[Recording]) -> str:
    """`dat` with each E6POS point a recorded PTP or LIN went to set to the recorded coordinates."""
    points: dict[str, dict[str, float]] = {}
    for rec in recs:
        for m in rec.motions:
            if m.kind in ("PTP", "LIN") and m.point_name and m.point:
                points[m.point_name.upper()] = m.point
    out = []
    for line in dat.splitlines():
        mt = _E6POS.match(line)
        if mt and mt.group(2).upper() in points:
            p = points[mt.group(2).upper()]
            val = (",".join(f"{k.upper()} {p[k]!r}" for k in "xyzabc")
                   + f",S {int(p['s'])},T {int(p['t'])}")
            line = f"{mt.group(1)}{mt.group(2)}{mt.group(3)}{{{val}}}{mt.group(4)}"
        out.append(line)
    return "\n".join(out) + "\n"


def prepare(traces: Path, program: str, recs: list[Recording], work: Path) -> Path:
    """The folder of `program`'s run (the module's docstring): its .src, its data list with the
    recorded points, a $config.dat with the recorded tool and load. Returns the .src."""
    folder = work / program
    folder.mkdir(parents=True, exist_ok=True)
    src = traces / "KRL Programs" / f"{program}.src"
    shutil.copyfile(src, folder / src.name)
    dat = src.with_suffix(".dat")
    (folder / dat.name).write_text(_recorded_points(dat.read_text(encoding="latin-1"), recs), encoding="latin-1")
    first = recs[0].motions[0]
    (folder / "$config.dat").write_text(_config_dat(first.tool, first.load), encoding="latin-1")
    return folder / src.name


def run_program(src: Path, override: float, interp: str = "vm", robot: Any = None) -> RunView:
    """The run of `src` on the KR 3 R540 (or the MachineData `robot`) at `override` (fraction), as
    a RunView of its trace."""
    tw = TraceWriter(keep=True)
    robot = load_robot(ROBOT) if robot is None else robot
    # the trace's header, as krl run writes it (interp/run.py RunSetup): the robot and its source
    tw.write("robot", 0.0, name=robot.name, source=str(robot.source), trafoname=robot.trafoname or None)
    rt, _ = make_runtime(run_spec(src, mujoco=False, interp=interp, robot=robot, max_sim_time=1200.0,
                                  check=True, override=round(100 * override)), RunSinks(trace=tw))
    res = rt.run()
    if res.reason != "completed":
        raise RuntimeError(f"{src.name}: the run ended with {res.reason}: {getattr(res, 'text', '')}")
    tw.close()
    return run_view(tw.events, "trace", str(src))


def _read_real(traces: Path, row: dict[str, str]) -> Recording:
    """The real robot's recording of the MAP row `row`."""
    return read_recording(traces / row["real_folder"] / f"{REAL_PREFIX}{row['trace_name']}")


def loaded_view(rec: Recording) -> RunView:
    """The view of the recording `rec` (``load_run``), each motion with PROG.TXT's LOAD
    (``Motion.load``; the view's motions are the recording's, in order)."""
    view = load_run(rec.prog_path)
    for seg in view.segments:
        for m in seg.motions:
            got = [r for r in rec.motions if abs(r.start - seg.origin - m.start) < 1e-9 and r.kind == m.kind]
            m.load = load_tuple(load_of(got[0])) if got else None
    return view


def loaded_pairs(run: RunView, rec_view: RunView) -> list[tuple[Segment, Segment]]:
    """``pair_segments`` of `run` against `rec_view` (:func:`loaded_view`), each run motion given the
    LOAD of the recorded motion it is matched with: the program ran with it (:func:`prepare` writes
    the recording's LOAD into its ``$config.dat``), which the run's trace does not hold."""
    pairs = pair_segments(run, rec_view)
    for a, b in pairs:
        for k, j in match_motions(a, b)[0]:
            a.motions[k].load = b.motions[j].load
    return pairs


def _program_run(traces: Path, program: str, mine: list[dict[str, str]], work: Path, interp: str,
                 robot: Any) -> tuple[dict[str, Recording], RunView]:
    """The real recordings of `program`'s MAP rows `mine` (by trace name) and the program's run on
    `robot` (None: the KR 3 R540) at their override, prepared in `work` (:func:`prepare`)."""
    real = {r["trace_name"]: _read_real(traces, r) for r in mine}
    src = prepare(traces, program, list(real.values()), work)
    return real, run_program(src, recording_override(next(iter(real.values())))[0], interp, robot)


def bench(traces: Path = TRACES, interp: str = "vm", only: str | None = None, robot: Any = None,
          programs: set[str] | None = None) -> list[Row]:
    """Run every program and compare (the module's docstring): one :class:`Row` per recording;
    `robot` the MachineData to run on (default robot/data/kr3_r540.dat with its identified
    parameters), `programs` only those programs."""
    rows = [r for r in map_rows(traces) if (only is None or only in r["trace_name"] or only in r["program"])
            and (programs is None or r["program"] in programs)]
    out: list[Row] = []
    with tempfile.TemporaryDirectory(prefix="krl-trace-bench-") as tmp:
        for program in dict.fromkeys(r["program"] for r in rows):
            mine = [r for r in rows if r["program"] == program]
            real, run = _program_run(traces, program, mine, Path(tmp), interp, robot)
            for r in mine:
                rec_view = loaded_view(real[r["trace_name"]])
                sim, settled, end, plan, drive, floor = _compared(run, rec_view, robot)
                row = Row(program, r["trace_name"], sim, sim_settled=settled, sim_settled_end=end,
                          sim_plan_part=plan, sim_drive_part=drive, sim_floor=floor)
                if r["officelite_folder"]:
                    ol = load_run(traces / r["officelite_folder"] / f"{OL_PREFIX}{r['officelite_name']}")
                    row.ol, row.ol_settled, row.ol_settled_end = [], [], []
                    for a, b in pair_segments(ol, rec_view):
                        got = compare_segments(a, b, actual_tcp(ol, a)).motions
                        row.ol += got
                        pct, end = settled_errors(a, b, got, a.axes, _window(robot))
                        row.ol_settled += pct
                        row.ol_settled_end += end
                out.append(row)
    return out


def real_recordings(traces: Path, programs: set[str] | None = None) -> list[tuple[dict[str, str], Recording, float]]:
    """(MAP row, Recording, override fraction) of each real recording of the training half (of
    `programs` only, when given): what robot/kukatrace/identify.py identifies from."""
    out = []
    for row in map_rows(traces):
        if programs is None or row["program"] in programs:
            rec = _read_real(traces, row)
            out.append((row, rec, recording_override(rec)[0]))
    return out


def cp_runner(traces: Path, interp: str = "vm"):
    """The ``run_cp(machine, programs)`` of robot/kukatrace/identify.py ``identify``: each LIN and
    CIRC program of `programs` run on `machine` (every recorded point as recorded), as (recording
    name, run, run's segment, recording's segment) of each paired segment."""
    def run_cp(machine: Any, programs: Any) -> list:
        rows = map_rows(traces)
        pairs = []
        with tempfile.TemporaryDirectory(prefix="krl-identify-") as tmp:
            for program in programs:
                mine = [r for r in rows if r["program"] == program]
                real, run = _program_run(traces, program, mine, Path(tmp), interp, machine)
                for r in mine:
                    pairs += [(r["trace_name"], run, a, b)
                              for a, b in loaded_pairs(run, loaded_view(real[r["trace_name"]]))]
        return pairs
    return run_cp


def identified(traces: Path, programs: set[str], interp: str = "vm", rated_kg: float = RATED_PAYLOAD_KG) -> Any:
    """robot/kukatrace/identify.py ``identify`` on the real recordings of `programs`, for the
    KR 3 R540's machine data (robot/data/kr3_r540.dat without its identified yaml) with the links
    of its description's collision meshes (:data:`MESHES`; without them no dynamic model)."""
    base = bare(load_mada(ROBOT_LIBRARY / f"{ROBOT}.dat"))
    links = link_inertials(MESHES) if (MESHES / "link_1.stl").exists() else None
    return identify(base, real_recordings(traces, programs), links, cp_runner(traces, interp), rated_kg)


def cross(traces: Path = TRACES, interp: str = "vm") -> dict[str, Any]:
    """Issue 73's "a fit is not a model": the parameters identified once on every program
    (``fitted``: measured on the recordings they were identified on) and once per program with
    that program left out (``cross``: each program measured with the parameters identified
    without it). Returns {"fitted": rows, "cross": rows, "programs": [...]}."""
    programs = list(dict.fromkeys(r["program"] for r in map_rows(traces)))
    every = identified(traces, set(programs), interp)
    fitted = bench(traces, interp, robot=every.machine)
    rows: list[Row] = []
    for left_out in programs:
        got = identified(traces, set(programs) - {left_out}, interp)
        rows += bench(traces, interp, robot=got.machine, programs={left_out})
    return {"fitted": fitted, "cross": rows, "programs": programs}


def cross_table(result: dict[str, Any]) -> list[str]:
    """The fitted and the cross-validated figures side by side, then the cross-validated figures of
    each left-out program."""
    f, c = (rows_summary(result[k]) for k in ("fitted", "cross"))

    def cell(d: dict[str, Any], key: str, scale: float, fmt: str) -> str:
        v = d.get(key)
        return "-" if v is None else fmt.format(v * scale)

    lines = [f"{'figure':<40}{'fitted (all programs)':>24}{'cross-validated':>18}   limit", "-" * 90]
    for label, key, scale, fmt in FIGURE_ROWS:
        lines.append(f"{label:<40}{cell(f, key, scale, fmt):>24}{cell(c, key, scale, fmt):>18}   {limit_text(key)}")
    lines.append(f"{'motions compared':<40}{f['motions']:>24}{c['motions']:>18}")
    lines.append(f"{'motions with a settled time':<40}{f['settled_motions']:>24}{c['settled_motions']:>18}")
    lines += ["", "left out, predicted           motions   median %   p90 %   max %   LIN mm   CIRC mm"
              "   settled median %   p90 %   plan's part median %   p90 %"]
    for program in result["programs"]:
        s = rows_summary([r for r in result["cross"] if r.program == program])
        lines.append(f"{program:<28}{s['motions']:>9}{cell(s, 'time_median_pct', 1, '{:.2f}'):>11}"
                     f"{cell(s, 'time_p90_pct', 1, '{:.2f}'):>8}{cell(s, 'time_max_pct', 1, '{:.2f}'):>8}"
                     f"{cell(s, 'lin_mm', 1, '{:.3f}'):>9}{cell(s, 'circ_mm', 1, '{:.3f}'):>10}"
                     f"{cell(s, 'settled_median_pct', 1, '{:.2f}'):>19}{cell(s, 'settled_p90_pct', 1, '{:.2f}'):>8}"
                     f"{cell(s, 'plan_part_median_pct', 1, '{:.2f}'):>23}{cell(s, 'plan_part_p90_pct', 1, '{:.2f}'):>8}")
    return lines


def _window(robot: Any) -> np.ndarray:
    """The axes' positioning windows ``$IN_POS_MA`` (deg) of `robot` (None: the KR 3 R540's)."""
    m = load_robot(ROBOT) if robot is None else robot
    return np.asarray(m.in_pos_ma_deg[:m.n_axes], dtype=float)


def _compared(run: RunView, rec: RunView, robot: Any) -> tuple[list[MotionComparison], list[float], list[float],
                                                                list[float], list[float], list[float]]:
    """The matched motions of `run` against `rec`, their settled motion time errors (%), settled
    end errors (ms), the plan's (%) and drive's (ms) parts (:func:`settled_split`) and the floor
    (%, :func:`settled_floor`); a run has its path and its poses taken through its robot's actual-value model
    (robot/actualvalue.py; a given `robot`'s, else the library's KR 3 R540's, which compare() would
    take), its settling lag with each motion's LOAD from `rec` (:func:`loaded_view`, :func:`loaded_pairs`)."""
    m = load_robot(ROBOT) if robot is None else robot
    motions, settled, ends, plans, drives, floors = [], [], [], [], [], []
    for a, b in loaded_pairs(run, rec):
        lag, taus = m.actual_settle_lag, segment_taus(m, a)
        got = compare_segments(a, b, actual_tcp(run, a, m.actual_filter_cycles, m.actual_following or {},
                                                m.actual_dead_cycles, m.actual_filter_cycles_ptp, lag, taus)).motions
        act = actual_axes(a.axes[:, :m.n_axes], m.actual_filter_cycles, m.actual_following, m.ipo_cycle_s,
                          dead=m.actual_dead_cycles, ptp_rows=ptp_rows_of(a.t, a.motions),
                          ptp_cycles=m.actual_filter_cycles_ptp, lag=lag, taus=taus)
        motions += got
        pct, end = settled_errors(a, b, got, act, _window(m))
        plan, drive = settled_split(a, b, got, act, _window(m))
        settled += pct
        ends += end
        plans += plan
        drives += drive
        floors += settled_floor(a, b, got, _window(m), m.ipo_cycle_s)
    return motions, settled, ends, plans, drives, floors


def summary(motions: list[MotionComparison], settled: list[float] | None = None,
            settled_end: list[float] | None = None, plan_part: list[float] | None = None,
            drive_part: list[float] | None = None, floor_part: list[float] | None = None) -> dict[str, Any]:
    """The figures of the table over `motions`, their `settled` motion time errors (%), their
    `settled_end` errors (ms), the settled errors' `plan_part` (%) and `drive_part` (ms,
    :func:`settled_split`) and their `floor_part` (%, :func:`settled_floor`; None where there is
    no data)."""
    e = np.abs([m.time_error_pct for m in motions if m.time_error_pct is not None])
    se = np.abs(settled or [])
    ee = np.abs(settled_end or [])
    pp = np.abs(plan_part or [])
    dp = np.asarray(drive_part or [], dtype=float)
    fp = np.abs(floor_part or [])
    run_p = [m.run_pause for m in motions if m.run_pause is not None and m.run_pause <= 0.5]
    rec_p = [m.rec_pause for m in motions if m.rec_pause is not None and m.rec_pause <= 0.5]

    def dev(kind: str) -> float | None:
        d = [m.path_deviation for m in motions if m.kind == kind and m.path_deviation is not None]
        return max(d) if d else None

    return {"motions": len(e),
            "time_median_pct": float(np.median(e)) if len(e) else None,
            "time_p90_pct": float(np.percentile(e, 90)) if len(e) else None,
            "time_max_pct": float(e.max()) if len(e) else None,
            "settled_motions": len(se),
            "settled_median_pct": float(np.median(se)) if len(se) else None,
            "settled_p90_pct": float(np.percentile(se, 90)) if len(se) else None,
            "settled_max_pct": float(se.max()) if len(se) else None,
            "settled_end_median_ms": float(np.median(ee)) if len(ee) else None,
            "settled_end_p90_ms": float(np.percentile(ee, 90)) if len(ee) else None,
            "plan_part_median_pct": float(np.median(pp)) if len(pp) else None,
            "plan_part_p90_pct": float(np.percentile(pp, 90)) if len(pp) else None,
            "plan_part_max_pct": float(pp.max()) if len(pp) else None,
            "drive_part_median_ms": float(np.median(dp)) if len(dp) else None,
            "drive_part_p90_ms": float(np.percentile(np.abs(dp), 90)) if len(dp) else None,
            "floor_median_pct": float(np.median(fp)) if len(fp) else None,
            "floor_p90_pct": float(np.percentile(fp, 90)) if len(fp) else None,
            "floor_max_pct": float(fp.max()) if len(fp) else None,
            "pause_run_s": float(np.median(run_p)) if run_p else None,
            "pause_real_s": float(np.median(rec_p)) if rec_p else None,
            "lin_mm": dev("LIN"), "circ_mm": dev("CIRC")}


def figures(rows: list[Row]) -> dict[str, dict[str, Any]]:
    """The simulator's figures on every recording, OfficeLite's on its recordings, and the
    simulator's on those same recordings."""
    with_ol = [r for r in rows if r.ol is not None]
    return {"sim": rows_summary(rows),
            "officelite": summary([m for r in with_ol for m in r.ol], [e for r in with_ol for e in r.ol_settled],
                                  [e for r in with_ol for e in r.ol_settled_end]),
            "sim_on_officelite_set": rows_summary(with_ol)}


def rows_summary(rows: list[Row]) -> dict[str, Any]:
    """:func:`summary` of the simulator's motions of `rows`."""
    return summary([m for r in rows for m in r.sim], [e for r in rows for e in r.sim_settled],
                   [e for r in rows for e in r.sim_settled_end], [e for r in rows for e in r.sim_plan_part],
                   [e for r in rows for e in r.sim_drive_part], [e for r in rows for e in r.sim_floor])


def worse_than_limits(f: dict[str, Any]) -> list[str]:
    """The figures of `f` (a :func:`summary`) outside :data:`LIMITS`."""
    bad = []
    for key in ("time_median_pct", "time_p90_pct", "time_max_pct", "lin_mm", "circ_mm", "settled_median_pct",
                "settled_p90_pct"):
        if f.get(key) is not None and f[key] > LIMITS[key]:
            bad.append(f"{key} {f[key]:.3f} > {LIMITS[key]}")
    if f["pause_run_s"] is not None and abs(f["pause_run_s"] - f["pause_real_s"]) > LIMITS["pause_s"]:
        bad.append(f"pause {1000 * f['pause_run_s']:.0f} ms, real {1000 * f['pause_real_s']:.0f} ms")
    return bad


def table(fig: dict[str, dict[str, Any]]) -> list[str]:
    """The table of the module's docstring."""
    def cell(f: dict[str, Any], key: str, scale: float = 1.0, fmt: str = "{:.2f}") -> str:
        v = f.get(key)
        return "-" if v is None else fmt.format(v * scale)

    s, o, so = fig["sim"], fig["officelite"], fig["sim_on_officelite_set"]
    lines = ["figure                                  simulated vs real   OfficeLite vs real   simulated (OL's set)   limit",
             "-" * 110]
    for label, key, scale, fmt in (r for r in FIGURE_ROWS if r[1] != "pause_real_s"):
        lines.append(f"{label:<40}{cell(s, key, scale, fmt):>18}{cell(o, key, scale, fmt):>21}"
                     f"{cell(so, key, scale, fmt):>23}   {limit_text(key)}")
    lines.append(f"{'real exact-stop pause (ms)':<40}{cell(s, 'pause_real_s', 1000, '{:.0f}'):>18}"
                 f"{cell(o, 'pause_real_s', 1000, '{:.0f}'):>21}{cell(so, 'pause_real_s', 1000, '{:.0f}'):>23}")
    lines.append(f"{'motions compared':<40}{s['motions']:>18}{o['motions']:>21}{so['motions']:>23}")
    lines.append(f"{'motions with a settled time':<40}{s['settled_motions']:>18}{o['settled_motions']:>21}"
                 f"{so['settled_motions']:>23}")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m interp.tracebench", description=__doc__.split("\n\n")[0])
    ap.add_argument("--traces", type=Path, default=TRACES, help="the recordings (default ../shared/real-traces)")
    ap.add_argument("--interp", choices=("vm", "tree"), default="vm")
    ap.add_argument("--only", default=None, help="only the recordings or programs whose name holds this")
    ap.add_argument("--json", type=Path, default=None, help="write the rows and the figures here")
    ap.add_argument("--cross", action="store_true",
                    help="identify once per program with it left out, predict it; beside the fit on all")
    args = ap.parse_args(argv)
    if not (args.traces / "MAP.csv").exists():
        print(f"no recordings at {args.traces} (MAP.csv)", file=sys.stderr)
        return 2
    t0 = time.process_time()
    if args.cross:
        return _main_cross(args, t0)
    rows = bench(args.traces, args.interp, args.only)
    fig = figures(rows)
    for line in table(fig):
        print(line)
    bad = worse_than_limits(fig["sim"])
    print(f"\n{len(rows)} recordings, {time.process_time() - t0:.1f} s of CPU; "
          + ("every figure within the issue's limits" if not bad else "outside the limits: " + "; ".join(bad)))
    if args.json is not None:
        _write_json(args.json, fig, [{"program": r.program, "name": r.name, "sim": rows_summary([r]),
                                      "officelite": None if r.ol is None else summary(r.ol, r.ol_settled, r.ol_settled_end)}
                                     for r in rows])
    return 0


def _main_cross(args: argparse.Namespace, t0: float) -> int:
    """``--cross``: :func:`cross`'s table, the figures outside the issue's limits, ``--json``."""
    result = cross(args.traces, args.interp)
    for line in cross_table(result):
        print(line)
    fig = {k: rows_summary(result[k]) for k in ("fitted", "cross")}
    bad = worse_than_limits(fig["cross"])
    print(f"\n{len(result['cross'])} recordings, {time.process_time() - t0:.1f} s of CPU; cross-validated: "
          + ("every figure within the issue's limits" if not bad else "outside the limits: " + "; ".join(bad)))
    if args.json is not None:
        _write_json(args.json, fig, [{"program": r.program, "name": r.name, "fold": k, "sim": rows_summary([r])}
                                     for k in ("fitted", "cross") for r in result[k]])
    return 0


def _write_json(path: Path, fig: dict[str, Any], rows: list[dict[str, Any]]) -> None:
    """``--json``'s file: the date (UTC), the figures `fig`, :data:`LIMITS` and the per-recording `rows`."""
    path.write_text(json.dumps({"date": datetime.now(timezone.utc).isoformat(timespec="seconds"), "figures": fig,
                                "limits": LIMITS, "rows": rows}, indent=1))


if __name__ == "__main__":
    sys.exit(main())
