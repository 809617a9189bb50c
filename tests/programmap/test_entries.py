"""Entry points of the program map (issue 37): what the controller, the PLC and the operator can
start, so that "unreachable" is only what none of them can.

* PLC-selected programs: the corpus backup khrzysio__KRC4_test, whose CELL.src selects programs
  by number (``SWITCH PGNO``); the expected numbers were read by hand from its CASE branches.
* Operator-selectable programs: every module main under R1/Program of the same backup, and of
  the flat Palletizer export (``Program/``).
* A KR C2 backup without cell.src: the corpus has none, so one is built here after KUKA's KR C2
  folder conventions (``KRC/R1/Program``, ``KRC/R1/System`` with ``$config.dat`` and
  ``bas.src``, ``KRC/R1/Mada/$machine.dat``, ``KRC/STEU/Mada/$custom.dat``, the submit program
  ``KRC/R1/SPS.SUB``).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from app import main
from krl.programmap import build_map
from krl.workspace import workspaces_for


@pytest.fixture(scope="module")
def krc4_test(shared_corpus):
    return build_map(workspaces_for(shared_corpus / "khrzysio__KRC4_test", timeout=60)[0])


def test_programs_the_plc_selects_by_number(krc4_test):
    plc = {n.name: n.entry for n in krc4_test.nodes.values() if n.entry_kind == "plc"}
    # CELL.src: CASE 1 GetProcessData(), CASE 10 PrepareMillingTools(), CASE 20..23 Cut_Frame*(),
    # CASE 45 Mill_FrameGlue(), CASE 200 GoHomePos(); CASE 30, 31, 42, 43, 50..55 only HALT (their
    # programs are commented out); CellProgramStart()/CellProgramEnd() run in most branches
    expected = {"GetProcessData": 1, "PrepareMillingTools": 10, "Cut_FrameLeft": 20, "Cut_FrameRight": 21,
                "Cut_FrameUpper": 22, "Cut_FrameThreshold": 23, "Mill_FrameGlue": 45, "GoHomePos": 200}
    assert set(plc) == set(expected)
    for name, number in expected.items():
        assert plc[name].startswith(f"PLC program number {number} (cell program, line "), plc[name]
    cell = [n for n in krc4_test.nodes.values() if n.entry_kind == "cell"]
    assert [n.name for n in cell] == ["CELL"]
    for name in ("CellProgramStart", "CellProgramEnd"):
        node = next(n for n in krc4_test.nodes.values() if n.name == name)
        assert node.entry_kind != "plc" and not node.unreachable


def test_one_program_with_two_numbers(shared_corpus):
    # ChinaMilling's cell.src: CASE 1 millingcn(), CASE 2 nothing, CASE 3 millingcn()
    pm = build_map(workspaces_for(shared_corpus / "HugoDanielson__ChinaMilling" / "KRC", timeout=60)[0])
    plc = [(n.name, n.entry) for n in pm.nodes.values() if n.entry_kind == "plc"]
    assert len(plc) == 1 and plc[0][0] == "millingcn"
    assert plc[0][1].startswith("PLC program number 1 (cell program, line ")


def test_operator_selectable_programs(krc4_test, shared_corpus):
    operator = [n for n in krc4_test.nodes.values() if n.entry_kind == "operator"]
    assert operator
    for n in operator:
        parts = [p.lower() for p in Path(n.path).parts]
        assert parts[parts.index("r1") + 1] == "program" and n.main and not n.kuka
    # every module main under R1/Program that is a DEF without parameters is an entry of some
    # kind (none is dead); a main with parameters is an entry only as what calls it
    program = shared_corpus / "khrzysio__KRC4_test" / "R1" / "Program"
    mains = [n for n in krc4_test.nodes.values() if n.main and n.kind == "routine"
             and Path(n.path).is_relative_to(program) and not n.kuka]
    assert mains and all(n.entry and not n.unreachable for n in mains if n.runnable)
    # DrillHole2step(stHole:IN): a parameter, called by nothing -- dead, not selectable
    drill = next(n for n in mains if n.name == "DrillHole2step")
    assert not drill.runnable and drill.unreachable and not drill.entry
    # a flat export (Program/ beside System/)
    pm = build_map(workspaces_for(shared_corpus / "ingeniado__KRC4-Robot-Palletizer", timeout=60)[0])
    flat = [n for n in pm.nodes.values() if n.entry_kind == "operator"]
    assert flat and all("Program" in Path(n.path).parts for n in flat)


KRC2 = {
    "KRC/R1/System/$config.dat": "DEFDAT $CONFIG\nDECL INT PGNO_TYPE=1\nENDDAT\n",
    "KRC/R1/System/bas.src": "DEF BAS (COMMAND :IN,NUMBER :IN )\n  INT COMMAND\n  REAL NUMBER\nEND\n",
    "KRC/R1/Mada/$machine.dat": "DEFDAT $MACHINE\nDECL INT $TECH_MAX=6\nENDDAT\n",
    "KRC/STEU/Mada/$custom.dat": "DEFDAT $CUSTOM\nDECL INT $PRO_I_O_SYS=1\nENDDAT\n",
    "KRC/R1/SPS.SUB": "DEF SPS ( )\n  LOOP\n    WAIT SEC 0.012\n  ENDLOOP\nEND\n",
    # two user programs an operator selects; one calls a GLOBAL routine of a library module
    "KRC/R1/Program/weld_part.src": "DEF weld_part ( )\n  approach()\n  seam_lib()\nEND\n"
                                    "DEF approach ( )\nEND\nDEF never_called ( )\nEND\n",
    "KRC/R1/Program/weld_part.dat": "DEFDAT weld_part\nDECL INT count=0\nENDDAT\n",
    "KRC/R1/Program/service/clean_torch.src": "DEF clean_torch ( )\n  WAIT SEC 1\nEND\n",
    "KRC/R1/Program/lib/seam_lib.src": "DEF seam_lib ( )\nEND\nGLOBAL DEF seam_start ( )\nEND\n",
}


def test_kr_c2_backup_without_cell_src(tmp_path):
    for rel, text in KRC2.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text.replace("\n", "\r\n"), encoding="latin-1", newline="")
    pm = build_map(workspaces_for(tmp_path / "KRC", timeout=60)[0])
    kinds = {n.name: n.entry_kind for n in pm.nodes.values() if n.entry}
    assert kinds == {"weld_part": "operator", "clean_torch": "operator", "seam_lib": "operator",
                     "SPS": "submit", "BAS": "system"}
    # approach is called by weld_part; seam_start is a GLOBAL routine nobody calls; never_called
    # is a local routine nobody calls
    assert sorted(n.name for n in pm.unreachable) == ["never_called", "seam_start"]


def test_a_folder_of_two_backups_names_them(tmp_path):
    for backup in ("line1_robot", "line2_robot"):
        for rel, text in KRC2.items():
            p = tmp_path / "backups" / backup / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_text(text)
    r = CliRunner().invoke(main, ["graph", str(tmp_path / "backups")])
    assert r.exit_code == 2
    assert r.output.strip() == (f"krl graph: {tmp_path / 'backups'} holds 2 programs (KRC backups or folders): "
                                f"{tmp_path / 'backups/line1_robot/KRC'}, {tmp_path / 'backups/line2_robot/KRC'}; "
                                "name one of them")
    r = CliRunner().invoke(main, ["graph", "--format", "json", str(tmp_path / "backups" / "line1_robot")])
    assert r.exit_code == 0, r.output
