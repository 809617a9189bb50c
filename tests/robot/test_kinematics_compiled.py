"""The kinematic families compiled and as Python (issue 86 item 1): robot/kinematics/fastpath.py's
``Chooser`` on every family's axis count, and each compiled family module (robot/build.py ``PURE``)
against its .py run as Python, bit for bit, and used where it is built.

Expected values: the Python run of the same source (the reference the compiled module must
reproduce: robot/kinematics/compiled.py ``pure_python``), and by hand where a figure is checked."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robot import build, ipocycle, planmemo, segments
from robot.blas import numpy_cblas
from robot.frames import frame_to_matrix
from robot.robotmodel import RobotModel
from robot.motion import MotionParams, MotionRequest
from robot.errors import SoftLimitError, WorkspaceError
from robot.kinematics import Kinematics, compiled, pal4rows, pal5rows, scararows
from robot.kinematics.family import _limit_error, select
from robot.machine import ROBOT_LIBRARY
from robot.mada import load_mada, load_robot
from tests.robot.test_simcore import _pal_args, _pure, _segments, fast  # noqa: F401  (fast: the fixture of the compiled fastpath)

#: the library's 5-axis palletizer ($DEF_A4FIX TRUE, $DEF_A5LINK FALSE; tests/robot/test_palletizer.py)
PA5 = ROBOT_LIBRARY / "kr180_r3200_pa5.dat"


def test_the_compiled_chooser_takes_a_seven_axis_row_as_python_does(fast):  # noqa: F811
    """The seven-axis family (robot/kinematics/redundant.py) chooses through fastpath's Chooser with
    n = 7: by hand, the row (10, 20, ..., 70) lies within the limits below and is the only row, so it
    is the answer; with the reference (1, ..., 7) the nearer of two rows is (1.5, ..., 7.5)."""
    lo = [-170.0, -120.0, -170.0, -120.0, -170.0, -120.0, -175.0]
    hi = [170.0, 120.0, 170.0, 120.0, 170.0, 120.0, 175.0]
    ks = [-720.0, -360.0, 0.0, 360.0, 720.0]
    ref = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]
    far = [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0]
    near = [v + 0.5 for v in ref]
    for mod in fast:
        c = mod.Chooser(7, lo, hi, ks, [False] * 7, 0)
        assert c.choose([far], ref, None) == far
        assert c.choose([far, near], ref, None) == near
    rng = np.random.default_rng(86)
    c, p = (m.Chooser(7, lo, hi, ks, [False] * 7, 0b100) for m in fast)
    for _ in range(500):
        rows = [list(rng.uniform(-200.0, 200.0, 7)) for _ in range(int(rng.integers(1, 9)))]
        r = list(rng.uniform(-200.0, 200.0, 7))
        turn = None if rng.random() < 0.5 else int(rng.integers(0, 128))
        assert c.choose(rows, r, turn) == p.choose(rows, r, turn)


# ---------------------------------------------------------------- the 5-axis palletizer
def _pal5_python(kin):
    """pal5rows.py run as Python on fastpath.py's OPW core as Python, for the 5-axis palletizer `kin`."""
    impl = kin.impl
    j = kin.joints
    if impl._a1_sign is None:
        impl._a1_of(0.0)
    return compiled.pure_python(pal5rows).Palletizer5Rows(
        impl.arm.python_core(), j.origins.tolist(), j.axes.tolist(), j.kuka_sign.tolist(), j.R_origin.tolist(),
        j.origin_rot, j.R_flange.tolist(), j.p_flange.tolist(), impl.a6_in_flange.tolist(), impl._a1_sign)


def test_the_5_axis_palletizer_rows_are_compiled_and_used_where_built(fast):  # noqa: F811
    """Issue 86: the KR 470 PA-2's INVERSE spent 3.4 ms a call in numpy on 3-vectors (palletizer5.py
    ``solutions``, two ``joints`` per candidate). Its rows are robot/kinematics/pal5rows.py now,
    compiled (robot/build.py ``PURE``) and the module the family uses when it is built."""
    got, _ = _pure(pal5rows)
    assert "robot.kinematics.pal5rows" in build.PURE
    kin = Kinematics(load_mada(PA5))
    kin.solutions(kin.forward([10.0, -60.0, 110.0, 0.0, 30.0, 45.0]))
    assert type(kin.impl._rows) is got.Palletizer5Rows and got.COMPILED


def test_the_5_axis_palletizer_rows_compiled_and_as_python_are_the_same_and_numpys():
    """The 5-axis palletizer's rows (pal5rows.py compiled where built, and as Python) are the same
    bytes; numpy's rows (palletizer5.py ``numpy_rows``: the same geometry through 4x4 matrices and
    scipy-style rotation vectors) are the same rows within 1e-9 deg, on configurations of the library
    palletizer within its limits, targets tilted out of the arm plane, off the reach, and without a
    reference; each row's flange is at the target's position (1e-6 mm), by the chain's forward."""
    kin = Kinematics(load_mada(PA5))
    python = _pal5_python(kin)
    rng = np.random.default_rng(86)
    found = empty = 0
    for _ in range(120):
        q = rng.uniform(kin._lo, kin._hi)
        q[3] = 0.0
        T = kin.forward(q)
        if rng.random() < 0.3:
            T[:3, :3] = Rotation.from_rotvec(rng.normal(size=3) * 0.1).as_matrix() @ T[:3, :3]
        if rng.random() < 0.15:
            T[:3, 3] += rng.normal(size=3) * 2000.0
        ref = None if rng.random() < 0.2 else q
        a, b, want = kin.impl.solutions(T, ref), python.rows(T, ref), kin.impl.numpy_rows(T, ref)
        assert np.array(a).tobytes() == np.array(b).tobytes(), (q.tolist(), ref)
        assert len(a) == len(want) and (not a or np.abs(np.array(a) - np.array(want)).max() < 1e-9)
        for row in a:
            assert np.abs(kin.forward(row)[:3, 3] - T[:3, 3]).max() < 1e-6
        found += bool(a)
        empty += not a
    assert found > 90 and empty > 3


@pytest.mark.parametrize("robot", ["kr180_r3200_pa5", "kr6_r500_z200"])
def test_the_choosers_limit_error_is_the_numpy_selections(fast, robot):  # noqa: F811
    """Where no row fits (a status/turn search through INVERSE meets this on most of its pairs),
    fastpath's ``Chooser.limit_error`` (compiled, and as Python) names the axis and value that
    family.py's numpy ``_limit_error`` raises, on a palletizer (free turn bits) and a SCARA (a
    linear A3), with and without a turn."""
    kin = Kinematics(load_robot(robot))
    n, t_free = kin.n_axes, kin.impl.t_free
    lin = [bool(v) for v in kin.joints.linear]
    choosers = [m.Chooser(n, kin._lo_l, kin._hi_l, kin._ks_l, lin, t_free) for m in fast]
    rng = np.random.default_rng(7)
    raised = 0
    for _ in range(400):
        rows = [list(rng.uniform(-420.0, 420.0, n)) for _ in range(int(rng.integers(1, 5)))]
        ref = rng.uniform(-200.0, 200.0, n)
        turn = None if rng.random() < 0.4 else int(rng.integers(0, 64))
        got = [c.choose(rows, ref.tolist(), turn) for c in choosers]
        if got[0] is not None:
            continue
        try:
            _limit_error(kin, np.array(rows), None if turn is None else turn & ~t_free, t_free, ref)
        except SoftLimitError as e:
            want = (e.axis - 1, e.value_deg)
        for c in choosers:
            assert c.limit_error(len(rows), turn, kin._lo_l0, kin._hi_l0) == want, (rows, ref.tolist(), turn)
        raised += 1
    assert raised > 150


def test_a_status_turn_search_answers_as_fresh_rows(fast):  # noqa: F811
    """A ``Find_Optimal_ST``-style search (every S, every T of a pose, through ``Kinematics.inverse``;
    the rows of the last pose and reference are kept between the calls) answers each pair as the
    selection over rows solved afresh does, also when the pose or the reference changes between
    calls; HOME's own S and T give HOME back (A4 = 0, A5 chosen by the arm's pitch)."""
    m = load_mada(PA5)
    kin = Kinematics(m)
    home = np.array(m.home_deg, dtype=float)
    poses = [kin.forward(home), kin.forward(home + [20.0, -10.0, 15.0, 0.0, -5.0, 30.0])]
    refs = [home, home + 3.0]
    seen = set()
    for T, ref in ((poses[0], refs[0]), (poses[1], refs[0]), (poses[1], refs[1]), (poses[0], refs[0])):
        fresh = kin.impl.solutions(T, ref)
        for s in range(8):
            for t in range(0, 64, 3):
                got = _answer(lambda: kin.inverse(T, s, t, ref))
                want = _answer(lambda: select(kin.impl, fresh, s, t, ref))
                assert got == want, (s, t)
                seen.add(got[0])
    assert seen == {"ok", "SoftLimitError", "WorkspaceError"}
    s, t = kin.status_turn(home)
    assert np.allclose(kin.inverse(poses[0], s, t, home), home, atol=1e-9)


def _answer(call):
    try:
        return ("ok", call().tobytes())
    except (SoftLimitError, WorkspaceError) as e:
        return (type(e).__name__, str(e), getattr(e, "axis", None), getattr(e, "value_deg", None))


# ---------------------------------------------------------------- a chain with a linear joint
def test_the_scara_forward_is_compiled_and_its_python_run_bit_for_bit():
    """The SCARA's forward (a linear A3) runs robot/ipocycle.py's ``Forward`` compiled, as the arms'
    does (before issue 86: numpy and scipy per joint, 140 us a call), the same bytes as that file run
    as Python, and the flange by hand (tests/robot/test_scara.py's robot: arms 225 + 275 mm, the
    arms' plane 400 mm up, the flange 150 mm below it at A3 = 0, every axis positive clockwise seen
    from above, A3 positive down)."""
    _pure(ipocycle)
    kin = Kinematics(load_robot("kr6_r500_z200"))
    c = kin.joints._compiled()
    assert c and type(c) is compiled.pure_module(ipocycle).Forward
    rng = np.random.default_rng(86)
    T = np.empty((4, 4))
    for _ in range(64):
        a = rng.uniform(-130.0, 130.0, 4)
        a[2] = rng.uniform(0.0, 200.0)
        c.forward(a, T)
        assert T.tobytes() == kin.joints.forward_py(a).tobytes()
        t1, t12 = np.radians(-a[0]), np.radians(-a[0] - a[1])
        x, y = 225 * np.cos(t1) + 275 * np.cos(t12), 225 * np.sin(t1) + 275 * np.sin(t12)
        assert np.allclose(T[:3, 3], [x, y, 400.0 - a[2] - 150.0], atol=1e-9)
        assert np.allclose(kin.forward_many(a[None])[0], T, atol=1e-12)


# ---------------------------------------------------------------- the SCARA
def _scara_rows_by_hand(impl, T, ref):
    """The SCARA's closed form as scara.py wrote it in numpy before robot/kinematics/scararows.py
    (the reference within 1e-9): theta from the flange's rotation about the vertical, the quill
    point, the two-link arm (math, not the module's code)."""
    M = T[:3, :3] @ impl.R_F.T
    theta = math.atan2(M[1, 0] - M[0, 1], M[0, 0] + M[1, 1])
    c, s = math.cos(theta), math.sin(theta)
    f = impl.f
    w = T[:3, 3] - impl.o0 - np.array([c * f[0] - s * f[1], s * f[0] + c * f[1], f[2]])
    a3 = (w[2] - impl.a[2] - impl.b[2]) * impl.s[2]
    l1, l2 = impl.l1, impl.l2
    r2 = w[0] ** 2 + w[1] ** 2
    cd = (r2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    if abs(cd) > 1.0 + 1e-9:
        return []
    delta = math.acos(min(1.0, max(-1.0, cd)))
    wrap = lambda v: -((-v + 180.0) % 360.0) + 180.0      # noqa: E731
    rows = []
    for dl in ((delta, -delta) if delta > 1e-12 else (0.0,)):
        phi1 = math.atan2(w[1], w[0]) - math.atan2(l2 * math.sin(dl), l1 + l2 * math.cos(dl))
        th1, th2 = phi1 - impl.alpha, dl - impl.beta + impl.alpha
        rows.append([wrap(math.degrees(th1) * impl.s[0]), wrap(math.degrees(th2) * impl.s[1]), a3,
                     wrap(math.degrees(theta - th1 - th2) * impl.s[3])])
    return rows


def test_the_scara_rows_compiled_and_as_python_are_the_same_and_by_hand():
    """The SCARA's inverse rows (robot/kinematics/scararows.py) compiled where built (and the module
    the family uses then) and run as Python give the same float reprs on 300 poses of the library's
    KR 6 R500 Z200 (within its limits, off the reach, tilted); the closed form written in the test
    gives the same rows within 1e-9, and each row's flange is the target's position (1e-6 mm)."""
    got, python = _pure(scararows)
    assert "robot.kinematics.scararows" in build.PURE
    kin = Kinematics(load_robot("kr6_r500_z200"))
    impl = kin.impl
    kin.solutions(kin.forward([10.0, 20.0, -50.0, 30.0]))
    assert type(impl._rows) is got.ScaraRows
    py = python.ScaraRows(impl.o0, impl.a, impl.b, impl.f, impl.R_F.reshape(9), impl.s, impl.l1, impl.l2,
                          impl.alpha, impl.beta)
    rng = np.random.default_rng(86)
    found = empty = 0
    for _ in range(300):
        q = rng.uniform(np.maximum(kin._lo, -170.0), np.minimum(kin._hi, 170.0))
        T = kin.forward(q)
        if rng.random() < 0.2:
            T[:3, 3] += rng.normal(size=3) * 800.0
        if rng.random() < 0.2:
            T[:3, :3] = Rotation.from_rotvec(rng.normal(size=3) * 0.05).as_matrix() @ T[:3, :3]
        a, b = impl.solutions(T, q), py.rows(T, q)
        assert [[repr(v) for v in r] for r in a] == [[repr(v) for v in r] for r in b]
        want = _scara_rows_by_hand(impl, T, q)
        assert len(a) == len(want) and (not a or np.abs(np.array(a) - np.array(want)).max() < 1e-9)
        for row in a:
            assert np.abs(kin.forward(row)[:3, 3] - T[:3, 3]).max() < 1e-6
        found += bool(a)
        empty += not a
    assert found > 200 and empty > 10


# ---------------------------------------------------------------- the 4-axis palletizer's vertical
def test_the_4_axis_palletizer_vertical_is_compiled_and_its_python_run_bit_for_bit():
    """Issue 86: the 4-axis palletizer's inverse spent a third of its call in numpy's two 3x3
    products of the flange rotation (palletizer4.py ``_vertical``: the vertical rotation nearest the
    pose's). pal4rows.py ``pose_rows`` computes it with the rows (compiled where built): on 300 poses
    of the library KR 180 R3200 PA (linked configurations, flanges turned anywhere, off the reach,
    without a reference) the compiled run, the Python run and numpy's ``_vertical`` followed by
    ``rows`` give the same bytes."""
    got, python = _pure(pal4rows)
    kin = Kinematics(load_robot("kr180_r3200_pa"))
    impl = kin.impl
    kin.solutions(kin.forward([10.0, -60.0, 110.0, 0.0, 40.0, 45.0]))
    assert type(impl._rows) is got.Palletizer4Rows
    py = python.Palletizer4Rows(impl.solver.python_core(), *_pal_args(impl))
    home = kin._home
    rng = np.random.default_rng(86)
    found = empty = 0
    for i in range(300):
        q = rng.uniform(kin._lo, kin._hi)
        q[3] = 0.0
        q[4] = home[4] + home[1] + home[2] - q[1] - q[2]
        T = kin.forward(q)
        if i % 3 == 0:
            T[:3, :3] = Rotation.random(random_state=i).as_matrix()
        if rng.random() < 0.15:
            T[:3, 3] += rng.normal(size=3) * 800.0
        ref = None if rng.random() < 0.2 else q
        want = impl._rows.rows(*impl._vertical(T), ref)
        a, b = impl._rows.pose_rows(T, ref), py.pose_rows(T, ref)
        assert [[repr(v) for v in r] for r in a] == [[repr(v) for v in r] for r in b] \
            == [[repr(v) for v in r] for r in want], (q.tolist(), ref)
        assert impl.solutions(T, ref) == a
        found += bool(a)
        empty += not a
    assert found > 250 and empty > 3


# ---------------------------------------------------------------- the palletizers' inverse in one call
def _palletizer_targets(kin, rng, n):
    """`n` (T, ref) of the palletizer `kin`: configurations within its limits (A4 = 0, A5 led on a
    4-axis palletizer), some flanges tilted, some off the reach, references near and far."""
    home = kin._home
    for i in range(n):
        q = rng.uniform(kin._lo, kin._hi)
        q[3] = 0.0
        if kin.family == "palletizer4":
            q[4] = home[4] + home[1] + home[2] - q[1] - q[2]
        T = kin.forward(q)
        if i % 4 == 1:
            T[:3, :3] = Rotation.from_rotvec(rng.normal(size=3) * 0.2).as_matrix() @ T[:3, :3]
        if i % 9 == 2:
            T[:3, 3] += rng.normal(size=3) * 2000.0
        ref = q + rng.normal(size=6) * (2.0 if i % 2 else 60.0)
        yield T, ref


@pytest.mark.parametrize("robot", ["kr180_r3200_pa5", "kr180_r3200_pa"])
def test_a_palletizers_inverse_is_one_compiled_call_that_selects_as_python(fast, robot):  # noqa: F811
    """Issue 86: on a palletizer the IPO cycle's inverse of a CP motion and INVERSE ran the rows
    compiled but each row's status, the S/T filter and the choice in Python (family.py ``select``);
    the compiled paths of robot/segments.py and robot/cartpath.py were for the OPW arms alone. Now
    ``compiled_core`` is fastpath's ``OPWCore`` solving with the palletizer's rows (``use_rows``):
    ``inverse_rp`` answers as ``select`` over the family's rows (the axes' bytes; None where it
    raises), with and without a status, with turns, and the core run as Python (fastpath.py and the
    rows module as Python) gives the same bytes; ``Kinematics.inverse`` too."""
    kin = Kinematics(load_robot(robot))
    core = kin.compiled_core()
    assert isinstance(core, fast[0].OPWCore)
    py = kin.impl.row_core(python=True)
    assert isinstance(py, fast[1].OPWCore) and py is not core
    rng = np.random.default_rng(86)
    answered = set()
    for i, (T, ref) in enumerate(_palletizer_targets(kin, rng, 90)):
        fresh = kin.impl.solutions(T, ref)
        for status, turn in ((None, None), (i % 8, None), (int(rng.integers(0, 8)), int(rng.integers(0, 64)))):
            want = _answer(lambda: select(kin.impl, fresh, status, turn, ref))
            got = [c.inverse_rp(T[:3, :3].copy(), T[:3, 3].copy(), status, turn, ref) for c in (core, py)]
            if want[0] == "ok":
                assert got[0] is not None and got[0].tobytes() == got[1].tobytes() == want[1], (i, status, turn)
            else:
                assert got == [None, None], (i, status, turn)
            assert _answer(lambda: kin.inverse(T, status, turn, ref)) == want
            # INVERSE's answer without the error made (issue 86): the axes' bytes or the error's kind
            q, err = kin.inverse_or_error(T, status, turn, ref)
            assert (("ok", q.tobytes()) if err is None else (err.__name__,)) == want[:1 if err else 2]
            answered.add(want[0])
    assert answered == {"ok", "SoftLimitError", "WorkspaceError"}


def test_inverse_or_error_of_the_other_families_is_inverses_answer():
    """``Kinematics.inverse_or_error`` of an OPW arm and a SCARA (robot/kinematics/family.py's default):
    the axes :meth:`inverse` gives, or the class of the error it raises, on reachable, far and
    limit-crossing targets."""
    rng = np.random.default_rng(8607)
    for robot in ("kr6_r900", "kr6_r500_z200"):
        kin = Kinematics(load_robot(robot))
        seen = set()
        for i in range(60):
            q = rng.uniform(kin._lo, kin._hi)
            T = kin.forward(q)
            if i % 3 == 1:
                T[:3, 3] *= 3.0
            st = kin.status_turn(q)
            status, turn = (None, None) if i % 2 else (st[0], (st[1] ^ (1 << int(rng.integers(0, 6)))) if i % 4 == 0 else st[1])
            want = _answer(lambda: kin.inverse(T, status, turn, q))
            got, err = kin.inverse_or_error(T, status, turn, q)
            assert (("ok", got.tobytes()) if err is None else (err.__name__,)) == want[:1 if err else 2]
            seen.add(want[0])
        assert "ok" in seen and "WorkspaceError" in seen, (robot, seen)


def test_a_palletizer_core_keeps_the_rows_of_one_pose_by_its_bits(fast):  # noqa: F811
    """The compiled core keeps the rows of the last pose and reference (a status/turn search asks one
    pose with each S and T): a pose that differs only in the sign of a zero is another pose. By hand:
    on the 4-axis palletizer a flange behind the A1 axis at Y = +0.0 or -0.0 gives A1 = +180 or -180
    before the wrap (atan2's sign), rows that differ in their last bits; the core's rows of each are
    its own, and its answer ``select``'s over them, compiled and as Python."""
    kin = Kinematics(load_robot("kr180_r3200_pa"))
    home = kin._home
    q = np.array([180.0, -60.0, 100.0, 0.0, home[4] + home[1] + home[2] + 60.0 - 100.0, 10.0])
    T = kin.forward(q)
    T[1, 3] = 0.0
    T2 = T.copy()
    T2[1, 3] = -0.0
    rows, rows2 = kin.impl.solutions(T, q), kin.impl.solutions(T2, q)
    assert rows and np.array(rows).tobytes() != np.array(rows2).tobytes()
    for core in (kin.compiled_core(), kin.impl.row_core(python=True)):
        for pose, fresh in ((T, rows), (T2, rows2), (T2, rows2), (T, rows)):
            want = select(kin.impl, fresh, None, None, q)
            got = core.inverse_rp(pose[:3, :3].copy(), pose[:3, 3].copy(), None, None, q)
            assert got.tobytes() == want.tobytes()
            assert np.array(core.rows_of(pose, q)).tobytes() == np.array(fresh).tobytes()


# ---------------------------------------------------------------- the PTP path-length table
def test_the_tcp_points_of_a_chain_compiled_and_as_python_are_the_same():
    """robot/ipocycle.py ``Forward.tcp_points`` (a PTP motion's path-length table in one call, issue
    86) compiled and as Python: the same bytes, with and without a $ROBROOT, on the OPW arm, the
    5-axis palletizer and the SCARA (a linear A3)."""
    fast, slow = _pure(ipocycle)
    gemm, gemv = numpy_cblas("dgemm"), numpy_cblas("dgemv")
    assert fast.COMPILED and gemm and gemv
    rng = np.random.default_rng(86)
    us = np.linspace(0.0, 1.0, 17)
    for kin in (Kinematics(), Kinematics(load_mada(PA5)), Kinematics(load_robot("kr6_r500_z200"))):
        j = kin.joints
        c, p = j._forward_of(fast, gemm, gemv), j._forward_of(slow, 0, 0)
        for i in range(6):
            frames = [np.eye(4) for _ in range(3)]
            for F, R in zip(frames, Rotation.random(3, random_state=rng).as_matrix()):
                F[:3, :3], F[:3, 3] = R, rng.uniform(-900.0, 900.0, 3)
            q0, dq = rng.uniform(-100.0, 100.0, kin.n_axes), rng.uniform(-60.0, 60.0, kin.n_axes)
            a, b = np.empty((17, 3)), np.empty((17, 3))
            c.tcp_points(q0, dq, us, frames[0], i % 2 == 0, frames[1], frames[2], a)
            p.tcp_points(q0, dq, us, frames[0], i % 2 == 0, frames[1], frames[2], b)
            assert a.tobytes() == b.tobytes()


def test_a_ptp_path_length_table_is_the_tcp_point_by_point():
    """A PTP motion's path-length table (robot/segments.py ``JointSegment``: C_DIS zones, path
    triggers) comes from one ``tcp_points`` call now: its 65 positions are ``RobotModel.tcp``'s point
    by point, bit for bit (in a $TOOL and a $BASE), so its lengths too. By hand: an A1-only PTP of 90
    deg moves the TCP on a circle of radius r about the A1 axis, and the table sums 64 chords,
    64 * 2 r sin(90 deg / 128)."""
    q = [0.0, -90.0, 90.0, 0.0, 30.0, 0.0]
    tool, base = (10.0, -20.0, 150.0, 30.0, 0.0, 0.0), (600.0, -50.0, 300.0, 15.0, 0.0, 180.0)
    framed = MotionParams.initmov(None).with_(tool=tool, base=base)
    plain = MotionParams.initmov(None)
    program = [MotionRequest("PTP", {f"A{i + 1}": v for i, v in enumerate(q)}, plain),
               MotionRequest("PTP", {"A1": 90.0}, plain),
               MotionRequest("PTP", {"A1": 20.0, "A2": -70.0, "A5": -40.0, "A6": 120.0}, framed)]
    segs = _segments(None, program, segments.JointSegment)
    assert len(segs) == 3
    for seg in segs:
        us, s = seg._table()
        pts = np.array([seg.model.tcp(seg.q0 + float(u) * seg.dq, seg.tool_T, seg.base_inv_T)[:3, 3] for u in us])
        want = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
        assert s.tobytes() == want.tobytes()
        assert seg.tcp_dist_to_end(0.3) == planmemo.norm3(seg.pose_u(0.3)[0] - seg.end_pose()[0])
    p = segs[1].model.tcp(segs[1].q0, segs[1].tool_T, segs[1].base_inv_T)[:3, 3]
    r = math.hypot(p[0], p[1])
    assert segs[1].path_length == pytest.approx(64 * 2 * r * math.sin(math.radians(90.0 / 128)), rel=1e-12)


# ---------------------------------------------------------------- external kinematics
@pytest.mark.parametrize("robot", ["kr16_2_kl1500", "kr16_2_turntable"])
def test_an_external_kinematic_chain_compiled_and_as_python_are_numpys(robot):
    """An external kinematic's ``ETn(E)`` (robot/external.py: a track's $ROBROOT_C every IPO cycle,
    a turntable's linked $BASE; issue 86 item 1) is robot/ipocycle.py ``ExternalChain``, compiled
    and as Python the bytes of the numpy chain (``_chain_py``) and used where built, on the
    kinematic's root and on another (EK's). By hand: E1 of
    the track moves the flange of ETn by |E1| mm along one line and turns nothing; E1 of the
    turntable turns it by |E1| deg and leaves the point on the table's axis where it is."""
    fast, slow = _pure(ipocycle)
    ext = RobotModel(load_robot(robot)).ext
    kin = ext.robroot_kin or next(iter(ext.base_kins.values()))
    c = ext._compiled(kin)
    assert c and type(c) is fast.ExternalChain
    m = len(kin.axes)
    frames = np.array([frame_to_matrix(*kin.root)] + [frame_to_matrix(*kin.frames[k]) for k in range(m)]
                      + [frame_to_matrix(*kin.frames[3])])
    args = ([ext.axes[n].kind == "linear" for n in kin.axes], [float(ext.axes[n].direction) for n in kin.axes],
            [n - 1 for n in kin.axes])
    p = slow.ExternalChain(0, frames, *args)
    rng = np.random.default_rng(86)
    a, b = np.empty((4, 4)), np.empty((4, 4))
    for v in [0.0, -0.0, 1e-9, -90.0, 180.0, *rng.uniform(-3000.0, 3000.0, 20)]:
        e = np.array([v])
        c.chain(e, a)
        p.chain(e, b)
        want = ext._chain_py(kin, e, None)
        assert a.tobytes() == b.tobytes() == want.tobytes() == ext.chain(kin, e).tobytes()
    root = (100.0, -2000.0, 50.0, 30.0, 0.0, 0.0)          # EK's MACHINE_DEF[].ROOT in place of the kinematic's
    c = ext._compiled(kin, root)
    assert c and type(c) is fast.ExternalChain
    for v in [0.0, -0.0, 33.3, -1234.5]:
        e = np.array([v])
        c.chain(e, a)
        assert a.tobytes() == ext._chain_py(kin, e, root).tobytes() == ext.chain(kin, e, root).tobytes()
    T0, T1 = ext.chain(kin, np.array([0.0])), ext.chain(kin, np.array([250.0]))
    if ext.axes[kin.axes[0]].kind == "linear":
        assert np.linalg.norm(T1[:3, 3] - T0[:3, 3]) == pytest.approx(250.0, abs=1e-9)
        assert np.abs(T1[:3, :3] - T0[:3, :3]).max() < 1e-12
    else:
        turn = T0[:3, :3].T @ T1[:3, :3]
        assert math.degrees(math.acos((np.trace(turn) - 1.0) / 2.0)) == pytest.approx(360.0 - 250.0, abs=1e-9)


def test_the_5_axis_palletizer_rows_shortcuts_are_libms_values_bit_for_bit():
    """pal5rows.py's shortcuts (pal15, issue 86): ``_rot`` at an angle of +-0 without cos and sin,
    ``_wrap`` without fmod inside (-180, 180), ``_times_u`` in place. Each gives the bytes of the
    spelled-out formula with math's functions and CPython's ``%``, on the zero angles of both signs,
    wrap values at and across the bounds, and random products."""
    kin = Kinematics(load_mada(PA5))
    py = _pal5_python(kin)
    mod = compiled.pure_python(pal5rows)
    for ang in (0.0, -0.0, 1e-300, -0.7):
        for x, y, z in ((0.0, 0.0, -1.0), (0.0, 1.0, 0.0), (0.6, 0.0, -0.8)):
            c, s = math.cos(ang), math.sin(ang)
            C = 1.0 - c
            want = [c + x * x * C, x * y * C - z * s, x * z * C + y * s, y * x * C + z * s, c + y * y * C,
                    y * z * C - x * s, z * x * C - y * s, z * y * C + x * s, c + z * z * C]
            py._rot(x, y, z, ang)
            assert np.array(py.U).tobytes() == np.array(want).tobytes(), (ang, x, y, z)
    for v in (180.0, -180.0, 0.0, -0.0, 179.99999999999997, -179.99999999999997, 359.5, -541.0, 1e-320,
              float("nan")):
        want = -((-v + 180.0) % 360.0) + 180.0
        assert np.array(mod._wrap(v)).tobytes() == np.array(want).tobytes(), v
    rng = np.random.default_rng(15)
    for _ in range(50):
        R, U = rng.normal(size=9).tolist(), rng.normal(size=9).tolist()
        py.R[:], py.U[:] = R, U
        py._times_u()
        want = [R[3 * a] * U[b] + R[3 * a + 1] * U[3 + b] + R[3 * a + 2] * U[6 + b] for a in range(3) for b in range(3)]
        assert np.array(py.R).tobytes() == np.array(want).tobytes()


def _spelled_wrapdeg(th, off, sg):
    """fastpath.py ``_wrapdeg`` as its docstring spells it: math's degrees and CPython's float ``%``."""
    return -((-math.degrees((th + off) * sg) + 180.0) % 360.0) + 180.0


def test_the_opw_wrap_without_fmod_is_cpythons_modulo_bit_for_bit(fast):  # noqa: F811
    """fastpath.py ``_wrapdeg`` takes its dividend x itself for 0 < x < 360 (where fmod would
    answer x): the bytes of the spelled-out formula on drawn angles, signed zeros, NaN and the
    infinities, and the angles at and beside +-180 deg (x at 0 and 360, one ulp either side). The
    compiled module's rows are checked against these in the palletizer tests above and below."""
    wrap = fast[1]._wrapdeg
    rng = np.random.default_rng(8601)
    pi = math.pi
    edge = [pi, -pi, 3 * pi, -3 * pi, 0.0, -0.0, 5e-324, -5e-324, float("nan")]
    edge += [math.nextafter(v, w) for v in (pi, -pi) for w in (0.0, 10.0, -10.0)]
    edge += [math.radians(v) for v in (180.0, -180.0, 179.99999999999997, -179.99999999999997, 540.0)]
    angles = edge + rng.uniform(-8.0, 8.0, 3000).tolist() + rng.normal(0.0, 1e-9, 200).tolist()
    for th in angles:
        for off, sg in ((0.0, 1.0), (0.0, -1.0), (-pi / 2, 1.0), (pi, -1.0), (-0.0, -1.0)):
            got, want = wrap(th, off, sg), _spelled_wrapdeg(th, off, sg)
            assert np.array(got).tobytes() == np.array(want).tobytes(), (th, off, sg, got, want)


def _opw_poses(rng, n, reach):
    """Flange poses (4x4) for an OPW core: drawn positions within `reach` (mm; some on the A1 axis:
    its singularity, where the reference's A1 is taken) and rotations."""
    out = []
    for k in range(n):
        T = np.eye(4)
        T[:3, :3] = Rotation.from_rotvec(rng.normal(size=3)).as_matrix()
        T[:3, 3] = rng.uniform(-reach, reach, 3)
        if k % 7 == 0:
            T[:2, 3] = (0.0, -0.0) if k % 2 else (0.0, 0.0)
        out.append(T)
    return out


def test_an_opw_cores_arm_rows_are_its_rows_arms_bit_for_bit(fast):  # noqa: F811
    """fastpath.py ``OPWCore.arm_rows`` (the arms alone, pal5rows.py's source) gives per arm the A1..A3
    of ``core``'s two rows of that arm (the wrist and its flip, whose A1..A3 ``_wrists`` copies from
    the wrist's): the same bytes, on the 5-axis palletizer's arm and a six-axis arm (Python run;
    ``sol`` is a list there), with and without a reference, on and off the A1 axis."""
    rng = np.random.default_rng(8602)
    for robot, reach in ((PA5, 2000.0), (ROBOT_LIBRARY / "kr16_2_krc2.dat", 1000.0)):
        kin = Kinematics(load_mada(robot))
        core = kin.impl.arm.python_core() if robot == PA5 else kin.impl.solver.python_core()
        seen = 0
        for T in _opw_poses(rng, 150, reach):
            ref = rng.uniform(-170.0, 170.0, 6)
            for has_ref in (0, 1):
                for i in range(3):
                    for k in range(4):
                        core.M[4 * i + k] = T[i, k]
                core.ref[:6] = ref.tolist()
                n = core.core(has_ref)
                rows = [core.sol[6 * j:6 * j + 3] for j in range(n)]
                m = core.arm_rows(has_ref)
                arms = [core.sol[6 * j:6 * j + 3] for j in range(m)]
                assert 2 * m == n
                for j in range(n):
                    assert np.array(rows[j]).tobytes() == np.array(arms[j // 2]).tobytes()
                    th = core.arm[3 * (j // 2):3 * (j // 2) + 3]
                    want = [_spelled_wrapdeg(th[i], core.offs[i], core.sgn[i]) for i in range(3)]
                    assert np.array(rows[j]).tobytes() == np.array(want).tobytes()
                seen += m
        assert seen > 500, seen


def test_the_5_axis_palletizer_rows_on_the_arms_alone_are_those_on_the_opw_rows(fast):  # noqa: F811
    """pal5rows.py solves each arm plane's A5 point with ``OPWCore.arm_rows`` (one row per arm, no
    wrists) where it took ``core``'s rows (two per arm; the flip's arm always one already seen):
    the rows of the earlier route (the Python run with ``arm_rows`` spelled as ``core`` and its
    rows' A1..A3) are the bytes of the compiled module's and of the Python run's, on targets in
    and out of reach, tilted, with and without a reference (its A1 read on the A1 axis)."""
    kin = Kinematics(load_mada(PA5))
    new, old = _pal5_python(kin), _pal5_python(kin)
    opw = old.opw

    def as_before(has_ref):
        n = opw.core(has_ref)
        firsts = [opw.sol[12 * j:12 * j + 3] for j in range(n // 2)]
        for j, arm in enumerate(firsts):
            opw.sol[6 * j:6 * j + 3] = arm
        return n // 2

    opw.arm_rows = as_before
    rng = np.random.default_rng(8603)
    found = 0
    for k in range(150):
        q = rng.uniform(kin._lo, kin._hi)
        q[3] = 0.0
        if k % 10 == 0:
            q[1:3] = (-90.0, 90.0)
        T = kin.forward(q)
        if rng.random() < 0.3:
            T[:3, :3] = Rotation.from_rotvec(rng.normal(size=3) * 0.1).as_matrix() @ T[:3, :3]
        if rng.random() < 0.15:
            T[:3, 3] += rng.normal(size=3) * 2000.0
        if k % 13 == 0:
            T[:2, 3] = 0.0
        ref = None if rng.random() < 0.2 else q
        want = old.rows(T, ref)
        assert np.array(kin.impl.solutions(T, ref)).tobytes() == np.array(want).tobytes(), (q.tolist(), ref)
        assert np.array(new.rows(T, ref)).tobytes() == np.array(want).tobytes()
        found += bool(want)
    assert found > 100
