"""The triggers of a planned motion (issue 76: out of robot/planner.py): each TRIGGER WHEN
DISTANCE/PATH and STOP WHEN PATH of a motion (and of a SPLINE block's segments) resolved to its
:class:`~robot.segments.TriggerPlan` on the segment: the path parameter of a PATH shift (clamped
to the path), or the start or end a DISTANCE trigger refers to."""

from __future__ import annotations


from .errors import RobotError
from .motion import Trigger
from .segments import CartSegment, Segment, TriggerPlan


def _plan_triggers(seg: Segment) -> None:
    req = seg.req
    plans: list[TriggerPlan] = []
    if req.kind == "SPLINE":
        # triggers of the block segments refer to that segment's start / end
        for k, s in enumerate(req.segments):
            for tr in s.triggers:
                plans.append(_trigger_plan(seg, tr, len(plans), k))
    for tr in req.triggers:
        plans.append(_trigger_plan(seg, tr, len(plans), None))
    seg.triggers = plans


def _trigger_plan(seg: Segment, tr: Trigger, index: int, piece: int | None) -> TriggerPlan:
    if piece is not None and isinstance(seg, CartSegment):
        u0, u1 = float(seg.u_bounds[piece]), float(seg.u_bounds[piece + 1])
        s0, s1 = float(seg.s_bounds[piece]), float(seg.s_bounds[piece + 1])
        last = piece == len(seg.pieces) - 1
    else:
        u0, u1, s0, s1, last = 0.0, 1.0, 0.0, None, True
    if isinstance(tr, Trigger) and tr.distance is not None:
        if tr.distance == 0:
            return TriggerPlan(tr, index, None if piece in (None, 0) else u0, "start")
        return TriggerPlan(tr, index, None if last else u1, "end")
    if seg.req.kind == "PTP":
        what = "TRIGGER WHEN PATH" if isinstance(tr, Trigger) else "STOP WHEN PATH"
        raise RobotError(f"{what} is not allowed for a PTP motion (use SPTP or a CP motion)")
    L = seg.path_length
    if s1 is None:
        s1 = L
    ref = s0 if tr.onstart else s1
    s = min(max(ref + float(tr.path_mm), 0.0), L)  # out-of-range shifts clamp silently
    return TriggerPlan(tr, index, seg.u_of_path(s), "path")
