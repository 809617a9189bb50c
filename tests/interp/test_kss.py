"""KUKA's system software at run time (issue 34, interp/runtime/kss.py), the standard P00
(interp/basis/kuka/p00.src), BRAKE outside an interrupt routine, EKI_CHECK, and setting the
scene: ``--start`` and ``--on-halt continue``."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from interp import realprograms as rp
from interp.run import make_runtime, run_spec, RunSinks
from interp.runtime import kss
from interp.runtime.kss import SystemSoftware
from app import main
from robot.trace import TraceWriter

from .helpers import write

INTERPS = ("tree", "vm")

KRC2_PROG = """
DEF weld()
  ;FOLD INI
  ;FOLD BASISTECH INI
  $OUT[9] = TRUE
  ;ENDFOLD (BASISTECH INI)
  ;FOLD SPOTTECH INI
  USERSPOT(1)
  USERSPOT(2)
  ;ENDFOLD (SPOTTECH INI)
  ;FOLD ARCHTECHDIGITAL INI
  IF ARC20==TRUE THEN
    A20 (ARC_INI)
    INTERRUPT DECL 6 WHEN $CYCFLAG[3]==FALSE DO A20(TECH_STOP2)
  ENDIF
  ;ENDFOLD (ARCHTECHDIGITAL INI)
  ;FOLD USER INI
  ;ENDFOLD (USER INI)
  ;ENDFOLD (INI)
  IF IS_KEY_PRESSED(5) THEN
    $OUT[2] = TRUE
  ENDIF
  $OUT[1] = TRUE
  GetJobNr()
END
"""


def _backup(tmp: Path, program: str, config: str = "DEFDAT $CONFIG\nENDDAT\n", name="weld.src",
            files: dict | None = None) -> Path:
    write(tmp, "R1/System/$config.dat", config)
    for f, text in (files or {}).items():
        write(tmp, f, text)
    return write(tmp, f"R1/Program/{name}", program)


def _run(prog, interp="tree", **kw):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, check=False, interp=interp, **kw), RunSinks(trace=tw))
    res = rt.run()
    return rt, res, tw.events


@pytest.mark.parametrize("interp", INTERPS)
def test_the_template_names_of_technology_packages_stand_in(tmp_path, interp):
    """The KR C2 template's ArcTech INI fold (IF ARC20==TRUE THEN A20(ARC_INI) ...) on a
    backup without ArcTech: ARC20 reads FALSE (the package is not installed), the INI is
    skipped; SpotTech's USERSPOT of the template's SPOTTECH INI fold runs as a no-op;
    IS_KEY_PRESSED (KSS, $operate.dat) is FALSE; a routine of the program that nothing
    declares stays its error."""
    prog = _backup(tmp_path, KRC2_PROG)
    rt, res, events = _run(prog, interp)
    notes = [e["text"] for e in events if e["kind"] == "message"]
    assert len(notes) == 3                      # one note per stand-in
    assert notes[0].startswith("stub: USERSPOT (procedure of KUKA's system software not in the backup: ")
    assert notes[1].startswith("stub: ARC20 (variable of KUKA's system software not in the backup: ")
    assert notes[1].endswith("): reads FALSE")
    assert "stub: IS_KEY_PRESSED (function of KUKA's system software not in the backup: a routine of the " \
           "platform tables (krl/semantics/data)): returns FALSE (TRUE while the key is held on the " \
           "KCP/smartPAD ($operate.dat EXTFCTP BOOL IS_KEY_PRESSED(INT KEY :IN)); nobody presses a key in " \
           "a simulation)" in notes
    io = [(e["signal"], e["value"]) for e in events if e["kind"] == "io"]
    assert io == [("$OUT[9]", True), ("$OUT[1]", True)]
    # GetJobNr: the program's own routine that nothing declares: the controller's error
    assert (res.reason, res.line, res.text) == ("error", 23, "routine GetJobNr not found")
    summary = {name: (what, n) for name, what, n in rt.kss.summary()}
    assert summary["ARC20"] == ("variable", 1)
    assert summary["IS_KEY_PRESSED"] == ("function", 1)
    assert summary["USERSPOT"] == ("procedure", 2)


ARC_PROG = """
DEF weld()
  ;FOLD INI
  ;FOLD ARCTECH INI
  IF ARC_OPTION==#ACTIVE THEN
    ARC_INIT(#STD, ARC_DEFAULT)
    $OUT[5] = TRUE
  ENDIF
  IF ARC_OPTION<>#ACTIVE THEN
    $OUT[6] = TRUE
  ENDIF
  SWITCH ARC_MODE
  CASE #PULSE, #STANDARD
    $OUT[7] = TRUE
  DEFAULT
    $OUT[8] = TRUE
  ENDSWITCH
  ;ENDFOLD (ARCTECH INI)
  ;FOLD SPOTTECH INI
  USERSPOT(SPOT_INI, 3 + SPOT_COUNT)
  ;ENDFOLD (SPOTTECH INI)
  ;FOLD USER INI
  ;ENDFOLD (USER INI)
  ;ENDFOLD (INI)
  $OUT[1] = TRUE
END
"""


@pytest.mark.parametrize("where", ("backup", "folder"))
def test_an_enum_of_a_package_the_backup_lacks_reads_not_installed(tmp_path, where):
    """ArcTech's INI fold tests a variable of an ENUM type nothing declares (issue 46):
    ARC_OPTION gets a stand-in ENUM of the literals its uses compare it with (#ACTIVE) plus
    #NOT_INSTALLED, so ==#ACTIVE is FALSE and <>#ACTIVE TRUE; ARC_MODE, switched on #PULSE and
    #STANDARD, takes the DEFAULT branch. USERSPOT's arguments are evaluated (SPOT_INI: no type
    from its uses, the not-installed value; SPOT_COUNT: INT from 3 + ...) in both interpreters,
    with one note each. The same in a plain folder: the checker decides the same there."""
    if where == "backup":
        prog = _backup(tmp_path, ARC_PROG)
    else:
        prog = write(tmp_path, "weld.src", ARC_PROG)
    runs = [_run(prog, i) for i in INTERPS]
    assert runs[0][2] == runs[1][2]                 # the same trace, event by event
    rt, res, events = runs[0]
    assert res.reason == "completed", res.text
    io = [(e["signal"], e["value"]) for e in events if e["kind"] == "io"]
    assert io == [("$OUT[6]", True), ("$OUT[8]", True), ("$OUT[1]", True)]
    notes = [e["text"] for e in events if e["kind"] == "message"]
    place = "the backup" if where == "backup" else "the program's files"
    ini = "the template's INI fold {} uses it (KUKA's template and technology packages write that fold)"
    assert notes == [
        f"stub: ARC_OPTION (variable of KUKA's system software not in {place}: {ini.format('ARCTECH INI')}): "
        "reads #NOT_INSTALLED (the package is not installed: equal to none of #ACTIVE)",
        f"stub: ARC_MODE (variable of KUKA's system software not in {place}: {ini.format('ARCTECH INI')}): "
        "reads #NOT_INSTALLED (the package is not installed: equal to none of #PULSE, #STANDARD)",
        f"stub: SPOT_INI (variable of KUKA's system software not in {place}: {ini.format('SPOTTECH INI')}): "
        "reads #NOT_INSTALLED (the package is not installed; its uses give it no type)",
        f"stub: SPOT_COUNT (variable of KUKA's system software not in {place}: {ini.format('SPOTTECH INI')}): "
        "reads 0",
        f"stub: USERSPOT (procedure of KUKA's system software not in {place}: {ini.format('SPOTTECH INI')}): "
        "no effect",
    ]
    summary = {name: (what, n) for name, what, n in rt.kss.summary()}
    assert summary["USERSPOT"] == ("procedure", 1) and summary["ARC_OPTION"] == ("variable", 1)
    assert "ARC_INIT" not in summary                # never called: the package is not installed


def test_the_not_installed_value_is_none_of_the_literals(tmp_path):
    """A program that compares with #NOT_INSTALLED itself: the stand-in's value differs."""
    prog = _backup(tmp_path, "DEF weld()\n  ;FOLD INI\n  IF X_OPT==#NOT_INSTALLED THEN\n    $OUT[1] = TRUE\n"
                             "  ENDIF\n  ;ENDFOLD (INI)\nEND\n")
    _rt, res, events = _run(prog)
    assert res.reason == "completed" and not [e for e in events if e["kind"] == "io"]
    assert [e["text"] for e in events if e["kind"] == "message"][0].endswith(
        "reads #NOT_INSTALLED_ (the package is not installed: equal to none of #NOT_INSTALLED)")


def test_a_name_of_the_program_only_is_its_error(tmp_path):
    prog = _backup(tmp_path, "DEF weld()\n  IF GATE_OPEN THEN\n    $OUT[1] = TRUE\n  ENDIF\nEND\n")
    _rt, res, _ = _run(prog)
    # issue 85: the run says what the checker knows of the backup's own undeclared name (E101 at
    # the IF's GATE_OPEN, column 6) and what the controller does with the module
    assert (res.reason, res.line, res.text) == (
        "error", 2, "unknown name GATE_OPEN: the backup declares no GATE_OPEN (krl check: E101 at weld.src:2:6); "
                    "KUKA's controller does not link weld.src with that error, so no program that is or calls "
                    "weld.src can be selected")


@pytest.mark.parametrize("interp", INTERPS)
def test_a_system_variable_only_kuka_writes_stands_in(tmp_path, interp):
    """$CP_VEL_MODE = 5 on a line of a KUKA system file (the backup's bas.src): a system
    variable no table lists, its uses give it INT; written, then read."""
    sysfile = """
    GLOBAL DEF HopVel(V :IN)
      DECL REAL V
      $CP_VEL_MODE = 5
      IF V > 0.1 * $CP_VEL_MODE THEN
        $OUT[3] = TRUE
      ENDIF
    END
    """
    prog = _backup(tmp_path, "DEF weld()\n  HopVel(2.0)\nEND\n", files={"R1/System/hop.src": sysfile})
    rt, res, events = _run(prog, interp)
    assert res.reason == "completed", res.text
    assert ("$OUT[3]", True) in [(e["signal"], e["value"]) for e in events if e["kind"] == "io"]
    # a variable counts once (the interpreters look it up differently)
    assert {n: (w, c) for n, w, c in rt.kss.summary()}["$CP_VEL_MODE"] == ("system variable", 1)


P00_CONFIG = """
DEFDAT  $CONFIG
ENUM FUNCT_TYPE PGNO_GET,PGNO_ACKN,PGNO_FAULT
ENUM P00_COMMAND INIT_EXT,EXT_PGNO,CHK_HOME,EXT_ERR
EXT  P00 (P00_COMMAND  :IN,FUNCT_TYPE  :IN,CHAR [] :OUT,INT  :IN )
INT PGNO=0 ;copy of ext. pgno
INT PGNO_ERROR=0 ;transmission error
INT PGNO_TYPE=1 ;coding type of ext. pgno
INT PGNO_LENGTH=8 ;length of ext. pgno
INT PGNO_FBIT=33 ;first bit of ext. pgno input $IN[]
INT PGNO_PARITY=41 ;parity bit of ext. pgno
INT PGNO_REQ=33 ;request ext. pgno output
INT PGNO_VALID=42 ;validate ext. pgno input
ENDDAT
"""

P00_CELL = """
DEF cell()
  DECL CHAR DMY[3]
  DMY[]="---"
  P00 (#INIT_EXT,#PGNO_GET,DMY[],0 )
  P00 (#EXT_PGNO,#PGNO_GET,DMY[],0 )
  SWITCH PGNO
  CASE 2
    P00 (#EXT_PGNO,#PGNO_ACKN,DMY[],0 )
    $OUT[2] = TRUE
  DEFAULT
    P00 (#EXT_PGNO,#PGNO_FAULT,DMY[],0 )
  ENDSWITCH
END
"""


@pytest.mark.parametrize("interp", INTERPS)
def test_the_standard_p00_runs_when_the_backup_has_none(tmp_path, interp):
    """A backup whose $config.dat declares P00 (EXT P00, PGNO_*) but has no R1/TP/p00.src:
    the project's standard P00 runs, with a note. The PLC (--pgno 2, robot/cellpresets.py)
    answers the request ($OUT[33] set at t = 0, seen in cycle 1, answered 0.1 s later in
    cycle 10): 2 = bit 1 on $IN[34], odd parity $IN[41], PGNO_VALID $IN[42] at 0.120 s; P00
    reads 2, CASE 2 acknowledges ($OUT[33] FALSE) and sets $OUT[2] in the same cycle."""
    prog = _backup(tmp_path, P00_CELL, P00_CONFIG, name="cell.src")
    rt, res, events = _run(prog, interp, pgno=2, mode="EXT")
    assert res.reason == "completed", (res.text, res.file, res.line)
    io = [(e["t"], e["signal"], e["value"]) for e in events if e["kind"] == "io"]
    assert (0.12, "$IN[34]", True) in io and (0.12, "$IN[42]", True) in io
    assert (0.12, "$OUT[2]", True) in io and (0.12, "$OUT[33]", False) in io
    notes = [e["text"] for e in events if e["kind"] == "message"]
    assert notes[0].startswith("stub: P00 (the backup has no P00 of its own (KUKA's R1/TP/p00.src); "
                               "the project's standard P00 runs (interp/basis/kuka/p00.src))")
    assert {n: (w, c) for n, w, c in rt.kss.summary()}["P00"] == ("standard program", 3)


@pytest.mark.parametrize("interp", INTERPS)
def test_brake_outside_an_interrupt_routine_is_an_error_at_its_line(tmp_path, interp):
    prog = write(tmp_path, "brk.src", "DEF brk()\n  PTP {A1 10, A2 -90, A3 90, A4 0, A5 0, A6 0}\n  BRAKE\n  $OUT[1] = TRUE\nEND\n")
    _rt, res, _ = _run(prog, interp)
    assert (res.reason, res.line) == ("error", 3)
    assert res.text.startswith("BRAKE outside an interrupt routine")


def test_eki_check_is_in_the_ethernetkrl_table(tmp_path):
    prog = write(tmp_path, "eki.src", """
    DEF eki()
      DECL EKI_STATUS ret
      ret = EKI_Init("XmlCallBack")
      EKI_CHECK(ret, #QUIT, "XmlCallBack")
    END
    """)
    out = CliRunner().invoke(main, ["check", str(prog)])
    assert out.exit_code == 0, out.output
    assert "EKI_CHECK" not in out.output


# ---------------------------------------------------------------------- set the scene
HOME_PROG = """
DEF home()
  E6AXIS here
  here = $AXIS_ACT
  $OUT[1] = (here.A1 > 44.9) AND (here.A1 < 45.1) AND (here.A2 > -100.1) AND (here.A2 < -99.9)
  HALT
  $OUT[2] = TRUE
  HALT
  $OUT[3] = TRUE
END
"""


def test_start_places_the_robot_and_on_halt_continue_presses_start(tmp_path):
    prog = write(tmp_path, "home.src", HOME_PROG)
    write(tmp_path, "home.dat", "DEFDAT home\nDECL E6AXIS XSTART={A1 45.0,A2 -100.0,A3 100.0,A4 0.0,A5 30.0,"
                                "A6 0.0,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}\nENDDAT\n")
    runner = CliRunner()
    out = runner.invoke(main, ["run", str(prog), "--start", "XSTART", "--on-halt", "continue"])
    assert out.exit_code == 0, out.output
    assert "start      XSTART" in out.output
    assert "HALT at home.src:5: Start pressed again (1 of 10, --on-halt continue)" in out.output
    out = runner.invoke(main, ["run", str(prog), "--start", "{A1 45, A2 -100, A3 100, A5 30}",
                               "--on-halt", "continue:1"])
    assert out.exit_code == 3 and "stopped by HALT" in out.output   # the second HALT ends it
    out = runner.invoke(main, ["run", str(prog)])                    # $AXIS_HOME: $OUT[1] FALSE
    assert out.exit_code == 3 and "I/O        0 change(s)" in out.output
    for bad, why in (("NOWHERE", "no point NOWHERE"), ("{A1 500}", "software limit switch +A1"),
                     ("1+2", "not an E6AXIS literal")):
        out = runner.invoke(main, ["run", str(prog), "--start", bad])
        assert out.exit_code == 2 and why in out.output and "Traceback" not in out.output, out.output
    cell = write(tmp_path, "cell.yaml", "start: XSTART\n")
    out = runner.invoke(main, ["run", str(prog), "--inputs", str(cell)])
    assert "start      XSTART" in out.output and "$OUT 1" in out.output


@pytest.mark.parametrize("interp", INTERPS)
def test_a_type_follows_the_checker_in_a_backup_or_not(tmp_path, interp):
    """A type nothing declares (issue 46: one decision). Named by an EXT declaration, the
    checker's W105 (the software that provides the routine declares it): untyped, one note, in
    a plain folder too (before, outside a backup, its data list did not load: "unknown name
    W1"). Named only by the program's own data list, the checker's E105: the program's error,
    in a backup too (its variable is not declared either: "unknown name W1")."""
    ext = "DEFDAT weld\n  EXT ArcOn(ARC_DATA_T :IN)\n  DECL ARC_DATA_T W1=#PULSE\nENDDAT\n"
    mine = "DEFDAT weld\n  DECL GRIPPER_T W1=#PULSE\nENDDAT\n"
    prog = "DEF weld()\n  $OUT[1] = W1 == #PULSE\nEND\n"
    for where in ("folder", "backup"):
        for dat, expected in ((ext, ("completed", "")), (mine, ("error", "unknown name W1"))):
            # (the data list is loaded when the program first reads W1)
            folder = tmp_path / f"{where}-{len(dat)}"
            folder.mkdir()
            if where == "backup":
                src = _backup(folder, prog, files={"R1/Program/weld.dat": dat})
            else:
                write(folder, "weld.dat", dat)
                src = write(folder, "weld.src", prog)
            rt, res, events = _run(src, interp)
            assert (res.reason, res.text if res.reason == "error" else "") == expected, (where, res.text)
            if expected[0] == "completed":
                assert "not simulated: type ARC_DATA_T (undeclared; values are untyped)" in \
                    [e["text"] for e in events if e["kind"] == "message"]
                assert ("$OUT[1]", True) in [(e["signal"], e["value"]) for e in events if e["kind"] == "io"]


def test_a_name_only_a_broken_file_mentions_stays_the_programs_error(tmp_path):
    """The checker warns (W101, rule 4: a line not understood mentions it: it may declare
    it) but does not call it KUKA's (Outside.kuka False): perhaps the program's own variable,
    in a data list the controller could not load either. The run stops on it, as before."""
    prog = _backup(tmp_path, "DEF weld()\n  IF PART_COUNT > 3 THEN\n    $OUT[1] = TRUE\n  ENDIF\nEND\n",
                   files={"R1/Program/cnt.dat": "DEFDAT cnt PUBLIC\n  DECL GLOBAL INT PART_COUNT = (\nENDDAT\n"})
    out = CliRunner().invoke(main, ["check", str(prog.parents[2])])
    assert "warning[W101]: name 'PART_COUNT' is not declared in this backup (used 1 time; first here): " \
           "a line not understood of this backup mentions it" in out.output, out.output
    rt, res, _ = _run(prog)
    assert (res.reason, res.line, res.text) == ("error", 2, "unknown name PART_COUNT")
    assert rt.kss.summary() == []


def test_outside_stops_finds_a_run_that_disagrees_with_the_checker(tmp_path, monkeypatch):
    """interp.realprograms.outside_stops, what tests/interp/test_outside_runs.py asserts empty
    on every backup of the corpus and the history: with the stand-in of a name taken away (the
    run and the checker disagree), the stop on it is found and said with the checker's why; the
    program's own unknown name is not."""
    prog = _backup(tmp_path, KRC2_PROG)
    rt, res, _ = _run(prog)
    assert res.text == "routine GetJobNr not found" and rp.outside_stops(rt) == []
    monkeypatch.setattr(SystemSoftware, "name_ref", lambda self, name: None)
    rt, res, _ = _run(prog)
    assert res.text == "unknown name ARC20"
    assert rp.outside_stops(rt) == [f"ARC20 at {prog}:11: the template's INI fold ARCHTECHDIGITAL INI uses it "
                                    "(KUKA's template and technology packages write that fold)"]



def test_an_installed_name_that_is_a_word_of_the_message_is_no_outside_stop(tmp_path):
    """The variants sweep (issue 59, ChinaMilling 04 without TP/p00.dat): KUKA's P00 uses FOUND,
    which no file of the backup declares (W101, KUKA's system files use it), and the user's
    cell program calls its own routine that the backup lacks. The run stops on that routine,
    the program's error (E106): "routine millingcn not found" names MILLINGCN, not FOUND, the
    word of the message."""
    prog = _backup(tmp_path, "DEF cell()\n  millingcn()\nEND\n", name="cell.src",
                   files={"R1/TP/p00.src": "DEF p00()\nEND\nDEF helper()\n  BOOL ok\n  FOUND=FALSE\n"
                                           "  ok = FOUND\nEND\n"})
    out = CliRunner().invoke(main, ["check", str(prog.parents[2])])
    assert "name 'FOUND' is not declared in this backup" in out.output and "KUKA's system files use it" in out.output
    assert "routine 'millingcn' is not declared" in out.output, out.output
    for interp in INTERPS:
        rt, res, _ = _run(prog, interp=interp)
        assert (res.reason, res.line, res.text) == ("error", 2, "routine millingcn not found")
        assert rp.outside_stops(rt) == []

# ---------------------------------------------------------------------- the operator's path
CELL_DAT = ("DEFDAT cell\n  DECL E6AXIS XHOME={A1 10.0,A2 -90.0,A3 90.0,A4 0.0,A5 30.0,A6 0.0,E1 0.0,E2 0.0,"
            "E3 0.0,E4 0.0,E5 0.0,E6 0.0}\nENDDAT\n")
HANDLER = "&ACCESS RVP\n&COMMENT HANDLER on external automatic\n" + P00_CELL.lstrip("\n")


def _cell(tmp: Path, program: str = HANDLER) -> Path:
    return _backup(tmp, program, P00_CONFIG, name="cell.src", files={"R1/Program/cell.dat": CELL_DAT})


def test_a_cell_program_starts_in_automatic_external_at_home(tmp_path):
    """issue 46: `krl run cell.src` with nothing else: EXT (the header says it is the handler
    of Automatic External) and XHOME (P00's CHK_HOME wants it there), each said with who chose
    it; P00's INIT_EXT passes, and the run waits for the PLC's program number: the summary
    names the input (PGNO_VALID = 42 of $config.dat) and the options that answer it."""
    prog = _cell(tmp_path)
    out = CliRunner().invoke(main, ["run", str(prog), "--max-sim-time", "5"])
    lines = out.output.splitlines()
    assert "  mode       EXT (cell.src is a cell program (its header &COMMENT HANDLER on external automatic): " \
           "the controller runs it in Automatic External; --mode to choose another)" in lines, out.output
    assert "  start      XHOME (the home position: cell.src is a cell program, and P00 #CHK_HOME wants it " \
           "there; --start to choose another)" in lines
    waits = [ln for ln in lines if ln.startswith("  waits      ")]
    assert waits and waits[0].startswith("  waits      in P00_GET (") and waits[0].endswith(
        "for the PLC's program number (P00's handshake): WAIT FOR $IN[PGNO_VALID] reads $IN[42] (PGNO_VALID) "
        "of $config.dat"), out.output
    assert "  answer     --pgno N (a number the cell program's SWITCH PGNO has a CASE for), or the cell " \
           "file's `pgno: N`, or --inputs auto" in lines
    # answered: the handshake completes, CASE 2 runs
    out = CliRunner().invoke(main, ["run", str(prog), "--pgno", "2", "--max-sim-time", "5"])
    assert "ended      completed" in out.output and "$OUT 3" in out.output, out.output


def test_a_cell_program_in_another_mode_says_it_waits_for_automatic_external(tmp_path):
    """--mode AUT: P00's INIT_EXT waits for $I_O_ACTCONF (the project's standard P00: WAIT FOR);
    the summary says so and how to answer. A program that calls P00 (#INIT_EXT, ...) without the
    header is a cell program too."""
    program = P00_CELL.replace("DEF cell()", "DEF cell()\n  ;FOLD AUTOEXT INI")   # no header
    prog = _cell(tmp_path, program.replace('  P00 (#INIT_EXT', '  ;ENDFOLD\n  P00 (#INIT_EXT'))
    out = CliRunner().invoke(main, ["run", str(prog), "--mode", "AUT", "--max-sim-time", "5"])
    lines = out.output.splitlines()
    assert "  mode       AUT (--mode)" in lines, out.output
    assert any(ln.startswith("  waits      in P00_INIT (") and ln.endswith(
        "for Automatic External ($MODE_OP #EX and $I_O_ACT): WAIT FOR $I_O_ACTCONF") for ln in lines), out.output
    assert "  answer     --mode EXT, or the cell file's `autoext: true`" in lines
    out = CliRunner().invoke(main, ["run", str(prog), "--max-sim-time", "5"])
    assert "it calls P00 (#INIT_EXT, ...) at line" in out.output, out.output


def test_chk_home_says_the_robot_is_not_home(tmp_path):
    """--start elsewhere: the standard P00's CHK_HOME HALTs in Automatic External while $IN_HOME
    is FALSE; the summary names the loop's condition and --start XHOME."""
    program = P00_CELL.replace("  P00 (#INIT_EXT", "  P00 (#CHK_HOME,#PGNO_GET,DMY[],0 )\n  P00 (#INIT_EXT")
    prog = _cell(tmp_path, program)
    out = CliRunner().invoke(main, ["run", str(prog), "--start", "{A1 40}", "--max-sim-time", "5"])
    lines = out.output.splitlines()
    assert "stopped by HALT" in out.output, out.output
    assert any(ln.startswith("  waits      in P00_HOME (") and ln.endswith(
        "for the robot in its home position ($H_POS, within $H_POS_TOL): WHILE NOT $IN_HOME") for ln in lines), \
        out.output
    assert "  answer     --start XHOME, or the cell file's `start: XHOME`" in lines


@pytest.mark.parametrize("interp", INTERPS)
def test_a_stand_in_takes_every_value_the_program_writes(tmp_path, interp):
    """Found by the variants (a history backup of HugoDanielson__ChinaMilling without the Milling
    package's data list: ``oFreqconverterCtlw = gsSpindleWord.WaitForCommand`` stopped the SPS
    on "cannot assign 0 to OFREQCONVERTERCTLW (stand-in ENUM)"). A stand-in's type is what its
    uses suggest, not a declaration: a value it cannot hold makes it that value's variable, and
    the run goes on (a name the checker classifies as installed software never ends a run)."""
    prog = _backup(tmp_path, "DEF weld()\n  ;FOLD INI\n  ARC_STATE = ARC_CFG.MODE\n  IF ARC_ON THEN\n"
                             "    $OUT[2] = TRUE\n  ENDIF\n  ARC_ON = 5\n  ;ENDFOLD (INI)\n"
                             "  $OUT[1] = TRUE\nEND\n")
    rt, res, events = _run(prog, interp)
    assert res.reason == "completed", res.text
    assert [(e["signal"], e["value"]) for e in events if e["kind"] == "io"] == [("$OUT[1]", True)]
    assert rt.kss.name_ref("ARC_STATE").get() == 0 and rt.kss.name_ref("ARC_ON").get() == 5


@pytest.mark.parametrize("interp", INTERPS)
def test_a_stand_in_used_as_an_index_reads_the_first_index(tmp_path, interp):
    """Found by the variants (the same backup: ``$CYCFLAG[cycEmStop] = ...`` in the package's
    submit routine, its data list removed): an index is INT whatever other uses say, and reads
    1, the first index of every KRL array (0 is an index of none)."""
    prog = _backup(tmp_path, "DEF weld()\n  ;FOLD INI\n  $CYCFLAG[CYC_STOP] = NOT $ALARM_STOP\n"
                             "  CYC_STOP = CYC_OTHER\n  ;ENDFOLD (INI)\n  $OUT[1] = TRUE\nEND\n")
    rt, res, events = _run(prog, interp)
    assert res.reason == "completed", res.text
    notes = [e["text"] for e in events if e["kind"] == "message"]
    assert any(n.startswith("stub: CYC_STOP (variable") and n.endswith("reads 1") for n in notes), notes


@pytest.mark.parametrize("interp", INTERPS)
def test_a_stand_in_in_a_for_bound_or_an_interrupt_number_is_an_int(tmp_path, interp):
    """Found by the whole variants sweep (2026-11-27): KSS 8's bas.src ``FOR I=1 TO MAX_TOOL``
    with the robot's $config.dat removed (MAX_TOOL is now in the BASIS $config.dat; here a
    package's name none declares) stopped on "operand is not a number: #NOT_INSTALLED",
    and a milling package's ``INTERRUPT OFF cItrMillWarning`` with its data list removed on
    "interrupt number is not a number: #NOT_INSTALLED" (both seen failing on a5fd3e4). FOR's
    bounds and an interrupt's number are INT (reference 5.4, 5.16): the bound reads 0, so the
    loop runs zero times; the interrupt number reads 128, the users' last priority (0 is none:
    "interrupt priority 0 outside 1..128" at a DECL), here one not declared, the error the
    unmodified backup gives there too ("interrupt 9 not declared")."""
    pkg = ("DEF pkg()\nEND\nGLOBAL DEF PKG_RESET()\n  INT I\n  FOR I = 1 TO PKG_MAX_GUN\n    $OUT[I] = TRUE\n"
           "  ENDFOR\n  $OUT[20] = TRUE\n  INTERRUPT OFF cItrPkgWarning\nEND\n")
    prog = _backup(tmp_path, "DEF weld()\n  PKG_RESET()\nEND\n", files={"R1/TP/Pkg/pkg.src": pkg})
    _rt, res, events = _run(prog, interp)
    assert [(e["signal"], e["value"]) for e in events if e["kind"] == "io"] == [("$OUT[20]", True)]
    assert (res.reason, res.text.split(" [")[0]) == ("error", "interrupt 128 not declared"), res.text


@pytest.mark.parametrize("interp", INTERPS)
def test_stand_in_interrupt_numbers_are_valid_and_distinct(tmp_path, interp):
    """Two interrupts of a package whose data list (their numbers) the backup lacks: declared as
    two (128 and 127, by name), both fire."""
    pkg = ("DEF pkg()\nEND\nGLOBAL DEF PKG_ARM()\n  GLOBAL INTERRUPT DECL cItrA WHEN $FLAG[1] DO PKG_A()\n"
           "  GLOBAL INTERRUPT DECL cItrB WHEN $FLAG[2] DO PKG_B()\n  INTERRUPT ON cItrA\n  INTERRUPT ON cItrB\n"
           "  $OUT[9] = TRUE\nEND\nGLOBAL DEF PKG_A()\n  $OUT[1] = TRUE\nEND\nGLOBAL DEF PKG_B()\n  $OUT[2] = TRUE\nEND\n")
    prog = _backup(tmp_path, "DEF weld()\n  PKG_ARM()\n  $FLAG[1] = TRUE\n  $FLAG[2] = TRUE\n  WAIT SEC 0.1\nEND\n",
                   files={"R1/TP/Pkg/pkg.src": pkg})
    _rt, res, events = _run(prog, interp)
    assert res.reason == "completed", res.text
    assert sorted(e["signal"] for e in events if e["kind"] == "io" and e["signal"].startswith("$OUT")) == \
        ["$OUT[1]", "$OUT[2]", "$OUT[9]"]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_stand_in_function_in_a_with_part_returns_the_targets_type(tmp_path, interp):
    """Found by the whole variants sweep (2026-11-27): a package's function called only in a KSS
    8 inline form's WITH part (``$COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0)`` with collmonlib.src
    removed) returned #NOT_INSTALLED and stopped the motion ("cannot assign #NOT_INSTALLED to
    REAL", seen failing on a5fd3e4), where the same call in a plain assignment returned 0. A WITH
    part assigns like an assignment (reference 6.1 ``with_clause``): the stand-in returns the
    target's type, 0."""
    pkg = ("DEF pkg()\nEND\nGLOBAL DEF PKG_MOVE()\n"
           "  SPTP $AXIS_ACT WITH $COLLMON_TOL_PRO[1] = PKG_CM_VALUES(0)\n  $OUT[3] = TRUE\nEND\n")
    prog = _backup(tmp_path, "DEF weld()\n  PKG_MOVE()\nEND\n", files={"R1/TP/Pkg/pkg.src": pkg})
    rt, res, events = _run(prog, interp)
    assert res.reason == "completed", res.text
    assert [(e["signal"], e["value"]) for e in events if e["kind"] == "io"] == [("$OUT[3]", True)]
    assert rp.outside_stops(rt) == []


def test_outside_stops_finds_a_stop_on_a_stand_ins_value(tmp_path, monkeypatch):
    """A stop on the value a stand-in reads (#NOT_INSTALLED, its type unknown) is a stop on
    installed software too: the variants sweep counted such runs as the program's own errors.
    With the WITH part's typing taken away (the case above as it was), it is found."""
    pkg = ("DEF pkg()\nEND\nGLOBAL DEF PKG_MOVE()\n"
           "  SPTP $AXIS_ACT WITH $COLLMON_TOL_PRO[1] = PKG_CM_VALUES(0)\nEND\n")
    prog = _backup(tmp_path, "DEF weld()\n  PKG_MOVE()\nEND\n", files={"R1/TP/Pkg/pkg.src": pkg})
    monkeypatch.setattr(kss, "_use_types_of", lambda program: ({}, {}))
    rt, res, _ = _run(prog)
    assert (res.reason, res.text) == ("error", "cannot assign #NOT_INSTALLED to REAL")
    assert rp.outside_stops(rt) == [f"a stand-in's value at {tmp_path / 'R1/TP/Pkg/pkg.src'}:4: "
                                    "cannot assign #NOT_INSTALLED to REAL"]
