"""The system software a backup expects (issue 22), on both interpreters with identical traces:
CONST arrays initialised element by element in their data list (reference §2.5
``array_elem_init``), GETSYSSTATE, system variables that the simulator does not model, and the
submit-interpreter errors of the real-programs report.

Expected values are worked out by hand from the programs below.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from interp import realprograms as rp
from interp.run import make_runtime
from krl.workspace import workspaces_for
from robot.trace import TraceWriter

from .helpers import run_krl, write

INTERPS = ("tree", "vm")


def both(tmp: Path, src: str, dat: str | None = None, **kw):
    """Run the program on the tree interpreter and the VM; their traces are identical."""
    runs = [run_krl(tmp, src, dat, interp=i, **kw) for i in INTERPS]
    assert runs[0].events == runs[1].events
    r0, r1 = runs[0].result, runs[1].result
    assert (r0.reason, r0.text, r0.line) == (r1.reason, r1.text, r1.line)
    return runs


def messages(run) -> list[str]:
    return [e["text"] for e in run.kinds("message")]


# ------------------------------------------------------------------ CONST arrays

CONST_DAT = """
DEFDAT prog
  DECL CONST REAL a[2]
  a[1] = 1.5
  a[2] = -2.25
  CONST CHAR nm[16]
  nm[] = "hello"
  DECL GLOBAL CONST INT seq[3]
  seq[1] = 3
  seq[3] = 1
  DECL REAL total
  DECL INT n
ENDDAT
"""


def test_const_array_elements_initialised_in_the_data_list(tmp_path):
    src = """
    DEF prog()
      total = a[1] + a[2]
      n = STRLEN(nm[]) * 10 + seq[1] - seq[3]
    END
    """
    for run in both(tmp_path, src, CONST_DAT):
        assert run.result.reason == "completed", run.result.text
        assert run.var("prog", "total") == pytest.approx(-0.75)     # 1.5 + -2.25
        assert run.var("prog", "n") == 52                           # 5 * 10 + 3 - 1


def test_const_array_element_not_initialised_is_value_invalid(tmp_path):
    src = """
    DEF prog()
      n = seq[2]
    END
    """
    for run in both(tmp_path, src, CONST_DAT):
        assert (run.result.reason, run.result.line) == ("error", 2)
        assert "value invalid: seq[2]" in run.result.text


def test_const_array_assigned_by_the_program_is_refused_by_checker_and_run(tmp_path):
    src = """
    DEF prog()
      a[1] = 2.0
    END
    """
    for run in both(tmp_path, src, CONST_DAT):
        assert (run.result.reason, run.result.line) == ("error", 2)
        assert "a[1] is write-protected" in run.result.text
        assert run.var("prog", "a").data == [1.5, -2.25]
    [ws] = workspaces_for(tmp_path / "prog.src")
    diags = ws.check()
    assert [(d.code, d.line) for d in diags if d.is_error] == [("E502", 2)]


def test_const_array_elements_in_the_data_list_pass_the_checker(tmp_path):
    write(tmp_path, "prog.src", "DEF prog()\n  total = a[1]\nEND\n")
    write(tmp_path, "prog.dat", CONST_DAT)
    [ws] = workspaces_for(tmp_path / "prog.src")
    assert [d for d in ws.check() if d.is_error] == []


# ------------------------------------------------------------------ GETSYSSTATE

def test_getsysstate_stopbits_and_an_unknown_command(tmp_path):
    src = """
    DEF prog()
      DECL INT ip
      DECL REAL rp
      DECL BOOL ok
      ip = 5
      rp = 2.5
      ok = GETSYSSTATE("STOPBITS", ip, rp)
      $OUT[1] = ok AND (ip == 0) AND (rp == 0.0)
      ip = 7
      ok = GetSysState("NOSUCH", ip, rp)
      $OUT[2] = (NOT ok) AND (ip == 7)
      ok = GetSysState("NOSUCH", ip, rp)
    END
    """
    for run in both(tmp_path, src):
        assert run.result.reason == "completed", run.result.text
        assert run.io("$OUT[1]") == [(0.0, True)]
        assert run.io("$OUT[2]") == [(0.0, True)]
        assert messages(run) == ['not simulated: GETSYSSTATE("NOSUCH") answers FALSE']   # once


# ------------------------------------------------------------------ system variables not simulated

def _backup(tmp: Path, program: str) -> Path:
    """A minimal KRC backup: R1/System/$config.dat, R1/Mada/$robcor.dat declaring two
    system variables the simulator does not model, and R1/Program/prog.src."""
    for d in ("R1/System", "R1/Mada", "R1/Program"):
        (tmp / d).mkdir(parents=True)
    write(tmp, "R1/System/$config.dat", "DEFDAT $CONFIG\nENDDAT\n")
    write(tmp, "R1/Mada/$robcor.dat", """
    DEFDAT $ROBCOR
    REAL $DEF_L_M=210.000 ;DEFAULTMASSE AM FLANSCH
    INT $TORQMON_DEF[3]
    $TORQMON_DEF[2]=40
    ENDDAT
    """)
    return write(tmp, "R1/Program/prog.src", program)


def _run_backup(prog: Path, interp: str):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(prog, trace=tw, mujoco=False, check=False, interp=interp)
    res = rt.run()
    return res, [e["text"] for e in tw.events if e["kind"] == "message"], tw.events, rt


SYS_PROG = """
DEF prog()
  DECL REAL m
  DECL INT t
  m = $DEF_L_M + $DEF_L_M
  t = $TORQMON_DEF[2] + $TORQMON[4]
  $TORQMON[4] = 3
  t = t + $TORQMON[4]
  $OUT[1] = (m == 420.0) AND (t == 43)
  t = $NO_SUCH_VARIABLE
END
"""


def test_declared_system_variable_reads_its_declared_value_with_one_note(tmp_path):
    prog = _backup(tmp_path, SYS_PROG)
    out = []
    for interp in INTERPS:
        res, notes, events, rt = _run_backup(prog, interp)
        out.append(events)
        assert rt.program.backup
        # 210 + 210 = 420; 40 (declared in $robcor.dat) + 0 (KSS's $TORQMON, no value) + 3 = 43
        assert rt.controller.io.get_out(1), (interp, res.text, notes)
        assert notes == [
            "not simulated: system variable $DEF_L_M reads its value declared at R1/Mada/$robcor.dat:2",
            "not simulated: system variable $TORQMON_DEF reads its value declared at R1/Mada/$robcor.dat:3",
            "not simulated: system variable $TORQMON (declared by KSS's system files, not by this "
            "program's): reads 0/FALSE",
        ]
        # an undeclared, unsimulated $ name is the controller's error, not a new variable
        assert (res.reason, res.line) == ("error", 9)
        assert res.text == "unknown name $NO_SUCH_VARIABLE"
    assert out[0] == out[1]


def test_undeclared_system_variable_is_an_error_outside_a_backup_too(tmp_path):
    src = """
    DEF prog()
      $NO_SUCH_VARIABLE = 1
    END
    """
    for run in both(tmp_path, src):
        assert (run.result.reason, run.result.line, run.result.text) == \
            ("error", 2, "unknown name $NO_SUCH_VARIABLE")


# ------------------------------------------------------------------ submit errors in the report

def test_submit_errors_are_in_the_real_programs_row_and_report(tmp_path):
    sub = """
    DEF sps()
      DECL INT k
      k = 0
      k = 10 / k
    END
    """
    src = """
    DEF prog()
      WAIT SEC 0.1
    END
    """
    for interp in INTERPS:
        run = run_krl(tmp_path, src, files={"sps.sub": sub}, submit=["sps.sub"], interp=interp)
        assert run.result.reason == "completed"
        errs = rp.submit_errors(run.rt)
        assert len(errs) == 1 and errs[0].startswith("sps: ") and errs[0].endswith(f"{tmp_path / 'sps.sub'}:4")
    rows = [{"program": "a", "reason": "completed", "text": "", "submit": errs},
            {"program": "b", "reason": "completed", "text": "", "submit": []}]
    text = rp.report(rows)
    assert "Submit-interpreter errors: 1 of 2 runs:" in text
