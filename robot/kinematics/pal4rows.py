# cython: auto_pickle=False
"""The 4-axis palletizer's rows of a flange pose (robot/kinematics/palletizer4.py
``Palletizer4.solutions``: the vertical rotation ``R_v`` nearest the pose's and the rows for it,
:meth:`Palletizer4Rows.pose_rows`; for a known ``R_v``: ``rows``), written once in Python
and compiled by Cython from this very file (the C types in pal4rows.pxd beside it; robot/build.py
``PURE``): without a compiler it runs as it stands, on fastpath.py's ``OPWCore`` as Python
(robot/kinematics/compiled.py ``pure_module`` picks the one in use).

:class:`Palletizer4Rows`: for each arm plane (towards the flange, and behind the A1 axis) the A5
point the fixed offset back from the flange, fastpath's ``OPWCore.core`` for it (c4 = 0), A4 at 0
(within 1e-6 deg: set to 0.0; the flipped wrist, |A4| = 180, dropped), and only the rows whose
flange lies within 1e-6 mm of the target. The flange test runs a forward kinematics of its own
(Rodrigues' formula per joint, the chain of ``JointChain.forward``), which may differ from numpy's
and scipy's in the last bits: it only tells the true solutions (errors about 1e-10 mm) from the
wrong arm plane's (millimetres), never near 1e-6 (tools/palletizer_rows_check.py shows it on the
corpus). Registers are attributes (lists here, C arrays compiled), as in fastpath.py; the
compiled class is never pickled (``auto_pickle=False``: Cython's generated unpickling of a C array
attribute copied past the array's end).

:class:`Palletizer4Rows`'s ``fill`` gives the same rows to an ``OPWCore`` of the arm (fastpath.py ``use_rows``,
robot/kinematics/palcore.py): that core's inverse is the family's, rows, status and choice in one
compiled call; it keeps the rows of the last pose and reference (bit for bit the same inputs).

Units: mm and deg.
"""

from math import *  # noqa: F403  (libm's functions: compiled, pal4rows.pxd declares them as C's)

try:
    import cython
    COMPILED = cython.compiled
except ImportError:     # an install without Cython (a need of the build only): this file as Python
    COMPILED = False

PI = 3.141592653589793
DEG_TO_RAD = PI / 180.0


def built_from() -> str:
    """The sha256 of pal4rows.py and pal4rows.pxd the compiled module was built from
    (robot/build.py embeds it); "" as Python."""
    if COMPILED:
        return pure_source_sha().decode("ascii")  # noqa: F821  (pal4rows.pxd's C function)
    return ""


class Palletizer4Rows:
    """The rows of the 4-axis palletizer (module docstring) on the OPW core `opw` (fastpath's
    ``OPWCore``, compiled with this module compiled) of the joint chain: `origins` and `axes` (6 x
    3), KUKA's axis signs `sign` (6), the joints' fixed rotations `R_origin` (6 x 3 x 3, used where
    `origin_rot`), the flange's rotation `R_flange` (3 x 3) and position `p_flange` (3, mm), and the
    flange's `offset` (3, mm) from the A5 axis point at A1 = 0 (robot/kinematics/joints.py
    ``JointChain``'s attributes; palletizer4.py's ``pa``) and the flange's rotation `R_ref` (3 x 3)
    at A1 = 0 (``pa``'s second; :meth:`pose_rows`)."""

    def __init__(self, opw, origins, axes, sign, R_origin, origin_rot, R_flange, p_flange, offset, R_ref):
        self.opw = opw
        self.rref = [0.0] * 9
        self.rz = [0.0] * 9
        for j in range(3):
            for k in range(3):
                self.rref[3 * j + k] = R_ref[j][k]
        self.orig = [0.0] * 18
        self.axis = [0.0] * 18
        self.sign = [0.0] * 6
        self.rorig = [0.0] * 54
        self.rfl = [0.0] * 9
        self.pfl = [0.0] * 3
        self.off = [0.0] * 3
        self.R = [0.0] * 9
        self.T = [0.0] * 9
        self.J = [0.0] * 9
        self.p = [0.0] * 3
        self.row = [0.0] * 6
        self.pos = [0.0] * 3
        self.sols = [0.0] * 48
        self.tm = [0.0] * 12
        self.last = [0.0] * 18
        self.last_has = -1
        self.last_n = 0
        self.found = [0.0] * 96
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
            self.off[j] = offset[j]
            for k in range(3):
                self.rfl[3 * j + k] = R_flange[j][k]

    def _turn(self, i):
        """R := R @ (the joint i's fixed rotation, where the chain has them) @ (its rotation by
        row[i] about its axis, Rodrigues' formula); T and J scratch."""
        if self.origin_rot:
            for a in range(3):
                for b in range(3):
                    self.T[3 * a + b] = (self.R[3 * a] * self.rorig[9 * i + b]
                                         + self.R[3 * a + 1] * self.rorig[9 * i + 3 + b]
                                         + self.R[3 * a + 2] * self.rorig[9 * i + 6 + b])
            for a in range(9):
                self.R[a] = self.T[a]
        q = self.sign[i] * (self.row[i] * DEG_TO_RAD)
        c = cos(q)  # noqa: F405
        s = sin(q)  # noqa: F405
        C = 1.0 - c
        x = self.axis[3 * i]
        y = self.axis[3 * i + 1]
        z = self.axis[3 * i + 2]
        self.J[0], self.J[1], self.J[2] = c + x * x * C, x * y * C - z * s, x * z * C + y * s
        self.J[3], self.J[4], self.J[5] = y * x * C + z * s, c + y * y * C, y * z * C - x * s
        self.J[6], self.J[7], self.J[8] = z * x * C - y * s, z * y * C + x * s, c + z * z * C
        for a in range(3):
            for b in range(3):
                self.T[3 * a + b] = (self.R[3 * a] * self.J[b] + self.R[3 * a + 1] * self.J[3 + b]
                                     + self.R[3 * a + 2] * self.J[6 + b])
        for a in range(9):
            self.R[a] = self.T[a]

    def _flange_pos(self):
        """The flange position (mm) of the axes ``row`` (6, deg) into ``pos``."""
        for a in range(9):
            self.R[a] = 0.0
        self.R[0] = self.R[4] = self.R[8] = 1.0
        self.p[0] = self.p[1] = self.p[2] = 0.0
        for i in range(6):
            for a in range(3):
                self.p[a] += (self.R[3 * a] * self.orig[3 * i] + self.R[3 * a + 1] * self.orig[3 * i + 1]
                              + self.R[3 * a + 2] * self.orig[3 * i + 2])
            self._turn(i)
        for a in range(3):
            self.pos[a] = (self.p[a] + self.R[3 * a] * self.pfl[0] + self.R[3 * a + 1] * self.pfl[1]
                           + self.R[3 * a + 2] * self.pfl[2])

    def flange_position(self, row):
        """The flange position [x, y, z] (mm) of the axes `row` (6 floats, deg), as the flange test
        computes it."""
        for i in range(6):
            self.row[i] = row[i]
        self._flange_pos()
        return [self.pos[0], self.pos[1], self.pos[2]]

    def rows(self, R_v, p, ref6):
        """The rows (lists of 6 floats, deg) for the flange position `p` (3, mm) with the vertical
        rotation `R_v` (3 x 3); `ref6` the reference axes (6, deg) or None."""
        opw = self.opw
        for i in range(3):
            for k in range(3):
                opw.M[4 * i + k] = R_v[i, k]
        return self._listed(self._rows_at(p[0], p[1], p[2], self._ref(ref6)))

    def pose_rows(self, T, ref6):
        """:meth:`rows` of the flange pose `T` (4 x 4, mm): its position, and the vertical rotation
        nearest its rotation (palletizer4.py ``_vertical``, ``Rz(psi) @ R_ref`` with psi the turn of
        ``T[:3, :3] @ R_ref.T`` about z), both products summed as numpy's matmul sums them (from 0.0,
        k = 0, 1, 2), so the rows are those of ``rows(*_vertical(T), ref6)``."""
        for i in range(3):
            for k in range(4):
                self.tm[4 * i + k] = T[i, k]
        has_ref = self._ref(ref6)
        return self._listed(self._pose_found(has_ref))

    def fill(self, core, has_ref):
        """The rows of `core`'s pose (its register ``M``, 3 x 4) for its reference ``ref`` (where
        `has_ref`) into its register ``sol``, as :meth:`pose_rows` gives them: their number, 0 for
        more than 8 (the register's rows; fastpath.py ``OPWCore.use_rows``: the Python code decides)."""
        if not self._same(core, has_ref):
            opw = self.opw
            for i in range(12):
                self.tm[i] = core.M[i]
            if has_ref:
                for i in range(6):
                    opw.ref[i] = core.ref[i]
            self.last_n = self._pose_found(has_ref)
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

    def _ref(self, ref6):
        """`ref6` (6 floats, or None) into the OPW core's reference: 1, or 0 for None."""
        if ref6 is None:
            return 0
        for i in range(6):
            self.opw.ref[i] = ref6[i]
        return 1

    def _listed(self, n):
        """The first `n` rows of ``found`` as lists of 6 floats (:meth:`rows`, :meth:`pose_rows`:
        ``found`` no longer holds the rows of the last :meth:`fill`)."""
        self.last_has = -1
        out = []
        for k in range(n):
            out.append([self.found[6 * k + i] for i in range(6)])
        return out

    def _pose_found(self, has_ref):
        """:meth:`pose_rows` of the pose in ``tm`` (3 x 4) into ``found``: the number of rows."""
        rr = self.rref
        rz = self.rz
        opw = self.opw
        for i in range(2):
            for j in range(2):
                acc = 0.0
                for k in range(3):
                    acc += self.tm[4 * i + k] * rr[3 * j + k]
                rz[3 * i + j] = acc
        psi = atan2(rz[3] - rz[1], rz[0] + rz[4])  # noqa: F405
        c = cos(psi)  # noqa: F405
        s = sin(psi)  # noqa: F405
        rz[0] = c
        rz[1] = -s
        rz[2] = 0.0
        rz[3] = s
        rz[4] = c
        rz[5] = 0.0
        rz[6] = 0.0
        rz[7] = 0.0
        rz[8] = 1.0
        for i in range(3):
            for j in range(3):
                acc = 0.0
                for k in range(3):
                    acc += rz[3 * i + k] * rr[3 * k + j]
                opw.M[4 * i + j] = acc
        return self._rows_at(self.tm[3], self.tm[7], self.tm[11], has_ref)

    def _rows_at(self, px, py, pz, has_ref):
        """The rows for the flange position (px, py, pz) (mm), the vertical rotation in the OPW
        core's registers ``M`` already (its reference ``ref`` where `has_ref`), into ``found`` (rows
        of 6): their number."""
        opw = self.opw
        phi = atan2(py, px)  # noqa: F405
        nout = 0
        for j in range(2):
            arm = phi if j == 0 else phi + PI
            ca = cos(arm)  # noqa: F405
            sa = sin(arm)  # noqa: F405
            # w = p - [ca * o0 - sa * o1, sa * o0 + ca * o1, o2]
            opw.M[3] = px - (ca * self.off[0] - sa * self.off[1])
            opw.M[7] = py - (sa * self.off[0] + ca * self.off[1])
            opw.M[11] = pz - self.off[2]
            n = opw.core(has_ref)
            for k in range(6 * n):
                self.sols[k] = opw.sol[k]
            for k in range(n):
                if self._keep(k, px, py, pz):
                    for i in range(6):
                        self.found[6 * nout + i] = self.row[i]
                    nout += 1
        return nout

    def _keep(self, k, px, py, pz):
        """Whether the k-th solution (into ``row``, A4 within 1e-6 deg of 0 set to 0.0) is kept: not
        the flipped wrist, its flange within 1e-6 mm of (px, py, pz) (a NaN fails, as numpy's max
        gives it)."""
        for i in range(6):
            self.row[i] = self.sols[6 * k + i]
        if abs(self.row[3]) < 1e-6:
            self.row[3] = 0.0
        elif abs(abs(self.row[3]) - 180.0) < 1e-6:
            return False
        self._flange_pos()
        err = 0.0
        for i in range(3):
            e = abs(self.pos[i] - (px if i == 0 else py if i == 1 else pz))
            if e > err or e != e:
                err = e
        return err < 1e-6
