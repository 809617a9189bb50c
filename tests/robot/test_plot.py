"""`krl plot`: the PNG of a trace, and the benchmark's sanity run."""

from __future__ import annotations

from robot.bench import run_bench
from robot.plot import plot_trace


def test_plot_trace_writes_png(tmp_path):
    trace = tmp_path / "t.jsonl"
    r = run_bench(min_motion_s=3.0, trace_path=str(trace))
    assert r["sim_s"] >= 3.0 and r["sim_realtime_factor"] > 0
    png = plot_trace(trace, tmp_path / "t.png")
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
