"""`krl cell init BACKUP BACKUP` (issue 89 item 5; interp/cellwires.py): the starter of a cell of
several robots: each backup's entry point and the wires its $config.dat makes evident, each
with why. The two backups are written here; the expected wires are worked out by hand from
their $config.dat below."""

from __future__ import annotations

import yaml
from click.testing import CliRunner

from app import main
from interp.robotcell import load_robot_cell

from .helpers import write

# the handler: PART_READY is its output 10, it waits for PART_TAKEN on input 11; output 20
# "clamp open" has a number and comment the palletizer's input 20 shares; output 30 "lamp"
# has no partner; its group output (TO) is no wire
HANDLER_CONFIG = """DEFDAT $CONFIG
SIGNAL PART_READY $OUT[10] ; part ready for the palletizer
SIGNAL PART_TAKEN $IN[11] ; the palletizer took the part
SIGNAL CLAMP_OPEN $OUT[20] ; Clamp open
SIGNAL LAMP $OUT[30] ; lamp
SIGNAL JOB $OUT[40] TO $OUT[43] ; job number
ENDDAT
"""
# the palletizer: PART_READY is its input 5 (same name: wired 10 -> 5); PART_TAKEN its output 7
# (same name: wired 7 -> 11); its input 20 "clamp open!" (same number and comment as the
# handler's output 20, punctuation and case aside); input 30 "lamp test" (a different comment:
# no wire); JOB_IN 40..43 is a group
PAL_CONFIG = """DEFDAT $CONFIG
SIGNAL PART_READY $IN[5] ; handler offers a part
SIGNAL PART_TAKEN $OUT[7] ; part taken
SIGNAL GRIP_OK $IN[20] ; clamp open!
SIGNAL LAMP_TEST $IN[30] ; lamp test
SIGNAL JOB_IN $IN[40] TO $IN[43]
ENDDAT
"""
CELL_SRC = """DEF CELL()
  WAIT FOR $IN[5]
END
"""
HANDLER_SRC = """DEF cell()
  $OUT[10] = TRUE
END
"""


def _backups(tmp_path):
    write(tmp_path, "handler/R1/System/$config.dat", HANDLER_CONFIG)
    write(tmp_path, "handler/R1/cell.src", HANDLER_SRC)
    write(tmp_path, "handler/R1/Program/other.src", "DEF other()\nEND\n")
    # a flat export: no cell.src, its cell program main.src (DEF CELL), as ingeniado's
    write(tmp_path, "pal/System/$config.dat", PAL_CONFIG)
    write(tmp_path, "pal/main.src", CELL_SRC)
    write(tmp_path, "pal/Program/a_pick.src", "DEF a_pick()\nEND\n")


def test_cell_init_of_two_backups_proposes_the_evident_wires(tmp_path):
    _backups(tmp_path)
    out = tmp_path / "cell.yaml"
    res = CliRunner().invoke(main, ["cell", "init", str(tmp_path / "handler"), str(tmp_path / "pal"), "-o", str(out)])
    assert res.exit_code == 0, res.output
    text = out.read_text(encoding="utf-8")
    doc = yaml.safe_load(text)
    assert doc["robots"] == {"R1": {"program": "handler/R1/cell.src", "workspace": "handler"},
                             "R2": {"program": "pal/main.src", "workspace": "pal"}}
    assert doc["wires"] == ["R1 $OUT[10] -> R2 $IN[5]", "R2 $OUT[7] -> R1 $IN[11]", "R1 $OUT[20] -> R2 $IN[20]"]
    # each with why: the name, or the number and the comment, and both declarations
    assert ("# same name PART_READY: R1 PART_READY $OUT[10] (handler/R1/System/$config.dat:2; part ready for "
            "the palletizer) -> R2 PART_READY $IN[5] (pal/System/$config.dat:2; handler offers a part)") in text
    assert "# same number 20, same comment 'Clamp open': R1 CLAMP_OPEN $OUT[20]" in text
    assert "other program(s)" in text
    # the starter is a cell the reader takes as it is
    cell = load_robot_cell(out)
    assert [str(w) for w in cell.wires] == doc["wires"]


def test_an_input_two_outputs_match_is_wired_once(tmp_path):
    _backups(tmp_path)
    # a third robot, a copy of the handler: its PART_READY matches the palletizer's input 5 too
    write(tmp_path, "handler2/R1/System/$config.dat", HANDLER_CONFIG)
    write(tmp_path, "handler2/R1/cell.src", HANDLER_SRC)
    res = CliRunner().invoke(main, ["cell", "init", *(str(tmp_path / n) for n in ("handler", "pal", "handler2"))])
    assert res.exit_code == 0, res.output
    doc = yaml.safe_load(res.output)
    wires = doc["wires"]
    assert wires.count("R1 $OUT[10] -> R2 $IN[5]") == 1 and "R3 $OUT[10] -> R2 $IN[5]" not in wires
    assert "# - R3 $OUT[10] -> R2 $IN[5]      # not wired: R2 $IN[5] is driven by R1 $OUT[10] -> R2 $IN[5]" \
        in res.output
    # the palletizer's PART_TAKEN may drive each handler's input 11
    assert "R2 $OUT[7] -> R1 $IN[11]" in wires and "R2 $OUT[7] -> R3 $IN[11]" in wires


def test_backups_without_matching_signals_give_no_wire(tmp_path):
    write(tmp_path, "a/R1/System/$config.dat", "DEFDAT $CONFIG\nSIGNAL X $OUT[1] ; x\nENDDAT\n")
    write(tmp_path, "a/R1/cell.src", HANDLER_SRC)
    write(tmp_path, "b/R1/System/$config.dat", "DEFDAT $CONFIG\nSIGNAL Y $IN[2] ; y\nENDDAT\n")
    write(tmp_path, "b/R1/cell.src", HANDLER_SRC)
    res = CliRunner().invoke(main, ["cell", "init", str(tmp_path / "a"), str(tmp_path / "b")])
    assert res.exit_code == 0, res.output
    assert yaml.safe_load(res.output)["wires"] == []
