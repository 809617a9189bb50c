"""The PTP time law of an axis whose acceleration depends on its speed (robot/profiles.py
FrictionProfile, issue 60).

Expected values from first principles, not from the code under test: the motion obeys
``u'' = A - c_a·u'`` while accelerating and ``u'' = -(A + c_d·u')`` while braking, from rest at
u = 0 to rest at u = 1, at most at the speed V; here both phases are integrated numerically (RK4,
forward from the start and backward from the end) and the profile must meet them. Without
friction it is the textbook trapezoid (``T = 1/V + V/A`` or ``2/sqrt(A)``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.profiles import FrictionProfile, Trapezoid


def _rk4_phase(A: float, c: float, sign: float, h: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(u, v) after each of n steps of ``v' = A - sign·c·v``, ``u' = v`` from rest at u = 0
    (sign +1: accelerating from the start; -1: the braking run backward from the end)."""
    u, v = 0.0, 0.0
    us, vs = [0.0], [0.0]

    def f(v_: float) -> float:
        return A - sign * c * v_

    for _ in range(n):
        k1v, k1u = f(v), v
        k2v, k2u = f(v + 0.5 * h * k1v), v + 0.5 * h * k1v
        k3v, k3u = f(v + 0.5 * h * k2v), v + 0.5 * h * k2v
        k4v, k4u = f(v + h * k3v), v + h * k3v
        v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        u += h / 6 * (k1u + 2 * k2u + 2 * k3u + k4u)
        us.append(u)
        vs.append(v)
    return np.array(us), np.array(vs)


def _numeric_duration(V: float, A: float, ca: float, cd: float) -> float:
    """The time-optimal duration from the two integrations: accelerate while the speed is below
    V and below the braking curve's speed at the same u; cruise; brake."""
    h = 2e-4
    ua, va = _rk4_phase(A, ca, +1.0, h, 15_000)
    ud, vd = _rk4_phase(A, cd, -1.0, h, 15_000)
    # the braking curve as speed over u (u measured from the end): v_brake(u) = vd at 1 - u
    v_brake = np.interp(1.0 - ua, ud, vd)
    k = int(np.argmax((va >= v_brake) | (va >= V)))
    vp = min(float(va[k]), V)
    ka = int(np.searchsorted(va, vp))
    kd = int(np.searchsorted(vd, vp))
    cruise = max(0.0, 1.0 - ua[ka] - ud[kd]) / vp
    return ka * h + kd * h + cruise


@pytest.mark.parametrize("V,A,ca,cd", [(3.5, 15.5, 4.7, 4.7), (0.8, 3.0, 2.0, 3.0), (100.0, 20.0, 0.5, 0.5)])
def test_duration_is_the_integrated_motions(V, A, ca, cd):
    p = FrictionProfile(V, A, ca, cd)
    assert p.t_total == pytest.approx(_numeric_duration(V, A, ca, cd), abs=1e-3)   # the steps: 0.2 ms
    assert p.v <= V + 1e-12


@pytest.mark.parametrize("V,A", [(2.0, 5.0), (10.0, 5.0), (0.3, 40.0)])
def test_without_friction_it_is_the_trapezoid(V, A):
    p, t = FrictionProfile(V, A, 0.0, 0.0), Trapezoid.plan(V, A)
    assert p.t_total == pytest.approx(t.t_total, abs=1e-12)
    for x in np.linspace(0.0, t.t_total, 37):
        assert p.u(x) == pytest.approx(t.u(x), abs=1e-12)
        assert p.du(x) == pytest.approx(t.du(x), abs=1e-12)


def test_the_time_law_obeys_its_equations():
    V, A, ca, cd = 3.5, 15.5, 4.7, 3.1
    p = FrictionProfile(V, A, ca, cd)
    h = 1e-4
    for t in np.linspace(0.01, p.t_total - 0.01, 200):
        d2 = (p.u(t + h) - 2 * p.u(t) + p.u(t - h)) / (h * h)
        v = p.du(t)
        assert v == pytest.approx((p.u(t + h) - p.u(t - h)) / (2 * h), abs=1e-6)
        if abs(t - p.t_acc) < 2 * h or abs(t - p.t_dec) < 2 * h:
            continue
        if t < p.t_acc:
            assert d2 == pytest.approx(A - ca * v, abs=1e-3)
        elif t > p.t_dec:
            assert d2 == pytest.approx(-(A + cd * v), abs=1e-3)
        else:
            assert d2 == pytest.approx(0.0, abs=1e-3)
    assert p.u(0.0) == 0.0 and p.u(p.t_total) == 1.0
    assert p.du(0.0) == 0.0 and p.du(p.t_total) == 0.0
    # the inverse, and the braking phase's speeds (C_VEL)
    for u in np.linspace(0.001, 0.999, 50):
        assert p.u(p.t_of_u(u)) == pytest.approx(u, abs=1e-9)
    t = p.t_of_speed_in_decel(0.5, p.v)
    assert t >= p.t_dec and p.du(t) == pytest.approx(0.5 * p.v, rel=1e-9)


def test_a_speed_the_axis_cannot_reach_is_approached():
    # A/c_a = 2 < V: the axis tends to the speed 2 and cruises just below it
    p = FrictionProfile(5.0, 4.0, 2.0, 2.0)
    assert p.v == pytest.approx(FrictionProfile.REACH * 2.0, rel=1e-9) or p.v < 2.0
    assert p.v < 2.0
    assert math.isfinite(p.t_total) and p.u(p.t_total) == 1.0
