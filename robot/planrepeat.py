"""A motion planned again: the same request from the same start on the same robot gives the
segment planned the first time, copied (issue 86: a palletizer's cycle plans the same
approach, pick and depart motions from the same points every cycle; examples/palletizer5's
300 s plan 298 motions, 57 of them different, the corpus palletizer's 301, 160 different).

:class:`PlanRepeats` holds, per :class:`~robot.motionqueue.MotionQueue` (one controller, one
robot), the segments robot/planner.py ``plan`` made, as they were when planned (before its
triggers and limits, which ``plan`` makes for each request), keyed by everything planning reads:
the start axes' bytes, the request's kind, target, relative frame, approximation, auxiliary
point, circular angle and :class:`~robot.motion.MotionParams` (by their ``repr``, exact for
floats: ``-0.0`` and ``0.0`` are two keys), the robot and its operating mode. A copy is a new
segment with the same attributes: each writable array copied (read-only arrays: the planner's
kept frames, shared as planning shares them), each list copied (an array or list held twice
copied once), the other values (the profile,
the path pieces, a compiled path, which the main run does not change) shared. It is used only
for requests planned without another model (``$IPO_MODE #BASE``, no ``$BASE`` on a BASE
kinematic) and without spline segments; a request that fails is planned (and fails) again.
tests/robot/test_planrepeat.py checks a copy against a fresh plan attribute by attribute."""

from __future__ import annotations

from typing import Any

import numpy as np

from .motion import MotionParams, MotionRequest
from .segments import Segment

#: Segments kept per queue (the table is cleared when full)
REPEAT_MEMO = 512
#: The motion kinds kept (the others plan every time)
KEPT_KINDS = frozenset(("PTP", "LIN", "CIRC"))
#: MotionParams whose ``repr`` is kept (by identity: robot/motion.py's snapshots are frozen, and
#: interp/runtime/motion.py hands the same one again while nothing changed)
PARAMS_MEMO = 64


class PlanRepeats:
    """The segments planned so far for one robot, by request and start (module docstring)."""

    def __init__(self) -> None:
        self._segs: dict[tuple, _Kept] = {}
        self._params: dict[int, tuple[MotionParams, str]] = {}

    def key(self, req: MotionRequest, q0: np.ndarray, model: Any) -> tuple | None:
        """The key of planning `req` from the axes `q0` (float64) on `model`, or None where the
        plan is not kept (module docstring)."""
        p = req.params
        if (req.kind not in KEPT_KINDS or req.segments or p.ipo_mode != "BASE" or p.base_kin is not None
                or q0.dtype != np.float64):
            return None
        got = self._params.get(id(p))
        if got is None or got[0] is not p:
            if len(self._params) >= PARAMS_MEMO:
                self._params.clear()
            got = self._params[id(p)] = (p, repr(p))
        return (q0.tobytes(), id(model), model.mode, got[1],
                repr((req.kind, req.relative, req.rel_frame, req.approx, req.approx2, req.ca,
                      None if req.aux is None else tuple(req.aux.items()), tuple(req.target.items()))))

    def get(self, key: tuple, req: MotionRequest) -> tuple[Segment | None, Any]:
        """A copy of the segment kept for `key`, for `req` (its id and request; no triggers or
        limits yet), and the motion's limits kept (robot/limits.py ``MotionLimits``, frozen; None
        when not kept); (None, None) when nothing is kept."""
        got = self._segs.get(key)
        if got is None:
            return None, None
        seg = got.copy()
        seg.req = req
        seg.id = req.id
        return seg, got.limits

    def keep(self, key: tuple, seg: Segment) -> None:
        """Keep `seg` as planned (before its triggers and limits) for `key`."""
        if len(self._segs) >= REPEAT_MEMO:
            self._segs.clear()
        self._segs[key] = _Kept(seg)

    def keep_limits(self, key: tuple, limits: Any) -> None:
        """Keep the limits of the motion kept for `key` (where it is still kept)."""
        got = self._segs.get(key)
        if got is not None:
            got.limits = limits


class _Kept:
    """A segment's attributes as planned, and how to copy them: each writable array and each list
    copied (the arrays in a list too), an array or list held twice copied once (``seg._R is
    seg.rots`` stays so), the other values shared."""

    def __init__(self, seg: Segment) -> None:
        self.cls = type(seg)
        self.limits: Any = None
        state = dict(seg.__dict__)
        self.shared = {k: v for k, v in state.items()
                       if not (type(v) is list or (type(v) is np.ndarray and v.flags.writeable))}
        #: (template list, its keys, its array slots: (index, array id)); (array copy source, keys)
        self.lists: list[tuple[list, list[str], list[tuple[int, int]]]] = []
        self.arrays: dict[int, tuple[np.ndarray, list[str]]] = {}
        seen: dict[int, list[str]] = {}
        for k, v in state.items():
            if type(v) is list:
                keys = seen.get(id(v))
                if keys is None:
                    keys = seen[id(v)] = []
                    slots = [(i, self._array(x, None)) for i, x in enumerate(v)
                             if type(x) is np.ndarray and x.flags.writeable]
                    self.lists.append((list(v), keys, slots))
                keys.append(k)
            elif type(v) is np.ndarray and v.flags.writeable:
                self._array(v, k)
        self.state = state      # the originals stay alive: their ids name them

    def _array(self, a: np.ndarray, key: str | None) -> int:
        got = self.arrays.get(id(a))
        if got is None:
            got = self.arrays[id(a)] = (a.copy(), [])
        if key is not None:
            got[1].append(key)
        return id(a)

    def copy(self) -> Segment:
        """A new segment with the kept attributes (class docstring)."""
        copies = {i: (a.copy(), keys) for i, (a, keys) in self.arrays.items()}
        d = dict(self.shared)
        for i, (c, keys) in copies.items():
            for k in keys:
                d[k] = c
        for template, keys, slots in self.lists:
            lst = list(template)
            for idx, i in slots:
                lst[idx] = copies[i][0]
            for k in keys:
                d[k] = lst
        seg = self.cls.__new__(self.cls)
        seg.__dict__.update(d)
        return seg


__all__ = ["PlanRepeats", "REPEAT_MEMO", "KEPT_KINDS"]
