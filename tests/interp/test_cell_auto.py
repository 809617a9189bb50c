"""``inputs: auto`` for a robot of a cell of several (issue 89; interp/robotcell.py
``wired_inputs``, interp/runtime/autocell.py): the automatic cell answers the inputs the robot
starves for that no wire drives; an input a partner's wire drives is the partner's, never
answered, even when the partner never sets it (the cell then deadlocks)."""

from __future__ import annotations

from pathlib import Path

import pytest

from interp.robotcell import _options, cell_runs, load_robot_cell, run_cell
from interp.run import RunSinks, make_runtime, run_setup
from interp.runtime.autocell import AUTO_DELAY_S

# R1 needs $IN[20] (nothing wires it: the automatic cell's) and then $IN[11] (R2's, by a wire)
R1 = """DEF r1()
  WAIT FOR $IN[20]
  WAIT FOR $IN[11]
  $OUT[12] = TRUE
END
"""
R2 = """DEF r2()
  WAIT SEC 2.0
  $OUT[11] = TRUE
END
"""
R2_SILENT = """DEF r2()
  WAIT SEC 2.0
END
"""
CELL = """robots:
  R1: {program: r1.src, inputs: auto}
  R2: {program: r2.src}
wires:
  - R2 $OUT[11] -> R1 $IN[11]
"""


def _run(tmp_path: Path, r2: str, interp: str):
    (tmp_path / "r1.src").write_text(R1, encoding="utf-8")
    (tmp_path / "r2.src").write_text(r2, encoding="utf-8")
    (tmp_path / "cell.yaml").write_text(CELL, encoding="utf-8")
    cell = load_robot_cell(tmp_path / "cell.yaml")
    with cell_runs(cell, interp, 10.0, mujoco=False) as runs:
        res = run_cell(cell, runs)
        log = {r.name: [(round(t, 3), s, v, src) for t, s, v, src, *_ in r.runtime.controller.io.log] for r in runs}
    return res, log


def _sources(log, signal):
    return [(t, v, src) for t, s, v, src in log if s == signal]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_auto_answers_the_unwired_input_and_leaves_the_wired_one_to_the_partner(tmp_path, interp):
    res, log = _run(tmp_path, R2, interp)
    assert res.reason == "completed", [r.runtime.result for r in res.robots]
    r1 = log["R1"]
    # $IN[20]: R1 starves at once; the automatic cell answers AUTO_DELAY_S later
    ((t20, v20, src20),) = _sources(r1, "$IN[20]")
    assert v20 is True and src20 == "auto" and t20 == pytest.approx(AUTO_DELAY_S, abs=0.013)
    # $IN[11]: only R2's wire, at the cycle after R2 wrote it (WAIT SEC 2.0 ends in the cycle at
    # 2.004 s: 2.0 / 0.012 is 166.7, so cycle 167), though R1 waited for it from ~0.5 s
    assert _sources(r1, "$IN[11]") == [(pytest.approx(2.016), True, "wire R2 $OUT[11]")]
    assert any(s == "$OUT[12]" and v is True for _t, s, v, _src in r1)
    released = res.robots[0].released
    assert [(text.rsplit(":", 1)[1], [str(w) for w in wires]) for text, _s, wires in released] == \
        [("3", ["R2 $OUT[11] -> R1 $IN[11]"])]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_wired_input_the_partner_never_sets_is_not_answered(tmp_path, interp):
    res, log = _run(tmp_path, R2_SILENT, interp)
    r1 = res.robots[0].runtime.result
    assert res.reason == "deadlock" and r1.reason == "deadlock" and r1.line == 3
    assert "R2 $OUT[11] -> R1 $IN[11]" in r1.text
    assert _sources(log["R1"], "$IN[11]") == []
    assert [src for _t, _v, src in _sources(log["R1"], "$IN[20]")] == ["auto"]


# A backup whose SPS.SUB runs beside the robot program (a pass that changes nothing: parked by the
# spin watch, so the robot's cycles are steady): the robot program waits for an input no wire
# drives. Alone the submit program keeps the wait from being a deadlock and the automatic cell
# answers once the run has been idle for a window; a robot of a cell whose wait reads inputs alone
# is *blocked* there (interp/runtime/scheduler.py ``_stands_on_inputs``), and before 2026-11-30 the
# cell's deadlock test answered it at once, a window early: the robot's own run differed from its
# run alone (ingeniado's palletizer, its caja_g_m1.src, two robots: completed at 16.692 s in the
# cell, 18.228 s alone), and from the same cell run with --trace (steady cycles off).
BACKUP_PROG = """DEF prog()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}
  WAIT FOR $IN[20]
  PTP {A1 10, A2 -90, A3 90, A4 0, A5 0, A6 0}
  WAIT FOR $IN[21] AND $IN[22]
  $OUT[12] = TRUE
END
"""
QUIET_SPS = """DEF sps()
  LOOP
    $OUT[3] = $IN[5]
  ENDLOOP
END
"""
TWO_FROM_ONE_BACKUP = """robots:
  R1: {program: bk/R1/Program/prog.src, workspace: bk, inputs: auto}
  R2: {program: bk/R1/Program/prog.src, workspace: bk, inputs: auto, base: [2000, 0, 0, 180, 0, 0]}
"""


def _backup(tmp_path: Path) -> Path:
    (tmp_path / "bk" / "R1" / "Program").mkdir(parents=True)
    (tmp_path / "bk" / "R1" / "System").mkdir()
    (tmp_path / "bk" / "R1" / "Program" / "prog.src").write_text(BACKUP_PROG, encoding="utf-8")
    (tmp_path / "bk" / "R1" / "System" / "$config.dat").write_text("DEFDAT $CONFIG\nENDDAT\n", encoding="utf-8")
    (tmp_path / "bk" / "R1" / "System" / "sps.sub").write_text(QUIET_SPS, encoding="utf-8")
    (tmp_path / "cell.yaml").write_text(TWO_FROM_ONE_BACKUP, encoding="utf-8")
    return tmp_path / "cell.yaml"


def _io(ctl) -> list:
    return [(round(t, 3), s, v, src) for t, s, v, src, *_ in ctl.io.log]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_robot_beside_its_submit_program_is_answered_in_a_cell_as_alone(tmp_path, interp):
    path = _backup(tmp_path)
    cell = load_robot_cell(path)
    with cell_runs(cell, interp, 20.0, mujoco=False) as runs:
        res = run_cell(cell, runs)
        in_cell = {r.name: (_io(r.runtime.controller), r.runtime.result.reason, r.runtime.result.sim_time)
                   for r in runs}
    assert res.reason == "completed"
    # the same robot program alone, as `krl run --inputs auto` runs it (the cell's own options)
    with run_setup(_options(cell.robots[0], interp, 20.0, None)) as setup:
        rt, _ = make_runtime(setup.spec.with_(mujoco=False), RunSinks())
        alone = rt.run()
        alone_io = _io(rt.controller)
    assert alone.reason == "completed" and len(setup.spec.submit) == 1     # the backup's SPS.SUB ran
    answers = [(t, s) for t, s, v, src in alone_io if src == "auto"]
    # alone each wait is answered AUTO_DELAY_S after a window of WINDOW_CYCLES idle cycles, not at once
    assert [s for _t, s in answers] == ["$IN[20]", "$IN[21]", "$IN[22]"] or \
        [s for _t, s in answers] == ["$IN[20]", "$IN[22]", "$IN[21]"]
    for name in ("R1", "R2"):
        assert in_cell[name] == (alone_io, "completed", alone.sim_time), name


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_beside_its_submit_program_a_wired_wait_the_partner_never_ends_still_deadlocks(tmp_path, interp):
    # R1's backup and SPS.SUB as above; its first wait reads $IN[20], which R2's wire drives: the
    # automatic cell finds nothing to answer there (the partner's input), so the robot is blocked
    # once the idle watch's window has passed, and the cell deadlocks when R2 has ended
    path = _backup(tmp_path)
    (tmp_path / "r2.src").write_text(R2_SILENT, encoding="utf-8")
    path.write_text("""robots:
  R1: {program: bk/R1/Program/prog.src, workspace: bk, inputs: auto}
  R2: {program: r2.src}
wires:
  - R2 $OUT[20] -> R1 $IN[20]
""", encoding="utf-8")
    cell = load_robot_cell(path)
    with cell_runs(cell, interp, 20.0, mujoco=False) as runs:
        res = run_cell(cell, runs)
        r1 = runs[0].runtime
        auto = [s for _t, s, _v, src, *_ in r1.controller.io.log if src == "auto"]
    assert res.reason == "deadlock", res.robots[0].runtime.result
    assert r1.result.reason == "deadlock" and r1.result.line == 3
    assert "R2 $OUT[20] -> R1 $IN[20]" in r1.result.text
    assert auto == []
    # after R2's end (WAIT SEC 2.0: the cycle at 2.004 s), not at the time limit
    assert 2.004 <= res.time < 3.0
