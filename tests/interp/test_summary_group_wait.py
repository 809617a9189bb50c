"""The run summary of a WAIT FOR on a group SIGNAL (issue 72, item 7): ``SIGNAL PartCode $IN[513]
TO $IN[544]`` (32 inputs, an INT) is an input the wait waits on, not "no input", and the cell
rule that releases ``WAIT FOR PartCode == 7`` sets the group to 7 (robot/stimuli.py: a group
takes an INT, bit 0 on its first input)."""

from __future__ import annotations

import pytest

from interp.summary import starvation_lines

from .helpers import run_krl

PROG = """
DEF prog()
  WAIT FOR PartCode == 7
  $OUT[1] = TRUE
END
"""
DAT = """
DEFDAT prog
  SIGNAL PartCode $IN[513] TO $IN[544]
ENDDAT
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_wait_on_a_group_signal_waits_on_its_inputs(tmp_path, interp):
    r = run_krl(tmp_path, PROG, DAT, max_sim_time=0.5, trace=False, interp=interp)
    assert r.result.reason in ("max_sim_time", "deadlock"), r.result.text
    lines = starvation_lines(r.rt)
    assert lines[0].startswith("  starves    WAIT FOR at ") and "prog.src:2 waits on PARTCODE ($IN[513..544])" in lines[0], lines
    assert "no input" not in lines[0]
    assert any("set: {PARTCODE: 7}" in line for line in lines), lines


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_the_rule_the_summary_proposes_releases_the_wait(tmp_path, interp):
    """The proposed rule, given as the cell file, releases the wait: the program ends."""
    cell = 'rules:\n  - {when: "TRUE", after: 0.1, set: {PartCode: 7}}\n'
    r = run_krl(tmp_path, PROG, DAT, stimuli=cell, max_sim_time=2.0, trace=False, interp=interp)
    assert r.result.reason == "completed", r.result.text
    assert r.rt.controller.io.get_in(513) and r.rt.controller.io.get_in(514) and r.rt.controller.io.get_in(515)
    assert not r.rt.controller.io.get_in(516)
