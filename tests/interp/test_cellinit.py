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
