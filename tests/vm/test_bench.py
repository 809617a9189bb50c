"""`krl bench` smoke test: it runs and prints the JSON keys (no timing assertions)."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

import interp.bench
from interp.bench import compute, run_krl, run_python
from interp.vm.vm import COMPILED
import app.bench
from app.bench import all_figures, bench

KEYS = {"vm_vs_tree", "tree_stmts_per_s", "vm_stmts_per_s", "sim_realtime_factor", "sim_cpu_factor", "parse_kb_per_s"}


@pytest.fixture(scope="module")
def one_round():
    """One real round of the compute benchmark (interp.bench ``compute(1)``: tree, VM and Python,
    their results compared), measured once for the module, and what each of its runs gave:
    ``(figures, runs)``, ``runs`` the (kind, steps, result) of each run of the round. The
    commands' tests print its figures (each test ran its own round, and the test of the results
    one more: 1.3-1.7 s of CPU each, 2026-11-29)."""
    runs = []

    def krl_run(kind, *args, **kwargs):
        dt, steps, result = run_krl(kind, *args, **kwargs)
        runs.append((kind, steps, result))
        return dt, steps, result

    def python_run(*args, **kwargs):
        dt, result = run_python(*args, **kwargs)
        runs.append(("python", None, result))
        return dt, result

    with pytest.MonkeyPatch.context() as mp:      # interp.bench's runs, as its compute calls them
        mp.setattr(interp.bench, "run_krl", krl_run)
        mp.setattr(interp.bench, "run_python", python_run)
        figures = compute(1)
    return figures, runs


def test_benchmark_gives_the_same_result_everywhere(one_round):
    figures, runs = one_round
    assert [kind for kind, _, _ in runs] == ["tree", "vm", "python"]
    (_, steps_t, tree), (_, steps_v, vm), (_, _, py) = runs
    assert tree == vm == py
    assert steps_t == steps_v == figures["steps"] > 0


@pytest.fixture
def computed(monkeypatch, one_round):
    """``app.bench.compute`` answers :func:`one_round`'s real figures (wall-clock times, no
    baseline); the repeat counts asked."""
    asked = []

    def compute_once(repeat, baseline=None, cpu=False):
        assert baseline is None and not cpu, (baseline, cpu)
        asked.append(repeat)
        return one_round[0]

    monkeypatch.setattr(app.bench, "compute", compute_once)   # interp.bench.compute, as app.bench calls it
    return asked


def test_bench_json_line(computed):
    res = CliRunner().invoke(bench, ["--json", "--repeat", "1", "--sim-seconds", "1", "--parse-kb", "20"])
    assert res.exit_code == 0, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1
    data = json.loads(lines[0])
    assert KEYS <= set(data)
    assert all(isinstance(data[k], (int, float)) and data[k] > 0 for k in KEYS)
    # make (pip install -e) builds the Cython loop: the benchmark must have run it
    assert data["vm_loop"] == ("compiled" if COMPILED else "python") == "compiled"
    assert computed == [1]


def test_bench_json_gives_the_simulator_figure_of_robot_bench(monkeypatch):
    """One figure per measure (issue 48): `krl bench --json` reports the simulator as
    ``python -m robot.bench`` measures it, warm, by the same function."""
    seen = {}

    def measure(min_motion_s=60.0, robot=None, warm_up=True):
        seen.update(min_motion_s=min_motion_s, warm_up=warm_up)
        return {"sim_realtime_factor": 123.0, "sim_cpu_factor": 456.0}

    def compute(repeat):
        # the compute benchmark, not this test's subject (its figures: test_bench_json_line; 1.3 s
        # of CPU less, 2026-11-29)
        seen.update(repeat=repeat)
        return {"vm_vs_tree": 20.0, "vm_loop": "compiled", "tree_stmts_per_s": 5e4, "vm_stmts_per_s": 1e6,
                "python_stmts_per_s": 2e7}

    monkeypatch.setattr(app.bench, "measure", measure)   # robot.bench.measure, as app.bench calls it
    monkeypatch.setattr(app.bench, "compute", compute)   # interp.bench.compute, as app.bench calls it
    got = all_figures(repeat=1, sim_seconds=2.0, parse_kb=4)
    assert (got["sim_realtime_factor"], got["sim_cpu_factor"]) == (123.0, 456.0)
    assert seen == {"min_motion_s": 2.0, "warm_up": True, "repeat": 1}


def test_bench_text(computed, one_round):
    res = CliRunner().invoke(bench, ["--repeat", "2"])
    assert res.exit_code == 0, res.output
    assert "VM" in res.output and "Python" in res.output
    assert "compiled loop" in res.output
    assert f"{one_round[0]['steps']} statements and loop iterations, best of 2" in res.output
    assert computed == [2]
