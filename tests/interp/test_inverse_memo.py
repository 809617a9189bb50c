"""INVERSE's run-owned memo (interp/runtime/natives/invmemo.py, issue 86): the answers of the
native, asked first (computed and kept) and asked again (from the memo), are the robot model's own
inverse (robot/robotmodel.py ``RobotModel.ik`` of the frames made afresh, its errors as STATUS), bit
for bit (every E6AXIS component's repr and STATUS), on every kinematic family, reachable poses,
poses out of reach and pairs outside the software limits alike; its size stays within its bounds;
each run has its own. ``make test`` asks a sample of each analytic family's S/T pairs (the
pose's own, soft-limit and unreachable ones among them), ``make nightly`` every pair."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from interp.run import RunSinks, make_runtime, run_spec
from interp.runtime.natives import geometry
from interp.runtime.natives.args import ValueRef
from interp.runtime.natives.invmemo import ANSWERS, POSES, InverseMemo
from interp.runtime.sysvars import axis_struct
from robot.errors import SoftLimitError, WorkspaceError
from robot.frames import frame_to_matrix
from robot.machine import ROBOT_LIBRARY
from robot.mada import load_robot

HERE = Path(__file__).resolve().parents[2]
IIWA = (HERE.parent / "shared" / "robots" / "descriptions" / "kuka_experimental" / "kuka_lbr_iiwa_support"
        / "urdf" / "lbr_iiwa_14_r820.urdf")

PROGRAM = """DEF s()
  $TOOL = {X 10, Y 20, Z 150, A 0, B 0, C 0}
  $BASE = {X 200, Y -100, Z 50, A 30, B 0, C 0}
END
"""


class _Out:
    v = None

    def set(self, v):
        self.v = v


def _numeric_robot(tmp_path: Path) -> Path:
    """The KR 16-2 with a twisted $TX3P3 (A 20 deg): no closed form, the numeric family."""
    text = (ROBOT_LIBRARY / "kr16_2_krc2.dat").read_text(encoding="utf-8")
    twisted = text.replace("$TX3P3={X 670.000,Y 0.0,Z -35.0000,A 0.0,B 90.0000",
                           "$TX3P3={X 670.000,Y 0.0,Z -35.0000,A 20.0,B 90.0000")
    assert twisted != text
    p = tmp_path / "$machine.dat"
    p.write_text(twisted, encoding="utf-8")
    return p


def _runtime(tmp_path: Path, robot):
    (tmp_path / "s.src").write_text(PROGRAM)
    rt, _ = make_runtime(run_spec(tmp_path / "s.src", max_sim_time=5.0, mujoco=False, check=False, interp="vm",
                                  robot=load_robot(robot)), RunSinks())
    rt.run()
    return rt


def _answer(ctx, pos, start):
    out = _Out()
    ax = geometry._inverse(ctx, [ValueRef(pos), ValueRef(start), out])
    return [(k, repr(v)) for k, v in ax.f.items()], out.v


def _model_answer(ctx, pos, start):
    """INVERSE's answer from the robot model itself: ``RobotModel.ik`` of TOOLPOS, INV($TOOL) and
    $BASE made afresh (robot/frames.py), STATUS 2 / 3 and START for its SoftLimitError /
    WorkspaceError (natives/geometry.py's INVERSE_SOFT_LIMIT, INVERSE_NOT_REACHABLE)."""
    model = ctx.controller.model
    store = ctx.sysvars.store
    frame = [frame_to_matrix(*(float(v.f[k]) for k in "XYZABC")) for v in (pos, store["$TOOL"], store["$BASE"])]
    ref = np.array([start.f[k] for k in model.axes.robot_keys])
    try:
        q, code = model.ik(frame[0], np.linalg.inv(frame[1]), frame[2], pos.f["S"], pos.f["T"], ref), 0
    except SoftLimitError:
        q, code = ref, 2
    except WorkspaceError:
        q, code = ref, 3
    return [(k, repr(v)) for k, v in axis_struct(model.to_krl(q)).f.items()], code


#: (family, robot, poses, S/T pairs per pose): the analytic families 4 poses (the fourth out of
#: reach) with 40 S/T pairs each (the pose's own and pairs drawn), every pair of 8 poses in make
#: nightly; the numeric solves (about 1-7 ms a call) a few pairs, the seven-axis arm's Newton
#: solves (seconds a call on a loaded machine) in make nightly
ANALYTIC = [("opw", "kr16_2_krc2"), ("palletizer4", "kr180_r3200_pa"), ("palletizer5", "kr180_r3200_pa5"),
            ("scara", "kr6_r500_z200")]
FAMILIES = ([pytest.param(f, r, 4, 40, id=f) for f, r in ANALYTIC]
            + [pytest.param(f, r, 8, 512, marks=pytest.mark.slow, id=f"{f}-every-pair") for f, r in ANALYTIC]
            + [pytest.param("numeric", "numeric", 2, 6, id="numeric"),
               pytest.param("redundant", str(IIWA), 1, 3, marks=pytest.mark.slow, id="redundant")])


@pytest.mark.parametrize("family,robot,n_poses,n_pairs", FAMILIES)
def test_memo_answers_are_the_computed_ones(tmp_path, monkeypatch, family, robot, n_poses, n_pairs):
    if family == "redundant" and not IIWA.exists():
        pytest.skip("../shared's LBR iiwa description is not there")
    if robot == "numeric":
        robot = _numeric_robot(tmp_path)
    rt = _runtime(tmp_path, robot)
    ctx = rt.natives
    model = ctx.controller.model
    assert model.kin.family == family
    n = len(model.axes.robot_keys)
    rng = np.random.default_rng(86)
    lo, hi = model.kin._lo, model.kin._hi
    home = np.array(model.kin.machine.home_deg, dtype=float)[:n]
    cases = []
    for i in range(n_poses):
        q = np.clip(home + rng.uniform(-60.0, 60.0, n), lo, hi)
        if model.kin.machine.a4fix:
            q[3] = 0.0
        st = _Out()
        pos = geometry._forward(ctx, [ValueRef(axis_struct(list(q))), st])
        if i % 4 == 3:      # out of reach: the same orientation three times as far out
            for k in ("X", "Y", "Z"):
                pos.f[k] = pos.f[k] * 3.0
        start = axis_struct(list(np.clip(q + rng.uniform(-30.0, 30.0, n), lo, hi)))
        pairs = [(s, t) for s in range(8) for t in range(64)]
        if n_pairs < len(pairs):    # the pose's own S and T, and pairs drawn
            own = (pos.f["S"], pos.f["T"])
            pairs = [own] + [p for p in (pairs[int(j)] for j in rng.choice(len(pairs), n_pairs, replace=False))
                             if p != own][:n_pairs - 1]
        cases.append((pos, start, pairs))

    def asked(pos, s, t):
        p = type(pos)(pos.type, dict(pos.f))
        p.f["S"], p.f["T"] = s, t
        return p

    computed = [[_model_answer(ctx, asked(pos, s, t), start) for s, t in pairs] for pos, start, pairs in cases]
    memo = ctx.inverse_memo     # the run's own, made with its NativeContext: nothing asked yet
    assert isinstance(memo, InverseMemo) and not memo.tables
    first = [[_answer(ctx, asked(pos, s, t), start) for s, t in pairs] for pos, start, pairs in cases]
    kept = sum(len(t) for t in memo.tables.values())
    # asked again in the other order: every answer from the memo, none computed (the arm's
    # inverse is not called)
    solved = []
    solve = geometry._solve
    monkeypatch.setattr(geometry, "_solve", lambda *args: solved.append(args) or solve(*args))
    again = [[_answer(ctx, asked(pos, s, t), start) for s, t in reversed(pairs)][::-1]
             for pos, start, pairs in reversed(cases)][::-1]
    if not model.n_ext:
        assert solved == []
    assert first == computed
    assert again == computed
    statuses = {code for row in computed for _, code in row}
    if family in ("numeric", "redundant"):
        assert 0 in statuses
    else:
        assert statuses == {0, geometry.INVERSE_SOFT_LIMIT, geometry.INVERSE_NOT_REACHABLE}
    if not model.n_ext:
        # the memo holds one table per pose and one answer per pair: nothing was computed again
        assert len(memo.tables) == len(cases)
        assert kept == sum(len(c[2]) for c in cases) == sum(len(t) for t in memo.tables.values())
    else:               # a robot with external axes: INVERSE's general path, which keeps nothing
        assert not memo.tables


def test_memo_keeps_its_bounds_and_forgets_another_robot():
    memo = InverseMemo()
    a, b = object(), object()
    for i in range(POSES):
        memo.table(a, bytes([i]))
    assert len(memo.tables) == POSES
    memo.table(a, b"new")
    assert list(memo.tables) == [b"new"]
    t = memo.table(a, b"new")
    for k in range(ANSWERS):
        memo.keep(t, (k, 0), (2, None))
    assert len(t) == ANSWERS
    memo.keep(t, (-1, 0), (3, None))
    assert t == {(-1, 0): (3, None)}
    memo.table(b, b"new")
    assert memo.tables == {b"new": {}}


def test_each_run_has_its_own_memo(tmp_path):
    rt1 = _runtime(tmp_path, "kr180_r3200_pa5")
    rt2 = _runtime(tmp_path, "kr180_r3200_pa5")
    assert isinstance(rt1.natives.inverse_memo, InverseMemo)
    assert rt1.natives.inverse_memo is not rt2.natives.inverse_memo
