"""How a KR C4 (KSS 8.5) ends an exact-stop motion and starts the next one: the controller's
timing, identified from the real KUKA Trace recordings of ../shared/real-traces (issue 60;
``python tools/identify_kr3.py`` checks it on every recording, docs/robot.md "The controller's
timing").

* The interpolation of a motion ends at ``t_f`` (its START plus its planned duration divided by
  the program override). The motion's END signal (KUKA Trace PROG.TXT, ``SIGNAL: END``) comes
  :data:`END_DELAY_CYCLES` IPO cycles after the cycle in which ``t_f`` falls:
  ``END = (floor(t_f / cycle) + 3) · cycle``, i.e. 24-36 ms after ``t_f``. It held for every
  motion of every recording (154 real motions, 79 of OfficeLite, no exception).
* The next motion starts :data:`RESTART_CYCLES` cycles after END (``TIME`` of its START block is
  exactly END + 60 ms in every real recording). When the program waited in between (``WAIT SEC
  2``, Linear_vertical) START came 167 + 5 cycles after END: the advance run resumed 4 cycles
  after END (:data:`DONE_CYCLES`), waited its 167 cycles, and the motion started in the next
  cycle, as a motion starts one cycle after it is queued to an idle main run (the first START of
  every recording is 2 cycles after the trace started: TraceStart's ``WAIT SEC 0.012``, then one).
  The simulator's main run does the same (robot/mainrun.py ``_Ending``).

So the pause between two exact-stop motions, from the end of one interpolation to the start of
the next, is 84-96 ms (8 cycles less the fraction of the cycle in which the first ended).
"""

from __future__ import annotations

import math

#: IPO cycles from the cycle in which an exact-stop motion's interpolation ends to its END signal
END_DELAY_CYCLES = 3
#: IPO cycles from an exact-stop motion's END signal until the main run is done with it: an
#: advance-run stop waiting for the motion resumes then, and a motion queued behind it starts in
#: the next cycle (START = END + 5 cycles = 60 ms; after ``WAIT SEC 2`` the next START comes 167 +
#: 5 cycles after END: the WAIT began 4 cycles after END)
DONE_CYCLES = 4
#: IPO cycles from an exact-stop motion's END signal to the start of a motion queued behind it
RESTART_CYCLES = DONE_CYCLES + 1
#: a time within this many seconds below a cycle boundary counts as on it (the recordings' times
#: are in µs; the planned ends are sums of floats)
_EPS = 1e-6


def end_signal(t_f: float, cycle: float) -> float:
    """The time (s) of the END signal of an exact-stop motion whose interpolation ends at `t_f`
    (s), for the IPO cycle `cycle` (s): ``(floor(t_f / cycle) + END_DELAY_CYCLES) · cycle``."""
    return (math.floor(t_f / cycle + _EPS) + END_DELAY_CYCLES) * cycle


def override_interval(motions, cycle: float) -> tuple[float, float] | None:
    """The program overrides (fractions, 0 < ov <= 1) under which every motion of `motions` —
    objects with ``start``, ``endtime`` (the planned end ignoring the override, as PROG.TXT's
    ENDTIME) and ``end`` (the END signal, None when the recording stopped before it) — has the
    END signal :func:`end_signal` gives: ``(low, high)``, or None when no override fits or no
    motion has both times. A recording's PROG.TXT does not state the override it ran at; this
    bounds it (an override of 85 % gives about (0.84, 0.86) on three PTPs)."""
    lo, hi = 0.0, 1.0
    seen = False
    for m in motions:
        if m.end is None or m.endtime is None:
            continue
        plan = m.endtime - m.start
        if plan <= 0:
            continue
        seen = True
        # END - 3 cycles <= START + plan / ov < END - 2 cycles
        a = m.end - END_DELAY_CYCLES * cycle - m.start
        b = a + cycle
        if b <= 0:
            return None
        lo = max(lo, plan / b)
        if a > 0:
            hi = min(hi, plan / a)
    if not seen or lo > hi + 1e-9:
        return None
    return lo, hi


__all__ = ["DONE_CYCLES", "END_DELAY_CYCLES", "RESTART_CYCLES", "end_signal", "override_interval"]
