"""Velocity profiles of the simulated controller (reference §6.6, §6.7).

KUKA uses an optimised higher-order profile; the reference allows a trapezoidal one
(§6.6 [U]). This module implements **one normalised trapezoidal profile** that every
motion uses:

* the path parameter ``u`` runs from 0 (start point) to 1 (end point);
* ``V`` is the highest allowed normalised speed (1/s) and ``A`` the highest normalised
  acceleration (1/s^2); both come from the *binding* component:

  - PTP (synchronised axes, §6.6): ``V = min_i v_i/|dq_i|`` and ``A = min_i a_i/|dq_i|`` over
    the moving axes, with ``v_i = $VEL_AXIS[i]% · $OV_PRO% · v_max_i`` and
    ``a_i = $ACC_AXIS[i]% · a_max_i``. Every axis follows ``q_i(t) = q0_i + u(t)·dq_i``, so
    all axes start, accelerate, cruise, decelerate and stop together; the axis that sets
    ``V`` (or ``A``) is the *leading axis*.
  - CP (LIN/CIRC, §6.7): ``V = min(v_cp·$OV_PRO%/L, v_ori·$OV_PRO%/θ)`` and
    ``A = min(a_cp/L, a_ori/θ)`` with the path length ``L`` (mm) and the orientation angle
    ``θ`` (deg); the slowest component determines the path speed.

* Trapezoid: accelerate with ``A`` to ``V``, cruise, decelerate with ``A``. When
  ``V²/A > 1`` the cruise phase vanishes (triangle, peak speed ``sqrt(A)``).
  Duration: ``T = 1/V + V/A`` (trapezoid) or ``T = 2/sqrt(A)`` (triangle). For a single
  axis this is the textbook ``T = d/v + v/a`` (``d ≥ v²/a``) or ``2·sqrt(d/a)``.

Times are in seconds; ``u`` is dimensionless.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Trapezoid:
    """Normalised trapezoidal profile u(t) on [0, T], u(0) = 0, u(T) = 1.

    Attributes:
        v: peak normalised speed reached (1/s), ``<= V`` requested.
        a: normalised acceleration (1/s^2).
        t_acc: duration of the acceleration phase (= deceleration phase), s.
        t_total: duration ``T``, s. Zero for a motion of length zero.
    """

    v: float
    a: float
    t_acc: float
    t_total: float

    @staticmethod
    def plan(v_max: float, a_max: float) -> "Trapezoid":
        """Profile for unit distance with speed limit ``v_max`` (1/s) and acceleration
        limit ``a_max`` (1/s^2). ``math.inf`` for both means a zero-length motion
        (T = 0). Raises ValueError for a non-positive limit."""
        if math.isinf(v_max) and math.isinf(a_max):
            return Trapezoid(0.0, 0.0, 0.0, 0.0)
        if not (v_max > 0.0 and a_max > 0.0):
            raise ValueError(f"profile limits must be positive (v={v_max}, a={a_max})")
        if math.isinf(a_max):
            a_max = 1e12
        if v_max * v_max / a_max >= 1.0 or math.isinf(v_max):
            t_acc = math.sqrt(1.0 / a_max)
            return Trapezoid(a_max * t_acc, a_max, t_acc, 2.0 * t_acc)
        t_acc = v_max / a_max
        return Trapezoid(v_max, a_max, t_acc, 1.0 / v_max + t_acc)

    @property
    def t_dec(self) -> float:
        """Time at which deceleration begins, s."""
        return self.t_total - self.t_acc

    def u(self, t: float) -> float:
        """Path parameter at time ``t`` (clamped to [0, T])."""
        T = self.t_total
        if T == 0.0:
            return 1.0
        if t <= 0.0:
            return 0.0
        if t >= T:
            return 1.0
        ta, a, v = self.t_acc, self.a, self.v
        if t < ta:
            return 0.5 * a * t * t
        if t <= T - ta:
            return 0.5 * a * ta * ta + v * (t - ta)
        r = T - t
        return 1.0 - 0.5 * a * r * r

    def du(self, t: float) -> float:
        """Normalised speed du/dt at time ``t`` (1/s)."""
        T = self.t_total
        if t <= 0.0 or t >= T:
            return 0.0
        if t < self.t_acc:
            return self.a * t
        if t <= T - self.t_acc:
            return self.v
        return self.a * (T - t)

    def t_of_u(self, u: float) -> float:
        """Inverse of :meth:`u`: the time at which the parameter reaches ``u`` (clamped)."""
        T = self.t_total
        if u <= 0.0 or T == 0.0:
            return 0.0
        if u >= 1.0:
            return T
        ta, a, v = self.t_acc, self.a, self.v
        u_acc = 0.5 * a * ta * ta
        if u <= u_acc:
            return math.sqrt(2.0 * u / a)
        if u <= 1.0 - u_acc:
            return ta + (u - u_acc) / v
        return T - math.sqrt(2.0 * (1.0 - u) / a)

    def t_of_speed_in_decel(self, fraction_of_v: float, v_ref: float) -> float:
        """First time in the deceleration phase at which du/dt <= ``fraction_of_v·v_ref``
        (C_VEL, §6.8). ``v_ref`` is the programmed normalised speed (1/s)."""
        target = fraction_of_v * v_ref
        if target >= self.v:
            return self.t_dec
        return self.t_total - target / self.a if self.a > 0 else self.t_total


def smoothstep(x: float) -> float:
    """C1 blend weight 3x² - 2x³ on [0, 1] (clamped); zero slope at both ends."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    return x * x * (3.0 - 2.0 * x)
