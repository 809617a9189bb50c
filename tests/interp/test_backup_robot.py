"""`krl run` in a backup simulates the backup's robot (issue 22): the one of its
R1/Mada/$machine.dat, unless --robot names another; KRL code and the controller see the same
robot ($TRAFONAME, soft limits), and the summary and the trace header name it."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from click.testing import CliRunner

from app import main

BASIS = Path(__file__).resolve().parents[2] / "interp" / "basis"
KR6 = Path(__file__).resolve().parents[2] / "robot" / "data" / "kr6_r900.yaml"

PROGRAM = """DEF reach()
  DECL CHAR name[32]
  name[] = $TRAFONAME[]
  IF $SOFTP_END[3] <> 155.0 THEN
    HALT
  ENDIF
  IF name[9] <> "7" THEN
    HALT
  ENDIF
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
  PTP {X 2200, Y 0, Z 1200, A 0, B 60, C 0}
  LIN_REL {X 100, Z -100}
END
"""


def make_backup(tmp_path: Path, corpus: Path) -> Path:
    """A minimal KRC backup: System/$config.dat (the project's BASIS), the KR 120 R2700 extra HA
    machine data of a corpus backup, and one program."""
    for sub, src in (("System", BASIS / "$config.dat"), ("System", BASIS / "bas.src"),
                     ("Mada", corpus / "khrzysio__KRC4_test" / "R1" / "Mada" / "$machine.dat")):
        (tmp_path / "R1" / sub).mkdir(parents=True, exist_ok=True)
        shutil.copy(src, tmp_path / "R1" / sub / src.name)
    prog = tmp_path / "R1" / "Program" / "reach.src"
    prog.parent.mkdir(parents=True)
    prog.write_text(PROGRAM, encoding="ascii")
    return prog


def test_run_in_a_backup_uses_its_robot(tmp_path, shared_corpus):
    prog = make_backup(tmp_path, shared_corpus)
    trace = tmp_path / "t.jsonl"
    res = CliRunner().invoke(main, ["run", str(prog), "--no-check", "--trace", str(trace)])
    # the target lies 2.2 m out: reachable by the KR 120 R2700 (2.7 m), not by a KR 6 R900
    assert res.exit_code == 0, res.output
    mada = tmp_path / "R1" / "Mada" / "$machine.dat"
    assert f"  robot      KR120R2700 EXTRA HA C4 FLR ({mada})" in res.output.splitlines()
    head = json.loads(trace.read_text(encoding="utf-8").splitlines()[0])
    assert head == {"t": 0.0, "kind": "robot", "name": "KR120R2700 EXTRA HA C4 FLR", "source": str(mada),
                    "trafoname": "#KR120R2700 EXTRA HA C4 FLR"}


def test_robot_option_overrides_the_backup_robot_for_krl_code_too(tmp_path, shared_corpus):
    prog = make_backup(tmp_path, shared_corpus)
    for interp in ("tree", "vm"):
        res = CliRunner().invoke(main, ["run", str(prog), "--no-check", "--interp", interp, "--robot", str(KR6)])
        # KRL reads the simulated robot's $SOFTP_END[3] (156 on the KR 6 R900), not the Mada's 155
        assert res.exit_code == 3, res.output
        assert f"{prog}:5" in res.output
        assert "  robot      KR 6 R900 sixx" in res.output


def test_bad_robot_path_is_a_clear_error(tmp_path):
    prog = tmp_path / "p.src"
    prog.write_text("DEF p()\nEND\n", encoding="ascii")
    res = CliRunner().invoke(main, ["run", str(prog), "--robot", str(tmp_path / "none.dat")])
    assert res.exit_code == 2
    assert "no such file or folder" in res.output
    assert "Traceback" not in res.output
