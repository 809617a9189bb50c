"""The cell of a backup (issue 22): P00's program-number handshake as a preset (--pgno), the
starving WAIT FOR in the run summary, `krl cell init` — on the small backup of
tests/robot/fixtures/cellbackup (its P00 is KUKA's EXT_PGNO #PGNO_GET, shortened)."""

from __future__ import annotations

import shutil
from pathlib import Path

from click.testing import CliRunner

from interp.run import make_runtime, run_spec, robot_for, RunSinks
from app import main
from krl.project import boot_submit
from robot.machine import library_robots
from robot.stimuli import StimulusError, load_cell
from robot.trace import TraceWriter

BACKUP = Path(__file__).parent / "fixtures" / "cellbackup"
CELL = BACKUP / "R1" / "cell.src"
JOB = BACKUP / "R1" / "Program" / "job.src"

JOB_RULES = """
rules:
  - when: "TRUE"          # the part arrives
    after: 0.5
    set: {PART_READY: true}
  - when: "CLAMP"         # the clamp closes
    after: 0.2
    set: {CLAMPED: true}
  - when: "TRUE"
    after: 0
    set: {"$IN[8]": true}
"""


def _run(program: Path, tmp_path: Path, cell: str | None = None, pgno: int | None = None):
    inputs = None
    if cell is not None:
        inputs = tmp_path / "cell.yaml"
        inputs.write_text(cell, encoding="utf-8")
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(program, inputs=inputs, mujoco=False, max_sim_time=5.0, pgno=pgno),
                         RunSinks(trace=tw))
    res = rt.run()
    io = [(e["t"], e["signal"], e["value"], e.get("source")) for e in tw.events if e["kind"] == "io"]
    return res, io


def test_pgno_handshake_selects_the_program(tmp_path):
    res, io = _run(CELL, tmp_path, JOB_RULES, pgno=2)
    assert res.reason == "completed", res.text
    # P00 sets PGNO_REQ ($OUT[20]) at t=0; the PLC sees it in cycle 1 (0.012 s) and answers
    # 0.1 s later, in the first cycle at or after 0.112 s: cycle 10, t=0.120 s. 2 = bit 1 on
    # $IN[34] (PGNO_FBIT 33), odd parity -> $IN[42] TRUE, PGNO_VALID $IN[41] TRUE.
    # The acknowledgement ($OUT[20] FALSE at 0.120 s) is seen in cycle 11 (0.132 s): PGNO_VALID
    # drops 0.1 s later, cycle 20 (0.240 s).
    pgno = [(t, s, v) for t, s, v, src in io if src == "cell:pgno"]
    assert pgno == [(0.12, "$IN[34]", True), (0.12, "$IN[42]", True), (0.12, "$IN[41]", True),
                    (0.24, "$IN[41]", False)]
    # the program acknowledges at 0.120 s: $OUT[20] FALSE; CASE 2 runs job():
    assert (0.12, "$OUT[20]", False, "program") in io
    # PART_READY: edge of TRUE in cycle 1, + 0.5 s -> cycle 43 (0.516 s); CLAMP at 0.516 s,
    # seen in cycle 44 (0.528 s), + 0.2 s -> cycle 61 (0.732 s); then $OUT[2].
    cell = [(t, s, v) for t, s, v, src in io if src == "cell"]
    assert cell == [(0.024, "$IN[8]", True), (0.516, "$IN[5]", True), (0.732, "$IN[7]", True)]
    assert (0.732, "$OUT[2]", True, "program") in io
    assert not any(s == "$OUT[1]" for _, s, _, _ in io)


def test_pgno_one_and_a_number_the_cell_does_not_know(tmp_path):
    res, io = _run(CELL, tmp_path, pgno=1)
    assert res.reason == "completed" and (0.12, "$OUT[1]", True, "program") in io
    res, _ = _run(CELL, tmp_path, pgno=3)      # SWITCH PGNO DEFAULT: HALT (cell.src:9)
    assert res.reason == "halt" and res.line == 9


def test_pgno_that_does_not_fit_is_a_clear_error():
    out = CliRunner().invoke(main, ["run", str(CELL), "--pgno", "300"])
    assert out.exit_code == 2
    assert "--pgno 300: program number 300 does not fit on PGNO_LENGTH=8 bits" in out.output
    assert "Traceback" not in out.output


def test_starving_wait_for_names_its_inputs_and_a_releasing_rule():
    out = CliRunner().invoke(main, ["run", str(JOB), "--max-sim-time", "2"])
    assert out.exit_code == 3
    assert f"starves    WAIT FOR at {JOB}:2 waits on PART_READY ($IN[5])" in out.output
    assert '- {when: "TRUE", after: 1.0, set: {PART_READY: true}}' in out.output


def test_starving_wait_for_on_two_inputs(tmp_path):
    p = tmp_path / "cell.yaml"
    p.write_text('rules:\n  - {when: "TRUE", after: 0.1, set: {PART_READY: true}}\n', encoding="utf-8")
    out = CliRunner().invoke(main, ["run", str(JOB), "--max-sim-time", "2", "--inputs", str(p)])
    assert f"starves    WAIT FOR at {JOB}:4 waits on CLAMPED ($IN[7]), $IN[8]" in out.output
    assert "set: {CLAMPED: true, '$IN[8]': true}" in out.output


def test_cell_init_lists_the_inputs_with_their_declarations(tmp_path):
    dest = tmp_path / "starter.yaml"
    out = CliRunner().invoke(main, ["cell", "init", str(BACKUP), "job", "-o", str(dest)])
    assert out.exit_code == 0, out.output
    text = dest.read_text(encoding="utf-8")
    assert "# PART_READY = $IN[5]   declared R1/System/$config.dat:12   ; part in the fixture" in text
    assert "#   read at R1/Program/job.src:2 (WAIT FOR)" in text
    assert "# CLAMPED = $IN[7]   declared R1/System/$config.dat:14   ; clamp closed switch" in text
    assert "# $IN[8]\n  #   read at R1/Program/job.src:4 (WAIT FOR)" in text
    assert "CLAMP =" not in text            # an output is not listed
    # the fixture has no machine data: the starter asks for the cell's robot, from the library
    assert "# robot: NAME       # this backup has no R1/Mada/$machine.dat: name the cell's robot " \
           f"(robot/data: {', '.join(library_robots())})" in text
    assert "kr180_r3200_pa" in library_robots()
    # the starter is a valid cell file (every rule commented out)
    cell = load_cell(dest)
    assert cell.rules == [] and cell.autoext is False


def test_a_cell_file_names_its_robot_from_the_library(tmp_path):
    """``robot:`` in a cell file (issue 22): a robot of the project's library by name; the run
    simulates it, and ``--robot`` still overrides it. A path or an unknown name is refused."""
    cell = tmp_path / "cell.yaml"
    cell.write_text("robot: kr180_r3200_pa\nrules: []\n", encoding="utf-8")
    assert load_cell(cell).robot.name == "kr180_r3200_pa.dat"
    assert robot_for(JOB, inputs=cell).trafoname == "#KR180R3200 PA C4 FLR"
    kr6 = Path(__file__).resolve().parents[2] / "robot" / "data" / "kr6_r900.yaml"
    assert robot_for(JOB, robot=kr6, inputs=cell).name == "KR 6 R900 sixx"
    res = CliRunner().invoke(main, ["run", str(JOB), "--inputs", str(cell), "--no-check",
                                    "--max-sim-time", "1"])
    assert "robot      KR180R3200 PA C4 FLR" in res.output, res.output
    for bad in ("../../etc/passwd", "/etc/passwd", "kr999", 3):
        cell.write_text(f"robot: {bad}\n", encoding="utf-8")
        try:
            load_cell(cell)
        except StimulusError as exc:
            assert f"{cell}:1" in str(exc) and "library" in str(exc)
        else:
            raise AssertionError(f"robot: {bad} was accepted")
    res = CliRunner().invoke(main, ["run", str(JOB), "--inputs", str(cell)])
    assert res.exit_code == 2 and "Traceback" not in res.output and "robot must name" in res.output


def test_sim_time_of_a_long_job_is_validated(tmp_path):
    cell = tmp_path / "cell.yaml"
    cell.write_text("sim_time: {Mill_Frame: 180, job: 90.5}\n", encoding="utf-8")
    assert load_cell(cell).sim_time == {"MILL_FRAME": 180.0, "JOB": 90.5}
    for bad, what in (("{job: 0}", "0 < s"), ("{job: 99999}", "0 < s"), ("{'../x': 10}", "not a program name"),
                      ("[job]", "must map"), ("{job: soon}", "sim_time of job")):
        cell.write_text(f"rules: []\nsim_time: {bad}\n", encoding="utf-8")
        try:
            load_cell(cell)
        except StimulusError as exc:
            assert f"{cell}:2" in str(exc) and what in str(exc), str(exc)
        else:
            raise AssertionError(f"sim_time: {bad} was accepted")


def test_krl_run_starts_the_backups_sps_sub_as_at_boot(tmp_path):
    """In a backup `krl run` starts its SPS.SUB beside the program, as the controller does at boot
    (reference §9), and says so; --no-submit runs without; a --submit that is not there is a
    clear error."""
    root = tmp_path / "b"
    shutil.copytree(BACKUP, root)
    (root / "R1" / "SPS.SUB").write_text("DEF SPS()\n  LOOP\n    $OUT[40] = TRUE\n    WAIT SEC 0.1\n  ENDLOOP\nEND\n",
                                         encoding="ascii")
    job = root / "R1" / "Program" / "job.src"
    assert boot_submit(job) == root / "R1" / "SPS.SUB"
    assert boot_submit(root / "R1" / "SPS.SUB") is None      # the submit program is not booted twice
    assert boot_submit(tmp_path / "elsewhere.src") is None    # outside a backup
    trace = tmp_path / "t.jsonl"
    res = CliRunner().invoke(main, ["run", str(job), "--no-check", "--max-sim-time", "2", "--trace", str(trace)])
    assert f"submit     {root / 'R1' / 'SPS.SUB'} (the backup's, started as at boot" in res.output, res.output
    assert '"signal":"$OUT[40]"' in trace.read_text().replace(" ", "")
    res = CliRunner().invoke(main, ["run", str(job), "--no-check", "--max-sim-time", "2", "--no-submit",
                                    "--trace", str(trace)])
    assert "the backup's, started as at boot" not in res.output
    assert '"signal":"$OUT[40]"' not in trace.read_text().replace(" ", "")
    res = CliRunner().invoke(main, ["run", str(job), "--submit", str(tmp_path / "none.sub")])
    assert res.exit_code == 2 and "none.sub: no such submit program" in res.output
