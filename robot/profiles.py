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
from bisect import bisect_right
from dataclasses import dataclass
from typing import Any

from . import lawtable
from .kinematics.compiled import pure_module

#: robot/lawtable.py's trapezoid, compiled where built (resolved once, at import: the same numbers
#: either way), :class:`Trapezoid`'s time law: one source with the blend checks' tables
_LAW = pure_module(lawtable)


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

    @property
    def t_brake(self) -> float:
        """Duration of the final braking phase, s (= ``t_acc``)."""
        return self.t_acc

    def u(self, t: float) -> float:
        """Path parameter at time ``t`` (clamped to [0, T]; robot/lawtable.py ``trapezoid_u``)."""
        return _LAW.trapezoid_u(self.t_total, self.t_acc, self.a, self.v, t)

    def du(self, t: float) -> float:
        """Normalised speed du/dt at time ``t`` (1/s; robot/lawtable.py ``trapezoid_du``)."""
        return _LAW.trapezoid_du(self.t_total, self.t_acc, self.a, self.v, t)

    def t_of_u(self, u: float) -> float:
        """Inverse of :meth:`u`: the time at which the parameter reaches ``u`` (clamped;
        robot/lawtable.py ``trapezoid_t_of_u``)."""
        return _LAW.trapezoid_t_of_u(self.t_total, self.t_acc, self.a, self.v, u)

    def t_of_speed_in_decel(self, fraction_of_v: float, v_ref: float) -> float:
        """First time in the deceleration phase at which du/dt <= ``fraction_of_v·v_ref``
        (C_VEL, §6.8). ``v_ref`` is the programmed normalised speed (1/s)."""
        target = fraction_of_v * v_ref
        if target >= self.v:
            return self.t_dec
        return self.t_total - target / self.a if self.a > 0 else self.t_total


def _acc_gain(x: float) -> float:
    """``-x - log(1 - x)`` (0 <= x < 1), by its series where it would cancel."""
    if x < 1e-3:
        return x * x * (0.5 + x * (1.0 / 3.0 + x * (0.25 + x * 0.2)))
    return -x - math.log1p(-x)


def _dec_gain(x: float) -> float:
    """``x - log(1 + x)`` (x >= 0), by its series where it would cancel."""
    if x < 1e-3:
        return x * x * (0.5 + x * (-1.0 / 3.0 + x * (0.25 - x * 0.2)))
    return x - math.log1p(x)


def _acc_path(y: float) -> float:
    """``y - 1 + exp(-y)`` (y >= 0), by its series where it would cancel."""
    if y < 1e-3:
        return y * y * (0.5 + y * (-1.0 / 6.0 + y * (1.0 / 24.0 - y / 120.0)))
    return y + math.expm1(-y)


def _dec_path(z: float) -> float:
    """``exp(z) - 1 - z`` (z >= 0), by its series where it would cancel."""
    if z < 1e-3:
        return z * z * (0.5 + z * (1.0 / 6.0 + z * (1.0 / 24.0 + z / 120.0)))
    return math.expm1(z) - z


class FrictionProfile:
    """Normalised time law u(t) on [0, T] of an axis whose acceleration depends on its speed
    (issue 60): a KR C4 plans a PTP with its dynamic model, in which the torque an axis has for
    accelerating is its acceleration torque less its friction, which grows with the speed. The
    real KR 3 R540's wrist axes at 10 % ``$ACC_AXIS`` show it plainly: A4 starts at 1 900 °/s²
    and accelerates at 300 °/s² by 400 °/s, then brakes at 3 500 °/s² (the friction helps):
    ``a = A - c_a·v`` while accelerating, ``|a| = A + c_d·v`` while braking (KUKA Trace
    recordings A4/A5/A6_PTP_ACC_10, tools/identify_kr3.py; docs/robot.md "PTP timing").

    Accelerate from rest with ``du'' = A - c_a·du`` to the speed ``V`` (or to the peak speed
    that leaves room to brake), cruise, brake with ``du'' = -(A + c_d·du)`` to rest at
    ``u = 1``. With ``c_a = c_d = 0`` this is :class:`Trapezoid`. A speed at or above
    ``A/c_a`` cannot be reached: ``V`` is held below it (:data:`REACH`). ``a_brake`` (``D``,
    default ``A``): the braking's rate at rest, ``|a| = D + c_d·v``: a robot's dynamic model gives
    a PTP another torque budget braking than starting, gravity helping one and hindering the other
    (robot/dynamics.py; issue 73). Same interface as :class:`Trapezoid` (``v``: the peak speed,
    ``a``: ``A``, ``a_peak``: the largest acceleration, the braking's at the peak speed)."""

    #: the fraction of the speed ``A/c_a`` the axis cruises at when ``V`` is not below it
    REACH = 0.999

    def __init__(self, v_max: float, a_max: float, c_acc: float, c_dec: float, a_brake: float | None = None) -> None:
        D = float(a_max if a_brake is None else a_brake)
        if not (v_max > 0.0 and a_max > 0.0 and D > 0.0 and c_acc >= 0.0 and c_dec >= 0.0):
            raise ValueError(f"profile limits must be positive (v={v_max}, a={a_max}, {D}, c={c_acc}, {c_dec})")
        A, ca, cd = float(a_max), float(c_acc), float(c_dec)
        self.d = D
        V = float(v_max)
        if ca > 0.0:
            V = min(V, self.REACH * A / ca)
        self.a, self.c_acc, self.c_dec = A, ca, cd
        if self._d_acc(V) + self._d_dec(V) <= 1.0:
            vp = V
        else:
            lo, hi = 0.0, V
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                if self._d_acc(mid) + self._d_dec(mid) < 1.0:
                    lo = mid
                else:
                    hi = mid
            vp = 0.5 * (lo + hi)
        self.v = vp
        self.t_acc = self._t_acc(vp)
        self.t_brake = self._t_dec(vp)
        self._u_acc = self._d_acc(vp)
        self._u_dec = 1.0 - self._d_dec(vp)
        cruise = max(0.0, self._u_dec - self._u_acc) / vp if vp > 0 else 0.0
        self.t_dec = self.t_acc + cruise
        self.t_total = self.t_dec + self.t_brake
        self.a_start = A
        self.a_peak = max(A, D + cd * vp)

    # the phases: time and distance from rest to the speed v (accelerating), from v to rest
    def _t_acc(self, v: float) -> float:
        A, ca = self.a, self.c_acc
        return v / A if ca * v < 1e-12 * A else -math.log1p(-ca * v / A) / ca

    def _t_dec(self, v: float) -> float:
        A, cd = self.d, self.c_dec
        return v / A if cd * v < 1e-12 * A else math.log1p(cd * v / A) / cd

    def _d_acc(self, v: float) -> float:
        A, ca = self.a, self.c_acc
        return v * v / (2.0 * A) if ca == 0.0 else A / (ca * ca) * _acc_gain(ca * v / A)

    def _d_dec(self, v: float) -> float:
        A, cd = self.d, self.c_dec
        return v * v / (2.0 * A) if cd == 0.0 else A / (cd * cd) * _dec_gain(cd * v / A)

    def u(self, t: float) -> float:
        T = self.t_total
        if t <= 0.0:
            return 0.0
        if t >= T:
            return 1.0
        A = self.a
        if t < self.t_acc:
            ca = self.c_acc
            return 0.5 * A * t * t if ca == 0.0 else A / (ca * ca) * _acc_path(ca * t)
        if t <= self.t_dec:
            return self._u_acc + self.v * (t - self.t_acc)
        r = T - t
        cd, D = self.c_dec, self.d
        return 1.0 - (0.5 * D * r * r if cd == 0.0 else D / (cd * cd) * _dec_path(cd * r))

    def du(self, t: float) -> float:
        T = self.t_total
        if t <= 0.0 or t >= T:
            return 0.0
        A = self.a
        if t < self.t_acc:
            ca = self.c_acc
            return A * t if ca == 0.0 else -A / ca * math.expm1(-ca * t)
        if t <= self.t_dec:
            return self.v
        r = T - t
        cd, D = self.c_dec, self.d
        return D * r if cd == 0.0 else D / cd * math.expm1(cd * r)

    def t_of_u(self, u: float) -> float:
        if u <= 0.0 or self.t_total == 0.0:
            return 0.0
        if u >= 1.0:
            return self.t_total
        if self._u_acc <= u <= self._u_dec and self.v > 0:
            return self.t_acc + (u - self._u_acc) / self.v
        lo, hi = (0.0, self.t_acc) if u < self._u_acc else (self.t_dec, self.t_total)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if self.u(mid) < u:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    def t_of_speed_in_decel(self, fraction_of_v: float, v_ref: float) -> float:
        """First time in the braking phase at which du/dt <= ``fraction_of_v·v_ref``."""
        target = fraction_of_v * v_ref
        if target >= self.v:
            return self.t_dec
        return self.t_total - self._t_dec(target)


class PiecewiseProfile:
    """Normalised time law u(t) over sections with their own limits (issue 15: spline
    blocks slowed at corners, CP paths slowed for the axes).

    Section ``j`` covers ``u`` in ``[bounds[j], bounds[j+1]]`` with speed limit ``vmax[j]``
    (1/s) and acceleration limit ``amax[j]`` (1/s²); ``vnode[j]`` limits du/dt at the
    junction ``bounds[j]`` (0 at both ends). A forward and a backward pass make the junction
    speeds reachable; every section is then a trapezoid from its entry to its exit speed
    (accelerate, cruise, decelerate), so the speed is continuous and the acceleration of
    each section stays within its limit. With one section this is :class:`Trapezoid`.

    Same interface as :class:`Trapezoid`: ``u``, ``du``, ``t_of_u``,
    ``t_of_speed_in_decel``, ``t_total``, ``t_acc`` (first acceleration phase, s),
    ``t_brake`` (final braking phase, s), ``v`` (peak speed), ``a`` (final braking
    acceleration). Raises ValueError for non-positive limits.
    """

    def __init__(self, bounds: list[float], vmax: list[float], amax: list[float],
                 vnode: list[float] | None = None) -> None:
        m = len(vmax)
        if len(bounds) != m + 1 or len(amax) != m:
            raise ValueError("profile: bounds must have one more entry than vmax/amax")
        if any(not (v > 0 and a > 0) for v, a in zip(vmax, amax)):
            raise ValueError("profile limits must be positive")
        L = [max(0.0, bounds[j + 1] - bounds[j]) for j in range(m)]
        vn = [0.0] + [math.inf] * (m - 1) + [0.0]
        if vnode is not None:
            for j in range(1, m):
                vn[j] = max(0.0, float(vnode[j]))
        for j in range(1, m):
            vn[j] = min(vn[j], vmax[j - 1], vmax[j])
        for j in range(m):  # forward
            reach = 2.0 * amax[j] * L[j] if L[j] > 0 else 0.0
            vn[j + 1] = min(vn[j + 1], math.sqrt(vn[j] ** 2 + reach))
        for j in range(m - 1, -1, -1):  # backward
            reach = 2.0 * amax[j] * L[j] if L[j] > 0 else 0.0
            vn[j] = min(vn[j], math.sqrt(vn[j + 1] ** 2 + reach))
        t0: list[float] = []
        u0: list[float] = []
        v0: list[float] = []
        acc: list[float] = []
        dur: list[float] = []
        t = 0.0
        peak = 0.0

        def add(du_: float, vs: float, a_: float, d_: float) -> None:
            nonlocal t
            if d_ <= 0.0:
                return
            t0.append(t)
            u0.append(du_)
            v0.append(vs)
            acc.append(a_)
            dur.append(d_)
            t += d_

        for j in range(m):
            if L[j] <= 0.0:
                continue
            a, vi, vo = amax[j], vn[j], vn[j + 1]
            vp = min(vmax[j], math.sqrt(max(0.0, (2.0 * a * L[j] + vi * vi + vo * vo) / 2.0)))
            vp = max(vp, vi, vo)
            d1 = (vp * vp - vi * vi) / (2.0 * a)
            d3 = (vp * vp - vo * vo) / (2.0 * a)
            d2 = max(0.0, L[j] - d1 - d3)
            u = bounds[j]
            add(u, vi, a, (vp - vi) / a)
            u += d1
            add(u, vp, 0.0, d2 / vp if vp > 0 else 0.0)
            u += d2
            add(u, vp, -a, (vp - vo) / a)
            peak = max(peak, vp)
        self._t0, self._u0, self._v0, self._acc, self._dur = t0, u0, v0, acc, dur
        self._end = float(bounds[-1])
        self.t_total = t
        self.v = peak
        self.t_acc = dur[0] if acc and acc[0] > 0 and v0[0] == 0.0 else 0.0
        self.t_brake = dur[-1] if acc and acc[-1] < 0 else 0.0
        self.a = -acc[-1] if acc and acc[-1] < 0 else (acc[0] if acc else 0.0)
        self.a_start = acc[0] if acc and acc[0] > 0 else self.a
        self.t_dec = t - self.t_brake
        self.vnode = vn
        self.bounds = [float(b) for b in bounds]

    def _phase(self, t: float) -> int:
        return max(0, bisect_right(self._t0, t) - 1)

    def u(self, t: float) -> float:
        if self.t_total == 0.0 or t >= self.t_total:
            return 1.0
        if t <= 0.0:
            return 0.0
        k = self._phase(t)
        tau = min(t - self._t0[k], self._dur[k])
        return min(1.0, self._u0[k] + self._v0[k] * tau + 0.5 * self._acc[k] * tau * tau)

    def du(self, t: float) -> float:
        if t <= 0.0 or t >= self.t_total:
            return 0.0
        k = self._phase(t)
        tau = min(t - self._t0[k], self._dur[k])
        return max(0.0, self._v0[k] + self._acc[k] * tau)

    def t_of_u(self, u: float) -> float:
        if u <= 0.0 or self.t_total == 0.0:
            return 0.0
        if u >= 1.0:
            return self.t_total
        k = max(0, bisect_right(self._u0, u) - 1)
        d = u - self._u0[k]
        v0, a = self._v0[k], self._acc[k]
        disc = max(0.0, v0 * v0 + 2.0 * a * d)
        den = v0 + math.sqrt(disc)
        tau = 2.0 * d / den if den > 0 else self._dur[k]
        return self._t0[k] + min(tau, self._dur[k])

    def t_of_speed_in_decel(self, fraction_of_v: float, v_ref: float) -> float:
        """First time in the final braking phase at which du/dt <= ``fraction_of_v·v_ref``."""
        target = fraction_of_v * v_ref
        if not self._acc or self._acc[-1] >= 0:
            return self.t_total
        if target >= self._v0[-1]:
            return self._t0[-1]
        return self.t_total - target / self.a


class BrakeProfile:
    """The approximated motion of a blend (issue 15): ``base`` until ``t_a``, then a uniform
    deceleration from the state there ``(u_a, v_a)`` to rest at ``u = 1``.

    Braking over the whole remaining zone instead of at full ``A`` at its end: the
    deceleration ``v_a²/(2(1-u_a))`` is never larger than the base profile's (the base could
    stop in that distance), and it lasts ``2(1-u_a)/v_a`` s. Same interface as
    :class:`Trapezoid`."""

    def __init__(self, base: Any, t_a: float) -> None:
        self.base = base
        self.t_a = t_a
        self.u_a = base.u(t_a)
        self.v_a = base.du(t_a)
        rem = 1.0 - self.u_a
        if self.v_a <= 1e-12 or rem <= 1e-12:
            self.a_b, self.tau = 0.0, 0.0
        else:
            self.a_b = self.v_a * self.v_a / (2.0 * rem)
            self.tau = 2.0 * rem / self.v_a
        self.t_total = t_a + self.tau if self.tau > 0 else max(t_a, 0.0)
        if self.tau <= 0 and self.u_a < 1.0:
            self.t_total = base.t_total
        self.v = base.v
        self.a = self.a_b if self.tau > 0 else base.a
        self.a_start = getattr(base, "a_start", base.a)
        self.t_acc = base.t_acc
        self.t_brake = self.tau if self.tau > 0 else getattr(base, "t_brake", base.t_acc)
        self.t_dec = self.t_total - self.t_brake
        self.bounds = getattr(base, "bounds", [0.0, 1.0])

    def u(self, t: float) -> float:
        if self.tau <= 0:
            return self.base.u(t)
        if t <= self.t_a:
            return self.base.u(t)
        if t >= self.t_total:
            return 1.0
        s = t - self.t_a
        return min(1.0, self.u_a + self.v_a * s - 0.5 * self.a_b * s * s)

    def du(self, t: float) -> float:
        if self.tau <= 0 or t <= self.t_a:
            return self.base.du(t)
        if t >= self.t_total:
            return 0.0
        return max(0.0, self.v_a - self.a_b * (t - self.t_a))

    def t_of_u(self, u: float) -> float:
        if self.tau <= 0 or u <= self.u_a:
            return self.base.t_of_u(u)
        if u >= 1.0:
            return self.t_total
        d = u - self.u_a
        den = self.v_a + math.sqrt(max(0.0, self.v_a * self.v_a - 2.0 * self.a_b * d))
        return self.t_a + (2.0 * d / den if den > 0 else self.tau)

    def t_of_speed_in_decel(self, fraction_of_v: float, v_ref: float) -> float:
        if self.tau <= 0:
            return self.base.t_of_speed_in_decel(fraction_of_v, v_ref)
        target = fraction_of_v * v_ref
        if target >= self.v_a:
            return self.t_a
        return self.t_total - target / self.a_b


class RampProfile:
    """The next motion of a blend (issue 15): at rest for ``delay`` s, then a uniform
    acceleration from rest to ``u_e``, arriving with the speed ``base`` has at ``u_e``, then
    ``base`` (shifted in time). The acceleration ``v_b²/(2·u_e)`` is never larger than the
    base profile's when ``u_e`` lies at or after the end of its acceleration phase. Same
    interface as :class:`Trapezoid`."""

    def __init__(self, base: Any, u_e: float, delay: float = 0.0) -> None:
        self.base = base
        self.delay = max(0.0, delay)
        t_b = base.t_of_u(u_e) if u_e > 0 else 0.0
        v_b = base.du(t_b) if u_e > 0 else 0.0
        if u_e <= 1e-12 or v_b <= 1e-12:
            self.u_e, self.tau, self.a_r = 0.0, 0.0, 0.0
            self.shift = self.delay
        else:
            self.u_e = u_e
            self.tau = 2.0 * u_e / v_b
            self.a_r = v_b / self.tau
            self.shift = self.delay + self.tau - t_b
        self.t_total = base.t_total + self.shift
        self.v = base.v
        self.a = base.a
        self.a_start = self.a_r if self.tau > 0 else getattr(base, "a_start", base.a)
        self.t_acc = self.delay + (self.tau if self.tau > 0 else base.t_acc)
        self.t_brake = getattr(base, "t_brake", base.t_acc)
        self.t_dec = self.t_total - self.t_brake
        self.bounds = getattr(base, "bounds", [0.0, 1.0])

    def u(self, t: float) -> float:
        if t <= self.delay:
            return 0.0 if self.t_total > 0 else 1.0
        if self.tau > 0 and t < self.delay + self.tau:
            s = t - self.delay
            return 0.5 * self.a_r * s * s
        return self.base.u(t - self.shift)

    def du(self, t: float) -> float:
        if t <= self.delay:
            return 0.0
        if self.tau > 0 and t < self.delay + self.tau:
            return self.a_r * (t - self.delay)
        return self.base.du(t - self.shift)

    def t_of_u(self, u: float) -> float:
        if u <= 0.0:
            return 0.0
        if self.tau > 0 and u < self.u_e:
            return self.delay + math.sqrt(2.0 * u / self.a_r)
        return self.base.t_of_u(u) + self.shift

    def t_of_speed_in_decel(self, fraction_of_v: float, v_ref: float) -> float:
        return self.base.t_of_speed_in_decel(fraction_of_v, v_ref) + self.shift
