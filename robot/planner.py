"""Motion planning: a :class:`~robot.motion.MotionRequest` becomes a :class:`Segment` that
the main run samples every IPO cycle (reference §6.3-§6.7, robot-model.md §7-§8).

A segment is a geometric path plus one normalised time law (:mod:`robot.profiles`: a
trapezoid, or a piecewise profile for a SPLINE block; CP paths are slowed so the axes keep
machine data, issue 15):

* :class:`JointSegment` (PTP, SPTP): ``q(u) = q0 + u·(q1 - q0)``, synchronised axes.

External axes E1..En (robot/external.py) are the axis vector's entries after A1..An: a PTP
moves them synchronised with the robot axes; on a CP path they move linearly in the path
parameter, ``E(u) = E0 + u·(E1 - E0)``, start and stop with the robot, and the path is slowed
for their speed and acceleration like for the robot's axes. A track (#ERSYS) moves
``$ROBROOT`` with E, so the arm's axes on a CP path follow it; a ``$BASE`` linked to a BASE
kinematic (``MotionParams.base_kin``, KSS ``EK``) turns with it.
* :class:`CartSegment` (LIN, CIRC, SLIN, SCIRC, SPLINE): the TCP moves in ``$BASE`` along
  a chain of path pieces (line, circular arc, Catmull-Rom curve for SPL points); the
  orientation follows ``$ORI_TYPE``/``$CIRC_TYPE``; axis values come from the inverse
  kinematics each cycle, keeping the start status S and the turn nearest to the last
  setpoint (reference §6.5: CP motions ignore the target's S and T). Where each solution
  is the next one's reference (the planning walk of a path, the main run's coming cycles at
  full path speed: :meth:`CartSegment.axes_run`) the chain is solved at once in numpy
  (:meth:`RobotModel.ik_chain`), with the same results bit for bit; a kept row is used only
  for the same time law, time and reference, so a BRAKE, a blend, an interrupt's motion or an
  advance-run event between cycles gets the per-cycle setpoint.

Planning happens in the advance run (:func:`plan`), so an unreachable target or a soft-limit
violation of a target raises :class:`~robot.errors.RobotError` at the motion statement.

This module holds :func:`plan`, the PTP planning with its time law and :func:`resolved_target`;
the rest is in its own modules (issue 76): the robot (robot/robotmodel.py ``RobotModel``), the
segments (robot/segments.py), the path pieces (robot/pathpieces.py), a CP motion's targets
(robot/targets.py), path (robot/cartplan.py), time law (robot/cartlaw.py) and triggers
(robot/pathtriggers.py), the single LIN planned in C (robot/cartline.py), the memos
(robot/planmemo.py) and a motion planned again from the same start (robot/planrepeat.py).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .errors import RobotError
from .frames import matrix_to_frame
from .cartline import _planned_line
from .cartplan import plan_cart
from .dynamics import ArmDynamics
from .external_tcp import external_tcp
from .motion import CART_KEYS, MotionParams, MotionRequest
from .limits import (DEFAULT_MODE, T1_MARGIN, T1_SPEED_MM_S, axis_percentages, motion_limits, ptp_axis_accelerations,
                     ptp_axis_speeds, ptp_ramp_accelerations)
from .pathtriggers import _plan_triggers
from .planmemo import _inverse_of, _matrix_of
from .planrepeat import PlanRepeats
from .profiles import FrictionProfile, Trapezoid
from .robotmodel import RobotModel
from .segments import JointSegment, Segment
from .targets import _cart_target, _check_complete, _ext_target


def plan(req: MotionRequest, q_start: np.ndarray, model: RobotModel, *,
         first: bool = False, repeats: PlanRepeats | None = None) -> Segment:
    """Plan one motion from the axes ``q_start`` (the previous programmed end point); with
    `repeats` (robot/planrepeat.py, the queue's) a request planned before from the same start
    on the same robot gives a copy of that segment.

    Raises:
        RobotError: incomplete first motion (BCO), PATH trigger on PTP, a ``$IPO_MODE``
            other than #BASE and #TCP (robot/external_tcp.py); WorkspaceError / SoftLimitError (subclasses) when the
            target (or a SPLINE/CIRC point) is unreachable or outside the soft limits.
    """
    if first:
        _check_complete(req, model.axes.robot_keys)
    q0 = np.asarray(q_start, dtype=float).copy()
    key = repeats.key(req, q0, model) if repeats is not None else None
    seg, limits = repeats.get(key, req) if key is not None else (None, None)    # type: ignore[union-attr]
    if seg is None:
        seg, model = _planned(req, q0, model)
        if key is not None:
            repeats.keep(key, seg)                              # type: ignore[union-attr]
    _plan_triggers(seg)
    if limits is None:
        limits = motion_limits(req, model.machine, model.mode)
        if key is not None:
            repeats.keep_limits(key, limits)                    # type: ignore[union-attr]
    seg.limits = limits
    return seg


def _planned(req: MotionRequest, q0: np.ndarray, model: RobotModel) -> tuple[Segment, RobotModel]:
    """:func:`plan`'s segment (no triggers, no limits yet) and the model it was planned on."""
    p: MotionParams = req.params
    if p.ipo_mode == "TCP":
        model = external_tcp(model)      # the fixed tool in the workpiece frame
    elif p.ipo_mode != "BASE":
        raise RobotError(f"$IPO_MODE=#{p.ipo_mode} is not supported by the simulator")
    if getattr(p, "base_kin", None) and model.n_ext:
        model = model.linked(p.base_kin, getattr(p, "base_root", None))   # $BASE on a BASE kinematic (robot/external.py)
    tool_T = _matrix_of(p.tool)
    base_T = _matrix_of(p.base)
    base_inv = _inverse_of(base_T)[0]
    start_T = model.tcp(q0, tool_T, base_inv)
    if req.kind in ("PTP", "SPTP"):
        return _plan_joint(req, q0, start_T, tool_T, base_T, model), model
    seg = (_planned_line(req, q0, start_T, tool_T, base_T, model) if req.kind == "LIN" else None) \
        or plan_cart(req, q0, start_T, tool_T, base_T, model)
    return seg, model


def _plan_joint(req: MotionRequest, q0: np.ndarray, start_T: np.ndarray, tool_T: np.ndarray,
                base_T: np.ndarray, model: RobotModel) -> JointSegment:
    p = req.params
    t = req.target
    n = model.n
    if req.is_axis_target:
        # the robot's axes A1..An (an A(n+1)..A6 of the target has no axis: ignored), then E
        keys = model.axes.model_keys[:len(q0)]
        if req.relative:
            q1 = q0 + np.array([float(t.get(k, 0.0)) for k in keys])
        else:
            q1 = np.array([float(t[k]) if k in t else q0[i] for i, k in enumerate(keys)])
        model.check_limits(q1)
    else:
        T1 = _cart_target(t, start_T, req.relative, req.rel_frame)
        s = int(t["S"]) if "S" in t and not req.relative else None
        tt = int(t["T"]) if "T" in t and not req.relative else None
        q1 = model.ik(T1, _inverse_of(tool_T)[0], base_T, s, tt, _ext_target(q0, t, req.relative, model.axes))
        if len(q1) > n:
            model.check_limits(q1)
    dq = np.abs(q1 - q0)
    moving = dq > 1e-9
    if not moving.any():
        prof = Trapezoid.plan(math.inf, math.inf)
        v_prog = math.inf
        V = 0.0
    else:
        V, alpha, fric, beta = _ptp_axis_limits(q1 - q0, p, model.machine, model.mode, q0)
        if model.mode == "T1":
            # TCP and flange <= 250 mm/s (reference §6.7 [C]): the largest |dp/du| on the path
            us = np.linspace(0.0, 1.0, 33)
            Q = q0[None, :] + us[:, None] * (q1 - q0)[None, :]
            F = model.kin.forward_many(Q)
            if not model._robroot_is_null:
                F = model.robroot_T @ F
            tcp = (_inverse_of(base_T)[0] @ F @ tool_T)[:, :3, 3]
            dp = max(float(np.max(np.linalg.norm(np.diff(tcp, axis=0), axis=1))),
                     float(np.max(np.linalg.norm(np.diff(F[:, :3, 3], axis=0), axis=1))))
            dp *= (len(us) - 1) * T1_MARGIN
            if dp > 0:
                V = min(V, T1_SPEED_MM_S / dp)
        prof = _ptp_profile(V, alpha, fric, p, beta)
        v_prog = V
    seg = JointSegment(req, q0, q1, prof, v_prog, tool_T, base_T, model)
    seg.vel_peak = dq * prof.v
    seg.acc_peak = dq * getattr(prof, "a_peak", prof.a)
    return seg


def ptp_limits(dq: np.ndarray, p: MotionParams, machine: Any, mode: str = DEFAULT_MODE,
               q0: np.ndarray | None = None) -> tuple[float, float]:
    """(V 1/s, A 1/s²) of a synchronised PTP moving the axes by `dq` (deg; A1..An, E1..En) from
    `q0`: the normalised speed and acceleration of the leading axis, ``min_i v_i/|dq_i|`` and
    ``min_i a_i/|dq_i|`` over the moving axes, with :func:`robot.limits.ptp_axis_speeds` and
    :func:`robot.limits.ptp_axis_accelerations` (reference §6.6; issue 60); for a robot with an
    identified dynamic model (``machine.dynamics``) and `q0` given, ``A`` is what the drives' torques
    allow at `q0` with the load of `p` (robot/dynamics.py, the axes moving together; issue 73). :func:`ptp_profile` is the
    motion's time law. Raises RobotError for a non-positive limit."""
    V, alpha, _, _ = _ptp_axis_limits(dq, p, machine, mode, q0)
    return V, float(np.min(alpha))


def leading_axes(dq: np.ndarray, v_axis: np.ndarray) -> np.ndarray:
    """Which axes lead a synchronised PTP moving by `dq` (deg, (n,)) at the programmed axis speeds
    `v_axis` (deg/s, (n,); :func:`robot.limits.ptp_axis_speeds`): the moving axes whose own
    ``|dq_i| / v_i`` is the motion's (to 1e-9 relative), bool (n,). The other axes are slowed to the
    leading one's time (reference §6.6: every axis starts and ends together) and never reach their
    programmed speed, so the ramp bound at a reduced ``$VEL_AXIS`` (robot/limits.py
    ``ptp_ramp_accelerations``, a bound of the programmed speed) applies to the leading axes alone:
    PTP_away's HOME -> XP1 at 10 % (../shared/real-traces, A2 leading, the wrist moving 40-80 deg)
    was planned 10-11 % too long with every moving axis' bound and is within 0.3 % with the leading
    axis' (docs/robot.md "The ramp at a reduced $VEL_AXIS in a synchronised PTP")."""
    ad = np.abs(np.asarray(dq, dtype=float))
    moving = ad > 1e-9
    t = np.where(moving, ad / np.where(v_axis > 0, v_axis, np.inf), 0.0)
    return moving & (t >= (1.0 - 1e-9) * float(np.max(t, initial=0.0)))


def _ptp_axis_limits(dq: np.ndarray, p: MotionParams, machine: Any, mode: str,
                     q0: np.ndarray | None, short: bool = True) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """(V, alpha, c, beta) of :func:`ptp_limits` per axis: ``alpha`` (1/s², (n,)) the normalised
    acceleration each axis allows starting from rest (inf for an axis that neither moves nor, by
    the arm's dynamics, needs torque), ``c`` (1/s, (n,)) what it loses per unit of normalised speed
    by its friction at 100 % override (machine data ``ptp_friction``; :func:`ptp_profile`),
    ``beta`` (1/s², (n,)) the braking's to rest (``alpha`` itself for a robot without a dynamic
    model; robot/dynamics.py ``ArmDynamics.ptp_bounds``); under :func:`short_ramp_scale` unless
    `short` is False; the law acts at a reduced speed only, where a leading axis (:func:`leading_axes`)
    runs below 100 % ``$VEL_AXIS`` (the recordings show it there and nowhere else; docs/robot.md
    "The short-ramp law where it is shown")."""
    dq = np.asarray(dq, dtype=float)
    ad = np.abs(dq)
    moving = ad > 1e-9
    v_axis = ptp_axis_speeds(p, machine, mode)       # $RED_T1 in T1 (issue 15)
    a_axis = ptp_axis_accelerations(p, machine, ramp=False)      # as KSS 8.5 (issue 60)
    if np.any(v_axis[moving] <= 0) or np.any(a_axis[moving] <= 0):
        raise RobotError("PTP: $VEL_AXIS, $ACC_AXIS and $OV_PRO must be positive")
    V = float(np.min(v_axis[moving] / ad[moving]))
    safe = np.where(moving, ad, 1.0)
    lead = leading_axes(dq, v_axis)
    ramp = np.where(lead, ptp_ramp_accelerations(p, machine) / safe, np.inf)
    slow = bool(np.any(axis_percentages(p.vel_axis, machine, len(v_axis))[lead] < 100.0))
    alpha = np.where(moving, np.minimum(a_axis / safe, ramp), np.inf)
    fr = np.zeros(len(dq))
    got = tuple(getattr(machine, "ptp_friction", ()) or ())[:len(dq)]
    fr[:len(got)] = got
    c = np.where(moving, fr, 0.0)
    dyn = arm_dynamics(machine)
    if dyn is None or q0 is None or len(dq) != dyn.n:
        return _short_ramp(V, alpha, c, alpha, p, machine) if short and slow else (V, alpha, c, alpha)
    # the robot's dynamic model decides (robot/dynamics.py: the drives' torques at the start and
    # at the end, with the load the program set); the leading axis' ramp bound at a reduced $VEL_AXIS stays, and
    # an axis whose torque limit was measured keeps its identified acceleration as a cap. An axis'
    # friction per unit of normalised speed scales as the dynamics scale its acceleration
    factor = np.asarray(list(p.acc_axis)[:dyn.n], dtype=float) / 100.0 * (p.ov_pro / 100.0) ** 2
    dyn.set_load(getattr(p, "load", None), getattr(p, "load_a3", None))
    a_acc, a_dec = dyn.ptp_bounds(q0, q0 + dq, factor)
    a_max = np.asarray(getattr(machine, "all_max_acc", machine.max_acc_deg_s2), dtype=float)[:dyn.n]
    static = a_max * factor / safe
    capped = moving & dyn.capped
    a_acc = np.where(capped, np.minimum(a_acc, static), a_acc)
    a_dec = np.where(capped, np.minimum(a_dec, static), a_dec)
    with np.errstate(invalid="ignore"):
        c = np.where(moving & np.isfinite(a_acc), c * a_acc / static, 0.0)
    alpha, beta = np.minimum(a_acc, ramp), np.minimum(a_dec, ramp)
    return _short_ramp(V, alpha, c, beta, p, machine) if short and slow else (V, alpha, c, beta)


def ptp_ramp_time(dq: np.ndarray, p: MotionParams, machine: Any, mode: str = DEFAULT_MODE,
                  q0: np.ndarray | None = None) -> float:
    """:func:`dynamic_ramp_time` of a synchronised PTP moving the axes by `dq` from `q0` (s, at
    100 % override): what :func:`short_ramp_scale` decides on, the axes' own limits without it."""
    V, alpha, _c, beta = _ptp_axis_limits(np.asarray(dq, dtype=float), p, machine, mode, q0, short=False)
    return dynamic_ramp_time(V, alpha, beta, p.ov_pro)


def dynamic_ramp_time(V: float, alpha: np.ndarray, beta: np.ndarray, ov_pro: float) -> float:
    """The time (s, at 100 % override) in which a synchronised PTP of normalised speed `V` (1/s) ramps
    to it at the least of its axes' normalised accelerations `alpha` (starting) and `beta` (braking)
    (1/s²; at the override `ov_pro` %, whose plan is the 100 % one in time over ov); inf when it
    does not move."""
    a = min(float(np.min(alpha)), float(np.min(beta)))
    if not (0.0 < V < math.inf) or not (0.0 < a < math.inf):
        return math.inf
    return V / a * ov_pro / 100.0


def short_ramp_scale(t: float, machine: Any) -> float:
    """The factor (<= 1) on a synchronised PTP's accelerations when its axes' own accelerations
    would ramp it to its speed in `t` s (:func:`dynamic_ramp_time`): ``t² / K`` (the ramp then
    lasts ``K / t``) when ``t`` is below ``θ``, else 1; ``K`` and ``θ`` the machine data
    ``ptp_short_ramp_s2`` and ``ptp_short_ramp_below_s`` (0: no such law). The planner applies it
    to a PTP at a reduced speed only (a leading axis below 100 % ``$VEL_AXIS``: :func:`_ptp_axis_limits`).

    Why (issue 88; docs/robot.md "The short-ramp law"): no KUKA page states the law (searched); it
    is what the real KR 3 R540 plans, PROG.TXT's ENDTIME - START to the millisecond (OfficeLite
    plans the same). Its single-axis PTPs at a reduced ``$VEL_AXIS`` ramp in ``K / t`` with one K
    (442-458 ms² on A1, A3, A4, A5, across poses and distances: A3's 30 and 60 deg moves take
    6.2 and 5.7 ms·(1/f) where their full-speed ramps take 72 and 80 ms) while ``t`` is short (A6 at
    70 %: 13 ms), and the dynamics' own ramp where it is not (A4 at 70 %: 16 ms; every 3 kg run at
    10 %: 18-23 ms). It is one law of the synchronised motion, not of an axis: PTP_vel_test's
    six-axis HOME -> XP1 at 10 % follows it with its leading axis A4 slowed by the others."""
    k = float(getattr(machine, "ptp_short_ramp_s2", 0.0) or 0.0)
    below = float(getattr(machine, "ptp_short_ramp_below_s", 0.0) or 0.0)
    if not (k > 0.0 and 0.0 < t < below):
        return 1.0
    return min(1.0, t * t / k)


def _short_ramp(V: float, alpha: np.ndarray, c: np.ndarray, beta: np.ndarray, p: MotionParams,
                machine: Any) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """(V, alpha, c, beta) of :func:`_ptp_axis_limits` under :func:`short_ramp_scale`: a PTP it
    slows is a plain trapezoid (no friction term: the law sets its ramp)."""
    s = short_ramp_scale(dynamic_ramp_time(V, alpha, beta, p.ov_pro), machine)
    if s >= 1.0:
        return V, alpha, c, beta
    return V, alpha * s, np.zeros_like(c), beta * s


def ptp_profile(dq: np.ndarray, p: MotionParams, machine: Any, mode: str = DEFAULT_MODE,
                q0: np.ndarray | None = None, V: float | None = None) -> Any:
    """The time law of a synchronised PTP moving the axes by `dq` from `q0` (:func:`ptp_limits`;
    at the normalised speed `V` when given, less than its): :class:`~robot.profiles.Trapezoid`
    with ``V`` and ``A`` of :func:`ptp_limits`; for a robot whose axes lose acceleration with
    their speed (machine data ``ptp_friction``, 1/s, identified: robot/identified.py) a
    :class:`~robot.profiles.FrictionProfile`: axis ``i`` allows the normalised acceleration
    ``alpha_i - c_i·u'`` accelerating and ``alpha_i + c_i·u'`` braking; the motion takes the
    line through the least of them at rest and at ``V`` (below the least of the lines, so
    within every axis' own). The override scales the motion's time: ``c_i · $OV_PRO%``."""
    v_lim, alpha, c, beta = _ptp_axis_limits(dq, p, machine, mode, q0)
    return _ptp_profile(v_lim if V is None else V, alpha, c, p, beta)


def _ptp_profile(V: float, alpha: np.ndarray, c: np.ndarray, p: MotionParams, beta: np.ndarray) -> Any:
    """:func:`ptp_profile` from the axes' limits (:func:`_ptp_axis_limits`): starting at the least
    of `alpha`, braking at the least of `beta` (robot/profiles.py ``FrictionProfile``'s
    ``a_brake`` when they differ)."""
    A = float(np.min(alpha))
    D = A if beta is alpha else float(np.min(beta))
    if not np.any(c > 0) or not (0 < V < math.inf):
        if D == A or not (0 < V < math.inf):
            return Trapezoid.plan(V, A)
        return FrictionProfile(V, A, 0.0, 0.0, a_brake=D)
    c = c * p.ov_pro / 100.0
    a_end = float(np.min(alpha - c * V))
    d_end = float(np.min(beta + c * V))
    return FrictionProfile(V, A, max(0.0, (A - a_end) / V), max(0.0, (d_end - D) / V), a_brake=D)


#: robot/dynamics.py ArmDynamics of a machine's ``dynamics`` (by the mapping's id: machines made
#: from one another with ``replace`` share it), kept: a program plans many PTPs on one robot
_DYNAMICS: dict[int, Any] = {}


def arm_dynamics(machine: Any) -> Any:
    """The robot/dynamics.py ArmDynamics the planner uses for `machine` (None for a robot without
    a dynamic model): one per ``dynamics`` mapping, kept (the identification adjusts its torques
    and rotor inertias in place, robot/kukatrace/identify.py)."""
    dyn = getattr(machine, "dynamics", None)
    if dyn is None or dyn.get("plan") is False:      # shown, not planned with (robot/described_dynamics.py)
        return None
    got = _DYNAMICS.get(id(dyn))
    if got is None or got[0] is not dyn:
        if len(_DYNAMICS) >= 16:
            _DYNAMICS.clear()
        got = _DYNAMICS[id(dyn)] = (dyn, ArmDynamics(machine, dyn))
    return got[1]


def resolved_target(seg: Segment) -> MotionRequest:
    """A request that drives to ``seg``'s end point from anywhere: PTP segments as an
    axis-target PTP, CP segments as a LIN to the end pose (used to re-plan motions
    suspended by BRAKE when the interrupt routine moved the robot)."""
    req = seg.req
    if not seg.cart:
        tgt = {k: float(v) for k, v in zip(seg.model.axes.robot_keys, seg.q1)}
        kind = "PTP"
    else:
        T = seg.model.tcp(seg.q1, seg.tool_T, seg.base_inv_T)
        tgt = dict(zip(CART_KEYS, matrix_to_frame(T)))
        kind = "LIN"
    return MotionRequest(kind=kind, target=tgt, params=req.params, approx=req.approx,
                         approx2=req.approx2, triggers=req.triggers, file=req.file,
                         line=req.line, id=req.id)


__all__ = ["plan", "ptp_limits", "ptp_profile", "arm_dynamics", "leading_axes", "resolved_target",
           "dynamic_ramp_time", "ptp_ramp_time", "short_ramp_scale"]
