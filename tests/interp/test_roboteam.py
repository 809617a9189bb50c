"""KUKA.RoboTeam's synchronised motions (issue 89 item 4; interp/runtime/teamsync.py,
interp/cellsync.py, docs/cells.md "RoboTeam synchronisation").

Expected times are worked out by hand. A CP motion of d mm at $VEL.CP v (m/s) and $ACC.CP a
(m/s²) that reaches v takes d/v + v/a (docs/robot.md "CP": trapezoid, no orientation change
here); two robots that start their motions in the same cycle with the same v and a arrive
(d2 - d1)/v apart, the ramps cancelling: 100 mm at 0.1 m/s is 1.0 s, 83.3 IPO cycles of 12 ms,
so the earlier robot waits 1.0 s to within one cycle.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from interp.cellsync import release_synced
from interp.robotcell import cell_runs, load_robot_cell, robot_trace, run_cell, summary_lines
from interp.run import RunSinks, make_runtime, run_spec
from interp.runtime.teamsync import SyncPoint, TeamSync, sync_point, team_of, text_of
from interp.runtime.values import UNSET
from krl.workspace import check_texts
from robot.trace import TraceWriter

CYCLE = 0.012
START = """  BAS(#INITMOV, 0)
  $TOOL = $NULLFRAME
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}
  $VEL.CP = 0.1
  $ACC.CP = 1.0
"""
# from the tool-down pose (445, 0, 810): R1 moves 50 mm out and R2 150 mm, then both come back
# in a synchronised SLIN ("First": R1 50 mm, R2 150 mm), then both go 50 mm in X in a second one
FIRST = "WITH $SYNC_ID[] = \"First\", $SYNC_LIST = 'B0011'"
SECOND = "WITH $Sync_Id[] = \"Second\", $Sync_List = 'B0011'"


def _program(name: str, out_mm: int, first: str = FIRST, second: str = SECOND) -> str:
    return (f"DEF {name}()\n{START}  SLIN {{Y {out_mm}}}\n  SLIN {{Y 0}} {first}\n"
            f"  SLIN {{X 495}} {second}\nEND\n")


def _cell(tmp_path: Path, r1: str, r2: str) -> Path:
    (tmp_path / "r1.src").write_text(r1, encoding="utf-8")
    (tmp_path / "r2.src").write_text(r2, encoding="utf-8")
    path = tmp_path / "cell.yaml"
    path.write_text("robots:\n  R1: {program: r1.src}\n  R2: {program: r2.src}\n", encoding="utf-8")
    return path


def _run(path: Path, interp: str):
    cell = load_robot_cell(path)
    trace = path.parent / "run.jsonl"
    with cell_runs(cell, interp, 20.0, trace=trace, mujoco=False) as runs:
        res = run_cell(cell, runs)
    motions = {}
    for r in res.robots:
        events = [json.loads(x) for x in robot_trace(trace, r.name).read_text(encoding="utf-8").splitlines()]
        motions[r.name] = {(e["line"], e["phase"]): e["t"] for e in events if e["kind"] == "motion"}
    return res, motions


def test_two_synchronised_slins_start_in_the_same_ipo_cycle_on_both_interpreters(tmp_path):
    path = _cell(tmp_path, _program("r1", 50), _program("r2", 150))
    runs = {interp: _run(path, interp) for interp in ("tree", "vm")}
    for interp, (res, m) in runs.items():
        _assert_synchronised(res, m, tmp_path)
    (tree, mt), (vm, mv) = runs["tree"], runs["vm"]
    assert mt == mv                                                  # robot by robot, motion by motion
    assert [(r.runtime.result.reason, r.waited) for r in tree.robots] == \
        [(r.runtime.result.reason, r.waited) for r in vm.robots]


def _assert_synchronised(res, m, tmp_path: Path) -> None:
    assert res.reason == "completed", summary_lines(res)
    r1, r2 = m["R1"], m["R2"]
    # lines: 7 SLIN out, 8 SLIN "First", 9 SLIN "Second"
    assert r1[7, "start"] == r2[7, "start"]                       # the same program up to there
    assert r2[7, "end"] - r1[7, "end"] == pytest.approx(1.0, abs=CYCLE)     # (150 - 50) mm / 0.1 m/s
    assert r1[8, "start"] == r2[8, "start"]                       # "First": together
    assert r1[8, "start"] > r2[7, "end"]                          # R1 waited for R2 to arrive
    # "Second": R1 comes back 50 mm, R2 150 mm: R1 waits the same 1.0 s again, then both start
    assert r2[8, "end"] - r1[8, "end"] == pytest.approx(1.0, abs=CYCLE)
    assert r1[9, "start"] == r2[9, "start"] > r2[8, "end"]
    # the time R1 waited, by hand: twice 1.0 s; R2 arrived last both times and waited a cycle at most
    first, second = res.robots
    assert first.waited == pytest.approx(2.0, abs=2 * CYCLE)
    assert second.waited <= 2 * CYCLE + 1e-9
    texts = [t for t, _, _ in first.released]
    assert texts == [f'SYNC "First" at {tmp_path / "r1.src"}:8', f'SYNC "Second" at {tmp_path / "r1.src"}:9']
    assert [list(map(str, w)) for _, _, w in first.released] == [["R2 (same $SYNC_ID)"]] * 2


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_robot_that_never_reaches_the_synchronised_motion_deadlocks_the_cell_naming_the_wait(tmp_path, interp):
    lone = _program("r2", 150, first="", second="")                  # R2 has no synchronised motion
    # R1's list comes from a function (as the inline form's WITH clause calls the BAS helpers):
    # the wait is still named at the motion's line, not at the function's last statement
    r1 = _program("r1", 50, first="WITH $SYNC_ID[] = \"First\", $SYNC_LIST = team()") + \
        "DEFFCT INT team()\n  RETURN 'B0011'\nENDFCT\n"
    res, m = _run(_cell(tmp_path, r1, lone), interp)
    r1, r2 = (r.runtime.result for r in res.robots)
    assert res.reason == "deadlock" and r2.reason == "completed"
    assert r1.reason == "deadlock" and r1.line == 8 and r1.file.endswith("r1.src")
    assert 'R1 SYNC "First" at' in r1.text and "r1.src:8" in r1.text
    assert (8, "start") not in m["R1"]                               # it never started
    # R1 waited from its arrival to R2's end, and the cell ended it a few cycles after that
    assert r2.sim_time < r1.sim_time <= r2.sim_time + 4 * CYCLE + 1e-9


def _single(tmp_path: Path, text: str, interp: str) -> list:
    path = tmp_path / "alone.src"
    path.write_text(text, encoding="utf-8")
    trace = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(path, mujoco=False, max_sim_time=20.0, interp=interp), RunSinks(trace=trace))
    assert rt.run().reason == "completed"
    trace.flush()
    return [(e["line"], e["phase"], e["t"]) for e in trace.events if e["kind"] == "motion"]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_alone_a_synchronised_motion_is_an_ordinary_one(tmp_path, interp):
    """No partners: no wait and no advance-run stop; with C_SPL the two motions still blend."""
    synced = _program("alone", 50).replace("'B0011'\n", "'B0011' C_SPL\n", 1)
    plain = _program("alone", 50, first="", second="").replace("SLIN {Y 0} \n", "SLIN {Y 0} C_SPL\n", 1)
    assert "C_SPL" in synced and "C_SPL" in plain
    events = _single(tmp_path, synced, interp)
    assert events == _single(tmp_path, plain, interp)
    assert (8, "blend_start") in [(line, phase) for line, phase, _ in events]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_partner_marked_simulated_in_the_machine_data_is_not_waited_for(tmp_path, interp):
    """R1's backup marks robot 2 simulated ($SIMULATED_COOP_ROBOTS = 'B0010', the line of every
    corpus $machine.dat, there 'B0000'): R1 runs its synchronised motions as ordinary ones, and R2,
    which has none, ends as it would alone."""
    (tmp_path / "R1" / "Program").mkdir(parents=True)
    (tmp_path / "R1" / "Mada").mkdir()
    (tmp_path / "R1" / "Mada" / "$machine.dat").write_text(
        "DEFDAT $MACHINE PUBLIC\nINT $SIMULATED_COOP_ROBOTS='B0010' ;Simulierte Roboter im Roboteam-Verbund\nENDDAT\n")
    (tmp_path / "R1" / "Program" / "r1.src").write_text(_program("r1", 150), encoding="utf-8")
    (tmp_path / "r2.src").write_text(_program("r2", 150, first="", second=""), encoding="utf-8")
    path = tmp_path / "cell.yaml"
    path.write_text("robots:\n  R1: {program: R1/Program/r1.src, workspace: .}\n  R2: {program: r2.src}\n")
    res, m = _run(path, interp)
    assert res.reason == "completed" and [r.waited for r in res.robots] == [0.0, 0.0]
    assert m["R1"] == m["R2"]                           # the same motions at the same times


def test_the_sync_values_as_the_controller_holds_them():
    assert team_of(0b0011) == {1, 2} and team_of(int("101", 2)) == {1, 3}
    assert team_of(UNSET) == frozenset() and team_of(True) == frozenset() and team_of(-1) == frozenset(range(1, 33))

    class Chars:
        data = list("AutoSync") + ["\0"] * 56

    assert text_of(Chars) == "AutoSync" and text_of(5) == ""
    assert sync_point({"$SYNC_ID": Chars, "$SYNC_LIST": 3}) == SyncPoint("AutoSync", frozenset({1, 2}))
    assert sync_point({"$SYNC_ID": type("E", (), {"data": [UNSET] * 64}), "$SYNC_LIST": 3}) is None


class _Run:
    """A robot of a cell as release_synced sees it: its name (for the robots already ahead of the
    cycle, interp/cellturns.py) and its runtime's team."""

    def __init__(self, number: int, size: int, at: SyncPoint | None) -> None:
        self.name = f"R{number}"
        team = TeamSync(None, None, None, {})
        team.join(number, size)
        team.at = at
        self.runtime = type("RT", (), {"motions": type("M", (), {"team": team})()})()


def test_the_cell_releases_a_robot_when_every_partner_waits_at_the_same_label():
    a12, b12 = SyncPoint("A", frozenset({1, 2})), SyncPoint("B", frozenset({1, 2}))
    both = [_Run(1, 2, a12), _Run(2, 2, a12)]
    assert release_synced(both) == both and all(r.runtime.motions.team.released for r in both)
    other_label = [_Run(1, 2, a12), _Run(2, 2, b12)]
    assert release_synced(other_label) == []
    one_moving = [_Run(1, 2, a12), _Run(2, 2, None)]
    assert release_synced(one_moving) == []
    # robot 3 of a 'B0111' list is not in a cell of two: not waited for
    a123 = SyncPoint("A", frozenset({1, 2, 3}))
    assert len(release_synced([_Run(1, 2, a123), _Run(2, 2, a12)])) == 2
    with pytest.raises(ValueError):
        TeamSync(None, None, None, {}).join(33, 33)


# ---------------------------------------------------------------- the checker (docs/diagnostics.md)
GENERATED = """DEF gen()
  ;FOLD SLIN 1 Vel=2 m/s CPDAT1 Sync=AutoSync -> 1_2 Tool[1] Base[0] ;%{PE}
    ;FOLD Parameters ;%{h}
      ;Params IlfProvider=kukaroboter.basistech.inlineforms.movement.spline; SyncLabel=AutoSync; CoopRobots=R1_R2; IlfCommand=SLIN
    ;ENDFOLD
    SLIN X1 WITH $VEL = SVEL_CP(2.0, , LCPDAT1), $TOOL = STOOL2(F1), $BASE = SBASE(F1.BASE_NO), $IPO_MODE = SIPO_MODE(F1.IPO_FRAME), $LOAD = SLOAD(F1.TOOL_NO), $ACC = SACC_CP(LCPDAT1), $ORI_TYPE = SORI_TYP(LCPDAT1), $APO = SAPO(LCPDAT1), $JERK = SJERK(LCPDAT1), $COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0), $Sync_Id[] = "AutoSync", $Sync_List = 'B0011' C_Spl
  ;ENDFOLD
END
"""
GENERATED_DAT = """DEFDAT gen
  DECL E6POS X1={X 500.0,Y 0.0,Z 800.0,A 0.0,B 90.0,C 0.0,S 2,T 2,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
  DECL FDAT F1={TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " "}
  DECL LDAT LCPDAT1={VEL 2.0,ACC 100.0,APO_DIST 100.0,APO_FAC 50.0,AXIS_VEL 100.0,AXIS_ACC 100.0,ORI_TYP #VAR,CIRC_TYP #BASE,JERK_FAC 50.0,GEAR_JERK 100.0,EXAX_IGN 0}
ENDDAT
"""


def _codes(with_: str) -> list[str]:
    text = f"DEF t()\n  DECL E6POS XP1\n  XP1 = $POS_ACT\n  SLIN XP1 WITH {with_}\nEND\n"
    return [d.code for d in check_texts({"t.src": text}).diagnostics]


def test_the_checker_takes_the_generated_form_and_types_the_sync_variables():
    """$SYNC_ID is CHAR[64] and $SYNC_LIST an INT (operate_r1.dat): the form MotionSynchSRC.py
    writes checks clean; a wrong type is E201 (W202 a REAL list, W210 a label past 64 characters)."""
    assert check_texts({"gen.src": GENERATED, "gen.dat": GENERATED_DAT}).diagnostics == []
    assert _codes("$SYNC_ID[] = \"AutoSync\", $SYNC_LIST = 'B0011'") == []
    assert _codes("$SYNC_ID[] = \"AutoSync\", $SYNC_LIST = 'H3'") == []
    assert _codes("$SYNC_ID[] = 5, $SYNC_LIST = 3") == ["E201"]
    assert _codes("$SYNC_ID[] = \"A\", $SYNC_LIST = \"AB\"") == ["E201"]
    assert _codes("$SYNC_ID[] = \"A\", $SYNC_LIST = TRUE") == ["E201"]
    assert _codes("$SYNC_ID[] = \"A\", $SYNC_LIST = 3.5") == ["W202"]
    assert _codes(f"$SYNC_ID[] = \"{'A' * 65}\", $SYNC_LIST = 3") == ["W210"]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_only_spline_motions_are_synchronised(tmp_path, interp):
    """$SYNC_ID assigned outside a WITH clause, then a LIN: no wait (the generator's README: the
    points must be SLIN for the synchronisation to work); R2, with no label, runs alone."""
    r1 = (f"DEF r1()\n{START}  $SYNC_ID[] = \"X\"\n  $SYNC_LIST = 'B0011'\n  LIN {{Y 50}}\nEND\n")
    r2 = f"DEF r2()\n{START}  LIN {{Y 50}}\nEND\n"
    res, m = _run(_cell(tmp_path, r1, r2), interp)
    assert res.reason == "completed" and [r.waited for r in res.robots] == [0.0, 0.0]
    assert m["R1"][9, "start"] == m["R2"][7, "start"]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_synchronised_ptp_spline_block_waits_once_at_its_start(tmp_path, interp):
    """A PTP_SPLINE block is one motion: its WITH clause synchronises its start; its segments
    after the first still blend (C_SPL between them), R1 waiting 1.0 s once (its SLIN out is
    100 mm shorter at 0.1 m/s)."""
    block = ("  PTP_SPLINE WITH $SYNC_ID[] = \"Block\", $SYNC_LIST = 'B0011'\n"
             "    SPTP {A1 10, A2 -90, A3 90, A4 0, A5 90, A6 0}\n    SPTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}\n"
             "  ENDSPLINE\n")
    r1, r2 = (f"DEF r{k}()\n{START}  SLIN {{Y {d}}}\n{block}END\n" for k, d in ((1, 50), (2, 150)))
    res, m = _run(_cell(tmp_path, r1, r2), interp)
    assert res.reason == "completed"
    assert m["R1"][9, "start"] == m["R2"][9, "start"]                # the block's first segment: together
    assert (9, "blend_start") in m["R1"]                             # into the second: approximated
    assert res.robots[0].waited == pytest.approx(1.0, abs=CYCLE) and res.robots[1].waited <= CYCLE + 1e-9


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_synchronised_spline_block_starts_together(tmp_path, interp):
    """A SPLINE block's WITH clause synchronises the block (one motion): R1 waits the 1.0 s."""
    block = ("  SPLINE WITH $SYNC_ID[] = \"S\", $SYNC_LIST = 'B0011'\n"
             "    SPL {X 475, Y 0, Z 810}\n    SPL {X 445, Y 0, Z 810}\n  ENDSPLINE\n")
    r1, r2 = (f"DEF r{k}()\n{START}  SLIN {{Y {d}}}\n{block}END\n" for k, d in ((1, 50), (2, 150)))
    res, m = _run(_cell(tmp_path, r1, r2), interp)
    assert res.reason == "completed" and m["R1"][8, "start"] == m["R2"][8, "start"]
    assert res.robots[0].waited == pytest.approx(1.0, abs=CYCLE) and res.robots[1].waited <= CYCLE + 1e-9
