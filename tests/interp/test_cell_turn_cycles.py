"""What a turn of a cell's robot skips and how long a turn is (issue 89, interp/cellturns.py,
interp/robotcell.py ``run_cell``).

A held run (a robot of a cell) yields None after a cycle the turn takes without a look
(interp/runtime/scheduler.py ``Scheduler.cycles``): here each such cycle is checked against what
the turn would have read after it, read independently before and after the cycle (the task's
statements run, its wait, the plain test's parts, the main run's motions); and the turns' lengths
are read from the calls of ``take_turns``: 1,024 cycles first, twice as long after a turn every
robot ran through, up to 4,096, and 1,024 again after a turn a robot cut short.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import interp.robotcell as robotcell
from interp.cellturns import TURN_CYCLES, TURN_CYCLES_MAX, _parts
from interp.robotcell import cell_runs, load_robot_cell, run_cell
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
# a robot that moves some 40 s and then stands in WAIT SEC 30 (it offers the cell to jump: its
# turn stops there)
IDLER = """DEF idler()
  DECL INT I
  LOOP
    FOR I = 1 TO 20
      PTP {A1 20, A2 -90, A3 90, A4 0, A5 0, A6 0}
      PTP {A1 -20, A2 -90, A3 90, A4 0, A5 0, A6 0}
    ENDFOR
    WAIT SEC 30
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


def _cell(folder: Path, programs: dict, spacing: float = 5000.0) -> Path:
    for name, text in programs.items():
        (folder / f"{name.lower()}.src").write_text(text, encoding="utf-8")
    (folder / "cell.yaml").write_text("robots:\n" + "".join(
        f"  {name}: {{program: {name.lower()}.src, no_submit: true, base: [{spacing * k}, 0, 0, 0, 0, 0]}}\n"
        for k, name in enumerate(programs)), encoding="utf-8")
    return folder / "cell.yaml"


def _turns(path: Path, monkeypatch, seconds: float) -> list:
    """Each ``take_turns`` of the cell `path` run for `seconds`: (its turn's cycles, whether a robot
    stopped its turn at an offer)."""
    calls = []
    take = robotcell.take_turns

    def spy(live, turn, ended, watch, pending):
        went = take(live, turn, ended, watch, pending)
        calls.append((turn, bool(pending) or len({item[0].runtime.controller.cycle for item in went}) > 1))
        return went
    monkeypatch.setattr(robotcell, "take_turns", spy)
    cell = load_robot_cell(path)
    with cell_runs(cell, "vm", seconds, mujoco=False) as runs:
        run_cell(cell, runs)
    return calls


def test_turns_double_while_every_robot_runs_through_them(tmp_path, monkeypatch):
    """Two robots moving without a stop for 200 s (16,667 cycles): the turns are 1,024, 2,048,
    then 4,096 cycles each, none cut short."""
    calls = _turns(_cell(tmp_path, {"R1": MOVE, "R2": MOVE.replace("A1 30", "A1 40")}), monkeypatch, 200.0)
    assert (TURN_CYCLES, TURN_CYCLES_MAX) == (1024, 4096)
    assert [turn for turn, _ in calls[:5]] == [1024, 2048, 4096, 4096, 4096]
    assert not any(cut for _, cut in calls[:-1])


def test_a_turn_after_one_cut_short_is_of_the_first_length(tmp_path, monkeypatch):
    """A mover beside a robot that stands 30 s in WAIT SEC after 40 PTPs (it stops its turn at its
    offer to jump): after every turn cut short the next is 1,024 cycles, after every
    turn run through twice the last (up to 4,096); both happen."""
    calls = _turns(_cell(tmp_path, {"R1": MOVE, "R2": IDLER}), monkeypatch, 300.0)
    assert calls[0][0] == TURN_CYCLES
    for (turn, cut), (following, _) in zip(calls, calls[1:]):
        assert following == (TURN_CYCLES if cut else min(2 * turn, TURN_CYCLES_MAX))
    assert any(cut for _, cut in calls) and any(not cut for _, cut in calls[:-1])
