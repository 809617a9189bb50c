"""The kinematics' hot path, written once in Python and compiled by Cython from this very file
(the C types are in fastpath.pxd beside it; robot/build.py, ``make vm-loop``): without a compiler
this module runs as it stands, with one it is the same code in C. Nothing here is a mirror of
anything else.

* :class:`Chooser`: the choice of ``Kinematics.inverse`` among candidate rows (robot/kinematics/
  family.py ``select``, every family): per row and axis the ±360° variant within the soft limits
  (and with the sign of its turn bit) nearest to the reference, then the row with the least axis
  motion, the first of equals;
* :class:`OPWCore`: the OPW closed form of one pose (robot-model.md §4.2; robot/kinematics/
  opwsolver.py uses it for every pose), the arm's status S of a row (robot-model.md §8) and the
  whole inverse of the six-axis family for one pose (the rows, those with the status, the choice).

The numbers are Python's in both forms: libm's sin, cos, atan2, acos, sqrt, fmod and copysign
(what ``math`` calls; the compiled module calls them directly), ``degrees``/``radians`` as
CPython's multiplications by 180/pi and pi/180, Python's float ``%`` spelled out as CPython's
``float_rem`` (:func:`_pymod`), ``min``/``max`` as comparisons in Python's order, and no fused
multiply-add (``-ffp-contract=off``). Buffers are attributes ("registers": ``M`` the pose,
``ref`` the reference, ``rows`` the candidates, ``q`` the answer): lists here, C arrays compiled.
tests/robot/test_simcore.py runs this file as Python against the compiled module.

Units: mm and deg; a pose is the first three rows of a 4x4 flange frame, row-major (12 values).
"""

from math import *  # noqa: F403  (libm's functions: compiled, fastpath.pxd declares them as C's)

import numpy as np

PI = 3.141592653589793
DEG_TO_RAD = PI / 180.0
RAD_TO_DEG = 180.0 / PI
BOUNDARY_EPS = 1e-9
WRIST_SINGULAR_DEG = 1e-6
OVERHEAD_SINGULAR_MM = 1e-6
ACOS_TOL = 1e-9
#: Rows a chooser holds (the OPW form has 8; the palletizers and the numeric solver fewer than this)
MAX_ROWS = 64
#: Axes a row holds (the registers below are of these sizes: 8, and 64 * 8 = 512 for the rows; the
#: seven-axis family chooses rows of 7)
MAX_AXES = 8


def _pymod(vx, wx):
    """CPython's float ``vx % wx`` (Objects/floatobject.c float_rem), wx != 0."""
    mod = fmod(vx, wx)  # noqa: F405
    if mod != 0.0:
        if (wx < 0.0) != (mod < 0.0):
            mod += wx
    else:
        mod = copysign(0.0, wx)  # noqa: F405
    return mod


def _wrapdeg(th, off, sg):
    """``-((-degrees((th + off) * sg) + 180.0) % 360.0) + 180.0``: KUKA's axis (deg, in
    (-180, 180]) of OPW's joint angle `th` (rad). Where 0 < x < 360 (x the dividend; an axis
    already in (-180, 180), as most are) :func:`_pymod`'s answer is x itself (fmod is exact and
    x lies below the divisor; x > 0 keeps its sign), taken without the call: the same bytes."""
    x = -((th + off) * sg * RAD_TO_DEG) + 180.0
    if 0.0 < x < 360.0:
        return -x + 180.0
    return -_pymod(x, 360.0) + 180.0


class Chooser:
    """The choice among candidate rows of n axes (module docstring) for the soft limits `lo`/`hi`
    (deg, already widened by the limit tolerance), the turn variants `ks` (deg: -720 .. 720) of
    each axis (`linear`: a linear axis has only its own value) and the turn bits `t_free` that
    select nothing. Raises ValueError for more than MAX_AXES axes; otherwise nothing: :meth:`pick`
    answers 0 when no row fits (the caller gives the error)."""

    def __init__(self, n, lo, hi, ks, linear, t_free):
        if n > MAX_AXES:
            raise ValueError(f"{n} axes: a row holds at most {MAX_AXES}")
        self.n = n
        self.t_free = t_free
        self.lo = [0.0] * 8
        self.hi = [0.0] * 8
        self.lin = [0] * 8
        for i in range(n):
            self.lo[i] = lo[i]
            self.hi[i] = hi[i]
            self.lin[i] = 1 if linear[i] else 0
        self.ks = [0.0] * 5
        for i in range(5):
            self.ks[i] = ks[i]
        self.ref = [0.0] * 8
        self.rows = [0.0] * 512
        self.q = [0.0] * 8
        self.cand = [0.0] * 8

    def pick(self, nrows, use_turn, tmask):
        """The row of ``rows[0:nrows]`` (each n values) that ``Kinematics.inverse`` takes for the
        reference ``ref`` into ``q``: 1, or 0 when none fits the limits (and the turn ``tmask``
        when `use_turn`; its bits in ``t_free`` left out)."""
        n = self.n
        have_best = 0
        best_cost = 0.0
        for j in range(nrows):
            base = j * MAX_AXES
            ok = 1
            for i in range(n):
                found = 0
                best_c = 0.0
                best_d = inf  # noqa: F405
                for kk in range(5):
                    if self.lin[i] and kk != 2:
                        continue                    # a linear axis: its own value alone
                    c = self.rows[base + i] + self.ks[kk]
                    if c < self.lo[i] or c > self.hi[i]:
                        continue
                    if use_turn and not ((c < 0.0) == (((tmask >> i) & 1) == 1) or fabs(c) < 1e-6  # noqa: F405
                                         or ((self.t_free >> i) & 1) == 1):
                        continue
                    d = fabs(c - self.ref[i])  # noqa: F405
                    if d < best_d:
                        best_c = c
                        best_d = d
                        found = 1
                if not found:
                    ok = 0
                    break
                self.cand[i] = best_c
            if ok:
                cost = 0.0
                for i in range(n):
                    cost += fabs(self.cand[i] - self.ref[i])  # noqa: F405
                if not have_best or cost < best_cost:
                    have_best = 1
                    best_cost = cost
                    for i in range(n):
                        self.q[i] = self.cand[i]
        return have_best

    def choose(self, rows, ref, turn):
        """:meth:`pick` of the rows `rows` (lists of n floats, at most MAX_ROWS) for the reference
        `ref` (n floats) and the turn `turn` (None: nearest): the chosen axes as a list, or None."""
        nrows = len(rows)
        if nrows > MAX_ROWS:
            raise ValueError(f"{nrows} candidate rows: at most {MAX_ROWS}")
        n = self.n
        for i in range(n):
            self.ref[i] = ref[i]
        for j in range(nrows):
            r = rows[j]
            for i in range(n):
                self.rows[j * MAX_AXES + i] = r[i]
        tmask = 0
        use_turn = 0
        if turn is not None:
            tmask = int(turn) & ~self.t_free
            use_turn = 1
        if not self.pick(nrows, use_turn, tmask):
            return None
        return [self.q[i] for i in range(n)]

    def limit_error(self, nrows, turn, lo0, hi0):
        """After :meth:`choose` found no row of its `nrows` rows for its reference: the axis index
        and value of robot/kinematics/family.py ``_limit_error``'s SoftLimitError for the soft
        limits `lo0`/`hi0` (n floats each, deg, not widened), as (i, value); None where a row
        fits (the caller's numpy code answers then). Per row and axis the variant (a linear
        axis: itself, its others infinite) within the widened limits and the turn nearest to the
        reference (the first of equals), else, where an axis has none, the allowed variant
        nearest to the limits (``max(lo - c, c - hi)``, the first of equals); the row whose sum of
        axis distances to the reference is least (the first of equals); its first such axis."""
        n = self.n
        tmask = 0
        use_turn = 0
        if turn is not None:
            tmask = int(turn) & ~self.t_free
            use_turn = 1
        have = 0
        best_cost = 0.0
        best_i = 0
        best_v = 0.0
        for j in range(nrows):
            base = j * MAX_AXES
            first_bad = -1
            for i in range(n):
                pick_c = 0.0
                pick_d = inf  # noqa: F405
                over_c = 0.0
                over_d = inf  # noqa: F405
                inlim_any = 0
                for kk in range(5):
                    if self.lin[i] and kk != 2:
                        c = inf  # noqa: F405
                    else:
                        c = self.rows[base + i] + self.ks[kk]
                    ok = 1
                    if use_turn and not ((c < 0.0) == (((tmask >> i) & 1) == 1) or fabs(c) < 1e-6  # noqa: F405
                                         or ((self.t_free >> i) & 1) == 1):
                        ok = 0
                    if kk == 0:
                        pick_c = c
                        over_c = c
                    if ok and c >= self.lo[i] and c <= self.hi[i]:
                        d = fabs(c - self.ref[i])  # noqa: F405
                        if not inlim_any or d < pick_d:
                            pick_c = c
                            pick_d = d
                        inlim_any = 1
                    if ok:
                        o = lo0[i] - c
                        if c - hi0[i] > o:
                            o = c - hi0[i]
                        if o < over_d:
                            over_c = c
                            over_d = o
                if inlim_any:
                    self.cand[i] = pick_c
                else:
                    self.cand[i] = over_c
                    if first_bad < 0:
                        first_bad = i
            if first_bad < 0:
                return None
            cost = 0.0
            for i in range(n):
                cost += fabs(self.cand[i] - self.ref[i])  # noqa: F405
            if not have or cost < best_cost:
                have = 1
                best_cost = cost
                best_i = first_bad
                best_v = self.cand[first_bad]
        if not have:
            return None
        return (best_i, best_v)


class OPWCore(Chooser):
    """The OPW solution of one six-axis arm (the parameters `o`, robot/machine.py ``OPWParams``,
    mm; the switching angle `phi` of S bit 1, deg; the axis signs `sgn` and offsets `offs`, rad,
    of OPW's convention), and its inverse for one pose with the limits of :class:`Chooser` and
    the S bits `s_free` that select nothing."""

    def __init__(self, o, phi, sgn, offs, lo, hi, ks, s_free, t_free):
        Chooser.__init__(self, 6, lo, hi, ks, [0, 0, 0, 0, 0, 0], t_free)
        self.a1 = o.a1
        self.a2 = o.a2
        self.b = o.b
        self.c1 = o.c1
        self.c2 = o.c2
        self.c3 = o.c3
        self.c4 = o.c4
        self.kappa_2 = o.a2 * o.a2 + o.c3 * o.c3
        self.c2_2 = o.c2 * o.c2
        self.k = sqrt(self.kappa_2)  # noqa: F405
        self.at23 = atan2(o.a2, o.c3)  # noqa: F405
        self.phi = phi
        self.s_free = s_free
        self.sgn = [0.0] * 6
        self.offs = [0.0] * 6
        for i in range(6):
            self.sgn[i] = sgn[i]
            self.offs[i] = offs[i]
        self.M = [0.0] * 12
        self.sol = [0.0] * (8 * 6)
        self.arm = [0.0] * 12
        self.s_out = 0
        self.amb_out = 0
        self.n_rows = 0
        self.n_match = 0
        self.src = None

    def use_rows(self, src):
        """Solve with the rows of `src` in place of the OPW closed form (a palletizer's rows:
        robot/kinematics/pal4rows.py, pal5rows.py, whose arm this core's status is): :meth:`core`
        answers ``src.fill(self, has_ref)``, which writes the rows of the pose ``M`` (for the
        reference ``ref`` where `has_ref`) into ``sol`` and gives their number (0: none; -1: more
        than 8, which the Python code then decides). The status, the choice and every caller of
        :meth:`solve` stay as they are: one compiled call per pose (rows, status, choice), as for
        the OPW arms."""
        self.src = src

    # ------------------------------------------------------------------ the closed form
    def core(self, has_ref):
        """The OPW solutions of the pose ``M`` into ``sol`` (up to 8 rows of 6 axes, deg, wrapped
        to (-180, 180]); their number. With `has_ref` the free angle at a singularity is the
        reference's (``ref``): A1 when the wrist point is on the A1 axis, A4 when A5 = 0. With a
        rows source (:meth:`use_rows`) its rows instead."""
        if self.src is not None:
            return self.src.fill(self, has_ref)
        return self._wrists(self._arms(has_ref), has_ref)

    def arm_rows(self, has_ref):
        """The arms of :meth:`core`'s closed form alone (a palletizer's rows, robot/kinematics/
        pal5rows.py, read A1..A3 of each row only): per arm solution of the pose ``M`` its A1,
        A2, A3 (deg, wrapped as :meth:`core` wraps them) into ``sol``'s row of that index (6
        values a row; A4..A6 not written); their number. :meth:`core` gives two rows per arm (the
        wrist and its flip), both with these A1..A3; the wrist (and the reference's A4 at its
        singularity) is left out."""
        narm = self._arms(has_ref)
        for j in range(narm):
            self.sol[6 * j] = _wrapdeg(self.arm[3 * j], self.offs[0], self.sgn[0])
            self.sol[6 * j + 1] = _wrapdeg(self.arm[3 * j + 1], self.offs[1], self.sgn[1])
            self.sol[6 * j + 2] = _wrapdeg(self.arm[3 * j + 2], self.offs[2], self.sgn[2])
        return narm

    def _arms(self, has_ref):
        """The arm solutions (A1, A2, A3 in OPW's radians, up to 4) of the pose ``M`` into ``arm``;
        their number (0: the wrist point out of reach)."""
        M = self.M
        r02, px = M[2], M[3]
        r12, py = M[6], M[7]
        r22, pz = M[10], M[11]
        cx = px - self.c4 * r02
        cy = py - self.c4 * r12
        cz = pz - self.c4 * r22
        rho2 = cx * cx + cy * cy - self.b * self.b
        if rho2 < 0.0:
            return 0
        nx1 = sqrt(rho2) - self.a1  # noqa: F405
        if has_ref and sqrt(cx * cx + cy * cy) < OVERHEAD_SINGULAR_MM:  # noqa: F405
            tmp1 = (self.sgn[0] * self.ref[0]) * DEG_TO_RAD - self.offs[0]
        else:
            tmp1 = atan2(cy, cx)  # noqa: F405
        tmp2 = atan2(self.b, nx1 + self.a1)  # noqa: F405
        th1_i = tmp1 - tmp2
        th1_ii = tmp1 + tmp2 - PI
        tmp3 = cz - self.c1
        s1_2 = nx1 * nx1 + tmp3 * tmp3
        tmp4 = nx1 + 2.0 * self.a1
        s2_2 = tmp4 * tmp4 + tmp3 * tmp3
        s1 = sqrt(s1_2)  # noqa: F405
        s2 = sqrt(s2_2)  # noqa: F405
        narm = 0
        for j in range(2):
            if j == 0:
                th1 = th1_i
                s_ = s1
                s_2 = s1_2
                base2 = atan2(nx1, tmp3)  # noqa: F405
            else:
                th1 = th1_ii
                s_ = s2
                s_2 = s2_2
                base2 = -atan2(tmp4, tmp3)  # noqa: F405
            if s_ < 1e-12:
                continue
            arg2 = (s_2 + self.c2_2 - self.kappa_2) / (2.0 * s_ * self.c2)
            arg3 = (s_2 - self.c2_2 - self.kappa_2) / (2.0 * self.c2 * self.k)
            if fabs(arg2) > 1.0 + ACOS_TOL or fabs(arg3) > 1.0 + ACOS_TOL:  # noqa: F405
                continue
            # acos(min(1.0, max(-1.0, arg))), min and max as Python decides them
            v = arg2 if arg2 > -1.0 else -1.0
            a2c = acos(v if v < 1.0 else 1.0)  # noqa: F405
            v = arg3 if arg3 > -1.0 else -1.0
            a3c = acos(v if v < 1.0 else 1.0)  # noqa: F405
            self.arm[3 * narm] = th1
            self.arm[3 * narm + 1] = -a2c + base2
            self.arm[3 * narm + 2] = a3c - self.at23
            narm += 1
            self.arm[3 * narm] = th1
            self.arm[3 * narm + 1] = a2c + base2
            self.arm[3 * narm + 2] = -a3c - self.at23
            narm += 1
        return narm

    def _wrists(self, narm, has_ref):
        """The wrist solutions of the `narm` arm solutions in ``arm`` (two each: the wrist and
        its flip), all six axes into ``sol`` (deg, wrapped to (-180, 180]); their number."""
        M = self.M
        r00, r01, r02 = M[0], M[1], M[2]
        r10, r11, r12 = M[4], M[5], M[6]
        r20, r21, r22 = M[8], M[9], M[10]
        n = 0
        for j in range(narm):
            th1 = self.arm[3 * j]
            th2 = self.arm[3 * j + 1]
            th3 = self.arm[3 * j + 2]
            sn1 = sin(th1)  # noqa: F405
            cs1 = cos(th1)  # noqa: F405
            s23 = sin(th2 + th3)  # noqa: F405
            c23 = cos(th2 + th3)  # noqa: F405
            mm = r02 * s23 * cs1 + r12 * s23 * sn1 + r22 * c23
            v = 1.0 - mm * mm
            th5 = atan2(sqrt(v if v > 0.0 else 0.0), mm)  # noqa: F405
            th4 = atan2(r12 * cs1 - r02 * sn1,  # noqa: F405
                        r02 * c23 * cs1 + r12 * c23 * sn1 - r22 * s23)
            th6 = atan2(r01 * s23 * cs1 + r11 * s23 * sn1 + r21 * c23,  # noqa: F405
                        -r00 * s23 * cs1 - r10 * s23 * sn1 - r20 * c23)
            if has_ref and fabs(th5 * RAD_TO_DEG) < WRIST_SINGULAR_DEG:  # noqa: F405
                # the wrist singularity: only th4 + th6 is defined; A4 is the reference's
                total = th4 + th6
                th4 = (self.sgn[3] * self.ref[3]) * DEG_TO_RAD - self.offs[3]
                th6 = total - th4
            b = 6 * n
            self.sol[b] = _wrapdeg(th1, self.offs[0], self.sgn[0])
            self.sol[b + 1] = _wrapdeg(th2, self.offs[1], self.sgn[1])
            self.sol[b + 2] = _wrapdeg(th3, self.offs[2], self.sgn[2])
            self.sol[b + 3] = _wrapdeg(th4, self.offs[3], self.sgn[3])
            self.sol[b + 4] = _wrapdeg(th5, self.offs[4], self.sgn[4])
            self.sol[b + 5] = _wrapdeg(th6, self.offs[5], self.sgn[5])
            n += 1
            b = 6 * n
            # the flip's arm: the wrist's A1..A3, the same function of the same angles
            self.sol[b] = self.sol[b - 6]
            self.sol[b + 1] = self.sol[b - 5]
            self.sol[b + 2] = self.sol[b - 4]
            self.sol[b + 3] = _wrapdeg(th4 + PI, self.offs[3], self.sgn[3])
            self.sol[b + 4] = _wrapdeg(-th5, self.offs[4], self.sgn[4])
            self.sol[b + 5] = _wrapdeg(th6 - PI, self.offs[5], self.sgn[5])
            n += 1
        return n

    def status(self, q0, q1, q2, q3, q4, q5):
        """S of the axes (deg) into ``s_out`` and the mask of its bits that sit on their
        switching point (wrist point on the A1 axis, A3 = phi, A5 = 0) or select nothing
        (``s_free``) into ``amb_out``."""
        t2 = (self.sgn[1] * q1) * DEG_TO_RAD - self.offs[1]
        t23 = t2 + (self.sgn[2] * q2) * DEG_TO_RAD - self.offs[2]
        xw = self.a1 + self.c2 * sin(t2) + self.c3 * sin(t23) + self.a2 * cos(t23)  # noqa: F405
        phi = self.phi
        s = 0
        if xw < -BOUNDARY_EPS:
            s |= 1
        if q2 >= phi - BOUNDARY_EPS:
            s |= 2
        if q4 < -BOUNDARY_EPS:
            s |= 4
        amb = self.s_free
        if fabs(xw) < OVERHEAD_SINGULAR_MM:  # noqa: F405
            amb |= 1
        if fabs(q2 - phi) < 1e-7:  # noqa: F405
            amb |= 2
        if fabs(q4) < WRIST_SINGULAR_DEG:  # noqa: F405
            amb |= 4
        self.s_out = s
        self.amb_out = amb

    def solve(self, has_status, status, use_turn, tmask):
        """The inverse of the pose ``M`` for the reference ``ref`` into ``q``: the rows of
        :meth:`core` whose S is `status` (masked with 7; without `has_status` the reference's,
        bits it sits on left free), then :meth:`pick`. 1, or 0 where ``Kinematics.inverse``
        raises (no row, none with the status, none within the limits): ``n_rows`` the rows of
        :meth:`core` (-1: a rows source had more than 8), ``n_match`` those with the status (in
        ``rows``, for :meth:`Chooser.limit_error`)."""
        n = self.core(1)
        self.n_rows = n
        self.n_match = 0
        if n <= 0:
            return 0
        if has_status:
            s_target = status & 7
            free = 0
        else:
            self.status(self.ref[0], self.ref[1], self.ref[2], self.ref[3], self.ref[4], self.ref[5])
            s_target = self.s_out
            free = self.amb_out
        keep = ~free
        nmatch = 0
        for j in range(n):
            b = 6 * j
            self.status(self.sol[b], self.sol[b + 1], self.sol[b + 2], self.sol[b + 3], self.sol[b + 4],
                        self.sol[b + 5])
            if ((self.s_out ^ s_target) & ~self.amb_out & keep & 7) != 0:
                continue
            for i in range(6):
                self.rows[nmatch * MAX_AXES + i] = self.sol[b + i]
            nmatch += 1
        self.n_match = nmatch
        return self.pick(nmatch, use_turn, tmask)

    # ------------------------------------------------------------------ for Python callers
    def rows_of(self, T, ref):
        """The OPW solutions of the flange pose T (4x4 float64 array, mm) as lists of 6 axes (deg),
        with the reference `ref` ((6,) float64 array, or None) for the singularities."""
        for i in range(3):
            for j in range(4):
                self.M[4 * i + j] = T[i, j]
        has_ref = 0
        if ref is not None:
            has_ref = 1
            for i in range(6):
                self.ref[i] = ref[i]
        n = self.core(has_ref)
        return [[self.sol[6 * j + i] for i in range(6)] for j in range(n)]

    def inverse(self, T, status, turn, ref):
        """``Kinematics.inverse`` of the flange pose T (4x4 float64 array, mm, the arm's own frame)
        for the reference `ref` ((6,) float64 array): the axes ((6,) array), or None where it
        raises (the caller gives the error)."""
        for i in range(3):
            for j in range(4):
                self.M[4 * i + j] = T[i, j]
        return self._inverse(status, turn, ref)

    def inverse_rp(self, R, p, status, turn, ref):
        """:meth:`inverse` of the pose with rotation R (3x3 float64 array) and position p ((3,), mm)."""
        for i in range(3):
            for j in range(3):
                self.M[4 * i + j] = R[i, j]
            self.M[4 * i + 3] = p[i]
        return self._inverse(status, turn, ref)

    def _inverse(self, status, turn, ref):
        for i in range(6):
            self.ref[i] = ref[i]
        tmask = 0
        use_turn = 0
        if turn is not None:
            tmask = int(turn) & ~self.t_free
            use_turn = 1
        if not self.solve(status is not None, int(status) if status is not None else 0, use_turn, tmask):
            return None
        res = np.empty(6)
        out = res
        for i in range(6):
            out[i] = self.q[i]
        return res

    def inverse_chain_rp(self, R, p, status, turn, ref):
        """:meth:`inverse_rp` of each pose (R[j] (3x3), p[j] (3,)) in turn, each solution the next
        one's reference (the first one's: `ref`): the axes (N, 6), the rows those of N calls of
        :meth:`inverse_rp` bit for bit, or None as soon as one of them is None (the caller then
        solves pose by pose for the error)."""
        n = R.shape[0]
        if p.shape[0] != n:
            raise ValueError("R and p hold different numbers of poses")
        res = np.empty((n, 6))
        out = res
        for i in range(6):
            self.ref[i] = ref[i]
        tmask = 0
        use_turn = 0
        if turn is not None:
            tmask = int(turn) & ~self.t_free
            use_turn = 1
        for j in range(n):
            for i in range(3):
                for k in range(3):
                    self.M[4 * i + k] = R[j, i, k]
                self.M[4 * i + 3] = p[j, i]
            if not self.solve(status is not None, int(status) if status is not None else 0, use_turn, tmask):
                return None
            for i in range(6):
                out[j, i] = self.q[i]
                self.ref[i] = self.q[i]
        return res


__all__ = ["Chooser", "MAX_ROWS", "OPWCore"]
