# cython: auto_pickle=False
"""The SCARA's rows of a flange pose (robot/kinematics/scara.py ``Scara.solutions``; issue 86
item 1), written once in Python and compiled by Cython from this very file (the C types in
scararows.pxd beside it; robot/build.py ``PURE``): without a compiler it runs as it stands
(robot/kinematics/compiled.py ``pure_module`` picks the one in use). Plain float arithmetic in a
fixed order, so the compiled module gives the Python run's rows bit for bit
(``-ffp-contract=off``).

:class:`ScaraRows` solves as scara.py's module docstring says: the flange's rotation about the
vertical ``theta`` (from ``R = T[:3, :3] R_F^T``, its tilt dropped), the quill point ``w``
(the target less the flange offset turned by ``theta``), A3 from its height, A1 and A2 from the
planar two-link arm to ``w`` (the elbow on either side: two rows, one when stretched), A4 from
``theta - A1 - A2``; out of reach: no row. The products of ``R`` are numpy's ``matmul`` order
(a sum from 0.0, term by term).

Units: mm and deg (angles inside in rad).
"""

from math import *  # noqa: F403  (libm's functions: compiled, scararows.pxd declares them as C's)

try:
    import cython
    COMPILED = cython.compiled
except ImportError:     # an install without Cython (a need of the build only): this file as Python
    COMPILED = False

PI = 3.141592653589793
DEG_TO_RAD = PI / 180.0
RAD_TO_DEG = 180.0 / PI
#: robot/kinematics/constants.py ACOS_TOL and OVERHEAD_SINGULAR_MM (their values; the build has no imports)
ACOS_TOL = 1e-9
OVERHEAD_SINGULAR_MM = 1e-6
#: an elbow angle below this (rad) is the stretched arm: one row
STRETCHED = 1e-12


def built_from() -> str:
    """The sha256 of scararows.py and scararows.pxd the compiled module was built from
    (robot/build.py embeds it); "" as Python."""
    if COMPILED:
        return pure_source_sha().decode("ascii")  # noqa: F821  (scararows.pxd's C function)
    return ""


def _wrap(v):
    """``-((-v + 180.0) % 360.0) + 180.0`` with CPython's float ``%`` spelled out (fmod, then the
    divisor's sign; a zero remainder is +0.0): the angle `v` (deg) in (-180, 180]."""
    x = -v + 180.0
    mod = fmod(x, 360.0)  # noqa: F405
    if mod != 0.0:
        if mod < 0.0:
            mod += 360.0
    else:
        mod = 0.0
    return -mod + 180.0


class ScaraRows:
    """One SCARA's closed form: ``rows(T, ref)`` the (up to two) rows A1..A4 (deg; A3 mm; A1, A2,
    A4 wrapped to (-180, 180]) of the flange pose `T` (4x4, mm, in $ROBROOT); `ref` (A1..A4 or
    None) gives A1 where the quill stands on the A1 axis.

    Args: `o0` the A1 axis point, `a` A1 axis -> A2 axis, `b` A2 axis -> the quill, `f` the quill
    point -> the flange (3 floats each, mm), `rf` the flange's rotation at A4 = 0 (9 floats, row
    major), `s` the axes' directions (4 floats), `l1`, `l2`, `alpha`, `beta` the arms' lengths
    (mm) and angles (rad) (scara.py ``Scara.__init__``)."""

    def __init__(self, o0, a, b, f, rf, s, l1, l2, alpha, beta):
        self.o0 = [0.0] * 3
        self.a = [0.0] * 3
        self.b = [0.0] * 3
        self.f = [0.0] * 3
        self.rf = [0.0] * 9
        self.s = [0.0] * 4
        for i in range(3):
            self.o0[i] = float(o0[i])
            self.a[i] = float(a[i])
            self.b[i] = float(b[i])
            self.f[i] = float(f[i])
        for i in range(9):
            self.rf[i] = float(rf[i])
        for i in range(4):
            self.s[i] = float(s[i])
        self.l1 = float(l1)
        self.l2 = float(l2)
        self.alpha = float(alpha)
        self.beta = float(beta)

    def _m(self, T, i, j):
        """``(T[:3, :3] @ R_F.T)[i, j]`` as numpy's matmul sums it (from 0.0, k = 0, 1, 2)."""
        rf = self.rf
        acc = 0.0
        acc += float(T[i, 0]) * rf[3 * j]
        acc += float(T[i, 1]) * rf[3 * j + 1]
        acc += float(T[i, 2]) * rf[3 * j + 2]
        return acc

    def rows(self, T, ref):
        """The rows of the flange pose `T` (4x4), a list of up to two lists of four floats."""
        theta = atan2(self._m(T, 1, 0) - self._m(T, 0, 1), self._m(T, 0, 0) + self._m(T, 1, 1))  # noqa: F405
        c = cos(theta)  # noqa: F405
        s = sin(theta)  # noqa: F405
        f = self.f     # noqa: F841 (compiled: the C array itself)
        w0 = (float(T[0, 3]) - self.o0[0]) - (c * f[0] - s * f[1])
        w1 = (float(T[1, 3]) - self.o0[1]) - (s * f[0] + c * f[1])
        w2 = (float(T[2, 3]) - self.o0[2]) - f[2]
        a3 = (w2 - self.a[2] - self.b[2]) * self.s[2]
        l1 = self.l1
        l2 = self.l2
        r2 = w0 * w0 + w1 * w1
        cd = (r2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
        out = []
        if fabs(cd) > 1.0 + ACOS_TOL:  # noqa: F405
            return out
        delta = acos(min(1.0, max(-1.0, cd)))  # noqa: F405
        n = 2 if delta > STRETCHED else 1
        for k in range(n):
            dl = delta if k == 0 else -delta
            if n == 1:
                dl = 0.0
            if sqrt(r2) < OVERHEAD_SINGULAR_MM and ref is not None:  # noqa: F405
                phi1 = (self.s[0] * float(ref[0])) * DEG_TO_RAD + self.alpha    # A1 free: the reference's
            else:
                phi1 = atan2(w1, w0) - atan2(l2 * sin(dl), l1 + l2 * cos(dl))  # noqa: F405
            th1 = phi1 - self.alpha
            th2 = dl - self.beta + self.alpha
            th4 = theta - th1 - th2
            out.append([_wrap((th1 * RAD_TO_DEG) * self.s[0]), _wrap((th2 * RAD_TO_DEG) * self.s[1]), a3,
                        _wrap((th4 * RAD_TO_DEG) * self.s[3])])
        return out
