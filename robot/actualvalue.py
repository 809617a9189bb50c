"""The actual-value model: the axes a robot's drives reach behind its interpolator's setpoints,
one IPO cycle at a time (issue 73, item 2), and when they have settled.

One model for ``krl run``'s trace (the ``pose`` events' ``axes_act``/``tcp_act``, robot/trace.py),
its summary's settled cycle time (interp/summary.py) and ``krl trace compare``
(robot/kukatrace/actual.py ``actual_tcp``, through :func:`actual_axes`): the setpoints averaged in
axis space over ``MachineData.actual_filter_cycles`` IPO cycles (causal: each row the mean of its
own and the n - 1 before, the first row standing for the rows before the start), less the drives'
following error ``m_i·q̈ + c_i·tanh(q̇_i/v0) + k_i·q̇_i`` of the averaged axes
(``MachineData.actual_following``; q̇, q̈ central differences, one-sided at the ends, as
``numpy.gradient``), all of it ``MachineData.actual_dead_cycles`` IPO cycles late (a dead time: row
k of the model is computed from the setpoints up to row k - d, the rows before the first being the
first). All three were identified from the real KR 3 R540's recordings (docs/robot.md "The drives'
following error", "The dead time": 3 cycles, the measured axes leave rest 36 ms after the model
without it); a robot without them has no model (:func:`has_model`).

**A PTP's own average** (issue 88). A row a PTP (or SPTP) set is averaged over
``MachineData.actual_filter_cycles_ptp`` cycles instead (None: the same): KSS filters a PTP's
setpoints with ``$DEF_FLT_PTP`` and a CP motion's with ``$DEF_FLT_CP``, and every KR C4
``$machine.dat`` of ../shared/krl-corpus holds the PTP one longer (168/120, 180/132, 216/156 ms,
"DEFAULTFILTER PTP/CP"). A row's kind travels with it through the dead time; rows at rest after a
motion keep its kind (:meth:`ActualStream.push`; :func:`ptp_rows_of` for a trace's segment). The
KR 3 R540's 5 cycles (4 for CP) were identified on the exact-stop PTPs of its recordings, chosen
the same in every program left out (robot/kukatrace/identify.py ``fit_filter_ptp``; docs/robot.md
"The settling into ``$IN_POS_MA``").

:class:`ActualStream` computes it as the rows come, in batches: a row's actual axes need its two
successors (the central differences), so each row is known two cycles later, and the rows are the
same, bit for bit, whichever batches they came in (every value is a sum over a fixed window of
rows, never a running sum). :func:`actual_axes` is the same stream over a whole array.

**Settled.** KUKA's controller checks, per axis, that the following error is inside the axis'
positioning window ``$IN_POS_MA`` (deg) with the axis at rest: the axis is *in position* (KUKA
Machine Data, KR C2, 12.04.00 en, §2.1.119 ``$IN_POS_MA[]``, default 0.1°). The stream says when
its actual axes last were outside ``MachineData.in_pos_ma_deg`` of the setpoint (the setpoint of
the same cycle: the dead time counts): the robot has settled from the next cycle on. The real KR 3 R540's measured ("Act") axes lag its setpoints by
36-48 ms (../shared/real-traces README, "KRCIpo.csv"); at the end of a run the stream goes on with
the robot at rest (:meth:`ActualStream.finish`) until its actual axes have settled.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

import numpy as np

#: rows the stream gathers before it computes them (a batch's numpy work is mostly per call)
BATCH_ROWS = 64
#: the rows at rest :meth:`ActualStream.finish` adds for a settling lag to decay (25 cycles: 10 τ
#: of the largest τ the KR 3 R540's lag reaches, about 30 ms)
LAG_REST_ROWS = 25
#: the motion kinds whose setpoints the PTP average takes (``MachineData.actual_filter_cycles_ptp``)
PTP_KINDS = ("PTP", "SPTP")


def has_model(machine: Any) -> bool:
    """True when `machine` (MachineData) has an actual-value model: an average over more than one
    IPO cycle, a following error or a dead time."""
    return (int(getattr(machine, "actual_filter_cycles", 1)) > 1 or bool(getattr(machine, "actual_following", None))
            or int(getattr(machine, "actual_dead_cycles", 0)) > 0)


def mean_window(x: np.ndarray, n: int) -> np.ndarray:
    """Row j of the result: the mean of rows j .. j + n - 1 of `x` (a sum in a fixed order, so
    the same rows give the same bits wherever they stand)."""
    m = len(x) - n + 1
    s = x[0:m].copy()
    for k in range(1, n):
        s += x[k:k + m]
    return s / n


def following_error(q: np.ndarray, params: dict, dt: float) -> np.ndarray:
    """The drives' following error (N, n_axes) deg behind averaged setpoints `q` (N, n_axes) deg,
    one row per IPO cycle of `dt` s: ``m_i·q̈_i + c_i·tanh(q̇_i/v0) + k_i·q̇_i`` (the module's
    docstring). `params`: ``inertia_s2`` m (n_axes,) s², ``coulomb_deg`` c deg, ``viscous_s`` k s,
    ``coulomb_speed_deg_s`` v0 deg/s. Fewer than 3 rows: zeros."""
    if len(q) < 3:
        return np.zeros_like(q)
    v = np.gradient(q, dt, axis=0)
    a = np.gradient(v, dt, axis=0)
    m, c, k = (np.asarray(params[key], dtype=float) for key in ("inertia_s2", "coulomb_deg", "viscous_s"))
    return m * a + c * np.tanh(v / float(params["coulomb_speed_deg_s"])) + k * v


class ActualStream:
    """The actual-value model over setpoints pushed one IPO cycle at a time (the module's
    docstring). ``cycles`` n of the average, ``following`` the following error's parameters (None
    or ``{}``: none), ``dt`` the IPO cycle (s), ``n_axes`` the robot's axes (the model acts on
    A1..An; external axes pass unchanged), ``window`` each axis' positioning window (deg; None:
    no settling kept), ``keep`` True to keep each computed row until :meth:`take` (a trace's
    poses), with the `extra` object pushed beside it; ``lag`` the settling lag's ``axis``,
    ``below_deg_s`` (the module's docstring; None: none, each row's τ then unused); ``at_rest`` True: the robot stood at the
    first row's setpoint before it (a run's start: the rows before it are that row), else the
    first rows take one-sided differences (a window of a longer run).

    Attributes after each computation: ``done`` rows computed, ``last_change`` the time of the
    last row whose setpoint differs from the one before (None: none did), ``last_out`` the time of
    the last row whose actual axes were outside the window (None: none was)."""

    def __init__(self, cycles: int, following: dict | None, dt: float, n_axes: int,
                 window: Any = None, keep: bool = False, at_rest: bool = False, dead: int = 0,
                 ptp_cycles: int | None = None, lag: dict | None = None) -> None:
        self.n = max(1, int(cycles))
        self.lag = dict(lag) if lag else None
        self._tau = 0.0                          # the settling lag's τ of the last row pushed (s)
        self._taus: list[float] = []             # each pending row's τ (delayed as its setpoint)
        self._lag_state: tuple[float, float, float] | None = None   # (y, x, |v|) of the last row computed
        self.n_ptp = self.n if not ptp_cycles else max(1, int(ptp_cycles))
        self.span = max(self.n, self.n_ptp)      # the rows the longer average spans
        self._ptp = False                        # the kind of the last row pushed (PTP or not)
        self._flags: list[bool] = []             # each pending row's input: a PTP's (delayed as it)
        self._ctx_flags: np.ndarray | None = None
        self.dead = max(0, int(dead))
        self._fifo: deque | None = None          # the last `dead` setpoints pushed (the dead time's)
        self._inputs: list[Any] = []             # the model's input of each row pending (delayed)
        self.at_rest = at_rest
        self.following = following or None
        self.dt = float(dt)
        self.n_axes = int(n_axes)
        self.window = None if window is None else np.asarray(window, dtype=float)[:self.n_axes]
        self.keep = keep
        self._ctx: np.ndarray | None = None      # rows before the first not computed (the average's)
        self._rows: list[Any] = []               # rows pushed, not computed
        self._times: list[float] = []
        self._extra: list[Any] = []
        self._prev: np.ndarray | None = None     # the setpoint row before the first not computed
        self.done = 0
        self.pushed = 0
        self.last_change: float | None = None
        self.last_out: float | None = None
        self.last_t: float | None = None
        self.out: list[tuple[int, Any, np.ndarray]] = []   # (row, extra, actual row) kept for take()
        self.finished = False

    def push(self, t: float, q: Any, extra: Any = None, ptp: bool | None = None, tau: float | None = None) -> None:
        """One IPO cycle's setpoint row `q` (deg, mm) at time `t` (s); `ptp` True when a PTP
        (or SPTP) set it, False for any other motion, None (default) as the row before (the robot
        at rest after a motion): the row is averaged over ``ptp_cycles`` or ``cycles``; `tau` the
        settling lag's time constant of the motion that set it (s; None: as the row before)."""
        if ptp is not None:
            self._ptp = bool(ptp)
        if tau is not None:
            self._tau = float(tau)
        self._rows.append(q)
        self._queue(q)
        self._times.append(t)
        self._extra.append(extra)
        self.pushed += 1
        self.last_t = t
        if len(self._rows) >= BATCH_ROWS:
            self._compute(final=False)

    def _queue(self, q: Any) -> None:
        """The model's input of the row `q` pushed: the (setpoint, kind, τ) `dead` rows before."""
        got = self._delayed((q, self._ptp, self._tau))
        self._inputs.append(got[0])
        self._flags.append(got[1])
        self._taus.append(got[2])

    def _delayed(self, q: Any) -> Any:
        """The (setpoint, kind) `dead` rows before `q` (the first row's before the first)."""
        if not self.dead:
            return q
        if self._fifo is None:
            self._fifo = deque([q] * self.dead)
        self._fifo.append(q)
        return self._fifo.popleft()

    def take(self) -> list[tuple[int, Any, np.ndarray]]:
        """The computed rows kept since the last call: (row number from 0, extra, actual row), in
        order."""
        got, self.out = self.out, []
        return got

    def finish(self, rest: bool = True) -> None:
        """Compute every row pushed. `rest`: the robot stays at its last setpoint after the last
        row (a run that ended): rows at rest follow until the actual axes have settled (they are
        not kept, their times count for the settled end); else the last rows take one-sided
        differences (a window of a longer run). A second call does nothing."""
        if self.finished:
            return
        self.finished = True
        if rest and self.pushed:
            q = np.asarray(self._rows[-1] if self._rows else self._last_row, dtype=float)
            t = self.last_t
            keep, self.keep = self.keep, False
            # the average, the two differences, the dead time (and the settling lag's decay)
            rest_rows = self.span + 2 + self.dead + (LAG_REST_ROWS if self.lag else 0)
            for k in range(1, rest_rows + 1):
                self._rows.append(q)
                self._queue(q)
                self._times.append(t + k * self.dt)
                self._extra.append(None)
            self._compute(final=True, kept=len(self._rows) - rest_rows, keep=keep)
            self.keep = keep
            return
        self._compute(final=True)

    def settled_at(self) -> float | None:
        """The time (s) from which the actual axes stayed within the positioning window: the row
        after the last one outside it (the first row when none was); None before any row."""
        if self.last_t is None:
            return None
        if self.last_out is None:
            return self._first_t
        return self.last_out + self.dt

    def _compute(self, final: bool, kept: int | None = None, keep: bool | None = None) -> None:
        """Compute the rows whose successors are pushed (all with `final`); `kept` of the rows
        pending are real (the rest are :meth:`finish`'s rest rows), `keep` whether to keep them."""
        if not self._rows:
            return
        Q = np.asarray(self._rows, dtype=float)
        if Q.ndim == 1:
            Q = Q.reshape(len(self._rows), -1)
        D = Q if not self.dead else np.asarray(self._inputs, dtype=float).reshape(Q.shape)
        F = np.asarray(self._flags, dtype=bool)
        start = self._ctx is None
        if start:
            self._first_t = self._times[0]
            self._prev = Q[0]
            ctx = np.repeat(D[:1], self.span - 1 + (2 if self.at_rest else 0), axis=0)
            self._ctx_flags = np.repeat(F[:1], len(ctx))
        else:
            ctx = self._ctx
        X = np.vstack([ctx, D]) if len(ctx) else D
        XF = np.concatenate([self._ctx_flags, F])
        na = self.n_axes
        qf = self._averaged(X[:, :na], XF)
        c = len(ctx) - (self.span - 1)           # rows of qf before the first to compute (0..2)
        L = len(qf)
        last = L - 1 if final else L - 3
        if last < c:
            return
        act_r = qf - following_error(qf, self.following, self.dt) if self.following else qf
        E = last - c + 1
        act = Q[:E].copy()
        act[:, :na] = act_r[c:c + E]
        if self.lag is not None:
            self._settle(act, self._taus[:E])
        self._account(Q[:E], act, kept, keep)
        u = len(ctx) + E                         # the first row of X not computed
        self._ctx = X[max(0, u - (self.span + 1)):u]
        self._ctx_flags = XF[max(0, u - (self.span + 1)):u]
        self._last_row = Q[E - 1]
        self._rows, self._times, self._extra = self._rows[E:], self._times[E:], self._extra[E:]
        self._inputs, self._flags, self._taus = self._inputs[E:], self._flags[E:], self._taus[E:]

    def _settle(self, act: np.ndarray, taus: list[float]) -> None:
        """The settling lag (the module's docstring) on ``lag['axis']`` of the rows `act` computed
        in order, each with its τ (s) of `taus`; in place."""
        i = int(self.lag["axis"]) - 1
        below = float(self.lag["below_deg_s"])
        col = act[:, i]
        y, x0, v0 = self._lag_state if self._lag_state is not None else (col[0], col[0], 0.0)
        for k in range(len(col)):
            x = float(col[k])
            v = abs(x - x0) / self.dt
            tau = taus[k]
            if tau > 0.0 and v < below and v <= v0:
                y += (x - y) * (1.0 - math.exp(-self.dt / tau))
            else:
                y = x
            x0, v0 = x, v
            col[k] = y
        self._lag_state = (y, x0, v0)

    def _averaged(self, X: np.ndarray, flags: np.ndarray) -> np.ndarray:
        """Row j: the mean of rows j .. j + span - 1 of `X`'s last ``cycles`` of them, or of its
        last ``ptp_cycles`` where row j + span - 1 is a PTP's (`flags`)."""
        def mean(n: int) -> np.ndarray:
            got = mean_window(X, n) if n > 1 else X.copy()
            return got[self.span - n:]
        qf = mean(self.n)
        if self.n_ptp != self.n and np.any(flags[self.span - 1:]):
            qf = np.where(flags[self.span - 1:, None], mean(self.n_ptp), qf)
        return qf

    def _account(self, Q: np.ndarray, act: np.ndarray, kept: int | None, keep: bool | None) -> None:
        """Settling, changes and the rows kept, for the rows `Q` computed as `act`."""
        times = self._times[:len(Q)]
        prev = np.vstack([self._prev[None, :], Q[:-1]])
        changed = np.flatnonzero(np.any(Q != prev, axis=1))
        real = len(Q) if kept is None else min(kept, len(Q))
        changed = changed[changed < real]
        if len(changed):
            self.last_change = times[int(changed[-1])]
        self._prev = Q[-1]
        if self.window is not None:
            na = self.n_axes
            out = np.flatnonzero(np.any(np.abs(act[:, :na] - Q[:, :na]) > self.window, axis=1))
            if len(out):
                self.last_out = times[int(out[-1])]
        if self.keep if keep is None else keep:
            for k in range(real):
                self.out.append((self.done + k, self._extra[k], act[k]))
        self.done += len(Q)


def actual_axes(q: np.ndarray, cycles: int, following: dict | None, dt: float,
                n_axes: int | None = None, dead: int = 0, ptp_rows: Any = None,
                ptp_cycles: int | None = None, lag: dict | None = None, taus: Any = None) -> np.ndarray:
    """The actual axes (N, k) of setpoints `q` (N, k) deg, one row per IPO cycle of `dt` s, through
    :class:`ActualStream` over the whole array (the last rows one-sided: a window of a run); the
    model acts on the first `n_axes` columns (default all; the following error's parameters
    have one value per such axis), `dead` IPO cycles behind (the rows before the first: its
    setpoint); `ptp_rows` (N,) bool: the rows a PTP set, averaged over `ptp_cycles` (None: every
    row over `cycles`; :func:`ptp_rows_of` gives them for a trace's segment); `lag` the settling
    lag (None: none) with `taus` (N,) each row's τ s (robot/settlelag.py ``row_taus``)."""
    q = np.asarray(q, dtype=float)
    if len(q) == 0:
        return q.copy()
    s = ActualStream(cycles, following, dt, q.shape[1] if n_axes is None else n_axes, keep=True, dead=dead,
                     ptp_cycles=ptp_cycles, lag=lag if taus is not None else None)
    flags = np.zeros(len(q), dtype=bool) if ptp_rows is None else np.asarray(ptp_rows, dtype=bool)
    tau = np.zeros(len(q)) if taus is None else np.asarray(taus, dtype=float)
    for k, row in enumerate(q):
        s.push(k * dt, row, ptp=bool(flags[k]), tau=float(tau[k]))
    s.finish(rest=False)
    return np.array([row for _, _, row in s.take()])


def ptp_rows_of(t: np.ndarray, motions: Any) -> np.ndarray:
    """(N,) bool: which samples at times `t` (s) a PTP or SPTP set, from `motions` (each with
    ``kind`` and ``start`` s, in order: robot/kukatrace/model.py ``Motion``): a sample belongs to
    the last motion started at or before it (the robot at rest after it included), a sample
    before the first motion to the first."""
    t = np.asarray(t, dtype=float)
    out = np.zeros(len(t), dtype=bool)
    for k, m in enumerate(motions):
        t0 = m.start if k else -np.inf
        t1 = motions[k + 1].start if k + 1 < len(motions) else np.inf
        if str(m.kind).upper() in PTP_KINDS:
            out[(t >= t0 - 1e-9) & (t < t1 - 1e-9)] = True
    return out


def stream_for(machine: Any, keep: bool = False) -> ActualStream | None:
    """The :class:`ActualStream` of a run on `machine` (MachineData: its average, following error,
    dead time, settling lag, IPO cycle, axes and ``$IN_POS_MA``; the robot at rest before the run and after it),
    or None when it has no actual-value model (:func:`has_model`)."""
    if not has_model(machine):
        return None
    n = int(machine.n_axes)
    return ActualStream(machine.actual_filter_cycles, machine.actual_following, machine.ipo_cycle_s, n,
                        window=tuple(machine.in_pos_ma_deg)[:n], keep=keep, at_rest=True,
                        dead=int(getattr(machine, "actual_dead_cycles", 0)),
                        ptp_cycles=getattr(machine, "actual_filter_cycles_ptp", None),
                        lag=getattr(machine, "actual_settle_lag", None))


__all__ = ["ActualStream", "BATCH_ROWS", "LAG_REST_ROWS", "PTP_KINDS", "actual_axes", "ptp_rows_of", "following_error", "has_model", "mean_window", "stream_for"]
