"""The system software a backup expects (issue 22), on both interpreters with identical traces:
CONST arrays initialised element by element in their data list (reference §2.5
``array_elem_init``), GETSYSSTATE, system variables that the simulator does not model, and the
submit-interpreter errors of the real-programs report.

Expected values are worked out by hand from the programs below.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from interp import realprograms as rp
from interp.run import make_runtime, run_spec, RunSinks
from interp.runtime.motions import TARGET_OUTSIDE_NOTE
from krl.workspace import workspaces_for
from robot.frames import matrix_to_frame
from robot.kinematics import Kinematics
from robot.trace import TraceWriter

from .helpers import run_krl, write

INTERPS = ("tree", "vm")


def both(tmp: Path, src: str, dat: str | None = None, **kw):
    """Run the program on the tree interpreter and the VM; their traces are identical."""
    runs = [run_krl(tmp, src, dat, interp=i, **kw) for i in INTERPS]
    assert runs[0].events == runs[1].events
    r0, r1 = runs[0].result, runs[1].result
    assert (r0.reason, r0.text, r0.line) == (r1.reason, r1.text, r1.line)
    return runs


def messages(run) -> list[str]:
    return [e["text"] for e in run.kinds("message")]


# ------------------------------------------------------------------ CONST arrays

CONST_DAT = """
DEFDAT prog
  DECL CONST REAL a[2]
  a[1] = 1.5
  a[2] = -2.25
  CONST CHAR nm[16]
  nm[] = "hello"
  DECL GLOBAL CONST INT seq[3]
  seq[1] = 3
  seq[3] = 1
  DECL REAL total
  DECL INT n
ENDDAT
"""


def test_const_array_elements_initialised_in_the_data_list(tmp_path):
    src = """
    DEF prog()
      total = a[1] + a[2]
      n = STRLEN(nm[]) * 10 + seq[1] - seq[3]
    END
    """
    for run in both(tmp_path, src, CONST_DAT):
        assert run.result.reason == "completed", run.result.text
        assert run.var("prog", "total") == pytest.approx(-0.75)     # 1.5 + -2.25
        assert run.var("prog", "n") == 52                           # 5 * 10 + 3 - 1


def test_const_array_element_not_initialised_is_value_invalid(tmp_path):
    src = """
    DEF prog()
      n = seq[2]
    END
    """
    for run in both(tmp_path, src, CONST_DAT):
        assert (run.result.reason, run.result.line) == ("error", 2)
        assert "value invalid: seq[2]" in run.result.text


def test_const_array_assigned_by_the_program_is_refused_by_checker_and_run(tmp_path):
    src = """
    DEF prog()
      a[1] = 2.0
    END
    """
    for run in both(tmp_path, src, CONST_DAT):
        assert (run.result.reason, run.result.line) == ("error", 2)
        assert "a[1] is write-protected" in run.result.text
        assert run.var("prog", "a").data == [1.5, -2.25]
    [ws] = workspaces_for(tmp_path / "prog.src")
    diags = ws.check()
    assert [(d.code, d.line) for d in diags if d.is_error] == [("E502", 2)]


def test_const_array_elements_in_the_data_list_pass_the_checker(tmp_path):
    write(tmp_path, "prog.src", "DEF prog()\n  total = a[1]\nEND\n")
    write(tmp_path, "prog.dat", CONST_DAT)
    [ws] = workspaces_for(tmp_path / "prog.src")
    assert [d for d in ws.check() if d.is_error] == []


# ------------------------------------------------------------------ GETSYSSTATE

def test_getsysstate_stopbits_and_an_unknown_command(tmp_path):
    src = """
    DEF prog()
      DECL INT ip
      DECL REAL rp
      DECL BOOL ok
      ip = 5
      rp = 2.5
      ok = GETSYSSTATE("STOPBITS", ip, rp)
      $OUT[1] = ok AND (ip == 0) AND (rp == 0.0)
      ip = 7
      ok = GetSysState("NOSUCH", ip, rp)
      $OUT[2] = (NOT ok) AND (ip == 7)
      ok = GetSysState("NOSUCH", ip, rp)
    END
    """
    for run in both(tmp_path, src):
        assert run.result.reason == "completed", run.result.text
        assert run.io("$OUT[1]") == [(0.0, True)]
        assert run.io("$OUT[2]") == [(0.0, True)]
        assert messages(run) == ['not simulated: GETSYSSTATE("NOSUCH") answers FALSE']   # once


# ------------------------------------------------------------------ system variables not simulated

def _backup(tmp: Path, program: str) -> Path:
    """A minimal KRC backup: R1/System/$config.dat, R1/Mada/$robcor.dat declaring two
    system variables the simulator does not model, and R1/Program/prog.src."""
    for d in ("R1/System", "R1/Mada", "R1/Program"):
        (tmp / d).mkdir(parents=True)
    write(tmp, "R1/System/$config.dat", "DEFDAT $CONFIG\nENDDAT\n")
    write(tmp, "R1/Mada/$robcor.dat", """
    DEFDAT $ROBCOR
    REAL $DEF_L_M=210.000 ;DEFAULTMASSE AM FLANSCH
    INT $TORQMON_DEF[3]
    $TORQMON_DEF[2]=40
    ENDDAT
    """)
    return write(tmp, "R1/Program/prog.src", program)


def _run_backup(prog: Path, interp: str):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, check=False, interp=interp), RunSinks(trace=tw))
    res = rt.run()
    return res, [e["text"] for e in tw.events if e["kind"] == "message"], tw.events, rt


SYS_PROG = """
DEF prog()
  DECL REAL m
  DECL INT t
  m = $DEF_L_M + $DEF_L_M
  t = $TORQMON_DEF[2] + $TORQMON[4]
  $TORQMON[4] = 3
  t = t + $TORQMON[4]
  $OUT[1] = (m == 420.0) AND (t == 43)
  t = $NO_SUCH_VARIABLE
END
"""


def test_declared_system_variable_reads_its_declared_value_with_one_note(tmp_path):
    prog = _backup(tmp_path, SYS_PROG)
    out = []
    for interp in INTERPS:
        res, notes, events, rt = _run_backup(prog, interp)
        out.append(events)
        assert rt.program.backup
        # 210 + 210 = 420; 40 (declared in $robcor.dat) + 0 (KSS's $TORQMON, no value) + 3 = 43
        assert rt.controller.io.get_out(1), (interp, res.text, notes)
        assert notes == [
            "not simulated: system variable $DEF_L_M reads its value declared at R1/Mada/$robcor.dat:2",
            "not simulated: system variable $TORQMON_DEF reads its value declared at R1/Mada/$robcor.dat:3",
            "not simulated: system variable $TORQMON (declared by KSS's system files, not by this "
            "program's): reads 0/FALSE",
            # a $ name no table lists: the checker's W107 (the controller's: programs cannot declare
            # $ names); the run follows it (issue 46): INT from `t = ...`, its zero value, one note
            "stub: $NO_SUCH_VARIABLE (system variable of KUKA's system software not in the backup: "
            "a system variable of the controller that the platform tables do not list): reads 0",
        ]
        assert (res.reason, rt.controller.io.get_out(1)) == ("completed", True)
    assert out[0] == out[1]


def test_undeclared_system_variable_stands_in_outside_a_backup_too(tmp_path):
    """The checker's W107 outside a backup too (krl/semantics/outside.py decides the same in
    any folder): the value written is kept, and read back."""
    src = """
    DEF prog()
      $NO_SUCH_VARIABLE = 5
      $OUT[1] = $NO_SUCH_VARIABLE == 5
    END
    """
    for run in both(tmp_path, src):
        assert run.result.reason == "completed", run.result.text
        assert ("$OUT[1]", True) in [(e["signal"], e["value"]) for e in run.kinds("io")]
        assert messages(run) == ["stub: $NO_SUCH_VARIABLE (system variable of KUKA's system software not in "
                                 "the program's files: a system variable of the controller that the platform tables do "
                                 "not list): reads 0"]


# ------------------------------------------------------------------ submit errors in the report

def test_submit_errors_are_in_the_real_programs_row_and_report(tmp_path):
    sub = """
    DEF sps()
      DECL INT k
      k = 0
      k = 10 / k
    END
    """
    src = """
    DEF prog()
      WAIT SEC 0.1
    END
    """
    for interp in INTERPS:
        run = run_krl(tmp_path, src, files={"sps.sub": sub}, submit=["sps.sub"], interp=interp)
        assert run.result.reason == "completed"
        errs = rp.submit_errors(run.rt)
        assert len(errs) == 1 and errs[0].startswith("sps: ") and errs[0].endswith(f"{tmp_path / 'sps.sub'}:4")
    rows = [{"program": "a", "reason": "completed", "text": "", "submit": errs},
            {"program": "b", "reason": "completed", "text": "", "submit": []}]
    text = rp.report(rows)
    assert "Submit-interpreter errors: 1 of 2 runs:" in text


# ------------------------------------------------------------------ $POS_ACT and $IPO_MODE = #TCP

FRAMES_DAT = """
DEFDAT prog
  DECL E6POS p
  DECL E6POS q
  DECL E6POS r
  DECL E6AXIS ax
ENDDAT
"""

# The tool-down pose of robot-model.md §7's worked example: the flange at {X 445, Y 0, Z 810}
# with the rotation diag(-1, 1, -1) (A 180, B 0, C 180).
FRAMES_SRC = """
DEF prog()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0, E1 0, E2 0, E3 0, E4 0, E5 0, E6 0}
  $TOOL = {X 0, Y 0, Z 225, A 0, B 0, C 0}
  $BASE = {X 500, Y 0, Z 0, A 90, B 0, C 0}
  p = $POS_ACT
  PTP $POS_ACT
  ax = $AXIS_ACT
  $IPO_MODE = #TCP
  q = $POS_ACT
  q.Z = q.Z - 50
  LIN q
  r = $POS_ACT
END
"""


def _pose(v) -> list[float]:
    return [v.f[k] for k in ("X", "Y", "Z", "A", "B", "C")]


def test_pos_act_is_in_the_frames_just_set_and_ptp_pos_act_does_not_move(tmp_path):
    for run in both(tmp_path, FRAMES_SRC, FRAMES_DAT):
        assert run.result.reason == "completed", run.result.text
        # TCP in WORLD (445, 0, 810 - 225 = 585); in $BASE (origin (500, 0, 0), x = world +Y,
        # y = world -X): (0, 55, 585); rotation Rz(-90)·diag(-1, 1, -1) = A 90, B 0, C 180
        assert _pose(run.var("prog", "p")) == pytest.approx([0.0, 55.0, 585.0, 90.0, 0.0, 180.0], abs=1e-6)
        ax = run.var("prog", "ax")
        assert [ax.f[k] for k in ("A1", "A2", "A3", "A4", "A5", "A6")] == \
            pytest.approx([0.0, -90.0, 90.0, 0.0, 90.0, 0.0], abs=1e-6)


def test_external_tcp_pose_and_linear_motion(tmp_path):
    for run in both(tmp_path, FRAMES_SRC, FRAMES_DAT):
        # #TCP: $TOOL = workpiece on the flange, $BASE = fixed tool in WORLD;
        # P = INV_POS(FLANGE : $TOOL) : $BASE. FLANGE : $TOOL = (445, 0, 585), R_w = diag(-1, 1, -1);
        # R_w^T ((500, 0, 0) - (445, 0, 585)) = (-55, 0, 585); R_w^T Rz(90) = A 90, B 0, C 180
        assert _pose(run.var("prog", "r"))[:3] == pytest.approx([-55.0, 0.0, 535.0], abs=1e-4)
        assert _pose(run.var("prog", "r"))[3:] == pytest.approx([90.0, 0.0, 180.0], abs=1e-4)
        # FLANGE = $BASE : INV_POS(P2) : INV_POS($TOOL): (500,0,0) + Rz(90)(0, 55, 535) = (445, 0, 535),
        # then 225 mm up along -z of diag(-1, 1, -1): the flange at (445, 0, 760), 50 mm lower
        q = run.rt.controller.actual.axis_act()
        F = run.rt.controller.model.tcp(q, np.eye(4), np.eye(4))
        assert F[:3, 3] == pytest.approx([445.0, 0.0, 760.0], abs=1e-4)
        assert F[:3, :3] == pytest.approx(np.diag([-1.0, 1.0, -1.0]), abs=1e-6)
        # P moves on a straight line with a constant rotation, so the flange does too: from
        # (445, 0, 810) straight down to (445, 0, 760), passing through every IPO cycle's pose
        [t0] = [e["t"] for e in run.events if e["kind"] == "motion" and e["type"] == "LIN" and e["phase"] == "start"]
        path = [run.rt.controller.model.tcp(np.array(e["axes"]), np.eye(4), np.eye(4))[:3, 3]
                for e in run.events if e["kind"] == "pose" and e["t"] >= t0]
        assert len(path) > 10
        for xyz in path:
            assert xyz[:2] == pytest.approx([445.0, 0.0], abs=1e-3) and 760.0 - 1e-3 <= xyz[2] <= 810.0 + 1e-3


def test_inverse_gives_the_axes_of_a_pose_and_a_status_when_out_of_reach(tmp_path):
    dat = """
    DEFDAT prog
      DECL E6AXIS ax
      DECL E6AXIS far
      DECL INT st1
      DECL INT st2
    ENDDAT
    """
    src = """
    DEF prog()
      DECL E6AXIS start
      DECL E6POS p
      start = {A1 10, A2 -80, A3 80, A4 0, A5 80, A6 0, E1 0, E2 0, E3 0, E4 0, E5 0, E6 0}
      $TOOL = {X 0, Y 0, Z 225, A 0, B 0, C 0}
      $BASE = {X 500, Y 0, Z 0, A 90, B 0, C 0}
      p = {X 0, Y 55, Z 585, A 90, B 0, C 180}
      st1 = -1
      ax = INVERSE(p, start, st1)
      p.X = 5000
      st2 = -1
      far = INVERSE(p, start, st2)
    END
    """
    for run in both(tmp_path, src, dat):
        assert run.result.reason == "completed", run.result.text
        # robot-model.md §7: this pose in these frames is the tool-down pose {0, -90, 90, 0, 90, 0}
        ax = run.var("prog", "ax")
        assert [ax.f[k] for k in ("A1", "A2", "A3", "A4", "A5", "A6")] == \
            pytest.approx([0.0, -90.0, 90.0, 0.0, 90.0, 0.0], abs=1e-6)
        assert run.var("prog", "st1") == 0
        # 5 m away: not reachable, STATUS 3, the result is START_AXIS
        far = run.var("prog", "far")
        assert run.var("prog", "st2") == 3
        assert [far.f[k] for k in ("A1", "A2", "A3")] == [10.0, -80.0, 80.0]


def test_inverse_follows_a_changed_tool_and_base_between_calls(tmp_path):
    """INVERSE keeps $TOOL's inverse and $BASE's matrix between calls (issue 86: a status/turn
    search calls it 512 times a point with the same frames); a changed $TOOL or $BASE counts at
    once. By hand (the test above): $TOOL Z 225 and P Z 585 put the flange where the tool-down pose
    {0, -90, 90, 0, 90, 0} has it; a tool 100 mm shorter reaches that flange from P 100 mm higher
    (the tool points down), and a $BASE 100 mm lower from P 100 mm higher again."""
    dat = """
    DEFDAT prog
      DECL E6AXIS ax1
      DECL E6AXIS ax2
      DECL E6AXIS ax3
      DECL E6AXIS ax4
      DECL INT st
    ENDDAT
    """
    src = """
    DEF prog()
      DECL E6AXIS start
      DECL E6POS p
      start = {A1 10, A2 -80, A3 80, A4 0, A5 80, A6 0, E1 0, E2 0, E3 0, E4 0, E5 0, E6 0}
      $TOOL = {X 0, Y 0, Z 225, A 0, B 0, C 0}
      $BASE = {X 500, Y 0, Z 0, A 90, B 0, C 0}
      p = {X 0, Y 55, Z 585, A 90, B 0, C 180}
      ax1 = INVERSE(p, start, st)
      $TOOL = {X 0, Y 0, Z 125, A 0, B 0, C 0}
      ax2 = INVERSE(p, start, st)
      p.Z = 685
      ax3 = INVERSE(p, start, st)
      $BASE = {X 500, Y 0, Z -100, A 90, B 0, C 0}
      p.Z = 785
      ax4 = INVERSE(p, start, st)
    END
    """
    for run in both(tmp_path, src, dat):
        assert run.result.reason == "completed", run.result.text
        axes = {n: [run.var("prog", n).f[k] for k in ("A1", "A2", "A3", "A4", "A5", "A6")]
                for n in ("ax1", "ax2", "ax3", "ax4")}
        for n in ("ax1", "ax3", "ax4"):
            assert axes[n] == pytest.approx([0.0, -90.0, 90.0, 0.0, 90.0, 0.0], abs=1e-6), n
        assert axes["ax2"][2] != pytest.approx(90.0, abs=1e-3)      # the flange 100 mm lower: another pose


# ------------------------------------------------------------------ $IN_HOME, machine-data signals

HOME_PROG = """
DEF prog()
  $OUT[1] = $IN_HOME                 ; the KR 6 starts at $H_POS = $AXIS_HOME[1] = {0,-90,90,0,0,0}
  $OUT[2] = $IN_HOME1
  PTP {A1 1.5, A2 -90, A3 90, A4 0, A5 0, A6 0}   ; a complete first target (BCO)
  WAIT SEC 0                         ; the advance run waits: $IN_HOME reads the robot at rest
  $OUT[3] = $IN_HOME                 ; 1.5 deg off, within $H_POS_TOL = 2 deg
  PTP {A1 -2.5}
  WAIT SEC 0
  $OUT[4] = $IN_HOME                 ; 2.5 deg off: outside
  $OUT[5] = $IN_HOME3                ; $AXIS_HOME[3] with $H_AXIS_TOL[3] = 2 deg: outside
  $H_POS_TOL.A1 = 3.0
  $OUT[6] = $IN_HOME                 ; the window is 3 deg now
  $H_AXIS_TOL[3].A1 = 2.6
  $OUT[7] = $IN_HOME3
  $H_POS.A1 = -2.5
  $H_POS_TOL.A1 = 0.1
  $OUT[8] = $IN_HOME                 ; the home position moved to the robot
  $H_POS.A5 = 10.0
  $OUT[9] = $IN_HOME                 ; every axis counts: A5 is 10 deg off
END
"""


def test_in_home_is_the_robot_within_the_home_window(tmp_path):
    """$IN_HOME: |$AXIS_ACT.Ai - $H_POS.Ai| <= $H_POS_TOL.Ai for A1..A6; $IN_HOMEn the same
    with $AXIS_HOME[n] and $H_AXIS_TOL[n] (2 deg by default, every backup's machine data)."""
    for run in both(tmp_path, HOME_PROG):
        assert run.result.reason == "completed", run.result.text
        got = {n: [v for _, v in run.io(f"$OUT[{n}]")] for n in range(1, 10)}
        assert got == {1: [True], 2: [True], 3: [True], 4: [], 5: [], 6: [True], 7: [True],
                       8: [True], 9: []}, got


def _steu_backup(tmp: Path) -> Path:
    """A backup whose STEU/Mada/$machine.dat wires system signals to I/O, as KUKA's does
    (HugoDanielson__ChinaMilling/KRC/STEU/Mada/$machine.dat:20-89)."""
    prog = _backup(tmp, """
    DEF prog()
      $OUT[1] = $I_O_ACT
      $OUT[2] = $I_O_ACTCONF
      $OUT[3] = $MOVE_ENABLE
    END
    """)
    (tmp / "STEU" / "Mada").mkdir(parents=True)
    write(tmp, "STEU/Mada/$machine.dat", """
    DEFDAT $MACHINE PUBLIC
    SIGNAL $MOVE_ENABLE $IN[13] ;FAHRFREIGABE GESAMT
    SIGNAL $I_O_ACTCONF $OUT[15] ;E/A-SCHNITTSTELLE AKTIV QUITTUNG
    SIGNAL $I_O_ACT $IN[11] ;E/A-SCHNITTSTELLE AKTIV
    ENDDAT
    """)
    return prog


def test_machine_data_signal_wiring_is_no_value(tmp_path):
    """`SIGNAL $I_O_ACT $IN[11]` of the machine data does not copy the input's state at load
    time (FALSE) into $I_O_ACT: the system signals keep their boot values (TRUE), so in
    Automatic External $I_O_ACTCONF is TRUE (docs/robot.md, Presets)."""
    prog = _steu_backup(tmp_path)
    events = []
    for interp in INTERPS:
        tw = TraceWriter(keep=True)
        rt, _ = make_runtime(run_spec(prog, mujoco=False, check=False, interp=interp, mode="EXT"), RunSinks(trace=tw))
        res = rt.run()
        assert res.reason == "completed", res.text
        assert [rt.controller.io.get_out(n) for n in (1, 2, 3)] == [True, True, True], interp
        events.append(tw.events)
    assert events[0] == events[1]


def test_a_target_out_of_the_robots_limits_says_so(tmp_path):
    """A LIN to the pose of {0,-90,90,0,125,0} (KR 6 R900: A5 within +-120; every configuration
    of that pose has |A5| >= 125, tests/robot/test_controller.py) is refused at planning with
    the note that the target itself is out; a PTP to A1 200 (limit 170) is an axis target: the
    plain message."""
    x, y, z, a, b, c = matrix_to_frame(Kinematics().forward([0, -90, 90, 0, 125, 0]))
    src = f"""
    DEF prog()
      PTP {{A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}}
      LIN {{X {x:.4f}, Y {y:.4f}, Z {z:.4f}, A {a:.4f}, B {b:.4f}, C {c:.4f}}}
    END
    """
    for run in both(tmp_path, src):
        assert (run.result.reason, run.result.line) == ("error", 3)
        # A5 past +120 or -120, as the configuration the planner tries: the sign is its choice
        assert run.result.text in (f"software limit switch {s}A5 ({TARGET_OUTSIDE_NOTE})" for s in "+-")
    src = """
    DEF prog()
      PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
      PTP {A1 200}
    END
    """
    for run in both(tmp_path, src):
        assert (run.result.reason, run.result.text) == ("error", "software limit switch +A1")
