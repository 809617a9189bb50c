"""The motion queue between the advance run and the main run of the simulated controller
(reference §5.16 ``$ADVANCE``, §6.3 BCO; robot/controller.py's ``Controller.queue``).

:class:`MotionQueue` holds what the advance run has planned and the main run has not started:
``pending``, a deque of :class:`~robot.planner.Segment` in planning order (one deque for the
controller's life: the main run and BRAKE take motions from it and put them back, it is never
replaced), ``plan_q``, the end point of the last planned motion (the model's axis order, A1..An
then E1..En, deg and mm; the start of the next motion), ``advance`` (``$ADVANCE``, 0..5), the
motion ids (1, 2, ... in planning order) and ``repeats``, the motions planned so far by request
and start (robot/planrepeat.py: a motion planned again is a copy).
"""

from __future__ import annotations

from collections import deque

import numpy as np

from .frames import frame_to_matrix, inv_pos
from .motion import MotionRequest
from .planner import plan
from .planrepeat import PlanRepeats
from .robotmodel import RobotModel
from .segments import Segment


class MotionQueue:
    """The planned motions not yet started (module docstring).

    Args:
        model: the robot (robot/planner.py ``RobotModel``) the motions are planned for.
        q: the axes (model order) the first motion starts from.
        advance: ``$ADVANCE`` at start (the machine data's default, ``MachineData.def_advance``).
        strict_bco: the first motion needs a complete PTP/LIN target (reference §6.3).
    """

    def __init__(self, model: RobotModel, q: np.ndarray, advance: int, strict_bco: bool) -> None:
        self.model = model
        self.advance = advance
        self.strict_bco = strict_bco
        self.pending: deque[Segment] = deque()
        self.plan_q = q.copy()
        #: the id the next planned motion gets (motions planned so far: ``next_id - 1``)
        self.next_id = 1
        self._bco_done = False
        #: the segments planned so far, by request and start (robot/planrepeat.py)
        self.repeats = PlanRepeats()

    def __len__(self) -> int:
        """Motions planned but not yet started by the main run."""
        return len(self.pending)

    def enqueue(self, req: MotionRequest) -> int:
        """Plan ``req`` from the end point of the previously planned motion and queue it.

        Returns the motion id (1, 2, ... in enqueue order). Raises
        :class:`~robot.errors.RobotError` (WorkspaceError, SoftLimitError, BCO errors) when
        the motion cannot be planned; nothing is queued then. It does not wait for queue
        space: check the controller's ``can_enqueue`` first.
        """
        req.id = self.next_id
        seg = plan(req, self.plan_q, self.model, first=self.strict_bco and not self._bco_done,
                   repeats=self.repeats)
        self.next_id += 1
        self._bco_done = True
        self.pending.append(seg)
        self.plan_q = seg.q1.copy()
        return req.id

    def replan(self, req: MotionRequest) -> None:
        """Plan `req` again from the end point of the last planned motion and queue it (a motion
        suspended by BRAKE, re-planned when the interrupt routine moved the robot): it keeps its
        id."""
        seg = plan(req, self.plan_q, self.model)
        self.pending.append(seg)
        self.plan_q = seg.q1.copy()

    def plan_from(self, q: np.ndarray) -> None:
        """The next motion is planned from `q` (model order): the robot stands there after a
        RESUME, an error, a BRAKE's hold or a sensor correction, or was placed there."""
        self.plan_q = np.array(q, dtype=float)

    def set_advance(self, n: int) -> None:
        """``$ADVANCE``: how many motions the advance run may plan ahead of the main run."""
        self.advance = n

    def last_planned(self) -> Segment:
        """The Segment (robot.planner) that :meth:`enqueue` planned last (for the motion
        history of backward motion, interp/runtime/runmode.py)."""
        return self.pending[-1]

    def planned_axes(self) -> np.ndarray:
        """End point (deg) of the last planned motion (the start of the next one)."""
        return self.plan_q.copy()

    def target_outside_limits(self, req: MotionRequest) -> bool:
        """True when the target of `req` is itself out of this robot's reach: an absolute
        Cartesian target with X, Y, Z, A, B, C in ``$BASE``/``$TOOL`` (``$IPO_MODE #BASE``) for
        which no axis configuration — any of the analytic solutions, any status and turn,
        each axis with its ±360° variants — lies within ``$SOFTN_END``/``$SOFTP_END``. Then no
        path and no S/T of the program reaches it: the robot of this machine data cannot take
        that pose. False for any other request (an axis target, a relative or partial one,
        ``#TCP``), or when some configuration is within the limits."""
        p = req.params
        keys = ("X", "Y", "Z", "A", "B", "C")
        if req.relative or req.is_axis_target or p.ipo_mode != "BASE" or \
                not all(k in req.target for k in keys):
            return False
        model = self.model
        flange = (inv_pos(model.robroot_T) @ frame_to_matrix(*p.base)
                  @ frame_to_matrix(*(float(req.target[k]) for k in keys)) @ inv_pos(frame_to_matrix(*p.tool)))
        limits = [j.limit_deg for j in model.machine.joints]
        for q in model.kin.solutions(flange):
            if all(any(lo <= v + k <= hi for k in (-720.0, -360.0, 0.0, 360.0, 720.0))
                   for v, (lo, hi) in zip(q, limits)):
                return False
        return True


__all__ = ["MotionQueue"]
