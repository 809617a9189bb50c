"""Signals, VARSTATE, $ADVANCE, spline blocks, CIRC, _REL, WITH, the CLI and the trace."""

from __future__ import annotations

import json
import subprocess

import pytest

from robot.trace import validate_event
from tests.forkserver import krl_command

from .helpers import run_krl, write

DAT = """
DEFDAT prog
  DECL INT N1, N2
  DECL BOOL B1
  DECL VAR_STATE VS1, VS2
  SIGNAL GripClose $OUT[17]
  SIGNAL ProgNo $IN[33] TO $IN[36]
ENDDAT
"""

HOME = "PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}"   # A5 = 0 would be the wrist singularity


def test_signals_bit_and_group(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      GripClose = TRUE
      WAIT SEC 0.05
      N1 = ProgNo
    END
    """, DAT, stimuli='stimuli:\n  - at: 0.0\n    set: {"$IN[33]": true, "$IN[35]": true}\n')
    assert r.io("$OUT[17]")[0][1] is True
    assert r.var("prog", "N1") == 5          # bits 1 and 3 (LSB first)


def test_varstate(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      DECL INT k
      VS1 = VARSTATE("k")
      k = 3
      VS2 = VARSTATE("k")
      B1 = VARSTATE("nothing") == #UNKNOWN
    END
    """, DAT)
    assert r.var("prog", "VS1").name == "DECLARED"
    assert r.var("prog", "VS2").name == "INITIALIZED"
    assert r.var("prog", "B1") is True


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_varstate_of_a_system_variable_the_program_uses_nowhere_else(tmp_path, interp):
    """VARSTATE's text is placed while the program runs (Names.ref_from_text): a system
    variable no statement of the program names gets a system slot past the program's list. Found
    by the variants of issue 59 (KUKA's BrakeTestReq.src run without $config.dat): an internal
    IndexError before."""
    r = run_krl(tmp_path, """
    DEF prog()
      B1 = VARSTATE("$VEL_ACT") == #INITIALIZED
    END
    """, DAT, interp=interp)
    assert r.result.reason == "completed", r.result.text
    assert r.var("prog", "B1") is True


def test_advance_limits_planning(tmp_path):
    src = f"""
    DEF prog()
      $ADVANCE = {{ADV}}
      {HOME}
      PTP {{A1 20}}
      PTP {{A1 40}}
      PTP {{A1 60}}
      PTP {{A1 80}}
      N1 = 1
    END
    """
    r1 = run_krl(tmp_path, src.replace("{ADV}", "1"), DAT)
    r3 = run_krl(tmp_path, src.replace("{ADV}", "3"), DAT)

    def t_of_n1(r):
        return [e["t"] for e in r.events if e["kind"] == "stmt" and e["line"] == 8][0]
    # N1 = 1 runs when the last motion is planned: with $ADVANCE 1 only one motion may wait
    # in the queue, so the advance run reaches line 8 later than with $ADVANCE 3
    assert t_of_n1(r1) > t_of_n1(r3)


def test_lin_rel_circ_and_spline(tmp_path):
    r = run_krl(tmp_path, f"""
    DEF prog()
      {HOME}
      LIN_REL {{Z -50}}
      LIN_REL {{X 20}} #TOOL
      CIRC {{X 480, Y 30, Z 790}}, {{X 460, Y 0, Z 790}}
      SPLINE
        SPL {{X 460, Y 30, Z 780}}
        SLIN {{X 480, Y 30, Z 770}}
      ENDSPLINE
      SLIN {{X 500, Y 0, Z 790}} WITH $VEL = {{CP 0.2, ORI1 100, ORI2 100}}
    END
    """)
    assert r.result.reason == "completed", r.result
    types = [e["type"] for e in r.kinds("motion") if e["phase"] == "start"]
    assert types == ["PTP", "LIN_REL", "LIN_REL", "CIRC", "SPLINE", "SLIN"]


def test_trace_is_deterministic_and_valid(tmp_path):
    src = """
    DEF prog()
      DECL INT i
      FOR i = 1 TO 3
        $OUT[i] = TRUE
      ENDFOR
      WAIT SEC 0.05
    END
    """
    a = run_krl(tmp_path, src)
    b = run_krl(tmp_path, src)
    assert a.trace.lines == b.trace.lines
    for ev in a.events:
        validate_event(ev)
    assert a.events[-1]["kind"] == "end" and a.events[-1]["reason"] == "completed"
    assert {"call", "return", "stmt"} <= {e["kind"] for e in a.events}


def _krl(*args, cwd=None):
    # a fork of the worker's fork server (tests/forkserver.py): krl's main without the import
    # of the project at each start
    return subprocess.run([*krl_command(), *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=120)


def test_cli_exit_codes_and_trace(tmp_path):
    ok = write(tmp_path, "ok.src", "DEF ok()\n  $OUT[1] = TRUE\nEND\n")
    bad = write(tmp_path, "bad.src", "DEF bad()\n  DECL INT u\n  u = u + 1\nEND\n")
    halt = write(tmp_path, "stop1.src", "DEF stop1()\n  HALT\nEND\n")
    out = tmp_path / "t.jsonl"
    p = _krl("run", ok, "--trace", out)
    assert p.returncode == 0, p.stderr
    events = [json.loads(x) for x in out.read_text().splitlines()]
    assert events[-1]["kind"] == "end" and events[-1]["reason"] == "completed"
    p = _krl("run", bad)
    assert p.returncode == 1 and "value invalid" in p.stdout and "bad.src:3" in p.stdout
    p = _krl("run", halt)
    assert p.returncode == 3 and "stopped by HALT" in p.stdout and "stop1.src:2" in p.stdout


def test_cycflag_is_reevaluated_and_fires_an_interrupt(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      $CYCFLAG[2] = $IN[4] AND $IN[5]
      INTERRUPT DECL 10 WHEN $CYCFLAG[2] DO Found()
      INTERRUPT ON 10
      WAIT SEC 0.5
    END
    DEF Found()
      $OUT[1] = TRUE
    END
    """, stimuli='stimuli:\n  - at: 0.1\n    set: {"$IN[4]": true}\n  - at: 0.2\n    set: {"$IN[5]": true}\n')
    assert r.io("$OUT[1]")[0][0] == pytest.approx(0.204, abs=0.013)


def test_anout_anin_on_off(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      SIGNAL SpeedOut $ANOUT[1]
      SIGNAL SensIn $ANIN[2]
      DECL REAL v
      ANOUT ON SpeedOut = 0.5 * SensIn
      ANIN ON v = 1.0 * SensIn
      WAIT SEC 0.3
      ANOUT OFF SpeedOut
      ANIN OFF SensIn
      $OUT[1] = ABS(v - 0.8) < 0.0001
      $ANOUT[1] = 0.1
    END
    """, stimuli='stimuli:\n  - at: 0.1\n    set: {"$ANIN[2]": 0.8}\n')
    assert r.result.reason == "completed"
    assert [v for _, v in r.io("$ANOUT[1]")] == [pytest.approx(0.4), pytest.approx(0.1)]
    assert r.io("$OUT[1]")[0][1] is True


def test_stub_statements_import_and_routine_const(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      DECL CONST INT OFFS = 10
      DECL INT handle
      IMPORT INT parts IS /R1/cell..PartCount
      handle = 0
      CONFIRM handle
      ASYPTP {E1 90}
      parts = parts + OFFS
    END
    """, files={"cell.dat": "DEFDAT cell\n  DECL INT PartCount = 7\nENDDAT\n"})
    assert r.result.reason == "completed", r.result
    assert r.var("cell", "PartCount") == 17
    assert any("stub: CONFIRM" in e.get("text", "") for e in r.kinds("message"))


def test_trigger_call_arguments_are_evaluated_in_the_advance_run(tmp_path):
    r = run_krl(tmp_path, f"""
    DEF prog()
      DECL INT n
      {HOME}
      n = 3
      TRIGGER WHEN DISTANCE=1 DELAY=0 DO Mark(n) PRIO=-1
      PTP {{A1 20}}
      n = 5
    END
    DEF Mark(k :IN)
      DECL INT k
      $OUT[k] = TRUE
    END
    """)
    assert r.io("$OUT[3]") and not r.io("$OUT[5]")


def test_no_return_event_after_an_error(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      Fail()
    END
    DEF Fail()
      DECL INT u
      u = u + 1
    END
    """)
    assert r.result.reason == "error"
    assert not [e for e in r.kinds("return") if e["name"] == "Fail"]


def test_cli_refuses_a_program_with_errors_unless_no_check(tmp_path):
    """A program the checker rejects does not run (exit 1, the errors and "not started"),
    unless --no-check: then it runs and stops on the run-time error at that line."""
    bad = write(tmp_path, "chk.src", "DEF chk()\n  DECL INT i\n  $OUT[1] = TRUE\n  i = Nowhere()\nEND\n")
    p = _krl("run", bad)
    assert p.returncode == 1 and "E106" in p.stdout and "not started" in p.stdout
    p = _krl("run", bad, "--no-check")
    assert p.returncode == 1 and "not started" not in p.stdout
    assert "chk.src:4" in p.stdout and "routine Nowhere not found" in p.stdout
