"""The submit interpreter beside a moving robot whose motion it reads (issue 86 item 2;
interp/runtime/spin.py, "Woken"): a pass whose reads did not change since the pass it repeats
writes what it wrote, the robot moving or not, and ``$PRO_MOVE``, ``$ACT_ADVANCE``, ``$POS_ACT``,
``$VEL_ACT`` are reads like any other. A pass that reads ``$PRO_MOVE`` stays parked while the
robot moves (the value is TRUE from the motion's start to its end); one that reads ``$POS_ACT``
is woken at every cycle the robot moves, its catch-up reading the position its steps read when
they ran. Until 2026-11-28 a pass that read any of them was never parked while the robot moved.

Each run is made with the spin watch and without it (tests/interp/helpers.py ``same_run``): the
I/O log (time, signal, value, source), the end and the steps must be the same, no catch-up may
leave its pass and no change be missed."""

from __future__ import annotations

import pytest

from interp.run import make_runtime, run_spec
from interp.runtime.core import run_cycles
from interp.runtime.scheduler import SUBMIT_BUDGET

from .helpers import same_run, write

INTERPS = ("tree", "vm")

#: three moves, each followed by half a second at rest: the robot moves, stands, moves, stands
PROG = """
DEF prog()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
  WAIT SEC 0.5
  PTP {A1 40, A2 -70, A3 80, A4 0, A5 30, A6 0}
  WAIT SEC 0.5
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
  WAIT SEC 0.5
  MOVES = 3
END
"""

DAT = """
DEFDAT prog PUBLIC
  DECL GLOBAL INT MOVES = 0
ENDDAT
"""

#: reads whether the robot moves and how many motions are planned: steady while it moves
SPS_STATE = """
DEF sps()
  LOOP
    WAIT FOR NOT($POWER_FAIL)
    $OUT[20] = $PRO_MOVE
    $OUT[21] = $ACT_ADVANCE > 0
    $OUT[22] = MOVES == 3
  ENDLOOP
END
"""

#: reads the axes, the TCP's position and speed: changes at every cycle the robot moves
SPS_POS = """
DEF sps()
  DECL REAL X
  LOOP
    X = $POS_ACT.X
    IF $AXIS_ACT.A1 > 20.0 THEN
      $OUT[23] = TRUE
    ELSE
      $OUT[23] = FALSE
    ENDIF
    $OUT[24] = $VEL_ACT > 0.1
  ENDLOOP
END
"""


def _rises(log, name: str) -> list:
    return [round(t, 3) for t, n, v, _s in log if n == name and v]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_that_reads_pro_move_stays_parked_while_the_robot_moves(tmp_path, interp):
    rt, res = same_run(tmp_path, PROG, SPS_STATE, DAT, interp, max_sim_time=20.0)
    assert res.reason == "completed"
    log = rt.controller.io.log
    # $PRO_MOVE rises at each of the three motions' start and falls at its end, a WAIT SEC 0.5 apart
    falls = [round(t, 3) for t, n, v, _s in log if n == "$OUT[20]" and not v]
    rises = _rises(log, "$OUT[20]")
    assert len(rises) == 3 and len(falls) == 3
    assert all(0.5 <= r2 - f1 <= 0.6 for f1, r2 in zip(falls, rises[1:]))     # (WAIT SEC 0.5, then planned)
    assert _rises(log, "$OUT[22]") == [pytest.approx(res.sim_time, abs=0.013)]
    # parked beside the moving robot: most of the submit task's steps in the cycles the robot
    # moved in (from each rise of $PRO_MOVE to its fall) were counted, not run
    moving = sum(f - r for r, f in zip(rises, falls)) / 0.012 * rt.scheduler.tasks[1].budget
    assert rt.ff.spin.moving > 0.8 * moving, (rt.ff.spin.moving, moving)


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_that_reads_the_position_is_the_same_as_run(tmp_path, interp):
    rt, res = same_run(tmp_path, PROG, SPS_POS, DAT, interp, max_sim_time=20.0)
    assert res.reason == "completed"
    log = rt.controller.io.log
    # A1 goes 0 -> 40 -> 0: past 20 once; $VEL_ACT > 0.1 on each of the three moves
    assert len(_rises(log, "$OUT[23]")) == 1
    assert len(_rises(log, "$OUT[24]")) == 3


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_that_reads_the_position_parks_again_after_its_first_pass_of_the_cycle(tmp_path, interp):
    """Within one IPO cycle the position stands, so after the pass that reads its new value the
    next pass repeats it: the woken task is recorded again in that time slice and parks for the
    rest of it (SpinWatch._again), where it used to run the whole slice (SUBMIT_BUDGET steps,
    every cycle the robot moves). Measured cycle by cycle (run_cycles yields after each): in the
    cycles whose step and the step before moved the robot, most run under a third of the slice."""
    p = write(tmp_path, "prog.src", PROG)
    write(tmp_path, "prog.dat", DAT)
    s = write(tmp_path, "sps.sub", SPS_POS)
    rt, _ = make_runtime(run_spec(p, max_sim_time=20.0, max_steps=10**7, mujoco=False, submit=[s], check=False,
                                  interp=interp))
    ctl, budget = rt.controller, SUBMIT_BUDGET
    ran, moved = [], []
    before = rt.ff.executed()
    for _ in run_cycles(rt):
        now = rt.ff.executed()
        moved.append(not (ctl._q is ctl._q_prev or (ctl._q == ctl._q_prev).all()))
        ran.append(now - before)
        before = now
    assert rt.result.reason == "completed"
    woken = [n for i, n in enumerate(ran) if i and moved[i] and moved[i - 1]]
    assert len(woken) > 50            # (three PTPs of about 0.4 s each)
    assert sum(n < budget / 3 for n in woken) > 0.9 * len(woken), sorted(woken)[len(woken) // 2]
