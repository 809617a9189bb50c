"""The simulator's compiled hot path (robot/build.py builds it; `make` and CI build it before the
tests) against the Python it is compiled from or mirrors, the reference:

* robot/kinematics/fastpath.py compiled against the same file run as Python (the OPW form, its
  status, the choice among solutions, every entry; the same bytes, the same None where the
  caller raises), and the kinematics that use it against the kinematics without it (KR 6 R900,
  a corpus KR 210: the same axes and errors);
* the pure-Python-mode modules of robot/build.py PURE (the palletizer's rows, the step check,
  the time-law tables, the pose lines) compiled against the same files run as Python, and the
  pose lines against Python's own repr of the rounded values;
* robot/ipocycle.py (PURE: the forward product, the IPO cycle's playback), compiled and as Python,
  against numpy's and scipy's forward kinematics and robot/mjcf.py ArmModel's own playback;
* robot/cartpath.py (PURE: the CP paths, a single LIN's plan), compiled against the Python code it
  gives the numbers of (robot/segments.py, robot/cartplan.py, robot/cartlaw.py, robot/blending.py),
  and as Python against itself compiled;
* robot/cellproof.py (PURE: the loops of a cell's bound), compiled against the same file run as
  Python (its tests against MuJoCo are tests/robot/test_cellbound.py's).

These tests never skip where the build is expected: with Cython and a C compiler at hand a
missing or stale build fails here (make vm-loop builds it). Without them there is nothing
compiled to compare and they skip saying so. Issue 39 ("Simulator": traces byte-identical),
issue 47 (the compiled core generated from the Python, its comparison always run)."""

from __future__ import annotations

import importlib.util
import math
import hashlib
import random
import shutil
import sys
import sysconfig
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robot import (blending, build, cartlaw, cartline, cellproof, ipocycle, kinematics, lawtable, motionqueue,
                   pathpieces, planmemo, planner, segments, steplimit, trace, tracecheck)
from robot.cellbound import LEVER_SLACK_M2
from robot.cellscene import CellScene, Placement
from robot.bench import bench_program, run_motions
from robot.blas import numpy_cblas
from robot.controller import Controller
from robot.errors import RobotError
from robot.frames import NULLFRAME, frame_to_matrix, inv_pos, matrix_to_frame
from robot.kinematics import Kinematics, constants, pal4rows
from robot import poseline
from robot.machine import ROBOT_LIBRARY, library_robots, load_machine
from robot.mada import load_mada, load_robot
from robot.mjcf import ArmModel, _numpy_dgemm
from robot.motion import MotionParams, MotionRequest
from robot.profiles import BrakeProfile, RampProfile, Trapezoid
from robot.trace import _round6, round_time
from tests.budget import examples

def _can_compile() -> bool:
    # without Cython (a dev dependency) nothing is compiled and loop.py/the Python core run
    if importlib.util.find_spec("Cython") is None:
        return False
    return shutil.which(sysconfig.get_config_var("CC").split()[0]) is not None


def _built(what: str) -> None:
    """Fail when the compiled module `what` is missing although it can be built; skip (saying
    why) where nothing can be compiled."""
    if _can_compile():
        pytest.fail(f"{what} is not built, or is stale, although Cython and a C compiler are here: "
                    f"run make vm-loop")
    pytest.skip(f"no Cython or no C compiler: {what} is not compiled, nothing to compare (make vm-loop says so)")


def _pure(module):
    """(`module` compiled, its .py run as Python): a pure-Python-mode module of robot/build.py
    ``PURE``, built and current (else :func:`_built`)."""
    got = kinematics.compiled.pure_module(module)
    if not got.__file__.endswith(sysconfig.get_config_var("EXT_SUFFIX")):
        _built(module.__name__.replace(".", "/") + ".py")
    return got, kinematics.compiled.pure_python(module)


@pytest.fixture()
def sc():
    """robot/cartpath.py compiled, built and current (else :func:`_built`)."""
    mod = kinematics.compiled_module()
    if mod is None:
        _built("robot/cartpath.py")
    return mod


@pytest.fixture()
def fast():
    """(compiled fastpath module, fastpath.py run as Python)."""
    if not kinematics.fastpath_compiled():
        _built("robot/kinematics/fastpath.py")
    return kinematics.fastpath_module(), kinematics.compiled._python_fastpath()


def test_the_compiled_core_is_built_current_and_used(sc, fast):
    assert build.fastpath_target().exists()
    # each PURE module's extension carries the sha256 of its .py and .pxd; no hand-written .pyx is left
    for name, py in build.PURE.items():
        got = kinematics.compiled.pure_module(importlib.import_module(name))
        assert build.pure_target(py).exists() and got.__file__ == str(build.pure_target(py))
        assert got.built_from() == hashlib.sha256(py.read_bytes() + py.with_suffix(".pxd").read_bytes()).hexdigest()
    assert sc.__name__ == "robot.cartpath" and sc.__file__ == str(build.pure_target(build.PURE["robot.cartpath"]))
    assert not list(build.HERE.rglob("*.pyx"))
    compiled, python = fast
    assert compiled.__file__.endswith(sysconfig.get_config_var("EXT_SUFFIX"))
    assert python.__file__.endswith("fastpath.py")
    k = Kinematics()
    assert k.compiled_inverse and isinstance(k.impl.solver.c, compiled.OPWCore)
    assert k.joints._compiled()                     # the forward product too


def test_a_stale_cartpath_is_not_used(monkeypatch, sc):
    python = kinematics.compiled.pure_python(sc)
    monkeypatch.setitem(kinematics.compiled._pure, "robot.cartpath", (None, python))   # built from other files
    assert kinematics.compiled_module() is None
    monkeypatch.undo()
    assert kinematics.compiled_module() is sc


def test_a_fastpath_that_answers_otherwise_is_not_used(monkeypatch, fast):
    compiled, python = fast

    class Off:
        OPWCore = python.OPWCore

        class Wrong(python.OPWCore):
            def inverse(self, T, status, turn, ref):
                q = python.OPWCore.inverse(self, T, status, turn, ref)
                return None if q is None else q + 1e-12

    Off.OPWCore = Off.Wrong
    assert kinematics.compiled._same_answers(compiled, python) and not kinematics.compiled._same_answers(Off, python)


def test_the_fastpath_constants_are_the_kinematics(fast):
    _, python = fast
    for name in ("BOUNDARY_EPS", "WRIST_SINGULAR_DEG", "OVERHEAD_SINGULAR_MM", "ACOS_TOL"):
        assert getattr(python, name) == getattr(constants, name), name


def _opw_cores(fast, machine, s_free=0, t_free=0, c4_zero=False):
    k = Kinematics(machine)
    s = k.impl.solver
    o = replace(s.o, c4=0.0) if c4_zero else s.o
    args = (o, s.phi_deg, s.sgn, s.offs, k._lo_l, k._hi_l, k._ks_l, s_free, t_free)
    return k, fast[0].OPWCore(*args), fast[1].OPWCore(*args)


@pytest.mark.parametrize("robot", ["kr6", "kr210", "pa4"])
def test_the_compiled_fastpath_is_fastpath_py_bit_for_bit(fast, robot, shared_corpus):
    machine = {"kr6": lambda: None, "kr210": lambda: load_robot(str(shared_corpus / "HugoDanielson__ChinaMilling")),
               "pa4": lambda: load_mada(ROBOT_LIBRARY / "kr180_r3200_pa.dat")}[robot]()
    k, c, p = _opw_cores(fast, machine, 4 if robot == "pa4" else 0, 0b11000 if robot == "pa4" else 0, robot == "pa4")
    rng = np.random.default_rng(46)
    lo, hi = np.maximum(k._lo, -185.0), np.minimum(k._hi, 185.0)

    def same(x, y):
        return (x is None and y is None) or (x is not None and y is not None and x.tobytes() == y.tobytes())
    solved = failed = 0
    for i in range(2500):
        q = rng.uniform(lo, hi)
        if i % 10 == 0:
            q[4] = 0.0
        elif i % 10 == 1:
            q[1], q[2] = -90.0, 90.0
        T = k.forward(q)
        if i % 17 == 0:
            T[:3, 3] *= 3.0                                  # out of reach
        ref = q + rng.normal(0.0, 25.0, 6)
        status = None if rng.random() < 0.6 else int(rng.integers(0, 8))
        turn = None if rng.random() < 0.6 else int(rng.integers(0, 64))
        a, b = c.inverse(T, status, turn, ref), p.inverse(T, status, turn, ref)
        assert same(a, b), (q.tolist(), status, turn)
        assert same(c.inverse_rp(T[:3, :3].copy(), T[:3, 3].copy(), status, turn, ref), a)
        assert c.rows_of(T, ref) == p.rows_of(T, ref) and c.rows_of(T, None) == p.rows_of(T, None)
        c.status(*ref)
        p.status(*ref)
        assert (c.s_out, c.amb_out) == (p.s_out, p.amb_out)
        solved += a is not None
        failed += a is None
    assert solved > 500 and failed > 100
    if robot == "pa4":
        return                                   # the chain is the six-axis family's (the planner's)
    # a chain of poses near HOME, each solution the next one's reference
    home = k._home
    Q = np.array([k.forward(q0) for q0 in np.linspace(home, home + np.array([30, 10, -10, 40, 15, 60]), 40)])
    x = c.inverse_chain_rp(np.ascontiguousarray(Q[:, :3, :3]), np.ascontiguousarray(Q[:, :3, 3]), None, None, home)
    y = p.inverse_chain_rp(Q[:, :3, :3], Q[:, :3, 3], None, None, home)
    assert same(x, y) and x is not None


def test_the_compiled_chooser_is_fastpath_py_bit_for_bit(fast):
    rng = np.random.default_rng(45)
    for n, linear in ((6, [False] * 6), (4, [False, False, True, False])):
        lo = [-170.0, -190.0, 0.0, -185.0, -120.0, -350.0][:n]
        hi = [170.0, 45.0, 200.0, 185.0, 120.0, 350.0][:n]
        ks = [-720.0, -360.0, 0.0, 360.0, 720.0]
        for t_free in (0, 0b11000):
            c, p = (m.Chooser(n, lo, hi, ks, linear, t_free) for m in fast)
            picked = 0
            for _ in range(1500):
                rows = [list(rng.uniform(-200.0, 200.0, n)) for _ in range(int(rng.integers(1, 9)))]
                ref = list(rng.uniform(-200.0, 200.0, n))
                turn = None if rng.random() < 0.5 else int(rng.integers(0, 64))
                x, y = c.choose(rows, ref, turn), p.choose(rows, ref, turn)
                assert x == y
                picked += x is not None
            assert picked > 300


def _answer(k: Kinematics, T, status, turn, ref):
    try:
        return k.inverse(T, status, turn, ref).tobytes()
    except RobotError as e:
        return (type(e).__name__, str(e))


def test_compiled_and_python_inverse_agree_bit_for_bit_kr6(fast, monkeypatch):
    _agree(None, 39, monkeypatch)


def test_compiled_and_python_inverse_agree_bit_for_bit_on_a_corpus_kr210(fast, monkeypatch, shared_corpus):
    _agree(load_robot(str(shared_corpus / "HugoDanielson__ChinaMilling")), 40, monkeypatch)


def _agree(machine, seed: int, monkeypatch) -> None:
    """The kinematics with the compiled fastpath against the kinematics with fastpath.py run as
    Python (USE_COMPILED off): the same axes, the same errors."""
    compiled = Kinematics(machine)
    monkeypatch.setattr(kinematics.compiled, "USE_COMPILED", False)
    python = Kinematics(machine)
    monkeypatch.setattr(kinematics.compiled, "USE_COMPILED", True)
    assert compiled.compiled_inverse and not python.compiled_inverse
    rng = np.random.default_rng(seed)
    lo, hi = np.maximum(compiled._lo, -185.0), np.minimum(compiled._hi, 185.0)
    solved = failed = 0
    for _ in range(3000):
        q = rng.uniform(lo, hi)
        r = rng.random()
        if r < 0.1:
            q[4] = 0.0                                   # the wrist singularity: A4 from the reference
        elif r < 0.15:
            q[4] = float(rng.choice([1e-7, -1e-7, 1e-6]))
        elif r < 0.2:
            q[1], q[2] = -90.0, 90.0                     # near the A1 axis
        T = compiled.forward(q)
        ref = q + rng.normal(0.0, 25.0, 6) if rng.random() < 0.7 else q.copy()
        if rng.random() < 0.1:
            ref[2] = compiled.phi_deg                    # a reference on the A3 switching point
        status = None if rng.random() < 0.6 else int(rng.integers(0, 8))
        turn = None if rng.random() < 0.6 else int(rng.integers(0, 64))
        a, b = _answer(compiled, T, status, turn, ref), _answer(python, T, status, turn, ref)
        assert a == b, (q.tolist(), ref.tolist(), status, turn)
        # the entry of robot/segments.py CartSegment.ik: rotation and position apart
        rp = compiled.impl.compiled().inverse_rp(T[:3, :3].copy(), T[:3, 3].copy(), status, turn, ref)
        assert (rp.tobytes() if rp is not None else None) == (a if isinstance(a, bytes) else None)
        solved += isinstance(a, bytes)
        failed += not isinstance(a, bytes)
    assert solved > 1000 and failed > 100      # both the solutions and the errors were compared


def test_the_build_falls_back_without_cython(monkeypatch):
    monkeypatch.setitem(sys.modules, "Cython.Build", None)
    assert "not compiled" in build.build(force=True)


def _python_pose_line(t, axes, tcp):
    # the reference: json.dumps's text of the event, each float Python's repr of round(v, 6)
    # with -0.0 as 0.0 (robot/trace.py _round6, round_time)
    ax, tc, tt = [_round6(float(v)) for v in axes], [_round6(v) for v in tcp], round_time(t)
    return (f'{{"t":{tt!r},"kind":"pose","axes":[{",".join(map(repr, ax))}],'
            f'"tcp":[{",".join(map(repr, tc))}]}}')


@pytest.mark.parametrize("compiled", [True, False])
def test_the_pose_line_is_pythons_repr_of_the_rounded_values(compiled):
    """robot/poseline.py (one source) compiled and as Python: its fast path and its fallback give
    Python's own text of each rounded value (10,000 lines compiled, 1,000 as Python in make test;
    make nightly draws 40 times as many: tests/budget.py)."""
    fast, slow = _pure(poseline)
    mod = fast if compiled else slow
    rng = random.Random(39)
    tricky = [0.0, -0.0, 5e-7, -5e-7, 4.9999999e-7, 1.5e-6, 1.25e-5, -1.25e-5, 1e-4, 9.9995e-5,
              -1e-4, 1.5e-4, 123.4565, 2.0000005, 99999999.9999995, 1e13, 99999999999999.98, 1e20]

    def value():
        r = rng.random()
        if r < 0.2:
            return rng.choice(tricky)
        if r < 0.3:
            return rng.uniform(-1e-3, 1e-3)                      # repr's exponent form below 1e-4
        if r < 0.45:
            return round(rng.uniform(-10, 10), 6) + rng.choice([5e-7, -5e-7])   # near a tie
        if r < 0.6:
            return round(rng.uniform(-1000, 1000), rng.choice([6, 7]))
        if r < 0.7:
            return rng.uniform(-1e14, 1e14) * rng.choice([1.0, 1e-3, 1e-6])
        return rng.uniform(-2000, 2000)

    for i in range(examples(10_000 if compiled else 1_000)):
        t = rng.choice([i * 0.012, rng.uniform(0.0, 1e4)])
        axes, tcp = [value() for _ in range(6)], [value() for _ in range(6)]
        line = mod.pose_line(t, axes, tcp)
        if line is None:     # left to the Python path: only for a huge number
            assert max(abs(v) for v in axes + tcp) >= 1e15, (t, axes, tcp)
        else:
            assert line == _python_pose_line(t, axes, tcp), (t, axes, tcp)
    assert mod.pose_line(1.0, [float("nan")] * 6, [0.0] * 6) is None    # json.dumps writes NaN
    assert mod.pose_line(1.0, [1e15] + [0.0] * 5, [0.0] * 6) is None
    assert mod.pose_line(2, [-0.0, 5e-7, -5e-7, 1.5e-6, 0.00012, 12.3456785], [1e8, -1e13, 0.1, 3, 2e-4, 1 / 3]) == (
        '{"t":2.0,"kind":"pose","axes":[0.0,0.0,0.0,2e-06,0.00012,12.345678],'
        '"tcp":[100000000.0,-10000000000000.0,0.1,3.0,0.0002,0.333333]}')


# ----------------------------------------------------------------------------- the IPO cycle
def _arm_agrees(machine, seed: int, mod, count: int) -> None:
    """robot/ipocycle.py's ArmCycle (`mod`: compiled or as Python) against ArmModel's own numpy
    playback (set_axes, axes_deg, flange_pose_world) on `count` random axis sets."""
    a, b = ArmModel(machine), ArmModel(machine)
    cyc = a.ipo_cycle(mod)
    assert cyc is not None, "the playback in one call is not used"
    rng = np.random.default_rng(seed)
    qa, F = np.empty(6), np.empty((4, 4))
    for i in range(count):
        q = rng.uniform(-200.0, 200.0, 6)
        if i % 7 == 0:
            q[rng.integers(0, 6)] = rng.choice([0.0, -0.0, 90.0, -90.0, 180.0])
        cyc.cycle(q, qa, F)
        b.set_axes(q)
        assert qa.tobytes() == b.axes_deg().tobytes(), q.tolist()
        assert F.tobytes() == b.flange_pose_world().tobytes(), q.tolist()
    assert a.axes_deg().tobytes() == qa.tobytes()        # the model's own read-back agrees


def test_the_cycle_compiled_and_as_python_is_the_arm_models_playback_kr6():
    compiled, python = _pure(ipocycle)
    _arm_agrees(None, 41, compiled, 3000)
    _arm_agrees(None, 43, python, 300)


def test_the_compiled_cycle_is_the_arm_models_playback_on_a_corpus_kr210(shared_corpus):
    _arm_agrees(load_robot(str(shared_corpus / "HugoDanielson__ChinaMilling")), 42, _pure(ipocycle)[0], 3000)


def test_the_cycle_keeps_each_cycles_qpos_in_the_block_it_was_given():
    """``ArmCycle.keep_rows`` (a cell's turn, interp/cellkeep.py), compiled and as Python: after
    each cycle the qpos slice is the block's next row, bit for bit as the arm's data holds it; the
    count goes on past the block's rows (none written there), None stops it, a slice past qpos is
    refused."""
    for mod in _pure(ipocycle):
        arm = ArmModel()
        cyc = arm.ipo_cycle(mod)
        rng = np.random.default_rng(7)
        qa, F = np.empty(6), np.empty((4, 4))
        rows = np.full((3, 4), -1.0)
        cyc.keep_rows(rows, 2)
        want = []
        for _ in range(5):
            cyc.cycle(rng.uniform(-170.0, 170.0, 6), qa, F)
            want.append(arm.data.qpos[2:6].copy())
        assert cyc.row == 5
        assert rows.tobytes() == np.array(want[:3]).tobytes()
        cyc.keep_rows(None, 0)
        cyc.cycle(np.zeros(6), qa, F)
        assert cyc.row == 5 and rows.tobytes() == np.array(want[:3]).tobytes()
        with pytest.raises(ValueError):
            cyc.keep_rows(np.empty((2, 4)), 3)


def test_the_cycle_is_off_in_actuated_mode_and_as_python_without_the_compiled_module(monkeypatch):
    compiled, python = _pure(ipocycle)
    assert ArmModel(actuated=True).ipo_cycle(compiled) is None
    arm = ArmModel()
    assert isinstance(arm.ipo_cycle(compiled), compiled.ArmCycle)
    assert isinstance(arm.ipo_cycle(python), python.ArmCycle)       # kept per module
    assert Controller().actual._cycles is compiled
    monkeypatch.setattr(kinematics.compiled, "USE_COMPILED", False)
    assert Controller().actual._cycles is python


def test_the_step_check_compiled_and_as_python_is_the_limit_test():
    """robot/steplimit.py ``speed_ok``, compiled and as Python: no axis step over its limit, a NaN
    step passing (the monitor's error search finds no axis over it), over the shortest list."""
    rng = np.random.default_rng(43)
    lim = rng.uniform(0.5, 3.0, 6).tolist()
    for mod in _pure(steplimit):
        for _ in range(5_000):
            q, prev = rng.uniform(-5, 5, 6), rng.uniform(-5, 5, 6)
            if rng.random() < 0.1:
                q[rng.integers(0, 6)] = float("nan")
            want = all(not abs(x - y) > m for x, y, m in zip(q.tolist(), prev.tolist(), lim))
            assert mod.speed_ok(q.tolist(), prev.tolist(), lim) == want
        assert mod.speed_ok([0.0] * 8, [9.0] * 6 + [0.0] * 2, [9.0] * 6)   # external axes beyond the limits
        assert not mod.speed_ok([0.0, 2.0], [0.0, 0.0], [1.0, 1.0])


def test_the_cell_bound_loops_compiled_and_as_python_give_the_same_bits():
    """robot/cellproof.py, compiled and as Python, on four KR 6 R900 0.8 m apart in a row at 30
    random poses: each reference's gaps and levers (``measure``), ``least`` of the gaps, the
    deepest pair of each robot pair beyond 2 mm (``deepest``) and the first row of a random walk
    from it left unproved (``Prover.first_unproved``, with every pair's limit and with one's):
    the same bits and rows."""
    fast, slow = _pure(cellproof)
    machine = load_machine()
    scene = CellScene([Placement(f"R{k + 1}", machine, (800.0 * k, 0, 0, 0, 0, 0)) for k in range(4)])
    bound = scene.bound()
    flat, joints, geoms = bound.hinge
    # each geom's columns its robot's (its levers' span): six a robot, in the robots' order
    spans = ((scene._robot_of * 6).astype(np.intp), (scene._robot_of * 6 + 6).astype(np.intp))
    rng = np.random.default_rng(404)
    held, rows = 0, set()
    for _ in range(30):
        q = np.concatenate([scene.scale(n) * (np.array([0, -90, 90, 0, 0, 0]) + rng.uniform(-80, 80, 6))
                            for n in scene.names])
        scene.place(q)
        d = scene.data
        out = []
        for mod in (fast, slow):
            prover = mod.Prover(bound.near, bound.far, bound.half, bound.reach, flat, joints, geoms, bound.slide,
                                LEVER_SLACK_M2, *spans, np.empty(bound.columns), np.empty(bound.ngeom),
                                np.empty(len(bound.near), dtype=np.intp))
            gaps, levers = np.empty(len(bound.near)), np.empty(bound.ngeom * bound.columns)
            prover.measure(d.geom_xpos, d.geom_xmat, d.xanchor, d.xaxis, gaps, levers)
            deep = [mod.deepest(gaps, bound.exact, a, b, 0.002) for a, b in bound.groups.values()]
            walk = q + np.cumsum(rng.normal(0.0, 0.002, (200, len(q))), axis=0) if not out else out[0][4]
            limits = np.abs(gaps) + 0.01
            one = np.where(np.arange(len(gaps)) == len(gaps) // 2, limits, np.inf)     # one pair's two bounds a row
            row = [prover.first_unproved(levers.reshape(bound.ngeom, -1), q, walk, 3, lim) for lim in (limits, one)]
            out.append((gaps.tobytes(), levers.tobytes(), mod.least(gaps), deep, walk, row))
        assert out[0][:4] == out[1][:4] and out[0][5] == out[1][5]
        held += sum(k >= 0 for k in out[0][3])
        rows.update(out[0][5])
    assert held > 5 and len(rows) > 5, (held, rows)


def _segments(machine, program, kind=segments.CartSegment):
    """The segments of class `kind` (the CP segments by default) a controller plans for `program`
    (a list of MotionRequest)."""
    segs = []
    orig = motionqueue.plan

    def keep(*a, **kw):
        seg = orig(*a, **kw)
        if isinstance(seg, kind):
            segs.append(seg)
        return seg

    motionqueue.plan = keep
    try:
        run_motions(Controller(machine, mujoco=False), program)
    finally:
        motionqueue.plan = orig
    return segs


@pytest.mark.parametrize("robot", ["kr6", "kr210"])
def test_the_compiled_cp_path_is_the_segments_poses_and_axes(sc, robot, shared_corpus):
    machine = None if robot == "kr6" else load_robot(str(shared_corpus / "HugoDanielson__ChinaMilling"))
    P = MotionParams.initmov(machine)
    k = machine.reach_wrist_point_mm / 901.456 if machine is not None else 1.0
    const = P.with_(ori_type="CONSTANT")
    turn = {"X": 500 * k, "Y": 100 * k, "Z": 650 * k, "A": 20.0, "B": 10.0, "C": 170.0}
    program = bench_program(machine) + [
        MotionRequest("LIN", turn, P),                                   # the orientation changes
        MotionRequest("LIN", {"X": 450 * k, "Y": -100 * k, "Z": 600 * k}, const),
        MotionRequest("CIRC", {"X": 450 * k, "Y": 100 * k, "Z": 600 * k}, const,
                      aux={"X": 400 * k, "Y": 0.0, "Z": 600 * k})]
    segs = _segments(machine, program)
    rng = np.random.default_rng(44)
    mirrored = compared = chains = slerps = 0
    for seg in segs:
        cp = seg._compiled_path()
        assert cp, "the compiled path is not used"
        us = np.concatenate([[-0.1, 0.0, 1.0, 1.2], rng.uniform(0.0, 1.0, 200)])
        for u in us.tolist():
            got = cp.pose_u(u)
            seg._c_path = False
            want = seg.pose_u(u)
            seg._c_path = cp
            k, f = seg._locate(u)
            turning = seg.ori[k] == "VAR" and seg._R_still[k] is None and 0.0 < f < 1.0
            if got is None:
                assert not turning      # a #VAR slerp is computed compiled too (issue 86)
                continue
            mirrored += 1
            slerps += turning
            assert got[0].tobytes() == np.asarray(want[0]).tobytes() and got[1].tobytes() == np.asarray(want[1]).tobytes()
            if seg.compiled_inverse():
                ref = seg.q0 + rng.normal(0.0, 2.0, 6)
                q = cp.axes_u(u, seg.status, ref)
                try:
                    expect = seg.ik(*want, ref).tobytes()
                except RobotError:
                    expect = None
                assert (q.tobytes() if q is not None else None) == expect
                compared += q is not None
        if seg.compiled_inverse():
            ups = np.sort(rng.uniform(0.0, 1.0, 40))
            chain = cp.chain_u(ups, seg.status, seg.q0)
            ref, rows = seg.q0, []
            for u in ups.tolist():
                seg._c_path = False
                ref = seg.ik(*seg.pose_u(u), ref)
                seg._c_path = cp
                rows.append(ref)
            if all(cp.pose_u(u) is not None for u in ups.tolist()):
                assert chain is not None and chain.tobytes() == np.array(rows).tobytes()
                chains += 1
            else:                  # a pose the Python code computes (a slerp): the caller's
                assert chain is None
    assert mirrored > 500 and (compared > 500 or robot == "kr210") and chains > 3 and slerps > 100


@pytest.mark.parametrize("frames", ["tool", "base", "both"])
def test_the_compiled_cp_path_solves_through_base_and_tool_as_the_python_code(sc, frames):
    """A CP motion with $TOOL and $BASE (a milling program's LINs: issue 62, the CAM-like
    program) solves its poses in C through ``$BASE @ T @ INV_POS($TOOL)`` (CartPath.use_frames,
    numpy's BLAS at its address): the same axes, bit for bit, and the same None where the Python
    code raises, as ``RobotModel.ik``; the planning walk's chains as pose-by-pose solutions."""
    if not numpy_cblas("dgemm"):
        pytest.skip("numpy without its bundled OpenBLAS: the compiled path solves only poses as they stand")
    tool = (10.0, -20.0, 150.0, 270.0, 0.0, 0.0) if frames != "base" else NULLFRAME
    base = (600.0, -50.0, 300.0, 15.0, 0.0, 180.0) if frames != "tool" else NULLFRAME
    P = MotionParams.initmov(None).with_(tool=tool, base=base)
    q = [10.0, -80.0, 100.0, 10.0, 40.0, 20.0]
    T0 = inv_pos(frame_to_matrix(*base)) @ Kinematics().forward(q) @ frame_to_matrix(*tool)
    start = dict(zip("XYZABC", matrix_to_frame(T0)))
    program = [MotionRequest("PTP", {f"A{i + 1}": v for i, v in enumerate(q)}, P)]
    for i in range(12):       # a circle of short LINs, C_VEL, as the CAM-like program's
        a = math.radians(30.0 * i)
        program.append(MotionRequest("LIN", {**start, "X": start["X"] + 40.0 * math.cos(a) - 40.0,
                                              "Y": start["Y"] + 40.0 * math.sin(a), "A": start["A"] + (5.0 if i >= 9 else 0.0)},
                                     P, approx="C_VEL"))
    segs = _segments(None, program)
    rng = np.random.default_rng(62)
    compared = raised = chains = 0
    for seg in segs:
        if seg.path_length <= 0:
            continue
        assert seg.compiled_solver() and not seg.compiled_inverse() and seg._c_framed
        cp = seg._compiled_path()
        for u in rng.uniform(0.0, 1.0, 60).tolist():
            p, R = seg.pose_u(u)
            ref = seg.q0 + rng.normal(0.0, 2.0, 6)
            if compared % 7 == 0:
                p = p + rng.normal(0.0, 5000.0 if compared % 14 == 0 else 1.0, 3)   # some out of reach
            got = cp.solve_rp(R, p, seg.status, ref)
            seg._c_path = False
            try:
                want = seg.ik(p, R, ref).tobytes()
            except RobotError:
                want = None
                raised += 1
            seg._c_path = cp
            assert (got.tobytes() if got is not None else None) == want
            compared += 1
        ups = np.sort(rng.uniform(0.0, 1.0, 20))
        chain = cp.chain_u(ups, seg.status, seg.q0)
        seg._c_path = False
        ref, rows = seg.q0, []
        for u in ups.tolist():
            ref = seg.ik(*seg.pose_u(u), ref)
            rows.append(ref)
        seg._c_path = cp
        if chain is not None:
            assert chain.tobytes() == np.array(rows).tobytes()
            chains += 1
    assert compared > 500 and raised > 10 and chains > 5


def _plan_bytes(req, q, model):
    """What a plan decides, as bytes (or the error it raises)."""
    try:
        seg = planner.plan(req, q, model)
    except RobotError as exc:
        return f"{type(exc).__name__}: {exc}"
    prof = seg.profile
    taus = np.linspace(0.0, prof.t_total, 9) if math.isfinite(prof.t_total) else []
    return b"".join(np.asarray(x, dtype=float).tobytes() for x in (
        seg.q1, seg.vel_peak, seg.acc_peak, seg.qd_start, seg.qd_end, [prof.t_total, seg.v_prog],
        [prof.u(t) for t in taus], [prof.du(t) for t in taus]))


def _drawn_cp_motions(rng, n, model):
    """(request, start axes) of drawn CP motions: LINs from 0.05 mm (a CAM program's) to 600 mm,
    with and without a turn of the orientation, CIRCs, SLIN splines (corners), $TOOL and $BASE
    or not, $VEL.CP and $ACC.CP drawn; some out of reach."""
    out = []
    reach = float(np.linalg.norm(model.kin.forward(np.zeros(6))[:3, 3])) / 1000.0   # m
    for i in range(n):
        tool = (10.0, -20.0, 150.0, 270.0, 0.0, 0.0) if i % 4 in (1, 3) else NULLFRAME
        base = (600.0, -50.0, 300.0, 15.0, 0.0, 180.0) if i % 4 in (2, 3) else NULLFRAME
        P = MotionParams.initmov(None).with_(tool=tool, base=base)
        P = P.with_(vel_cp=float(rng.choice([0.02, 0.2, 2.0])), acc_cp=float(rng.choice([0.5, 2.3, 10.0])))
        q = np.array([rng.uniform(-120, 120), rng.uniform(-110, -50), rng.uniform(60, 130),
                      rng.uniform(-60, 60), rng.uniform(-100, 100) if i % 9 else rng.uniform(-3, 3),
                      rng.uniform(-150, 150)])
        T0 = inv_pos(frame_to_matrix(*base)) @ model.kin.forward(q) @ frame_to_matrix(*tool)
        start = dict(zip("XYZABC", matrix_to_frame(T0)))

        def moved(scale):
            d = rng.normal(0.0, 1.0, 3)
            d *= scale / np.linalg.norm(d)
            t = {**start, "X": start["X"] + d[0], "Y": start["Y"] + d[1], "Z": start["Z"] + d[2]}
            if rng.uniform() < 0.4:
                t[str(rng.choice(["A", "B", "C"]))] += float(rng.normal(0.0, 40.0))
            return t

        scale = float(rng.choice([0.05, 0.7, 20.0, 150.0, 600.0])) * reach
        kind = ("LIN", "LIN", "CIRC", "SPLINE")[i % 4 if i % 3 else 0]
        if kind == "LIN":
            req = MotionRequest("LIN", moved(scale), P, approx="C_VEL" if i % 2 else None)
        elif kind == "CIRC":
            req = MotionRequest("CIRC", moved(scale), P, aux=moved(scale / 2))
        else:
            segs = [MotionRequest("SLIN", moved(scale * (k + 1)), P) for k in range(3)]
            req = MotionRequest("SPLINE", {}, P, segments=segs)
        out.append((req, q))
    return out


@pytest.mark.parametrize("robot", ["kr6", "kr3_r540"])
def test_the_compiled_planning_walk_is_the_python_walk_bit_for_bit(sc, monkeypatch, robot):
    """The planning walk of a CP motion's pieces in C (robot/cartpath.py ``CartPath.walk``: the
    samples, the chain of axes, the finer resolution, the derivatives and the speed and
    acceleration limits; issue 62, the CAM-like program) plans what the Python walk plans, bit
    for bit, on drawn motions (the KR 3 R540 keeps $ACC.CP: its axis accelerations were
    identified, robot/identified.py), and raises the same errors."""
    model = Controller(None if robot == "kr6" else load_robot(robot), mujoco=False).model
    motions = _drawn_cp_motions(np.random.default_rng(6202), 60, model)
    walker, samples = cartlaw._compiled_walker, cartlaw._samples
    walked, sampled = [], []
    monkeypatch.setattr(planner, "_planned_line", lambda *a: None)    # every LIN through plan_cart's walk

    def counting(seg):
        w = walker(seg)
        return None if w is None else (lambda *a: walked.append(w(*a)) or walked[-1])

    monkeypatch.setattr(cartlaw, "_compiled_walker", counting)
    compiled, in_c = [], []
    for req, q in motions:
        n = len(walked)
        compiled.append(_plan_bytes(req, q, model))
        in_c.append(any(w is not None for w in walked[n:]))
    monkeypatch.setattr(cartlaw, "_compiled_walker", lambda seg: None)
    monkeypatch.setattr(cartlaw, "_samples", lambda a, b, n: sampled.append(n) or samples(a, b, n))
    python, finer = [], []
    for req, q in motions:
        del sampled[:]
        python.append(_plan_bytes(req, q, model))
        finer.append(any(b > a for a, b in zip(sampled, sampled[1:])))
    assert compiled == python
    done = [w for w in walked if w is not None]
    # walked in C: short and long pieces, some at a finer resolution; errors raised alike
    assert len(done) > 30 and sum(c and f for c, f in zip(in_c, finer)) > 8
    assert sum(isinstance(b, str) for b in python) >= 5
    assert any(w[-1] is None for w in done) == (robot == "kr3_r540")


def _same(a, b) -> bool:
    """Are a and b the same values bit for bit (arrays: dtype, shape and bytes; floats: their bits;
    lists, tuples, dicts and plain objects: element by element and attribute by attribute)?"""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (type(a) is type(b) and a.dtype == b.dtype and a.shape == b.shape
                and a.tobytes() == b.tobytes() and a.flags.writeable == b.flags.writeable)
    if isinstance(a, float) or isinstance(b, float):
        return type(a) is type(b) and a.hex() == b.hex()
    if isinstance(a, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict):
        return type(a) is type(b) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (pathpieces.LinePiece, Trapezoid)):
        return type(a) is type(b) and _same(vars(a), vars(b))
    return a is b or a == b


def _drawn_lines(rng, n, model):
    """(request, start axes) of drawn single LINs to complete targets: a CAM program's (0.01 to
    2 mm, the orientation kept) to 600 mm, some turning the orientation (a slerp: the Python
    plan), some of zero length or out of reach, with $TOOL and $BASE or not, #VAR and
    #CONSTANT, $VEL.CP, $ACC.CP and $OV_PRO drawn."""
    out = []
    reach = float(np.linalg.norm(model.kin.forward(np.zeros(6))[:3, 3]))
    for i in range(n):
        tool = (10.0, -20.0, 150.0, 270.0, 0.0, 0.0) if i % 4 in (1, 3) else NULLFRAME
        base = (600.0, -50.0, 300.0, 15.0, 0.0, 180.0) if i % 4 in (2, 3) else NULLFRAME
        P = MotionParams.initmov(None).with_(
            tool=tool, base=base, vel_cp=float(rng.choice([0.02, 0.2, 2.0])), acc_cp=float(rng.choice([0.5, 2.3, 10.0])),
            ov_pro=float(rng.choice([100.0, 100.0, 37.0])), ori_type="CONSTANT" if i % 17 == 5 else "VAR")
        q = np.array([rng.uniform(-120, 120), rng.uniform(-110, -50), rng.uniform(60, 130),
                      rng.uniform(-60, 60), rng.uniform(-100, 100) if i % 9 else rng.uniform(-3, 3),
                      rng.uniform(-150, 150)])
        T0 = inv_pos(frame_to_matrix(*base)) @ model.kin.forward(q) @ frame_to_matrix(*tool)
        t = dict(zip("XYZABC", matrix_to_frame(T0)))
        d = rng.normal(0.0, 1.0, 3)
        d *= float(rng.choice([0.0, 0.01, 0.3, 2.0, 50.0, 0.3 * reach, 0.8 * reach])) / np.linalg.norm(d)
        t.update(X=t["X"] + d[0], Y=t["Y"] + d[1], Z=t["Z"] + d[2])
        if i % 5 == 4:
            t[str(rng.choice(["A", "B", "C"]))] += float(rng.choice([1e-9, 0.5, 40.0]))
        out.append((MotionRequest("LIN", t, P, approx="C_VEL" if i % 2 else None), q))
    return out


@pytest.mark.parametrize("robot", ["kr6", "kr3_r540"])
def test_the_compiled_line_plan_is_the_python_plan_bit_for_bit(sc, monkeypatch, robot):
    """A single LIN planned in C (robot/cartline.py ``_planned_line``, robot/cartpath.py
    ``plan_line``: the set-up of its segment, its tables, its compiled path and its walk; issue 62,
    the CAM-like program) is the segment the Python code plans, attribute by attribute, bit for bit
    (its compiled path gives the same poses and axes), on drawn LINs; those it leaves to the Python
    code (an orientation that turns, #CONSTANT, a zero length) and the errors are the Python code's."""
    model = Controller(None if robot == "kr6" else load_robot(robot), mujoco=False).model
    motions = _drawn_lines(np.random.default_rng(6206), 80, model)
    line, planned = cartline._planned_line, []
    monkeypatch.setattr(planner, "_planned_line", lambda *a: planned.append(line(*a)) or planned[-1])

    def planned_or_error(req, q):
        try:
            return planner.plan(req, q, model)
        except RobotError as exc:
            return f"{type(exc).__name__}: {exc}"

    compiled = [planned_or_error(req, q) for req, q in motions]
    in_c = [p is not None for p in planned]
    monkeypatch.setattr(planner, "_planned_line", lambda *a: None)
    python = [planned_or_error(req, q) for req, q in motions]
    for c, p in zip(compiled, python):
        if isinstance(p, str):
            assert c == p
            continue
        cp, pp = c._c_path, p._c_path
        assert _same({k: v for k, v in vars(c).items() if k != "_c_path"},
                     {k: v for k, v in vars(p).items() if k != "_c_path"})
        assert c._R is c.rots and (c._ik_tool is None or c._ik_tool is c.tool_inv_T)
        assert (cp is None) == (pp is None) and (cp is False) == (pp is False)
        for u in np.linspace(0.0, 1.0, 7).tolist() if cp else ():     # the same poses and axes
            a, b = cp.pose_u(u), pp.pose_u(u)
            assert _same(a, b) and _same(cp.axes_u(u, c.status, c.q0), pp.axes_u(u, p.status, p.q0))
            # the distance to the end in C (CartPath.dist_to), as norm3 of the pose's
            assert c.tcp_dist_to_end(u).hex() == planmemo.norm3(p.pose_u(u)[0] - c.pieces[-1].pos(c.path_length)).hex()
    assert 30 < sum(in_c) < len(motions) - 10
    assert sum(isinstance(p, str) for p in python) >= 3


def _same_paths(c, p, status, q0, rng, blas):
    """Do the CartPaths c (compiled) and p (robot/cartpath.py as Python, its inverse fastpath.py's) give
    the same bits: poses, axes, chains, distances, flange poses, solutions, a blend's setpoint over
    themselves and walks with drawn arguments?"""
    gemm, ddot = blas
    for u in [-0.1, 0.0, 1.0, 1.3, *rng.uniform(0.0, 1.0, 8).tolist()]:
        ref, end = q0 + rng.normal(0.0, 2.0, 6), rng.normal(0.0, 500.0, 3)
        assert _same(c.pose_u(u), p.pose_u(u)) and _same(c.axes_u(u, status, ref), p.axes_u(u, status, ref))
        assert _same(c.dist_to(u, end, ddot), p.dist_to(u, end, ddot))
        us = rng.uniform(0.0, 1.0, 2).tolist()
        assert _same(c.superposed(c, u, *us, status, ref, gemm), p.superposed(p, u, *us, status, ref, gemm))
        R, pos = frame_to_matrix(*rng.uniform(-180.0, 180.0, 6))[:3, :3].copy(), rng.uniform(-900.0, 900.0, 3)
        assert _same(c.flange_rp(R, pos), p.flange_rp(R, pos))
        assert _same(c.solve_rp(R, pos, status, ref), p.solve_rp(R, pos, status, ref))
    ups = np.sort(rng.uniform(0.0, 1.0, 6))
    assert _same(c.chain_u(ups, status, q0), p.chain_u(ups, status, q0))
    walked = 0
    for plain in (True, False):
        u0, u1 = sorted(rng.uniform(0.0, 1.0, 2).tolist())
        args = (u0, u1, int(rng.integers(2, 12)), status, q0, 49, float(rng.uniform(0.5, 1.0)), plain,
                rng.uniform(100.0, 400.0, 6), rng.uniform(200.0, 900.0, 6), float(rng.uniform(0.5, 3.0)), 30.0,
                float(rng.choice([0.5, 5.0])), 48)
        got = c.walk(*args)
        assert _same(got, p.walk(*args))
        walked += got is not None
    return walked


def test_cartpath_as_python_is_itself_compiled_bit_for_bit(sc, monkeypatch):
    """robot/cartpath.py is one source (issue 76 item 5): run as Python, with fastpath.py's inverse
    as Python, it gives the bits of its compiled build: ``plan_line`` on drawn single LINs (with
    $TOOL and $BASE or not) and each ``CartPath`` the planner makes (those LINs', and LINs',
    CIRCs' and splines' of robot/segments.py ``_cart_path``, through $BASE and $TOOL by
    ``use_frames`` or not), method by method on drawn arguments; and the set-up products."""
    py = kinematics.compiled.pure_python(sc)
    assert py.__file__.endswith("cartpath.py") and not py.COMPILED and sc.COMPILED
    model = Controller(None, mujoco=False).model
    core = model.kin.impl.solver.python_core()
    assert not isinstance(core, type(model.kin.compiled_core()))
    lines, paths = [], []

    class Path(sc.CartPath):                    # the compiled CartPath, its arguments kept
        def __init__(self, *a):
            super().__init__(*a)
            paths.append([a, self, None, None])

        def use_frames(self, *a):
            paths[-1][2] = a
            super().use_frames(*a)

        def use_turns(self, *a):
            paths[-1][3] = a
            super().use_turns(*a)

    def plan_line(*a):
        lines.append((a, sc.plan_line(*a)))
        return lines[-1][1]

    rec = type(sys)("recorded")
    rec.__dict__.update({k: getattr(sc, k) for k in ("line_products", "superpose_products")},
                        CartPath=Path, plan_line=plan_line)
    monkeypatch.setattr(kinematics, "compiled_module", lambda: rec)
    rng = np.random.default_rng(7605)
    for req, q in _drawn_lines(rng, 16, model) + _drawn_cp_motions(rng, 8, model):
        try:
            planner.plan(req, q, model)
        except RobotError:
            pass
    monkeypatch.undo()
    blas = segments._line_blas(sc)
    planned = walked = 0
    for a, got in lines:
        want = py.plan_line(core, *a[1:])
        assert (got is None) == (want is None)
        if got is not None:
            planned += 1
            assert _same(got[:11] + got[12:], want[:11] + want[12:])
            walked += _same_paths(got[11], want[11], a[14], a[15], rng, blas)
    for a, cp, frames, turns in paths:
        p = py.CartPath(core if a[0] is not None else None, *a[1:])
        if frames is not None:
            p.use_frames(*frames)
        if turns is not None:           # the slerps within #VAR pieces (issue 86)
            p.use_turns(*turns)
        walked += _same_paths(cp, p, None, rng.uniform(-90.0, 90.0, 6), rng, blas)
    assert planned > 5 and len(paths) > 3 and any(f is not None for _, _, f, _t in paths) and walked > 10
    assert any(t is not None for _, _, _f, t in paths)
    A, B, C = (frame_to_matrix(*rng.uniform(-500.0, 500.0, 6))[:3, :3].copy() for _ in range(3))
    v = rng.normal(0.0, 1.0, 3)
    assert _same(sc.line_products(*blas, A, B, v), py.line_products(*blas, A, B, v))
    assert _same(sc.superpose_products(blas[0], A, B, C), py.superpose_products(blas[0], A, B, C))


def test_the_compiled_blend_setpoint_is_the_pythons(sc, monkeypatch):
    """A Cartesian blend's setpoint in C (robot/blending.py ``_superposed``, robot/cartpath.py
    ``CartPath.superposed``: the three poses, their overlap with numpy's products, the next
    motion's inverse; issue 62, the CAM-like program) is ``blend_setpoint``'s Python one bit for
    bit, on drawn pairs of LINs at drawn times of both, with $TOOL and $BASE or not."""
    model = Controller(None, mujoco=False).model
    rng = np.random.default_rng(6209)
    pairs = []
    for req, q in _drawn_lines(rng, 120, model):
        try:
            a = planner.plan(req, q, model)
            back = {k: v - 3.0 * rng.uniform() if k in "XY" else v for k, v in dict(
                zip("XYZABC", matrix_to_frame(a.model.tcp(a.q1, a.tool_T, a.base_inv_T)))).items()}
            b = planner.plan(replace(req, target=back), a.q1, model)
        except RobotError:
            continue
        if a.T > 0 and b.T > 0 and blending.blend_space(a, b) == "cart":
            pairs.append((a, b))
    compiled, python, in_c = [], [], 0
    for a, b in pairs:
        for _ in range(6):
            t_a, t_b = float(rng.uniform(0.0, a.T)), float(rng.uniform(0.0, b.T))
            ref = a.q1 + rng.normal(0.0, 1.0, 6)
            in_c += blending._superposed(a, t_a, b, t_b, model, ref) is not None
            for out, off in ((compiled, False), (python, True)):
                if off:
                    monkeypatch.setattr(blending, "_superposed", lambda *x: None)
                try:
                    out.append(blending.blend_setpoint(a, t_a, b, t_b, "cart", model, ref).tobytes())
                except RobotError as exc:
                    out.append(str(exc))
                monkeypatch.undo()
    assert compiled == python and in_c > 100 and len(pairs) > 30


def test_the_compiled_blend_plan_is_the_pythons(sc, monkeypatch):
    """A blend between two CP motions planned in C from its braking on (robot/blending.py
    ``_cart_blend``: robot/lawtable.py's braking check, CartPath.dist_to, lawtable's blend end and
    ramp; issue 62, the CAM-like program) is ``plan_blend``'s Python plan bit for bit (the time
    laws attribute by attribute, the window), on drawn pairs of CP motions (LINs, CIRCs; the
    approximated one ramped in from a blend before it or not) at drawn blend starts."""
    model = Controller(None, mujoco=False).model
    rng = np.random.default_rng(6210)
    pairs = []
    for req, q in _drawn_cp_motions(rng, 160, model):
        if req.kind == "SPLINE":
            continue
        try:
            a = planner.plan(req, q, model)
            back = {k: v - 5.0 * rng.uniform() if k in "XY" else v for k, v in dict(
                zip("XYZABC", matrix_to_frame(a.model.tcp(a.q1, a.tool_T, a.base_inv_T)))).items()}
            b = planner.plan(replace(req, kind="LIN", target=back, aux=None), a.q1, model)
        except RobotError:
            continue
        if a.T > 0 and b.T > 0:
            if rng.uniform() < 0.5:         # ramped in from a blend before it
                a.profile = RampProfile(a.profile, float(rng.uniform(0.0, 0.3)), float(rng.choice([0.0, 0.01])))
            pairs.append((a, b))
    plans, in_c, none = {True: [], False: []}, 0, 0
    for a, b in pairs:
        for tau in rng.uniform(0.0, a.T, 5).tolist():
            got = blending._cart_blend(a, b, BrakeProfile(a.profile, tau), 1.0)
            in_c += got is not None
            for compiled in (True, False):
                if not compiled:
                    monkeypatch.setattr(blending, "_cart_blend", lambda *x: None)
                bp = blending.plan_blend(a, b, "C_DIS", tau)
                monkeypatch.undo()
                none += bp is None
                plans[compiled].append(None if bp is None else (
                    bp.window, bp.space, vars(bp.prev_profile), vars(bp.next_profile)))
    assert all(_same(x, y) for x, y in zip(plans[True], plans[False]))
    assert in_c > 200 and len(pairs) > 40 and none > 0


def _drawn_time_laws(rng, n):
    """Drawn time laws of blends (robot/profiles.py): trapezoids and triangles, ramps onto them
    (with and without a delay, a ramp of length 0), braking from them, braking from a ramp."""
    laws = []
    for i in range(n):
        trap = Trapezoid.plan(float(rng.uniform(0.05, 30.0)), float(rng.uniform(0.5, 400.0)))
        ramp = RampProfile(trap, float(rng.choice([0.0, rng.uniform(0.0, 0.6)])),
                           float(rng.choice([0.0, rng.uniform(0.0, 0.2)])))
        laws.append((trap, ramp, BrakeProfile(trap, float(rng.uniform(0.0, trap.t_total))),
                     BrakeProfile(ramp, float(rng.uniform(0.0, ramp.t_total))))[i % 4])
    return laws


def test_the_blend_speed_check_on_tables_is_the_time_laws():
    """A blend's check of its braking and its ramp against a planned time law held as a table
    (robot/lawtable.py ``below``, compiled and as Python; issue 62, the CAM-like program) answers
    as robot/blending.py ``_below`` on the time law objects themselves (robot/profiles.py's
    methods), on drawn time laws with speed laws set within a few bits of the limit at a sample,
    both ways (the table's speeds must be the law's bits for the answers to agree)."""
    mods = _pure(lawtable)
    rng = np.random.default_rng(6203)
    answers = []
    for base in _drawn_time_laws(rng, 400):
        table = blending.profile_table(base)
        assert table is not None
        u0 = float(rng.choice([0.0, rng.uniform(0.0, 0.9)]))
        u1 = float(rng.choice([1.0, rng.uniform(u0, 1.0)]))
        points = [i * ((u1 - u0) / 25) + u0 for i in range(1, 25)]
        limits = [base.du(base.t_of_u(x)) * (1.0 + 1e-6) + 1e-12 for x in points]
        # the speed laws that touch the limit at one sample: a constant speed (a braking of 0)
        # at the lowest limit, the ramp whose a_r the samples allow
        v_min = min(limits)
        a_min = min(lim * lim / (2.0 * x) for lim, x in zip(limits, points))
        for bits in (-2, -1, 0, 1, 2):
            v, a_r = v_min, a_min
            for _ in range(abs(bits)):
                v = math.nextafter(v, math.inf if bits > 0 else -math.inf)
                a_r = math.nextafter(a_r, math.inf if bits > 0 else -math.inf)
            for law, p in ((blending.RAMP_LAW, (a_r, 0.0, 0.0)), (blending.BRAKE_LAW, (v, 0.0, 0.0)),
                           (blending.BRAKE_LAW, (v, 0.3 * v * v, 0.5 * (u0 + u1)))):
                python = blending._below(
                    (lambda x, p=p: math.sqrt(2.0 * p[0] * x)) if law == blending.RAMP_LAW else
                    (lambda x, p=p: math.sqrt(max(0.0, p[0] ** 2 - 2.0 * p[1] * (x - p[2])))), base, u0, u1)
                for mod in mods:
                    assert mod.below(law, *p, table, getattr(base, "bounds", ()), u0, u1) is python
                answers.append(python)
    assert 0.2 < sum(answers) / len(answers) < 0.8
    assert blending.profile_table(object()) is None


def test_the_ramp_of_a_blend_on_tables_is_the_time_laws(monkeypatch):
    """The next motion's ramp of a blend (robot/blending.py ``_ramp``: the bisection of its length
    within the window, then of a shorter ramp where it would exceed the planned speed) on a time
    law held as a table (robot/lawtable.py ``ramp_args``, compiled and as Python; issue 62, the
    CAM-like program) is the ramp ``_ramp`` finds on the time law objects themselves bit for bit,
    on drawn time laws, blend ends and windows, every branch taken."""
    compiled_lt, python_lt = _pure(lawtable)
    rng = np.random.default_rng(6207)
    cases = []
    for base in _drawn_time_laws(rng, 600):
        u_max = float(rng.choice([0.0, -0.1, 1.0, rng.uniform(0.0, 1.0), rng.uniform(0.0, 0.05)]))
        tau_p = float(rng.choice([0.0, rng.uniform(0.0, 0.2), rng.uniform(0.0, 2.0)]) * base.t_total)
        cases.append((base, u_max, tau_p))
    compiled = [vars(blending._ramp(*c)) for c in cases]
    monkeypatch.setattr(kinematics.compiled, "USE_COMPILED", False)
    assert kinematics.compiled.pure_module(lawtable) is python_lt and compiled_lt is not python_lt
    as_python = [vars(blending._ramp(*c)) for c in cases]
    monkeypatch.setattr(blending, "profile_table", lambda prof: None)      # the time law objects
    python = [vars(blending._ramp(*c)) for c in cases]
    assert all(_same(a, b) and _same(c, b) for a, c, b in zip(compiled, as_python, python))
    # the branches: no ramp, the whole window, a shorter ramp bisected, a ramp the speed check shortened
    rt = [2.0 * u / b.du(b.t_of_u(u)) if u > 0 and b.du(b.t_of_u(u)) > 0 else 0.0 for b, u, _ in cases]
    kinds = [0 if u <= 0 else 1 if r <= t else 2 for (_, u, t), r in zip(cases, rt)]
    shortened = [p["u_e"] < u and k == 1 for p, (_, u, _), k in zip(python, cases, kinds)]
    assert min(kinds.count(0), kinds.count(1), kinds.count(2), sum(shortened)) >= 10


def test_norm3_is_numpys_norm_bit_for_bit():
    """robot/planmemo.py ``norm3`` (a CP segment's lengths and distances) is ``np.linalg.norm``
    on drawn float64 vectors from 1e-160 to 1e150 (squares underflowing to subnormals), and zero."""
    rng = np.random.default_rng(6204)
    for i in range(4000):
        v = rng.normal(0.0, 1.0, 3) * 10.0 ** rng.uniform(-160, 150) if i % 50 else np.zeros(3)
        assert planmemo.norm3(v).hex() == float(np.linalg.norm(v)).hex()


def test_the_trace_is_the_same_with_and_without_the_compiled_module(sc, fast, monkeypatch):
    """The whole compiled path (inverse, CP poses, the IPO cycle, pose lines) against the
    Python code on a random sequence of robot/tracecheck.py: the same bytes."""
    compiled = tracecheck.run_case("random-05")
    monkeypatch.setattr(kinematics.compiled, "USE_COMPILED", False)
    monkeypatch.setattr(trace, "_POSE", kinematics.compiled.pure_python(poseline))
    assert tracecheck.run_case("random-05") == compiled


def test_the_compiled_tcp_product_is_numpys_matmul():
    """The read-back's INV_POS($BASE) : FLANGE : $TOOL in numpy's own BLAS call: numpy's
    ``@`` bit for bit (a C loop in the textbook order differs in the last bit: numpy's
    OpenBLAS fuses multiply and add)."""
    if not _numpy_dgemm():
        pytest.skip("numpy without its bundled OpenBLAS: numpy multiplies")
    cyc = ArmModel().ipo_cycle(_pure(ipocycle)[0])
    rng = np.random.default_rng(45)
    out, F, qa = np.empty((4, 4)), np.empty((4, 4)), np.empty(6)
    for i in range(5000):
        cyc.cycle(rng.uniform(-170.0, 170.0, 6), qa, F)
        tool = np.eye(4) if i % 3 == 0 else frame_to_matrix(*rng.uniform(-200.0, 200.0, 6))
        base_inv = np.eye(4) if i % 4 == 0 else inv_pos(frame_to_matrix(*rng.uniform(-900.0, 900.0, 6)))
        assert cyc.product(base_inv, F, tool, out)
        assert out.tobytes() == (base_inv @ F @ tool).tobytes(), i
    with pytest.raises(ValueError):                   # not C-contiguous: the caller's numpy
        cyc.product(np.eye(4).T[:, ::-1], F, np.eye(4), out)
    cyc.use_gemm(0)
    assert cyc.product(np.eye(4), F, np.eye(4), out) is False


def _scipy_forward(j, a):
    """The flange of the rotary JointChain `j` at the axes `a` (deg) in numpy and scipy: each
    joint's ``Rotation.from_rotvec(axis * sign * radians(A)).as_matrix()``, chained by ``@``."""
    Rj = Rotation.from_rotvec(j.axes * (j.kuka_sign * np.radians(a))[:, None]).as_matrix()
    R, p = np.eye(3), np.zeros(3)
    for i in range(j.n):
        p = p + R @ j.origins[i]
        if j.origin_rot:
            R = R @ j.R_origin[i]
        R = R @ Rj[i]
    T = np.eye(4)
    T[:3, :3] = R @ j.R_flange
    T[:3, 3] = p + R @ j.p_flange
    return T


def test_the_forward_compiled_and_as_python_is_numpys_and_scipys_bit_for_bit(shared_corpus):
    """Kinematics.forward through robot/ipocycle.py ``Forward`` compiled (numpy's own BLAS
    products) and as Python (JointChain.forward_py) against numpy's and scipy's forward kinematics
    (:func:`_scipy_forward`): the same bytes on random axes of the library's robots, of a corpus
    KR 210 and of a chain with rotated joint origins (500 axis sets each in make test; make nightly
    draws 40 times as many: tests/budget.py)."""
    if not numpy_cblas("dgemm") or not numpy_cblas("dgemv"):
        pytest.skip("numpy without its bundled OpenBLAS: numpy multiplies")
    _pure(ipocycle)
    kins = [Kinematics(load_mada(p)) for p in library_robots().values() if p.suffix == ".dat"]
    kins = [k for k in kins if k.n_axes == 6]         # the compiled product is of six rotary joints
    kins += [Kinematics(), Kinematics(load_robot(str(shared_corpus / "HugoDanielson__ChinaMilling")))]
    rot = Kinematics()
    rot.joints.R_origin = Rotation.from_euler("xyz", np.random.default_rng(3).normal(size=(6, 3))).as_matrix()
    rot.joints.origin_rot = True
    kins.append(rot)
    rng = np.random.default_rng(47)
    T = np.empty((4, 4))
    for k in kins:
        c = k.joints._compiled()
        assert c, k.machine.name
        for i in range(examples(500)):
            a = rng.uniform(k._lo, k._hi)
            if i % 5 == 0:
                a = np.round(a, 1)
            if i % 7 == 0:
                a[rng.integers(0, 6)] = 0.0 if i % 2 else -0.0
            if i % 11 == 0:
                a *= 1e-5                                # the small-angle series of from_rotvec
            c.forward(a, T)
            want = _scipy_forward(k.joints, a).tobytes()
            assert T.tobytes() == want, (k.machine.name, a.tolist())
            if i % 10 == 0:
                assert k.joints.forward_py(a).tobytes() == want, (k.machine.name, a.tolist())
    assert kins[-1].forward(np.zeros(6)).tobytes() == _scipy_forward(rot.joints, np.zeros(6)).tobytes()


def test_the_palletizer_rows_compiled_and_as_python_are_numpys_selection():
    """The 4-axis palletizer's solutions (robot/kinematics/pal4rows.py, compiled and as Python on
    fastpath.py's OPW core as Python) are the rows of the OPW core whose flange numpy's forward
    kinematics puts within 1e-6 mm of the target, bit for bit, on linked configurations of the
    library palletizer, with tilted flanges, targets off the arm's reach and no reference; the
    module's own flange test tells the rows apart by millimetres."""
    compiled_mod, python_mod = _pure(pal4rows)
    m = load_mada(ROBOT_LIBRARY / "kr180_r3200_pa.dat")
    compiled, python = Kinematics(m), Kinematics(m)
    python.impl._rows = python.impl.make_rows()[0]
    if compiled.impl.solver.compiled:
        python.impl._rows = python_mod.Palletizer4Rows(python.impl.solver.python_core(), *_pal_args(python.impl))
        assert type(compiled.impl.make_rows()[0]).__module__ == compiled_mod.__name__
    home = compiled._home
    rng = np.random.default_rng(48)
    found = empty = 0
    for _ in range(400):
        q = rng.uniform(compiled._lo, compiled._hi)
        q[3] = 0.0
        q[4] = home[4] + home[1] + home[2] - q[1] - q[2]
        T = compiled.forward(q)
        if rng.random() < 0.3:
            T[:3, :3] = T[:3, :3] @ Rotation.from_rotvec(rng.normal(size=3) * 0.01).as_matrix()
        if rng.random() < 0.2:
            T[:3, 3] += rng.normal(size=3) * 300.0
        ref = None if rng.random() < 0.2 else rng.uniform(compiled._lo, compiled._hi)
        a, b = compiled.impl.solutions(T, ref), python.impl.solutions(T, ref)
        want = python.impl.numpy_rows(T, ref)
        assert np.array(a).tobytes() == np.array(b).tobytes() == np.array(want).tobytes(), (q.tolist(), ref)
        found += bool(a)
        empty += not a
        for row in a:                                 # the module's own flange test: within 1e-6 mm
            assert np.abs(np.array(compiled.impl._rows.flange_position(row)) - T[:3, 3]).max() < 1e-6
    assert found > 250 and empty > 3


def _pal_args(impl):
    """Palletizer4Rows's arguments after the core, of the palletizer family `impl`."""
    j = impl.kin.joints
    return (j.origins.tolist(), j.axes.tolist(), j.kuka_sign.tolist(), j.R_origin.tolist(), j.origin_rot,
            j.R_flange.tolist(), j.p_flange.tolist(), impl.pa[0].tolist(), impl.pa[1].tolist())
