# cython: boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False, auto_pickle=False
"""The loops of robot/cellbound.py's bound (issue 89; docs/cells.md "Speed"), written once in Python
and compiled by Cython from this very file (the C types in cellproof.pxd beside it; robot/build.py
``PURE``): without a compiler it runs as it stands (robot/kinematics/compiled.py ``pure_module``
picks the one in use). Plain float arithmetic in one order and libm's ``sqrt``: the same numbers
compiled and as Python.

* :func:`segment_distance`: the least distance of two segments;
* :class:`Prover`, one a scene's bound, its arrays given once: ``measure``, a reference pose's
  gaps (each checked geom pair's segments' distance less its reach) and levers (each joint's for
  each geom it carries: the larger distance of the geom's segment's two ends from the joint's
  axis); ``first_unproved``, the first row of poses a reference leaves unproved (windows of
  rows bounded at once by their largest displacements, as numpy's form did before 2026-11-30);
* :func:`deepest`: the deepest of a robot pair's exact geom pairs;
* :func:`least`: the least of some values.

The arrays are numpy's, C-contiguous: float64, and ``intp`` for indices (robot/cellbound.py
``CellBound``'s).
"""

from math import *  # noqa: F403  (sqrt: cellproof.pxd declares libm's as C's when compiled)

try:
    import cython
    COMPILED = cython.compiled
except ImportError:     # an install without Cython (a need of the build only): this file as Python
    COMPILED = False

#: a segment shorter than this squared (m^2) is taken as a point
POINT_M2 = 1e-18
INF = float("inf")
#: the rows :meth:`Prover.first_unproved` looks at first, doubled while they all pass (64 before
#: 2026-11-30 05:15 UTC: the references of robots touching prove 3-7 rows; docs/cells.md "Speed")
WINDOW = 8


def built_from():
    """The sha256 of cellproof.py and cellproof.pxd the compiled module was built from
    (robot/build.py embeds it); "" as Python."""
    if COMPILED:
        return pure_source_sha().decode("ascii")  # noqa: F821  (cellproof.pxd's C constant)
    return ""


def _clamp(x):
    """`x` clamped to [0, 1]."""
    if x < 0.0:
        return 0.0
    if x > 1.0:
        return 1.0
    return x


def segment_distance(px, py, pz, ux, uy, uz, qx, qy, qz, vx, vy, vz):
    """The least distance (m) of the segment from p along u (``p + s u``, s in [0, 1]) and the
    one from q along v (a segment whose u or v is shorter than :data:`POINT_M2` squared is its
    point): the closest points' parameters as in Ericson, *Real-Time Collision Detection*
    (2005), 5.1.9, clamped to the segments."""
    rx = px - qx
    ry = py - qy
    rz = pz - qz
    a = ux * ux + uy * uy + uz * uz
    e = vx * vx + vy * vy + vz * vz
    f = vx * rx + vy * ry + vz * rz
    s = 0.0
    t = 0.0
    if a <= POINT_M2:
        if e > POINT_M2:
            t = _clamp(f / e)
    else:
        c = ux * rx + uy * ry + uz * rz
        if e <= POINT_M2:
            s = _clamp(-c / a)
        else:
            b = ux * vx + uy * vy + uz * vz
            denom = a * e - b * b
            if denom > 0.0:
                s = _clamp((b * f - c * e) / denom)
            t = (b * s + f) / e
            # t clamped to the second segment, s again the closest to it on the first
            if t < 0.0:
                t = 0.0
                s = _clamp(-c / a)
            elif t > 1.0:
                t = 1.0
                s = _clamp((b - c) / a)
    dx = rx + ux * s - vx * t
    dy = ry + uy * s - vy * t
    dz = rz + uz * s - vz * t
    return sqrt(dx * dx + dy * dy + dz * dz)  # noqa: F405


def deepest(gaps, exact, start, stop, beyond):
    """The index k in [`start`, `stop`) of the pair with ``exact[k]`` whose depth ``-gaps[k] -
    beyond`` is the largest and positive (the first of equal ones); -1 when there is none."""
    best = -1
    depth = 0.0
    for k in range(start, stop):
        if exact[k] and -gaps[k] - beyond > depth:
            depth = -gaps[k] - beyond
            best = k
    return best


def least(values):
    """The least of `values` (float64; +inf when empty)."""
    low = INF
    for k in range(values.shape[0]):
        if values[k] < low:
            low = values[k]
    return low


class Prover:
    """The loops of one scene's bound (robot/cellbound.py ``CellBound``: `near`, `far`, `half`,
    `reach`, the hinges' `hflat`, `hjoint`, `hgeom`, `slide`, as its fields are; `slack`: its
    :data:`~robot.cellbound.LEVER_SLACK_M2`; `lo`, `hi`: each geom's columns whose levers can
    be other than 0, ``lo[g]`` to ``hi[g]``, its own robot's), with their scratch arrays `top`
    (columns), `moved` (geoms) and `over` (pairs, intp): the arrays given once, not at each call
    (a typed array given to a call costs about 1,000 instructions; since 2026-11-30 05:15 UTC,
    docs/cells.md "Speed": before, module functions took all of them at each call)."""

    def __init__(self, near, far, half, reach, hflat, hjoint, hgeom, slide, slack, lo, hi, top, moved, over):
        self.near, self.far, self.half, self.reach = near, far, half, reach
        self.lo, self.hi = lo, hi
        self.hflat, self.hjoint, self.hgeom, self.slide = hflat, hjoint, hgeom, slide
        self.slack = slack
        self.top, self.moved, self.over = top, moved, over

    def measure(self, xpos, xmat, anchor, axis, gaps, levers):
        """A reference's `gaps` and `levers` (both written; robot/cellbound.py
        ``CellBound.reference``) from the scene's geom centres `xpos` (ngeom, 3, m), frames `xmat`
        (ngeom, 9: a capsule along its Z) and joints' `anchor` and `axis` (njnt, 3): ``gaps[k]``
        the distance of the segments (half-length ``half``) of geoms ``near[k]`` and ``far[k]``
        less ``reach[k]``; `levers` (the (geoms, columns) array flat) 0 but at ``hflat[i]``: the
        larger squared distance of geom ``hgeom[i]``'s segment's ends from joint ``hjoint[i]``'s
        axis, plus ``slack``, its root; and 1 at each of ``slide``."""
        near, far, half = self.near, self.far, self.half
        for k in range(near.shape[0]):
            g = near[k]
            h = far[k]
            hg = half[g]
            hh = half[h]
            gaps[k] = segment_distance(xpos[g, 0] - hg * xmat[g, 2], xpos[g, 1] - hg * xmat[g, 5],
                                       xpos[g, 2] - hg * xmat[g, 8],
                                       2.0 * hg * xmat[g, 2], 2.0 * hg * xmat[g, 5], 2.0 * hg * xmat[g, 8],
                                       xpos[h, 0] - hh * xmat[h, 2], xpos[h, 1] - hh * xmat[h, 5],
                                       xpos[h, 2] - hh * xmat[h, 8],
                                       2.0 * hh * xmat[h, 2], 2.0 * hh * xmat[h, 5],
                                       2.0 * hh * xmat[h, 8]) - self.reach[k]
        for i in range(levers.shape[0]):
            levers[i] = 0.0
        for i in range(self.hflat.shape[0]):
            g = self.hgeom[i]
            j = self.hjoint[i]
            best = 0.0
            for e in range(2):          # the segment's two ends
                hz = half[g] if e == 0 else -half[g]
                vx = xpos[g, 0] + hz * xmat[g, 2] - anchor[j, 0]
                vy = xpos[g, 1] + hz * xmat[g, 5] - anchor[j, 1]
                vz = xpos[g, 2] + hz * xmat[g, 8] - anchor[j, 2]
                along = vx * axis[j, 0] + vy * axis[j, 1] + vz * axis[j, 2]
                r2 = (vx * vx + vy * vy + vz * vz) - along * along
                if r2 > best:
                    best = r2
            levers[self.hflat[i]] = sqrt(best + self.slack)  # noqa: F405
        for i in range(self.slide.shape[0]):
            levers[self.slide[i]] = 1.0

    def first_unproved(self, levers, pose, poses, start, limits):
        """The first row of `poses` (rows, columns) from `start` on in which some pair k's two
        displacement bounds reach ``limits[k]`` (``len(poses)`` when none does): geom g's bound
        is the sum over the columns of ``levers[g, c] * |poses[r, c] - pose[c]|``. Rows are taken
        in windows of :data:`WINDOW`, doubled while they pass: a window's largest displacement of
        each column (into ``top``) bounds every row of it (each geom's bound then into ``moved``),
        and only the pairs it does not pass (their indices into ``over``) are summed row by row:
        each geom's bound once a row where those pairs outnumber half the geoms (since
        2026-11-30 05:15 UTC: before, each pair's two, a pair at a time; the same sums)."""
        near, far, top, moved, over = self.near, self.far, self.top, self.moved, self.over
        n = poses.shape[0]
        r = start
        width = WINDOW
        while r < n:
            stop = r + width
            if stop > n:
                stop = n
            for c in range(levers.shape[1]):
                top[c] = 0.0
            for i in range(r, stop):
                for c in range(levers.shape[1]):
                    d = abs(poses[i, c] - pose[c])
                    if d > top[c]:
                        top[c] = d
            for g in range(levers.shape[0]):
                moved[g] = _moved(levers, top, g, self.lo[g], self.hi[g])
            m = 0
            for k in range(near.shape[0]):
                if moved[near[k]] + moved[far[k]] >= limits[k]:
                    over[m] = k
                    m += 1
            if m:
                every = 2 * m > levers.shape[0]
                for i in range(r, stop):
                    for c in range(levers.shape[1]):
                        top[c] = abs(poses[i, c] - pose[c])
                    if every:
                        for g in range(levers.shape[0]):
                            moved[g] = _moved(levers, top, g, self.lo[g], self.hi[g])
                        for j in range(m):
                            k = over[j]
                            if moved[near[k]] + moved[far[k]] >= limits[k]:
                                return i
                    else:
                        for j in range(m):
                            k = over[j]
                            if _moved(levers, top, near[k], self.lo[near[k]], self.hi[near[k]]) + \
                                    _moved(levers, top, far[k], self.lo[far[k]], self.hi[far[k]]) >= limits[k]:
                                return i
            r = stop
            width = 2 * width
        return n


def _moved(levers, top, g, lo, hi):
    """Geom `g`'s displacement bound: ``sum_c levers[g, c] * top[c]``, the columns in order from
    `lo` to `hi` (the others' levers 0: their terms add exactly 0 to the sum)."""
    acc = 0.0
    for c in range(lo, hi):
        acc += levers[g, c] * top[c]
    return acc
