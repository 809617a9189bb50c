"""KUKA's files known by their own header lines wherever they lie (krl/project.py rule 7,
krl/semantics/outside.py; issue 85: the ``flat MACHINE_DEF`` layout).

A backup whose files lie flat in one folder, without ``System/`` and ``TP/``, still holds KUKA's
BASIS modules: ``bas.src`` calling the installed ``RESET_CD_PARAMS`` at its line 12 was "routine
not found" and every one of KUKA's modules an entry point (``ir_stopm.src``: "interrupt 3 not
declared"), because only the folder said whose a file is. The files say it themselves: KUKA's
delivered modules carry a read-only header hidden from the operator with a title (``&ACCESS R``,
``&COMMENT BASIS package``: bas.src, ir_stopm.src, p00.src of the corpus's backups), a
technology package's modules the controller's folder they belong in (``&PARAM DISKPATH =
KRC:\\R1\\TP\\BrakeTest``). A user's file with ``&ACCESS R`` alone (as some of the corpus's
hand-written ones are) stays the user's.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from interp import realprograms as rp
from krl.project import find_backups, header_folder
from krl.workspace import load_workspace

# KUKA's BASIS module as delivered (header as the corpus's bas.src: read-only, titled), its
# call of the installed RESET_CD_PARAMS (KSS's collision detection) on line 12 as there
BAS = """\
&ACCESS R
&REL 1
&COMMENT BASIS package
DEF BAS (COMMAND :IN, VALUE :IN)
  DECL BAS_COMMAND COMMAND
  DECL REAL VALUE
  ; KUKA's dispatcher
  IF COMMAND == #INITMOV THEN
    $OUT[7] = TRUE
  ENDIF
  IF COMMAND == #INITMOV THEN
    RESET_CD_PARAMS ()
  ENDIF
END
"""
# KUKA's fault handler: declares no interrupt of its own (bas.src's INITMOV does on a controller)
IR_STOPM = """\
&ACCESS R4
&COMMENT HandlerOnRobotFault
DEF IR_STOPM ( )
  INTERRUPT OFF 3
  BRAKE
END
"""
# a technology package's module: its header names the controller folder it belongs in
PACKAGE = """\
&ACCESS RVO
&REL 3
&PARAM EDITMASK = *
&PARAM DISKPATH = KRC:\\R1\\TP\\Pkg
DEF PKG ( )
  PKG_INSTALLED_INIT ()
END

GLOBAL DEF PKG_START ( )
  $OUT[8] = TRUE
END
"""
# a user's library with a read-only header and no title: the user's, its error stays an error
USER_LIB = """\
&ACCESS R
DEF USER_LIB ( )
  NOT_THERE ()
END
"""
MAIN = """\
&ACCESS RVP
&REL 2
&PARAM TEMPLATE = C:\\KRC\\Roboter\\Template\\vorgabe
&PARAM EDITMASK = *
DEF MAIN ( )
  BAS (#INITMOV, 0)
  PKG_START ()
  $OUT[9] = $OUT[7] AND $OUT[8]
END
"""


def flat(tmp_path: Path) -> Path:
    root = tmp_path / "flat"
    root.mkdir()
    for name, text in (("bas.src", BAS), ("ir_stopm.src", IR_STOPM), ("pkg.src", PACKAGE),
                       ("user_lib.src", USER_LIB), ("main.src", MAIN)):
        (root / name).write_text(text.replace("\n", "\r\n"), encoding="latin-1")
    assert find_backups(root) == []          # no System/$config.dat: a folder of loose files
    return root


@pytest.mark.parametrize("head, folder", [
    ("&ACCESS R\r\n&REL 1\r\n&COMMENT BASIS package\r\nDEF BAS (COMMAND :IN)\r\n", "kuka"),
    ("&ACCESS  R\n&COMMENT EXTERNAL package\nDEFDAT  P00\n", "kuka"),
    ("&ACCESS RVO\n&PARAM DISKPATH = KRC:\\R1\\TP\\BrakeTest\nDEF X()\n", "tp"),
    ("&ACCESS RV\n&PARAM DISKPATH = KRC:\\R1\\Program\\System\nDEF X()\n", "system"),
    ("&ACCESS RVO\n&PARAM DISKPATH = TP/BrakeTest\nDEF X()\n", "tp"),
    ("&ACCESS RVP\n&COMMENT my cell\n&PARAM DISKPATH = KRC:\\R1\\Program\nDEF X()\n", None),
    ("&ACCESS R\nDEF X()\n", None),                         # read-only, untitled: a user's
    ("&ACCESS R\n&COMMENT\n&USER PKL_AST\nDEF X()\n", None),  # an empty title is none
    ("&ACCESS RV\n&COMMENT BASIS package\nDEF X()\n", None),  # visible: the operator's file
    ("DEF X()\n&ACCESS R\n&COMMENT BASIS package\n", None),   # header lines only before DEF
])
def test_the_header_says_whose_file_it_is(tmp_path, head, folder):
    p = tmp_path / "x.src"
    p.write_text(head, encoding="latin-1")
    assert header_folder(p) == folder


def test_kuka_modules_lying_flat_are_not_entry_points(tmp_path):
    root = flat(tmp_path)
    want = [root / "main.src", root / "user_lib.src"]
    assert rp.programs_of(root) == want
    assert rp.folder_entries(sorted(root.iterdir())) == want


def test_a_flat_bas_src_calling_installed_software_is_no_error(tmp_path):
    root = flat(tmp_path)
    ws = load_workspace([root], str(root))
    got = {(Path(d.path).name, d.line, d.code) for d in ws.check() if d.code[1:] in ("101", "106")}
    assert ("bas.src", 12, "W106") in got, got
    assert ("pkg.src", 6, "W106") in got, got
    assert ("user_lib.src", 3, "E106") in got, got
    assert not any(c.startswith("E") and f != "user_lib.src" for f, _ln, c in got), got


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_flat_backups_program_runs_through_kukas_bas(tmp_path, interp):
    root = flat(tmp_path)
    row = rp.run_one(root / "main.src", 5.0, 20_000, auto=True, interp=interp)
    assert row["reason"] == "completed", row.get("text")
