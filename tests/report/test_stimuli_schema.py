"""Stimuli files are validated against their schema (robot/stimuli.py, issue 12); SIGNAL names work."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from robot.stimuli import StimulusError, load_stimuli, parse_stimuli, resolve_signals


def write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "stim.yaml"
    p.write_text(textwrap.dedent(text).lstrip("\n"), encoding="utf-8")
    return p


def error_of(path: Path) -> str:
    with pytest.raises(StimulusError) as info:
        load_stimuli(path)
    return str(info.value)


def test_mapping_without_stimuli_is_an_error_naming_the_key(tmp_path):
    # Before: this gave zero inputs and exit 0 (the interrupt never fired).
    p = write(tmp_path, """
        stimulus:
          - at: 0.5
            set: {"$IN[1]": true}
        """)
    msg = error_of(p)
    assert msg.startswith(f"{p}:1: unknown top-level key 'stimulus'")


def test_unknown_field_of_a_stimulus_names_field_and_line(tmp_path):
    p = write(tmp_path, """
        stimuli:
          - at: 0.5
            set: {"$IN[1]": true}
          - at: 0.7
            sett: {"$IN[2]": true}
        """)
    assert error_of(p).startswith(f"{p}:5: unknown field of stimulus 2: 'sett'")


def test_unknown_field_of_when(tmp_path):
    p = write(tmp_path, """
        stimuli:
          - when: {motion: 2, phse: start}
            set: {"$IN[1]": true}
        """)
    assert error_of(p).startswith(f"{p}:2: unknown field of 'when': 'phse'")


def test_wrong_types_and_outputs(tmp_path):
    assert "at must be a number" in error_of(write(tmp_path, "- at: soon\n  set: {'$IN[1]': true}\n"))
    assert "only $IN/$ANIN" in error_of(write(tmp_path, "- at: 1\n  set: {'$OUT[1]': true}\n"))
    assert ":3: not valid YAML" in error_of(write(tmp_path, "- at: 1\n  set: {'$IN[1]': true\n"))
    assert "needs 'at' or 'when'" in error_of(write(tmp_path, "- set: {'$IN[1]': true}\n"))


def test_valid_file_still_loads(tmp_path):
    p = write(tmp_path, """
        stimuli:
          - at: 0.3
            set: {"$in[ 3 ]": true, "$ANIN[1]": 0.5}
          - when: {line: 12, reached: 2.0}
            set: {"$IN[5]": true}
            delay: 0.1
        """)
    a, b = load_stimuli(p)
    assert a.at == 0.3 and a.set == {"$IN[3]": True, "$ANIN[1]": 0.5}
    assert b.line == 12 and b.reached_mm == 2.0 and b.delay == 0.1 and b.phase is None


def test_signal_names_resolve_to_inputs():
    stim = parse_stimuli([{"at": 0.1, "set": {"part_ok": True}}, {"at": 0.2, "set": {"CODE": 5}}],
                         source="s.yaml")
    table = {"PART_OK": ("$IN", 3, None), "CODE": ("$IN", 10, 13), "LAMP": ("$OUT", 2, None)}
    resolve_signals(stim, table.get)
    assert stim[0].set == {"$IN[3]": True}
    # 5 = 0b0101: bit 0 on $IN[10]
    assert stim[1].set == {"$IN[10]": True, "$IN[11]": False, "$IN[12]": True, "$IN[13]": False}
    with pytest.raises(StimulusError, match="unknown signal NOPE"):
        resolve_signals(parse_stimuli([{"at": 0, "set": {"NOPE": True}}]), table.get)
    with pytest.raises(StimulusError, match="LAMP is a SIGNAL on \\$OUT"):
        resolve_signals(parse_stimuli([{"at": 0, "set": {"LAMP": True}}]), table.get)
    with pytest.raises(StimulusError, match="0..15"):
        resolve_signals(parse_stimuli([{"at": 0, "set": {"CODE": 16}}]), table.get)


def test_a_signal_is_read_by_the_front_end(tmp_path):
    """`$IN[n]` in a stimulus is a KRL expression read by krl/semantics/expression.py: any case
    and spacing; a malformed or out-of-range index is an error naming the line."""
    p = write(tmp_path, "- at: 1\n  set: {'$in[ 3 ]': true}\n")
    [st] = load_stimuli(p)
    assert st.set == {"$IN[3]": True}
    for bad in ("$IN[3", "$IN[-3]", "$IN[1,2]", "$IN[8193]", "$IN[X]"):
        msg = error_of(write(tmp_path, f"- at: 1\n  set: {{'{bad}': true}}\n"))
        assert msg.startswith(f"{tmp_path / 'stim.yaml'}:2: not a signal: {bad!r}"), msg
