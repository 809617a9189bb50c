"""The real-programs run over the KRC backups of ../shared/krl-corpus (skipped when absent)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from interp import realprograms as rp
from interp.realprograms import CELLS, cause_of, cell_of
from interp.run import make_runtime, run_spec, RunSinks
from app import main
from robot.limits import check_trace
from robot.stimuli import load_cell
from robot.trace import TraceWriter

pytestmark = [pytest.mark.corpus,
              pytest.mark.skipif(not rp.DEFAULT_CORPUS.is_dir(), reason="../shared/krl-corpus absent")]


def test_backups_found_and_a_few_programs_run():
    backups = rp.find_backups(rp.DEFAULT_CORPUS)
    assert backups
    progs = [p for b in backups for p in rp.programs_of(b)][:4]
    rows = [rp.run_one(p, max_sim_time=5.0, max_steps=20_000) for p in progs]
    assert all(r["reason"] != "internal" for r in rows), rows
    text = rp.report(rows)
    assert text.startswith(f"{len(rows)} programs by cause:")
    assert all(r["cause"] in rp.CAUSES for r in rows)


@pytest.mark.slow
def test_all_backup_programs():
    rows = []
    for b in rp.find_backups(rp.DEFAULT_CORPUS):
        for p in rp.programs_of(b):
            rows.append(rp.run_one(p, 60.0, 300_000, rp.cell_of(p)))
    assert not [r for r in rows if r["reason"] == "internal"]
    print(rp.report(rows))


def test_every_stop_gets_one_cause():
    """interp/realprograms.py cause_of (issue 22, "Every stop explained")."""
    assert cause_of({"reason": "completed"}) == "completed"
    assert cause_of({"reason": "halt", "file": "p.src", "line": 9}) == "intended end"
    assert cause_of({"reason": "error", "text": "unknown name t_vel"}) == "program error"
    assert cause_of({"reason": "error", "text": "workspace error: target not reachable"}) == "interpreter gap"
    assert cause_of({"reason": "internal", "text": "KeyError"}) == "interpreter gap"
    # a cycle loop stopped by the limit while its cell answers: answers until 58 s of 60 s
    assert cause_of({"reason": "max_sim_time", "sim_time": 60.0, "cell_answers": 29, "cell_last": 58.0}) \
        == "intended end"
    # the cell answered once at the start, then the program starved: a limit
    assert cause_of({"reason": "max_steps", "sim_time": 60.0, "cell_answers": 6, "cell_last": 2.0}) == "limit"
    assert cause_of({"reason": "max_sim_time", "sim_time": 60.0, "cell_answers": 0}) == "limit"
    # a target the backup's own robot cannot take in any configuration: the program's error;
    # on another robot (a backup without machine data), or when only the path is out: a gap
    note = f" ({rp.TARGET_OUTSIDE_NOTE})"
    own = {"reason": "error", "text": "software limit switch -A5" + note, "robot_own": True}
    assert cause_of(own) == "program error"
    assert cause_of({**own, "robot_own": False}) == "interpreter gap"
    assert cause_of({**own, "text": "software limit switch -A5"}) == "interpreter gap"   # the path only
    assert cause_of({**own, "text": "workspace error: target not reachable" + note}) == "program error"
    assert cause_of({**own, "text": "LIN through a singularity"}) == "interpreter gap"


def test_step_limit_is_the_robot_programs():
    """The step limit counts the robot program's steps only (issue 59): a submit program beside
    it, however many, adds nothing to the limit and uses none of it."""
    assert rp.step_limit(300_000, 60.0, 0, 0.012) == 300_000
    assert rp.step_limit(300_000, 60.0, 2, 0.012) == 300_000


def test_block_calibration_target_is_out_of_its_own_robots_limits(tmp_path):
    """HugoDanielson__ChinaMilling BlockCalibration: Get3Basepoints.src:21 LIN
    gfStartMeasPoint[1]:{X -15,Y 0,Z 55} in BASE_DATA[2] with TOOL_DATA[2] (BlockCalibration.src:15-24)
    asks the KR210 R2700-2 of its $machine.dat for a pose whose 8 configurations all leave
    its soft limits (A5 +-129.2 or +-137.3 past +-125, or A2 past -140..-5): the program's error."""
    p = (rp.DEFAULT_CORPUS / "HugoDanielson__ChinaMilling/KRC/R1/Program/KukaMiling/Subprogs/BaseCalib"
         / "BlockCalibration.src")
    row = rp.run_one(p, 60.0, 300_000, rp.cell_of(p))
    assert (row["reason"], Path(row["file"]).name, row["line"]) == ("error", "Get3Basepoints.src", 21)
    assert row["text"] == f"software limit switch -A5 ({rp.TARGET_OUTSIDE_NOTE})"
    assert row["robot_own"] and row["cause"] == "program error"
    # the conformance report's row, from the trace of `krl run`, says the same
    trace = tmp_path / "trace.jsonl"
    CliRunner().invoke(main, ["run", str(p), "--no-check", "--max-sim-time", "5", "--trace", str(trace),
                              "--inputs", str(rp.cell_of(p))])
    trow = rp.row_from_trace(p, [json.loads(x) for x in trace.read_text().splitlines()])
    assert trow["robot_own"] and (trow["line"], trow["cause"]) == (21, "program error")


def test_committed_cell_files_load_and_are_found():
    """Every corpus/cells file is a valid cell file; cell_of prefers the program's own file."""
    files = sorted(CELLS.rglob("*.yaml"))
    assert len(files) >= 4
    for f in files:
        cell = load_cell(f)
        assert cell.rules or cell.autoext or cell.pgno
    corpus = Path("/corpus")
    assert cell_of(corpus / "khrzysio__KRC4_test/R1/CELL.src", corpus) == CELLS / "khrzysio__KRC4_test/cell.yaml"
    assert cell_of(corpus / "khrzysio__KRC4_test/R1/Program/a.src", corpus) == CELLS / "khrzysio__KRC4_test.yaml"
    assert cell_of(corpus / "nobody/R1/a.src", corpus) is None


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_palletizer_runs_on_the_robot_its_cell_chooses(interp):
    """ingeniado__KRC4-Robot-Palletizer has no machine data; its cell file names the KR 180
    R3200 PA (robot: kr180_r3200_pa). coge_20.src, the bag pick, then runs to its end on it: the
    pick XC1 (coge_20.dat:24, in BASE_DATA[1] with TOOL_DATA[1] Z 775) lies 1.5 m from the
    robot, out of the KR 6 R900's 0.9 m. Its BAS calls run the backup's System/bas.src (its
    EXT BAS declaration links to it) and it reports the pick with PULSE SACO_COGIDO."""
    p = rp.DEFAULT_CORPUS / "ingeniado__KRC4-Robot-Palletizer/Program/SACO_20/coge_20.src"
    cell = rp.cell_of(p)
    assert cell is not None and cell.name == "ingeniado__KRC4-Robot-Palletizer.yaml"
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(p, mujoco=False, max_sim_time=30.0, submit=rp.submit_of(p),
                         check=False, inputs=cell, interp=interp), RunSinks(trace=tw))
    res = rt.run()
    assert res.reason == "completed", (res.reason, res.text, res.file, res.line)
    assert rt.controller.machine.trafoname == "#KR180R3200 PA C4 FLR"
    assert "BAS" not in rt.program.stubs
    motions = [e for e in tw.events if e["kind"] == "motion"]
    assert len(motions) >= 5
    # the flange stays vertical all along (A2 + A3 + A5 = 90, A4 = 0): the parallelogram;
    # 0.01 deg: the taught XHOME ($config.dat:186) itself sums to 90.0013
    poses = [e["axes"] for e in tw.events if e["kind"] == "pose"]
    assert len(poses) > 100
    for a in poses:
        assert abs(a[3]) < 1e-6 and abs(a[1] + a[2] + a[4] - 90.0) < 0.01, a
    # and the motion limits of the palletizer's own machine data hold on the whole pick
    rep = check_trace(tw.events, rt.controller.machine)
    assert rep.ok, rep.summary()


def test_a_cell_gives_a_long_job_its_time():
    """khrzysio's Mill_FrameAut3 mills a whole frame: its cell says it needs 180 s (sim_time)."""
    p = rp.DEFAULT_CORPUS / "khrzysio__KRC4_test/R1/Program/CELL/Frame/Mill_FrameAut3.src"
    cell = rp.cell_of(p)
    assert rp.time_limit(p, cell, 60.0) == 180.0
    assert rp.time_limit(p.with_name("Mill_FrameGlue.src"), cell, 60.0) == 60.0
    assert rp.time_limit(p, None, 60.0) == 60.0


def test_parallel_runs_give_the_rows_of_the_serial_run(monkeypatch):
    """``--jobs`` (issue 39, "Real programs"): the runs of one small backup (two programs and
    its cell.src, both columns) in two worker processes give the rows of the run one after the
    other, in the corpus's order, ``seconds`` aside."""
    small = rp.DEFAULT_CORPUS / "rawpython__kukaKRLmagic"
    monkeypatch.setattr(rp, "find_backups", lambda corpus: [small])
    seen = []
    serial = rp.run_rows(rp.DEFAULT_CORPUS, max_sim_time=5.0, columns=("cells", "auto"))
    parallel = rp.run_rows(rp.DEFAULT_CORPUS, max_sim_time=5.0, columns=("cells", "auto"), jobs=2,
                           progress=lambda col, row: seen.append((col, row["program"])))

    def same(rows):
        return [{k: v for k, v in r.items() if k != "seconds"} for r in rows]

    assert [Path(r["program"]).relative_to(small).as_posix() for r in parallel] == [
        p for p in ("R1/Program/sample_program.src", "R1/Program/sample_program_with_globals.src", "R1/cell.src")
        for _col in ("cells", "auto")]
    assert [r["mode"] for r in parallel] == ["cells", "auto"] * 3
    assert all(r["reason"] != "internal" for r in parallel)
    assert same(parallel) == same(serial)
    assert sorted(seen) == sorted((r["mode"], r["program"]) for r in serial)


def test_jobs_below_one_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as exc:
        rp.main(["--jobs", "0"])
    assert exc.value.code == 2
    assert "--jobs takes a number of worker processes" in capsys.readouterr().err
