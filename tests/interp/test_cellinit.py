"""`krl cell init` (issue 34): inputs read in SWITCH and through routine parameters, only for
the program asked, every rule valid YAML once uncommented (interp/cellinit.py)."""

from __future__ import annotations

import yaml
from click.testing import CliRunner

from app import main
from robot.stimuli import parse_cell

from .helpers import refuse_runs, write
from .test_autocell import _backup, uncomment_rules

OTHER = """
DEF other()
  WAIT FOR $IN[77]
END
"""


def test_the_starter_reads_switch_parameters_and_only_the_program(tmp_path, monkeypatch):
    refuse_runs(monkeypatch)        # the programs are loaded, not run: no controller (issue 76)
    _backup(tmp_path)
    write(tmp_path, "R1/Program/other.src", OTHER)
    out = CliRunner().invoke(main, ["cell", "init", str(tmp_path), "job"])
    assert out.exit_code == 0, out.output
    text = out.output
    # the SWITCH's selector: a SIGNAL group, with its rule taking a number
    assert "# PROG_NR = $IN[17] TO $IN[20]   declared R1/System/$config.dat:6   ; program number of the PLC" in text
    assert "#   read at R1/Program/job.src:9 (SWITCH)" in text
    assert "#   set: {PROG_NR: 0}   # a number: the group's bits, bit 0 on its first input" in text
    # a SIGNAL passed to a routine whose parameter a WAIT FOR reads
    assert "# BPERMISOENTRADA = $IN[12]   declared R1/System/$config.dat:5   ; permission to enter" in text
    assert "#   read at R1/Program/job.src:29 (WAIT FOR, through parameter bPermit from R1/Program/job.src:6)" in text
    # another program's input is not this program's
    assert "$IN[77]" not in text
    # every rule, once uncommented, is a valid rule of a valid cell file
    cell = parse_cell(yaml.safe_load(uncomment_rules(text)), source="starter")
    assert len(cell.rules) == 7            # PART_READY, CLAMPED, $IN[8], BPERMISOENTRADA, PROG_NR, $IN[4], $IN[9]
    # without PROGRAM: every program of the backup
    out = CliRunner().invoke(main, ["cell", "init", str(tmp_path)])
    assert out.exit_code == 0 and "$IN[77]" in out.output
    parse_cell(yaml.safe_load(uncomment_rules(out.output)), source="starter")


def test_from_run_needs_a_trace(tmp_path):
    bad = write(tmp_path, "bad.jsonl", "not json\n")
    out = CliRunner().invoke(main, ["cell", "init", "--from-run", str(bad)])
    assert out.exit_code == 2 and "not a trace of krl run" in out.output and "Traceback" not in out.output
    out = CliRunner().invoke(main, ["cell", "init"])
    assert out.exit_code == 2 and "name the BACKUP" in out.output


def test_the_starter_lists_inputs_read_through_variables_with_the_value_production_needs(tmp_path, monkeypatch):
    """Issue 85 item 1: the group inputs are read only through variables assigned from them;
    the starter lists them, read through each variable, with the value of the first IF whose
    THEN branch is the program's work (krl/semantics/inputflow.py)."""
    refuse_runs(monkeypatch)
    write(tmp_path, "R1/System/$config.dat", CONFIG_GROUPS)
    write(tmp_path, "R1/Program/pal.src", PALLET)
    out = CliRunner().invoke(main, ["cell", "init", str(tmp_path), "pal"])
    assert out.exit_code == 0, out.output
    text = out.output
    assert "# GI_PRODUCTWITH = $IN[41] TO $IN[52]   declared R1/System/$config.dat:2   ; product width" in text
    assert "#   read at R1/Program/pal.src:5 (IF, through Width)" in text
    assert "#   a producing cell gives 900: the program's production path at pal.src:5 (IF) needs it" in text
    assert "#   set: {GI_PRODUCTWITH: 900}" in text
    assert "#   read at R1/Program/pal.src:5 (IF, through Kind)" in text
    assert "#   set: {GI_PRODUCTTYPE: 10}" in text
    cell = parse_cell(yaml.safe_load(uncomment_rules(text)), source="starter")
    assert len(cell.rules) == 2


CONFIG_GROUPS = """
DEFDAT  $CONFIG
SIGNAL GI_ProductWith $IN[41] TO $IN[52] ;product width
SIGNAL GI_ProductType $IN[53] TO $IN[56] ;product type
ENDDAT
"""

PALLET = """
DEF pal()
  DECL INT Width, Kind, Weight
  Width = GI_ProductWith
  Kind = GI_ProductType
  IF (Width == 900) AND (Kind == 10) THEN
    Weight = 55
  ENDIF
  LOAD_DATA[1].M = 130 + Weight
END
"""


# A backup's files in the KRC/R1 layout and lying flat (issue 85: the flat MACHINE_DEF layout,
# a backup whose KUKA files do not lie in KUKA's folders). KUKA's System library with its
# delivery header (read-only, titled: ingeniado's System/tm_bib.src reads STQM_SPSACTIVE at its
# line 164), a System module whose header names its folder, a technology package's module
# naming TP (read in both layouts: P00's folder, whose handshake reads cell inputs), the user's
# program.
KUKA_FILES = {
    "System/$config.dat": """
        DEFDAT  $CONFIG
        SIGNAL STQM_SPSACTIVE $IN[1026] ;KUKA's
        SIGNAL MASREF_REQ $IN[990] ;KUKA's mastering test
        SIGNAL PKG_READY $IN[30] ;package ready
        SIGNAL PART_THERE $IN[31] ;part present
        ENDDAT
        """,
    "System/tm_bib.src": """
        &ACCESS R
        &COMMENT Collision Detection Library
        DEF TM_BIB()
          IF STQM_SPSACTIVE THEN
            $OUT[5] = TRUE
          ENDIF
        END
        """,
    "System/masref_main.src": """
        &ACCESS RVO
        &PARAM DISKPATH = KRC:\\R1\\System
        DEF MASREF_MAIN()
          WAIT FOR MASREF_REQ
        END
        """,
    "TP/Pkg/pkg.src": """
        &ACCESS RVO
        &PARAM DISKPATH = KRC:\\R1\\TP\\Pkg
        DEF PKG()
          WAIT FOR PKG_READY
        END
        """,
    "Program/main.src": """
        &ACCESS RVP
        DEF MAIN()
          WAIT FOR PART_THERE
          PKG()
        END
        """,
}


def _listed(text: str) -> set[str]:
    """The inputs a starter lists (its rule heads ``  # NAME = ...``)."""
    return {line.split()[1] for line in text.splitlines() if line.startswith("  # ") and " = $IN[" in line}


def test_a_flat_layout_lists_what_the_folder_layout_lists(tmp_path, monkeypatch):
    """Issue 85's flat layout: the starter of the files lying flat reads KUKA's files by their
    header lines (krl/project.py rule 7) as the KRC/R1 layout does by their folders: KUKA's System
    inputs (STQM_SPSACTIVE, MASREF_REQ) are not the user's in either; the package's (read as TP
    is) and the program's are listed in both. Seen failing on the unchanged code (the flat starter
    listed STQM_SPSACTIVE and MASREF_REQ)."""
    refuse_runs(monkeypatch)
    for rel, text in KUKA_FILES.items():
        write(tmp_path / "tree", "R1/" + rel, text)
        write(tmp_path / "flat", rel.rsplit("/", 1)[1], text)
    want = {"PKG_READY", "PART_THERE"}
    for layout in ("tree", "flat"):
        out = CliRunner().invoke(main, ["cell", "init", str(tmp_path / layout)])
        assert out.exit_code == 0, out.output
        assert _listed(out.output) == want, (layout, out.output)
        out = CliRunner().invoke(main, ["cell", "init", str(tmp_path / layout), "main"])
        assert out.exit_code == 0, out.output
        assert _listed(out.output) == want, (layout, out.output)
