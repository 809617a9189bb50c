"""The limits a motion must respect, and a checker that measures them on a trace (issue 15).

Two halves that share one definition:

* :func:`motion_limits` — the programmed and machine limits of one motion (reference §6.6,
  §6.7, §7.5; robot-model.md §5, §10): TCP path speed ``$VEL.CP · $OV_PRO%`` for CP motions
  (the largest ``WITH $VEL.CP`` of a SPLINE block), axis speeds ``$VEL_AXIS[i]% · $OV_PRO% ·
  v_max_i`` for PTP/SPTP and ``v_max_i`` for CP motions, axis accelerations ``a_max_i``; in
  T1 additionally TCP and flange ≤ 250 mm/s and PTP axis speeds ``· $RED_T1%``. The planner
  plans within these numbers; the controller writes them into the ``start`` event of every
  motion (trace field ``limits``).
* :func:`check_trace` — measures the ``pose`` events of a trace by finite differences (TCP
  path speed from the axes through the forward kinematics with the motion's ``$TOOL`` and
  ``$BASE``; flange speed in T1; axis speeds; axis accelerations by the second difference)
  and returns every sample above its limit by more than the tolerance (3 % for speeds, 10 %
  for accelerations, issue 15). In an approximation window the larger limit of the two
  motions applies. Stops that are not planned (a motion error, RESUME without BRAKE) are
  excluded from the acceleration check: they are fault stops, not planned motion.

Units: mm, deg, s (speeds mm/s and deg/s, accelerations deg/s²).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .axismap import ROBOT_KEYS, robot_slots
from .frames import frame_to_matrix, inv_pos
from .kinematics import Kinematics
from .machine import load_machine
from .mada import load_robot
from .external import ExternalAxes

#: T1 speed limit of the TCP and the flange (reference §6.7 [C], §7.5), mm/s.
T1_SPEED_MM_S = 250.0
#: Safety factor on the sampled TCP/flange speed of a path in T1 (sampling between points;
#: robot/planner.py, robot/cartlaw.py).
T1_MARGIN = 1.02
#: ``$RED_T1`` (%) when the machine data do not give it (robot-model.md §10, KR6 $machine.dat).
RED_T1_DEFAULT_PCT = 7.0
#: Operating modes (enum MODE_OP, reference §7.5); the CLI spells ``#EX`` as ``EXT``.
MODES = ("T1", "T2", "AUT", "EX")
#: The mode of the unattended virtual controller (docs/robot.md, "Operating modes").
DEFAULT_MODE = "AUT"
#: Tolerances of the checker (issue 15): speeds 3 %, accelerations estimated by finite
#: differences 10 %.
TOL_SPEED = 0.03
TOL_ACC = 0.10


def normalise_mode(mode: str | None) -> str:
    """``T1``/``T2``/``AUT``/``EX`` from a CLI or enum spelling (``EXT``, ``#ex``, ...).
    None gives :data:`DEFAULT_MODE`. Raises ValueError for anything else."""
    if mode is None:
        return DEFAULT_MODE
    m = str(mode).strip().lstrip("#").upper()
    if m == "EXT":
        m = "EX"
    if m not in MODES:
        raise ValueError(f"unknown operating mode {mode!r} (T1, T2, AUT or EXT)")
    return m


def red_t1_pct(machine: Any) -> float:
    """``$RED_T1`` in % from the machine data yaml (key ``machine_data_kinematics.red_t1_pct``),
    else robot-model.md's KR6 value 7 %."""
    raw = getattr(machine, "raw", None) or {}
    v = (raw.get("machine_data_kinematics") or {}).get("red_t1_pct")
    return float(v) if v is not None else RED_T1_DEFAULT_PCT


@dataclass(frozen=True)
class MotionLimits:
    """Limits of one motion.

    Attributes:
        path: TCP path speed limit (mm/s) or None (PTP outside T1).
        axes: axis speed limits A1..A6 (deg/s).
        flange: flange speed limit (mm/s) or None (only T1 has one).
        tool, base: the motion's ``$TOOL``/``$BASE`` (X, Y, Z, A, B, C), mm/deg, the frames
            the path speed is measured in.
    """

    path: float | None
    axes: tuple[float, ...]
    flange: float | None = None
    tool: tuple[float, ...] = (0.0,) * 6
    base: tuple[float, ...] = (0.0,) * 6
    #: the BASE kinematic the base is linked to (robot/external.py), None: a fixed base
    base_kin: str | None = None
    #: its root in $WORLD (EK's; None: the machine data's)
    base_root: tuple[float, ...] | None = None

    def as_trace(self) -> dict[str, Any]:
        """The ``limits`` field of a motion ``start`` trace event."""
        out = {"path": self.path, "axes": list(self.axes), "flange": self.flange,
               "tool": list(self.tool), "base": list(self.base)}
        if self.base_kin:
            out["base_kin"] = self.base_kin
            if self.base_root is not None:
                out["base_root"] = list(self.base_root)
        return out

    @staticmethod
    def from_trace(d: dict[str, Any]) -> "MotionLimits":
        return MotionLimits(d.get("path"), tuple(float(v) for v in d["axes"]), d.get("flange"),
                            tuple(float(v) for v in d.get("tool") or (0.0,) * 6),
                            tuple(float(v) for v in d.get("base") or (0.0,) * 6), d.get("base_kin"),
                            tuple(float(v) for v in d["base_root"]) if d.get("base_root") else None)


def axis_percentages(pcts: Any, machine: Any, size: int) -> np.ndarray:
    """``$VEL_AXIS``/``$ACC_AXIS``'s A1..A6 percentages (`pcts`) per model axis (`size` of them,
    robot/axismap.py): an axis in an A component takes that component's; an axis in an E component
    (an external axis, a seven-axis arm's redundancy J3) 100 %."""
    out = np.full(size, 100.0)
    for i, k in enumerate(robot_slots(len(machine.joints))):
        if k in ROBOT_KEYS:
            out[i] = float(pcts[ROBOT_KEYS.index(k)])
    return out


def ptp_axis_speeds(params: Any, machine: Any, mode: str = DEFAULT_MODE) -> np.ndarray:
    """The programmed axis speeds of a PTP/SPTP motion, deg/s per axis (shape (n,): A1..An, a
    linear axis in mm/s; then the external axes E1..En in mm/s or deg/s):
    ``v_max_i · $VEL_AXIS[i]% · $OV_PRO%``, ``· $RED_T1%`` in T1 (reference §6.7, robot-model.md
    §10; an external axis at 100 % of ``$VEL_AXIS``). The one formula: the planner plans with
    it, :func:`motion_limits` checks with it."""
    v_max = np.asarray(getattr(machine, "all_max_speed", machine.max_speed_deg_s), dtype=float)
    axes = v_max * axis_percentages(params.vel_axis, machine, len(v_max)) / 100.0 * params.ov_pro / 100.0
    if mode == "T1":
        axes = axes * red_t1_pct(machine) / 100.0
    return axes


def ptp_axis_accelerations(params: Any, machine: Any, ramp: bool = True) -> np.ndarray:
    """The axis accelerations a PTP/SPTP motion is planned with, deg/s² per axis (as
    :func:`ptp_axis_speeds`: A1..An, then E1..En), as KSS 8.5 applies ``$ACC_AXIS``, ``$VEL_AXIS``
    and the program override (identified on the real KR 3 R540's recordings, tools/identify_kr3.py;
    docs/robot.md "PTP timing"):

    * ``a_max_i · $ACC_AXIS[i]%``: the percentage scales the axis' acceleration;
    * at most ``v_i² / (2 R_i)`` with ``v_i = v_max_i · $VEL_AXIS[i]%``: at a reduced axis speed the
      ramp to it covers at least the distance ``R_i`` (deg; machine data ``ptp_ramp_deg``, where
      identified: a robot without it has no such bound; `ramp` False: without this bound, which
      robot/planner.py applies to a synchronised PTP's leading axes only);
    * ``· ($OV_PRO%)²``: the program override scales the motion's time (``v · ov``, ``a · ov²``), so
      the motion takes its planned time divided by the override: the END signals of every
      recording made at 85 % (robot/exactstop.py). KUKA: the program override "is specified as a
      percentage of the programmed velocity" and "refers to all motions of the robot system"
      (mxAutomation, KRC_SetOverride, infosys.beckhoff.com/content/1033/tf5120/13081546379.html)."""
    a_max = np.asarray(getattr(machine, "all_max_acc", machine.max_acc_deg_s2), dtype=float)
    acc = axis_percentages(params.acc_axis, machine, len(a_max))
    plain = a_max * acc / 100.0 * (params.ov_pro / 100.0) ** 2
    return np.minimum(plain, ptp_ramp_accelerations(params, machine)) if ramp else plain


def ptp_ramp_accelerations(params: Any, machine: Any) -> np.ndarray:
    """The bound of :func:`ptp_axis_accelerations` at a reduced ``$VEL_AXIS``: ``v_i² / (2 R_i) ·
    ($OV_PRO%)²`` per axis (deg/s²; inf for an axis without ``R_i``)."""
    v_max = np.asarray(getattr(machine, "all_max_speed", machine.max_speed_deg_s), dtype=float)
    vel = axis_percentages(params.vel_axis, machine, len(v_max))
    out = np.full(len(v_max), np.inf)
    ramp = getattr(machine, "ptp_ramp_deg", None)
    if ramp:
        r = np.zeros(len(v_max))
        r[:len(ramp)] = ramp
        v = v_max * vel / 100.0
        out = np.where(r > 0, v * v / (2.0 * np.where(r > 0, r, 1.0)), np.inf)
    return out * (params.ov_pro / 100.0) ** 2


def cp_path_speed(params: Any, mode: str = DEFAULT_MODE) -> float:
    """The programmed path speed of a CP motion piece, mm/s: ``$VEL.CP`` (m/s) ``· 1000 ·
    $OV_PRO%``, at most 250 mm/s in T1 (reference §6.7). The one formula, as
    :func:`ptp_axis_speeds`."""
    v = params.vel_cp * 1000.0 * params.ov_pro / 100.0
    return min(v, T1_SPEED_MM_S) if mode == "T1" else v


def motion_limits(req: Any, machine: Any, mode: str = DEFAULT_MODE) -> MotionLimits:
    """The limits of a :class:`~robot.motion.MotionRequest` (see the module docstring).

    PTP/SPTP: axes ``v_max_i · $VEL_AXIS[i]% · $OV_PRO%`` (``· $RED_T1%`` in T1), no path
    limit outside T1. CP: path ``$VEL.CP · 1000 · $OV_PRO%`` mm/s (a SPLINE block: the largest
    over its segments), axes ``v_max_i``. T1: path and flange ``<= 250 mm/s``."""
    p = req.params
    if req.kind in ("PTP", "SPTP"):
        axes = ptp_axis_speeds(p, machine, mode)
        path: float | None = T1_SPEED_MM_S if mode == "T1" else None
    else:
        segments = getattr(req, "segments", ())
        axes = getattr(machine, "all_max_speed", None)
        if axes is None:
            axes = machine.max_speed_deg_s
        last = _LAST_CP
        if (not segments and last and last[0] is p and last[1] is machine and last[2] == mode
                and last[3] == axes and 0.0 not in axes):
            # the same MotionParams (interp/runtime/motion.py hands the same snapshot again while
            # nothing changed; frozen) and the same axis speeds (no zero: == is their bits): the
            # same (frozen) limits
            return last[4]
        path = cp_path_speed(p, mode) if not segments else \
            max(cp_path_speed(q, mode) for q in [p] + [s.params for s in segments if s.params])
    flange = T1_SPEED_MM_S if mode == "T1" else None
    out = MotionLimits(path, tuple(map(float, axes)), flange, tuple(map(float, p.tool)), tuple(map(float, p.base)),
                       getattr(p, "base_kin", None), getattr(p, "base_root", None))
    if path is not None and not getattr(req, "segments", ()) and req.kind not in ("PTP", "SPTP"):
        _LAST_CP[:] = [p, machine, mode, axes, out]
    return out


#: the last CP motion's (MotionParams, machine, mode, axis speeds, MotionLimits): motion_limits
_LAST_CP: list[Any] = []


# ----------------------------------------------------------------------------- checker
@dataclass(frozen=True)
class Violation:
    """One sample above its limit: ``what`` is ``path`` (TCP mm/s), ``flange`` (mm/s),
    ``axis_speed`` (deg/s) or ``axis_acc`` (deg/s²); ``axis`` 1..6 for the axis checks;
    ``t`` the time (s) of the later pose of the sample; ``motion`` the newest active id."""

    what: str
    t: float
    value: float
    limit: float
    axis: int | None = None
    motion: int | None = None

    @property
    def ratio(self) -> float:
        return self.value / self.limit if self.limit > 0 else math.inf

    def __str__(self) -> str:
        ax = f" A{self.axis}" if self.axis else ""
        return (f"t={self.t:.3f} s motion {self.motion}: {self.what}{ax} {self.value:.1f} > "
                f"{self.limit:.1f} ({100 * self.ratio:.0f} %)")


@dataclass
class LimitReport:
    """Result of :func:`check_trace`: the violations and the largest ratios measured
    (value / limit) for path speed, flange speed, axis speed and axis acceleration."""

    violations: list[Violation] = field(default_factory=list)
    path_ratio: float = 0.0
    flange_ratio: float = 0.0
    axis_speed_ratio: float = 0.0
    axis_acc_ratio: float = 0.0
    samples: int = 0

    @property
    def ok(self) -> bool:
        return not self.violations

    def summary(self) -> str:
        return (f"path {100 * self.path_ratio:.1f} %, axis speed {100 * self.axis_speed_ratio:.1f} %, "
                f"axis acc {100 * self.axis_acc_ratio:.1f} %, flange {100 * self.flange_ratio:.1f} % "
                f"of the limits over {self.samples} poses; {len(self.violations)} violations")


def _frame(f: Iterable[float]) -> np.ndarray:
    return frame_to_matrix(*[float(v) for v in f])


def _trace_robot(events: list[dict[str, Any]]) -> Any:
    """The robot named by the trace's ``robot`` header (krl run, issue 22), or None when the
    trace has none or its source is no longer there (a backup archive's temporary folder)."""

    for ev in events[:4]:
        if ev.get("kind") == "robot":
            src = Path(str(ev.get("source", "")))
            return load_robot(src) if src.is_file() else None
    return None


def check_trace(events: Iterable[dict[str, Any]], machine: Any = None, *,
                limits: dict[int, MotionLimits] | None = None,
                tol_speed: float = TOL_SPEED, tol_acc: float = TOL_ACC,
                max_violations: int = 50) -> LimitReport:
    """Check the ``pose`` events of a trace against the motions' limits.

    Args:
        events: trace event dicts (:func:`robot.trace.read_trace`).
        machine: machine data: axis maxima, kinematics for the TCP/flange speed. Default:
            the robot the trace's ``robot`` header names (its ``source``, read with
            :func:`robot.mada.load_robot`), else :func:`robot.machine.load_machine`.
        limits: motion id -> :class:`MotionLimits`; default: the ``limits`` fields of the
            trace's motion ``start`` events (motions without one are checked against the
            machine axis maxima only).
        tol_speed, tol_acc: relative tolerances (3 %, 10 %).
        max_violations: at most this many violations are listed (the ratios cover all).

    Returns a :class:`LimitReport`. Speeds of a sample (k-1, k] are checked against the
    largest limit of the motions active in it (both motions of an approximation window);
    accelerations over (k-2, k] against ``a_max_i`` (``+ c_i·|v_i|`` for an axis with
    identified friction, machine data ``ptp_friction``), except across a fault stop (an
    ``error`` event or a motion ended with ``reason`` ``abort``)."""
    events = list(events)
    machine = machine if machine is not None else _trace_robot(events) or load_machine()
    lim: dict[int, MotionLimits] = dict(limits or {})
    ts, qs, span, faults = _trace_poses(events, lim)
    rep = LimitReport(samples=len(ts))
    if len(ts) < 2:
        return rep
    chk = _TraceCheck(machine, lim, span, np.asarray(ts), np.asarray(qs, dtype=float), rep, max_violations)
    chk.check(np.asarray(sorted(faults)), tol_speed, tol_acc)
    return rep


def _trace_poses(events: list[dict[str, Any]], lim: dict[int, MotionLimits]) -> tuple[
        list[float], list[list[float]], dict[int, list[float]], list[float]]:
    """(pose times, pose axes, motion id -> [start, end], fault times) of the trace's events; the
    limits of a motion ``start`` event not in `lim` are added to it."""
    ts: list[float] = []
    qs: list[list[float]] = []
    span: dict[int, list[float]] = {}       # id -> [start, end]
    faults: list[float] = []
    for ev in events:
        k = ev.get("kind")
        if k == "pose":
            ts.append(float(ev["t"]))
            qs.append(ev["axes"])
        elif k == "motion":
            mid = int(ev["id"])
            ph = ev.get("phase")
            if ph == "start":
                span[mid] = [float(ev["t"]), math.inf]
                if mid not in lim and ev.get("limits"):
                    lim[mid] = MotionLimits.from_trace(ev["limits"])
            elif ph == "end" and mid in span:
                span[mid][1] = float(ev["t"])
                if ev.get("reason") == "abort":
                    faults.append(float(ev["t"]))
        elif k == "error":
            faults.append(float(ev["t"]))
            for s in span.values():
                if s[1] == math.inf:
                    s[1] = float(ev["t"])
    return ts, qs, span, faults


class _TraceCheck:
    """:func:`check_trace`'s samples (times T, axes Q) with their flange frames F (in world),
    the motions active at each sample, and the report it fills."""

    def __init__(self, machine: Any, lim: dict[int, MotionLimits], span: dict[int, list[float]],
                 T: np.ndarray, Q: np.ndarray, rep: LimitReport, max_violations: int) -> None:
        self.machine, self.lim, self.T, self.Q, self.rep = machine, lim, T, Q, rep
        self.max_violations = max_violations
        self.v_max = np.asarray(getattr(machine, "all_max_speed", machine.max_speed_deg_s), dtype=float)
        self.a_max = np.asarray(getattr(machine, "all_max_acc", machine.max_acc_deg_s2), dtype=float)
        # an axis with identified friction brakes the harder the faster it goes (robot/profiles.py
        # FrictionProfile): its limit is a_max + c·|v|
        self.friction = np.zeros(len(self.a_max))
        got = tuple(getattr(machine, "ptp_friction", ()) or ())[:len(self.a_max)]
        self.friction[:len(got)] = got
        self.kin = Kinematics(machine)
        F = self.kin.forward_many(Q)
        if any(k.robroot for k in getattr(machine, "external_kinematics", ())):
            ext = ExternalAxes(machine)
            F = np.array([ext.robroot(q[self.kin.n_axes:]) for q in Q]) @ F     # $ROBROOT_C on a track
        else:
            robroot = frame_to_matrix(*machine.robroot_frame)
            F = robroot @ F
        self.F = F
        self.ids = sorted(span, key=lambda m: (span[m][0], m))
        self.starts = np.array([span[m][0] for m in self.ids]) if self.ids else np.zeros(0)
        self.ends = np.array([span[m][1] for m in self.ids]) if self.ids else np.zeros(0)
        self.frames_cache: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def frames_of(self, mid: int) -> tuple[np.ndarray, np.ndarray]:
        """($TOOL, inverse $BASE) of motion `mid` (identities without its limits)."""
        if mid not in self.frames_cache:
            ml = self.lim.get(mid)
            tool = _frame(ml.tool) if ml else np.eye(4)
            base = _frame(ml.base) if ml else np.eye(4)
            self.frames_cache[mid] = (tool, inv_pos(base))
        return self.frames_cache[mid]

    def check(self, faults: np.ndarray, tol_speed: float, tol_acc: float) -> None:
        """Check every sample (k-1, k] whose time advances, all at once (numpy over the samples,
        the same numbers as one sample at a time: elementwise operations and numpy's own
        products), and list the violations in the samples' order: at each sample its axis
        speed, path, flange, then acceleration. `faults`: the fault stops' times, sorted."""
        T, Q, rep = self.T, self.Q, self.rep
        ok = ~(T[1:] - T[:-1] <= 0)         # a time that does not advance: neither side is checked
        k = np.nonzero(ok)[0] + 1
        if not len(k):
            return
        dt = T[k] - T[k - 1]
        V = np.zeros_like(Q)
        V[k] = (Q[k] - Q[k - 1]) / dt[:, None]
        group, sets = self._active_sets(k)
        found: list[tuple[int, int, Violation]] = []      # (sample, order in the sample, violation)
        newest = [act[-1] if act else None for act in sets]
        ax_lim = np.empty((len(sets), Q.shape[1]))
        for g, act in enumerate(sets):
            ids = [m for m in act if m in self.lim]
            ax_lim[g] = np.max([self.lim[m].axes for m in ids], axis=0) if ids else self.v_max
        R = np.abs(V[k]) / ax_lim[group]
        rep.axis_speed_ratio = _ratio(rep.axis_speed_ratio, R, float)
        for j in np.nonzero(R.max(axis=1) > 1.0 + tol_speed)[0]:
            i, g = int(np.argmax(R[j])), group[j]
            found.append((k[j], 0, Violation("axis_speed", float(T[k[j]]), float(abs(V[k[j]][i])),
                                             float(ax_lim[g][i]), i + 1, newest[g])))
        self._cartesian(k, dt, group, sets, tol_speed, found)
        # accelerations over (k-2, k]: both samples checked, no fault stop in between
        a = k[(k >= 2) & ok[np.maximum(k - 2, 0)]]
        if len(faults):
            a = a[np.searchsorted(faults, T[a] + 1e-9, "right") <= np.searchsorted(faults, T[a - 2] - 1e-9, "right")]
        acc = (V[a] - V[a - 1]) / (0.5 * (T[a] - T[a - 2]))[:, None]
        a_lim = self.a_max + self.friction * np.maximum(np.abs(V[a]), np.abs(V[a - 1]))
        RA = np.abs(acc) / a_lim
        rep.axis_acc_ratio = _ratio(rep.axis_acc_ratio, RA, float)
        ga = group[np.searchsorted(k, a)]
        for j in np.nonzero(RA.max(axis=1) > 1.0 + tol_acc)[0] if len(a) else ():
            i = int(np.argmax(RA[j]))
            found.append((a[j], 3, Violation("axis_acc", float(T[a[j]]), float(abs(acc[j][i])), float(a_lim[j][i]),
                                             i + 1, newest[ga[j]])))
        for _, _, v in sorted(found, key=lambda f: (f[0], f[1]))[:self.max_violations - len(rep.violations)]:
            rep.violations.append(v)

    def _active_sets(self, k: np.ndarray) -> tuple[np.ndarray, list[tuple[int, ...]]]:
        """(per sample of `k`, the index of the motions active in (k-1, k] among the sets; the
        sets, each the motion ids in start order). A motion is active in a sample its span
        touches (1 ns tolerance)."""
        ids = self.ids
        if not ids:
            return np.zeros(len(k), dtype=np.intp), [()]
        rows = max(1, (1 << 22) // len(ids))           # a few MB of the sample x motion table at a time
        packed = np.concatenate([np.packbits((self.starts <= (self.T[kk] + 1e-9)[:, None])
                                             & (self.ends >= (self.T[kk - 1] - 1e-9)[:, None]), axis=1)
                                 for kk in (k[s:s + rows] for s in range(0, len(k), rows))])
        packed = np.ascontiguousarray(packed)
        keys = packed.view(np.dtype((np.void, packed.shape[1]))).ravel()
        uniq, group = np.unique(keys, return_inverse=True)
        sets = [tuple(ids[j] for j in np.nonzero(np.unpackbits(np.frombuffer(u.tobytes(), np.uint8))[:len(ids)])[0])
                for u in uniq]
        return group.reshape(-1), sets

    def _cartesian(self, k: np.ndarray, dt: np.ndarray, group: np.ndarray, sets: list[tuple[int, ...]],
                   tol_speed: float, found: list) -> None:
        """Check the path (TCP in the newest motion's $BASE) and flange speeds of the samples
        `k` (their intervals `dt`, their active sets `sets[group]`) where a motion active has
        limits; the largest of the active motions' limits applies."""
        lim, rep, F = self.lim, self.rep, self.F
        path_rows: dict[int, list[int]] = {}     # newest motion -> rows of k with a path limit
        p_of, f_of = np.full(len(sets), np.nan), np.full(len(sets), np.nan)
        for g, act in enumerate(sets):
            ids = [m for m in act if m in lim]
            if not act or not ids:
                continue
            paths, fl = [lim[m].path for m in ids], [lim[m].flange for m in ids]
            if not any(p is None for p in paths):
                p_of[g] = max(paths)
            if not any(f is None for f in fl):
                f_of[g] = max(fl)
        p_row, f_row = p_of[group], f_of[group]
        for j in np.nonzero(~np.isnan(p_row))[0]:
            path_rows.setdefault(sets[group[j]][-1], []).append(j)
        ratios = []
        for mid, js in path_rows.items():
            js = np.asarray(js)
            sp = self._path_speeds(mid, k[js]) / dt[js]
            ratios.append(sp / p_row[js])
            for j in np.nonzero(sp > p_row[js] * (1.0 + tol_speed))[0]:
                kk = k[js[j]]
                found.append((kk, 1, Violation("path", float(self.T[kk]), sp[j], float(p_row[js[j]]), None, mid)))
        if ratios:
            rep.path_ratio = _ratio(rep.path_ratio, np.concatenate(ratios)[:, None], np.float64)
        js = np.nonzero(~np.isnan(f_row))[0]
        if len(js):
            sp = _norms(F[k[js], :3, 3] - F[k[js] - 1, :3, 3]) / dt[js]
            rep.flange_ratio = _ratio(rep.flange_ratio, (sp / f_row[js])[:, None], np.float64)
            for j in np.nonzero(sp > f_row[js] * (1.0 + tol_speed))[0]:
                kk = k[js[j]]
                found.append((kk, 2, Violation("flange", float(self.T[kk]), sp[j], float(f_row[js[j]]), None,
                                               sets[group[js[j]]][-1])))

    def _path_speeds(self, mid: int, k: np.ndarray) -> np.ndarray:
        """The TCP's distances (mm) from sample k-1 to k in motion `mid`'s $BASE with its $TOOL."""
        tool, binv = self.frames_of(mid)
        ml = self.lim.get(mid)
        if ml is not None and ml.base_kin:
            # a base on a turntable: the path is measured in the turning base
            ext = ExternalAxes(self.machine)
            na, Q, F = self.kin.n_axes, self.Q, self.F
            et = ext.base_kins[ml.base_kin]
            out = np.empty(len(k))
            for j, kk in enumerate(k):
                a = (binv @ inv_pos(ext.chain(et, Q[kk - 1][na:], ml.base_root)) @ F[kk - 1] @ tool)[:3, 3]
                b = (binv @ inv_pos(ext.chain(et, Q[kk][na:], ml.base_root)) @ F[kk] @ tool)[:3, 3]
                out[j] = float(np.linalg.norm(b - a))
            return out
        W = binv @ self.F[np.concatenate([k - 1, k])] @ tool
        return _norms(W[len(k):, :3, 3] - W[:len(k), :3, 3])


def _norms(d: np.ndarray) -> np.ndarray:
    """``np.linalg.norm`` of each row of `d` (n x 3), bit for bit: the square root of the row's
    own dot product (numpy's, as the norm of one vector takes it)."""
    return np.sqrt((d[:, None, :] @ d[:, :, None])[:, 0, 0])


def _ratio(now: Any, ratios: np.ndarray, kind: type) -> Any:
    """`now` raised to the largest of the rows' largest `ratios` (n x m), as a maximum taken
    row by row would: a row with a NaN counts for nothing; the result is a `kind` (float or
    numpy's float64) when it is larger than `now`."""
    if not ratios.size:
        return now
    top = ratios.max(axis=1)
    top = top[~np.isnan(top)]
    return max(now, kind(top.max())) if top.size else now


__all__ = ["MotionLimits", "motion_limits", "check_trace", "LimitReport", "Violation",
           "normalise_mode", "red_t1_pct", "ptp_axis_speeds", "cp_path_speed", "T1_SPEED_MM_S", "MODES", "DEFAULT_MODE",
           "TOL_SPEED", "TOL_ACC"]
