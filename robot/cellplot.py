"""``krl plot run.cell.json``: every robot's TCP path of a cell of several robots in one figure, in
the cell's world (issue 89; docs/cells.md).

A cell run with ``--trace run.jsonl`` writes one stream per robot (``run.R1.jsonl``, ...) and the
cell's result ``run.cell.json`` (interp/robotcell.py: each robot's name and ``base``). Each
stream's ``pose`` events hold the TCP in the ``$BASE`` of the motion the main run executed (the
``limits.base`` of the last ``motion`` start event; ``$NULLFRAME`` before the first motion), so a
pose is placed in the cell's world as ``base : $BASE : TCP`` (robot/frames.py, KUKA's X, Y, Z, A,
B, C). Two panels: a 3D view and a top view (X-Y), one colour per robot, its base marked.

Raises FileNotFoundError for a result or stream that is not there, ValueError for a result that
is not a cell's (no ``robots`` list) or streams without a pose.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from krl.durable import write_with
from .axismap import CART_KEYS
from .frames import frame_to_matrix
from .trace import read_trace
import matplotlib
import matplotlib.pyplot as plt

#: a cell's result file larger than this is no cell's (16 robots' ends, conflicts, collisions)
MAX_RESULT_BYTES = 16 * 1024 * 1024


def cell_paths(result_path: str | Path) -> dict[str, np.ndarray]:
    """Each robot's TCP path (n x 3, mm, the cell's world) of the cell result `result_path`
    (``run.cell.json``) and the streams beside it (module docstring)."""
    result_path = Path(result_path)
    if result_path.stat().st_size > MAX_RESULT_BYTES:
        raise ValueError(f"{result_path}: larger than {MAX_RESULT_BYTES} bytes, not a cell's result")
    doc = json.loads(result_path.read_text(encoding="utf-8"))
    robots = doc.get("robots") if isinstance(doc, dict) else None
    if not isinstance(robots, list) or not robots:
        raise ValueError(f"{result_path}: not a cell's result (krl run CELL.yaml --trace: run.cell.json)")
    stem = result_path.name[:-len(".cell.json")] if result_path.name.endswith(".cell.json") else result_path.stem
    out = {}
    for r in robots:
        name, base = str(r.get("name")), r.get("base") or [0.0] * len(CART_KEYS)
        stream = result_path.with_name(f"{stem}.{name}.jsonl")
        out[name] = _world_path(stream, frame_to_matrix(*[float(v) for v in base]))
    return out


def _world_path(stream: Path, base_T: np.ndarray) -> np.ndarray:
    """The TCP of the stream's pose events in the cell's world (mm), n x 3."""
    frame, pts = base_T, []
    for ev in read_trace(stream):
        kind = ev.get("kind")
        if kind == "motion" and ev.get("phase") == "start":
            b = (ev.get("limits") or {}).get("base")
            frame = base_T @ frame_to_matrix(*b) if isinstance(b, list) and len(b) == len(CART_KEYS) else base_T
        elif kind == "pose":
            pts.append((frame @ np.array([*ev["tcp"][:3], 1.0]))[:3])
    if not pts:
        raise ValueError(f"{stream}: no pose events to plot")
    return np.array(pts)


def plot_cell(result_path: str | Path, png_path: str | Path) -> Path:
    """Write the PNG of every robot's TCP path (module docstring); returns its path."""
    matplotlib.use("Agg")
    paths = cell_paths(result_path)
    fig = plt.figure(figsize=(13, 6))
    ax3 = fig.add_subplot(1, 2, 1, projection="3d")
    ax2 = fig.add_subplot(1, 2, 2)
    for k, (name, P) in enumerate(paths.items()):
        colour = f"C{k % 10}"
        ax3.plot(P[:, 0], P[:, 1], P[:, 2], lw=1.2, color=colour, label=name)
        ax2.plot(P[:, 0], P[:, 1], lw=1.2, color=colour, label=name)
        ax2.scatter([P[-1, 0]], [P[-1, 1]], s=20, color=colour)
    for ax, title in ((ax3, "TCP paths (3D)"), (ax2, "top view")):
        ax.set_xlabel("X [mm]")
        ax.set_ylabel("Y [mm]")
        ax.set_title(title)
        ax.legend(loc="best", fontsize=7)
    ax3.set_zlabel("Z [mm]")
    ax2.set_aspect("equal", adjustable="datalim")
    ax2.grid(True, lw=0.3)
    fig.suptitle(f"{Path(result_path).name}: {len(paths)} robots in the cell's world")
    fig.tight_layout()
    out = Path(png_path)
    write_with(out, lambda fh: fig.savefig(fh, dpi=110, format="png"))
    plt.close(fig)
    return out


__all__ = ["cell_paths", "plot_cell", "MAX_RESULT_BYTES"]
