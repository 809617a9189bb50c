"""``krl plot TRACE``: draw a trace's TCP path as a PNG (issue 5, "Plots").

Two panels: a 3D view and a top view (X-Y) of the TCP path from the ``pose`` events, with

* the programmed points (``point`` of the motion ``end`` events; filled = exact stop,
  open = approximated),
* the approximation zones: the TCP where each blend starts and ends, and a circle through
  the blend start around the approximated point (top view),
* the I/O events, marked at the TCP position of their IPO cycle and labelled;

and, for a robot with external axes (the trace's ``robot`` event names the pose axes,
robot/axismap.py), a third panel: E1..En over time (mm or deg), the axes the TCP path does not show.

Uses matplotlib with the Agg backend (no display needed).
"""

from __future__ import annotations

import bisect
from pathlib import Path
from typing import Any

import numpy as np

from .trace import how_it_ended, read_trace, unfinished
from krl.durable import write_with
import matplotlib
import matplotlib.pyplot as plt


def _collect(events: list[dict[str, Any]]) -> dict[str, Any]:
    xyz: list[tuple[float, float, float]] = []
    times: list[float] = []
    points: list[tuple[list[float], bool, int]] = []
    blend_starts: dict[int, float] = {}
    blend_ends: dict[int, float] = {}
    ios: list[tuple[float, str, Any]] = []
    names: list[str] = []
    ext: list[list[float]] = []
    for ev in events:
        k = ev.get("kind")
        if k == "pose":
            x, y, z = ev["tcp"][:3]
            xyz.append((x, y, z))
            times.append(ev["t"])
            ext.append([v for n, v in zip(names, ev["axes"]) if n.startswith("E")])
        elif k == "robot":
            names = list(ev.get("axes") or ())
        elif k == "motion":
            ph = ev.get("phase")
            if ph == "end" and "point" in ev:
                points.append((ev["point"], ev.get("approximation") is None, ev["id"]))
            elif ph == "blend_start":
                blend_starts[ev["id"]] = ev["t"]
            elif ph == "blend_end":
                blend_ends[ev["id"]] = ev["t"]
        elif k == "io":
            ios.append((ev["t"], ev["signal"], ev["value"]))
    return {"xyz": xyz, "times": times, "points": points, "bs": blend_starts,
            "be": blend_ends, "io": ios, "ext_names": [n for n in names if n.startswith("E")], "ext": ext}


def _pose_at(data: dict[str, Any], t: float) -> tuple[float, float, float] | None:
    times = data["times"]
    if not times:
        return None
    i = bisect.bisect_left(times, t - 1e-9)
    i = min(i, len(times) - 1)
    return data["xyz"][i]


def _plot_external(axe: Any, data: dict) -> None:
    """The external axes over time into the panel `axe`."""
    E = np.array(data["ext"])
    for i, name in enumerate(data["ext_names"]):
        axe.plot(data["times"], E[:, i], lw=1.2, label=name)
    axe.set_xlabel("t [s]")
    axe.set_ylabel("external axes [mm or deg]")
    axe.set_title("external axes")
    axe.grid(True, lw=0.3)
    axe.legend(loc="best", fontsize=7)


def _plot_blends(ax3: Any, ax2: Any, data: dict) -> None:
    """Each blend's start and end on the TCP path (3D and top view), with its circle around the
    approximated point in the top view."""
    pts_by_id = {mid: pt for pt, _, mid in data["points"]}
    first = True
    for mid, tb in sorted(data["bs"].items()):
        a = _pose_at(data, tb)
        e = _pose_at(data, data["be"].get(mid, tb))
        if a is None or e is None:
            continue
        lab = "blend start / end" if first else None
        ax3.scatter([a[0], e[0]], [a[1], e[1]], [a[2], e[2]], marker="x", color="tab:green",
                    s=30, label=lab)
        ax2.scatter([a[0], e[0]], [a[1], e[1]], marker="x", color="tab:green", s=30, label=lab)
        if mid in pts_by_id:
            c = pts_by_id[mid]
            r = float(np.linalg.norm(np.array(a) - np.array(c[:3])))
            ax2.add_patch(plt.Circle((c[0], c[1]), r, fill=False, ls="--", color="tab:green",
                                     lw=0.8))
        first = False


def _plot_io(ax3: Any, ax2: Any, data: dict) -> None:
    """Each I/O event at the TCP's position then (3D and top view)."""
    first = True
    for t, sig, val in data["io"]:
        p = _pose_at(data, t)
        if p is None:
            continue
        lab = "I/O event" if first else None
        ax3.scatter([p[0]], [p[1]], [p[2]], marker="^", color="tab:orange", s=30, label=lab)
        ax2.scatter([p[0]], [p[1]], marker="^", color="tab:orange", s=30, label=lab)
        ax2.annotate(f"{sig}={val}", (p[0], p[1]), textcoords="offset points", xytext=(4, -10),
                     fontsize=6, color="tab:orange")
        first = False


def plot_trace(trace_path: str | Path, png_path: str | Path, title: str | None = None, warn=None) -> Path:
    """Read a JSON Lines trace and write the PNG; returns the PNG path. A run that did not end
    by itself (no end event, or interrupted) says so in the title (robot/trace.py
    ``how_it_ended``); a cut last line is dropped with a warning through `warn`.

    Raises FileNotFoundError if the trace does not exist, ValueError if it has no pose events.
    """

    matplotlib.use("Agg")
    events = list(read_trace(trace_path, warn))
    data = _collect(events)
    if not data["xyz"]:
        raise ValueError(f"{trace_path}: no pose events to plot")
    P = np.array(data["xyz"])
    panels = 3 if data["ext_names"] else 2
    fig = plt.figure(figsize=(6.5 * panels, 6))
    ax3 = fig.add_subplot(1, panels, 1, projection="3d")
    ax2 = fig.add_subplot(1, panels, 2)
    if panels == 3:
        _plot_external(fig.add_subplot(1, 3, 3), data)
    ax3.plot(P[:, 0], P[:, 1], P[:, 2], lw=1.2, color="tab:blue", label="TCP path")
    ax2.plot(P[:, 0], P[:, 1], lw=1.2, color="tab:blue", label="TCP path")

    for pt, exact, mid in data["points"]:
        kw = dict(marker="o", s=36, edgecolors="k",
                  facecolors="tab:red" if exact else "none", zorder=5)
        ax3.scatter([pt[0]], [pt[1]], [pt[2]], **kw)
        ax2.scatter([pt[0]], [pt[1]], **kw)
        ax2.annotate(str(mid), (pt[0], pt[1]), textcoords="offset points", xytext=(4, 4),
                     fontsize=7)
    _plot_blends(ax3, ax2, data)
    _plot_io(ax3, ax2, data)

    ax3.set_xlabel("X [mm]")
    ax3.set_ylabel("Y [mm]")
    ax3.set_zlabel("Z [mm]")
    ax3.set_title("TCP path (3D)")
    ax2.set_xlabel("X [mm]")
    ax2.set_ylabel("Y [mm]")
    ax2.set_aspect("equal", adjustable="datalim")
    ax2.set_title("top view")
    ax2.grid(True, lw=0.3)
    ax2.legend(loc="best", fontsize=7)
    ended = how_it_ended(events)
    fig.suptitle((title or Path(trace_path).name) + (f": {ended}" if unfinished(ended) else ""))
    fig.tight_layout()
    out = Path(png_path)
    write_with(out, lambda fh: fig.savefig(fh, dpi=110, format="png"))
    plt.close(fig)
    return out
