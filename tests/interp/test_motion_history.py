"""The executed-motion history keeps the newest MAX_MOTION_HISTORY motions (interp/runtime/runmode.py
``MotionHistory``): past the bound the oldest drops out, and backward motion retraces newest first."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from interp.runtime import runmode
from robot.motion import MotionParams


def test_the_history_drops_the_oldest_past_its_bound(monkeypatch):
    monkeypatch.setattr(runmode, "MAX_MOTION_HISTORY", 3)
    h = runmode.MotionHistory()
    p = MotionParams()
    for i in range(5):
        req = SimpleNamespace(id=i, kind="PTP", target={"A1": float(i)}, params=p, file="f.src", line=10 + i)
        seg = SimpleNamespace(q0=np.full(6, float(i)), q1=np.full(6, i + 1.0), T=1.0)
        h.record(req, seg)
    assert [r.id for r in h.records] == [2, 3, 4]
    got = []
    while h.records:
        req, rec = h.next_backward("T1", p.tool, p.base)
        got.append((rec.id, req.target["A1"]))
    assert got == [(4, 4.0), (3, 3.0), (2, 2.0)]
