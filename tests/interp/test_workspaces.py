"""KUKA's workspace monitoring (issue 64; robot/workspace.py, interp/runtime/sysvars.py).

Workspaces declared as real machine data declare them: a copy of a corpus backup (khrzysio's KR C4:
its STEU/Mada/$custom.dat holds $WORKSPACE[1..8], its R1/Mada/$machine.dat $AXWORKSPACE[1..8], all
#OFF) with two cartesian workspaces and one axis workspace set active as KUKA's manual describes (a
frame in $WORLD, the box's corners X1..Z2 in it, MODE). Each IPO cycle's $WORKSTATEn/$AXWORKSTATEn is
predicted here by an independent point-in-box computation over the trace's TCP and axes (its own
rotation matrix, written out), and every change in the trace happens at exactly the predicted cycle,
on the tree interpreter and the VM. A program that sets a #INSIDE_STOP workspace at run time stops at
the first IPO cycle inside it, at that motion's line, with the message; a path outside it runs on.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from interp.run import make_runtime, run_spec, RunSinks
from interp.runtime.errors import KrlRuntimeError
from interp.runtime.sysvars import _entries
from robot.trace import TraceWriter
from tests.interp.helpers import Run, write

BACKUP = "khrzysio__KRC4_test"
WS1 = "{X 1600.0,Y 0.0,Z 1400.0,A 20.0,B 0.0,C 10.0,X1 -150.0,Y1 -250.0,Z1 -120.0,X2 150.0,Y2 250.0,Z2 120.0,MODE #INSIDE}"
WS2 = "{X 1500.0,Y -100.0,Z 1350.0,A 0.0,B 15.0,C 0.0,X1 200.0,Y1 100.0,Z1 200.0,X2 -200.0,Y2 -100.0,Z2 -200.0,MODE #OUTSIDE}"
AXWS1 = ("{A1_N -5.0,A1_P 5.0,A2_N 0.0,A2_P 0.0,A3_N 0.0,A3_P 0.0,A4_N 0.0,A4_P 0.0,A5_N 0.0,A5_P 0.0,A6_N 0.0,"
         "A6_P 0.0,E1_N 0.0,E1_P 0.0,E2_N 0.0,E2_P 0.0,E3_N 0.0,E3_P 0.0,E4_N 0.0,E4_P 0.0,E5_N 0.0,E5_P 0.0,E6_N 0.0,"
         "E6_P 0.0,MODE #INSIDE,STATE FALSE}")

PROGRAM = """DEF wsrun()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}
  LIN {X 1900, Y -300, Z 1300, A 180, B 0, C 180}
  LIN {X 1300, Y 300, Z 1500, A 180, B 0, C 180}
  PTP {A1 -20, A2 -80, A3 90, A4 0, A5 80, A6 0}
  LIN {X 1700, Y 0, Z 1200, A 180, B 0, C 180}
END
"""


def box(frame, corners):
    """(inverse rotation, origin, lo, hi) of a box: R = Rz(A) Ry(B) Rx(C) written out (KUKA's ABC)."""
    x, y, z, a, b, c = (float(v) for v in frame)
    ca, sa, cb, sb, cc, sc = (f(math.radians(t)) for t in (a, b, c) for f in (math.cos, math.sin))
    R = np.array([[ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc],
                  [sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc],
                  [-sb, cb * sc, cb * cc]])
    lo = np.minimum(corners[:3], corners[3:])
    hi = np.maximum(corners[:3], corners[3:])
    return R.T, np.array([x, y, z]), lo, hi


def inside(b, p) -> bool:
    Rt, o, lo, hi = b
    q = Rt @ (np.asarray(p, dtype=float) - o)
    return bool(np.all(q >= lo - 1e-6) and np.all(q <= hi + 1e-6))


def make_backup(tmp_path: Path, corpus: Path) -> Path:
    src = corpus / BACKUP
    for rel in ("R1/Mada/$machine.dat", "R1/Mada/$robcor.dat", "R1/System/$config.dat", "STEU/Mada/$custom.dat"):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(src / rel, tmp_path / rel)
    cust = tmp_path / "STEU/Mada/$custom.dat"
    text = cust.read_text(encoding="latin-1")
    off = "{X 0.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0,X1 0.0,Y1 0.0,Z1 0.0,X2 0.0,Y2 0.0,Z2 0.0,MODE #OFF}"
    assert f"$WORKSPACE[1]={off}" in text and f"$WORKSPACE[2]={off}" in text
    text = text.replace(f"$WORKSPACE[1]={off}", f"$WORKSPACE[1]={WS1}").replace(f"$WORKSPACE[2]={off}", f"$WORKSPACE[2]={WS2}")
    cust.write_text(text, encoding="latin-1")
    mada = tmp_path / "R1/Mada/$machine.dat"
    mtext = mada.read_text(encoding="latin-1")
    line = next(ln for ln in mtext.splitlines() if ln.startswith("$AXWORKSPACE[1]="))
    mada.write_text(mtext.replace(line, f"$AXWORKSPACE[1]={AXWS1}"), encoding="latin-1")
    (tmp_path / "R1" / "Program").mkdir()
    return write(tmp_path / "R1" / "Program", "wsrun.src", PROGRAM)


def _run(prog: Path, interp: str, robot=None) -> Run:
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, max_sim_time=60.0, mujoco=False, check=False, interp=interp,
                                  robot=robot), RunSinks(trace=tw))
    return Run(rt, rt.run(), tw)


def _transitions(run: Run, signal: str) -> list[tuple[float, bool]]:
    return [(e["t"], e["value"]) for e in run.events if e["kind"] == "io" and e["signal"] == signal]


def _predicted(poses, test) -> list[tuple[float, bool]]:
    out, state = [], False
    for t, q, tcp in poses:
        v = test(q, tcp)
        if v != state:
            out.append((t, v))
            state = v
    return out


#: make test runs the VM on the backup; the tree interpreter's run of it (the conformance suites hold
#: the two identical; the STOP test below runs both) is in make nightly, about 6 s under load
@pytest.mark.parametrize("interp", ["vm", pytest.param("tree", marks=pytest.mark.slow)])
def test_workstate_follows_the_tcp_cycle_by_cycle(tmp_path, shared_corpus, interp):
    prog = make_backup(tmp_path, shared_corpus)
    run = _run(prog, interp)
    assert run.result.reason == "completed", run.result
    poses = [(e["t"], e["axes"], e["tcp"][:3]) for e in run.events if e["kind"] == "pose"]
    assert len(poses) > 200
    b1 = box((1600, 0, 1400, 20, 0, 10), np.array([-150, -250, -120, 150, 250, 120]))
    b2 = box((1500, -100, 1350, 0, 15, 0), np.array([200, 100, 200, -200, -100, -200]))
    exp1 = _predicted(poses, lambda q, p: inside(b1, p))                  # #INSIDE
    exp2 = _predicted(poses, lambda q, p: not inside(b2, p))              # #OUTSIDE
    exp3 = _predicted(poses, lambda q, p: -5.0 <= q[0] <= 5.0)            # A1 in -5..5, #INSIDE
    # the path enters and leaves each workspace: the prediction is not empty
    assert len(exp1) >= 2 and len(exp2) >= 2 and len(exp3) >= 1, (exp1, exp2, exp3)
    assert _transitions(run, "$WORKSTATE1") == exp1
    assert _transitions(run, "$WORKSTATE2") == exp2
    assert _transitions(run, "$AXWORKSTATE1") == exp3
    # the other workspaces of the backup stay #OFF: no signal of theirs changes
    assert {e["signal"] for e in run.events if e["kind"] == "io"} == {"$WORKSTATE1", "$WORKSTATE2", "$AXWORKSTATE1"}


STOP_SRC = """DEF wsstop()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}
  WAIT SEC 0
  $WORKSPACE[3] = {X 0, Y 0, Z 0, A 0, B 0, C 0, X1 520, Y1 -50, Z1 500, X2 560, Y2 50, Z2 800, MODE #INSIDE_STOP}
  LIN {X 445, Y 200, Z 650, A 180, B 0, C 180}
  LIN {X 650, Y 200, Z 650, A 180, B 0, C 180}
  state_before = $WORKSTATE3 OR $WORKSPACE[3].STATE
  LIN {X 450, Y 0, Z 650, A 180, B 0, C 180}
  LIN {X 650, Y 0, Z 650, A 180, B 0, C 180}
  $OUT[7] = TRUE
END
"""
STOP_DAT = """DEFDAT wsstop
  BOOL state_before = TRUE
ENDDAT
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_an_inside_stop_workspace_set_at_run_time_stops_the_robot(tmp_path, interp):
    prog = write(tmp_path, "wsstop.src", STOP_SRC)
    write(tmp_path, "wsstop.dat", STOP_DAT)
    run = _run(prog, interp)
    assert run.result.reason == "error", run.result
    assert "workspace 3 violated: the robot stopped (#INSIDE_STOP)" in str(run.result.error)
    err = next(e for e in run.events if e["kind"] == "error")
    assert err["line"] == 9                     # the LIN that enters it, not the ones beside it
    assert run.var("wsstop", "state_before") is False
    # the robot stopped at the first IPO cycle whose TCP is inside the box, not later
    b3 = box((0, 0, 0, 0, 0, 0), np.array([520, -50, 500, 560, 50, 800]))
    poses = [(e["t"], e["tcp"][:3]) for e in run.events if e["kind"] == "pose"]
    first = next(i for i, (t, p) in enumerate(poses) if inside(b3, p))
    assert poses[first][0] == err["t"]
    assert all(p == poses[first][1] for _, p in poses[first:])
    assert _transitions(run, "$WORKSTATE3") == [(err["t"], True)]
    assert run.rt.sysvars.lookup("$WORKSPACE").peek().data[2].f["STATE"] is True
    assert not run.io("$OUT[7]")


def test_a_workspace_variable_that_cannot_be_read_is_no_workspace():
    """interp/runtime/sysvars.py catches KrlRuntimeError where a workspace variable's value
    cannot be read (its name was not imported from 0760e46 on: NameError instead)."""

    class Unreadable:
        def peek(self):
            raise KrlRuntimeError("value invalid")

    assert _entries(Unreadable()) == [None] * 8
