"""Approximate positioning (blending) between two planned segments (reference §6.8).

Model (documented in docs/robot.md, "Motion"):

* **Where the blend starts** — on the approximated segment, from the keyword valid for it:

  - ``C_DIS`` (CP): where the remaining path length to the programmed point equals
    ``d = min($APO.CDIS, L/2, L_next/2)``; the remaining straight-line distance is then at
    most ``d`` too.
  - ``C_ORI`` (CP): where the remaining orientation change equals ``min($APO.CORI, θ/2)``.
  - ``C_VEL`` (CP): in the deceleration phase, where the path speed falls to
    ``$APO.CVEL`` % of the programmed speed (not before the middle of the segment).
  - ``C_PTP`` (PTP): per axis ``d_i = min($APO.CPTP% · $APO_DIS_PTP[i], |Δq_i|/2,
    |Δq_next_i|/2)``; the blend starts when every axis is within its ``d_i``.
  - ``C_DIS`` on PTP (KSS 8 inline forms): where the TCP gets within ``$APO.CDIS`` of the
    point (found on the sampled TCP path, not before the middle).
  - ``C_SPL`` = ``C_PTP`` for SPTP, ``C_DIS`` otherwise; ``C_PTP`` on a CP motion is read as
    ``C_DIS``; ``C_VEL``/``C_ORI`` on a PTP as ``C_PTP``. ``PTP P C_PTP C_DIS``: the second
    keyword applies when the next motion is a CP motion.

* **Where it ends** — on the next segment, at the point whose distance from the start of
  that segment equals the blend-start distance (capped at half the next segment), or, for
  PTP→PTP with ``C_PTP``, with the per-axis rule and the ``$APO.CPTP`` of the *next* motion
  (KSS 8 per-point rule, reference §6.8).

* **Contour (issue 15)** — :func:`plan_blend`: from the blend start the approximated motion
  brakes uniformly through the rest of the zone and the next one ramps up uniformly to its
  blend end, both over the same window, and the two are overlapped (below), so the path
  speed never exceeds the faster programmed speed. The setpoint is the *overlap of the
  velocity profiles* ``x = x_prev(t) + (x_next(t) - P)`` (:func:`superpose_pose`; axis values
  for blends with a PTP side); the blend ends when the approximated motion reaches its point.
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass
from typing import Any

import numpy as np

from .blas import numpy_cblas
from .frames import frame_to_matrix
from . import lawtable
from .kinematics import compiled_module
from .kinematics.compiled import COMPILED_AXES, pure_module
from .planmemo import gradient_rows
from .segments import CartSegment, JointSegment, Segment, _line_blas
from .profiles import BrakeProfile, RampProfile, Trapezoid


def effective_keyword(prev: Segment, nxt: Segment | None) -> str | None:
    """The approximation keyword that governs the blend ``prev`` -> ``nxt``."""
    k = prev.req.approx
    if k is None:
        return None
    if not prev.cart and nxt is not None and nxt.cart and prev.req.approx2:
        k = prev.req.approx2
    if k == "C_SPL":
        k = "C_DIS" if prev.cart else "C_PTP"
    if prev.cart and k == "C_PTP":
        k = "C_DIS"
    if not prev.cart and k in ("C_VEL", "C_ORI"):
        k = "C_PTP"
    return k


def _ptp_fraction(seg: JointSegment, other: Segment | None, cptp: float) -> float:
    """min over moving axes of d_i/|Δq_i| (C_PTP per-axis rule); 0 if nothing moves."""
    dq = np.abs(seg.dq)
    moving = dq > 1e-9
    if not moving.any():
        return 0.0
    d = np.minimum(cptp / 100.0 * seg.model.apo_dis_ptp, dq / 2.0)
    if isinstance(other, JointSegment):
        odq = np.abs(other.dq)
        d = np.where(odq > 1e-9, np.minimum(d, odq / 2.0), d)
    return float(np.min(d[moving] / dq[moving]))


def blend_start_tau(prev: Segment, nxt: Segment | None, keyword: str) -> float | None:
    """Local time on ``prev`` (s) at which its approximation starts, or None when the
    segment cannot be approximated (zero duration, no TCP path for C_DIS, or a next motion
    of zero length). ``nxt`` may be None (not yet known): then the half-segment cap of the
    next motion is not applied."""
    if prev.T <= 0.0:
        return None
    if nxt is not None and nxt.T <= 0.0:
        return None  # a zero-length motion is never part of an approximation
    return _zone_start_tau(prev, nxt, keyword)


def _zone_start_tau(prev: Segment, nxt: Segment | None, keyword: str) -> float | None:
    """The earliest blend start (s) by the keyword's zone rule (module docstring)."""
    prof = prev.profile
    if keyword == "C_PTP":
        assert isinstance(prev, JointSegment)
        frac = _ptp_fraction(prev, nxt, prev.req.params.apo_cptp)
        return prof.t_of_u(1.0 - frac)
    if keyword == "C_VEL":
        t = prof.t_of_speed_in_decel(prev.req.params.apo_cvel / 100.0, prev.v_prog)
        return max(t, prof.t_of_u(0.5))
    if keyword == "C_ORI" and isinstance(prev, CartSegment):
        theta = prev.ori_angle
        if theta <= 1e-9:
            return prof.t_of_u(0.5)
        dth = min(prev.req.params.apo_cori, theta / 2.0)
        lo, hi = 0.5, 1.0  # smallest u with remaining angle <= dth
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            if prev.ori_angle_to_end(mid) <= dth:
                hi = mid
            else:
                lo = mid
        return prof.t_of_u(hi)
    # C_DIS
    d = prev.req.params.apo_cdis
    if isinstance(prev, CartSegment):
        L = prev.path_length
        d = min(d, L / 2.0)
        if nxt is not None:
            d = min(d, nxt.path_length / 2.0)
        if L <= 1e-9:  # no TCP path: a zero-length LIN/CIRC is never approximated
            return None
        return prof.t_of_u(prev.u_of_path(L - d))
    assert isinstance(prev, JointSegment)
    if prev.path_length <= 1e-9:  # the TCP does not move (wrist-only PTP)
        return prof.t_total
    if nxt is not None:
        d = min(d, nxt.path_length / 2.0)
    # the last of the 33 points of the segment's second half still farther than d from its end:
    # scanned back from the end, each point's distance made when the scan reaches it (the
    # zone is mostly a few of them; the same distances as made all at once)
    us = np.linspace(0.5, 1.0, 33)
    end = prev.end_pose()[0]
    k = len(us) - 1
    while k > 0 and prev.tcp_dist_to_end(float(us[k - 1]), end) <= d:
        k -= 1
    if k == 0:
        return prof.t_of_u(0.5)
    lo, hi = float(us[k - 1]), float(us[k])  # dist(lo) > d >= dist(hi)
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        if prev.tcp_dist_to_end(mid, end) <= d:
            hi = mid
        else:
            lo = mid
    return prof.t_of_u(hi)


def blend_end_tau(prev: Segment, nxt: Segment, keyword: str, tau_start: float) -> float:
    """Local time on ``nxt`` (s) at which the blend that started at ``tau_start`` on
    ``prev`` ends (see the module docstring)."""
    if nxt.T <= 0.0:
        return 0.0
    if keyword == "C_PTP" and isinstance(prev, JointSegment) and isinstance(nxt, JointSegment):
        frac = _ptp_fraction(nxt, prev, nxt.req.params.apo_cptp)
        return nxt.profile.t_of_u(frac)
    u_a = prev.profile.u(tau_start)
    d_start = prev.tcp_dist_to_end(u_a)
    L = nxt.path_length
    if L <= 1e-9 or (d_start <= 1e-9 and u_a < 1.0):
        # no TCP distance to measure with: the same fraction as left on the approximated motion
        return nxt.profile.t_of_u(min(1.0 - u_a, 0.5))
    return nxt.profile.t_of_u(nxt.u_of_path(min(d_start, L / 2.0)))


def _below(v_of_u: Any, base: Any, u0: float, u1: float) -> bool:
    """Is the speed law ``v_of_u`` (du/dt as a function of u) at or below the planned
    profile ``base`` on [u0, u1]? Checked on 24 points plus the base's section bounds."""
    if u1 <= u0:
        return True
    step = (u1 - u0) / 25          # numpy's linspace(u0, u1, 26)[1:-1], bit for bit, without numpy
    us = [i * step + u0 for i in range(1, 25)]
    us += [b for b in getattr(base, "bounds", ()) if u0 < b < u1]
    du, t_of_u = base.du, base.t_of_u
    for u in us:
        vb = du(t_of_u(float(u)))
        if v_of_u(float(u)) > vb * (1.0 + 1e-6) + 1e-12:
            # at a section bound the planned speed is the junction speed: compare with the
            # smaller of the speeds just before and after
            return False
    return True


#: the speed laws of a blend that :func:`_below_law` checks: the uniform braking of the
#: approximated motion, the uniform ramp of the next one (robot/lawtable.py)
BRAKE_LAW, RAMP_LAW = lawtable.BRAKE_LAW, lawtable.RAMP_LAW


def _below_law(law: int, p0: float, p1: float, p2: float, base: Any, u0: float, u1: float) -> bool:
    """:func:`_below` of a blend's speed law: :data:`BRAKE_LAW` ``sqrt(max(0, v_a² - 2·a_b·(u - u_a)))``
    (p0, p1, p2 = v_a, a_b, u_a of a ``BrakeProfile``) or :data:`RAMP_LAW` ``sqrt(2·a_r·u)`` (p0 =
    a_r of a ``RampProfile``); robot/lawtable.py ``below`` (compiled where built) for a time law
    `base` :func:`profile_table` reads (the same operations in the same order: the same answer)."""
    table = profile_table(base)
    if table is not None:
        return pure_module(lawtable).below(law, p0, p1, p2, table, getattr(base, "bounds", ()), u0, u1)
    if law == BRAKE_LAW:
        return _below(lambda u: math.sqrt(max(0.0, p0 ** 2 - 2.0 * p1 * (u - p2))), base, u0, u1)
    return _below(lambda u: math.sqrt(2.0 * p0 * u), base, u0, u1)


def profile_table(prof: Any) -> array | None:
    """The time law `prof` and its bases as the table of robot/lawtable.py (``PROFILE_FIELDS``
    floats a record: a ``Trapezoid`` at the bottom, ``RampProfile`` and ``BrakeProfile`` above
    it; an ``array('d')``), or None for another time law (a spline block's, a friction PTP's)."""
    rows: list[float] = []
    while True:
        kind = type(prof)
        if kind is Trapezoid:
            rows += (0.0, prof.t_total, prof.t_acc, prof.a, prof.v, 0.0, 0.0)
            return array("d", rows)
        if kind is RampProfile:
            rows += (1.0, prof.delay, prof.tau, prof.u_e, prof.a_r, prof.shift, 0.0)
        elif kind is BrakeProfile:
            rows += (2.0, prof.tau, prof.t_a, prof.u_a, prof.v_a, prof.a_b, prof.t_total)
        else:
            return None
        prof = prof.base


@dataclass
class BlendPlan:
    """How a blend runs (issue 15), from :func:`plan_blend`: the new time laws of the two
    motions (``prev_profile`` brakes uniformly from the blend start to the point,
    ``next_profile`` ramps up to the blend end) and the blend length ``window`` (s)."""

    prev_profile: Any
    next_profile: Any
    window: float
    #: :func:`blend_space` of the two motions, when plan_blend made it (else None)
    space: str | None = None


def plan_blend(prev: Segment, nxt: Segment, keyword: str, tau_a: float) -> BlendPlan | None:
    """Time laws of a blend that starts at local time ``tau_a`` of ``prev`` (issue 15).

    The contour is the overlap of the two profiles (module docstring), but with profiles
    made for it: ``prev`` brakes uniformly over the whole rest of the zone
    (:class:`~robot.profiles.BrakeProfile`) and ``nxt`` accelerates uniformly to its blend
    end point (:class:`~robot.profiles.RampProfile`), timed so that it arrives there when
    ``prev`` reaches its point (started later if it cannot take that long). Both speeds are
    then linear in time over the window, so ``|v_prev + v_next| <= max(v_prev, v_next)``:
    the path never runs faster than the faster of the two programmed motions, and no
    acceleration exceeds what either motion was planned with. With equal speeds the blend
    ends as far after the point as it started before it, and ``ρ + π = (1-x)² + x² <= 1``
    keeps the contour in the zone.

    Returns None when an axis reverses between the two motions and the two accelerations
    would add up beyond ``a_max``: the blend then has to wait until ``prev`` reaches its point
    (call again with ``tau_a = prev.T``, which always succeeds)."""
    bp = BrakeProfile(prev.profile, tau_a)
    tau_p = bp.t_total - tau_a if bp.tau > 0 else 0.0
    if tau_p <= 0.0 or nxt.T <= 0.0:
        return BlendPlan(bp, RampProfile(nxt.profile, 0.0), 0.0)
    base = nxt.profile
    got = _cart_blend(prev, nxt, bp, tau_p)
    if got is False:
        return None
    if got is not None:
        rp = RampProfile(base, got[0], got[1])
    else:
        # the uniform braking must stay below the planned speed everywhere (a spline block's
        # corners and curves have lower speeds than the blend start): else no blend before the point
        if not _below_law(BRAKE_LAW, bp.v_a, bp.a_b, bp.u_a, prev.profile, bp.u_a, 1.0):
            return None
        u_max = base.u(blend_end_tau(prev, nxt, keyword, tau_a))
        u_max = min(u_max, base.u(max(0.0, base.t_total - getattr(base, "t_brake", base.t_acc))))
        rp = _ramp(base, u_max, tau_p)
    # only an axis that reverses can add up both accelerations (numpy's elementwise operations
    # on the floats, one axis at a time)
    for e, s, a in zip(prev.qd_end.tolist(), nxt.qd_start.tolist(), prev.model.a_max.tolist()):
        if e * s < 0 and abs(e) * bp.a_b + abs(s) * rp.a_r > a * (1.0 + 1e-6):
            return None
    space = blend_space(prev, nxt)
    if space == "joint" and tau_p > 0.0 and _joint_blend_acc_ratio(prev, bp, nxt, rp, tau_p) > 1.0 + 1e-6:
        return None
    return BlendPlan(bp, rp, tau_p, space)


def _cart_blend(prev: Segment, nxt: Segment, bp: BrakeProfile, tau_p: float) -> Any:
    """:func:`plan_blend` from its braking `bp` on, for two CP motions whose paths robot/cartpath.py
    holds and whose time laws robot/lawtable.py reads: the braking's check (lawtable ``below``), the
    distance from the braking's start to the path's end in C (``CartPath.dist_to``) and
    robot/lawtable.py ``blend_end_ramp`` on the next path's pieces: (u_e, delay) of the next
    motion's ramp, False for no blend before the point, None where the Python code decides
    (``blend_end_tau`` and :func:`_ramp` on the segments)."""
    if not (prev.cart and nxt.cart):
        return None
    sc = compiled_module()
    if sc is None:
        return None
    cp, cq = prev._compiled_path(), nxt._compiled_path()      # type: ignore[attr-defined]
    blas = _line_blas(sc) if cp and cq else None
    if blas is None:
        return None
    pt, nt = profile_table(prev.profile), profile_table(nxt.profile)
    if pt is None or nt is None:
        return None
    base = nxt.profile
    end = prev._path_end                                       # type: ignore[attr-defined]
    if end is None:
        end = prev._path_end = prev.pieces[-1].pos(prev.pieces[-1].length)    # type: ignore[attr-defined]
    laws = pure_module(lawtable)
    if not laws.below(BRAKE_LAW, bp.v_a, bp.a_b, bp.u_a, pt, getattr(prev.profile, "bounds", ()), bp.u_a, 1.0):
        return False
    got = cp.dist_to(bp.u_a, end, blas[1])
    if got is None or min(cq.kinds) < 0:       # a piece whose length the path does not hold
        return None
    return laws.blend_end_ramp(nt, getattr(base, "bounds", ()), cq.length, cq.ub, got, bp.u_a,
                               getattr(base, "t_brake", base.t_acc), tau_p)


def _ramp(base: Any, u_max: float, tau_p: float) -> RampProfile:
    """:func:`plan_blend`'s ramp of the next motion onto its time law `base` up to the blend end
    ``u_max`` within the window ``tau_p`` (s): as long as the window where the ramp can take that
    long (bisected where it cannot), shorter where it would exceed the planned speed (bisected);
    robot/lawtable.py ``ramp_args`` (compiled where built) for a time law `base`
    :func:`profile_table` reads (the same bisections, the same operations in the same order: the
    same ramp)."""
    table = profile_table(base)
    if table is not None:
        u_e, delay = pure_module(lawtable).ramp_args(table, getattr(base, "bounds", ()), u_max, tau_p)
        return RampProfile(base, u_e, delay)

    def ramp_time(u: float) -> float:
        if u <= 0:
            return 0.0
        v = base.du(base.t_of_u(u))
        return 2.0 * u / v if v > 0 else math.inf

    if u_max <= 0.0:
        rp = RampProfile(base, 0.0, tau_p)
    elif ramp_time(u_max) <= tau_p:
        rp = RampProfile(base, u_max, tau_p - ramp_time(u_max))
    else:
        lo, hi = 0.0, u_max
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            if ramp_time(mid) <= tau_p:
                lo = mid
            else:
                hi = mid
        rp = RampProfile(base, lo, tau_p - ramp_time(lo))
    if rp.tau > 0 and not _below_law(RAMP_LAW, rp.a_r, 0.0, 0.0, base, 0.0, rp.u_e):
        lo, hi = 0.0, rp.u_e  # a shorter ramp (at its shortest it is the planned acceleration)
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            t_m = ramp_time(mid)
            cand = RampProfile(base, mid, max(0.0, tau_p - t_m))
            if cand.tau <= 0 or _below_law(RAMP_LAW, cand.a_r, 0.0, 0.0, base, 0.0, mid):
                lo = mid
            else:
                hi = mid
        rp = RampProfile(base, lo, max(0.0, tau_p - ramp_time(lo)))
    return rp


#: Samples of a blend window, and of a CP motion's path, for :func:`_joint_blend_acc_ratio`.
_BLEND_SAMPLES = 16


def _rates_at(seg: Segment, us: np.ndarray, from_end: bool) -> tuple[np.ndarray, np.ndarray]:
    """dq/du and d2q/du2 (deg, shape (len(us), w)) of a segment at the path parameters ``us``. A PTP
    is linear in u; a CP motion is sampled with inverse kinematics along its path, from its
    end point's axes (``from_end``) or its start's (the segment's own state is not touched). If the IK cannot follow the window
    (the planner already accepted this path), the planned end rates are used."""
    n = len(us)
    w = len(seg.q0)                       # A1..An and the external axes (robot/planner.py)
    if not seg.cart:
        return np.broadcast_to(seg.q1 - seg.q0, (n, w)), np.zeros((n, w))
    lo, hi = float(np.min(us)), float(np.max(us))
    if hi - lo < 1e-9:
        lo, hi = max(0.0, lo - 1e-3), min(1.0, hi + 1e-3)
    grid = np.linspace(lo, hi, _BLEND_SAMPLES + 1)
    ref = seg.q1 if from_end else seg.q0
    Q = _chained_axes(seg, grid, from_end, ref)
    if Q is None:
        order = range(len(grid) - 1, -1, -1) if from_end else range(len(grid))
        Q = np.empty((len(grid), w))
        try:
            for j in order:
                p, R = seg.pose_u(float(grid[j]))
                ref = Q[j] = seg.ik(p, R, ref, float(grid[j])) if w > seg.model.n else seg.ik(p, R, ref)
        except Exception:  # noqa: BLE001 - keep the planned rates
            d = seg.qd_start if lo <= 0.0 else seg.qd_end
            return np.broadcast_to(d, (n, w)), np.zeros((n, w))
    h = float(grid[1] - grid[0])
    d1 = gradient_rows(Q, h)
    d2 = gradient_rows(d1, h)
    return (np.stack([np.interp(us, grid, d1[:, i]) for i in range(w)], axis=1),
            np.stack([np.interp(us, grid, d2[:, i]) for i in range(w)], axis=1))


def _chained_axes(seg: Segment, grid: np.ndarray, from_end: bool, ref: np.ndarray) -> np.ndarray | None:
    """:func:`_rates_at`'s axes at the path parameters `grid` ((k,), increasing) of the CP
    segment `seg`, solved in a chain from `ref` (its end's axes when `from_end`, the chain then
    runs from the last parameter down): ``seg.ik(*seg.pose_u(u), ref)`` of each, each the next
    one's reference, in one call of its compiled path (robot/cartpath.py ``CartPath.chain_u``:
    ``axes_u`` of each u in turn, the same axes bit for bit), shape (k, COMPILED_AXES); None where that does
    not run (no compiled path or inverse, external axes) or leaves a pose to the Python code
    (which then solves, or raises, point by point)."""
    cp = seg._compiled_path()      # type: ignore[attr-defined]
    if not cp or len(ref) != COMPILED_AXES:
        return None
    us = np.ascontiguousarray(grid[::-1]) if from_end else grid
    try:
        Q = cp.chain_u(us, seg.status, np.asarray(ref, dtype=float))  # type: ignore[attr-defined]
    except (TypeError, ValueError):     # not float64 arrays: the Python code takes them
        return None
    if Q is None:
        return None
    return np.ascontiguousarray(Q[::-1]) if from_end else Q


def _joint_blend_acc_ratio(prev: Segment, bp: Any, nxt: Segment, rp: Any, window: float) -> float:
    """Largest ratio of an axis acceleration to ``a_max`` over a blend superposed in axis
    space (``q = q_prev(t) + q_next(t) - P``): ``a_i = q'_i(u) u'' + q''_i(u) u'^2`` of the
    braking motion plus that of the ramping one, on samples of the window. The two can add
    up on an axis that reverses, and a CP side's axis rates change along its path, so the
    sum is evaluated, not bounded at the programmed point (issue 22: a PTP C_PTP into a LIN
    reached 1.13-1.15x a_max at the end of the blend)."""
    ts = np.linspace(0.0, window, _BLEND_SAMPLES + 1)
    tb = np.minimum(ts, bp.tau)
    up = np.clip(bp.u_a + bp.v_a * tb - 0.5 * bp.a_b * tb * tb, 0.0, 1.0)
    udp = np.maximum(bp.v_a - bp.a_b * tb, 0.0)
    uddp = np.where(ts <= bp.tau, -bp.a_b, 0.0)
    d1, d2 = _rates_at(prev, up, True)
    acc = d1 * uddp[:, None] + d2 * (udp * udp)[:, None]
    if rp.tau > 0.0:
        s = np.clip(ts - rp.delay, 0.0, rp.tau)
        un = 0.5 * rp.a_r * s * s
        udn = rp.a_r * s
        uddn = np.where((ts > rp.delay) & (ts - rp.delay <= rp.tau), rp.a_r, 0.0)
        d1, d2 = _rates_at(nxt, un, False)
        acc = acc + d1 * uddn[:, None] + d2 * (udn * udn)[:, None]
    return float(np.max(np.abs(acc) / np.asarray(prev.model.a_max, dtype=float)))


def superpose_pose(p0: np.ndarray, R0: np.ndarray, p1: np.ndarray, R1: np.ndarray,
                   pc: np.ndarray, Rc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Profile overlap in Cartesian space: ``p = p_prev + (p_next - P)``,
    ``R = (R_next · R_Pᵀ) · R_prev`` (the next motion's change applied on top)."""
    return p0 + (p1 - pc), (R1 @ Rc.T) @ R0


def reduced_orientation(model: Any) -> bool:
    """Does the robot reach only part of an orientation? True for the kinematic families that
    say so (``reduced_orientation``: the palletizers, whose A4 stays at 0, docs/robot.md "The
    palletizers"; a SCARA), whose inverse drops the component of a target's orientation they
    have no axis for."""
    return bool(model.kin.impl.reduced_orientation)


def reached_pose(seg: Segment, p: np.ndarray, R: np.ndarray, ref: np.ndarray,
                 u: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The pose the robot reaches for the pose ``(p, R)`` of ``seg``'s path (mm, (3,); 3x3, in
    its ``$BASE``): the TCP of its inverse kinematics (solution nearest ``ref``, external axes
    at path parameter ``u``). On a robot of :func:`reduced_orientation` a CP path may carry an
    orientation the robot cannot take (``$ORI_TYPE #CONSTANT`` while A1 turns, a target's
    tilt): the blend overlaps the reached poses, so that at its end the setpoint is the next
    motion's own (a 5-axis palletizer's A2 jumped to 1.46x a_max at the end of a CIRC
    #CONSTANT -> CIRC blend, whose orientations were 29 deg apart at the point). Raises
    WorkspaceError/SoftLimitError as :meth:`CartSegment.ik`."""
    q = seg.ik(p, R, ref, u) if len(ref) > seg.model.n else seg.ik(p, R, ref)  # type: ignore[attr-defined]
    T = seg.model.tcp(q, seg.tool_T, seg.base_inv_T)
    return T[:3, 3], T[:3, :3]


def _close(a: np.ndarray, b: np.ndarray) -> bool:
    """``np.allclose(a, b)``, at once for the same or equal frames (the motions of a program
    share their $TOOL and $BASE)."""
    # a.tolist() == b.tolist(): (a == b).all() of two 4x4 frames (float ==: -0.0 equals 0.0, a NaN
    # nothing: each tolist makes new floats), without numpy's reduction per call
    return a is b or a.tolist() == b.tolist() or bool(np.allclose(a, b))


def blend_space(prev: Segment, nxt: Segment) -> str:
    """``"cart"`` when both segments are CP motions (combined in Cartesian space with the
    same $TOOL/$BASE, neither with ``$ORI_TYPE #JOINT``), else ``"joint"``."""
    if prev.cart and nxt.cart and _close(prev.tool_T, nxt.tool_T) and _close(prev.base_T, nxt.base_T) and \
            not getattr(prev, "joint_ori", False) and not getattr(nxt, "joint_ori", False):
        return "cart"
    return "joint"


def blend_window(seg: Segment, nxt: Segment, keyword: str, tau_a: float) -> float:
    """Length (s) of the blend that starts at local time `tau_a` of `seg` (it ends when `seg`
    reaches its point)."""
    bp = plan_blend(seg, nxt, keyword, tau_a) or plan_blend(seg, nxt, keyword, seg.T)
    assert bp is not None
    return bp.window


def blend_setpoint(prev: Segment, t_prev: float, nxt: Segment, t_next: float, space: str, model: Any,
                   q: np.ndarray) -> np.ndarray:
    """The setpoint of the blend from `prev` (at its local time `t_prev`, s) into `nxt` (at
    `t_next`): the overlap of the two velocity profiles, in Cartesian space (``space`` "cart":
    the poses superposed, solved near the setpoint `q`; the external axes overlap like axes) or
    in axis space (``prev(t) + nxt(t) - nxt's start``, within the software limits: raises
    SoftLimitError). Axes in the model's order (deg, mm)."""
    if space == "cart":
        q_c = _superposed(prev, t_prev, nxt, t_next, model, q)
        if q_c is not None:
            return q_c
        p0, R0 = prev.pose(t_prev)
        p1, R1 = nxt.pose(t_next)
        pc, Rc = nxt.pose(0.0)
        if reduced_orientation(model):
            # a palletizer: overlap the poses it reaches, not the paths' own orientations
            # (reached_pose)
            u0, u1 = prev.u(t_prev), nxt.u(t_next)
            p0, R0 = reached_pose(prev, p0, R0, q, u0)
            p1, R1 = reached_pose(nxt, p1, R1, q, u1)
            pc, Rc = reached_pose(nxt, pc, Rc, q, 0.0)
        p, R = superpose_pose(p0, R0, p1, R1, pc, Rc)
        ref = q
        n = model.n
        if len(ref) > n:
            # the external axes overlap like axes: E_prev(t) + E_next(t) - E at the point
            e = _e_at(prev, prev.u(t_prev), n) + _e_at(nxt, nxt.u(t_next), n) - nxt.q0[n:]
            ref = np.concatenate([ref[:n], e])
        return nxt.ik(p, R, ref)  # type: ignore[attr-defined]
    out = prev.axes(t_prev) + (nxt.axes(t_next) - nxt.q0)
    model.check_limits(out)
    return out


def _superposed(prev: Segment, t_prev: float, nxt: Segment, t_next: float, model: Any, q: np.ndarray) -> np.ndarray | None:
    """:func:`blend_setpoint` of a Cartesian blend in C (robot/cartpath.py ``CartPath.superposed``:
    the three poses, their overlap with numpy's products through its BLAS, checked once a process
    by :func:`_superpose_gemm`, and the next motion's compiled inverse): the same axes bit for bit,
    or None where it does not run (no compiled paths or inverse, external axes, a robot of
    :func:`reduced_orientation`) or leaves the setpoint to the Python code."""
    if not (prev.cart and nxt.cart) or len(q) != model.n:
        return None
    sc = compiled_module()
    if sc is None or reduced_orientation(model):
        return None
    cp, cq = prev._compiled_path(), nxt._compiled_path()      # type: ignore[attr-defined]
    if not (cp and cq and (nxt._c_framed or nxt.compiled_inverse())):   # type: ignore[attr-defined]
        return None
    gemm = _superpose_gemm(sc)
    if not gemm:
        return None
    try:
        return cq.superposed(cp, prev.u(t_prev), nxt.u(t_next), nxt.u(0.0), nxt.status, q, gemm)
    except (TypeError, ValueError):     # not float64 axes: the Python code takes them
        return None


#: [address] of numpy's cblas_dgemm once robot/cartpath.py ``superpose_products`` was seen to
#: compute ``(A @ B.T) @ C`` as numpy does, [0] when not: :func:`_superpose_gemm`
_SUPERPOSE_GEMM: list[int] = []


def _superpose_gemm(sc: Any) -> int:
    """The ``cblas_dgemm`` address for robot/cartpath.py ``CartPath.superposed`` (0: none, or its
    products are not numpy's bit for bit on a probe of drawn rotations), checked once a process."""
    if not _SUPERPOSE_GEMM:
        gemm = numpy_cblas("dgemm")
        rng = np.random.default_rng(6208)
        for i in range(48 if gemm else 0):
            A, B, C = (frame_to_matrix(*rng.uniform(-500.0, 500.0, 6))[:3, :3].copy() for _ in range(3))
            if i % 3 == 0:
                B = A + rng.normal(0.0, 1e-15, (3, 3))
            if sc.superpose_products(gemm, A, B, C).tobytes() != ((A @ B.T) @ C).tobytes():
                gemm = 0
        _SUPERPOSE_GEMM.append(gemm)
    return _SUPERPOSE_GEMM[0]


def _e_at(seg: Segment, u: float, n: int) -> np.ndarray:
    """The external axes of `seg` (after its n robot axes) at its path parameter `u` (linear
    from start to end)."""
    return seg.q0[n:] + u * (seg.q1[n:] - seg.q0[n:])


__all__ = ["effective_keyword", "blend_start_tau", "blend_window", "blend_setpoint", "blend_end_tau", "blend_space", "superpose_pose",
           "plan_blend", "BlendPlan", "reduced_orientation", "reached_pose"]
