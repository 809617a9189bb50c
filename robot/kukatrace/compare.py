"""``krl trace compare RUN REC``: a run (simulated, or another recording) against a KUKA Trace
recording, motion by motion (issue 60).

**Segments.** Each segment of REC (a recording is one segment; a run's trace has one per
``TraceStart``) is paired with RUN's segment of the same name (case-insensitive), else with the one
whose name it extends or that extends it at a ``_`` (``A1_PTP_10`` and ``A1_PTP_10_po85``: the real
recordings carry a suffix their program's TraceStart does not), else, when both have as many
segments, by order; ``segment=`` chooses RUN's segment by name or 1-based number.

**Motions.** Within a pair of segments the motions are matched by program line and order: with as
many motions of the same types on both sides, in order (lines that differ are reported: a PROG.TXT
counts the lines of the file as it was on the controller); otherwise by the longest common
sequence of (type, line), or of the types alone when that matches more (the lines differ: an
edited file), the rest left unmatched.

**Per motion:** the start (s from the segment's start) on both sides; the motion time, END -
START, and its error (RUN - REC, s and % of REC's); the exact-stop pause before it, START - the
previous motion's end of interpolation (``reached``; a recording's from PROG.TXT's ENDTIME under
its program override, robot/kukatrace/model.py); the path deviation, the largest distance (mm) of
RUN's TCP samples from the START of the motion to the START of the next (or the segment's end) to
REC's TCP path over the same motion (the polyline of its samples): the measure the issue gives
OfficeLite's figures in (its CIRC points lie up to 1.48 mm from the real robot's path). A
simulated run's samples are its setpoints: their TCP is taken as the controller's actual-value
model makes it (robot/kukatrace/actual.py: the setpoints averaged over the cycles identified for
the robot, less its drives' identified following error), as a recording's are measured values;
``actual=False`` takes the setpoints.

**In total**, over the matched exact-stop motions with a time on both sides: the motion time
|error| median, 90th percentile and maximum (%), the median exact-stop pause of each side (pauses
over 0.5 s are program waits, not the controller's pause, and are left out of the median), the
largest path deviation per motion type, and the median start offset.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from .actual import actual_tcp
from .model import RunView, Segment

#: pauses (s) longer than this between two motions are a program's wait (WAIT SEC, WAIT FOR), not
#: the controller's exact-stop pause: they count per motion, not in the median pause
PAUSE_MAX_S = 0.5


class CompareError(ValueError):
    """The two runs cannot be compared as asked (no such segment, an ambiguous name)."""


@dataclass
class MotionComparison:
    """One matched motion: index (0-based) on each side, its type and lines, and the measures of
    the module's docstring (seconds, %, mm; None where a side lacks the data)."""

    run_index: int
    rec_index: int
    kind: str
    run_line: int | None
    rec_line: int | None
    run_start: float
    rec_start: float
    run_time: float | None
    rec_time: float | None
    time_error: float | None
    time_error_pct: float | None
    run_pause: float | None
    rec_pause: float | None
    path_deviation: float | None


@dataclass
class SegmentComparison:
    """The comparison of one pair of segments: their names, how the motions were matched
    (``order``, ``line`` or ``type``), whether lines differ, the matched motions, the indices left
    unmatched on each side, and :attr:`totals`."""

    run_segment: str
    rec_segment: str
    matched_by: str
    lines_differ: bool
    motions: list[MotionComparison]
    run_unmatched: list[int] = field(default_factory=list)
    rec_unmatched: list[int] = field(default_factory=list)

    @property
    def totals(self) -> dict[str, Any]:
        return totals(self.motions)


def totals(motions: list[MotionComparison]) -> dict[str, Any]:
    """The totals of the module's docstring over `motions` (None for a figure without data)."""
    errs = [abs(m.time_error_pct) for m in motions if m.time_error_pct is not None]
    run_p = [m.run_pause for m in motions if m.run_pause is not None and m.run_pause <= PAUSE_MAX_S]
    rec_p = [m.rec_pause for m in motions if m.rec_pause is not None and m.rec_pause <= PAUSE_MAX_S]
    dev: dict[str, float | None] = {}
    for m in motions:
        if m.path_deviation is not None:
            dev[m.kind] = max(dev.get(m.kind) or 0.0, m.path_deviation)
    starts = [m.run_start - m.rec_start for m in motions]
    return {
        "motions": len(motions),
        "timed": len(errs),
        "time_error_pct": {"median": _q(errs, 50), "p90": _q(errs, 90), "max": max(errs) if errs else None},
        "pause_s": {"run": _q(run_p, 50), "rec": _q(rec_p, 50)},
        "path_deviation_mm": dev,
        "start_offset_s": _q(starts, 50),
    }


def _q(values: list[float], pct: float) -> float | None:
    return float(np.percentile(values, pct)) if values else None


# ------------------------------------------------------------------------------ segments
def _norm(name: str) -> str:
    return name.strip().upper()


def pair_segments(run: RunView, rec: RunView, segment: str | None = None) -> list[tuple[Segment, Segment]]:
    """(RUN's segment, REC's segment) pairs (the module's docstring). Raises CompareError."""
    names = ", ".join(s.name for s in run.segments)
    if segment is not None:
        if len(rec.segments) != 1:
            raise CompareError("--segment chooses RUN's segment for a REC of one segment")
        if segment.isdigit():
            k = int(segment)
            if not 1 <= k <= len(run.segments):
                raise CompareError(f"segment {k}: RUN has {len(run.segments)} segments ({names})")
            return [(run.segments[k - 1], rec.segments[0])]
        found = [s for s in run.segments if _norm(s.name) == _norm(segment)]
        if not found:
            raise CompareError(f"no segment {segment!r} in {run.source} (its segments: {names})")
        return [(found[0], rec.segments[0])]
    pairs = []
    for r in rec.segments:
        exact = [s for s in run.segments if _norm(s.name) == _norm(r.name)]
        if exact:
            pairs.append((exact[0], r))
            continue
        a = _norm(r.name)
        near = [s for s in run.segments if a.startswith(_norm(s.name) + "_") or _norm(s.name).startswith(a + "_")]
        if len(near) == 1:
            pairs.append((near[0], r))
            continue
        if len(run.segments) == len(rec.segments):
            return list(zip(run.segments, rec.segments))
        why = "several" if near else "none"
        raise CompareError(f"{why} of RUN's segments ({names}) match the recording {r.name!r}: "
                           f"choose one with --segment NAME|N")
    return pairs


# ------------------------------------------------------------------------------ motions
def match_motions(run: Segment, rec: Segment) -> tuple[list[tuple[int, int]], str, bool]:
    """(index pairs, ``order`` | ``line`` | ``type``, whether matched lines differ) for the motions
    of two segments (the module's docstring)."""
    a, b = run.motions, rec.motions
    if len(a) == len(b) and all(x.kind == y.kind for x, y in zip(a, b)):
        pairs = list(range(len(a)))
        differ = any(x.line != y.line for x, y in zip(a, b))
        return list(zip(pairs, pairs)), "order", differ
    by_line = _lcs([(m.kind, m.line) for m in a], [(m.kind, m.line) for m in b])
    by_type = _lcs([m.kind for m in a], [m.kind for m in b])
    if len(by_type) > len(by_line):
        return by_type, "type", any(a[i].line != b[j].line for i, j in by_type)
    return by_line, "line", False


def _lcs(ka: list, kb: list) -> list[tuple[int, int]]:
    """The index pairs of the longest common subsequence of `ka` and `kb` (the earliest)."""
    n, m = len(ka), len(kb)
    L = [[0] * (m + 1) for _ in range(n + 1)]
    for i in range(n - 1, -1, -1):
        for j in range(m - 1, -1, -1):
            L[i][j] = L[i + 1][j + 1] + 1 if ka[i] == kb[j] else max(L[i + 1][j], L[i][j + 1])
    out = []
    i = j = 0
    while i < n and j < m:
        if ka[i] == kb[j]:
            out.append((i, j))
            i += 1
            j += 1
        elif L[i + 1][j] >= L[i][j + 1]:
            i += 1
        else:
            j += 1
    return out


def _pauses(seg: Segment) -> list[float | None]:
    out: list[float | None] = [None]
    for prev, cur in zip(seg.motions, seg.motions[1:]):
        out.append(cur.start - prev.reached if prev.reached is not None and prev.exact_stop else None)
    return out


def motion_span(seg: Segment, k: int) -> tuple[float, float]:
    """The time span (s) of motion k's samples: its START to the next START (or the end)."""
    t0 = seg.motions[k].start
    t1 = seg.motions[k + 1].start if k + 1 < len(seg.motions) else seg.length
    return t0, max(t1, t0)


def path_deviation(points: np.ndarray, path: np.ndarray) -> float | None:
    """The largest distance (mm) of `points` (M, 3) to the polyline `path` (K, 3); None when
    either is empty."""
    if len(points) == 0 or len(path) == 0:
        return None
    if len(path) == 1:
        return float(np.max(np.linalg.norm(points - path[0], axis=1)))
    a, b = path[:-1], path[1:]
    ab = b - a
    ll = np.einsum("ij,ij->i", ab, ab)
    ll[ll == 0.0] = 1e-30
    best = np.empty(len(points))
    for s in range(0, len(points), 256):          # (256, K, 3) at a time
        p = points[s:s + 256, None, :]
        u = np.clip(np.einsum("mkj,kj->mk", p - a[None], ab) / ll[None], 0.0, 1.0)
        d = np.linalg.norm(p - (a[None] + u[..., None] * ab[None]), axis=2)
        best[s:s + 256] = d.min(axis=1)
    return float(best.max())


def compare_segments(run: Segment, rec: Segment, run_tcp: np.ndarray | None = None) -> SegmentComparison:
    """The :class:`SegmentComparison` of two segments; `run_tcp`: RUN's TCP positions (N, 3) to
    measure the path deviation on (default its samples' own)."""
    pairs, how, differ = match_motions(run, rec)
    tcp = run.tcp[:, :3] if run_tcp is None else run_tcp
    pr, pc = _pauses(run), _pauses(rec)
    rows = []
    for i, j in pairs:
        a, b = run.motions[i], rec.motions[j]
        err = pct = None
        if a.duration is not None and b.duration is not None:
            err = a.duration - b.duration
            pct = 100.0 * err / b.duration if b.duration > 0 else None
        ia = run.window(*motion_span(run, i))
        ib = rec.window(*motion_span(rec, j))
        dev = path_deviation(tcp[ia], rec.tcp[ib, :3]) if len(run.tcp) and len(rec.tcp) else None
        rows.append(MotionComparison(i, j, a.kind, a.line, b.line, a.start, b.start, a.duration, b.duration,
                                     err, pct, pr[i], pc[j], dev))
    used_a = {i for i, _ in pairs}
    used_b = {j for _, j in pairs}
    return SegmentComparison(run.name, rec.name, how, differ, rows,
                             [i for i in range(len(run.motions)) if i not in used_a],
                             [j for j in range(len(rec.motions)) if j not in used_b])


def compare(run: RunView, rec: RunView, segment: str | None = None, actual: bool = True) -> list[SegmentComparison]:
    """The comparison of `run` against `rec`, one entry per paired segment; with `actual`, a
    simulated run's path is that of the actual values its setpoints give (robot/kukatrace/actual.py),
    else its setpoints'. Raises CompareError."""
    out = []
    for a, b in pair_segments(run, rec, segment):
        out.append(compare_segments(a, b, actual_tcp(run, a) if actual else None))
    return out


# ------------------------------------------------------------------------------ output
def as_json(run: RunView, rec: RunView, result: list[SegmentComparison]) -> dict[str, Any]:
    """The comparison as JSON data (docs/schemas/trace-compare.schema.json)."""
    def side(v: RunView) -> dict[str, Any]:
        return {"kind": v.kind, "source": v.source, "robot": v.robot,
                "override_pct": None if v.override is None else round(100 * v.override, 3),
                "override_note": v.override_note or None}

    every = [m for s in result for m in s.motions]
    return {
        "run": side(run), "rec": side(rec),
        "segments": [{"run_segment": s.run_segment, "rec_segment": s.rec_segment, "matched_by": s.matched_by,
                      "lines_differ": s.lines_differ, "motions": [_clean(asdict(m)) for m in s.motions],
                      "run_unmatched": s.run_unmatched, "rec_unmatched": s.rec_unmatched,
                      "totals": _clean(s.totals)} for s in result],
        "totals": _clean(totals(every)),
    }


def _clean(v: Any) -> Any:
    if isinstance(v, float):
        return round(v, 6) if math.isfinite(v) else None
    if isinstance(v, dict):
        return {k: _clean(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_clean(x) for x in v]
    return v


def _f(v: float | None, scale: float = 1.0, fmt: str = "{:.3f}") -> str:
    return "-" if v is None else fmt.format(v * scale)


def text_lines(run: RunView, rec: RunView, result: list[SegmentComparison]) -> list[str]:
    """The comparison as a table: one line per matched motion, the totals of each segment and of
    all. Times in s, errors in ms and %, pauses in ms, deviations in mm."""
    out = [f"run  {run.source} ({run.kind}{_ov(run)})", f"rec  {rec.source} ({rec.kind}{_ov(rec)})"]
    for s in result:
        out.append("")
        how = {"order": "order", "line": "type and line", "type": "type"}[s.matched_by]
        out.append(f"segment {s.run_segment} / {s.rec_segment}: {len(s.motions)} motions matched by {how}"
                   + (" (lines differ)" if s.lines_differ else ""))
        out.append("   #  type  line run/rec   start run/rec (s)   time run/rec (s)   error ms      %"
                   "   pause run/rec ms   dev mm")
        for k, m in enumerate(s.motions, 1):
            out.append(f"{k:>4}  {m.kind:<5} {str(m.run_line):>4}/{str(m.rec_line):<5} "
                       f"{m.run_start:>8.3f}/{m.rec_start:<8.3f} {_f(m.run_time):>8}/{_f(m.rec_time):<8} "
                       f"{_f(m.time_error, 1000, '{:+.0f}'):>6} {_f(m.time_error_pct, 1, '{:+.1f}'):>6}"
                       f"   {_f(m.run_pause, 1000, '{:.0f}'):>6}/{_f(m.rec_pause, 1000, '{:.0f}'):<6}"
                       f"   {_f(m.path_deviation, 1, '{:.3f}'):>6}")
        if s.run_unmatched or s.rec_unmatched:
            out.append(f"      unmatched: run {s.run_unmatched}, rec {s.rec_unmatched}")
        out.append("      " + total_line(s.totals))
    if len(result) > 1:
        out += ["", "all   " + total_line(totals([m for s in result for m in s.motions]))]
    return out


def _ov(v: RunView) -> str:
    return f", program override {v.override_note}" if v.override_note else ""


def total_line(t: dict[str, Any]) -> str:
    """One line of totals: motion time |error| median/p90/max, pauses, deviations, start offset."""
    e = t["time_error_pct"]
    dev = ", ".join(f"{k} {v:.3f}" for k, v in sorted(t["path_deviation_mm"].items())) or "-"
    return (f"time |error| median {_f(e['median'], 1, '{:.2f}')} %, p90 {_f(e['p90'], 1, '{:.2f}')} %, "
            f"max {_f(e['max'], 1, '{:.2f}')} % ({t['timed']} motions); "
            f"pause run {_f(t['pause_s']['run'], 1000, '{:.0f}')} ms, rec {_f(t['pause_s']['rec'], 1000, '{:.0f}')} ms; "
            f"path deviation mm {dev}; start offset {_f(t['start_offset_s'], 1000, '{:+.0f}')} ms")


__all__ = ["CompareError", "MotionComparison", "PAUSE_MAX_S", "SegmentComparison", "as_json", "compare",
           "compare_segments", "match_motions", "motion_span", "pair_segments", "path_deviation", "text_lines",
           "totals"]
