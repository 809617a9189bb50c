"""The conversions the planner and the forward kinematics keep by value (issue 39,
"Simulator": a program's cycle plans the same points again) give what the functions give, and
a kept result is never shared with a caller that could change it."""

from __future__ import annotations

import numpy as np

from robot import planmemo
from robot.frames import frame_to_matrix, matrix_to_frame
from robot.kinematics import FK_MEMO, Kinematics


def test_the_kept_frame_is_the_conversions_and_signed_zeros_are_apart():
    rng = np.random.default_rng(46)
    for _ in range(200):
        T = frame_to_matrix(*rng.uniform(-500.0, 500.0, 6))
        assert planmemo._frame_of(T) == matrix_to_frame(T)
        assert planmemo._frame_of(T.copy()) == matrix_to_frame(T)         # a hit: the same answer
    R = np.array([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]])
    Rm = R.copy()
    Rm[1, 0] = -0.0                              # atan2(-0.0, -1) is -pi, atan2(0.0, -1) pi
    assert planmemo._frame_of(R) == matrix_to_frame(R)
    assert planmemo._frame_of(Rm) == matrix_to_frame(Rm)


def test_the_kept_matrix_is_the_conversions_and_a_copy():
    f = (10.0, -0.0, 3.0, 90.0, -0.0, 180.0)
    g = (10.0, 0.0, 3.0, 90.0, 0.0, 180.0)
    for fr in (f, g, f):
        assert planmemo._matrix_of(fr).tobytes() == frame_to_matrix(*fr).tobytes()
    M = planmemo._matrix_of(f)
    M[0, 3] = 999.0                              # the caller's array: the kept one is not changed
    assert planmemo._matrix_of(f).tobytes() == frame_to_matrix(*f).tobytes()


def test_the_kept_flange_is_forwards_and_a_copy():
    k = Kinematics()
    q = np.array([10.0, -80.0, 95.0, 5.0, 40.0, -30.0])
    first = k.forward(q)
    first[0, 3] = 1e9
    again = k.forward(q)
    assert again[0, 3] != 1e9
    for i in range(FK_MEMO + 5):                 # past the bound: cleared, still the same numbers
        k.forward(q + i * 1e-3)
    fresh = Kinematics()
    fresh._fk_memo = {}
    assert k.forward(q).tobytes() == again.tobytes() == fresh.forward(q).tobytes()
