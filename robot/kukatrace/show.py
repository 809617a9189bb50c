"""``krl trace show REC`` and the plots of ``krl trace show`` / ``krl trace compare`` (issue 60).

:func:`show_lines`: a run's segments (a recording's one), each with its motions (START, END,
motion time, the pause before it, type, line, point) and its samples. :func:`plot_view`: per
segment the axes (deg), the TCP speed (mm/s, from the TCP positions of consecutive samples) with
the motion boundaries (START solid, END dashed), and the TCP path (top view X-Y and side view
X-Z). :func:`plot_compare`: the same three panels with RUN and REC over each other, one figure
per compared segment, stacked. matplotlib with the Agg backend (no display needed).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .compare import SegmentComparison
from .model import RunView, Segment
from ..trace import unfinished
from krl.durable import write_with
import matplotlib
import matplotlib.pyplot as plt


def show_lines(view: RunView) -> list[str]:
    """The text of ``krl trace show``: source, robot, override, then per segment its motions."""
    out = [f"{view.kind:<9} {view.source}", f"robot     {view.robot or '-'}"]
    if view.override_note:
        out.append(f"override  {view.override_note}")
    if view.ended:
        out.append(f"ended     {view.ended}")
    for s in view.segments:
        out.append("")
        out.append(f"segment {s.name}" + (f" ({s.config})" if s.config else "")
                   + f": {s.length:.3f} s, {len(s.motions)} motions, {len(s.t)} samples")
        out.append("   #  type  line  start (s)  END (s)   time (s)  pause ms  point X, Y, Z mm  A, B, C deg")
        prev = None
        for k, m in enumerate(s.motions, 1):
            pause = "-" if prev is None or prev.reached is None else f"{1000 * (m.start - prev.reached):.0f}"
            end = "-" if m.end is None else f"{m.end:.3f}"
            dur = "-" if m.duration is None else f"{m.duration:.3f}"
            pt = "-" if m.point is None else ", ".join(f"{v:.2f}" for v in m.point)
            out.append(f"{k:>4}  {m.kind:<5} {str(m.line):>4}  {m.start:>9.3f}  {end:>7}  {dur:>8}  {pause:>8}  {pt}")
            prev = m
    return out


def as_json(view: RunView) -> dict[str, Any]:
    """``krl trace show --json`` (docs/schemas/trace-show.schema.json)."""
    return {
        "kind": view.kind, "source": view.source, "robot": view.robot,
        "override_pct": None if view.override is None else round(100 * view.override, 3),
        "override_note": view.override_note or None,
        "ended": view.ended or None,
        "segments": [{"name": s.name, "config": s.config or None, "length_s": round(s.length, 6),
                      "samples": int(len(s.t)),
                      "motions": [{"kind": m.kind, "line": m.line, "file": m.file or None,
                                   "start_s": round(m.start, 6),
                                   "end_s": None if m.end is None else round(m.end, 6),
                                   "reached_s": None if m.reached is None else round(m.reached, 6),
                                   "exact_stop": m.exact_stop,
                                   "point": None if m.point is None else [round(v, 6) for v in m.point]}
                                  for m in s.motions]} for s in view.segments],
    }


def _speed(seg: Segment) -> np.ndarray:
    if len(seg.t) < 2:
        return np.zeros(len(seg.t))
    dt = np.diff(seg.t)
    dt[dt <= 0] = np.nan
    v = np.linalg.norm(np.diff(seg.tcp[:, :3], axis=0), axis=1) / dt
    return np.concatenate([[0.0], v])


def _panels(axs, seg: Segment, style: str, label: str) -> None:
    ax_q, ax_v, ax_xy, ax_xz = axs
    for i in range(seg.axes.shape[1] if seg.axes.ndim == 2 else 0):
        ax_q.plot(seg.t, seg.axes[:, i], style, lw=1, color=f"C{i}", label=f"A{i + 1} {label}")
    ax_v.plot(seg.t, _speed(seg), style, lw=1, color="k", label=label)
    for m in seg.motions:
        ax_v.axvline(m.start, color="g", ls=style, lw=0.6)
        if m.end is not None:
            ax_v.axvline(m.end, color="r", ls=style, lw=0.6)
    ax_xy.plot(seg.tcp[:, 0], seg.tcp[:, 1], style, lw=1, label=label)
    ax_xz.plot(seg.tcp[:, 0], seg.tcp[:, 2], style, lw=1, label=label)


def _figure(n: int):

    matplotlib.use("Agg")

    fig, axs = plt.subplots(n, 4, figsize=(20, 4.2 * n), squeeze=False)
    return plt, fig, axs


def _finish(plt, fig, axs, out: Path) -> None:
    for row in axs:
        row[0].set_xlabel("t (s)")
        row[0].set_ylabel("axes (deg)")
        row[1].set_xlabel("t (s)")
        row[1].set_ylabel("TCP speed (mm/s); START green, END red")
        row[2].set_xlabel("X (mm)")
        row[2].set_ylabel("Y (mm)")
        row[3].set_xlabel("X (mm)")
        row[3].set_ylabel("Z (mm)")
        for ax in row[2:]:
            ax.set_aspect("equal", adjustable="datalim")
        row[1].legend(fontsize=7)
    fig.tight_layout()
    write_with(out, lambda fh: fig.savefig(fh, dpi=80, format="png"))
    plt.close(fig)


def plot_view(view: RunView, out: Path) -> None:
    """Write the plot of `view` (one row of panels per segment) as a PNG."""
    plt, fig, axs = _figure(max(1, len(view.segments)))
    for row, seg in zip(axs, view.segments):
        _panels(row, seg, "-", view.kind)
        row[0].set_title(f"{seg.name}: axes")
    if unfinished(view.ended):
        fig.suptitle(f"{Path(view.source).name}: {view.ended}", color="tab:red")
    _finish(plt, fig, axs, out)


def plot_compare(run: RunView, rec: RunView, result: list[SegmentComparison], out: Path) -> None:
    """Write the comparison plot (RUN dashed over REC solid, one row per segment pair) as a PNG."""
    by_run = {s.name: s for s in run.segments}
    by_rec = {s.name: s for s in rec.segments}
    plt, fig, axs = _figure(max(1, len(result)))
    for row, s in zip(axs, result):
        _panels(row, by_rec[s.rec_segment], "-", "rec")
        _panels(row, by_run[s.run_segment], "--", "run")
        row[0].set_title(f"{s.run_segment} (run, dashed) / {s.rec_segment} (rec)")
    _finish(plt, fig, axs, out)


__all__ = ["as_json", "plot_compare", "plot_view", "show_lines"]
