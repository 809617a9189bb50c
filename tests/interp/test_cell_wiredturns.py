"""Robots coupled by wires take turns (issue 89; interp/cellturns.py ``WiredTurns``, docs/cells.md
"Wires in turns"): every robot's trace stream (each event, pose and I/O change, byte for byte), its
end, its waits and who released them are those of the cycle-by-cycle run (``wired`` patched to
False gives that run), on both interpreters, while most cycles run in turns.

The cells: a hand-off of two moving robots taking turns to move (each waits, held, while the
other moves), a chain of four moving robots each reading its predecessor's output (the movers
run in the chain's order), the same chain closed into a ring (two movers reach each other: no
wired turn), and examples/cells/handoff with its miswired file.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import interp.robotcell as robotcell
from interp.cellturns import WiredTurns
from interp.robotcell import Wire, cell_runs, load_robot_cell, robot_trace, run_cell, summary_lines

EXAMPLES = Path(__file__).resolve().parents[2] / "examples/cells/handoff"

R1_RELAY = """DEF r1()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
  LOOP
    PTP {A1 40, A2 -80, A3 100, A4 0, A5 45, A6 0}
    LIN {X 500, Y 100, Z 700, A 0, B 90, C 0}
    $OUT[10] = TRUE
    WAIT FOR $IN[11]
    PTP {A1 -40, A2 -95, A3 85, A4 10, A5 30, A6 0}
    $OUT[10] = FALSE
    WAIT FOR NOT $IN[11]
  ENDLOOP
END
"""
R2_RELAY = """DEF r2()
  LOOP
    WAIT FOR $IN[10]
    PTP {A1 30, A2 -80, A3 100, A4 0, A5 45, A6 0}
    LIN {X 500, Y -100, Z 700, A 0, B 90, C 0}
    $OUT[11] = TRUE
    WAIT FOR NOT $IN[10]
    PTP {A1 -30, A2 -95, A3 85, A4 10, A5 30, A6 0}
    $OUT[11] = FALSE
  ENDLOOP
END
"""
# a moving robot that copies its input $IN[20] to $OUT[21] in every loop (the read shows in its
# trace as an I/O change) and toggles $OUT[20], its successor's $IN[20]
R_CHAIN = """DEF r{k}()
  PTP {{A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}}
  LOOP
    PTP {{A1 {a}, A2 -80, A3 100, A4 0, A5 45, A6 0}}
    $OUT[21] = $IN[20]
    LIN {{X 500, Y 100, Z 700, A 0, B 90, C 0}}
    $OUT[20] = NOT $OUT[20]
    PTP {{A1 -{a}, A2 -95, A3 85, A4 10, A5 30, A6 0}}
  ENDLOOP
END
"""


def _relay(folder: Path) -> Path:
    (folder / "r1.src").write_text(R1_RELAY)
    (folder / "r2.src").write_text(R2_RELAY)
    (folder / "cell.yaml").write_text("robots:\n  R1: {program: r1.src}\n"
                                      "  R2: {program: r2.src, base: [2000, 0, 0, 180, 0, 0]}\n"
                                      "wires:\n  - R1 $OUT[10] -> R2 $IN[10]\n  - R2 $OUT[11] -> R1 $IN[11]\n")
    return folder / "cell.yaml"


def _chain(folder: Path, ring: bool) -> Path:
    lines = ["robots:"]
    for k in (1, 2, 3, 4):
        (folder / f"r{k}.src").write_text(R_CHAIN.format(k=k, a=20 + 5 * k))
        lines.append(f"  R{k}: {{program: r{k}.src, no_submit: true, base: [{2000 * (k - 1)}, 0, 0, 0, 0, 0]}}")
    lines += ["wires:"] + [f"  - R{k} $OUT[20] -> R{k + 1} $IN[20]" for k in (1, 2, 3)]
    if ring:
        lines.append("  - R4 $OUT[20] -> R1 $IN[20]")
    (folder / "cell.yaml").write_text("\n".join(lines) + "\n")
    return folder / "cell.yaml"


def _run(path: Path, out: Path, interp: str, monkeypatch, turns: bool, seconds: float, mujoco: bool = False):
    """The cell `path` run for `seconds`, traced into `out` (a folder): (its summary lines, each
    robot's trace stream as bytes, the cycles run in wired turns: the furthest robot's)."""
    out.mkdir()
    counted = []
    take = WiredTurns.take

    def counting(self, live, *a):
        start = min(item[0].runtime.controller.cycle for item in live)
        went = take(self, live, *a)
        if went is not None:
            counted.append(max(item[0].runtime.controller.cycle for item in live) - start)
        return went
    with monkeypatch.context() as m:
        m.setattr(WiredTurns, "take", counting)
        if not turns:
            m.setattr(robotcell, "wired", lambda *a: False)
        cell = load_robot_cell(path)
        with cell_runs(cell, interp, seconds, trace=out / "run.jsonl", **({} if mujoco else {"mujoco": False})) as runs:
            res = run_cell(cell, runs)
    streams = {r.name: robot_trace(out / "run.jsonl", r.name).read_bytes() for r in cell.robots}
    return summary_lines(res, path.parent), streams, sum(counted)


def _both(path: Path, tmp_path: Path, interp: str, monkeypatch, seconds: float, mujoco: bool = False):
    ours = _run(path, tmp_path / "turns", interp, monkeypatch, True, seconds, mujoco)
    ref = _run(path, tmp_path / "lockstep", interp, monkeypatch, False, seconds, mujoco)
    assert ref[2] == 0
    assert ours[0] == ref[0]
    for name, stream in ref[1].items():
        assert ours[1][name] == stream, name
    return ours


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_two_robots_handing_off_in_turns_trace_as_cycle_by_cycle(tmp_path, interp, monkeypatch):
    """Each robot moves while the other is held in WAIT FOR; each output that releases the
    partner ends the mover's turn. 10 s simulated (834 cycles): nearly all of them in turns, each
    robot's stream byte for byte the cycle-by-cycle run's; every wait after the first is
    released by the partner's wire, and both robots' streams hold their I/O changes."""
    summary, streams, in_turns = _both(_relay(tmp_path), tmp_path, interp, monkeypatch, 10.0)
    assert in_turns > 0.9 * 834
    released = [line for line in summary if "released by" in line]
    assert len(released) >= 4
    assert all("R2 $OUT[11] -> R1 $IN[11]" in line for line in released if "r1.src" in line)
    assert all("R1 $OUT[10] -> R2 $IN[10]" in line for line in released if "r2.src" in line)
    for name in ("R1", "R2"):
        assert b'"$OUT[1' in streams[name]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_chain_of_moving_robots_reading_each_other_takes_turns_as_cycle_by_cycle(tmp_path, interp, monkeypatch):
    """R1 -> R2 -> R3 -> R4, all four moving: a mover runs no further than the cycle its
    predecessor stopped at (after changing the output the successor reads), so each reads its
    $IN[20] in every cycle as cycle by cycle: each $OUT[21] copy of it lands at the same time."""
    summary, streams, in_turns = _both(_chain(tmp_path, False), tmp_path, interp, monkeypatch, 8.0)
    assert in_turns > 0.9 * 667
    assert all(b'"$OUT[21]' in streams[f"R{k}"] for k in (2, 3, 4))


def test_a_mover_reaching_movers_alone_runs_on_past_its_output_changes(tmp_path, monkeypatch):
    """The chain R1 -> R2 -> R3 -> R4 of moving robots: each reaches movers alone, so it runs on
    past a change of its $OUT[20] (logged), each successor given that change at the cycle boundary
    where the cell's carry gives it cycle by cycle (``WiredTurns._feed``). 8 s simulated, 667
    cycles a robot: fewer than 1 % of the 2,668 robot cycles are stepped one by one (before
    2026-11-29 each mover stopped at its change and the robots behind caught up cycle by cycle:
    1,158 of them), every stream byte for byte the cycle-by-cycle run's."""
    stepped = []
    step = robotcell._step
    monkeypatch.setattr(robotcell, "_step", lambda live, *a: stepped.append(len(live)) or step(live, *a))
    _, streams, _ = _run(_chain(tmp_path, False), tmp_path / "turns", "vm", monkeypatch, True, 8.0)
    assert sum(stepped) < 0.01 * 4 * 667
    monkeypatch.setattr(robotcell, "_step", step)
    _, ref, _ = _run(tmp_path / "cell.yaml", tmp_path / "lockstep", "vm", monkeypatch, False, 8.0)
    assert streams == ref
    # each successor's input set by the wire at least twice in the 8 s, and copied to its $OUT[21]
    assert all(ref[f"R{k}"].count(b'"$IN[20]') >= 2 and b'"$OUT[21]' in ref[f"R{k}"] for k in (2, 3, 4))


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_robots_behind_a_mover_that_ran_on_read_its_logged_outputs(tmp_path, interp, monkeypatch):
    """R1 moves and toggles $OUT[20] once a loop; R2 and R3 wait in WAIT FOR for their input to
    rise, then to fall, each copying it to its own $OUT[20]; R4 moves. In the first turn all four
    move: R1 runs on past its toggles (it reaches movers alone), R2 soon blocks in its WAIT FOR and
    stops; R2 and R3 then catch up cycle by cycle with R1 ahead, each wire from R1 carried with
    R1's logged value of the cycle caught up (``WiredTurns.logged``: R2 released in the cycle after
    R1's toggle, as cycle by cycle, and not when the cell reaches R1's cycle). 12 s simulated,
    every stream and wait as cycle by cycle."""
    folder = tmp_path / "cell"
    folder.mkdir()
    wait = ("DEF r{k}()\n  PTP {{A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}}\n  LOOP\n"
            "    PTP {{A1 {a}, A2 -85, A3 95, A4 0, A5 45, A6 0}}\n    WAIT FOR $IN[20]\n    $OUT[20] = TRUE\n"
            "    PTP {{A1 -{a}, A2 -90, A3 90, A4 0, A5 45, A6 0}}\n    WAIT FOR NOT $IN[20]\n    $OUT[20] = FALSE\n"
            "  ENDLOOP\nEND\n")
    for k, text in ((1, R_CHAIN.format(k=1, a=25)), (2, wait.format(k=2, a=10)), (3, wait.format(k=3, a=15)),
                    (4, R_CHAIN.format(k=4, a=40))):
        (folder / f"r{k}.src").write_text(text)
    (folder / "cell.yaml").write_text("robots:\n" + "".join(
        f"  R{k}: {{program: r{k}.src, no_submit: true, base: [{2000 * (k - 1)}, 0, 0, 0, 0, 0]}}\n" for k in (1, 2, 3, 4))
        + "wires:\n" + "".join(f"  - R{k} $OUT[20] -> R{k + 1} $IN[20]\n" for k in (1, 2, 3)))
    summary, _, in_turns = _both(folder / "cell.yaml", tmp_path, interp, monkeypatch, 12.0)
    assert in_turns > 0
    released = [line for line in summary if "released by R1 $OUT[20] -> R2 $IN[20]" in line]
    assert len(released) >= 3


def test_a_wait_a_feed_ends_is_released_by_its_wire(tmp_path, monkeypatch):
    """R2 waits in WAIT FOR for R1's toggles while its slow motions run on (CONTINUE), so it is not
    blocked (a mover, not held): R1 reaches movers alone and runs on, and R2's input changes come
    from R1's log in R2's turn (its first release at 3.216 s, in the turn, then an offer to jump
    stops it); each wait they end is released by the wire, as cycle by cycle (the summary's lines)."""
    (tmp_path / "r1.src").write_text(R_CHAIN.format(k=1, a=25))
    (tmp_path / "r2.src").write_text(
        "DEF r2()\n  $VEL_AXIS[1] = 2\n  LOOP\n    PTP {A1 30, A2 -90, A3 90, A4 0, A5 45, A6 0}\n    CONTINUE\n"
        "    WAIT FOR $IN[20]\n    WAIT SEC 0.05\n    PTP {A1 -30, A2 -90, A3 90, A4 0, A5 45, A6 0}\n    CONTINUE\n"
        "    WAIT FOR NOT $IN[20]\n    WAIT SEC 0.05\n  ENDLOOP\nEND\n")
    (tmp_path / "cell.yaml").write_text("robots:\n  R1: {program: r1.src, no_submit: true}\n"
                                        "  R2: {program: r2.src, no_submit: true, base: [2000, 0, 0, 0, 0, 0]}\n"
                                        "wires:\n  - R1 $OUT[20] -> R2 $IN[20]\n")
    summary, _, in_turns = _both(tmp_path / "cell.yaml", tmp_path, "vm", monkeypatch, 12.0)
    assert in_turns > 0.9 * 1000
    assert "             3.216 s WAIT FOR at r2.src:6, released by R1 $OUT[20] -> R2 $IN[20]" in summary
    assert len([line for line in summary if "released by R1 $OUT[20] -> R2 $IN[20]" in line]) == 2


def test_a_ring_of_moving_robots_runs_cycle_by_cycle(tmp_path, monkeypatch):
    """The chain closed (R4 -> R1): every mover reaches every other, no wired turn is taken."""
    _, _, in_turns = _both(_chain(tmp_path, True), tmp_path, "vm", monkeypatch, 3.0)
    assert in_turns == 0


@pytest.mark.parametrize("cell", ["cell.yaml", "miswired.yaml"])
@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_example_hand_off_and_its_miswired_file_as_cycle_by_cycle(tmp_path, interp, cell, monkeypatch):
    """examples/cells/handoff (docs/cells.md's summaries: completed at 1.116 s, R1 released after
    0.228 s; miswired: deadlock at 1.140 s), with MuJoCo, its robots 1.5 m apart."""
    summary, _, in_turns = _both(EXAMPLES / cell, tmp_path, interp, monkeypatch, 30.0, True)
    assert in_turns > 0
    assert summary[0] == ("cell       2 robots: completed at 1.116 s" if cell == "cell.yaml"
                          else "cell       2 robots: deadlock at 1.140 s")


def _wires(*pairs: str) -> list[Wire]:
    return [Wire(a, 1, b, 1) for a, b in (p.split() for p in pairs)]


def test_movers_run_after_the_movers_that_reach_them():
    """The order of the movers (``WiredTurns._order``): a mover after every mover whose outputs
    reach it, along wires through any robot; none when two reach each other."""
    chain = WiredTurns(_wires("A B", "B C", "C D"))
    assert chain.reach["A"] == {"B", "C", "D"} and chain.reach["C"] == {"D"}
    assert chain._order(("D", "B", "A")) == ["A", "B", "D"]
    # A and C moving, B held between them: A reaches C through B
    assert chain._order(("C", "A")) == ["A", "C"]
    ring = WiredTurns(_wires("A B", "B C", "C A"))
    assert ring._order(("A", "C")) is None
    # a mover whose outputs come back to it through a held robot (a hand-off) moves alone
    assert ring._order(("B",)) == ["B"]
    assert chain._order(()) is None


def test_a_wired_idle_cell_still_jumps_its_idle_cycles(tmp_path, monkeypatch):
    """tools/cell_bench.py's idle cell: R1 toggles $OUT[5] every 30 s, R2 and R3 follow it in WAIT
    FOR. Between the toggles every robot offers to jump and the cell jumps (interp/robotcell.py
    ``_step``): a wired turn stopped at R1's offer hands the next cycle to the cell, which jumps
    (a first form of this code took one-cycle turns over the 120 s instead: 10,000 cycles, 18x the
    CPU); and a turn that answered R1's offer with an ordinary cycle put its trace's ``idle``
    event a cycle late. Fewer than 300 of the 10,000 cycles are stepped, the streams as cycle by cycle."""
    (tmp_path / "r1.src").write_text("DEF r1()\n  LOOP\n    WAIT SEC 30\n    $OUT[5] = NOT $OUT[5]\n  ENDLOOP\nEND\n")
    for k in (2, 3):
        (tmp_path / f"r{k}.src").write_text(f"DEF r{k}()\n  LOOP\n    WAIT FOR $IN[5]\n    $OUT[6] = TRUE\n"
                                            "    WAIT FOR NOT $IN[5]\n    $OUT[6] = FALSE\n  ENDLOOP\nEND\n")
    (tmp_path / "cell.yaml").write_text("robots:\n" + "".join(
        f"  R{k}: {{program: r{k}.src, no_submit: true, base: [{3000 * (k - 1)}, 0, 0, 0, 0, 0]}}\n" for k in (1, 2, 3))
        + "wires:\n  - R1 $OUT[5] -> R2 $IN[5]\n  - R1 $OUT[5] -> R3 $IN[5]\n")
    steps = []
    step = robotcell._step
    monkeypatch.setattr(robotcell, "_step", lambda *a: steps.append(1) or step(*a))
    summary, streams, _ = _both(tmp_path / "cell.yaml", tmp_path, "vm", monkeypatch, 120.0)
    assert len(steps) < 2 * 300        # both runs' steps: the turns' and the cycle-by-cycle run's
    assert summary[0] == "cell       3 robots: max_sim_time at 120.000 s"
    # R1 toggles at 30, 60, 90 and 120 s; R2 answers the first three (the fourth reaches it at the limit)
    assert streams["R2"].count(b'"$OUT[6]') == 3 and streams["R2"].count(b'"$IN[5]') == 4


def test_unwired_robots_offering_to_jump_in_their_turns_jump_as_cycle_by_cycle(tmp_path, monkeypatch):
    """Two robots 5 m apart (no wire: interp/cellturns.py ``take_turns``) move, then wait 5 s and
    move again, the second a little longer first. Each stops its turn at its first offer to skip
    its idle cycles, the offer left for the cell, which grants the skip in the cycle both offer,
    as cycle by cycle (before 2026-11-29 the turn answered it 0: the skip, and the trace's ``idle``
    event, came a cycle or more late)."""
    for k, a in ((1, 20), (2, 35)):
        (tmp_path / f"r{k}.src").write_text(f"DEF r{k}()\n  PTP {{A1 {a}, A2 -90, A3 90, A4 0, A5 0, A6 0}}\n"
                                            f"  WAIT SEC 5\n  PTP {{A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}}\nEND\n")
    (tmp_path / "cell.yaml").write_text("robots:\n  R1: {program: r1.src, no_submit: true}\n"
                                        "  R2: {program: r2.src, no_submit: true, base: [5000, 0, 0, 0, 0, 0]}\n")
    turns = []
    take = robotcell.take_turns
    monkeypatch.setattr(robotcell, "take_turns", lambda *a: turns.append(1) or take(*a))
    ours = _run(tmp_path / "cell.yaml", tmp_path / "turns", "vm", monkeypatch, True, 30.0)
    monkeypatch.setattr(robotcell, "uncoupled", lambda *a: False)
    ref = _run(tmp_path / "cell.yaml", tmp_path / "lockstep", "vm", monkeypatch, True, 30.0)
    assert turns and ours[0] == ref[0] and ours[1] == ref[1]
    assert all(b'"kind":"idle"' in stream for stream in ours[1].values())
