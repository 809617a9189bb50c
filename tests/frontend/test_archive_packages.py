"""A controller archive's am.ini names the technology packages installed on the controller
(issue 72 item 8: "am.ini's technology packages known as installed"). A program of the archive
calls a package's routines (declared EXT, or a GLOBAL routine called by name) without the
package's files (R1/TP/<package>): those calls are installed software, named as the package
the archive lists, and `krl check` and the run summary say which packages the archive declares.

The case rebuilt from the issue's description: a KSS 8.7 archive (am.ini, KRC/R1, KRC/STEU)
whose am.ini lists KUKA.GripperSpotTech and KUKA.EthernetKRL, and a program calling
GripperSpotTech's GRPg_SetState under EXT and its GRPg_Check without one. Expected values:
the routines are GLOBAL DEFs of KUKA's R1/TP/GripperSpotTech/Grp_Func.src (the corpus's
khrzysio__KRC4_test, lines 71 and 335: read below, not from the checker), the package names
and versions are the am.ini text written here. Before the fix, `krl check` reported
"E106 routine 'GRPg_Check' is not declared" and `krl run` refused the module; nothing said
which packages the archive declares."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main
from krl.semantics.outside import installed_clause, package_installed
from tests.logbook.archive import write_files, zip_folder

AM_INI = """[Archive]
ID=00000000-0000-0000-0000-000000000072
Date=2026-11-27_01-00-00
[Roboter]
RobName=Gripper_Cell
IRSerialNr=720008
[Version]
Version=V8.7.8
[TechPacks]
TechPacks={packs}|
KUKA.GripperSpotTech=4.1.2
KUKA.EthernetKRL=3.1.3
"""
PICK = """DEF pick()
  EXT GRPg_SetState(INT:IN, INT:IN)
  INT n
  n = 1
  GRPg_SetState(1, 2)
  GRPg_Check(1, 2, FALSE, 1)
  n = GRPg_MaxGrp
END
"""
GRP_FUNC = "khrzysio__KRC4_test/R1/TP/GripperSpotTech/Grp_Func.src"
GRP_DATA = "khrzysio__KRC4_test/R1/TP/GripperSpotTech/Grp_Data.dat"


def _archive(root: Path, packs: str) -> Path:
    return write_files(root, (("am.ini", AM_INI.format(packs=packs)), ("KRC/R1/System/$config.dat", "DEFDAT $CONFIG\nENDDAT\n"),
                              ("KRC/STEU/$config.dat", "DEFDAT $CONFIG\nENDDAT\n"), ("KRC/R1/Program/pick.src", PICK)))


def krl(*args: str):
    return CliRunner().invoke(main, list(args))


def test_the_corpus_declares_the_routines_in_gripperspottech(shared_corpus):
    """The independent source of the package's routine names: KUKA's own file."""
    lines = (shared_corpus / GRP_FUNC).read_text(encoding="latin-1").splitlines()
    assert re.match(r"\s*GLOBAL DEF GRPg_SetState\b", lines[70], re.I), lines[70]
    assert re.match(r"\s*GLOBAL DEF GRPg_Check\b", lines[334], re.I), lines[334]
    line = (shared_corpus / GRP_DATA).read_text(encoding="latin-1").splitlines()[18]
    assert re.match(r"\s*GLOBAL INT GRPg_MaxGrp\b", line, re.I), line


@pytest.mark.parametrize("zipped", [False, True])
def test_a_package_the_archive_lists_is_installed_software(tmp_path, zipped):
    root = _archive(tmp_path / "archive", "KUKA.GripperSpotTech|KUKA.EthernetKRL")
    target = root
    if zipped:
        target = zip_folder(root, tmp_path / "archive.zip")
    res = krl("check", str(target))
    assert res.exit_code == 0, res.output
    assert "E106" not in res.output
    assert (f"{target / 'KRC'}: the archive's am.ini lists these technology packages as installed: "
            "KUKA.GripperSpotTech 4.1.2, KUKA.EthernetKRL 3.1.3") in res.output
    for name, source in (("GRPg_SetState", f"{GRP_FUNC}:71"), ("GRPg_Check", f"{GRP_FUNC}:335"),
                         ("GRPg_MaxGrp", f"{GRP_DATA}:19")):
        warning = next(x for x in res.output.splitlines() if f"'{name}'" in x)
        assert "warning[W10" in warning
        assert (f"declared by technology package GripperSpotTech ({source}), which this backup does not "
                "contain; the archive's am.ini lists it as installed (KUKA.GripperSpotTech 4.1.2)") in warning
    res = krl("check", str(target), "--format", "json")
    assert json.loads(res.output.splitlines()[0])["installed_packages"] == [
        {"name": "KUKA.GripperSpotTech", "version": "4.1.2"}, {"name": "KUKA.EthernetKRL", "version": "3.1.3"}]


def test_a_package_the_archive_does_not_list_is_said_so(tmp_path):
    """am.ini lists EthernetKRL only: GripperSpotTech's routine called without EXT is the
    program's error (nothing declares it and the archive says the package is not installed),
    its EXT-declared routine stays installed software by its EXT, the warning adding that the
    archive does not list its package, and its data-list variable
    (a name the tables give the package whatever the archive says) is named as not listed."""
    root = _archive(tmp_path / "archive", "KUKA.EthernetKRL")
    res = krl("check", str(root))
    assert res.exit_code == 1, res.output
    out = res.output.splitlines()
    assert any("error[E106]: routine 'GRPg_Check' is not declared" in x for x in out), res.output
    ext = next(x for x in out if "routine 'GRPg_SetState'" in x)
    assert "warning[W106]" in ext and "an EXT declaration (pick.src:2) names it" in ext, ext
    assert ext.endswith(f"; it is a routine of technology package GripperSpotTech ({GRP_FUNC}:71); the archive's "
                        "am.ini does not list it among its installed technology packages"), ext
    var = next(x for x in out if "'GRPg_MaxGrp'" in x)
    assert var.endswith(f"declared by technology package GripperSpotTech ({GRP_DATA}:19), which this backup does "
                        "not contain; the archive's am.ini does not list it among its installed technology "
                        "packages"), var
    assert "technology packages as installed: KUKA.EthernetKRL 3.1.3" in res.output


def test_without_an_archive_nothing_changes(tmp_path):
    """The same backup without am.ini (a KRC backup, not an archive): the package's routine
    called without EXT is the program's error, as before; no package line."""
    root = _archive(tmp_path / "archive", "KUKA.GripperSpotTech")
    (root / "am.ini").unlink()
    res = krl("check", str(root))
    assert "error[E106]: routine 'GRPg_Check' is not declared" in res.output
    assert "am.ini" not in res.output


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_run_stands_in_for_the_package_and_names_it(tmp_path, interp):
    root = _archive(tmp_path / "archive", "KUKA.GripperSpotTech|KUKA.EthernetKRL")
    res = krl("run", str(root / "KRC" / "R1" / "Program" / "pick.src"), "--interp", interp, "--max-sim-time", "1")
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert "  ended      completed at t=0.000 s" in lines, res.output
    assert lines[4].startswith("  stubs      3: "), res.output
    assert "GRPg_Check (procedure, 1 call)" in lines[4] and "GRPg_SetState (procedure, 1 call)" in lines[4], lines[4]
    assert "GRPg_MaxGrp (" in lines[4], lines[4]
    assert ("  packages   KUKA.GripperSpotTech 4.1.2, KUKA.EthernetKRL 3.1.3 (installed: the archive's am.ini)"
            in lines), res.output


def test_package_names_match_as_am_ini_and_the_tp_folder_spell_them():
    listed = (("KUKA.GripperSpotTech", "4.1.2"), ("KUKA.PROFINET MS", "6.0.8"))
    assert package_installed("GripperSpotTech", listed) == ("KUKA.GripperSpotTech", "4.1.2")
    assert package_installed("gripperspottech", listed) == ("KUKA.GripperSpotTech", "4.1.2")
    assert package_installed("PROFINETMS", listed) == ("KUKA.PROFINET MS", "6.0.8")
    assert package_installed("Milling", listed) is None
    assert package_installed("", listed) is None
    assert installed_clause("Milling", ()) == ""
