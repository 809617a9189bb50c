"""Names the backup cannot know (krl/semantics/outside.py, docs/diagnostics.md).

Small synthetic KRC backups (R1/System/$config.dat, R1/Program/...) written to tmp_path: a name
that only installed software can declare is one warning per backup, saying where it is first
used and how often; a name that nothing explains stays an error at every line that uses it.
"""

from __future__ import annotations

from pathlib import Path

from krl.semantics.outside import template_lines
from krl.workspace import load_workspace
from krl.project import find_backups

CONFIG = "DEFDAT $CONFIG\n  DECL INT CELL_NO = 1\nENDDAT\n"

# KUKA's program template with a technology package's INI fold (as the spot template writes it)
TEMPLATE = """\
&ACCESS RVP
DEF {name}( )
;FOLD INI;%{{PE}}
  ;FOLD BASISTECH INI
    BAS (#INITMOV,0 )
  ;ENDFOLD (BASISTECH INI)
  ;FOLD ARCTECH INI
    ARC_INIT_DONE = FALSE
    ArcInit(ARC_DEFAULT)
  ;ENDFOLD (ARCTECH INI)
  ;FOLD USER INI
    ;Make your modifications here
{user_ini}
  ;ENDFOLD (USER INI)
;ENDFOLD (INI)
{body}
END
"""


def backup(tmp_path: Path, files: dict[str, str]) -> Path:
    root = tmp_path / "KRC"
    (root / "R1" / "System").mkdir(parents=True)
    (root / "R1" / "Program").mkdir(parents=True)
    (root / "R1" / "System" / "$config.dat").write_text(CONFIG)
    for rel, text in files.items():
        p = root / "R1" / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text.replace("\n", "\r\n"))
    assert find_backups(tmp_path) == [root]
    return root


def diags(root: Path):
    ws = load_workspace([root], str(root))
    return [(Path(d.path).relative_to(root / "R1").as_posix(), d.line, d.code, d.message) for d in ws.check()]


def test_template_fold_name_is_one_warning_for_the_backup(tmp_path):
    """ARC_INIT_DONE and ArcInit are used in the ARCTECH INI fold of two programs and once more
    in user code: one W101 and one W106 for the backup, at the first use, with the counts."""
    root = backup(tmp_path, {
        "Program/a.src": TEMPLATE.format(name="a", user_ini="", body="  IF ARC_INIT_DONE THEN\n  ENDIF"),
        "Program/b.src": TEMPLATE.format(name="b", user_ini="", body=""),
    })
    got = diags(root)
    assert [(p, ln, c) for p, ln, c, _m in got] == [
        ("Program/a.src", 8, "W101"), ("Program/a.src", 9, "W106"), ("Program/a.src", 9, "W101")], got
    by_code = {c: m for _p, _ln, c, m in got if c == "W106"}
    assert "ArcInit" in by_code["W106"] and "used 2 times in 2 files" in by_code["W106"]
    w101 = [m for _p, _ln, c, m in got if c == "W101" and "ARC_INIT_DONE" in m]
    assert len(w101) == 1 and "used 3 times in 2 files" in w101[0] and "INI fold" in w101[0]


def test_misspelled_variable_in_user_code_is_an_error_at_its_line(tmp_path):
    """The same template, a user variable declared in the data list and misspelled in the
    USER INI fold and in the body: E101 at both lines; the only warning is ArcInit's, which the
    data list declares EXT and no module defines (issue 59: installed software)."""
    root = backup(tmp_path, {
        "Program/a.src": TEMPLATE.format(name="a", user_ini="    nCount = 0",
                                         body="  nCuont = nCount + 1"),
        "Program/a.dat": "DEFDAT a\n  DECL INT nCount = 0\n  DECL BOOL ARC_INIT_DONE\n"
                         "  EXT ArcInit(INT :IN)\n  DECL INT ARC_DEFAULT = 1\nENDDAT\n",
    })
    got = diags(root)
    assert [(p, ln, c) for p, ln, c, _m in got] == [("Program/a.src", 9, "W106"), ("Program/a.src", 16, "E101")], got
    assert "'nCuont' is not declared" in got[1][3]
    root2 = backup(tmp_path / "second", {
        "Program/a.src": TEMPLATE.format(name="a", user_ini="    nCuont = 0", body="  nCuont = 1"),
        "Program/a.dat": "DEFDAT a\n  DECL BOOL ARC_INIT_DONE\n  EXT ArcInit(INT :IN)\n"
                         "  DECL INT ARC_DEFAULT = 1\nENDDAT\n",
    })
    got = diags(root2)
    assert [(p, ln, c) for p, ln, c, _m in got] == [("Program/a.src", 9, "W106"), ("Program/a.src", 13, "E101"),
                                                    ("Program/a.src", 16, "E101")]


def test_package_name_from_the_table_names_its_package(tmp_path):
    """DI_gbSpindleClamp is a GLOBAL signal of KUKA's milling package (kss.yaml packages,
    R2M_SpindleVariables.dat:152). A backup without the package's files uses it in user code:
    one warning naming the package and its source."""
    root = backup(tmp_path, {"Program/m.src": "DEF m()\n  BOOL b\n  b = DI_gbSpindleClamp\n"
                                              "  WAIT FOR DI_gbSpindleClamp\nEND\n"})
    got = diags(root)
    assert [(p, ln, c) for p, ln, c, _m in got] == [("Program/m.src", 3, "W101")], got
    assert "Milling" in got[0][3] and "R2M_SpindleVariables.dat:152" in got[0][3]
    assert "used 2 times;" in got[0][3]


def test_system_file_routine_once_per_name(tmp_path):
    """A routine called from KUKA's system files (masref_main.src calls MasRefStartG1 of
    masref_user.src, which the backup lacks): one W106, however often it is called."""
    calls = "\n".join(["  MasRefStartG1()"] * 3)
    root = backup(tmp_path, {"System/masref_main.src": f"DEF masref_main()\n{calls}\nEND\n"})
    got = diags(root)
    assert [(p, ln, c) for p, ln, c, _m in got] == [("System/masref_main.src", 2, "W106")], got
    assert "used 3 times;" in got[0][3]


def test_unknown_type_has_one_severity_in_user_and_system_files(tmp_path):
    """A type that KUKA's system files use without declaring (controller-side) has the
    same severity in a user program: one W105 for the backup, not E105 here and W105 there."""
    root = backup(tmp_path, {
        "System/tech.src": "DEF tech()\n  DECL TECH_STATE_T s\nEND\n",
        "Program/p.src": "DEF p()\n  DECL TECH_STATE_T mine\nEND\n",
    })
    got = diags(root)
    assert [(p, ln, c) for p, ln, c, _m in got] == [("Program/p.src", 2, "W105")], got
    assert "used 2 times in 2 files" in got[0][3]
    # and with no system file using it, it is the program's error in user code
    root2 = backup(tmp_path / "second", {"Program/p.src": "DEF p()\n  DECL TECH_STATE_T mine\nEND\n"})
    assert [(p, ln, c) for p, ln, c, _m in diags(root2)] == [("Program/p.src", 2, "E105")]


def test_unknown_system_variable_is_one_warning_per_backup(tmp_path):
    body = "\n".join([f"  r = $NO_SUCH_SYSVAR + {i}" for i in range(4)])
    root = backup(tmp_path, {"Program/p.src": f"DEF p()\n  REAL r\n{body}\nEND\n"})
    got = diags(root)
    assert [(p, ln, c) for p, ln, c, _m in got] == [("Program/p.src", 3, "W107")], got


def test_inline_form_routine_is_outside_but_not_its_points(tmp_path):
    """A KUKA inline form (;FOLD ... ;%{PE}) calls a package routine: a warning. The point it
    moves to belongs to the program's data list: missing, it is an error."""
    src = ("DEF p()\n;FOLD SPINDLE ON ;%{PE}%MKUKATPUSER\n  SpindleOn(#CW)\n;ENDFOLD\n"
           ";FOLD PTP P1 Vel=100 % PDAT1 ;%{PE}\n  PTP XP1\n;ENDFOLD\nEND\n")
    root = backup(tmp_path, {"Program/p.src": src})
    got = diags(root)
    assert [(p, ln, c) for p, ln, c, _m in got] == [("Program/p.src", 3, "W106"), ("Program/p.src", 6, "E101")]


def test_the_form_module_names_the_package(tmp_path):
    """A form of a technology package names its module in the opening comment (%{P}, %{E}:
    older and package folds carry the module, not %{PE}); a KSS 8 form names its provider in
    its hidden parameter fold: the warning says which. The template's INI fold is named by its
    title. A hidden fold (%{H}) is no form."""
    src = ("DEF p()\n;FOLD INI\n;FOLD SPOTTECH INI\n  USERSPOT(#INIT)\n;ENDFOLD (SPOTTECH INI)\n;ENDFOLD (INI)\n"
           ";FOLD GRIPPER 1 ;%{P}%MKUKATPVW,%CGRP,%VSET,%P 1:1\n  VW_GRP(1)\n;ENDFOLD\n"
           ";FOLD Gripper SET [1] ;%{PE}\n;FOLD Parameters ;%{h}\n"
           ";Params IlfProvider=GripperTech.GripperSet;setgripper=1\n;ENDFOLD\n  GRPg_Set(1, 1)\n;ENDFOLD\n"
           ";FOLD ;%{H}\n  Hidden_Call()\n;ENDFOLD\nEND\n")
    root = backup(tmp_path, {"Program/p.src": src})
    got = diags(root)
    assert [(ln, c) for _p, ln, c, _m in got] == [(4, "W106"), (8, "W106"), (14, "W106"), (17, "E106")], got
    assert got[0][3].endswith("the template's INI fold SPOTTECH INI uses it (KUKA's template and technology "
                              "packages write that fold)")
    assert got[1][3].endswith("a KUKA inline form (KUKATPVW) uses it")
    assert got[2][3].endswith("a KUKA inline form (GripperTech.GripperSet) uses it")


def test_template_lines():
    text = TEMPLATE.format(name="a", user_ini="    x = 1", body="  y = 2")
    ini, inline, user = template_lines(text)
    lines = text.splitlines()
    assert {lines[i - 1].strip(): title for i, title in user.items()}["x = 1"] == "USER INI"
    assert {lines[i - 1].strip() for i in ini} >= {"BAS (#INITMOV,0 )", "ArcInit(ARC_DEFAULT)"}
    assert {lines[i - 1].strip(): title for i, title in ini.items()}["ArcInit(ARC_DEFAULT)"] == "ARCTECH INI"
    assert "x = 1" not in {lines[i - 1].strip() for i in ini}
    assert "y = 2" not in {lines[i - 1].strip() for i in ini | inline}


def test_hook_program_routine_names_its_program(tmp_path):
    """A backup whose masref_user.src is missing: the system file's calls of MasRefStartG1 are one
    W106 naming KUKA's hook program; inside a hook program under R1/Program an unknown routine is
    KUKA's too, in a user program of the same name elsewhere it is an error."""
    root = backup(tmp_path, {"System/masref_main.src": "DEF masref_main()\n  MasRefStartG1()\nEND\n",
                             "Program/CollDetect_UserAction.src": "DEF CollDetect_UserAction()\n  HookHelper()\nEND\n",
                             "Program/Cell/mine.src": "DEF mine()\n  OtherHelper()\nEND\n"})
    got = diags(root)
    assert [(p, ln, c) for p, ln, c, _m in got] == [
        ("Program/Cell/mine.src", 2, "E106"), ("Program/CollDetect_UserAction.src", 2, "W106"),
        ("System/masref_main.src", 2, "W106")], got
    assert "hook program masref_user.src" in got[2][3]


# KUKA's submit template (sps.sub of KSS 8, as the corpus' KR C4 backups hold it: the template's
# folds and RESET_OUT, the user's code only in the USER folds), written here by hand; the user's
# part names two variables nothing declares
SPS_TEMPLATE = """\
&ACCESS RVP
&COMMENT PLC on control
DEF  SPS ( )
;FOLD DECLARATIONS
  ;FOLD USER DECL
  ;ENDFOLD (USER DECL)
;ENDFOLD (DECLARATIONS)
;FOLD INI
  ;FOLD BASISTECH INI
    BasisTech_PLC_INIT()
  ;ENDFOLD (BASISTECH INI)
  ;FOLD AUTOEXT INIT
    INTERRUPT DECL 91 WHEN $PRO_STATE1==#P_FREE DO RESET_OUT ( )
  ;ENDFOLD (AUTOEXT INIT)
  ;FOLD BACKUPMANAGER PLC INIT
    BM_ENABLED = FALSE
  ;ENDFOLD (BACKUPMANAGER PLC INIT)
  ;FOLD USER INIT
    conveyor_count = 0
  ;ENDFOLD (USER INIT)
;ENDFOLD (INI)
LOOP
  ;FOLD BASISTECH PLC
    BasisTech_PLC_LOOP()
  ;ENDFOLD (BASISTECH PLC)
  ;FOLD BACKUPMANAGER PLC
    IF BM_ENABLED THEN
      BM_OUTPUTSIGNAL = TRUE
    ENDIF
  ;ENDFOLD (BACKUPMANAGER PLC)
  ;FOLD USER PLC
    conveyor_on = TRUE
    conveyor_step()
  ;ENDFOLD (USER PLC)
ENDLOOP
END

DEF RESET_OUT ( )
  IF (PGNO_REQ>0) THEN
    $OUT[PGNO_REQ]=FALSE
  ENDIF
END

DEF conveyor_step()
  conveyor_speed = 2
END
"""


def test_the_submit_template_is_kuka_s_outside_its_user_folds_wherever_it_lies(tmp_path):
    """Issue 85 item 8: one sps.sub gave BasisTech_PLC_INIT (BASISTECH INI fold) W106 but
    BasisTech_PLC_LOOP (BASISTECH PLC fold) E106, BM_ENABLED (BACKUPMANAGER PLC INIT) W101 but
    BM_OUTPUTSIGNAL (BACKUPMANAGER PLC) and PGNO_REQ (the template's RESET_OUT) E101. In a
    file built from KUKA's submit template (it holds the template's USER PLC fold) the template's
    lines -- its main routine and the routines they call (RESET_OUT, the handler of the INTERRUPT
    of its AUTOEXT INIT fold) outside the USER folds -- are KUKA's: every template name a
    warning, once; the user's names (USER INIT, USER PLC, and conveyor_step, a routine only the
    USER PLC fold calls) errors at their lines."""
    expected = [(10, "W106", "BasisTech_PLC_INIT"), (16, "W101", "BM_ENABLED"), (19, "E101", "conveyor_count"),
                (24, "W106", "BasisTech_PLC_LOOP"), (28, "W101", "BM_OUTPUTSIGNAL"), (32, "E101", "conveyor_on"),
                (39, "W101", "PGNO_REQ"), (45, "E101", "conveyor_speed")]
    for where in ("Program/Addons/sps.sub",):
        root = backup(tmp_path / where.replace("/", "_"), {where: SPS_TEMPLATE})
        got = [(ln, c, m) for p, ln, c, m in diags(root) if p == where]
        assert [(ln, c) for ln, c, _m in got] == [(ln, c) for ln, c, _n in expected], (where, got)
        for (_ln, _c, m), (_l, _k, name) in zip(got, expected):
            assert f"'{name}'" in m, (where, m)
        pgno = next(m for _ln, c, m in got if "PGNO_REQ" in m)
        assert "used 2 times" in pgno, pgno
