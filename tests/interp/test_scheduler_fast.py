"""The scheduler's per-cycle fast test (interp/runtime/scheduler.py ``moved_axes``, whether the robot
moved in an IPO cycle) answers as numpy's ``not (q == q0).all()`` on drawn axis vectors, with the
axes as a list where they moved."""

from __future__ import annotations

import random

import numpy as np

from interp.runtime.scheduler import moved_axes


def test_moved_axes_is_numpys_comparison():
    rng = random.Random(7)
    seen = set()
    for _ in range(3000):
        n = rng.choice([6, 7, 12])
        q = np.array([rng.choice([0.0, -0.0, 1.5, rng.uniform(-180, 180), float("nan"), float("inf")])
                      for _ in range(n)])
        q0 = q.copy()
        for _ in range(rng.choice([0, 0, 1, 2])):
            i = rng.randrange(n)
            q0[i] = rng.choice([np.nextafter(q0[i], np.inf), -q0[i], 0.0, -0.0, float("nan"), q0[i]])
        want = bool((q == q0).all())
        got = moved_axes(q, q0)
        assert (got is None) is want
        if got is not None:
            assert len(got) == n and all(a == b or (a != a and b != b) for a, b in zip(got, q.tolist()))
        seen.add(want)
    assert seen == {True, False}
