"""``$POS_ACT`` computed once per IPO cycle (issue 86; robot/readback.py ``ReadBack.pos_act``):
a submit interpreter beside a moving robot reads it at each of its passes, about 9 per IPO cycle,
and each read made the forward kinematics, the frames' matrices and their inverse again, though
within one cycle the axes, ``$TOOL`` and ``$BASE`` are the same.

Expected values by hand: the KR 6 R900's forward kinematics from its DH table (robot-model.md
§4.1, written out in tests/robot/test_kinematics.py ``dh_forward``) and the frame chain
``$POS_ACT = INV_POS($BASE) : FLANGE(q) : $TOOL`` (reference §6.4), with robot-model.md §7's worked
example (axes {0, -90, 90, 0, 90, 0}, ``$TOOL`` Z 225, ``$BASE`` X 500 A 90: X 0, Y 55, Z 585,
A 90, B 0, C 180) and §9's status and turn of those axes (S 2, T 2)."""

from __future__ import annotations

import numpy as np
import pytest

from interp.run import make_runtime, run_spec
import robot.readback
from robot.readback import ReadBack

from ..interp.helpers import write
from .test_kinematics import abc_matrix, dh_forward

INTERPS = ("tree", "vm")

#: the worked example read three times in one IPO cycle, $TOOL and $BASE changed between reads
PROG_FRAMES = """
DEF prog()
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 90, A6 0}
  $TOOL = {X 0, Y 0, Z 225, A 0, B 0, C 0}
  $BASE = {X 500, Y 0, Z 0, A 90, B 0, C 0}
  P1 = $POS_ACT
  $TOOL = {X 0, Y 0, Z 125, A 0, B 0, C 0}
  P2 = $POS_ACT
  $BASE = {X 0, Y 0, Z 0, A 0, B 0, C 0}
  P3 = $POS_ACT
END
"""

DAT_FRAMES = """
DEFDAT prog PUBLIC
  DECL GLOBAL E6POS P1, P2, P3
ENDDAT
"""

#: a robot that moves for about 2 s with a tool and a base
PROG_MOVE = """
DEF prog()
  $TOOL = {X 10, Y -20, Z 225, A 0, B 30, C 0}
  $BASE = {X 500, Y 100, Z 0, A 90, B 0, C 0}
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
  PTP {A1 60, A2 -60, A3 70, A4 40, A5 -30, A6 100}
  PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}
END
"""

#: reads the position twice per pass, the axes once: many passes per IPO cycle
SPS_POS = """
DEF sps()
  DECL REAL X
  LOOP
    X = $POS_ACT.X
    $OUT[30] = $POS_ACT.Z > 600.0
    $OUT[31] = $AXIS_ACT.A1 > 30.0
  ENDLOOP
END
"""


def _pose(e6) -> tuple:
    return tuple(e6.f[k] for k in ("X", "Y", "Z", "A", "B", "C", "S", "T"))


@pytest.mark.parametrize("interp", INTERPS)
def test_reads_in_one_cycle_follow_tool_and_base_by_hand(tmp_path, interp):
    prog = write(tmp_path, "prog.src", PROG_FRAMES)
    write(tmp_path, "prog.dat", DAT_FRAMES)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, max_sim_time=20.0, check=False, interp=interp))
    res = rt.run()
    assert res.reason == "completed"
    data = rt.program.module("prog").data
    p1, p2, p3 = (_pose(data[n].get()) for n in ("P1", "P2", "P3"))
    # robot-model.md §7: the TCP 225 mm below the flange at (445, 0, 810), seen from $BASE
    assert p1[:3] == pytest.approx((0.0, 55.0, 585.0), abs=1e-9)
    assert p1[3:6] == pytest.approx((90.0, 0.0, 180.0), abs=1e-9)
    # the tool 100 mm shorter: the TCP 100 mm higher, read in the same cycle
    assert p2[:3] == pytest.approx((0.0, 55.0, 685.0), abs=1e-9)
    assert p2[3:6] == pytest.approx((90.0, 0.0, 180.0), abs=1e-9)
    # $BASE the null frame: the flange's orientation Rz(180) Rx(180) (§9), the TCP in WORLD
    assert p3[:3] == pytest.approx((445.0, 0.0, 685.0), abs=1e-9)
    assert p3[3:6] == pytest.approx((180.0, 0.0, 180.0), abs=1e-9)
    assert [p[6:] for p in (p1, p2, p3)] == [(2, 2)] * 3


def _hand_pose(axes, tool, base) -> np.ndarray:
    """INV_POS($BASE) : FLANGE(axes) : $TOOL by hand (4x4; frames as X, Y, Z, A, B, C)."""
    def frame(x, y, z, a, b, c):
        T = np.eye(4)
        T[:3, :3] = abc_matrix(a, b, c)
        T[:3, 3] = (x, y, z)
        return T
    B = frame(*base)
    Binv = np.eye(4)
    Binv[:3, :3] = B[:3, :3].T
    Binv[:3, 3] = -B[:3, :3].T @ B[:3, 3]
    return Binv @ dh_forward(axes) @ frame(*tool)


@pytest.mark.parametrize("interp", INTERPS)
def test_a_pass_beside_the_moving_robot_reads_one_pose_per_cycle(tmp_path, interp, monkeypatch):
    prog = write(tmp_path, "prog.src", PROG_MOVE)
    sub = write(tmp_path, "sps.sub", SPS_POS)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, max_sim_time=20.0, submit=[sub], check=False,
                                  interp=interp))
    ctl = rt.controller
    reads: list = []          # (cycle, axes, the dict the read gave, ($TOOL, $BASE) read)
    made: list = []           # the cycles a pose was made in (its matrix turned into X..C)
    pos_act, to_frame = ReadBack.pos_act, robot.readback.matrix_to_frame

    def spy_pos_act(self, *a, **k):
        out = pos_act(self, *a, **k)
        reads.append((ctl.cycle, self.axes(), out, a[:2]))
        return out

    def spy_to_frame(T):
        made.append(ctl.cycle)
        return to_frame(T)
    monkeypatch.setattr(ReadBack, "pos_act", spy_pos_act)
    monkeypatch.setattr(robot.readback, "matrix_to_frame", spy_to_frame)
    res = rt.run()
    assert res.reason == "completed"
    # the program sets $TOOL, then $BASE in its first cycle: the pass reads in between
    cycles = {(k, frames) for k, _q, _d, frames in reads}
    moving = {k for k, q, _d, _f in reads if not np.array_equal(q, reads[0][1])}
    assert len(moving) > 100                    # the robot moved for about 2 s beside the pass
    assert len(reads) > 3 * len(cycles)         # several reads per cycle and frames ...
    assert len(made) == len(cycles)             # ... one pose computed for each
    # every read is the chain by hand ($TOOL and $BASE of the program; robot-model.md §4.1, §6)
    tool, base = (10, -20, 225, 0, 30, 0), (500, 100, 0, 90, 0, 0)
    reads = [r for r in reads if r[3] == (tool, base)]
    assert len(reads) > 300
    for _k, q, d, _f in reads[::7]:
        T = _hand_pose(q, tool, base)
        assert (d["X"], d["Y"], d["Z"]) == pytest.approx(tuple(T[:3, 3]), abs=1e-9)
        np.testing.assert_allclose(abc_matrix(d["A"], d["B"], d["C"]), T[:3, :3], atol=1e-12)
    # and bit for bit the pose a read without the memo makes (a read-back of its own at those
    # axes: robot/readback.py's computation), each read its own dict
    fresh = ReadBack(ctl.model, reads[0][1], actuated=False, mujoco=False, cycles=None, dt=ctl.dt)
    for _k, q, d, _f in reads[::7]:
        fresh.place(q)
        assert fresh.pos_act(tool, base) == d
    assert len({id(d) for _k, _q, d, _f in reads}) == len(reads)
