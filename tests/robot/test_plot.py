"""`krl plot`: the PNG of a trace, and the benchmark's sanity run."""

from __future__ import annotations

import json
import struct

from robot.bench import run_bench
from robot.plot import _collect, plot_trace


def test_plot_trace_writes_png(tmp_path):
    trace = tmp_path / "t.jsonl"
    r = run_bench(min_motion_s=3.0, trace_path=str(trace))
    assert r["sim_s"] >= 3.0 and r["sim_realtime_factor"] > 0
    png = plot_trace(trace, tmp_path / "t.png")
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


def test_plot_draws_the_external_axes_over_time(tmp_path):
    """A robot with E1 (the trace's robot event names the pose axes): a third panel, E1 over
    time; the PNG is 3 panels wide (6.5 in each at 110 dpi) instead of 2."""
    events = [{"t": 0.0, "kind": "robot", "name": "r", "source": "s", "axes": ["A1", "A2", "A3", "A4", "A5", "A6", "E1"]}]
    events += [{"t": 0.012 * i, "kind": "pose", "axes": [i, -90, 90, 0, 30, 0, 10.0 * i], "tcp": [1000 + i, 0, 1500, 0, 90, 0]}
               for i in range(20)]
    trace = tmp_path / "e.jsonl"
    trace.write_text("".join(json.dumps(e) + "\n" for e in events), encoding="utf-8")
    data = _collect(events)
    assert data["ext_names"] == ["E1"] and [e[0] for e in data["ext"]] == [10.0 * i for i in range(20)]
    width = struct.unpack(">I", plot_trace(trace, tmp_path / "e.png").read_bytes()[16:20])[0]
    assert width == round(6.5 * 3 * 110)
    events[0]["axes"] = None
    trace.write_text("".join(json.dumps(e) + "\n" for e in events), encoding="utf-8")
    assert struct.unpack(">I", plot_trace(trace, tmp_path / "f.png").read_bytes()[16:20])[0] == round(6.5 * 2 * 110)
