"""Issue 59: installed software, one rule for every kind of name (krl/semantics/outside.py), the
user's code of KUKA's files kept the user's, and limits that agree with what the user asked.
Each case below is rebuilt from the issue's description of material nobody here has seen; the
expected values are worked out by hand from the programs written here.

1. A backup without ``TP/`` whose KUKA INI folds call ``USERSPOT(#INIT)``, declared in every
   module's data list by ``EXT USERSPOT(S_COMMAND:IN, SPOT_TYPE:IN)`` (SpotTech's user routine,
   installed on the controller, not exported): the EXT resolves the name, nothing defines it,
   and the run stopped on "routine USERSPOT not found".
4. Signals the user deleted from ``$config.dat`` but still writes in the USER PLC fold of
   ``sps.sub``: the checker only warned ("KUKA's system files use it"), and the run stood in
   with an invented ENUM and stopped on "cannot assign False to ... (stand-in ENUM)".
(Case 5 of the issue, the step limit, is tests/interp/test_step_limit.py.)
"""

from __future__ import annotations

from pathlib import Path

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from krl.workspace import workspaces_for
from robot.trace import TraceWriter

from .helpers import write

INTERPS = ("tree", "vm")


def _run(prog: Path, interp: str, **kw):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, check=False, interp=interp, **kw), RunSinks(trace=tw))
    res = rt.run()
    return rt, res, tw.events


def _diags(backup: Path):
    """Every diagnostic of the backup at `backup` (a warning of a name is reported once per
    backup, at its first use)."""
    [ws] = workspaces_for(backup)
    return ws.check()


# ------------------------------------------------------------------ case 1: EXT without a body

WELD_SRC = """
&ACCESS RVP
DEF weld( )
;FOLD INI;%{PE}
  ;FOLD BASISTECH INI
    $OUT[9] = TRUE
  ;ENDFOLD (BASISTECH INI)
;FOLD SPOT INI;%{E}%V3.2.0,%MKUKATPSPOT,%CINIT,%VINIT,%P
USERSPOT(#INIT)
;ENDFOLD (SPOT INI)
  ;FOLD USER INI
  ;ENDFOLD (USER INI)
;ENDFOLD (INI)
$OUT[1] = TRUE
n = SPOTGUNS(2)
IF n == 0 THEN
  $OUT[2] = TRUE
ENDIF
USERSPOT(#SPOT)
END
"""

WELD_DAT = """
DEFDAT weld
;FOLD EXTERNAL DECLARATIONS;%{PE}%MKUKATPBASIS,%CEXT,%VCOMMON,%P
;FOLD SPOTTECH EXT
EXT  USERSPOT (S_COMMAND  :IN,SPOT_TYPE  :IN )
EXTFCT INT SPOTGUNS (INT :IN)
;ENDFOLD (SPOTTECH EXT)
;ENDFOLD (EXTERNAL DECLARATIONS)
DECL INT n = 7
ENDDAT
"""

PICK_SRC = """
DEF pick( )
;FOLD INI;%{PE}
;FOLD SPOT INI;%{E}%V3.2.0,%MKUKATPSPOT,%CINIT,%VINIT,%P
USERSPOT(#INIT)
;ENDFOLD (SPOT INI)
;ENDFOLD (INI)
$OUT[3] = TRUE
END
"""

PICK_DAT = """
DEFDAT pick
EXT  USERSPOT (S_COMMAND  :IN,SPOT_TYPE  :IN )
ENDDAT
"""


def _spot_backup(tmp: Path) -> Path:
    """A backup without TP/: $config.dat declares nothing of SpotTech; every module's data list
    declares USERSPOT by EXT, and nothing defines it."""
    write(tmp, "R1/System/$config.dat", "DEFDAT $CONFIG\nENDDAT\n")
    write(tmp, "R1/Program/pick.src", PICK_SRC)
    write(tmp, "R1/Program/pick.dat", PICK_DAT)
    write(tmp, "R1/Program/weld.dat", WELD_DAT)
    return write(tmp, "R1/Program/weld.src", WELD_SRC)


def test_an_ext_routine_nothing_defines_is_installed_software_for_the_checker(tmp_path):
    _spot_backup(tmp_path)
    diags = _diags(tmp_path)
    assert [d for d in diags if d.is_error] == []
    found = {(d.code, d.message.split("'")[1]) for d in diags}
    # the routines once each (W106), the two types of the EXT signature once each (W105)
    assert {("W106", "USERSPOT"), ("W106", "SPOTGUNS"), ("W105", "S_COMMAND"), ("W105", "SPOT_TYPE")} <= found
    userspot = [d for d in diags if d.code == "W106" and "'USERSPOT'" in d.message]
    assert len(userspot) == 1
    # three calls in two files; the first is in a KUKA fold: that is the evidence it names
    assert "used 3 times in 2 files" in userspot[0].message
    assert "SPOT INI" in userspot[0].message or "KUKATPSPOT" in userspot[0].message
    spotguns = next(d for d in diags if d.code == "W106" and "'SPOTGUNS'" in d.message)
    assert "EXT" in spotguns.message and "weld.dat:5" in spotguns.message
    # the message says what the run does with it
    assert "krl run" in spotguns.help


@pytest.mark.parametrize("interp", INTERPS)
def test_an_ext_routine_nothing_defines_stands_in_with_its_signature(tmp_path, interp):
    """USERSPOT (a procedure) runs as a no-op, SPOTGUNS (EXTFCT INT) returns 0, each with one
    note and its calls counted; the program goes on to its end."""
    prog = _spot_backup(tmp_path)
    rt, res, events = _run(prog, interp)
    assert res.reason == "completed", res.text
    io = [(e["signal"], e["value"]) for e in events if e["kind"] == "io"]
    assert io == [("$OUT[9]", True), ("$OUT[1]", True), ("$OUT[2]", True)]
    notes = [e["text"] for e in events if e["kind"] == "message"]
    assert len([n for n in notes if n.startswith("stub: USERSPOT (procedure")]) == 1
    assert len([n for n in notes if n.startswith("stub: SPOTGUNS (function")]) == 1
    assert any(n.startswith("stub: SPOTGUNS") and n.endswith(": returns 0") for n in notes)
    summary = {name: (what, n) for name, what, n in rt.kss.summary()}
    assert summary["USERSPOT"] == ("procedure", 2)
    assert summary["SPOTGUNS"] == ("function", 1)


def test_both_interpreters_give_the_same_trace_for_the_ext_stand_ins(tmp_path):
    prog = _spot_backup(tmp_path)
    assert _run(prog, "tree")[2] == _run(prog, "vm")[2]


# ------------------------------------------------------------------ case 4: the USER PLC fold is the user's

CONFIG_USER = """
DEFDAT $CONFIG
;FOLD BASISTECH GLOBALS
DECL INT PGNO_TYPE=1
;ENDFOLD (BASISTECH GLOBALS)
;FOLD USER GLOBALS
;Make your modifications here
SIGNAL I_LimitSwitchRear $IN[10]
;ENDFOLD (USER GLOBALS)
ENDDAT
"""

SPS_USER_PLC = """
&ACCESS RVP
&COMMENT PLC on control
DEF  SPS ( )
  ;FOLD INI
  ;FOLD USER INIT
  ; Please insert user defined initialization commands
  ;ENDFOLD (USER INIT)
  ;ENDFOLD (INI)
  LOOP
    ;FOLD BASISTECH PLC
    BasisTech_PLC_LOOP()
    ;ENDFOLD (BASISTECH PLC)
    ;FOLD USER PLC
    ;Make your modifications here
    O_LimitSwitchFront_PLC = I_LimitSwitchFront AND $IN[3]
    $OUT[5] = I_LimitSwitchRear
    ;ENDFOLD (USER PLC)
  ENDLOOP
END
"""


def _plc_backup(tmp: Path) -> Path:
    write(tmp, "R1/System/$config.dat", CONFIG_USER)
    write(tmp, "R1/System/sps.sub", SPS_USER_PLC)
    return write(tmp, "R1/Program/prog.src", "DEF prog( )\n  WAIT SEC 0.5\n  $OUT[1] = TRUE\nEND\n")


def test_names_only_the_user_plc_fold_uses_are_the_programs_errors(tmp_path):
    _plc_backup(tmp_path)
    diags = _diags(tmp_path)
    errors = sorted((d.code, Path(d.path).name, d.line, d.message) for d in diags if d.is_error)
    assert errors == [("E101", "sps.sub", 15, "'I_LimitSwitchFront' is not declared"),
                      ("E101", "sps.sub", 15, "'O_LimitSwitchFront_PLC' is not declared")]
    # the routine of the BASISTECH PLC fold (KUKA's part of sps.sub) stays installed software
    assert [(d.code, d.line) for d in diags if "BasisTech_PLC_LOOP" in d.message] == [("W106", 11)]


@pytest.mark.parametrize("interp", INTERPS)
def test_the_user_plc_fold_stops_on_its_own_error_in_krl_words(tmp_path, interp):
    """The robot program completes; the SPS stops at its USER PLC line on the name the user
    deleted (the right-hand side is evaluated first), as the checker's E101 says; no stand-in."""
    prog = _plc_backup(tmp_path)
    rt, res, events = _run(prog, interp, submit=[tmp_path / "R1/System/sps.sub"])
    assert res.reason == "completed", res.text
    [sps] = [t for t in rt.scheduler.tasks if t.kind == "submit"]
    reason, err = sps.outcome
    assert reason == "error"
    # issue 85: with the checker's E101 (line 15, column 30: after "    O_LimitSwitchFront_PLC = ")
    assert (err.message, err.line) == (
        "unknown name I_LimitSwitchFront: the backup declares no I_LimitSwitchFront (krl check: E101 at "
        "sps.sub:15:30); KUKA's controller does not link sps.sub with that error, so no program that is or "
        "calls sps.sub can be selected", 15)
    names = {name for name, _what, _n in rt.kss.summary()}
    assert not names & {"I_LIMITSWITCHFRONT", "O_LIMITSWITCHFRONT_PLC", "I_LimitSwitchFront",
                        "O_LimitSwitchFront_PLC"}
    assert "BasisTech_PLC_LOOP" in names


@pytest.mark.parametrize("interp", INTERPS)
def test_a_value_that_does_not_convert_is_named_in_krl_words(tmp_path, interp):
    prog = write(tmp_path, "prog.src", "DEF prog( )\n  DECL INT n\n  DECL BOOL b\n  b = TRUE\n  n = b\nEND\n")
    _rt, res, _events = _run(prog, interp)
    assert (res.reason, res.line, res.text) == ("error", 5, "cannot assign TRUE to INT")
