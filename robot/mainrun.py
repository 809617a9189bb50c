"""The main run's records (issue 76: out of robot/controller.py): a segment being executed
(:class:`_Run`, with the path time each of its triggers switches at, reference §5.18), a blend
between two (:class:`_Blend`), the state a BRAKE suspends (:class:`_Held`) and an exact-stop
motion between its end point and done (:class:`_Ending`, robot/exactstop.py). The Controller
(robot/controller.py) owns them."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np

from .segments import Segment, TriggerPlan


@dataclass
class _Run:
    """A segment being executed by the main run."""

    seg: Segment
    t0: float                     # path time of local time 0
    blend_in_end: float | None = None   # path time where the blend into it ended/ends
    blend_mid: float | None = None      # path time of the middle of its outgoing blend
    planned_mid: float | None = None    # expected blend middle (for DISTANCE=1 early)
    decided: bool = False               # approximation decided (blend or exact stop)
    fired: set[int] = field(default_factory=set)
    tau_cache: tuple[int | None, float | None] | None = None
    stops: dict[int, str] = field(default_factory=dict)   # conditional stop index -> braking / stopped

    def shift(self, d: float) -> None:
        self.t0 += d
        for name in ("blend_in_end", "blend_mid", "planned_mid"):
            v = getattr(self, name)
            if v is not None:
                setattr(self, name, v + d)

    def trigger_time(self, tp: TriggerPlan) -> float:
        """Path time at which trigger ``tp`` switches (reference §5.18; see docs)."""
        seg = self.seg
        if tp.u_ref is not None:
            ref = self.t0 + seg.profile.t_of_u(tp.u_ref)
        elif tp.kind == "start":
            ref = self.blend_in_end if self.blend_in_end is not None else self.t0
        else:  # end
            if self.blend_mid is not None:
                ref = self.blend_mid
            elif self.planned_mid is not None and not self.decided:
                ref = self.planned_mid
            else:
                ref = self.t0 + seg.T
        return max(self.t0, ref + tp.trigger.delay_ms / 1000.0)

    @property
    def pending_triggers(self) -> bool:
        return len(self.fired) < len(self.seg.triggers)


@dataclass
class _Blend:
    prev: _Run
    nxt: _Run
    pa: float
    pb: float
    space: str
    keyword: str


@dataclass
class _Held:
    """Main-run state suspended by BRAKE (restored by :meth:`Controller.release`)."""

    runs: list[_Run]
    blend: _Blend | None
    pending: deque
    tracked: list[_Run]
    pt: float
    q: np.ndarray
    tool_T: np.ndarray
    base_T: np.ndarray
    plan_q: np.ndarray            # end point of the last motion planned before the hold
    next_id: int                  # the queue's next motion id at the hold (a motion planned since: re-plan)


@dataclass
class _Ending:
    """An exact-stop motion whose interpolation has ended at ``reached`` (s): the main run keeps
    the robot at its end point, signals the motion's END at cycle ``k_end`` and is done with it
    at cycle ``k_done`` (robot/exactstop.py)."""

    seg: Segment
    reached: float
    k_end: int
    k_done: int
    signalled: bool = False


__all__ = ["_Run", "_Blend", "_Held", "_Ending"]
