"""One view of a run, recorded or simulated: its segments, motions and samples (issue 60).

Both kinds of run are events of the project's trace model (robot/trace.py ``SCHEMA``): a
simulated run's JSON Lines trace (``krl run --trace``) as written, a KUKA Trace recording
(robot/kukatrace/recording.py) through :func:`recording_events`. :func:`run_view` turns the
events into :class:`RunView`: the **segments**, each between a ``recording`` start and stop
event (what KUKA's ``TraceStart``/``TraceStop`` mark; a run without one is a single segment
named ``run``), with times counted from the segment's start as KUKA Trace counts them; each
segment's **motions** (start, END, the interpolation's end, line, type, point) and **samples**
(axes deg, TCP X, Y, Z mm and A, B, C deg in ``$BASE``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..trace import ending_words, make_event, trace_lines
from .recording import Recording, RecordingError, is_recording, read_recording

#: overrides (fractions) a recording is taken to have run at when its END signals allow them
#: (:func:`recording_override`): 100 %, then the multiples of 5 %
_ROUND_OVERRIDES = [1.0] + [k / 20 for k in range(19, 0, -1)]


@dataclass
class Motion:
    """One motion of a segment. Times in s from the segment's start: ``start`` (START),
    ``end`` (the END signal; None when the segment stops before it), ``reached`` (the end of the
    interpolation, None when unknown); ``kind`` (PTP, LIN, CIRC, ...), ``line``, ``file``
    (the module or file of the statement), ``exact_stop``, ``point`` (the programmed end
    point X, Y, Z, A, B, C in ``$BASE``, mm/deg; None when unknown), ``tool``, ``base`` (frames),
    ``load`` (``$LOAD`` as robot/dynamics.py ``set_load`` takes it, M kg, X, Y, Z mm, A, B, C deg,
    JX, JY, JZ kg m²; None when unknown: neither a trace nor this model's recording view holds it,
    interp/tracebench.py sets it from PROG.TXT's LOAD)."""

    kind: str
    line: int | None
    file: str
    start: float
    end: float | None = None
    reached: float | None = None
    exact_stop: bool = True
    point: list[float] | None = None
    tool: tuple[float, ...] | None = None
    base: tuple[float, ...] | None = None
    load: tuple[float, ...] | None = None

    @property
    def duration(self) -> float | None:
        """END - START (s), None without an END."""
        return None if self.end is None else self.end - self.start


@dataclass
class Segment:
    """What one recording holds: ``name``, ``config``, ``origin`` (its start in the source's
    time, s), ``length`` (s), ``motions``, and the samples ``t`` (N,) s from the start, ``axes``
    (N, n) deg, ``tcp`` (N, 6)."""

    name: str
    config: str
    origin: float
    length: float
    motions: list[Motion] = field(default_factory=list)
    t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    axes: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    tcp: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))

    def window(self, t0: float, t1: float) -> np.ndarray:
        """Indices of the samples with ``t0 <= t <= t1``."""
        return np.flatnonzero((self.t >= t0 - 1e-9) & (self.t <= t1 + 1e-9))


@dataclass
class RunView:
    """A run's segments; ``kind`` "recording" or "trace"; ``source`` the path read; ``robot`` the
    robot's name; ``override`` the program override a recording is read with (fraction) and
    ``override_note`` how it was chosen (None for a simulated run)."""

    kind: str
    source: str
    robot: str
    segments: list[Segment]
    override: float | None = None
    override_note: str = ""
    robot_source: str = ""
    #: how a simulated run's trace ended (robot/trace.py ``how_it_ended``: the end event's
    #: reason, or "incomplete ..." without one); "" for a recording
    ended: str = ""


# ------------------------------------------------------------------------------ recordings
def recording_override(rec: Recording, override_pct: float | None = None) -> tuple[float, str]:
    """(override fraction, how it was chosen) for reading `rec`'s interpolation ends: the given
    percentage; else the one its END signals allow (robot/exactstop.py): 100 % when allowed, else
    the allowed multiple of 5 % (overrides are set in such steps), else the middle of what is
    allowed; 100 % when the recording tells nothing. Raises RecordingError for a percentage
    outside (0, 100]."""
    if override_pct is not None:
        if not 0 < override_pct <= 100:
            raise RecordingError(f"program override {override_pct:g} %: a value in (0, 100] was expected")
        return override_pct / 100.0, f"{override_pct:g} % (given)"
    iv = rec.override_interval()
    if iv is None:
        return 1.0, "100 % (the END signals tell nothing)"
    lo, hi = iv
    span = f"the END signals allow {100 * lo:.1f}-{100 * hi:.1f} %"
    for ov in _ROUND_OVERRIDES:
        if lo - 1e-9 <= ov <= hi + 1e-9:
            return ov, f"{100 * ov:g} % ({span})"
    mid = 0.5 * (lo + hi)
    return mid, f"{100 * mid:.1f} % ({span})"


def recording_events(rec: Recording, override: float = 1.0) -> list[dict[str, Any]]:
    """`rec` as events of the project's trace model (robot/trace.py ``SCHEMA``): ``robot`` (the
    recording's robot type), ``recording`` start at 0 and stop at the last sample, per motion
    ``motion`` start and end events (``reached``: its START plus PROG.TXT's planned duration over
    `override`, a fraction), a ``pose`` per sample; in time order."""
    events: list[tuple[float, int, dict[str, Any]]] = []
    src = str(rec.prog_path or rec.ipo_path)
    events.append((0.0, 0, make_event("robot", 0.0, name=rec.robot_type.lstrip("#") or "unknown", source=src,
                                      trafoname=rec.robot_type or None)))
    events.append((0.0, 1, make_event("recording", 0.0, phase="start", name=rec.name)))
    for i, m in enumerate(rec.motions, 1):
        target = {k.upper(): float(v) for k, v in (m.point or {}).items() if isinstance(v, float)}
        point = [target[k] for k in "XYZABC"] if all(k in target for k in "XYZABC") else None
        common = dict(id=i, type=m.kind, target=target, approximation=None if m.exact_stop else m.blending,
                      point=point, line=m.line, file=m.module or None)
        events.append((m.start, 2, make_event("motion", m.start, phase="start", **common)))
        if m.end is not None:
            reached = None
            if m.endtime is not None and m.exact_stop:
                reached = m.start + (m.endtime - m.start) / override
            events.append((m.end, 2, make_event("motion", m.end, phase="end", reached=reached, **common)))
    for k in range(len(rec.t)):
        events.append((float(rec.t[k]), 3, {"t": float(rec.t[k]), "kind": "pose",
                                           "axes": rec.axes[k].tolist(), "tcp": rec.tcp[k].tolist()}))
    last = float(rec.t[-1]) if len(rec.t) else max((m.end or m.start for m in rec.motions), default=0.0)
    events.append((last, 4, make_event("recording", last, phase="stop", name=rec.name)))
    events.sort(key=lambda e: (e[0], e[1]))
    return [e[2] for e in events]


# ------------------------------------------------------------------------------ events
def run_view(events, kind: str = "trace", source: str = "") -> RunView:
    """The :class:`RunView` of trace events (an iterable of dicts): segments between
    ``recording`` start and stop events (a ``recording`` event without a name takes the
    configuration's), or the whole run as one segment named ``run``."""
    robot = robot_source = ""
    segs: list[Segment] = []
    cur: Segment | None = None
    whole = Segment("run", "", 0.0, 0.0)
    open_motions: dict[int, Motion] = {}
    samples: list[tuple[float, list[float], list[float]]] = []
    whole_samples: list[tuple[float, list[float], list[float]]] = []
    last_t = 0.0
    end_ev = None

    def close(seg: Segment, smp: list, t_end: float) -> None:
        seg.length = max(0.0, t_end - seg.origin)
        if smp:
            seg.t = np.array([s[0] for s in smp], dtype=float) - seg.origin
            seg.axes = np.array([s[1] for s in smp], dtype=float)
            seg.tcp = np.array([s[2] for s in smp], dtype=float)

    for ev in events:
        k = ev.get("kind")
        t = float(ev.get("t", 0.0))
        last_t = max(last_t, t)
        if k == "robot":
            robot, robot_source = str(ev.get("name", "")), str(ev.get("source", ""))
        elif k == "recording":
            ph = ev.get("phase")
            if ph == "start":
                if cur is not None:
                    close(cur, samples, t)
                cur = Segment(str(ev.get("name") or ev.get("config") or f"segment {len(segs) + 1}"),
                              str(ev.get("config") or ""), t, 0.0)
                segs.append(cur)
                samples = []
                open_motions = {}
            elif ph == "stop" and cur is not None:
                close(cur, samples, t)
                cur = None
        elif k == "motion":
            seg = cur if cur is not None else (whole if not segs else None)
            if seg is None:
                continue
            ph = ev.get("phase")
            mid = int(ev["id"])
            if ph == "start":
                pt = ev.get("point")
                lim = ev.get("limits") or {}
                m = Motion(str(ev.get("type", "")), ev.get("line"), str(ev.get("file") or ""), t - seg.origin,
                           exact_stop=ev.get("approximation") is None,
                           point=[float(x) for x in pt] if pt else None,
                           tool=tuple(lim["tool"]) if lim.get("tool") else None,
                           base=tuple(lim["base"]) if lim.get("base") else None)
                seg.motions.append(m)
                open_motions[mid] = m
            elif ph == "end":
                m = open_motions.pop(mid, None)
                if m is not None and ev.get("reason") != "abort":
                    m.end = t - seg.origin
                    if ev.get("reached") is not None:
                        m.reached = float(ev["reached"]) - seg.origin
        elif k == "end":
            end_ev = ev
        elif k == "pose":
            smp = (t, ev["axes"], ev["tcp"])
            if cur is not None:
                samples.append(smp)
            elif not segs:
                whole_samples.append(smp)
    if cur is not None:
        close(cur, samples, last_t)
    if not segs:
        close(whole, whole_samples, last_t)
        segs = [whole]
    return RunView(kind, source, robot, segs, robot_source=robot_source,
                   ended=ending_words(end_ev) if kind == "trace" else "")


def load_run(path: str | Path, override_pct: float | None = None, warn=None) -> RunView:
    """The :class:`RunView` of `path`: a KUKA Trace recording (either of its files or their stem;
    read with :func:`recording_override`) or a simulated run's JSON Lines trace. Raises
    RecordingError for a recording that cannot be read, ValueError (file:line) for a trace line
    that is no JSON (a cut last line is dropped, with a warning through `warn`: robot/trace.py
    ``trace_lines``), OSError for a file that cannot be opened."""
    p = Path(path)
    if is_recording(p) and not p.suffix.lower() in (".jsonl", ".json"):
        rec = read_recording(p)
        ov, note = recording_override(rec, override_pct)
        view = run_view(recording_events(rec, ov), "recording", str(p))
        view.override, view.override_note = ov, note
        return view
    return run_view(_trace_events(p, warn), "trace", str(p))


def _trace_events(p: Path, warn=None):
    """The events of the trace `p` (robot/trace.py ``trace_lines``: a cut last line dropped
    with a warning through `warn`)."""
    with open(p, encoding="utf-8") as fh:
        for _n, ev in trace_lines(fh, str(p), warn):
            yield ev


__all__ = ["Motion", "RunView", "Segment", "load_run", "recording_events", "recording_override", "run_view"]
