"""``inputs: auto`` for a robot of a cell of several (issue 89; interp/robotcell.py
``wired_inputs``, interp/runtime/autocell.py): the automatic cell answers the inputs the robot
starves for that no wire drives; an input a partner's wire drives is the partner's, never
answered, even when the partner never sets it (the cell then deadlocks)."""

from __future__ import annotations

from pathlib import Path

import pytest

from interp.robotcell import cell_runs, load_robot_cell, run_cell
from interp.runtime.autocell import AUTO_DELAY_S

# R1 needs $IN[20] (nothing wires it: the automatic cell's) and then $IN[11] (R2's, by a wire)
R1 = """DEF r1()
  WAIT FOR $IN[20]
  WAIT FOR $IN[11]
  $OUT[12] = TRUE
END
"""
R2 = """DEF r2()
  WAIT SEC 2.0
  $OUT[11] = TRUE
END
"""
R2_SILENT = """DEF r2()
  WAIT SEC 2.0
END
"""
CELL = """robots:
  R1: {program: r1.src, inputs: auto}
  R2: {program: r2.src}
wires:
  - R2 $OUT[11] -> R1 $IN[11]
"""


def _run(tmp_path: Path, r2: str, interp: str):
    (tmp_path / "r1.src").write_text(R1, encoding="utf-8")
    (tmp_path / "r2.src").write_text(r2, encoding="utf-8")
    (tmp_path / "cell.yaml").write_text(CELL, encoding="utf-8")
    cell = load_robot_cell(tmp_path / "cell.yaml")
    with cell_runs(cell, interp, 10.0, mujoco=False) as runs:
        res = run_cell(cell, runs)
        log = {r.name: [(round(t, 3), s, v, src) for t, s, v, src, *_ in r.runtime.controller.io.log] for r in runs}
    return res, log


def _sources(log, signal):
    return [(t, v, src) for t, s, v, src in log if s == signal]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_auto_answers_the_unwired_input_and_leaves_the_wired_one_to_the_partner(tmp_path, interp):
    res, log = _run(tmp_path, R2, interp)
    assert res.reason == "completed", [r.runtime.result for r in res.robots]
    r1 = log["R1"]
    # $IN[20]: R1 starves at once; the automatic cell answers AUTO_DELAY_S later
    ((t20, v20, src20),) = _sources(r1, "$IN[20]")
    assert v20 is True and src20 == "auto" and t20 == pytest.approx(AUTO_DELAY_S, abs=0.013)
    # $IN[11]: only R2's wire, at the cycle after R2 wrote it (WAIT SEC 2.0 ends in the cycle at
    # 2.004 s: 2.0 / 0.012 is 166.7, so cycle 167), though R1 waited for it from ~0.5 s
    assert _sources(r1, "$IN[11]") == [(pytest.approx(2.016), True, "wire R2 $OUT[11]")]
    assert any(s == "$OUT[12]" and v is True for _t, s, v, _src in r1)
    released = res.robots[0].released
    assert [(text.rsplit(":", 1)[1], [str(w) for w in wires]) for text, _s, wires in released] == \
        [("3", ["R2 $OUT[11] -> R1 $IN[11]"])]


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_wired_input_the_partner_never_sets_is_not_answered(tmp_path, interp):
    res, log = _run(tmp_path, R2_SILENT, interp)
    r1 = res.robots[0].runtime.result
    assert res.reason == "deadlock" and r1.reason == "deadlock" and r1.line == 3
    assert "R2 $OUT[11] -> R1 $IN[11]" in r1.text
    assert _sources(log["R1"], "$IN[11]") == []
    assert [src for _t, _v, src in _sources(log["R1"], "$IN[20]")] == ["auto"]
