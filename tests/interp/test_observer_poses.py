"""An observer of the controller that has no use for poses (robot/trace.py ``takes_poses``:
interp/summary.py RunObserver without a trace behind it, the outcome and report observers) is
not handed the per-IPO-cycle pose, so the TCP read back is made only where the run asks for it
(``$POS_ACT``). The run is the same: the program reads the same $POS_ACT, bit for bit, while the
robot moves, as under a trace that takes every pose."""

from __future__ import annotations

import math

import pytest

from interp.run import global_value, make_runtime, run_spec, RunSinks
from interp.summary import RunObserver
from robot.trace import TraceWriter

#: x0: the flange's X at A1 = 0 (read at rest: $POS_ACT stops the advance run); then A1 turns
#: to 40 deg and, with CONTINUE (no advance-run stop), $POS_ACT.Y is read while it starts to turn: 6 000
#: reads, 300 to each element of ys (about one IPO cycle each at the robot program's
#: budget of statements per cycle)
PROGRAM = """DEF poses()
  DECL E6POS p
  DECL INT i
  $BASE = $NULLFRAME
  $TOOL = $NULLFRAME
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 45, A6 0}
  p = $POS_ACT
  x0 = p.X
  PTP {A1 40, A2 -90, A3 90, A4 0, A5 45, A6 0} C_PTP
  FOR i = 0 TO 5999
    CONTINUE
    p = $POS_ACT
    ys[i / 300 + 1] = p.Y
  ENDFOR
  WAIT SEC 0
  p = $POS_ACT
  y_end = p.Y
END
"""
DATA = """DEFDAT poses
  DECL REAL x0
  DECL REAL ys[20]
  DECL REAL y_end
ENDDAT
"""


def _run(tmp_path, trace, observer):
    src = tmp_path / "poses.src"
    src.write_text(PROGRAM)
    (tmp_path / "poses.dat").write_text(DATA)
    rt, _ = make_runtime(run_spec(str(src), mujoco=False, max_sim_time=30.0, interp="vm"),
                         RunSinks(trace=trace, observer=observer))
    res = rt.run()
    return (res, list(rt.controller.io.log), global_value(rt, "poses", "x0"), list(global_value(rt, "poses", "ys").data),
            global_value(rt, "poses", "y_end"))


def test_an_observer_without_poses_gets_none_and_the_run_is_the_same(tmp_path):
    writer = TraceWriter()
    res_a, io_a, x0_a, ys_a, y_end = _run(tmp_path, writer, None)
    observer = RunObserver()
    assert not observer.takes_poses and TraceWriter.takes_poses
    res_b, io_b, x0_b, ys_b, y_end_b = _run(tmp_path, None, observer)
    assert res_a.reason == res_b.reason == "completed"
    assert (res_a.sim_time, res_a.steps, io_a) == (res_b.sim_time, res_b.steps, io_b)
    assert (x0_a, ys_a, y_end) == (x0_b, ys_b, y_end_b)               # every read, bit for bit
    # the reads followed the turn of A1 (KUKA's A1 turns clockwise seen from above: Y < 0): from
    # 0 towards -x0 sin 40 deg (the turn about the base's Z axis), where A1 ends
    assert x0_a > 100.0
    assert y_end == pytest.approx(-x0_a * math.sin(math.radians(40.0)), abs=1e-6)
    assert all(b <= a + 1e-9 for a, b in zip(ys_a, ys_a[1:]))
    assert 1e-9 >= ys_a[0] > ys_a[-1] + 1.0 > y_end + 2.0
    # the trace writer took a pose a cycle; an observer in front of a trace takes them for it
    writer.flush()
    assert sum('"kind":"pose"' in line for line in writer.lines) >= int(res_a.sim_time / 0.012) - 1
    assert RunObserver(inner=writer).takes_poses


class _Fields(RunObserver):
    """A RunObserver that keeps the fields of each motion event it is handed."""

    def __init__(self, inner=None):
        super().__init__(inner=inner)
        self.seen = []

    def write(self, kind, t, **fields):
        if kind == "motion":
            self.seen.append(fields)
        return super().write(kind, t, **fields)


def test_an_observer_without_a_trace_gets_the_motion_events_without_their_end_points(tmp_path):
    """The controller makes a motion event's programmed end point (a forward kinematics), target
    and limits only for an observer that takes them (robot/trace.py ``takes_motion_points``):
    RunObserver alone does not; in front of a trace it does, and the trace has them. The run,
    and what the observer records of the motions, are the same."""
    writer = TraceWriter()
    bare, traced = _Fields(), _Fields(inner=writer)     # the observer in front of the trace (RunSinks)
    assert not bare.takes_motion_points and TraceWriter.takes_motion_points
    a, b = _run(tmp_path, None, bare), _run(tmp_path, writer, traced)
    assert traced.takes_motion_points
    assert a == b
    assert len(bare.seen) == len(traced.seen) >= 4 and bare.motion_types == traced.motion_types == {1: "PTP", 2: "PTP"}
    assert all("point" not in f and "limits" not in f and "target" not in f for f in bare.seen)
    assert [(f["id"], f["phase"], f["line"]) for f in bare.seen] == [(f["id"], f["phase"], f["line"]) for f in traced.seen]
    assert all(len(f["point"]) == 6 for f in traced.seen)
    writer.flush()
    assert sum('"kind":"motion"' in line and '"point"' in line for line in writer.lines) == len(traced.seen)
