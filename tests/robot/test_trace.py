"""The JSON Lines trace: schema, rounding, determinism (issue 5, "Trace")."""

from __future__ import annotations

import json

import numpy as np
import pytest

from robot.bench import bench_program, run_motions
from robot.controller import Controller
from robot.frames import frame_to_matrix, matrix_to_frame
from robot.motion import MotionParams, MotionRequest, Trigger
from robot.stimuli import parse_stimuli
from robot.trace import KINDS, SCHEMA, TraceWriter, _frames_of, make_event, read_trace, validate_event
import json as _json
from robot.trace import load_event


def test_schema_has_the_issue_kinds():
    for k in ("motion", "io", "pose", "message", "error", "end", "stmt", "call", "return",
              "interrupt"):
        assert k in KINDS
    assert [f for f, _ in SCHEMA["motion"]][:5] == ["id", "type", "target", "approximation", "phase"]


def test_make_event_checks_fields_and_rounds():
    ev = make_event("io", 1.0000004, signal="$OUT[1]", value=True)
    assert ev == {"t": 1.0, "kind": "io", "signal": "$OUT[1]", "value": True}
    assert make_event("end", -0.0000001, reason="x")["t"] == 0.0
    with pytest.raises(ValueError):
        make_event("nope", 0.0)
    with pytest.raises(ValueError):
        make_event("io", 0.0, signal="$OUT[1]")
    with pytest.raises(ValueError):
        make_event("end", 0.0, reason="x", extra=1)
    ev = make_event("pose", 0.012, axes=[-0.0, 1e-9, 1.23456789, 0, 0, 0], tcp=[0.0] * 6)
    assert ev["axes"][:3] == [0.0, 0.0, 1.234568]


def _program_trace(path=None):
    tw = TraceWriter(path) if path else TraceWriter()
    stim = parse_stimuli([{"at": 0.5, "set": {"$IN[2]": True}}])
    ctl = Controller(trace=tw, stimuli=stim)
    reqs = bench_program(ctl.machine)[:5]
    reqs[1].triggers = (Trigger(distance=0, delay_ms=20),)
    for ev in run_motions(ctl, reqs):
        if ev.kind == "trigger":
            ctl.io.set_out(5, True, "trigger")
    ctl.log.finish()
    tw.close()
    return tw


def test_deterministic_bit_for_bit(tmp_path):
    a = _program_trace().text()
    b = _program_trace().text()
    assert a == b
    _program_trace(tmp_path / "t.jsonl")
    assert (tmp_path / "t.jsonl").read_text() == a


def test_trace_events_valid_and_ordered(tmp_path):
    p = tmp_path / "t.jsonl"
    _program_trace(p)
    events = list(read_trace(p))
    kinds = {e["kind"] for e in events}
    assert {"motion", "pose", "io", "trigger", "end"} <= kinds
    for e in events:
        validate_event(e)
    ts = [e["t"] for e in events]
    assert ts == sorted(ts)
    assert events[-1]["kind"] == "end" and events[-1]["reason"] == "program_end"
    # one pose per IPO cycle
    poses = [e["t"] for e in events if e["kind"] == "pose"]
    assert all(abs((b - a) - 0.012) < 1e-9 for a, b in zip(poses, poses[1:]))
    # times are rounded to the µs
    for line in p.read_text().splitlines():
        t = json.loads(line)["t"]
        assert round(t, 6) == t


def test_interpreter_events_through_same_writer():
    tw = TraceWriter(keep=True)
    ctl = Controller(trace=tw, mujoco=False)
    tw.write("stmt", ctl.time, file="a.src", line=3)
    ctl.queue.enqueue(MotionRequest("PTP", {"A1": 0, "A2": -90, "A3": 90, "A4": 0, "A5": 0, "A6": 0},
                              MotionParams(), line=3, file="a.src"))
    for _ in range(4):
        ctl.step()
    tw.write("call", ctl.time, name="FOO")
    kinds = [e["kind"] for e in tw.events]
    # a zero-length PTP starts and reaches its end point in the same IPO cycle; its END (an
    # exact stop's) comes 3 cycles later (robot/exactstop.py)
    assert kinds == ["stmt", "motion", "pose", "pose", "pose", "motion", "pose", "call"]


def test_frames_of_poses_in_gimbal_lock_are_matrix_to_frame_each():
    # a robot at rest at HOME (B = 90: gimbal lock) repeats its matrix; the conversion keeps
    # its last answer, which must be the one of each matrix (also when another comes between)
    Ts = [frame_to_matrix(500.0, 0.0, 900.0, 30.0, 90.0, 0.0),
          frame_to_matrix(500.0, 0.0, 900.0, -40.0, -90.0, 0.0),
          frame_to_matrix(100.0, 2.0, 3.0, 10.0, 20.0, 30.0)]
    seq = [Ts[0], Ts[0], Ts[1], Ts[0], Ts[2], Ts[1], Ts[1]]
    for _ in range(2):
        assert _frames_of(seq) == [list(matrix_to_frame(T)) for T in seq]
    assert all(isinstance(v, float) for fr in _frames_of(seq) for v in fr) and np.isfinite(_frames_of(seq)).all()


def test_a_trace_line_reads_as_the_json_module_reads_it():
    """robot.trace.load_event (orjson, else the json module): the same data for every line a
    trace holds, those orjson refuses or reads otherwise included (NaN, Infinity, a lone surrogate
    escape, an integer past 64 bits, nested too), and ValueError for a line that is no JSON."""

    tw = TraceWriter(keep=True)
    tw.write("io", 0.012, signal="$OUT[3]", value=True, source="program")
    tw.write("message", 0.5, text="Ä ü \\u00e9 \u2028 done", number=None)
    lines = [ln for ln in tw.lines if ln.strip()]
    lines += ['{"t":1.5e-07,"kind":"x","v":NaN,"w":-Infinity}', '{"t":0,"kind":"x","n":123456789012345678901234}',
              '{"t":0,"kind":"x","s":"\\ud800"}',
              '{"t":0,"kind":"x","big":[1e+20,{"w":-9223372036854775809}],"u64":18446744073709551615}', '{"t":0.1,"kind":"pose","axes":[0.0,-90.0,1e+16,-0.0]}']
    for line in lines:
        got, want = load_event(line), _json.loads(line)
        assert _json.dumps(got, sort_keys=True) == _json.dumps(want, sort_keys=True), line
    with pytest.raises(ValueError):
        load_event('{"t": 0, "kind": ')


def test_the_cached_text_of_plain_events_is_the_uncached_text():
    """TraceWriter.write keeps the text after the time of an event whose fields are strings and
    integers (issue 86: a busy run's stmt/call/return events were validated and serialised one
    by one); the lines must be json.dumps of make_event, the uncached path, byte for byte: the
    same event at other times (0 and -0.0 written 0.0, an INT time as a REAL), an io event's
    TRUE after an INT 1 (True == 1 in Python), a line given as a REAL."""
    calls = [("stmt", 0.012, dict(file="a.src", line=3, context="main")),
             ("stmt", 0.024, dict(file="a.src", line=3, context="main")),
             ("stmt", -0.0, dict(file="a.src", line=3, context="main")),
             ("stmt", 2, dict(file="a.src", line=3, context="main")),
             ("stmt", 0.036, dict(file="a.src", line=3.0, context="main")),
             ("call", 0.048, dict(name="PICK", line=None)),
             ("call", 0.06, dict(name="PICK", line=None)),
             ("io", 0.072, dict(signal="$OUT[41]", value=1, source="program")),
             ("io", 0.084, dict(signal="$OUT[41]", value=True, source="program")),
             ("io", 0.096, dict(signal="$OUT[41]", value=1, source="program")),
             ("stmt", 0.108, dict(file="ü\u2028.src", line=4))]
    tw = TraceWriter()
    got = [tw.write(kind, t, **f) for kind, t, f in calls]
    want = [make_event(kind, t, **f) for kind, t, f in calls]
    assert got == want
    assert tw.lines == [json.dumps(ev, separators=(",", ":"), ensure_ascii=True) for ev in want]
    assert tw.lines[2].startswith('{"t":0.0,') and tw.lines[3].startswith('{"t":2.0,')
    assert '"line":3.0' in tw.lines[4] and '"value":true' in tw.lines[8] and '"value":1' in tw.lines[9]
