"""Program run modes (``$PRO_MODE``) and backward motion (issue 24; docs/robot.md, "Program
run modes and backward motion", lists every rule with its source).

* ``#GO``: the program runs continuously (the default).
* ``#MSTEP``: a stop after each motion. The advance run does not pass the stop (the next
  statement is read only when the motion has ended), so approximation becomes exact
  positioning.
* ``#ISTEP``: a stop after each statement of the robot interpreter, again without advance
  run and without approximation.
* ``#BSTEP``: backward motion: the executed motions, newest first, are retraced to their
  start points, one motion per step, executing no logic.

A *step stop* is the point where the operator presses Start again. In a non-interactive
``krl run`` nobody presses it: the run records a ``step_stop`` trace event and goes on at
once, so runs complete and the trace shows every stop. ``krl debug`` stops there instead
(``Stepping.step_hook``).

The submit interpreter is not affected by ``$PRO_MODE`` (it has no motions and its own
``$PRO_MODE0``); a TRIGGER action never stops.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from krl.limits import MAX_MOTION_HISTORY
from robot.motion import MotionRequest

RUN_MODES = ("GO", "MSTEP", "ISTEP", "BSTEP")
#: modes that run without advance run: every motion ends exactly at its point
STEP_MODES = ("MSTEP", "ISTEP", "BSTEP")
#: operating modes in which backward motion is possible
BACKWARD_MODES_OP = ("T1", "T2")
#: motion kinds retraced backward (the same kind; SPTP for PTP-type spline motions)
BACKWARD_KINDS = {"PTP": "PTP", "SPTP": "PTP", "LIN": "LIN", "SLIN": "LIN", "CIRC": "CIRC", "SCIRC": "CIRC"}


def mode_name(value) -> str:
    """``#MSTEP`` / EnumValue / str -> ``"MSTEP"``; ValueError for a mode this simulator
    does not know (PSTEP and CSTEP are program-step modes of other KSS versions)."""
    name = str(getattr(value, "name", value)).lstrip("#").upper()
    if name not in RUN_MODES:
        raise ValueError(f"run mode #{name} is not simulated (GO, MSTEP, ISTEP, BSTEP)")
    return name


class BackwardRefused(Exception):
    """Backward motion is not possible; ``reason`` says why in the pendant's words."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


@dataclass
class MotionRecord:
    """One executed motion as backward motion needs it: the planned start and end axes
    (deg, KRL's order: robot/axismap.py), the programmed target, the frames ($TOOL, $BASE as X..C mm/deg), the speed
    parameters (robot.motion.MotionParams) and, for a CIRC, a point in the middle of the
    executed arc (X, Y, Z mm in $BASE) that the backward CIRC passes."""

    id: int
    kind: str
    start: np.ndarray
    end: np.ndarray
    target: dict
    tool: tuple
    base: tuple
    params: object
    file: str | None = None
    line: int | None = None
    mid: dict | None = None


class MotionHistory:
    """The executed motions of the robot interpreter, oldest first (at most
    :data:`krl.limits.MAX_MOTION_HISTORY`; the oldest is dropped past that)."""

    def __init__(self) -> None:
        # (a deque with its bound: the oldest drops out in O(1); a list's del [0] moved the
        # 10 000 records left at each motion past the bound)
        self.records: deque[MotionRecord] = deque(maxlen=MAX_MOTION_HISTORY)
        self.last_frames: tuple | None = None   # ($TOOL, $BASE) of the motion retraced last

    def record(self, req, seg) -> None:
        """Record the planned motion ``seg`` (robot.planner.Segment) of request ``req``."""
        mid = None
        if req.kind in ("CIRC", "SCIRC"):
            pos, _ = seg.pose(seg.T / 2.0)
            mid = {"X": float(pos[0]), "Y": float(pos[1]), "Z": float(pos[2])}
        p = req.params
        self.records.append(MotionRecord(req.id, req.kind, seg.q0.copy(), seg.q1.copy(), dict(req.target),
                                         tuple(p.tool), tuple(p.base), p, req.file, req.line, mid))
        self.last_frames = None

    def next_backward(self, mode_op: str, tool: tuple, base: tuple):
        """The backward request for the newest motion not yet retraced, and its record
        (which is removed). ``tool``/``base``: the frames now active.

        Raises :class:`BackwardRefused`: not in T1/T2; no motion left; a SPLINE block;
        frames changed since the motion (docs/robot.md)."""
        if mode_op not in BACKWARD_MODES_OP:
            raise BackwardRefused(f"backward motion is only possible in T1 and T2 (operating mode {mode_op})")
        if not self.records:
            raise BackwardRefused("backward motion not possible: no executed motion left to retrace")
        rec = self.records[-1]
        kind = BACKWARD_KINDS.get(rec.kind)
        if kind is None:
            raise BackwardRefused(f"backward motion not possible over a {rec.kind} block (line {rec.line})")
        tool, base = self.last_frames or (tool, base)
        if not (_same(rec.tool, tool) and _same(rec.base, base)):
            raise BackwardRefused(f"backward motion not possible: $TOOL or $BASE changed after the motion "
                                  f"of line {rec.line}")
        self.records.pop()
        self.last_frames = (rec.tool, rec.base)
        target = {f"A{i + 1}": float(v) for i, v in enumerate(rec.start)}
        req = MotionRequest(kind, target, rec.params, approx=None, aux=rec.mid, file=rec.file, line=rec.line)
        return req, rec


def _same(a: tuple, b: tuple) -> bool:
    return all(abs(float(x) - float(y)) <= 1e-6 for x, y in zip(a, b))
