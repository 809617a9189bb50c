"""Reactive rules of a cell file (robot/cellrules.py, issue 22): rising edge, delay in IPO
cycles of 12 ms, hostile files refused with file:line."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest

from robot.cellrules import names_of, parse_condition, step_rules
from robot.io import IOImage
from robot.stimuli import StimulusError, load_cell, resolve_signals
from tests.interp.helpers import run_krl

PROGRAM = """
DEF prog()
  $OUT[1] = TRUE
  WAIT FOR $IN[2]
  $OUT[3] = TRUE
  $OUT[1] = FALSE
  WAIT SEC 0.1
  $OUT[1] = TRUE
  WAIT FOR $IN[4]
END
"""

RULES = """
rules:
  - when: "$OUT[1] AND NOT $IN[2]"
    after: 0.05
    set: {"$IN[2]": true}
  - when: "$OUT[1] AND $IN[2] AND $OUT[3]"
    set: {"$IN[4]": true}
"""


def test_rule_fires_on_rising_edge_after_its_delay(tmp_path):
    r = run_krl(tmp_path, PROGRAM, stimuli=RULES)
    assert r.result.reason == "completed"
    cell = [(e["t"], e["signal"], e["value"]) for e in r.kinds("io") if e.get("source") == "cell"]
    # $OUT[1] is set at t=0; the cell sees the edge in IPO cycle 1 (t=0.012 s) and answers in
    # the first cycle at or after 0.012 + 0.05 = 0.062 s: cycle 6, t=0.072 s.
    # Rule 2: $OUT[1] drops at 0.072 s, WAIT SEC 0.1 = 9 cycles (0.108 s) -> rises again at
    # 0.180 s; edge seen in cycle 16 (0.192 s); after 0 -> the next cycle, 0.204 s.
    assert cell == [(0.072, "$IN[2]", True), (0.204, "$IN[4]", True)]
    assert r.result.sim_time == pytest.approx(0.204)


def test_rule_fires_once_per_rising_edge_not_while_true(tmp_path):
    src = """
    DEF prog()
      $OUT[1] = TRUE
      WAIT SEC 0.06
      $OUT[1] = FALSE
      WAIT SEC 0.06
      $OUT[1] = TRUE
      WAIT SEC 0.06
    END
    """
    # $IN[7] shows each answer: set by the first rule, reset by the second
    r = run_krl(tmp_path, src, stimuli="""
        rules:
          - when: "$OUT[1]"
            after: 0.024
            set: {"$IN[7]": true}
          - when: "NOT $OUT[1]"
            after: 0.024
            set: {"$IN[7]": false}
        """)
    ins = r.io("$IN[7]")
    # edges: $OUT[1] TRUE seen at cycle 1 (0.012) -> 0.036; NOT $OUT[1] is TRUE only from
    # 0.060 (5 cycles of WAIT SEC 0.06) -> seen 0.072 -> 0.096; TRUE again at 0.120 ->
    # seen 0.132 -> 0.156. (NOT $OUT[1] at the first cycle is FALSE: no answer at the start.)
    assert ins == [(0.036, True), (0.096, False), (0.156, True)]


def _cell(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "cell.yaml"
    p.write_text(textwrap.dedent(text).lstrip("\n"), encoding="utf-8")
    return p


def _error(tmp_path, text: str) -> str:
    p = _cell(tmp_path, text)
    with pytest.raises(StimulusError) as info:
        load_cell(p)
    return str(info.value).replace(str(p), "cell.yaml")


@pytest.mark.parametrize("when, message", [
    ("$IN[1] AND", "cell.yaml:3: not a KRL expression"),
    ("__import__('os').system('rm -rf /')", "cell.yaml:3: not a KRL expression"),
    ('__import__("os")', "cell.yaml:3: a function call is not allowed"),
    ("open(\"x\")", "cell.yaml:3: a function call is not allowed"),
    ("$IN[1] + 1 == 2", "cell.yaml:3: operator + is not allowed"),
    ("\"text\" == \"text\"", "cell.yaml:3: a string is not allowed"),
    ("$POS_ACT.X > 0", "cell.yaml:3: a structure component is not allowed"),
    ("$IN[i]", "cell.yaml:3: $IN[...] needs one constant index"),
    ("$IN[9000]", "cell.yaml:3: $IN[9000]: index outside 1..8192"),
    ("$IN[1]\nWAIT SEC 1", "cell.yaml:3: not a KRL expression: an expression is one line"),
    ("$IN[1] $IN[2]", "cell.yaml:3: not a KRL expression: unexpected '$IN'"),
])
def test_hostile_conditions_are_refused_at_load_with_file_line(tmp_path, when, message):
    text = "rules:\n  - set: {\"$IN[1]\": true}\n    when: " + json.dumps(when) + "\n"
    assert _error(tmp_path, text).startswith(message)


def test_schema_of_rules(tmp_path):
    assert _error(tmp_path, """
        rules:
          - when: "$IN[1]"
            set: {"$IN[2]": true}
            afterr: 1
        """).startswith("cell.yaml:4: unknown field of rule 1: 'afterr'")
    assert _error(tmp_path, """
        rules:
          - when: "$IN[1]"
            after: -1
            set: {"$IN[2]": true}
        """).startswith("cell.yaml:3: after must not be negative")
    assert _error(tmp_path, """
        rules:
          - when: "$IN[1]"
        """).startswith("cell.yaml:2: rule 1 needs a 'set' mapping")
    assert _error(tmp_path, """
        rules:
          - when: "$IN[1]"
            set: {"$OUT[2]": true}
        """).startswith("cell.yaml:3: only $IN/$ANIN can be stimulated")
    assert "more than the limit of" in _error(tmp_path, "rules:\n" + "  - {when: 'TRUE', set: {'$IN[1]': true}}\n" * 1001)
    long = " OR ".join(["$IN[1]"] * 120)
    assert "more than the limit of 200" in _error(tmp_path, f"rules:\n  - {{when: '{long}', set: {{'$IN[1]': true}}}}\n")


def test_unknown_signal_and_types_are_errors_when_the_run_resolves_names(tmp_path):
    table = {"PART_OK": ("$IN", 3, None), "CODE": ("$IN", 10, 13), "GRIP": ("$OUT", 5, None)}
    cell = load_cell(_cell(tmp_path, """
        rules:
          - when: "GRIP AND (CODE == 5)"   # comparisons bind weaker than AND (reference §4.1)
            set: {PART_OK: true}
        """))
    resolve_signals([], table.get, cell.rules)
    assert cell.rules[0].set == {"$IN[3]": True}
    for when, msg in (("NOPE", "unknown signal NOPE"), ("CODE", "the condition is INT, not BOOL"),
                      # the front end's checker types the condition: krl check's messages
                      ("GRIP AND CODE", "'AND' cannot be applied to BOOL and INT"),
                      ("GRIP > 1", "'>' cannot be applied to BOOL and INT")):
        bad = load_cell(_cell(tmp_path, f"rules:\n  - when: \"{when}\"\n    set: {{PART_OK: true}}\n"))
        with pytest.raises(StimulusError) as info:
            resolve_signals([], table.get, bad.rules)
        assert str(info.value).startswith(f"{tmp_path / 'cell.yaml'}:2: when '{when}': {msg}")


def test_signal_group_reads_as_int_and_names_are_listed():
    expr = parse_condition("(CODE == 5) AND NOT $IN[3] OR $ANIN[1] > 0.5")
    assert names_of(expr) == ["CODE", "$IN[3]", "$ANIN[1]"]


TWO_DELAYS = """
rules:
  - when: "$OUT[1]"
    after: 0.05
    set: {"$IN[2]": true}
  - when: "$OUT[1]"
    after: 0.1
    set: {"$IN[3]": true}
  - when: "$IN[2] AND $IN[3]"
    set: {"$IN[4]": true}
"""


def _stepped(tmp_path, name, skip: bool, cycles: int = 20) -> list:
    """The I/O changes of the TWO_DELAYS cell over `cycles` IPO cycles of 12 ms after $OUT[1]
    rises: with step_rules' `seen` passed on (`skip`), or None each cycle (nothing skipped)."""
    f = tmp_path / name
    f.write_text(TWO_DELAYS, encoding="utf-8")
    cell = load_cell(f)
    resolve_signals([], lambda _name: None, cell.rules)
    io = IOImage()
    io.set_out(1, True, "program")
    seen = None
    for k in range(1, cycles + 1):
        io.now = k * 0.012
        got = step_rules(cell.rules, io, k * 0.012, 0.012, seen)
        seen = got if skip else None
    return [(round(t, 6), n, v) for t, n, v, src in io.log if src == "cell"]


def test_answers_are_written_at_their_cycle_whether_or_not_the_image_changed(tmp_path):
    # the edge is seen in the first cycle (0.012 s): the answers are due 0.062 and 0.112 s, so
    # written in the first cycles at or after them, 0.072 (6) and 0.120 (10); the third rule
    # sees both inputs in cycle 10 and answers a cycle later (max(after, dt)), 0.132 (11).
    # Between them no I/O changes: step_rules skips the rules' answers until the earliest one due
    expected = [(0.072, "$IN[2]", True), (0.12, "$IN[3]", True), (0.132, "$IN[4]", True)]
    assert _stepped(tmp_path, "a.yaml", skip=True) == expected
    assert _stepped(tmp_path, "b.yaml", skip=False) == expected
