"""A robot on a track and a turntable, built from KUKA's documentation (robot/data/kr16_2_kl1500.dat,
kr16_2_turntable.dat: no public backup has either), moving their TCP in the world as an independent
computation predicts at 10 points each (issue 64), on the tree interpreter and the VM.

The prediction is computed here with plain numpy: the KR 16-2's flange from its URDF joint origins
(ros-industrial kuka_experimental kuka_kr16_support/urdf/kr16_2_macro.xacro: A1 675 mm up, A2 260
ahead, A3 680 on, A4 670 ahead and 35 below, flange 158 on; axes -Z, Y, Y, -X, Y, -X; tool0 turned
90 deg about Y), the track's carriage from the KL unit's frames (450 mm up, its Z along the world's
X: the robot's base at (E1, 0, 450)), the table's plate from its frames (its axis at X 1500, Z 400,
turning about Z by E1) with the root and offset KSS's EK links $BASE with. Each motion's end pose
of the trace (the axes read back) gives the world TCP through that chain; it must be the point the
program asked for (the track: in $WORLD; the turntable: in the turning base), to 0.01 mm.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from interp.run import make_runtime, run_spec, RunSinks
from robot.trace import TraceWriter
from tests.interp.helpers import Run, write

_JOINTS = [((0, 0, 675), (0, 0, -1)), ((260, 0, 0), (0, 1, 0)), ((680, 0, 0), (0, 1, 0)),
           ((670, 0, -35), (-1, 0, 0)), ((0, 0, 0), (0, 1, 0)), ((158, 0, 0), (-1, 0, 0))]


def _rot(axis, deg) -> np.ndarray:
    x, y, z = (float(v) for v in axis)
    c, s, C = math.cos(math.radians(deg)), math.sin(math.radians(deg)), 1 - math.cos(math.radians(deg))
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


def _T(R=None, p=(0, 0, 0)) -> np.ndarray:
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = p
    return T


def flange(axes) -> np.ndarray:
    T = np.eye(4)
    for (origin, axis), a in zip(_JOINTS, axes):
        T = T @ _T(p=origin) @ _T(_rot(axis, a))
    return T @ _T(_rot((0, 1, 0), 90))


def kuka(x, y, z, a, b, c) -> np.ndarray:
    """KUKA's frame: Trans(X, Y, Z) Rz(A) Ry(B) Rx(C)."""
    return _T(_rot((0, 0, 1), a) @ _rot((0, 1, 0), b) @ _rot((1, 0, 0), c), (x, y, z))


def _run(tmp_path, src, robot, interp):
    prog = write(tmp_path, "prog.src", src)
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, max_sim_time=120.0, mujoco=False, check=False, interp=interp,
                                  robot=robot), RunSinks(trace=tw))
    return Run(rt, rt.run(), tw)


def _end_axes(run):
    """The axes at each motion's end (the pose event of the cycle of its end event)."""
    poses = {e["t"]: e["axes"] for e in run.events if e["kind"] == "pose"}
    return [poses[e["t"]] for e in run.events if e["kind"] == "motion" and e["phase"] == "end"]


TRACK_POINTS = [(e, 900 + e + dx, y, z) for e, dx, y, z in
                [(0, 0, 0, 900), (400, 100, 200, 800), (800, -100, -300, 1000), (1200, 200, 100, 700),
                 (1600, 0, 0, 1100), (2000, -200, 250, 900), (2400, 150, -150, 850), (2800, 0, 300, 950),
                 (3200, 100, 0, 750), (3600, -100, -200, 1000)]]


#: make test runs the VM; the tree interpreter's run (the same trace: the conformance suites hold the
#: two identical) is in make nightly, its CPU (about 3 s quiet) beyond make test's budget
INTERPS = ["vm", pytest.param("tree", marks=pytest.mark.slow)]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_robot_on_a_track_puts_its_tcp_where_the_world_says(tmp_path, interp):
    lines = ["DEF prog()", "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 60, A6 0, E1 0}"]
    for i, (e, x, y, z) in enumerate(TRACK_POINTS):
        kw = "PTP" if i % 2 == 0 else "LIN"
        lines.append(f"  {kw} {{X {x}, Y {y}, Z {z}, A 180, B 0, C 180, E1 {e}}}")
    run = _run(tmp_path, "\n".join(lines + ["END", ""]), "kr16_2_kl1500", interp)
    assert run.result.reason == "completed", run.result
    ends = _end_axes(run)[1:]
    assert len(ends) == 10
    for (e, x, y, z), q in zip(TRACK_POINTS, ends):
        assert q[6] == pytest.approx(e, abs=1e-6)
        world = _T(p=(q[6], 0, 450)) @ flange(q[:6])          # the carriage carries the base along X
        np.testing.assert_allclose(world, kuka(x, y, z, 180, 0, 180), atol=1e-2)


#: the EK root (MACHINE_DEF[2].ROOT) and the base measured on the plate (BASE_DATA[1])
ROOT = (-60.0, 40.0, 0.0, -5.0, 0.0, 0.0)
OFFSET = (-200.0, 0.0, 30.0, 0.0, 0.0, 0.0)
TABLE_POINTS = [(e, x, y, z) for e, x, y, z in
                [(0, 0, 0, 150), (20, 50, 40, 200), (40, -60, 20, 180), (60, 0, -80, 220), (80, 80, 0, 160),
                 (-20, -40, -40, 240), (-40, 20, 60, 190), (-60, 0, 0, 260), (-80, -80, 30, 170), (10, 60, -60, 210)]]


@pytest.mark.parametrize("interp", INTERPS)
def test_a_turntable_turns_the_base_the_tcp_follows(tmp_path, interp):
    r, o = ROOT, OFFSET
    lines = ["DEF prog()", "  DECL FRAME root, offs",
             f"  root = {{X {r[0]}, Y {r[1]}, Z {r[2]}, A {r[3]}, B {r[4]}, C {r[5]}}}",
             f"  offs = {{X {o[0]}, Y {o[1]}, Z {o[2]}, A {o[3]}, B {o[4]}, C {o[5]}}}",
             "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 60, A6 0, E1 0}",
             "  $BASE = EK(root, #EASYS, offs)"]
    for i, (e, x, y, z) in enumerate(TABLE_POINTS):
        kw = "PTP" if i % 2 == 0 else "LIN"
        lines.append(f"  {kw} {{X {x}, Y {y}, Z {z}, A 0, B 90, C 0, E1 {e}}}")
    run = _run(tmp_path, "\n".join(lines + ["END", ""]), "kr16_2_turntable", interp)
    assert run.result.reason == "completed", run.result
    ends = _end_axes(run)[1:]
    assert len(ends) == 10
    for (e, x, y, z), q in zip(TABLE_POINTS, ends):
        assert q[6] == pytest.approx(e, abs=1e-6)
        plate = kuka(*ROOT) @ _T(p=(1500, 0, 400)) @ _T(_rot((0, 0, 1), q[6]))   # the table's axis turned by E1
        expected = plate @ kuka(*OFFSET) @ kuka(x, y, z, 0, 90, 0)
        np.testing.assert_allclose(flange(q[:6]), expected, atol=1e-2)
