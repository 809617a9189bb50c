# cython: auto_pickle=False
"""The 5-axis palletizer's rows of a flange pose (robot/kinematics/palletizer5.py
``Palletizer5.solutions``; issue 86 item 1), written once in Python and compiled by Cython from
this very file (the C types in pal5rows.pxd beside it; robot/build.py ``PURE``): without a
compiler it runs as it stands, on fastpath.py's ``OPWCore`` as Python (robot/kinematics/compiled.py
``pure_module`` picks the one in use). Plain float arithmetic on 3-vectors in a fixed order, so
the compiled module gives the Python run's rows bit for bit (``-ffp-contract=off``).

:class:`Palletizer5Rows` solves as palletizer5.py's module docstring says, at A4 = 0:

1. for each arm plane (A1 towards the target's position, and behind the A1 axis) the A5 axis is
   the plane's normal ``n``; the target's A6 axis ``a_des`` projected into the plane (dropped
   when it lies along ``n``, within 1e-9) gives the pitch ``psi`` of the A6 axis against its
   direction at A2 = A3 = A5 = 0; the flange's offset from the A5 point turned by ``psi`` about
   ``n`` gives the A5 point ``w``;
2. fastpath's ``OPWCore.arm_rows`` of ``w`` (c4 = 0, the rotation the identity) gives the arms
   (A1, A2, A3 of ``OPWCore.core``'s rows, one per wrist and flip pair, whose flip repeats its
   arm; a pair of arms equal within 1e-9 deg is one arm);
3. per arm: A5 turns the A6 axis onto the projected ``a_des``; the target turned least so that
   its A6 axis lies in the plane, relative to the flange at A6 = 0, is a rotation about the A6
   axis whose angle (sin from its skew part, cos from its trace) is A6; the row wrapped to
   (-180, 180] is kept when its flange lies within 1e-6 mm of the target (a NaN fails).

Rotations about a unit axis are Rodrigues' formula; the chain is ``JointChain``'s (per joint its
origin, its fixed rotation where the chain has them, its turn about its axis). Registers are
attributes (lists here, C arrays compiled), as in fastpath.py and pal4rows.py.

:class:`Palletizer5Rows`'s ``fill`` gives the same rows to an ``OPWCore`` of the arm (fastpath.py ``use_rows``,
robot/kinematics/palcore.py): that core's inverse is the family's, rows, status and choice in one
compiled call; it keeps the rows of the last pose and reference (bit for bit the same inputs).

Units: mm and deg (angles inside in rad).
"""

from math import *  # noqa: F403  (libm's functions: compiled, pal5rows.pxd declares them as C's)

try:
    import cython
    COMPILED = cython.compiled
except ImportError:     # an install without Cython (a need of the build only): this file as Python
    COMPILED = False

PI = 3.141592653589793
DEG_TO_RAD = PI / 180.0
RAD_TO_DEG = 180.0 / PI
#: the projected A6 axis's least length (palletizer5.py's: the A6 axis along the plane's normal)
PLANE_EPS = 1e-9
#: two arm rows within this (deg, each of A1..A3) are one arm
ARM_EPS = 1e-9
#: a row is kept when its flange lies within this of the target (mm)
KEEP_MM = 1e-6


def built_from() -> str:
    """The sha256 of pal5rows.py and pal5rows.pxd the compiled module was built from
    (robot/build.py embeds it); "" as Python."""
    if COMPILED:
        return pure_source_sha().decode("ascii")  # noqa: F821  (pal5rows.pxd's C function)
    return ""


def _wrap(v):
    """``-((-v + 180.0) % 360.0) + 180.0`` with CPython's float ``%`` spelled out (fmod, then the
    divisor's sign; a zero remainder is +0.0): the axis value `v` (deg) in (-180, 180]. Where
    0 < x < 360 (`v` already in (-180, 180), as the OPW core's rows are) fmod's exact answer is x
    itself, taken without the call."""
    x = -v + 180.0
    if 0.0 < x < 360.0:
        mod = x
    else:
        mod = fmod(x, 360.0)  # noqa: F405
    if mod != 0.0:
        if mod < 0.0:
            mod += 360.0
    else:
        mod = 0.0
    return -mod + 180.0


class Palletizer5Rows:
    """The rows of the 5-axis palletizer (module docstring) on the OPW core `opw` of its arm (c4 =
    0; fastpath's ``OPWCore``, compiled with this module compiled) of the joint chain: `origins`
    and `axes` (6 x 3), KUKA's axis signs `sign` (6), the joints' fixed rotations `R_origin` (6 x 3
    x 3, used where `origin_rot`), the flange's rotation `R_flange` (3 x 3) and position `p_flange`
    (3, mm) (robot/kinematics/joints.py ``JointChain``'s attributes), the A6 axis in the flange
    frame `a6f` (3) and the sign `a1_sign` (+1 or -1) of A1 turning the arm plane counterclockwise
    seen from above (palletizer5.py's ``a6_in_flange`` and ``_a1_of``)."""

    def __init__(self, opw, origins, axes, sign, R_origin, origin_rot, R_flange, p_flange, a6f, a1_sign):
        self.opw = opw
        self.orig = [0.0] * 18
        self.axis = [0.0] * 18
        self.sign = [0.0] * 6
        self.rorig = [0.0] * 54
        self.rfl = [0.0] * 9
        self.pfl = [0.0] * 3
        self.a6f = [0.0] * 3
        self.R = [0.0] * 9
        self.T = [0.0] * 9
        self.U = [0.0] * 9
        self.p = [0.0] * 3
        self.row = [0.0] * 6
        self.P4 = [0.0] * 3
        self.D4 = [0.0] * 3
        self.D5 = [0.0] * 3
        self.FR = [0.0] * 9
        self.FP = [0.0] * 3
        self.N = [0.0] * 3
        self.AP = [0.0] * 3
        self.AD = [0.0] * 3
        self.RT = [0.0] * 9
        self.RC = [0.0] * 9
        self.tp = [0.0] * 3
        self.sols = [0.0] * 48
        self.arms = [0.0] * 24
        self.last = [0.0] * 18
        self.last_has = -1
        self.last_n = 0
        self.found = [0.0] * 48
        self.pre_row = [0.0] * 4
        self.pre_R = [0.0] * 9
        self.pre_p = [0.0] * 3
        self.pre_has = 0
        for i in range(6):
            self.sign[i] = sign[i]
            for j in range(3):
                self.orig[3 * i + j] = origins[i][j]
                self.axis[3 * i + j] = axes[i][j]
                for k in range(3):
                    self.rorig[9 * i + 3 * j + k] = R_origin[i][j][k]
        self.origin_rot = 1 if origin_rot else 0
        for j in range(3):
            self.pfl[j] = p_flange[j]
            self.a6f[j] = a6f[j]
            for k in range(3):
                self.rfl[3 * j + k] = R_flange[j][k]
        self.a1s = a1_sign

    # ------------------------------------------------------------------ the chain
    def _rot(self, x, y, z, ang):
        """U := the rotation by `ang` (rad) about the unit axis (x, y, z): Rodrigues' formula. At
        ``ang == 0`` (a chain's A4 always, most of its A5 and A6) libm's values without the call:
        cos(+-0) is 1.0 and sin(+-0) is +-0, the argument itself (IEEE 754; bit for bit)."""
        if ang == 0.0:
            c = 1.0
            s = ang
        else:
            c = cos(ang)  # noqa: F405
            s = sin(ang)  # noqa: F405
        C = 1.0 - c
        self.U[0], self.U[1], self.U[2] = c + x * x * C, x * y * C - z * s, x * z * C + y * s
        self.U[3], self.U[4], self.U[5] = y * x * C + z * s, c + y * y * C, y * z * C - x * s
        self.U[6], self.U[7], self.U[8] = z * x * C - y * s, z * y * C + x * s, c + z * z * C

    def _times_u(self):
        """R := R @ U, row by row (a row's three old values in locals)."""
        for a in range(3):
            r0 = self.R[3 * a]
            r1 = self.R[3 * a + 1]
            r2 = self.R[3 * a + 2]
            self.R[3 * a] = r0 * self.U[0] + r1 * self.U[3] + r2 * self.U[6]
            self.R[3 * a + 1] = r0 * self.U[1] + r1 * self.U[4] + r2 * self.U[7]
            self.R[3 * a + 2] = r0 * self.U[2] + r1 * self.U[5] + r2 * self.U[8]

    def _chain(self, need):
        """The chain at the axes ``row`` (6, deg): the A5 axis point ``P4`` and direction ``D4``,
        the A6 axis direction ``D5`` (all in ``$ROBROOT``), with `need` 1 the flange's position
        ``FP`` (mm) too, with 2 also its rotation ``FR`` (0: neither, nor A6's turn; each caller
        asks what it reads). The chain up to A5 (``R``, ``p`` after A1..A4) is kept with the axes
        it was made of (``pre_row``): where A1..A4 are those, bit for bit (the same value and
        sign; a NaN never), it starts from the kept one (the same operations, the same numbers:
        the wrist's three chains of one arm differ in A5 and A6 only)."""
        start = 0
        if self.pre_has:
            start = 4
            for i in range(4):
                if self.row[i] != self.pre_row[i] or copysign(1.0, self.row[i]) != copysign(1.0, self.pre_row[i]):  # noqa: F405
                    start = 0
        if start:
            for a in range(9):
                self.R[a] = self.pre_R[a]
            for a in range(3):
                self.p[a] = self.pre_p[a]
        else:
            for a in range(9):
                self.R[a] = 0.0
            self.R[0] = self.R[4] = self.R[8] = 1.0
            self.p[0] = self.p[1] = self.p[2] = 0.0
        for i in range(start, 6):
            if i == 4 and not start:
                for a in range(9):
                    self.pre_R[a] = self.R[a]
                for a in range(3):
                    self.pre_p[a] = self.p[a]
                for a in range(4):
                    self.pre_row[a] = self.row[a]
                self.pre_has = 1
            for a in range(3):
                self.p[a] += (self.R[3 * a] * self.orig[3 * i] + self.R[3 * a + 1] * self.orig[3 * i + 1]
                              + self.R[3 * a + 2] * self.orig[3 * i + 2])
            if self.origin_rot:
                for a in range(9):
                    self.U[a] = self.rorig[9 * i + a]
                self._times_u()
            if i >= 4:
                for a in range(3):
                    d = (self.R[3 * a] * self.axis[3 * i] + self.R[3 * a + 1] * self.axis[3 * i + 1]
                         + self.R[3 * a + 2] * self.axis[3 * i + 2])
                    if i == 4:
                        self.P4[a] = self.p[a]
                        self.D4[a] = d
                    else:
                        self.D5[a] = d
                if i == 5 and need == 0:
                    return
            self._rot(self.axis[3 * i], self.axis[3 * i + 1], self.axis[3 * i + 2],
                      self.sign[i] * (self.row[i] * DEG_TO_RAD))
            self._times_u()
        for a in range(3):
            if need == 2:
                for b in range(3):
                    self.FR[3 * a + b] = (self.R[3 * a] * self.rfl[b] + self.R[3 * a + 1] * self.rfl[3 + b]
                                          + self.R[3 * a + 2] * self.rfl[6 + b])
            self.FP[a] = (self.p[a] + self.R[3 * a] * self.pfl[0] + self.R[3 * a + 1] * self.pfl[1]
                          + self.R[3 * a + 2] * self.pfl[2])

    def _plane(self):
        """The plane's normal ``N`` (``D4`` made unit) and the target's A6 axis ``AD`` projected
        into the plane, made unit, into ``AP``: 1, or 0 when the projection is shorter than
        PLANE_EPS (the A6 axis along the normal)."""
        d = sqrt(self.D4[0] * self.D4[0] + self.D4[1] * self.D4[1] + self.D4[2] * self.D4[2])  # noqa: F405
        for a in range(3):
            self.N[a] = self.D4[a] / d
        t = self.AD[0] * self.N[0] + self.AD[1] * self.N[1] + self.AD[2] * self.N[2]
        for a in range(3):
            self.AP[a] = self.AD[a] - t * self.N[a]
        d = sqrt(self.AP[0] * self.AP[0] + self.AP[1] * self.AP[1] + self.AP[2] * self.AP[2])  # noqa: F405
        if d < PLANE_EPS:
            return 0
        for a in range(3):
            self.AP[a] = self.AP[a] / d
        return 1

    def _pitch(self):
        """The angle (rad) about ``N`` that turns the A6 axis ``D5`` onto ``AP``."""
        cx = self.D5[1] * self.AP[2] - self.D5[2] * self.AP[1]
        cy = self.D5[2] * self.AP[0] - self.D5[0] * self.AP[2]
        cz = self.D5[0] * self.AP[1] - self.D5[1] * self.AP[0]
        return atan2(self.N[0] * cx + self.N[1] * cy + self.N[2] * cz,  # noqa: F405
                     self.D5[0] * self.AP[0] + self.D5[1] * self.AP[1] + self.D5[2] * self.AP[2])

    # ------------------------------------------------------------------ the rows
    def rows(self, T, ref6):
        """The rows (lists of 6 floats, deg, wrapped to (-180, 180]) of the flange pose T (4 x 4,
        mm); `ref6` the reference axes (6, deg; the OPW arm's free A1 on the A1 axis) or None."""
        opw = self.opw
        has_ref = 0
        if ref6 is not None:
            for i in range(6):
                opw.ref[i] = ref6[i]
            has_ref = 1
        for i in range(3):
            for k in range(3):
                self.RT[3 * i + k] = T[i, k]
            self.tp[i] = T[i, 3]
        self.last_has = -1              # ``found`` no longer holds the rows of the last fill
        n = self._found(has_ref)
        out = []
        for k in range(n):
            out.append([self.found[6 * k + i] for i in range(6)])
        return out

    def fill(self, core, has_ref):
        """The rows of `core`'s pose (its register ``M``, 3 x 4) for its reference ``ref`` (where
        `has_ref`) into its register ``sol``, as :meth:`rows` gives them: their number, 0 for more
        than 8 (the register's rows; fastpath.py ``OPWCore.use_rows``: the Python code decides)."""
        if not self._same(core, has_ref):
            opw = self.opw
            if has_ref:
                for i in range(6):
                    opw.ref[i] = core.ref[i]
            for i in range(3):
                for k in range(3):
                    self.RT[3 * i + k] = core.M[4 * i + k]
                self.tp[i] = core.M[4 * i + 3]
            self.last_n = self._found(has_ref)
        n = self.last_n
        if n > 8:
            return -1
        for k in range(6 * n):
            core.sol[k] = self.found[k]
        return n

    def _same(self, core, has_ref):
        """Whether `core`'s pose (and its reference, where `has_ref`) are those of the last
        :meth:`fill`, bit for bit (the same value and sign; a NaN is never the same): its rows in
        ``found`` are theirs then (a program's status/turn search asks one pose with each S and T,
        issue 86). Keeps them for the next call otherwise."""
        same = 1 if has_ref == self.last_has else 0
        for i in range(18):
            if i < 12:
                a = core.M[i]
            elif has_ref:
                a = core.ref[i - 12]
            else:
                a = 0.0
            b = self.last[i]
            if a != b or copysign(1.0, a) != copysign(1.0, b):  # noqa: F405
                same = 0
                self.last[i] = a
        self.last_has = has_ref
        return same

    def _found(self, has_ref):
        """The rows of the target ``RT``, ``tp`` (the OPW arm's reference loaded where `has_ref`)
        into ``found`` (rows of 6): their number."""
        opw = self.opw
        for i in range(3):
            self.AD[i] = self.RT[3 * i] * self.a6f[0] + self.RT[3 * i + 1] * self.a6f[1] + self.RT[3 * i + 2] * self.a6f[2]
        phi = atan2(self.tp[1], self.tp[0])  # noqa: F405
        nout = 0
        for j in range(2):
            arm = phi if j == 0 else phi + PI
            self.row[0] = (arm * RAD_TO_DEG) * self.a1s
            for i in range(1, 6):
                self.row[i] = 0.0
            self._chain(1)
            if not self._plane():
                continue
            # the A5 point: the target's position less the flange's offset from it turned by the pitch
            self._rot(self.N[0], self.N[1], self.N[2], self._pitch())
            v0 = self.FP[0] - self.P4[0]
            v1 = self.FP[1] - self.P4[1]
            v2 = self.FP[2] - self.P4[2]
            for i in range(3):
                opw.M[4 * i] = 0.0
                opw.M[4 * i + 1] = 0.0
                opw.M[4 * i + 2] = 0.0
                opw.M[4 * i + i] = 1.0
                opw.M[4 * i + 3] = self.tp[i] - (self.U[3 * i] * v0 + self.U[3 * i + 1] * v1 + self.U[3 * i + 2] * v2)
            n = opw.arm_rows(has_ref)     # the arms alone: their wrists are solved below
            for k in range(6 * n):
                self.sols[k] = opw.sol[k]
            narms = 0
            for k in range(n):
                if self._known(k, narms):
                    continue
                for i in range(3):
                    self.arms[3 * narms + i] = self.sols[6 * k + i]
                narms += 1
                if self._wrist(k):
                    for i in range(6):
                        self.found[6 * nout + i] = self.row[i]
                    nout += 1
        return nout

    def _known(self, k, narms):
        """Whether the arm (A1..A3) of the k-th OPW row is one of the first `narms` of ``arms``."""
        for m in range(narms):
            same = 1
            for i in range(3):
                if fabs(self.sols[6 * k + i] - self.arms[3 * m + i]) > ARM_EPS:  # noqa: F405
                    same = 0
            if same:
                return 1
        return 0

    def _wrist(self, k):
        """The row (into ``row``) of the k-th OPW row's arm for the target ``RT``, ``tp`` and its A6
        axis ``AD`` (module docstring, step 3): 1 when it is kept, else 0."""
        for i in range(3):
            self.row[i] = self.sols[6 * k + i]
        self.row[3] = self.row[4] = self.row[5] = 0.0
        self._chain(0)
        if not self._plane():
            return 0
        self.row[4] = self._pitch() * RAD_TO_DEG
        self._chain(2)
        # the target turned (least) so that its A6 axis lies in the plane: RC = Rot(c / s, angle) @ RT
        cx = self.AD[1] * self.AP[2] - self.AD[2] * self.AP[1]
        cy = self.AD[2] * self.AP[0] - self.AD[0] * self.AP[2]
        cz = self.AD[0] * self.AP[1] - self.AD[1] * self.AP[0]
        s = sqrt(cx * cx + cy * cy + cz * cz)  # noqa: F405
        if s < 1e-15:
            for a in range(9):
                self.RC[a] = self.RT[a]
        else:
            self._rot(cx / s, cy / s, cz / s,
                      atan2(s, self.AD[0] * self.AP[0] + self.AD[1] * self.AP[1] + self.AD[2] * self.AP[2]))  # noqa: F405
            for a in range(3):
                for b in range(3):
                    self.RC[3 * a + b] = (self.U[3 * a] * self.RT[b] + self.U[3 * a + 1] * self.RT[3 + b]
                                          + self.U[3 * a + 2] * self.RT[6 + b])
        # rel = RC @ FR.T = Rot(d6, A6): its angle about d6, sin from the skew part, cos from the trace
        for a in range(3):
            for b in range(3):
                self.T[3 * a + b] = (self.RC[3 * a] * self.FR[3 * b] + self.RC[3 * a + 1] * self.FR[3 * b + 1]
                                     + self.RC[3 * a + 2] * self.FR[3 * b + 2])
        d = sqrt(self.D5[0] * self.D5[0] + self.D5[1] * self.D5[1] + self.D5[2] * self.D5[2])  # noqa: F405
        sin_t = 0.5 * ((self.D5[0] / d) * (self.T[7] - self.T[5]) + (self.D5[1] / d) * (self.T[2] - self.T[6])
                       + (self.D5[2] / d) * (self.T[3] - self.T[1]))
        self.row[5] = atan2(sin_t, 0.5 * ((self.T[0] + self.T[4] + self.T[8]) - 1.0)) * RAD_TO_DEG  # noqa: F405
        for i in range(6):
            self.row[i] = _wrap(self.row[i])
        self._chain(1)
        err = 0.0
        for i in range(3):
            e = fabs(self.FP[i] - self.tp[i])  # noqa: F405
            if e > err or e != e:
                err = e
        return 1 if err <= KEEP_MM else 0
