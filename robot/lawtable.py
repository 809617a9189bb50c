# cython: cdivision=True, wraparound=False
"""A blend's checks against a planned time law held as a table (robot/blending.py ``_below_law``,
``_ramp``, ``_cart_blend``), written once in Python and compiled by Cython from this very file
(the C types in lawtable.pxd beside it; robot/build.py ``PURE``): without a compiler it runs as it
stands (robot/kinematics/compiled.py ``pure_module`` picks the one in use).

The table: the time law and its bases as records of :data:`PROFILE_FIELDS` floats each
(robot/blending.py ``profile_table``, an ``array('d')``), a law's base after it, one trapezoid at
the bottom: ``Trapezoid`` (0, t_total, t_acc, a, v), ``RampProfile`` (1, delay, tau, u_e, a_r,
shift), ``BrakeProfile`` (2, tau, t_a, u_a, v_a, a_b, t_total) (robot/profiles.py). A record is
named by its first index ``i`` in the table; its base starts at ``i + PROFILE_FIELDS``. The
tables come from ``profile_table``, which makes only such tables (an index outside one raises
IndexError, compiled too).

* :func:`trapezoid_u`, :func:`trapezoid_du`, :func:`trapezoid_t_of_u`: the trapezoid's time law
  (robot/profiles.py ``Trapezoid`` calls them: one source);
* :func:`t_of_u`, :func:`du`, :func:`u`, :func:`t_total`: the time law's own functions of the
  record at ``i`` (robot/profiles.py's ``t_of_u``, ``du``, ``u``, ``t_total``: the same
  operations in the same order);
* :func:`below`: a blend's speed law against the time law (robot/blending.py ``_below``);
* :func:`ramp_args`: the next motion's ramp onto the time law (robot/blending.py ``_ramp``);
* :func:`blend_end_ramp`: the ramp of a Cartesian blend from its start distance on
  (robot/blending.py ``plan_blend``'s blend end and ramp);
* :func:`piece_of`: the piece of a path whose bounds hold a distance or a path parameter
  (robot/cartpath.py ``CartPath`` calls it too).

Units: s, and the path parameter u (dimensionless, 0 .. 1). Compiled and as Python the numbers
are the same: the operations of doubles in Python's order, libm's ``sqrt`` and ``pow`` (``**``
of Python's floats), no fused multiply-add (robot/build.py ``CFLAGS``), C's division
(``cdivision``: a division by zero gives inf or NaN compiled; no law the tables hold divides by
zero where it matters, robot/profiles.py's guards).
"""

import math
from array import array
from math import *  # noqa: F403  (sqrt, inf: libm's compiled, lawtable.pxd declares them as C's)

try:
    import cython
    COMPILED = cython.compiled
except ImportError:     # an install without Cython (a need of the build only): this file as Python
    COMPILED = False

# C ints compiled (lawtable.pxd), each given to Python under its public name below
_FIELDS = 7
_BRAKE = 0
_RAMP = 1
#: floats a record holds (module docstring)
PROFILE_FIELDS = _FIELDS
#: the speed laws :func:`below` checks: a blend's uniform braking ``sqrt(max(0, p0 ** 2 - 2 * p1 *
#: (u - p2)))`` (p0, p1, p2 = v_a, a_b, u_a), and a ramp ``sqrt(2 * p0 * u)`` (p0 = a_r)
BRAKE_LAW = _BRAKE
RAMP_LAW = _RAMP


def built_from() -> str:
    """The sha256 of lawtable.py and lawtable.pxd the compiled module was built from
    (robot/build.py embeds it); "" as Python."""
    if COMPILED:
        return pure_source_sha().decode("ascii")  # noqa: F821  (lawtable.pxd's C constant)
    return ""


def trapezoid_u(T, ta, a, v, t):
    """robot/profiles.py ``Trapezoid.u``: the path parameter at time t (s) of the trapezoid of
    duration T, acceleration phase ta (s), acceleration a (1/s^2) and peak speed v (1/s),
    clamped to [0, 1]."""
    if T == 0.0:
        return 1.0
    if t <= 0.0:
        return 0.0
    if t >= T:
        return 1.0
    if t < ta:
        return 0.5 * a * t * t
    if t <= T - ta:
        return 0.5 * a * ta * ta + v * (t - ta)
    r = T - t
    return 1.0 - 0.5 * a * r * r


def trapezoid_du(T, ta, a, v, t):
    """robot/profiles.py ``Trapezoid.du``: the speed du/dt (1/s) at time t (s) of the trapezoid
    (:func:`trapezoid_u`'s parameters)."""
    if t <= 0.0 or t >= T:
        return 0.0
    if t < ta:
        return a * t
    if t <= T - ta:
        return v
    return a * (T - t)


def trapezoid_t_of_u(T, ta, a, v, x):
    """robot/profiles.py ``Trapezoid.t_of_u``: the time (s) at which the trapezoid
    (:func:`trapezoid_u`'s parameters) reaches the path parameter x (clamped to [0, T])."""
    if x <= 0.0 or T == 0.0:
        return 0.0
    if x >= 1.0:
        return T
    u_acc = 0.5 * a * ta * ta
    if x <= u_acc:
        return sqrt(2.0 * x / a)
    if x <= 1.0 - u_acc:
        return ta + (x - u_acc) / v
    return T - sqrt(2.0 * (1.0 - x) / a)


def t_of_u(tab, i, x):
    """``t_of_u(x)`` (s) of the time law whose record starts at index i of `tab`."""
    while True:
        kind = tab[i]
        if kind == 0:
            return trapezoid_t_of_u(tab[i + 1], tab[i + 2], tab[i + 3], tab[i + 4], x)
        if kind == 1:
            if x <= 0.0:
                return 0.0
            if tab[i + 2] > 0 and x < tab[i + 3]:
                return tab[i + 1] + sqrt(2.0 * x / tab[i + 4])
            return t_of_u(tab, i + _FIELDS, x) + tab[i + 5]
        # a braking
        if tab[i + 1] <= 0 or x <= tab[i + 3]:
            i += _FIELDS
            continue
        if x >= 1.0:
            return tab[i + 6]
        d = x - tab[i + 3]
        r = tab[i + 4] * tab[i + 4] - 2.0 * tab[i + 5] * d
        den = tab[i + 4] + sqrt(r if r > 0.0 else 0.0)
        return tab[i + 2] + (2.0 * d / den if den > 0 else tab[i + 1])


def du(tab, i, t):
    """``du(t)`` (1/s) of the time law whose record starts at index i of `tab`."""
    while True:
        kind = tab[i]
        if kind == 0:
            return trapezoid_du(tab[i + 1], tab[i + 2], tab[i + 3], tab[i + 4], t)
        if kind == 1:
            if t <= tab[i + 1]:
                return 0.0
            if tab[i + 2] > 0 and t < tab[i + 1] + tab[i + 2]:
                return tab[i + 4] * (t - tab[i + 1])
            t = t - tab[i + 5]
            i += _FIELDS
            continue
        if tab[i + 1] <= 0 or t <= tab[i + 2]:
            i += _FIELDS
            continue
        if t >= tab[i + 6]:
            return 0.0
        r = tab[i + 4] - tab[i + 5] * (t - tab[i + 2])
        return r if r > 0.0 else 0.0


def t_total(tab, i):
    """``t_total`` (s) of the time law whose record starts at index i (a ramp's: its base's plus its shift)."""
    kind = tab[i]
    if kind == 0:
        return tab[i + 1]
    if kind == 1:
        return t_total(tab, i + _FIELDS) + tab[i + 5]
    return tab[i + 6]


def u(tab, i, t):
    """``u(t)`` of the time law whose record starts at index i of `tab`."""
    while True:
        kind = tab[i]
        if kind == 0:
            return trapezoid_u(tab[i + 1], tab[i + 2], tab[i + 3], tab[i + 4], t)
        if kind == 1:
            if t <= tab[i + 1]:
                return 0.0 if t_total(tab, i) > 0 else 1.0
            if tab[i + 2] > 0 and t < tab[i + 1] + tab[i + 2]:
                s = t - tab[i + 1]
                return 0.5 * tab[i + 4] * s * s
            t = t - tab[i + 5]
            i += _FIELDS
            continue
        if tab[i + 1] <= 0 or t <= tab[i + 2]:
            i += _FIELDS
            continue
        if t >= tab[i + 6]:
            return 1.0
        s = t - tab[i + 2]
        r = tab[i + 3] + tab[i + 4] * s - 0.5 * tab[i + 5] * s * s
        return r if r < 1.0 else 1.0


def below(law, p0, p1, p2, tab, bounds, u0, u1):
    """robot/blending.py ``_below``: True when the speed law `law` (:data:`BRAKE_LAW` or
    :data:`RAMP_LAW`, parameters p0, p1, p2) stays below the time law `tab`'s speed (within 1e-6
    relative and 1e-12) at 24 points evenly between u0 and u1 and at the section bounds `bounds`
    (floats) strictly between them."""
    if u1 <= u0:
        return True
    va2 = 0.0
    if law == _BRAKE:
        va2 = math.pow(p0, 2.0)      # libm's pow, as Python's p0 ** 2 (never folded into p0 * p0)
    step = (u1 - u0) / 25
    nb = len(bounds)
    for k in range(1, 25 + nb):
        if k < 25:
            x = k * step + u0
        else:
            x = bounds[k - 25]
            if not (u0 < x < u1):
                continue
        vb = du(tab, 0, t_of_u(tab, 0, x))
        if law == _BRAKE:
            r = va2 - 2.0 * p1 * (x - p2)
            v = sqrt(r if r > 0.0 else 0.0)
        else:
            v = sqrt(2.0 * p0 * x)
        if v > vb * (1.0 + 1e-6) + 1e-12:
            return False
    return True


def ramp_time(tab, x):
    """robot/blending.py ``_ramp``'s ``ramp_time(x)`` (s): how long a uniform ramp takes to reach
    the time law `tab` at x, inf where the law stands."""
    if x <= 0:
        return 0.0
    v = du(tab, 0, t_of_u(tab, 0, x))
    return 2.0 * x / v if v > 0 else inf


def ramp_tau(tab, u_e):
    """``RampProfile(base, u_e).tau`` (s) of the time law ``base`` `tab`."""
    t_b = t_of_u(tab, 0, u_e) if u_e > 0 else 0.0
    v_b = du(tab, 0, t_b) if u_e > 0 else 0.0
    if u_e <= 1e-12 or v_b <= 1e-12:
        return 0.0
    return 2.0 * u_e / v_b


def ramp_rate(tab, u_e):
    """``RampProfile(base, u_e).a_r`` (1/s^2) of the time law ``base`` `tab` (0 where its ``tau`` is 0)."""
    t_b = t_of_u(tab, 0, u_e) if u_e > 0 else 0.0
    v_b = du(tab, 0, t_b) if u_e > 0 else 0.0
    if u_e <= 1e-12 or v_b <= 1e-12:
        return 0.0
    tau = 2.0 * u_e / v_b
    return v_b / tau


def ramp_args(tab, bounds, u_max, tau_p):
    """robot/blending.py ``_ramp``: (u_e, delay) of the ``RampProfile(base, u_e, delay)`` onto the
    time law `tab` (section bounds `bounds`) for the blend end ``u_max`` and the window ``tau_p``
    (s): as long as the window where the ramp can take that long (bisected where it cannot),
    shorter where it would exceed the planned speed (bisected)."""
    if u_max <= 0.0:
        u_e = 0.0
        delay = tau_p
    else:
        rt = ramp_time(tab, u_max)
        if rt <= tau_p:
            u_e = u_max
            delay = tau_p - rt
        else:
            lo = 0.0
            hi = u_max
            for it in range(40):
                mid = 0.5 * (lo + hi)
                if ramp_time(tab, mid) <= tau_p:
                    lo = mid
                else:
                    hi = mid
            u_e = lo
            delay = tau_p - ramp_time(tab, lo)
    if ramp_tau(tab, u_e) > 0 and not below(_RAMP, ramp_rate(tab, u_e), 0.0, 0.0, tab, bounds, 0.0, u_e):
        lo = 0.0          # a shorter ramp (at its shortest it is the planned acceleration)
        hi = u_e
        for it in range(30):
            mid = 0.5 * (lo + hi)
            if ramp_tau(tab, mid) <= 0 or below(_RAMP, ramp_rate(tab, mid), 0.0, 0.0, tab, bounds, 0.0, mid):
                lo = mid
            else:
                hi = mid
        d = tau_p - ramp_time(tab, lo)
        u_e = lo
        delay = d if d > 0.0 else 0.0
    return u_e, delay


def blend_end_ramp(tab, bounds, lengths, u_bounds, d_start, u_a, t_brake,
                   tau_p):
    """robot/blending.py ``plan_blend``'s blend end and ramp of the next CP motion (time law
    `tab`, section bounds `bounds`): the blend end ``u_max`` at ``blend_end_tau`` (the time law at
    the path's ``u_of_path(min(d_start, L / 2))``: `lengths` its m pieces' lengths (mm), `u_bounds`
    their m + 1 path parameters; at ``t_of_u(min(0.5, 1 - u_a))`` for a path of no length or a
    braking that starts at its point), no later than the braking `t_brake` (s) before the law's
    end, and :func:`ramp_args` for it within the window ``tau_p`` (s): (u_e, delay)."""
    m = len(lengths)
    s_bounds = array("d", [0.0]) * (m + 1)       # [0, *accumulate(lengths)]
    for k in range(m):
        s_bounds[k + 1] = lengths[k] if k == 0 else s_bounds[k] + lengths[k]
    L = s_bounds[m]
    if L <= 1e-9 or (d_start <= 1e-9 and u_a < 1.0):
        t_end = t_of_u(tab, 0, 0.5 if 0.5 < 1.0 - u_a else 1.0 - u_a)
    else:
        s = L / 2.0 if L / 2.0 < d_start else d_start
        if 0.0 > s:
            s = 0.0
        if L < s:
            s = L
        k = piece_of(s_bounds, m, s)
        Lk = lengths[k]
        f = (s - s_bounds[k]) / Lk if Lk > 0 else 1.0
        t_end = t_of_u(tab, 0, u_bounds[k] + f * (u_bounds[k + 1] - u_bounds[k]))
    u_max = u(tab, 0, t_end)
    t2 = t_total(tab, 0) - t_brake
    u2 = u(tab, 0, t2 if t2 > 0.0 else 0.0)
    if u2 < u_max:
        u_max = u2
    return ramp_args(tab, bounds, u_max, tau_p)


def piece_of(bounds, n, x):
    """``bisect_right(bounds, x) - 1`` over the n + 1 bounds of n pieces, clamped to 0 .. n - 1:
    the piece whose bounds hold x (robot/segments.py ``CartSegment._locate``, ``u_of_path``)."""
    lo = 0
    hi = n + 1
    while lo < hi:
        mid = (lo + hi) // 2
        if x < bounds[mid]:
            hi = mid
        else:
            lo = mid + 1
    lo -= 1
    if lo < 0:
        lo = 0
    if lo > n - 1:
        lo = n - 1
    return lo
