"""Robots that nothing couples take turns of several IPO cycles (issue 89, interp/cellturns.py):
each robot's end, time and wait, the cell's deadlock, the RoboTeam release and the collisions
between robots within reach of each other are those of the cycle-by-cycle run (``uncoupled``
patched to False gives that run), on both interpreters.

Expected times by hand: a WAIT SEC t ends in the first IPO cycle (12 ms) at or after t; a cell
whose every running robot is blocked ends them BLOCKED_CYCLES cycles later (interp/robotcell.py).
"""

from __future__ import annotations

import copy
import random
from pathlib import Path

import mujoco
import pytest

import interp.robotcell as robotcell
from interp.cellcontacts import ContactWatch
from interp.robotcell import BLOCKED_CYCLES, cell_runs, load_robot_cell, run_cell
from robot.cellbound import CellBound
from robot.readback import ReadBack

EXAMPLES = Path(__file__).resolve().parents[2] / "examples/cells/roboteam"
# R1 turns A1 and then waits for an input nothing drives (blocked: only a partner could set it);
# R2 waits 2 s and ends; then R1 alone is blocked, and the cell ends it
R1 = "DEF r1()\n  PTP {A1 30, A2 -90, A3 90, A4 0, A5 0, A6 0}\n  WAIT FOR $IN[1]\nEND\n"
R2 = "DEF r2()\n  WAIT SEC 2\nEND\n"


def _run(path: Path, interp: str, monkeypatch, turns: bool, mujoco: bool = False, seconds: float = 30.0):
    with monkeypatch.context() as m:
        if not turns:
            m.setattr(robotcell, "uncoupled", lambda *a: False)
        taken = []
        m.setattr(robotcell, "take_turns", lambda *a: taken.append(1) or TAKE(*a))
        cell = load_robot_cell(path)
        with cell_runs(cell, interp, seconds, **({} if mujoco else {"mujoco": False})) as runs:
            res = run_cell(cell, runs)
    assert bool(taken) is turns
    return res, [(r.name, r.runtime.result.reason, r.runtime.result.sim_time, r.runtime.result.text,
                  r.runtime.result.line, round(r.waited, 6), r.released) for r in res.robots]


TAKE = robotcell.take_turns
WATCH = robotcell.ContactWatch


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


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_wait_its_own_cell_ends_is_counted_inside_the_turn_as_cycle_by_cycle(tmp_path, interp, monkeypatch):
    """R1 waits in WAIT FOR $IN[1], which its own cell file's stimulus sets at 0.5 s: not blocked
    (its own controller will change the input), so it stays plain and its wait is counted inside its
    turn (interp/cellturns.py ``take_turns`` calls the cell's ``wait`` while the task waits, and
    once more in the cycle its wait ends). By hand: the stimulus is applied at the first IPO cycle
    at or after 0.5 s (42 x 12 ms = 0.504 s), the wait began in the first cycle (at 0 s), so
    R1 waited 0.504 s; no wire released it; R2, 5 m away, takes its turn beside it."""
    (tmp_path / "r1.src").write_text("DEF r1()\n  WAIT FOR $IN[1]\n  WAIT SEC 0.1\nEND\n")
    (tmp_path / "r1.yaml").write_text("stimuli:\n  - at: 0.5\n    set: {\"$IN[1]\": true}\n")
    (tmp_path / "r2.src").write_text("DEF r2()\n  PTP {A1 10, A2 -90, A3 90, A4 0, A5 0, A6 0}\nEND\n")
    (tmp_path / "cell.yaml").write_text("robots:\n  R1: {program: r1.src, inputs: r1.yaml}\n"
                                        "  R2: {program: r2.src, base: [5000, 0, 0, 180, 0, 0]}\n")
    res, ends = _run(tmp_path / "cell.yaml", interp, monkeypatch, True)
    assert ends == _run(tmp_path / "cell.yaml", interp, monkeypatch, False)[1]
    r1 = res.robots[0]
    assert r1.runtime.result.reason == "completed" and round(r1.waited, 3) == 0.504 and r1.released == []


# two KR 6 R900, R2 at X 1150 turned 180 deg about Z: at HOME their wrists overlap, and a wrist
# turning to HOME first touches the other's at |A1| = 12.23 deg (tests/interp/test_cellcontacts.py
# works it out by hand: ``_theta``)
THETA = 12.23
R_TURNS = "DEF r{k}()\n  PTP {{A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}}\n  PTP {{A1 90, A2 -90, A3 90, A4 0, A5 0, A6 0}}\n" \
    "  PTP {{A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}}\nEND\n"
R_BLOCKED = "DEF r{k}()\n  WAIT SEC 0.05\n  WAIT FOR $IN[1]\nEND\n"
START = 'start: "{A1 90, A2 -90, A3 90, A4 0, A5 0, A6 0}"\n'


def _reach_cell(tmp_path, mover: str, other: str) -> Path:
    """Robot `mover` turns to its partner, away and back (lines 2, 3, 4) from A1 90; the other
    runs `other` at HOME; 1,150 mm apart, within reach: before 2026-11-28 such a cell took every
    cycle one by one for its contact check (interp/cellcontacts.py)."""
    for k in (1, 2):
        name = f"R{k}"
        (tmp_path / f"r{k}.src").write_text((R_TURNS if name == mover else other).format(k=k))
        (tmp_path / f"r{k}.yaml").write_text(START if name == mover else "")
    (tmp_path / "cell.yaml").write_text("robots:\n  R1: {program: r1.src, inputs: r1.yaml}\n"
                                        "  R2: {program: r2.src, inputs: r2.yaml, base: [1150, 0, 0, 180, 0, 0]}\n")
    return tmp_path / "cell.yaml"


def _collisions(res):
    return [c.as_json() for c in res.collisions]


@pytest.mark.parametrize("mujoco", [False, True])
@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_robots_within_reach_take_turns_and_collide_as_cycle_by_cycle(tmp_path, interp, mujoco, monkeypatch):
    """R1 turns to R2 twice (two contact episodes, lines 2 and 4) while R2 stands at HOME and
    ends after its WAIT SEC 0.1 in its first turn: the contacts are checked from the poses kept in
    the turns (some proved apart by robot/cellbound.py's bound, the others checked by MuJoCo),
    the same collisions (time, bodies, axes, motions) as cycle by cycle."""
    path = _reach_cell(tmp_path, "R1", "DEF r{k}()\n  WAIT SEC 0.1\nEND\n")
    watches = []
    monkeypatch.setattr(robotcell, "ContactWatch", lambda *a: watches.append(WATCH(*a)) or watches[-1])
    res, ends = _run(path, interp, monkeypatch, True, mujoco)
    # the bound spared some cycles MuJoCo's check (R1 turned away), MuJoCo checked the others
    assert watches[0].proved > 0 and watches[0].checks > 0
    ref, ref_ends = _run(path, interp, monkeypatch, False, mujoco)
    assert ends == ref_ends and _collisions(res) == _collisions(ref)
    first, again = res.collisions
    for c, line in ((first, 2), (again, 4)):
        assert (c.first[0], c.first[2].endswith(f"r1.src:{line}"), c.second[0], c.second[2]) == ("R1", True, "R2", None)
        # the first cycle past THETA: A1 turns at most 360 deg/s x 12 ms a cycle
        assert THETA - 360 * 0.012 <= c.axes["R1"][0] <= THETA
        assert c.axes["R2"] == pytest.approx([0, -90, 90, 0, 0, 0])
    assert res.robots[1].runtime.result.sim_time == pytest.approx(0.108)     # 9 cycles: >= 0.1 s
    assert first.time > 0.108


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_poses_kept_by_the_compiled_cycle_or_by_the_turns_loop_give_the_same_checks(tmp_path, interp, monkeypatch):
    """A turn's poses kept by each robot's compiled IPO cycle (robot/ipocycle.py ``keep_rows``:
    interp/cellkeep.py) and, that playback refused, appended by the turn's loop from the arm's
    qpos: the same kept bytes, so the same MuJoCo checks, proofs and collisions, both as cycle
    by cycle."""
    path = _reach_cell(tmp_path, "R1", "DEF r{k}()\n  WAIT SEC 0.1\nEND\n")
    kept, runs = [], []

    def counting(self, rows, at):
        kept.append(at)
        return KEEP(self, rows, at)
    monkeypatch.setattr(ReadBack, "keep_poses", counting)
    watches = []
    monkeypatch.setattr(robotcell, "ContactWatch", lambda *a: watches.append(WATCH(*a)) or watches[-1])
    for keeping in (True, False):
        if not keeping:
            monkeypatch.setattr(ReadBack, "keep_poses", lambda self, rows, at: kept.append(None) or False)
        res, ends = _run(path, interp, monkeypatch, True, True)
        runs.append((ends, _collisions(res), watches[-1].checks, watches[-1].proved))
    assert kept and None not in kept[:kept.index(None)] and set(kept[kept.index(None):]) == {None}
    assert runs[0] == runs[1] and len(runs[0][1]) == 2 and runs[0][2] > 0 and runs[0][3] > 0
    ref, ref_ends = _run(path, interp, monkeypatch, False, True)
    assert runs[0][:2] == (ref_ends, _collisions(ref))


KEEP = ReadBack.keep_poses


@pytest.mark.parametrize("mujoco", [False, True])
@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_collision_with_a_robot_catching_up_is_found_as_cycle_by_cycle(tmp_path, interp, mujoco, monkeypatch):
    """R1 stands at HOME and waits 0.05 s, then blocks in WAIT FOR (its turn stops there); R2 turns to it in its
    turn and ends; R1 catches up cycle by cycle, its poses kept, and the cell deadlocks it
    BLOCKED_CYCLES after R2's end. R2's wrist meets R1's (lines 2 and 4 of R2), R1 at rest."""
    path = _reach_cell(tmp_path, "R2", R_BLOCKED)
    res, ends = _run(path, interp, monkeypatch, True, mujoco)
    ref, ref_ends = _run(path, interp, monkeypatch, False, mujoco)
    assert ends == ref_ends and _collisions(res) == _collisions(ref)
    r1, r2 = (r.runtime.result for r in res.robots)
    assert (r1.reason, r2.reason) == ("deadlock", "completed")
    assert r1.sim_time == pytest.approx(r2.sim_time + BLOCKED_CYCLES * 0.012)
    assert [(c.first[0], c.first[2], c.second[0], c.second[2].rsplit(":", 1)[1]) for c in res.collisions] == \
        [("R1", None, "R2", "2"), ("R1", None, "R2", "4")]
    for c in res.collisions:
        assert THETA - 360 * 0.012 <= abs(c.axes["R2"][0]) <= THETA


# a robot cycling two PTPs and a LIN (tools/cell_bench.py's moving robot, its points drawn at random)
R_CYCLE = ("DEF r{k}()\n  PTP {{A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}}\n  LOOP\n"
           "    PTP {{A1 {a}, A2 {b}, A3 {c}, A4 0, A5 45, A6 0}}\n    LIN {{X {x}, Y {y}, Z {z}, A 0, B 90, C 0}}\n"
           "    PTP {{A1 -{d}, A2 -95, A3 85, A4 10, A5 30, A6 0}}\n  ENDLOOP\nEND\n")


def _random_cell(folder: Path, rnd, spacing: tuple = (600, 1100)) -> Path:
    """Two to four robots of :data:`R_CYCLE`, `spacing` (0.6-1.1 m) apart on X (within each
    other's reach)."""
    folder.mkdir()
    n, spacing = rnd.choice((2, 3, 4)), rnd.uniform(*spacing)
    lines = ["robots:"]
    for k in range(1, n + 1):
        (folder / f"r{k}.src").write_text(R_CYCLE.format(
            k=k, a=rnd.randint(-80, 80), b=rnd.randint(-110, -50), c=rnd.randint(60, 120), x=rnd.randint(350, 650),
            y=rnd.randint(-300, 300), z=rnd.randint(400, 800), d=rnd.randint(0, 80)))
        lines.append(f"  R{k}: {{program: r{k}.src, no_submit: true, base: [{spacing * (k - 1):.1f}, 0, 0, 0, 0, 0]}}")
    (folder / "cell.yaml").write_text("\n".join(lines) + "\n")
    return folder / "cell.yaml"


def test_random_cells_within_reach_collide_in_turns_as_cycle_by_cycle(tmp_path, monkeypatch):
    """Six random moving cells (seeded), MuJoCo on, 4 s each: taking turns (the poses kept, a run
    of cycles proved apart by robot/cellbound.py's bound, the others checked by MuJoCo after the
    turn) gives the collisions (time, bodies, axes, motions) and ends of the cycle-by-cycle run,
    which checks every cycle. Some of these cells collide, some robots end in an error."""
    rnd = random.Random(89)
    total, errors = 0, 0
    for i in range(6):
        path = _random_cell(tmp_path / f"c{i}", rnd)
        res, ends = _run(path, "vm", monkeypatch, True, True, 4.0)
        ref, ref_ends = _run(path, "vm", monkeypatch, False, True, 4.0)
        assert ends == ref_ends and _collisions(res) == _collisions(ref), path
        total += len(res.collisions)
        errors += sum(end[1] == "error" for end in ends)
    assert total > 0 and errors > 0


def test_every_kept_cycle_the_bound_proves_has_the_touches_its_reference_holds(tmp_path, monkeypatch):
    """Every kept cycle robot/cellbound.py's bound proves (a run of cycles from a reference, or a
    reference pose by its own tests) in the reach cell with both robots turning and four random
    moving cells 0.85-1.25 m apart, checked by MuJoCo on a twin of the cell's scene
    (robot/cellscene.py ``touches``): the pairs of robots touching there are exactly those the
    reference holds touching (none where it holds none). The test is not empty: the bound proves
    hundreds of cycles, some of them with robots held touching, and MuJoCo finds robots touching
    in others."""
    rnd = random.Random(8989)
    twins, counts = {}, {"proved": 0, "held touching": 0, "touching": 0}

    def twin(watch):
        if id(watch) not in twins:
            t = twins[id(watch)] = copy.copy(watch.scene)
            t.data = mujoco.MjData(watch.scene.model)
        return twins[id(watch)]

    def touching(watch, pose) -> set:
        t = twin(watch)
        t.copy_all(pose)
        return {(watch._index[touch.first[0]], watch._index[touch.second[0]]) for touch in t.touches()}

    def replay(self, poses, t, motion, axes):
        counts["touching"] += sum(bool(touching(self, row)) for row in poses)
        proved = CellBound.proved

        def checked(bound, ref, rows, start):
            end = proved(bound, ref, rows, start)
            assert all(touching(self, rows[j]) == set(ref.touching) for j in range(start, end))
            if ref.proves:
                assert touching(self, ref.pose) == set(ref.touching)
            counts["proved"] += end - start
            counts["held touching"] += (end - start) * bool(ref.touching)
            return end
        with monkeypatch.context() as m:
            m.setattr(CellBound, "proved", checked)
            REPLAY(self, poses, t, motion, axes)
    monkeypatch.setattr(ContactWatch, "_replay", replay)
    # both robots of the reach cell turning to each other and away (touching at |A1| under THETA)
    _run(_reach_cell(tmp_path, "R1", R_TURNS), "vm", monkeypatch, True, True)
    for i in range(4):
        _run(_random_cell(tmp_path / f"c{i}", rnd, (850, 1250)), "vm", monkeypatch, True, True, 4.0)
    assert counts["proved"] > 300 and counts["held touching"] > 5 and counts["touching"] > 10, counts


REPLAY = ContactWatch._replay


def test_a_corpus_milling_robot_twice_within_reach_collides_in_turns_as_cycle_by_cycle(tmp_path, shared_corpus,
                                                                                       monkeypatch):
    """A backup's own robot, not the KR 6 the bound was built on: HugoDanielson's KR 210 milling cell
    running its TestMoves.src twice, the second robot 2 m away facing the first (the corpus sweep of
    2026-11-29 put every corpus entry point in such a cell: ends and collisions the same in turns,
    cycle by cycle and on the code before the per-geom bound). In turns the bound proves some of
    the kept cycles apart and MuJoCo checks the rest: the same collisions (bodies, times, axes,
    motions) and ends as cycle by cycle, where every cycle is checked."""
    root = shared_corpus / "HugoDanielson__ChinaMilling"
    prog = root / "KRC/R1/Program/KukaMiling/Commisioning/TestMoves.src"
    (tmp_path / "cell.yaml").write_text("robots:\n" + "".join(
        f"  R{k}: {{program: '{prog}', workspace: '{root}', inputs: auto, base: [{2000 * (k - 1)}, 0, 0, "
        f"{180 * (k - 1)}, 0, 0]}}\n" for k in (1, 2)))
    watches = []
    monkeypatch.setattr(robotcell, "ContactWatch", lambda *a: watches.append(WATCH(*a)) or watches[-1])
    res, ends = _run(tmp_path / "cell.yaml", "vm", monkeypatch, True, True, 12.0)
    turned = watches[-1]
    ref, ref_ends = _run(tmp_path / "cell.yaml", "vm", monkeypatch, False, True, 12.0)
    assert ends == ref_ends and _collisions(res) == _collisions(ref)
    assert turned.proved > 0 and turned.checks < watches[-1].checks
    # the wrists meet five times in 12 s (the corpus sweep's run of 20 s, cycle by cycle, read)
    assert [(c.time, c.first[:2], c.second[:2]) for c in res.collisions] == [
        (1.224, ("R1", "link_4"), ("R2", "link_4")), (2.4, ("R1", "link_5"), ("R2", "link_2")),
        (4.764, ("R1", "link_4"), ("R2", "link_4")), (6.252, ("R1", "link_2"), ("R2", "link_5")),
        (8.544, ("R1", "link_4"), ("R2", "link_4"))]
