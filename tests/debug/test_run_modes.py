"""Program run modes ($PRO_MODE, krl run --run-mode) and backward motion (#BSTEP) on
motion programs (interp/runtime/runmode.py; docs/robot.md "Program run modes and backward
motion"). Expected points are the programmed targets, read off the program text."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from interp.run import make_runtime, run_spec, RunSinks
from app import main
from robot.exactstop import DONE_CYCLES
from robot.trace import TraceWriter

CASES = Path(__file__).resolve().parents[2] / "conformance" / "cases"
CIRC = CASES / "064_circ_c_dis" / "program.src"      # PTP (l.4), CIRC ... C_DIS (l.7), LIN {Y -100} (l.8)
SPLINE = CASES / "065_spline_block" / "program.src"
#: how long after a motion's END the main run is done with it, in s (DONE_CYCLES IPO cycles of 12 ms)
DONE = DONE_CYCLES * 0.012
HOME = [0.0, -90.0, 90.0, 0.0, 0.0, 0.0]               # the arm's start axes (robot/data, $AXIS_HOME)


def run(program, run_mode=None, mode="T1", interp="tree"):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(program, mujoco=False, mode=mode, run_mode=run_mode, interp=interp,
                         max_sim_time=120.0), RunSinks(trace=tw))
    res = rt.run()
    return rt, res, tw.events


def kinds(events, kind):
    return [e for e in events if e["kind"] == kind]


def pose_at(events, t):
    """The last pose event at or before time t."""
    return [e for e in events if e["kind"] == "pose" and e["t"] <= t + 1e-9][-1]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_go_runs_through_with_approximation(interp):
    _, res, ev = run(CIRC, "GO", interp=interp)
    assert res.reason == "completed" and not kinds(ev, "step_stop")
    circ = [e for e in kinds(ev, "motion") if e["id"] == 2]
    assert [e["phase"] for e in circ] == ["start", "blend_start", "blend_end", "end"]   # C_DIS approximates


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_mstep_stops_at_each_motion_end_exactly(interp):
    _, res, ev = run(CIRC, "MSTEP", interp=interp)
    assert res.reason == "completed"
    stops = kinds(ev, "step_stop")
    assert [(s["mode"], s["line"], s["id"]) for s in stops] == [("MSTEP", 4, 1), ("MSTEP", 7, 2), ("MSTEP", 8, 3)]
    ends = {e["id"]: e["t"] for e in kinds(ev, "motion") if e["phase"] == "end"}
    for s in stops:
        # the stop comes when the main run is done with the motion: DONE_CYCLES IPO cycles after
        # its END (robot/exactstop.py, from the real KR C4's recordings, issue 60)
        assert s["t"] == pytest.approx(ends[s["id"]] + DONE)
    assert all(e["approximation"] is None for e in kinds(ev, "motion"))   # C_DIS suppressed
    assert not [e for e in kinds(ev, "motion") if e["phase"].startswith("blend")]
    # the advance run does not pass the stop: motion n+1 starts after motion n ended
    starts = {e["id"]: e["t"] for e in kinds(ev, "motion") if e["phase"] == "start"}
    assert starts[2] > ends[1] and starts[3] > ends[2]
    # exact positioning: the CIRC ends at its programmed target X 605, Y 0, Z 810
    assert np.allclose(pose_at(ev, ends[2])["tcp"][:3], [605, 0, 810], atol=1e-3)


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_istep_stops_before_each_statement_with_the_robot_at_rest(interp):
    _, res, ev = run(CIRC, "ISTEP", interp=interp)
    assert res.reason == "completed"
    stops = kinds(ev, "step_stop")
    main = [s for s in stops if s["file"].endswith("program.src")]
    assert [s["line"] for s in main] == [2, 3, 4, 5, 6, 7, 8]     # every statement of the program
    ends = sorted(e["t"] for e in kinds(ev, "motion") if e["phase"] == "end")
    # the stop before line 5 comes when the PTP of line 4 has ended, before line 8 when the CIRC has
    assert next(s["t"] for s in main if s["line"] == 5) == pytest.approx(ends[0] + DONE)
    assert next(s["t"] for s in main if s["line"] == 8) == pytest.approx(ends[1] + DONE)
    assert all(e["approximation"] is None for e in kinds(ev, "motion"))


def test_pro_mode_set_by_the_program(tmp_path):
    prog = tmp_path / "pm.src"
    prog.write_text(CIRC.read_text().replace("  $VEL.CP = 0.1\n", "  $VEL.CP = 0.1\n  $PRO_MODE = #MSTEP\n"))
    for interp in ("tree", "vm"):
        _, res, ev = run(prog, None, interp=interp)
        assert res.reason == "completed"
        # the PTP ran in #GO; the CIRC (now l.8) and the LIN (l.9) in #MSTEP
        assert [(s["line"], s["id"]) for s in kinds(ev, "step_stop")] == [(8, 2), (9, 3)]


def test_backward_motion_retraces_lin_circ_ptp_to_the_start_pose():
    _, res, ev = run(CIRC, "BSTEP", mode="T1")
    assert res.reason == "completed"
    stops = kinds(ev, "step_stop")
    fwd = [s for s in stops if s["mode"] == "MSTEP"]
    back = [s for s in stops if s["mode"] == "BSTEP"]
    assert [s["line"] for s in fwd] == [4, 7, 8]
    # one backward motion per step, newest first, each of the forward motion's type
    assert [s.get("line") for s in back] == [8, 7, 4, 8]
    assert "no executed motion left" in back[-1]["text"]
    types = {e["id"]: e["type"] for e in kinds(ev, "motion")}
    assert [types[s["id"]] for s in back[:3]] == ["LIN", "CIRC", "PTP"]
    fwd_start = {s["id"]: pose_at(ev, s["t"]) for s in fwd}
    # back along the LIN: at the CIRC's end (605, 0, 810); along the CIRC: at the PTP's end
    assert np.allclose(pose_at(ev, back[0]["t"])["tcp"][:3], [605, 0, 810], atol=0.1)
    assert np.allclose(pose_at(ev, back[1]["t"])["tcp"][:3], fwd_start[1]["tcp"][:3], atol=0.1)
    # along the PTP: the start pose of the program (home axes)
    assert np.allclose(pose_at(ev, back[2]["t"])["axes"], HOME, atol=1e-6)
    # the backward CIRC passes the middle of the forward arc (same circle: radius from its centre)
    circ_back = [e for e in kinds(ev, "pose") if back[0]["t"] < e["t"] < back[1]["t"]]
    circ_fwd = [e for e in kinds(ev, "pose") if fwd[0]["t"] < e["t"] < fwd[1]["t"]]
    fwd_pts = np.array([e["tcp"][:3] for e in circ_fwd])
    for e in circ_back[::10]:
        assert np.min(np.linalg.norm(fwd_pts - np.array(e["tcp"][:3]), axis=1)) < 1.0   # on the forward path


def test_backward_motion_is_refused_in_aut():
    _, res, ev = run(CIRC, "BSTEP", mode="AUT")
    back = [s for s in kinds(ev, "step_stop") if s["mode"] == "BSTEP"]
    assert len(back) == 1 and "only possible in T1 and T2" in back[0]["text"]
    assert len({e["id"] for e in kinds(ev, "motion")}) == 3     # no backward motion


def test_backward_motion_is_refused_after_a_spline_block():
    _, res, ev = run(SPLINE, "BSTEP", mode="T2")
    back = [s for s in kinds(ev, "step_stop") if s["mode"] == "BSTEP"]
    assert len(back) == 1 and "SPLINE block" in back[0]["text"]


def test_backward_motion_is_refused_past_changed_frames(tmp_path):
    prog = tmp_path / "frames.src"
    prog.write_text("DEF frames()\n  BAS(#INITMOV, 0)\n  $TOOL = $NULLFRAME\n"
                    "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}\n  $VEL.CP = 0.1\n"
                    "  LIN {X 500}\n  $TOOL = {X 0, Y 0, Z 10, A 0, B 0, C 0}\n  LIN {X 520}\nEND\n")
    _, res, ev = run(prog, "BSTEP", mode="T1")
    back = [s for s in kinds(ev, "step_stop") if s["mode"] == "BSTEP"]
    # the LIN of line 8 (new $TOOL) is retraced; the LIN of line 6 had the old $TOOL: refused
    assert [s.get("line") for s in back[:1]] == [8] and len(back) == 2
    assert "$TOOL or $BASE changed" in back[1]["text"] and "line 6" in back[1]["text"]


def test_krl_run_run_mode_option(tmp_path):
    out = tmp_path / "t.jsonl"
    r = CliRunner().invoke(main, ["run", str(CIRC), "--run-mode", "mstep", "--trace", str(out)])
    assert r.exit_code == 0, r.output
    assert out.read_text().count('"kind":"step_stop"') == 3


def test_mstep_stops_once_after_a_spline_block():
    _, res, ev = run(SPLINE, "MSTEP")
    # 065: PTP (l.4), SPLINE ... ENDSPLINE (l.6-10): two motions, two stops
    assert [(s["mode"], s["id"]) for s in kinds(ev, "step_stop")] == [("MSTEP", 1), ("MSTEP", 2)]
    assert all(e["approximation"] is None for e in kinds(ev, "motion"))
