"""Digital and analog I/O, timers and the I/O event log of the simulated controller
(reference §5.12-§5.15, §7.1).

* ``$IN[1..8192]`` (read-only for programs; ``$IN[1025]`` is always TRUE), ``$OUT[1..8192]``;
* ``$ANIN[1..32]``, ``$ANOUT[1..32]``, values clamped to -1.0 .. +1.0;
* ``$TIMER[1..64]`` in ms, counting up by one IPO cycle (12 ms) per cycle while
  ``$TIMER_STOP[n]`` is FALSE (boot: all stopped); ``$TIMER_FLAG[n]`` = ``$TIMER[n] >= 0``.

Every change of a signal is appended to :attr:`IOImage.log` as ``(t, signal, value, source)``
and reported to the optional ``on_change`` callback (the controller writes it to the trace
as an ``io`` event). Writing the value a signal already has is not an event.

:attr:`IOImage.version` changes with every change of a signal and every write that changes a
timer or its stop flag (not with a running timer's count: that is the clock; not with a write
of the value it has, which changes nothing: a submit program that resets a stopped timer in
every pass is a spin, interp/runtime/spin.py); it is unique across images, so "same version"
means "nothing here changed" (the runtime re-evaluates an interrupt condition over I/O only
then: interp/runtime/watch.py).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass, field

N_DIGITAL = 8192
N_ANALOG = 32
N_TIMERS = 64
ALWAYS_TRUE_INPUT = 1025

#: the versions of every I/O image of the process (IOImage.version)
_VERSIONS = itertools.count(1)


class IOError_(ValueError):
    """Bad signal index or a write to a read-only signal (reference §5.13)."""


@dataclass
class IOImage:
    """The I/O image. Indices are 1-based as in KRL.

    Attributes:
        log: list of ``(t_s, signal_name, value, source)`` for every change.
        on_change: called as ``on_change(t_s, signal_name, value, source)`` on every change.
        now: current simulated time in s (kept up to date by the controller).
        writer: a network partner writing into the run now (its I/O changes' source), or None.
    """

    on_change: Callable[[float, str, object, str], None] | None = None
    now: float = 0.0
    #: who writes now when it is not the running program: a network partner writing a variable
    #: into the run (interp/runtime/netvars.py ``RuntimeSink.write_var``: ``varproxy``), the
    #: source its I/O changes are logged with (interp/runtime/sysvars.py ``RunReads.io_source``)
    writer: str | None = None
    log: list[tuple[float, str, object, str]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._in = bytearray(N_DIGITAL + 1)
        self._in[ALWAYS_TRUE_INPUT] = 1
        self._out = bytearray(N_DIGITAL + 1)
        self._anin = [0.0] * (N_ANALOG + 1)
        self._anout = [0.0] * (N_ANALOG + 1)
        self.timer_ms = [0] * (N_TIMERS + 1)
        self.timer_stop = [True] * (N_TIMERS + 1)
        self.version = next(_VERSIONS)
        #: the running timers as tick_timers last found them (:meth:`_running_now`)
        self._running: tuple = (None, ())

    # -- helpers ---------------------------------------------------------------------------
    @staticmethod
    def _check(n: int, hi: int, name: str) -> int:
        n = int(n)
        if not 1 <= n <= hi:
            raise IOError_(f"{name}[{n}]: index outside 1..{hi}")
        return n

    def _changed(self, name: str, value: object, source: str) -> None:
        self.version = next(_VERSIONS)
        self.log.append((self.now, name, value, source))
        if self.on_change is not None:
            self.on_change(self.now, name, value, source)

    # -- digital ---------------------------------------------------------------------------
    def get_in(self, n: int) -> bool:
        """``$IN[n]``."""
        if type(n) is int and 0 < n <= N_DIGITAL:     # the common case, without the call
            return bool(self._in[n])
        return bool(self._in[self._check(n, N_DIGITAL, "$IN")])

    def set_in(self, n: int, value: bool, source: str = "stimulus") -> None:
        """Set a simulated input (environment side; programs cannot write inputs)."""
        n = self._check(n, N_DIGITAL, "$IN")
        if n == ALWAYS_TRUE_INPUT:
            return
        v = 1 if value else 0
        if self._in[n] != v:
            self._in[n] = v
            self._changed(f"$IN[{n}]", bool(v), source)

    def get_out(self, n: int) -> bool:
        """``$OUT[n]``."""
        if type(n) is int and 0 < n <= N_DIGITAL:     # the common case, without the call
            return bool(self._out[n])
        return bool(self._out[self._check(n, N_DIGITAL, "$OUT")])

    def set_out(self, n: int, value: bool, source: str = "program") -> None:
        """``$OUT[n] = value``."""
        n = self._check(n, N_DIGITAL, "$OUT")
        v = 1 if value else 0
        if self._out[n] != v:
            self._out[n] = v
            self._changed(f"$OUT[{n}]", bool(v), source)

    # -- analog ----------------------------------------------------------------------------
    def get_anin(self, n: int) -> float:
        """``$ANIN[n]`` (-1.0 .. 1.0)."""
        return self._anin[self._check(n, N_ANALOG, "$ANIN")]

    def set_anin(self, n: int, value: float, source: str = "stimulus") -> None:
        n = self._check(n, N_ANALOG, "$ANIN")
        v = max(-1.0, min(1.0, float(value)))
        if self._anin[n] != v:
            self._anin[n] = v
            self._changed(f"$ANIN[{n}]", v, source)

    def get_anout(self, n: int) -> float:
        """``$ANOUT[n]`` (-1.0 .. 1.0)."""
        return self._anout[self._check(n, N_ANALOG, "$ANOUT")]

    def set_anout(self, n: int, value: float, source: str = "program") -> None:
        """``$ANOUT[n] = value``; the value is clamped to -1.0 .. 1.0."""
        n = self._check(n, N_ANALOG, "$ANOUT")
        v = max(-1.0, min(1.0, float(value)))
        if self._anout[n] != v:
            self._anout[n] = v
            self._changed(f"$ANOUT[{n}]", v, source)

    # -- by name ---------------------------------------------------------------------------
    def set_signal(self, name: str, value: object, source: str = "stimulus") -> None:
        """Set ``$IN[n]``, ``$ANIN[n]``, ``$OUT[n]`` or ``$ANOUT[n]`` given as text."""
        base, n = parse_signal(name)
        if base == "$IN":
            self.set_in(n, bool(value), source)
        elif base == "$ANIN":
            self.set_anin(n, float(value), source)  # type: ignore[arg-type]
        elif base == "$OUT":
            self.set_out(n, bool(value), source)
        elif base == "$ANOUT":
            self.set_anout(n, float(value), source)  # type: ignore[arg-type]
        else:  # pragma: no cover - parse_signal guards this
            raise IOError_(f"unknown signal {name}")

    def image(self) -> tuple:
        """The values of every digital and analog input and output and of every timer and its
        stop flag, comparable (``==``): what a program that names the I/O image whole reads
        (interp/runtime/spin.py ``SpinWatch._image``)."""
        return (bytes(self._in), bytes(self._out), tuple(self._anin), tuple(self._anout), tuple(self.timer_ms),
                tuple(self.timer_stop))

    # -- timers ----------------------------------------------------------------------------
    def tick_timers(self, dt_ms: int) -> None:
        """Advance every running ``$TIMER`` by ``dt_ms`` (called once per IPO cycle)."""
        run = self._running
        if run[0] is not self.timer_stop:
            run = self._running = self._running_now()
        if run[1]:
            tm = self.timer_ms
            for i in run[1]:
                tm[i] += dt_ms

    def _running_now(self) -> tuple:
        """(the stop flags' list, the indices of the running timers): what :meth:`tick_timers`
        counts until :meth:`set_timer_stop` changes a flag or the list is replaced
        (interp/runtime/model.py copies a model's image); count() and index() run in C."""
        st = self.timer_stop
        found, i = [], 0
        for _ in range(st.count(False) - (not st[0])):      # [0] is no timer
            i = st.index(False, i + 1)
            found.append(i)
        return st, tuple(found)

    def get_timer(self, n: int) -> int:
        """``$TIMER[n]`` in ms."""
        return self.timer_ms[self._check(n, N_TIMERS, "$TIMER")]

    def set_timer(self, n: int, ms: int) -> None:
        """Preset ``$TIMER[n]`` (ms). Writing the value it has changes nothing (no new version)."""
        n = self._check(n, N_TIMERS, "$TIMER")
        ms = int(ms)
        if self.timer_ms[n] != ms:
            self.timer_ms[n] = ms
            self.version = next(_VERSIONS)

    def get_timer_stop(self, n: int) -> bool:
        return self.timer_stop[self._check(n, N_TIMERS, "$TIMER_STOP")]

    def set_timer_stop(self, n: int, stopped: bool) -> None:
        """``$TIMER_STOP[n] = stopped``. Writing the value it has changes nothing (no new version)."""
        n = self._check(n, N_TIMERS, "$TIMER_STOP")
        stopped = bool(stopped)
        if self.timer_stop[n] != stopped:
            self.timer_stop[n] = stopped
            self.version = next(_VERSIONS)
            self._running = (None, ())       # tick_timers finds the running ones again

    def get_timer_flag(self, n: int) -> bool:
        """``$TIMER_FLAG[n]`` = ``$TIMER[n] >= 0``."""
        return self.get_timer(n) >= 0


def parse_signal(name: str) -> tuple[str, int]:
    """``"$IN[3]"`` -> ``("$IN", 3)``: decodes the signal keys the project writes itself (the
    ``set`` of a stimulus or rule after robot/stimuli.py read the user's text through the front
    end with :func:`robot.cellrules.signal_of`, robot/cellpresets.py's answers); never given a
    user's text, which only krl/semantics/expression.py parses. Accepts $IN, $OUT, $ANIN,
    $ANOUT (case-insensitive); raises IOError_ for anything else."""
    s = name.strip().upper().replace(" ", "")
    if "[" not in s or not s.endswith("]"):
        raise IOError_(f"not a signal: {name!r}")
    base, idx = s[:-1].split("[", 1)
    if base not in ("$IN", "$OUT", "$ANIN", "$ANOUT"):
        raise IOError_(f"not a signal: {name!r}")
    try:
        return base, int(idx)
    except ValueError:
        raise IOError_(f"not a signal: {name!r}") from None
