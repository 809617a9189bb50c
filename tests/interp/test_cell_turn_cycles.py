"""What a turn of a cell's robot skips (issue 89, interp/cellturns.py).

A held run (a robot of a cell) yields None after a cycle the turn takes without a look
(interp/runtime/scheduler.py ``Scheduler.cycles``): here each such cycle is checked against what
the turn would have read after it, read independently before and after the cycle (the task's
statements run, its wait, the plain test's parts, the main run's motions).
"""

from __future__ import annotations

import pytest

from interp.cellturns import _parts
from interp.run import RunSinks, make_runtime, run_setup
from interp.runtime.core import run_cycles
from interp.runtime.scheduler import RAN

# two PTPs and a LIN in a loop (tools/cell_bench.py's moving robot), an output set in between
MOVE = """DEF mover()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
  LOOP
    PTP {A1 30, A2 -80, A3 100, A4 0, A5 45, A6 0} C_PTP
    $OUT[3] = NOT $OUT[3]
    LIN {X 500, Y 100, Z 700, A 0, B 90, C 0}
    PTP {A1 -30, A2 -95, A3 85, A4 10, A5 30, A6 0}
  ENDLOOP
END
"""
def _seen(rt) -> tuple:
    """What a turn reads of run `rt` after a cycle: the statements run so far, the robot task's
    wait, the plain test's four parts (interp/cellturns.py ``plain``), and the main run's motions
    (the list itself, compared by identity: the controller replaces it, never changes one in
    place)."""
    scheduler, team, monitor, net = _parts(type("Run", (), {"runtime": rt})())
    return (rt.clock.steps, rt.robot.waiting, scheduler.blocked, team.at, monitor.workspaces,
            getattr(net, "polling", False)), rt.controller._runs


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_held_run_yields_none_only_after_a_cycle_that_changed_nothing_a_turn_reads(tmp_path, interp):
    """60 s of a moving robot held as a cell's: after every cycle yielded None the run's statement
    count, its wait, its plain test's parts and its main run's motions are as before the cycle
    (so after every cycle that changed one of them, RAN). Most cycles are None (the turn's steady
    cycles), and RAN comes both after cycles that ran statements and after cycles in which only
    the motions changed."""
    (tmp_path / "mover.src").write_text(MOVE, encoding="utf-8")
    with run_setup({"program": tmp_path / "mover.src", "interp_kind": interp, "max_sim_time": 60.0,
                    "no_submit": True}) as setup:
        rt, _ = make_runtime(setup.spec, RunSinks())
        rt.scheduler.hold()
        cycles = run_cycles(rt)
        kinds = {"none": 0, "statements": 0, "motions only": 0, "offers": 0}
        before, runs = _seen(rt)
        got = next(cycles)
        while True:
            if type(got) is int:            # an offer to jump (the robot stands): an ordinary cycle
                kinds["offers"] += 1
                got = cycles.send(0)
                continue
            now, now_runs = _seen(rt)
            if got is None:
                assert now == before and now_runs is runs
                kinds["none"] += 1
            else:
                assert got is RAN
                if now[0] != before[0]:
                    kinds["statements"] += 1
                elif now_runs is not runs:
                    kinds["motions only"] += 1
            before, runs = now, now_runs
            got = next(cycles, StopIteration)
            if got is StopIteration:
                break
    assert rt.controller.cycle == 5000
    assert kinds["none"] > 0.8 * 5000 and kinds["statements"] > 10 and kinds["motions only"] > 50, kinds
