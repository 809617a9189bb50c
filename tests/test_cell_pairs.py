"""tools/cell_pairs.py (issue 89): each entry point of a corpus as two robots of one cell against its
run alone. On a corpus of one backup written here (its SPS.SUB beside a program whose waits the
automatic cell answers: tests/interp/test_cell_auto.py), every robot's I/O log and end are its run
alone's, and with the automatic cell answering a blocked robot's wait at once (the behaviour before
2026-11-30) the tool finds the robot program's answers a window early and exits 1. No timing is
asserted (``--speed`` is a benchmark's figure)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from interp.runtime.autocell import AutoCell
from interp.runtime.idle import WINDOW_CYCLES

from .interp.test_cell_auto import BACKUP_PROG, QUIET_SPS

REPO = Path(__file__).resolve().parent.parent
_spec = importlib.util.spec_from_file_location("cell_pairs", REPO / "tools" / "cell_pairs.py")
cell_pairs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cell_pairs)

pytestmark = [pytest.mark.xdist_group("cell-pairs")]


def _corpus(tmp_path: Path) -> Path:
    corpus = tmp_path / "corpus"
    for part, text in (("R1/Program/prog.src", BACKUP_PROG), ("R1/System/$config.dat", "DEFDAT $CONFIG\nENDDAT\n"),
                       ("R1/System/sps.sub", QUIET_SPS)):
        (corpus / "bk" / part).parent.mkdir(parents=True, exist_ok=True)
        (corpus / "bk" / part).write_text(text, encoding="utf-8")
    return corpus


def test_each_robot_of_the_pair_runs_as_alone(tmp_path, capsys):
    out = tmp_path / "pairs.json"
    assert cell_pairs.main(["--corpus", str(_corpus(tmp_path)), "--sim-time", "10", "--json", str(out)]) == 0
    rows = json.loads(out.read_text())
    assert sorted(rows) == ["bk/R1/Program/prog.src", "bk/R1/System/sps.sub"]
    prog = rows["bk/R1/Program/prog.src"]
    assert prog["same"] == [True, True] and prog["cell"] == "completed" and prog["alone"][0] == "completed"
    assert prog["io"] == 4          # $IN[20], $IN[21], $IN[22] by the automatic cell, $OUT[12] by the program
    assert rows["bk/R1/System/sps.sub"]["same"] == [True, True]
    assert "2 of 2 entry points" in capsys.readouterr().out


def test_a_cell_answering_a_blocked_wait_at_once_is_found(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(AutoCell, "would_answer", lambda self, robot: False)
    out = tmp_path / "pairs.json"
    assert cell_pairs.main(["--corpus", str(_corpus(tmp_path)), "--sim-time", "10", "--only", "prog",
                            "--json", str(out)]) == 1
    row = json.loads(out.read_text())["bk/R1/Program/prog.src"]
    assert row["same"] == [False, False]
    alone, cell = row["first"]
    # the first answer: alone a window of idle cycles later than in the cell
    assert alone[1:] == cell[1:] == ["$IN[20]", True, "auto"]
    assert alone[0] - cell[0] == pytest.approx(WINDOW_CYCLES * 0.012, abs=1e-6)
    assert "DIFFERS" in capsys.readouterr().out


def test_the_pooled_figure_leaves_out_an_entry_whose_steady_cost_is_not_positive():
    """``pooled``: the steady costs summed over the entry points timed, but for one whose cost did
    not grow from T1 to T2 (cell or alone: no ratio), which is counted as left out; rows without a
    ``speed`` (not run to the limit, failed) are not timed at all."""
    rows = {"a": {"speed": {"cell": 2.0, "alone": 1.8}}, "b": {"speed": {"cell": 1.0, "alone": 0.9}},
            "c": {"speed": {"cell": -0.001, "alone": 0.002}}, "d": {"speed": {"cell": 0.5, "alone": 0.0}},
            "e": {"same": [True, True]}, "f": {"error": "RuntimeError: x"}}
    assert cell_pairs.pooled(rows) == (3.0, pytest.approx(2.7), 2, 2)
    assert cell_pairs.pooled({}) == (0, 0, 0, 0)
