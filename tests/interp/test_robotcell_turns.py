"""Robots that nothing couples take turns of several IPO cycles (issue 89, interp/cellturns.py):
each robot's end, time and wait, the cell's deadlock and the RoboTeam release are those of the
cycle-by-cycle run (``uncoupled`` patched to False gives that run), on both interpreters.

Expected times by hand: a WAIT SEC t ends in the first IPO cycle (12 ms) at or after t; a cell
whose every running robot is blocked ends them BLOCKED_CYCLES cycles later (interp/robotcell.py).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import interp.robotcell as robotcell
from interp.robotcell import BLOCKED_CYCLES, cell_runs, load_robot_cell, run_cell

EXAMPLES = Path(__file__).resolve().parents[2] / "examples/cells/roboteam"
# R1 turns A1 and then waits for an input nothing drives (blocked: only a partner could set it);
# R2 waits 2 s and ends; then R1 alone is blocked, and the cell ends it
R1 = "DEF r1()\n  PTP {A1 30, A2 -90, A3 90, A4 0, A5 0, A6 0}\n  WAIT FOR $IN[1]\nEND\n"
R2 = "DEF r2()\n  WAIT SEC 2\nEND\n"


def _run(path: Path, interp: str, monkeypatch, turns: bool):
    with monkeypatch.context() as m:
        if not turns:
            m.setattr(robotcell, "uncoupled", lambda *a: False)
        taken = []
        m.setattr(robotcell, "take_turns", lambda *a: taken.append(1) or TAKE(*a))
        cell = load_robot_cell(path)
        with cell_runs(cell, interp, 30.0, mujoco=False) as runs:
            res = run_cell(cell, runs)
    assert bool(taken) is turns
    return res, [(r.name, r.runtime.result.reason, r.runtime.result.sim_time, r.runtime.result.text,
                  r.runtime.result.line, round(r.waited, 6), r.released) for r in res.robots]


TAKE = robotcell.take_turns


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_robot_blocked_in_its_turn_deadlocks_when_the_other_ends_as_cycle_by_cycle(tmp_path, interp, monkeypatch):
    (tmp_path / "r1.src").write_text(R1)
    (tmp_path / "r2.src").write_text(R2)
    (tmp_path / "cell.yaml").write_text("robots:\n  R1: {program: r1.src}\n"
                                        "  R2: {program: r2.src, base: [5000, 0, 0, 0, 0, 0]}\n")
    res, ends = _run(tmp_path / "cell.yaml", interp, monkeypatch, True)
    assert ends == _run(tmp_path / "cell.yaml", interp, monkeypatch, False)[1]
    r1, r2 = (r.runtime.result for r in res.robots)
    assert (r2.reason, r2.sim_time) == ("completed", pytest.approx(2.004))        # 167 cycles: >= 2 s
    assert r1.reason == "deadlock" and r1.line == 3 and "WAIT FOR" in r1.text
    assert r1.sim_time == pytest.approx(r2.sim_time + BLOCKED_CYCLES * 0.012)
    assert res.reason == "deadlock"


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_synchronised_motions_of_robots_far_apart_start_together_as_cycle_by_cycle(tmp_path, interp, monkeypatch):
    """examples/cells/roboteam (docs/cells.md: both end at 3.096 s, R1 waiting 1.008 s for R2)
    with the robots 5 m apart: out of reach, they take turns until one waits at the label."""
    for name in ("r1.src", "r2.src"):
        (tmp_path / name).write_text((EXAMPLES / name).read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "cell.yaml").write_text("robots:\n  R1: {program: r1.src}\n"
                                        "  R2: {program: r2.src, base: [5000, 0, 0, 180, 0, 0]}\n")
    res, ends = _run(tmp_path / "cell.yaml", interp, monkeypatch, True)
    assert ends == _run(tmp_path / "cell.yaml", interp, monkeypatch, False)[1]
    assert [(r.runtime.result.reason, round(r.runtime.result.sim_time, 3)) for r in res.robots] == \
        [("completed", 3.096), ("completed", 3.096)]
    assert round(res.robots[0].waited, 3) == 1.008


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_partner_ending_after_a_motion_in_its_turn_deadlocks_the_blocked_robot_as_cycle_by_cycle(
        tmp_path, interp, monkeypatch):
    """R1 waits 0.05 s, then blocks in WAIT FOR (its turn stops there); R2, 5 m away, ends after a
    PTP in its turn, at its controller's cycle `last`. Cycle by cycle R2 is still running when R1
    reaches `last` and ends in the step after: R1 is deadlocked BLOCKED_CYCLES cycles after R2's
    end, as when R2 ends after a WAIT SEC (above). Before 2026-11-28 the turns deadlocked it one
    cycle early (0.276 s for 0.288 s)."""
    (tmp_path / "r1.src").write_text("DEF r1()\n  WAIT SEC 0.05\n  WAIT FOR $IN[1]\nEND\n")
    (tmp_path / "r2.src").write_text("DEF r2()\n  PTP {A1 10, A2 -90, A3 90, A4 0, A5 0, A6 0}\nEND\n")
    (tmp_path / "cell.yaml").write_text("robots:\n  R1: {program: r1.src}\n"
                                        "  R2: {program: r2.src, base: [5000, 0, 0, 180, 0, 0]}\n")
    res, ends = _run(tmp_path / "cell.yaml", interp, monkeypatch, True)
    assert ends == _run(tmp_path / "cell.yaml", interp, monkeypatch, False)[1]
    r1, r2 = (r.runtime.result for r in res.robots)
    assert r2.reason == "completed" and r1.reason == "deadlock" and r1.line == 3
    assert r1.sim_time == pytest.approx(r2.sim_time + BLOCKED_CYCLES * 0.012)
