"""The robots' own ``$WORKSPACE``s across a cell (issue 89; interp/cellworkspaces.py, docs/cells.md).

Each robot monitors its own workspaces in its own ``$WORLD`` (robot/workspace.py): a cartesian box
with mode ``#INSIDE`` sets ``$WORKSTATEn`` while its TCP is inside. Two robots whose such boxes
overlap in the cell's world, both inside at once, are the conflict the cell reports, with both
programs' lines.

The geometry by hand (tests/interp/test_robotcell.py, ../shared/docs/robot-model.md §9): the
KR 6 R900's flange at HOME (0, -90, 90, 0, 0, 0) is at (525, 0, 890) mm in its world, "tool down"
(A5 90) at (445, 0, 810). R2 stands at X 970 turned 180° about Z, so a point (x, y, z) of its
world is (970 - x, -y, z) in the cell's.

* R1's workspace 1: centred on its HOME flange, X -30..30, Y -30..30, Z -100..30: the cell's
  x 495..555, z 790..920. R1 starts at HOME (inside), waits 1 s, then goes tool down to
  (445, 0, 810): x 445 is outside, so it leaves during that PTP (after 1 s).
* R2's workspace 1: centred on its tool-down flange (445, 0, 810) of its world, +-30 mm: the cell's
  (525, 0, 810), x 495..555, z 780..840. R2 starts at HOME ((525, 0, 890) of its world: x 525 is
  80 mm from 445, outside) and goes tool down at once: it enters during that PTP, before 1 s.
* The two boxes share x 495..555, y -30..30, z 790..840: a conflict from the cycle R2's own
  $WORKSTATE1 rises, R1 at rest (its WAIT SEC), R2 in its PTP (r2.src:3).
* With R1's box Z -30..30 (the cell's z 860..920) the boxes are 20 mm apart: both robots are in
  their own workspace at once, and nothing is reported.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from interp.robotcell import cell_runs, load_robot_cell, robot_trace, run_cell, summary_lines

CELL = """robots:
  R1: {program: r1.src}
  R2: {program: r2.src, base: [970, 0, 0, 180, 0, 0]}
wires:
  - R1 $OUT[1] -> R2 $IN[1]
"""
TOOL_DOWN = "PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}"
R1_BOX = "{X 525, Y 0, Z 890, A 0, B 0, C 0, X1 -30, Y1 -30, Z1 %s, X2 30, Y2 30, Z2 30, MODE %s}"
R2_BOX = "{X 445, Y 0, Z 810, A 0, B 0, C 0, X1 -30, Y1 -30, Z1 -30, X2 30, Y2 30, Z2 30, MODE %s}"


def _run(tmp_path: Path, interp: str, z1: str = "-100", mode1: str = "#INSIDE", mode2: str = "#INSIDE",
         interlock: bool = False):
    (tmp_path / "r1.src").write_text(
        f"DEF r1()\n  $WORKSPACE[1] = {R1_BOX % (z1, mode1)}\n  WAIT SEC 1\n  {TOOL_DOWN}\n"
        "  $OUT[1] = TRUE\nEND\n", encoding="utf-8")
    wait = "  WAIT FOR $IN[1]\n" if interlock else "  WAIT SEC 0\n"
    (tmp_path / "r2.src").write_text(
        f"DEF r2()\n  $WORKSPACE[1] = {R2_BOX % mode2}\n{wait}  {TOOL_DOWN}\nEND\n", encoding="utf-8")
    (tmp_path / "cell.yaml").write_text(CELL, encoding="utf-8")
    cell = load_robot_cell(tmp_path / "cell.yaml")
    with cell_runs(cell, interp, 10.0, trace=tmp_path / "run.jsonl", mujoco=False) as runs:
        res = run_cell(cell, runs)
    states = {}
    for r in res.robots:           # each robot's own monitor: its trace's io events
        events = [json.loads(line) for line in robot_trace(tmp_path / "run.jsonl", r.name).read_text().splitlines()]
        states[r.name] = [(e["t"], e["value"]) for e in events if e.get("kind") == "io" and e.get("signal") == "$WORKSTATE1"]
    return res, states


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_two_robots_in_their_overlapping_workspaces_at_once_are_reported(tmp_path, interp):
    res, states = _run(tmp_path, interp)
    assert res.reason == "completed"
    # each robot's own monitor: R1 inside from the start until its PTP, R2 from its PTP on
    (r1_in, _), (r1_out, _) = states["R1"]
    (r2_in, _), = states["R2"]
    assert [v for _, v in states["R1"]] == [True, False] and states["R2"][0][1] is True
    assert r1_in <= 0.012 and r1_out > 1.0 and r2_in < 1.0
    (c,) = res.conflicts
    assert c.zone == "R1 $WORKSPACE[1], R2 $WORKSPACE[1]"
    assert c.time == pytest.approx(r2_in)
    assert c.first == ("R1", None)                                        # at rest in its WAIT SEC
    assert c.second[0] == "R2" and c.second[1].endswith("r2.src:4")       # its PTP
    assert "conflict   R1 $WORKSPACE[1], R2 $WORKSPACE[1]: R1 (at rest) and R2 (r2.src:4) from" \
        in "\n".join(summary_lines(res, tmp_path))
    assert res.as_json()["conflicts"][0]["robots"][1]["motion"].endswith("r2.src:4")


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_workspaces_that_do_not_overlap_or_an_interlock_give_no_conflict(tmp_path, interp):
    res, states = _run(tmp_path, interp, z1="-30")
    # both robots are in their own workspace at once (R2 enters before R1 leaves) ...
    assert states["R2"][0][0] < states["R1"][1][0]
    assert res.conflicts == []                                            # ... 20 mm apart
    res, states = _run(tmp_path, interp, interlock=True)
    assert states["R2"][0][0] > states["R1"][1][0] and res.conflicts == []


def test_a_workspace_that_is_not_an_occupancy_is_not_shared(tmp_path):
    """#OUTSIDE: the robot's permitted region (violated outside it): not a place it occupies
    (robot/workspace.py's modes); an #INSIDE_STOP box is, and stops its robot (R2 here)."""
    res, _ = _run(tmp_path, "vm", mode2="#OUTSIDE")
    assert res.conflicts == []
    res, _ = _run(tmp_path, "vm", mode2="#INSIDE_STOP")
    (c,) = res.conflicts
    assert c.zone == "R1 $WORKSPACE[1], R2 $WORKSPACE[1]"
    r2 = res.robots[1].runtime.result
    assert "workspace 1 violated" in r2.text and r2.line == 4


CUSTOM_DAT = """&ACCESS RV$
DEFDAT  $CUSTOM PUBLIC
DECL BOX $WORKSPACE[8]
$WORKSPACE[1]={X 525.0,Y 0.0,Z 890.0,A 0.0,B 0.0,C 0.0,X1 -30.0,Y1 -30.0,Z1 -100.0,X2 30.0,Y2 30.0,Z2 30.0,MODE #INSIDE}
ENDDAT
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_workspace_of_the_machine_data_counts_as_the_programs(tmp_path, interp):
    """R1's workspace 1 from its backup's STEU/Mada/$custom.dat (where KSS keeps $WORKSPACE), the
    same box as R1_BOX's: the same conflict as the program's assignment gives."""
    (tmp_path / "r1bk" / "STEU" / "Mada").mkdir(parents=True)
    (tmp_path / "r1bk" / "STEU" / "Mada" / "$custom.dat").write_text(CUSTOM_DAT, encoding="utf-8")
    (tmp_path / "r1bk" / "R1" / "Program").mkdir(parents=True)
    (tmp_path / "r1bk" / "R1" / "Program" / "r1.src").write_text(
        f"DEF r1()\n  WAIT SEC 1\n  {TOOL_DOWN}\nEND\n", encoding="utf-8")
    (tmp_path / "r2.src").write_text(f"DEF r2()\n  $WORKSPACE[1] = {R2_BOX % '#INSIDE'}\n  WAIT SEC 0\n  {TOOL_DOWN}\nEND\n",
                                     encoding="utf-8")
    (tmp_path / "cell.yaml").write_text(
        "robots:\n  R1: {program: r1bk/R1/Program/r1.src, workspace: r1bk}\n"
        "  R2: {program: r2.src, base: [970, 0, 0, 180, 0, 0]}\n", encoding="utf-8")
    cell = load_robot_cell(tmp_path / "cell.yaml")
    with cell_runs(cell, interp, 10.0, mujoco=False) as runs:
        res = run_cell(cell, runs)
    (c,) = res.conflicts
    assert c.zone == "R1 $WORKSPACE[1], R2 $WORKSPACE[1]" and c.first == ("R1", None)
    assert c.second[1].endswith("r2.src:4") and 0.0 < c.time < 1.0
