"""A backup whose System folder lacks bas.src runs the BAS commands on the project's model of
KUKA's BASIS (issue 72 item 5; interp/runtime/kss.py ``STANDARD``): BAS(#INITMOV), BAS(#TOOL, n),
BAS(#BASE, n), BAS(#PTP_PARAMS, v), BAS(#CP_PARAMS, v) act on the system variables with the
backup's own ``$config.dat`` data (its TOOL_DATA, BASE_DATA, DEF_* values), not as stand-ins
that do nothing.

The case as the issue saw it: the palletizer of ../shared/krl-corpus without bas.src stopped on
"software limit switch +A1" at 3.48 s (its tool and speeds never set); with bas.src it runs on.
The small backup below is written here in the layout of a KR C4 backup, with a ``$config.dat``
of its own values (not the project's BASIS defaults: DEF_ACC_PTP 20, TOOL_DATA[2] Z 300); the
expected values are worked out by hand from the reference, 6.4 ("BAS(#TOOL, n) sets $TOOL =
TOOL_DATA[n]", $BASE = BASE_DATA[n]) and 6.9 (#INITMOV: $ACC_AXIS = DEF_ACC_PTP, $TOOL =
TOOL_DATA[1] with its load LOAD_DATA[1], $BASE = $WORLD; #PTP_PARAMS: $APO from PDAT_ACT, FRAMES, VEL_PTP(v) = DEF_VEL_PTP
* v / 100; #CP_PARAMS: $APO.CDIS, $ORI_TYPE from LDAT_ACT, $VEL.CP = v).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from robot.trace import TraceWriter

from .helpers import write

INTERPS = ("tree", "vm")

# a KR C4's $config.dat as KUKA writes it (KSS 8.3: its BASIS types, EXT BAS, the DEF_* motion
# defaults, the tool and base data), with this cell's own values; no DEF_ADAP_ACC or
# DEF_LOAD_DATA (the project's model reads them: its BASIS $config.dat fills them in)
CONFIG = """DEFDAT  $CONFIG
ENUM APO_MODE_T CPTP,CDIS
ENUM BAS_COMMAND INITMOV,ACC_CP,ACC_PTP,VEL_CP,VEL_PTP,ACC_GLUE,TOOL,BASE,EX_BASE,PTP_DAT,CP_DAT,OUT_SYNC,OUT_ASYNC,GROUP,FRAMES,PTP_PARAMS,CP_PARAMS
ENUM OUT_MODETYPE TRIGGER_,CONT_,STOP_
STRUC PDAT REAL VEL,ACC,APO_DIST,APO_MODE_T APO_MODE,REAL GEAR_JERK,INT EXAX_IGN
STRUC LDAT REAL VEL,ACC,APO_DIST,APO_FAC,AXIS_VEL,AXIS_ACC,ORI_TYPE ORI_TYP,CIRC_TYPE CIRC_TYP,REAL JERK_FAC,GEAR_JERK,INT EXAX_IGN,CIRC_MODE CB
STRUC FDAT INT TOOL_NO,BASE_NO,IPO_MODE IPO_FRAME,CHAR POINT2[24],BOOL TQ_STATE
STRUC ODAT INT OUT_NO,BOOL STATE,REAL PULSE_TIME,OUT_MODETYPE OUT_MODE,REAL TIME_DELAY,OFFSET
EXT  BAS (BAS_COMMAND  :IN,REAL  :IN )
DECL INT DEF_ADVANCE=3
DECL REAL DEF_VEL_PTP=100.0
DECL REAL DEF_ACC_PTP=20.0
DECL REAL DEF_VEL_CP=1.5
DECL REAL DEF_ACC_CP=2.0
DECL REAL DEF_VEL_ORI1=150.0
DECL REAL DEF_VEL_ORI2=150.0
DECL REAL DEF_ACC_ORI1=100.0
DECL REAL DEF_ACC_ORI2=100.0
DECL REAL DEF_APO_CPTP=50.0
DECL REAL DEF_APO_CDIS=3.0
DECL REAL DEF_APO_CVEL=100.0
DECL REAL DEF_APO_CORI=5.0
DECL CIRC_TYPE DEF_CIRC_TYP=#BASE
DECL FRAME TOOL_DATA[16]
TOOL_DATA[1]={X 0.0,Y 0.0,Z 150.0,A 0.0,B 0.0,C 0.0}
TOOL_DATA[2]={X 10.0,Y 0.0,Z 300.0,A 0.0,B 0.0,C 0.0}
DECL FRAME BASE_DATA[32]
BASE_DATA[1]={X 1000.0,Y 200.0,Z 0.0,A 90.0,B 0.0,C 0.0}
DECL LOAD LOAD_DATA[16]
LOAD_DATA[1]={M 12.5,CM {X 0.0,Y 0.0,Z 80.0,A 0.0,B 0.0,C 0.0},J {X 0.1,Y 0.1,Z 0.1}}
LOAD_DATA[2]={M -1.0,CM {X 0.0,Y 0.0,Z 0.0,A 0.0,B 0.0,C 0.0},J {X 0.0,Y 0.0,Z 0.0}}
DECL PDAT PDEFAULT={VEL 100.0,ACC 100.0,APO_DIST 100.0,APO_MODE #CDIS}
DECL LDAT LDEFAULT={VEL 2.0,ACC 100.0,APO_DIST 100.0,APO_FAC 50.0,ORI_TYP #VAR,CIRC_TYP #BASE}
DECL FDAT FDEFAULT={TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " "}
DECL ODAT ODEFAULT={OUT_NO 1,STATE TRUE,PULSE_TIME 0.0,OUT_MODE #STOP_,TIME_DELAY 0.0,OFFSET 0.0}
DECL PDAT PDAT_ACT
DECL LDAT LDAT_ACT
DECL FDAT FDAT_ACT
DECL ODAT ODAT_ACT
ENDDAT
"""

CELL = """DEF cell()
  BAS(#INITMOV, 0)
  $OUT[1] = ($ACC_AXIS[1] == 20.0) AND ($TOOL.Z == 150.0) AND ($ACT_TOOL == 1) AND ($BASE.X == 0.0) AND ($ACT_BASE == 0) AND ($LOAD.M == 12.5)
  BAS(#TOOL, 2)
  $OUT[2] = ($TOOL.Z == 300.0) AND ($TOOL.X == 10.0) AND ($ACT_TOOL == 2)
  BAS(#BASE, 1)
  $OUT[3] = ($BASE.X == 1000.0) AND ($BASE.A == 90.0) AND ($ACT_BASE == 1)
  PDAT_ACT = {VEL 100.0, ACC 100.0, APO_DIST 10.0, APO_MODE #CDIS}
  FDAT_ACT = {TOOL_NO 1, BASE_NO 0, IPO_FRAME #BASE}
  BAS(#PTP_PARAMS, 50.0)
  $OUT[4] = ($VEL_AXIS[1] == 50.0) AND ($APO.CDIS == 10.0) AND ($TOOL.Z == 150.0) AND ($ACT_TOOL == 1) AND ($ACT_BASE == 0)
  LDAT_ACT = {VEL 2.0, ACC 100.0, APO_DIST 5.0, APO_FAC 50.0, ORI_TYP #CONSTANT, CIRC_TYP #BASE}
  BAS(#CP_PARAMS, 0.3)
  $OUT[5] = ($VEL.CP == 0.3) AND ($APO.CDIS == 5.0) AND ($ORI_TYPE == #CONSTANT)
END
"""


def _backup(tmp: Path) -> Path:
    """A KR C4 backup (R1/System/$config.dat, no bas.src) with the cell program."""
    write(tmp, "R1/System/$config.dat", CONFIG)
    return write(tmp, "R1/Program/cell.src", CELL)


def _completed(prog: Path, interp: str) -> tuple:
    """(Runtime, its kept trace) of `prog` run on `interp` to its END."""
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, interp=interp), RunSinks(trace=tw))
    res = rt.run()
    assert res.reason == "completed", (res.reason, res.text)
    return rt, tw


@pytest.mark.parametrize("interp", INTERPS)
def test_bas_commands_act_in_a_backup_without_bas_src(tmp_path, interp):
    prog = _backup(tmp_path)
    rt, tw = _completed(prog, interp)
    outs = {e["signal"]: e["value"] for e in tw.events if e["kind"] == "io"}
    assert outs == {f"$OUT[{i}]": True for i in range(1, 6)}
    # never silently: the run says the BASIS is the project's model, and why
    notes = [e["text"] for e in tw.events if e["kind"] == "message"]
    assert ("stub: BAS (the backup has no BAS of its own (KUKA's R1/System/bas.src); the project's "
            "model of KUKA's BASIS runs (interp/basis/bas.src))") in notes
    assert {n: (w, c) for n, w, c in rt.kss.summary()}["BAS"] == ("BASIS model", 5)


@pytest.mark.slow
@pytest.mark.parametrize("interp", INTERPS)
def test_the_palletizer_without_bas_src_runs_on(tmp_path, interp, shared_corpus):
    """The issue's case: ../shared/krl-corpus/ingeniado__KRC4-Robot-Palletizer copied without
    System/bas.src, --inputs auto: it stopped on "software limit switch +A1" at 3.48 s; with
    the model it runs on to the time limit, as the backup with its own bas.src does."""
    dst = tmp_path / "pal"
    shutil.copytree(shared_corpus / "ingeniado__KRC4-Robot-Palletizer", dst)
    (dst / "System" / "bas.src").unlink()
    rt, _ = make_runtime(run_spec(dst / "main.src", mujoco=False, interp=interp, inputs="auto", max_sim_time=10.0))
    res = rt.run()
    assert (res.reason, res.text) == ("max_sim_time", "simulated time limit 10.0 s reached")


@pytest.mark.parametrize("interp", INTERPS)
def test_outside_a_backup_the_basis_is_the_programs_own_not_a_stand_in(tmp_path, interp):
    """Outside a backup the project's BASIS is the program's System folder (krl/project.py rule
    4): BAS runs there without a note or a count (the model's note is for a backup only)."""
    prog = write(tmp_path, "prog.src", "DEF prog()\n  BAS(#INITMOV, 0)\n  $OUT[1] = $ACT_TOOL == 1\nEND\n")
    rt, tw = _completed(prog, interp)
    assert [e["text"] for e in tw.events if e["kind"] == "message"] == []
    assert "BAS" not in {n for n, _w, _c in rt.kss.summary()}
    assert [(e["signal"], e["value"]) for e in tw.events if e["kind"] == "io"] == [("$OUT[1]", True)]


# a KR C2's $config.dat (KSS 5): its PDAT has no APO_MODE, its LDAT no CIRC_TYP (KUKA added them
# with KSS 8's spline forms); the cell's defaults of its own
CONFIG_KRC2 = """DEFDAT  $CONFIG
ENUM BAS_COMMAND INITMOV,ACC_CP,ACC_PTP,VEL_CP,VEL_PTP,ACC_GLUE,TOOL,BASE,EX_BASE,PTP_DAT,CP_DAT,OUT_SYNC,OUT_ASYNC,GROUP,FRAMES,PTP_PARAMS,CP_PARAMS
STRUC PDAT REAL VEL,ACC,APO_DIST
STRUC LDAT REAL VEL,ACC,APO_DIST,APO_FAC,ORI_TYPE ORI_TYP
STRUC FDAT INT TOOL_NO,BASE_NO,IPO_MODE IPO_FRAME
DECL REAL DEF_VEL_PTP=100.0
DECL REAL DEF_ACC_PTP=20.0
DECL FRAME TOOL_DATA[16]
TOOL_DATA[1]={X 0.0,Y 0.0,Z 150.0,A 0.0,B 0.0,C 0.0}
DECL FRAME BASE_DATA[32]
DECL PDAT PDEFAULT={VEL 100.0,ACC 100.0,APO_DIST 100.0}
DECL LDAT LDEFAULT={VEL 2.0,ACC 100.0,APO_DIST 100.0,APO_FAC 50.0,ORI_TYP #VAR}
DECL FDAT FDEFAULT={TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE}
DECL PDAT PDAT_ACT
DECL LDAT LDAT_ACT
DECL FDAT FDAT_ACT
ENDDAT
"""

CELL_KRC2 = """DEF cell()
  BAS(#INITMOV, 0)
  PDAT_ACT = {VEL 100.0, ACC 50.0, APO_DIST 10.0}
  BAS(#PTP_PARAMS, 50.0)
  $OUT[1] = ($TOOL.Z == 150.0) AND ($VEL_AXIS[1] == 50.0) AND ($APO.CPTP == 10.0)
  LDAT_ACT = {VEL 1.0, ACC 50.0, APO_DIST 7.0, APO_FAC 50.0, ORI_TYP #CONSTANT}
  BAS(#CP_PARAMS, 0.5)
  $OUT[2] = ($VEL.CP == 0.5) AND ($APO.CDIS == 7.0) AND ($ORI_TYPE == #CONSTANT) AND ($CIRC_TYPE == #BASE)
END
"""


@pytest.mark.parametrize("interp", INTERPS)
def test_the_model_runs_over_a_kr_c2_config_dat(tmp_path, interp):
    """PTP_PARAMS without APO_MODE: $APO.CPTP = APO_DIST (reference 6.9, #CPTP when unset);
    CP_PARAMS without CIRC_TYP: $CIRC_TYPE keeps INITMOV's DEF_CIRC_TYP (#BASE)."""
    write(tmp_path, "R1/System/$config.dat", CONFIG_KRC2)
    prog = write(tmp_path, "R1/Program/cell.src", CELL_KRC2)
    rt, tw = _completed(prog, interp)
    assert {e["signal"]: e["value"] for e in tw.events if e["kind"] == "io"} == {"$OUT[1]": True, "$OUT[2]": True}


# KUKA's BAS(#INITMOV) as a backup's own bas.src writes it (KSS 8.3, the corpus's KR C4 backups:
# ``$CIRC_TYPE = DEF_CIRC_TYP``, ``$ADVANCE = DEF_ADVANCE``), cut to the two lines this test reads;
# its parameter's type BAS_COMMAND is declared in the robot's $config.dat, as on the controller
OWN_BAS = """DEF BAS (COMMAND :IN, VALUE :IN)
  DECL BAS_COMMAND COMMAND
  DECL REAL VALUE
  DECL INT I
  IF COMMAND == #INITMOV THEN
    $CIRC_TYPE = DEF_CIRC_TYP
    $ADVANCE = DEF_ADVANCE
    FOR I = 1 TO MAX_TOOL
      $OUT[10] = I == 16
    ENDFOR
  ENDIF
  IF COMMAND == #VEL_CP THEN
    $VEL.CP = VALUE * DEF_VEL_FACT
  ENDIF
END
"""


@pytest.mark.parametrize("interp", INTERPS)
def test_an_archive_without_the_robots_config_dat_runs_its_bas_on_kukas_defaults(tmp_path, interp):
    """The variants sweep's ``no-system R1/System/$config.dat`` on a KR C4 archive (R1 beside
    STEU/$config.dat, so still a backup): its own bas.src read DEF_CIRC_TYP as a stand-in and
    stopped ("#NOT_INSTALLED is not a value of CIRC_TYPE", seen failing on a5fd3e4). The robot's
    $config.dat is then KUKA's standard one, the BASIS $config.dat: DEF_CIRC_TYP = #BASE,
    DEF_ADVANCE = 3, MAX_TOOL = 16 and DEF_VEL_FACT = 1.0, as every KR C4 $config.dat of
    ../shared/krl-corpus declares them (a CP motion's $VEL.CP = v * DEF_VEL_FACT was 0 with a
    stand-in: "CP motion: $VEL, $ACC and $OV_PRO must be positive", the variants sweep)."""
    write(tmp_path, "STEU/$config.dat", "DEFDAT $CONFIG PUBLIC\nDECL INT CELL_NR=1\nENDDAT\n")
    write(tmp_path, "R1/System/bas.src", OWN_BAS)
    prog = write(tmp_path, "R1/Program/prog.src",
                 "DEF prog()\n  BAS(#INITMOV, 0)\n  $OUT[1] = $CIRC_TYPE == #BASE\n  $OUT[2] = $ADVANCE == 3\n"
                 "  BAS(#VEL_CP, 0.3)\n  $OUT[3] = $VEL.CP == 0.3\nEND\n")
    _rt, tw = _completed(prog, interp)
    assert [(e["signal"], e["value"]) for e in tw.events if e["kind"] == "io"] == \
        [("$OUT[10]", True), ("$OUT[1]", True), ("$OUT[2]", True), ("$OUT[3]", True)]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_backup_without_collmonlib_src_runs_the_spline_forms_collision_call(tmp_path, interp):
    """The variants sweep's ``no-system R1/System/collmonlib.src`` (collmonlib.dat kept): every
    KSS 8 inline form's ``$COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0)`` stopped on the stand-in's
    value ("cannot assign #NOT_INSTALLED to REAL", seen failing on a5fd3e4). The project's model
    of KUKA's collision-detection library runs: for setting 0 without a global tolerance set
    KUKA's USE_CM_PRO_VALUES returns 0 (its ELSE branch with COLLMON_TOL_PRO[1] = -1)."""
    write(tmp_path, "R1/System/collmonlib.dat", "DEFDAT COLLMONLIB PUBLIC\nINT COLLMON_TOL_PRO[12]\nENDDAT\n")
    prog = _backup(tmp_path)
    prog.write_text("DEF cell()\n  SPTP $AXIS_ACT WITH $COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0)\n"
                    "  $OUT[1] = USE_CM_PRO_VALUES(0) == 0\nEND\n", encoding="utf-8")
    rt, tw = _completed(prog, interp)
    assert [(e["signal"], e["value"]) for e in tw.events if e["kind"] == "io"] == [("$OUT[1]", True)]
    assert {n: (w, c) for n, w, c in rt.kss.summary()}["COLLMONLIB"] == ("collision detection model", 2)
