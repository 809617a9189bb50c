# The C types of robot/kinematics/pal4rows.py for its Cython build (robot/build.py ``PURE``;
# pal4rows.py stays plain Python, the fallback without a compiler). libm's functions replace the
# names pal4rows.py takes from `math` (the same C functions); the registers are C arrays; the OPW
# core is fastpath's compiled OPWCore (its C registers M, ref, sol and its C method core).
cimport cython
from libc.math cimport sin, cos, atan2, copysign
from robot.kinematics.fastpath cimport OPWCore

cdef extern from *:
    """
    #ifndef PURE_SOURCE_SHA
    #define PURE_SOURCE_SHA ""
    #endif
    static const char* pure_source_sha(void) { return PURE_SOURCE_SHA; }
    """
    const char* pure_source_sha() noexcept

cdef double PI, DEG_TO_RAD

@cython.final
cdef class Palletizer4Rows:
    cdef OPWCore opw
    cdef double orig[18]
    cdef double axis[18]
    cdef double sign[6]
    cdef double rorig[54]
    cdef double rfl[9]
    cdef double pfl[3]
    cdef double off[3]
    cdef double R[9]
    cdef double T[9]
    cdef double J[9]
    cdef double p[3]
    cdef double row[6]
    cdef double pos[3]
    cdef double sols[48]
    cdef double tm[12]
    cdef double last[18]
    cdef int last_has
    cdef int last_n
    cdef double found[96]
    cdef int origin_rot
    cdef double rref[9]
    cdef double rz[9]

    @cython.locals(a=int, b=int, q=double, c=double, s=double, C=double, x=double, y=double, z=double)
    cdef void _turn(self, int i) noexcept

    @cython.locals(a=int, i=int)
    cdef void _flange_pos(self) noexcept

    @cython.locals(i=int)
    cpdef list flange_position(self, row)

    @cython.locals(opw=OPWCore, i=int, k=int)
    cpdef list rows(self, const double[:, :] R_v, const double[:] p, ref6)

    @cython.locals(i=int, k=int, has_ref=int)
    cpdef list pose_rows(self, const double[:, :] T, ref6)

    @cython.locals(opw=OPWCore, i=int, k=int, n=int)
    cpdef int fill(self, OPWCore core, int has_ref)

    @cython.locals(same=int, i=int, a=double, b=double)
    cdef int _same(self, OPWCore core, int has_ref) noexcept

    @cython.locals(i=int)
    cdef int _ref(self, ref6) except -1

    @cython.locals(k=int, i=int, out=list)
    cdef list _listed(self, int n)

    @cython.locals(opw=OPWCore, i=int, j=int, k=int, acc=double, psi=double, c=double, s=double)
    cdef int _pose_found(self, int has_ref) noexcept

    @cython.locals(opw=OPWCore, i=int, k=int, j=int, n=int, nout=int, phi=double, arm=double, ca=double,
                   sa=double)
    cdef int _rows_at(self, double px, double py, double pz, int has_ref) noexcept

    @cython.locals(i=int, err=double, e=double)
    cdef bint _keep(self, int k, double px, double py, double pz) noexcept
