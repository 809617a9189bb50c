"""Issue 74, case 11: a trace says how its run ended, and a cut last line costs only that line.

A run stopped by a signal ends its trace with ``end`` reason ``interrupted``
(tests/faults/test_signals_and_exit_codes.py); a trace without any ``end`` event (a run killed
by SIGKILL, a trace cut by a full disk) is shown by ``krl trace show`` and the plots as
"incomplete"; a last line cut mid-way is dropped with a warning naming it, and every whole line
before it is read (before, the whole file was refused).
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib.figure
import pytest
from click.testing import CliRunner

from app import main
from robot.kukatrace.model import load_run
from robot.trace import INCOMPLETE, how_it_ended, read_trace

ROBOT = {"t": 0.0, "kind": "robot", "name": "KR 6 R900", "source": "catalogue"}
POSE = {"t": 0.012, "kind": "pose", "axes": [0, -90, 90, 0, 0, 0], "tcp": [500.0, 0.0, 800.0, 0.0, 90.0, 0.0]}
END_INT = {"t": 0.024, "kind": "end", "reason": "interrupted", "text": "SIGTERM"}


def _trace(path: Path, events: list[dict], tail: str = "") -> Path:
    path.write_text("".join(json.dumps(e) + "\n" for e in events) + tail, encoding="utf-8")
    return path


def test_a_cut_last_line_is_dropped_with_a_warning_and_the_rest_is_read(tmp_path: Path) -> None:
    t = _trace(tmp_path / "t.jsonl", [ROBOT, POSE], tail='{"t":0.024,"kind":"po')
    warnings: list[str] = []
    events = list(read_trace(t, warnings.append))
    assert [e["kind"] for e in events] == ["robot", "pose"]
    assert warnings == [f"{t}:3: warning: the last line is cut short (a full disk, or the run was killed "
                        "while writing it): dropped"]


def test_a_bad_line_that_is_not_the_last_is_still_an_error(tmp_path: Path) -> None:
    t = _trace(tmp_path / "t.jsonl", [ROBOT], tail='{"t":0.0,"kind":"po\n' + json.dumps(POSE) + "\n")
    with pytest.raises(ValueError, match=r"t\.jsonl:2: not a trace event"):
        list(read_trace(t, lambda w: None))


def test_how_a_trace_ended() -> None:
    assert how_it_ended([ROBOT, POSE]) == INCOMPLETE
    assert how_it_ended([ROBOT, POSE, END_INT]) == "interrupted (SIGTERM)"
    assert how_it_ended([ROBOT, {"t": 1.0, "kind": "end", "reason": "completed"}]) == "completed"


def test_krl_trace_show_says_a_killed_runs_trace_is_incomplete(tmp_path: Path) -> None:
    t = _trace(tmp_path / "t.jsonl", [ROBOT, POSE], tail='{"t":0.024,"ki')
    res = CliRunner().invoke(main, ["trace", "show", str(t)])
    assert res.exit_code == 0, res.output
    assert "ended     incomplete (no end event" in res.stdout
    assert "the last line is cut short" in res.stderr
    js = CliRunner().invoke(main, ["trace", "show", "--json", str(t)])
    assert json.loads(js.stdout)["ended"].startswith("incomplete")


def test_krl_trace_show_and_the_view_say_an_interrupted_run(tmp_path: Path) -> None:
    t = _trace(tmp_path / "t.jsonl", [ROBOT, POSE, END_INT])
    assert load_run(t).ended == "interrupted (SIGTERM)"
    res = CliRunner().invoke(main, ["trace", "show", str(t)])
    assert "ended     interrupted (SIGTERM)" in res.stdout


def test_the_plot_of_an_incomplete_trace_says_so(tmp_path: Path, monkeypatch) -> None:
    titles: list[str] = []
    real = matplotlib.figure.Figure.suptitle
    monkeypatch.setattr(matplotlib.figure.Figure, "suptitle",
                        lambda self, text, **kw: (titles.append(text), real(self, text, **kw))[1])
    t = _trace(tmp_path / "t.jsonl", [ROBOT, POSE, dict(POSE, t=0.024)])
    res = CliRunner().invoke(main, ["plot", str(t), "-o", str(tmp_path / "t.png")])
    assert res.exit_code == 0, res.output
    assert titles == [f"t.jsonl: {INCOMPLETE}"]
