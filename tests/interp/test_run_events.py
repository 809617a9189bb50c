"""What a run of the real-programs report keeps of the controller's events (interp/realprograms.py
RunEvents, issue 49): the motion errors with their kind and the motion's place, the times P00's
program-number request rose; and the entry points of a folder that is not a backup."""

from __future__ import annotations

from pathlib import Path

from interp import realprograms as rp

CONFIG = """DEFDAT $CONFIG PUBLIC
INT PGNO_REQ=33
ENDDAT
"""

#: the request output ($OUT[PGNO_REQ]) rises three times, a period of two WAIT SEC 0.5 apart; the
#: LIN at line 16 goes to X 5000 mm: out of the KR 6 R900's reach (its arm is 0.9 m long)
PROGRAM = """DEF p()
  DECL INT n
  $BASE = $NULLFRAME
  $TOOL = $NULLFRAME
  $VEL.CP = 0.2
  $ACC.CP = 1.0
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
  FOR n = 1 TO 3
    $OUT[33] = TRUE
    WAIT SEC 0.5
    $OUT[33] = FALSE
    WAIT SEC 0.5
  ENDFOR
  $OUT[33] = FALSE
  $OUT[34] = TRUE
  LIN {X 5000, Y 0, Z 500, A 0, B 90, C 0}
END
"""


def _backup(tmp_path: Path) -> Path:
    root = tmp_path / "b"
    (root / "R1" / "System").mkdir(parents=True)
    (root / "R1" / "Program").mkdir(parents=True)
    (root / "R1" / "System" / "$config.dat").write_text(CONFIG)
    (root / "R1" / "Program" / "p.src").write_text(PROGRAM)
    return root / "R1" / "Program" / "p.src"


def test_a_run_keeps_its_motion_errors_and_program_number_requests(tmp_path):
    prog = _backup(tmp_path)
    row = rp.run_one(prog, 20.0, 100_000, auto=True, interp="vm", auto_sim_time=20.0)
    # rising edges of $OUT[33] only: three requests, a period apart: two WAIT SEC 0.5, each
    # ending at a whole 12 ms IPO cycle (0.5 / 0.012 = 41.7: 42 cycles, 0.504 s)
    assert row["requests_total"] == 3
    assert [round(b - a, 3) for a, b in zip(row["requests"], row["requests"][1:])] == [1.008, 1.008]
    # the LIN's target is out of reach: the program stops there, one motion error of kind reach
    assert row["reason"] == "error" and row["line"] == 16
    assert row["event_counts"] == {"reach": 1}
    (ev,) = row["events"]
    assert ev["kind"] == "reach" and ev["line"] == 16 and "not reachable" in ev["text"]
    assert row["motions"] >= 1


def test_motion_event_kinds_from_the_controllers_messages():
    assert rp.motion_event_kind("workspace error: target not reachable with status S=2") == "reach"
    assert rp.motion_event_kind("software limit switch -A5") == "limit"
    assert rp.motion_event_kind("CP path through a singularity: A4 would turn 170 deg") == "singularity"
    assert rp.motion_event_kind("speed limit exceeded A4: CP path through a singularity") == "singularity"
    assert rp.motion_event_kind("CIRC: start, auxiliary and end point do not define a circle") == "motion"


def test_the_entry_points_of_a_folder_that_is_not_a_backup(tmp_path):
    (tmp_path / "deep" / "er").mkdir(parents=True)
    files = {"top.src": "DEF top()\nEND\n", "deep/er/nested.src": "DEF nested()\nEND\n",
             "deep/lib.src": "DEF lib(x:IN)\n  INT x\nEND\n", "deep/fn.src": "DEFFCT INT fn()\n  RETURN 1\nENDFCT\n",
             "deep/er/cyc.sub": "DEF cyc()\nEND\n", "deep/data.dat": "DEFDAT data\nENDDAT\n"}
    for rel, text in files.items():
        (tmp_path / rel).write_text(text)
    listed = [tmp_path / rel for rel in files]
    # a DEF without parameters is a program; a DEF with one and a DEFFCT are not; a .sub runs alone
    assert rp.folder_entries(listed) == [tmp_path / "top.src", tmp_path / "deep/er/nested.src",
                                         tmp_path / "deep/er/cyc.sub"]
