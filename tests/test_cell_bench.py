"""tools/cell_bench.py's instruction count (issue 89: a moving cell "as fast per robot as one robot
alone"): the cost of a simulated second is the difference of two runs' counts over their extra
simulated seconds, the ratio the four programs alone over the cell; the child process it counts
runs the run phase inside ``eval`` (callgrind's ``--toggle-collect=builtin_eval*``). No timing and
no count is asserted (a benchmark prints ratios; it is not tested by time), and valgrind is not
run here: its counting is replaced by given counts."""

from __future__ import annotations

import fcntl
import importlib.util
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
_spec = importlib.util.spec_from_file_location("cell_bench", REPO / "tools" / "cell_bench.py")
cell_bench = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cell_bench)


def test_the_marginal_cost_and_the_ratio_from_two_durations(monkeypatch, tmp_path):
    # the cell: 1,000 M at 5 s, 3,000 M at 15 s -> 200 M a second (its fixed 0 M); the four alone:
    # 700 M and 2,500 M -> 180 M a second (fixed 250 M, which cancels): 180 / 200 = 0.9
    counts = {("cell", 5.0): 1_000_000_000, ("cell", 15.0): 3_000_000_000,
              ("alone", 5.0): 700_000_000, ("alone", 15.0): 2_500_000_000}
    seen = []

    def count(kind, paths, interp, t, out):
        seen.append((kind, [p.name for p in paths], interp, t))
        return counts[kind, t]
    monkeypatch.setattr(cell_bench, "_count", count)
    move4 = tmp_path / "move4" / "move4.yaml"
    (line,) = cell_bench._instructions(move4, "vm", (5.0, 15.0), tmp_path, 2)
    assert "the cell: 200.000 M instructions a simulated second (50.000 M a robot" in line
    assert "the four alone 180.000 M" in line and "per robot / alone 0.9000" in line
    # the cell once, its four programs together in one process, each at both durations
    assert sorted(seen) == sorted([("cell", ["move4.yaml"], "vm", t) for t in (5.0, 15.0)]
                                  + [("alone", ["r1.src", "r2.src", "r3.src", "r4.src"], "vm", t)
                                     for t in (5.0, 15.0)])


def test_callgrind_totals_read_from_its_file():
    text = "events: Ir\nfn=(1) main\n5 17\nsummary: 123456\n\n\ntotals: 123456\n"
    assert int(cell_bench._TOTALS.search(text)[1]) == 123456


def test_the_child_runs_the_run_phase_inside_eval(monkeypatch, tmp_path, capsys):
    # the programs alone, 0.5 s simulated each: the run phase called through eval (what callgrind's
    # toggle counts), ending at the time limit as krl run would
    prog = tmp_path / "r1.src"
    prog.write_text(cell_bench.MOVE.format(k=1, a=25), encoding="utf-8")
    calls = []
    real_eval = eval

    def spy(text, env):
        calls.append(text)
        return real_eval(text, env)
    monkeypatch.setattr(cell_bench, "eval", spy, raising=False)
    assert cell_bench.main(["--_child", "alone", "--moving-time", "0.5", str(prog)]) == 0
    out = capsys.readouterr().out
    assert calls == ["rt.run()"]
    assert out.rstrip().endswith("s CPU the run phase, 0.504 s simulated, max_sim_time"), out


def test_the_counted_cells_lie_in_one_folder_held_by_one_bench(monkeypatch, tmp_path):
    """``--instructions`` writes its cells to one path each time (the path's hash moves a count),
    emptied before and after, and held: while one bench counts, another's lock on it would wait."""
    folder = tmp_path / "reports" / "cell-bench-count"
    monkeypatch.setattr(cell_bench, "COUNT_FOLDER", folder)
    for _ in range(2):
        with cell_bench._count_folder() as got:
            assert got == folder and list(got.iterdir()) == []
            (got / "left.txt").write_text("x")
            with open(folder.parent / "cell-bench-count.lock", "w") as other:
                with pytest.raises(BlockingIOError):
                    fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)
        assert not folder.exists()
