"""A cell that answers by itself: ``krl run --inputs auto`` (issue 34, interp/runtime/autocell.py).

Times are worked out from the documented rules: the cell answers AUTO_DELAY_S = 0.5 s after it
sees the program starve; a WAIT FOR with nothing else running is seen at once (the scheduler's
deadlock test, in the cycle the wait began); a polling loop after two quiet windows of 32 IPO
cycles (the state compared, interp/runtime/idle.py) and one more window watched; an answer at
time t is applied in the first cycle k with k * 12 ms >= t. P00's program number comes from the
PLC rules of robot/cellpresets.py (0.1 s after the request), with the CASE values of the
program's SWITCH PGNO in turn."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from interp.run import make_runtime, run_spec, RunSinks
from app import main
from robot.trace import TraceWriter

from .helpers import write
from robot.stimuli import parse_cell
import yaml

INTERPS = ("tree", "vm")
CELLBACKUP = Path(__file__).resolve().parents[1] / "robot" / "fixtures" / "cellbackup"

CONFIG = """
DEFDAT  $CONFIG
SIGNAL PART_READY $IN[5] ;part in the fixture
SIGNAL CLAMP $OUT[6] ;close the clamp
SIGNAL CLAMPED $IN[7] ;clamp closed switch
SIGNAL bPermisoEntrada $IN[12] ;permission to enter
SIGNAL PROG_NR $IN[17] TO $IN[20] ;program number of the PLC
ENDDAT
"""

JOB = """
DEF job()
  WAIT FOR PART_READY
  CLAMP = TRUE
  WAIT FOR CLAMPED AND $IN[8]
  $OUT[1] = TRUE
  WaitPermit(bPermisoEntrada)
  $OUT[2] = TRUE
  LOOP
    SWITCH PROG_NR
    CASE 3
      $OUT[3] = TRUE
      EXIT
    CASE 5
      $OUT[5] = TRUE
      EXIT
    ENDSWITCH
  ENDLOOP
  LOOP
    IF $IN[4] OR $IN[9] THEN
      EXIT
    ENDIF
  ENDLOOP
  $OUT[4] = TRUE
  WAIT FOR $OUT[30]
END

DEF WaitPermit(bPermit :OUT)
  DECL BOOL bPermit
  WAIT FOR bPermit
END
"""


def uncomment_rules(text: str) -> str:
    """The text with every commented rule line (``# - when:``, ``#   after:``, ``#   set:``)
    uncommented, as a maintainer keeps the rules."""
    out = []
    for line in text.splitlines():
        s = line.lstrip()
        if s.startswith(("# - when:", "#   after:", "#   set:")):
            line = line.replace("# ", "", 1)
        out.append(line)
    return "\n".join(out)


def _backup(tmp: Path) -> Path:
    for d in ("R1/System", "R1/Program"):
        (tmp / d).mkdir(parents=True)
    write(tmp, "R1/System/$config.dat", CONFIG)
    return write(tmp, "R1/Program/job.src", JOB)


def _run(prog: Path, interp: str = "tree", max_sim_time: float = 30.0):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, inputs="auto", max_sim_time=max_sim_time, mujoco=False,
                         check=False, interp=interp), RunSinks(trace=tw))
    res = rt.run()
    return rt, res, tw.events


def test_the_automatic_cell_answers_waits_loops_groups_and_parameters(tmp_path):
    """On both interpreters (one run each), and the two runs' events identical (until 2026-11-28
    a test of its own ran both again)."""
    prog = _backup(tmp_path)
    out = [_answers_of(prog, interp) for interp in INTERPS]
    assert out[0] == out[1]


def _answers_of(prog: Path, interp: str) -> list:
    """The run of `prog` on `interp` with the expected answers checked; its events."""
    rt, res, events = _run(prog, interp)
    answers = [a.describe() for a in rt.autocell.answers]
    assert answers[:3] == [
        # WAIT FOR PART_READY at t = 0: answered 0.5 s later, cycle 42
        "at 0.504 s, $IN[5] PART_READY := TRUE releases job.src:2 (WAIT FOR)",
        # both inputs of the AND: the fewest that make it TRUE are both
        "at 1.008 s, $IN[7] CLAMPED := TRUE, $IN[8] := TRUE releases job.src:4 (WAIT FOR)",
        # WAIT FOR bPermit in WaitPermit: the parameter is bound to the caller's SIGNAL
        "at 1.512 s, $IN[12] bPermisoEntrada := TRUE releases job.src:29 (WAIT FOR)",
    ]
    # the SWITCH over the group polls: its first CASE value other than the current 0
    assert answers[3].endswith("$IN[17..20] PROG_NR := 3 releases job.src:9 (SWITCH)")
    # the polling IF: the first operand of the OR
    assert answers[4].endswith("$IN[4] := TRUE releases job.src:19 (IF)")
    assert len(answers) == 5
    io = [(e["signal"], e["value"], e.get("source")) for e in events if e["kind"] == "io"]
    assert ("$OUT[3]", True, "program") in io and ("$OUT[5]", True, "program") not in io
    assert ("$IN[17]", True, "auto") in io and ("$IN[18]", True, "auto") in io   # 3 = bits 0 and 1
    assert ("$OUT[4]", True, "program") in io
    # WAIT FOR $OUT[30]: an output, nothing the cell can set: the program deadlocks there
    assert (res.reason, res.line) == ("deadlock", 24)
    assert [e for e in events if e["kind"] == "answer"][0] == {
        "t": 0.504, "kind": "answer", "sets": {"$IN[5]": True}, "names": {"$IN[5]": "PART_READY"},
        "file": str(prog), "line": 2, "statement": "WAIT FOR", "condition": "WAIT FOR PART_READY"}
    return events


def test_p00s_program_number_comes_from_the_programs_switch(tmp_path):
    """The fixture's cell.src selects with SWITCH PGNO CASE 1 / CASE 2: the PLC of the
    automatic cell answers the first request with 1 (robot/cellpresets.py timing: 0.120 s),
    bit 0 on $IN[33], odd parity on $IN[42], PGNO_VALID $IN[41]; CASE 1 sets $OUT[1]."""
    rt, res, events = _run(CELLBACKUP / "R1" / "cell.src")
    assert res.reason == "completed", res.text
    pgno = [(e["t"], e["signal"], e["value"]) for e in events if e["kind"] == "io" and e.get("source") == "auto:pgno"]
    assert pgno[:3] == [(0.12, "$IN[33]", True), (0.12, "$IN[42]", True), (0.12, "$IN[41]", True)]
    assert any(e["kind"] == "io" and e["signal"] == "$OUT[1]" and e["t"] == 0.12 for e in events)
    assert rt.mode_op == "EX"      # the automatic cell runs in Automatic External


def test_krl_run_inputs_auto_lists_the_answers(tmp_path):
    prog = _backup(tmp_path)
    trace = tmp_path / "run.jsonl"
    out = CliRunner().invoke(main, ["run", str(prog), "--inputs", "auto", "--trace", str(trace),
                                    "--max-sim-time", "30"])
    assert out.exit_code == 3, out.output          # the deadlock on $OUT[30]
    assert "auto cell  5 answer(s), each 0.5 s after the program starved:" in out.output
    assert "at 0.504 s, $IN[5] PART_READY := TRUE releases job.src:2 (WAIT FOR)" in out.output
    # the answers as rules of a cell file, commented, each valid once uncommented
    rules = CliRunner().invoke(main, ["cell", "init", "--from-run", str(trace)])
    assert rules.exit_code == 0, rules.output
    assert "#   set: {PART_READY: true}" in rules.output
    assert "#   set: {PROG_NR: 3}" in rules.output
    # CLAMP = TRUE (the program's output) was switched on 0.504 s before the answer at 1.008 s
    assert '# - when: "$OUT[6]"\n  #   after: 0.504\n  #   set: {CLAMPED: true, "$IN[8]": true}' in rules.output

    text = uncomment_rules(rules.output)
    doc = yaml.safe_load(text)
    cell = parse_cell(doc, source="from-run")
    assert len(cell.rules) == 5
