"""`krl run --mode T1|T2|AUT|EXT` sets $MODE_OP (reference §7.5) and T1 limits the TCP speed
(reference §6.7 [C]: 250 mm/s); the default is AUT (docs/robot.md, "Operating modes")."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main
from robot.limits import check_trace

PROG = """
DEF modes()
  BAS(#INITMOV, 0)
  $TOOL = $NULLFRAME
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}
  IF $MODE_OP == #T1 THEN
    $OUT[1] = TRUE
  ENDIF
  IF $MODE_OP == #AUT THEN
    $OUT[2] = TRUE
  ENDIF
  IF $MODE_OP == #EX THEN
    $OUT[3] = TRUE
  ENDIF
  IF $MODE_OP == #T2 THEN
    $OUT[4] = TRUE
  ENDIF
  $VEL.CP = 2.0
  LIN {X 450, Y -200, Z 600}
  LIN {X 450, Y 200, Z 600}
END
"""


def _run(tmp_path: Path, *mode: str) -> list[dict]:
    src = tmp_path / "modes.src"
    src.write_text(textwrap.dedent(PROG).lstrip("\n"), encoding="utf-8")
    trace = tmp_path / "t.jsonl"
    res = CliRunner().invoke(main, ["run", str(src), "--trace", str(trace), *mode])
    assert res.exit_code == 0, res.output
    return [json.loads(line) for line in trace.read_text().splitlines()]


@pytest.mark.parametrize("args, out", [((), 2), (("--mode", "T1"), 1), (("--mode", "AUT"), 2),
                                       (("--mode", "EXT"), 3), (("--mode", "t2"), 4)])
def test_mode_sets_mode_op(tmp_path, args, out):
    ev = _run(tmp_path, *args)
    outs = [e["signal"] for e in ev if e["kind"] == "io" and e["value"] is True]
    assert outs == [f"$OUT[{out}]"]


def test_t1_run_keeps_250_mm_s(tmp_path):
    ev = _run(tmp_path, "--mode", "T1")
    lin = [e for e in ev if e["kind"] == "motion" and e["type"] == "LIN" and e["phase"] == "start"]
    assert lin[-1]["limits"]["path"] == 250.0 and lin[-1]["limits"]["flange"] == 250.0
    rep = check_trace(ev)
    assert rep.ok, [str(v) for v in rep.violations]
    assert 0.97 <= rep.path_ratio <= 1.03  # it does run at 250 mm/s
