"""External axes seen by the program (issue 64): on the real machine data of a KR C4 with one
linear external axis (../shared/robots/kr210r2700_2_e1: ``$EX_AX_NUM=1``, ``$EX_KIN={ET1
#EASYS}``), a program reads E1 through ``$AXIS_ACT`` and ``$POS_ACT`` as the trace shows it,
starts at XHOME's E1 (10.376, the unseen backup's value the issue quotes), reads ``$EX_AX_NUM``,
``$NUM_AX`` and E1's software limits, and E1 moves synchronously in PTP and LIN; the same on
the tree interpreter and the VM."""

from __future__ import annotations

from pathlib import Path

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from robot.mada import load_robot
from robot.trace import TraceWriter
from tests.interp.helpers import Run, write


E1_MADA = Path(__file__).resolve().parents[2].parent / "shared" / "robots" / "kr210r2700_2_e1" / "$machine.dat"

SRC = """
DEF e1prog()
  start_e1 = $AXIS_ACT.E1
  start_pos_e1 = $POS_ACT.E1
  ex_num = $EX_AX_NUM
  num_ax = $NUM_AX
  e1_max = $SOFTP_END[7]
  PTP {A1 10, A2 -80, A3 90, A4 0, A5 30, A6 0, E1 250}
  ptp_e1 = $AXIS_ACT.E1
  ptp_t = $POS_ACT
  LIN_REL {X 100, Z -50, E1 -150}
  lin_e1 = $AXIS_ACT.E1
  lin_pos_e1 = $POS_ACT.E1
  IF $AXIS_ACT.E1 < 99.0 THEN
    HALT
  ENDIF
END
"""
DAT = """
DEFDAT e1prog
  DECL E6AXIS XHOME={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 0.0,A6 0.0,E1 10.376,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
  REAL start_e1, start_pos_e1, ptp_e1, lin_e1, lin_pos_e1, e1_max
  INT ex_num, num_ax
  DECL E6POS ptp_t
ENDDAT
"""


@pytest.fixture(scope="module")
def e1_mada() -> Path:
    if not E1_MADA.exists():
        pytest.skip("../shared/robots/kr210r2700_2_e1 is not present")
    return E1_MADA


def _poses(run):
    return [(e["t"], e["axes"]) for e in run.events if e["kind"] == "pose"]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_program_reads_e1_as_the_trace_shows_it(tmp_path, e1_mada, interp):
    machine = load_robot(e1_mada)
    run = _run(tmp_path, machine, interp)
    assert run.result.reason == "completed", run.result
    v = lambda name: run.var("e1prog", name)     # noqa: E731
    assert (v("ex_num"), v("num_ax"), v("e1_max")) == (1, 6, 360.0)
    assert v("start_e1") == pytest.approx(10.376, abs=1e-9)      # XHOME's E1, not 0
    assert v("start_pos_e1") == pytest.approx(10.376, abs=1e-9)
    poses = _poses(run)
    assert poses[0][1][6] == pytest.approx(10.376, abs=1e-9)       # the trace starts there too
    # after the PTP and the LIN the robot stands still: the read equals the trace's last pose
    assert v("ptp_e1") == pytest.approx(250.0, abs=1e-6)
    assert v("lin_e1") == pytest.approx(100.0, abs=1e-6)
    assert v("lin_pos_e1") == pytest.approx(100.0, abs=1e-6)
    assert poses[-1][1][6] == pytest.approx(v("lin_e1"), abs=1e-6)
    # E1 moved synchronously: it left 10.376 with the arm and arrived at 250 when the arm did
    motions = [e for e in run.events if e["kind"] == "motion"]
    start = next(e["t"] for e in motions if e["id"] == 1 and e["phase"] == "start")
    # until the cycle the interpolation ended (END comes 24-36 ms later, robot/exactstop.py)
    end = next(e["reached"] for e in motions if e["id"] == 1 and e["phase"] == "end")
    during = [q for t, q in poses if start < t < end + 0.012 - 1e-6]
    assert all(10.376 < q[6] < 250.0 for q in during[1:-1])
    a5 = [q[4] for q in during]
    e1 = [q[6] for q in during]
    # the same normalised profile on both axes (a PTP moves every axis on one time law)
    for x, y in zip(a5, e1):
        assert x / 30.0 == pytest.approx((y - 10.376) / (250.0 - 10.376), abs=1e-6)   # trace: 6 decimals


def _run(tmp_path, machine, interp):
    prog = write(tmp_path, "e1prog.src", SRC)
    write(tmp_path, "e1prog.dat", DAT)
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, max_sim_time=60.0, mujoco=False, check=False, interp=interp,
                         robot=machine, start="XHOME"), RunSinks(trace=tw))
    return Run(rt, rt.run(), tw)


FWD_SRC = """
DEF fwd()
  DECL E6AXIS ax
  DECL E6POS p
  DECL INT st
  ax = {A1 10, A2 -80, A3 90, A4 0, A5 30, A6 0, E1 123.5}
  p = FORWARD(ax, st)
  fwd_e1 = p.E1
  p.E1 = 77.25
  ax = INVERSE(p, $AXIS_ACT, st)
  inv_e1 = ax.E1
  inv_a5 = ax.A5
  inv_st = st
END
"""
FWD_DAT = """
DEFDAT fwd
  REAL fwd_e1, inv_e1, inv_a5
  INT inv_st
ENDDAT
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_forward_and_inverse_carry_the_external_axes(tmp_path, e1_mada, interp):
    """FORWARD's E6POS has the E6AXIS's E1; INVERSE's E6AXIS has the E6POS's E1 (KSS operate.dat
    declares both over E6 types: the external axes pass through the robot's kinematics)."""
    prog = write(tmp_path, "fwd.src", FWD_SRC)
    write(tmp_path, "fwd.dat", FWD_DAT)
    rt, _ = make_runtime(run_spec(prog, max_sim_time=10.0, mujoco=False, check=False, interp=interp,
                         robot=load_robot(e1_mada)))
    run = Run(rt, rt.run(), None)
    assert run.result.reason == "completed", run.result
    assert run.var("fwd", "fwd_e1") == 123.5
    assert (run.var("fwd", "inv_e1"), run.var("fwd", "inv_st")) == (77.25, 0)
    assert run.var("fwd", "inv_a5") == pytest.approx(30.0, abs=1e-9)
