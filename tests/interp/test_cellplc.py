"""A PLC between the robots of a cell (issue 89; interp/cellplc.py, docs/cells.md "A PLC between
the robots"): robot R1's output wired to the PLC's input, the PLC's rules, the PLC's output wired
to robot R2's input.

Expected times by hand from the documented rules: a WAIT SEC t ends in the first IPO cycle
(12 ms) at or after t; a wire carries a value written in cycle k to its input for cycle k + 1
(docs/cells.md), a robot's output into the PLC as well; the PLC scans once per IPO cycle, after
the wires, and a rule answers at its first scan at least ``after`` s (and one cycle) after its
condition rose (robot/cellrules.py, a robot's own cell rules); its output then reaches the
robot's input at the next cycle boundary.

R1 raises $OUT[10] at line 3 in the cycle that starts at 0.504 s (WAIT SEC 0.5: 42 cycles). The
PLC's $IN[1] is TRUE from 0.516 s; its rule (after 0.2 s) rises at the scan of 0.516 s and answers
at the first scan at or after 0.716 s: 0.72 s (60 cycles), $OUT[1] TRUE; R2's $IN[10] is TRUE
from 0.732 s, and R2 leaves its WAIT FOR (line 2) in that cycle and raises $OUT[11] at line 3.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from jsonschema import Draft202012Validator

from interp.robotcell import CellError, cell_runs, load_robot_cell, run_cell, summary_lines

R1 = "DEF r1()\n  WAIT SEC 0.5\n  $OUT[10] = TRUE\n  WAIT FOR $IN[11]\nEND\n"
R2 = "DEF r2()\n  WAIT FOR $IN[10]\n  $OUT[11] = TRUE\nEND\n"
CELL = """robots:
  R1: {program: r1.src}
  R2: {program: r2.src}
wires:
  - R1 $OUT[10] -> PLC $IN[1]
  - PLC $OUT[1] -> R2 $IN[10]
  - R2 $OUT[11] -> R1 $IN[11]
plc:
  rules:
    - when: "$IN[1] AND NOT $IN[2]"
      after: 0.2
      set: {"$OUT[1]": true}
"""


def _run(tmp_path: Path, interp: str, cell: str = CELL):
    for name, text in (("r1.src", R1), ("r2.src", R2), ("cell.yaml", cell)):
        (tmp_path / name).write_text(text, encoding="utf-8")
    c = load_robot_cell(tmp_path / "cell.yaml")
    with cell_runs(c, interp, 10.0, mujoco=False) as runs:
        res = run_cell(c, runs)
        logs = {r.name: [(round(t, 3), s, v, src) for t, s, v, src in r.runtime.controller.io.log] for r in runs}
    return res, logs


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_r1_drives_r2_through_the_plc(tmp_path, interp):
    res, logs = _run(tmp_path, interp)
    assert res.reason == "completed", [r.runtime.result.text for r in res.robots]
    assert (0.504, "$OUT[10]", True, "program") in logs["R1"]
    assert (0.732, "$IN[10]", True, "wire PLC $OUT[1]") in logs["R2"]
    assert (0.732, "$OUT[11]", True, "program") in logs["R2"]
    assert (0.744, "$IN[11]", True, "wire R2 $OUT[11]") in logs["R1"]
    plc = res.plc
    assert [(round(t, 3), s, v) for t, s, v, _ in plc.io.log] == [(0.516, "$IN[1]", True), (0.72, "$OUT[1]", True)]
    (text, seconds, wires), = res.robots[1].released
    assert [str(w) for w in wires] == ["PLC $OUT[1] -> R2 $IN[10]"] and seconds == pytest.approx(0.732)
    assert "released by PLC $OUT[1] -> R2 $IN[10]" in "\n".join(summary_lines(res, tmp_path))
    doc = res.as_json()
    schema = json.loads((Path(__file__).resolve().parents[2] / "docs/schemas/cell-result.schema.json").read_text())
    assert not list(Draft202012Validator(schema).iter_errors(doc))
    assert doc["plc"] == [{"time": 0.516, "signal": "$IN[1]", "value": True, "source": "wire R1 $OUT[10]"},
                          {"time": 0.72, "signal": "$OUT[1]", "value": True, "source": "plc"}]


def test_the_plc_interlock_blocks_and_the_cell_deadlocks_naming_the_plc_wire(tmp_path):
    """The PLC's $IN[2] wired from R2's $OUT[12]: while R2 does not set it, the cell is the good
    one; R2 setting it first holds the rule's condition FALSE, so R2 waits for the PLC forever
    and R1 for R2: a deadlock, R2's end naming its wire from the PLC (the PLC has nothing
    pending, so it cannot end the waits either)."""
    res, _ = _run(tmp_path, "vm", CELL.replace("wires:\n", "wires:\n  - R2 $OUT[12] -> PLC $IN[2]\n"))
    # R2 never sets $OUT[12]: the PLC's $IN[2] stays FALSE, so this is the good cell again
    assert res.reason == "completed"
    (tmp_path / "r2.src").write_text("DEF r2()\n  $OUT[12] = TRUE\n  WAIT FOR $IN[10]\n  $OUT[11] = TRUE\nEND\n")
    c = load_robot_cell(tmp_path / "cell.yaml")
    with cell_runs(c, "vm", 10.0, mujoco=False) as runs:
        res = run_cell(c, runs)
    assert res.reason == "deadlock"
    assert "PLC $OUT[1] -> R2 $IN[10]" in res.robots[1].runtime.result.text


@pytest.mark.parametrize("text, message", [
    (CELL.replace('"$OUT[1]": true', '"$IN[1]": true'), "the PLC's rules set its outputs"),
    (CELL.replace("$IN[1] AND NOT $IN[2]", "PART_OK"), "unknown signal PART_OK"),
    (CELL.replace("  R2: {program: r2.src}\n", "  R2: {program: r2.src}\n  PLC: {program: r2.src}\n"),
     "PLC is the cell's PLC"),
    (CELL.replace("plc:\n  rules:\n", "plc:\n  rulez:\n"), "unknown key"),
])
def test_a_bad_plc_is_refused_at_its_line(tmp_path, text, message):
    for name, t in (("r1.src", R1), ("r2.src", R2), ("cell.yaml", text)):
        (tmp_path / name).write_text(t, encoding="utf-8")
    with pytest.raises(CellError) as err:
        load_robot_cell(tmp_path / "cell.yaml")
    assert message in str(err.value) and "cell.yaml:" in str(err.value)


def test_the_json_schema_takes_the_plc_the_reader_takes():
    schema = json.loads((Path(__file__).resolve().parents[2] / "docs/schemas/robot-cell.schema.json").read_text())
    check = Draft202012Validator(schema)
    assert not list(check.iter_errors(yaml.safe_load(CELL)))
    for bad in (CELL.replace('"$OUT[1]": true', '"$IN[1]": true'), CELL.replace("plc:\n  rules:\n", "plc:\n  rulez:\n"),
                CELL.replace("after: 0.2", "after: -1")):
        assert list(check.iter_errors(yaml.safe_load(bad))), bad
