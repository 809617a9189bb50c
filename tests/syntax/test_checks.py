"""Post-parse token checks (krl/syntax/checks.py): restrictions the grammar used to state as
Python-only semantic predicates. Expected positions are counted by hand from the text."""

from __future__ import annotations

import pytest

from krl.syntax.checks import may_fail
from krl.syntax.parse import parse_text


def routine(line: str) -> str:
    return "DEF t()\n" + line + "\nEND\n"


@pytest.mark.parametrize("line", [
    "TRIGGER WHEN DISTANCE=0 DELAY=0 DO $OUT[7]=TRUE",
    "TRIGGER WHEN DISTANCE=1 DELAY=20 DO $OUT[7]=FALSE PRIO=-1",
    "trigger when distance = 1 delay = 0 do Mark()",
])
def test_trigger_distance_zero_or_one_accepted(line):
    res = parse_text(routine(line))
    assert res.ok, [e.message for e in res.errors]


@pytest.mark.parametrize("value", ["2", "01", "10"])
def test_trigger_distance_other_values_rejected_at_the_value(value):
    res = parse_text(routine(f"  TRIGGER WHEN DISTANCE={value} DELAY=0 DO $OUT[7]=TRUE"))
    assert not res.ok and res.status == "syntax_error"
    [err] = res.errors
    # "  TRIGGER WHEN DISTANCE=" is 24 characters: the value starts at 0-based column 24.
    assert (err.line, err.column, err.offending) == (2, 24, value)
    assert err.message == f"TRIGGER WHEN DISTANCE takes 0 or 1, not {value}"
    assert err.expected == ["0", "1"]
    assert err.rule_stack[-1] == "triggerStatement"
    assert not err.cascade


def test_check_error_beside_a_grammar_error():
    text = "DEF t()\nTRIGGER WHEN DISTANCE=3 DELAY=0 DO $OUT[7]=TRUE\nx = = 1\nEND\n"
    res = parse_text(text)
    assert [e.line for e in res.errors if not e.cascade] == [2, 3]
    assert res.errors[0].message.startswith("TRIGGER WHEN DISTANCE takes 0 or 1")


@pytest.mark.parametrize("text, expected", [
    ("TRIGGER WHEN DISTANCE=2 DELAY=0 DO x=1", True),
    ("trigger when distance = 01 delay=0 do x=1", True),
    ("TRIGGER WHEN DISTANCE=0 DELAY=0 DO x=1", False),
    ("TRIGGER WHEN DISTANCE=1 DELAY=0 DO x=1", False),
    ("LIN_REL {X 10} #WORLD", True),
    ("lin_rel {x 10} c_dis #base", False),
    ("SCIRC_REL a, b #TOOL", False),
    ("PTP_REL {A1 10} #BASEX", True),
    ("LIN XP1 ;#WORLD", False),
])
def test_may_fail_prefilter(text, expected):
    assert may_fail(text) is expected


@pytest.mark.parametrize("line", [
    "LIN_REL {X 10} #BASE", "PTP_REL {A1 5} C_PTP #TOOL", "slin_rel {z 1} #tool",
    "CIRC_REL {X 1}, {X 2} #BASE", "SPTP_REL {A1 5}", "SCIRC_REL {X 1}, {X 2} #Tool",
])
def test_relative_motion_frames_accepted(line):
    res = parse_text(routine(line))
    assert res.ok, [e.message for e in res.errors]


@pytest.mark.parametrize("line, column, frame", [
    ("LIN_REL {Z 10.0} #WORLD", 17, "#WORLD"),
    ("PTP_REL {A1 5} C_PTP #ROBROOT", 21, "#ROBROOT"),
    ("SLIN_REL {X 1} #base1", 15, "#base1"),
])
def test_relative_motion_other_frames_rejected_at_the_frame(line, column, frame):
    res = parse_text(routine(line))
    [err] = res.errors
    assert (err.line, err.column, err.offending) == (2, column, frame)
    assert err.message == f"a relative motion takes #BASE or #TOOL, not {frame}"
    assert err.rule_stack[-2:] == ["statement", "motion"]
