# The C types of robot/kinematics/pal5rows.py for its Cython build (robot/build.py ``PURE``;
# pal5rows.py stays plain Python, the fallback without a compiler). libm's functions replace the
# names pal5rows.py takes from `math` (the same C functions); the registers are C arrays; the OPW
# core is fastpath's compiled OPWCore (its C registers M, ref, sol and its C method core).
cimport cython
from libc.math cimport sin, cos, atan2, sqrt, fmod, fabs, copysign
from robot.kinematics.fastpath cimport OPWCore

cdef extern from *:
    """
    #ifndef PURE_SOURCE_SHA
    #define PURE_SOURCE_SHA ""
    #endif
    static const char* pure_source_sha(void) { return PURE_SOURCE_SHA; }
    """
    const char* pure_source_sha() noexcept

cdef double PI, DEG_TO_RAD, RAD_TO_DEG, PLANE_EPS, ARM_EPS, KEEP_MM

@cython.locals(x=double, mod=double)
cdef double _wrap(double v) noexcept

@cython.final
cdef class Palletizer5Rows:
    cdef OPWCore opw
    cdef double orig[18]
    cdef double axis[18]
    cdef double sign[6]
    cdef double rorig[54]
    cdef double rfl[9]
    cdef double pfl[3]
    cdef double a6f[3]
    cdef double R[9]
    cdef double T[9]
    cdef double U[9]
    cdef double p[3]
    cdef double row[6]
    cdef double P4[3]
    cdef double D4[3]
    cdef double D5[3]
    cdef double FR[9]
    cdef double FP[3]
    cdef double N[3]
    cdef double AP[3]
    cdef double AD[3]
    cdef double RT[9]
    cdef double RC[9]
    cdef double tp[3]
    cdef double sols[48]
    cdef double arms[24]
    cdef double last[18]
    cdef int last_has
    cdef int last_n
    cdef double found[48]
    cdef double pre_row[4]
    cdef double pre_R[9]
    cdef double pre_p[3]
    cdef int pre_has
    cdef int origin_rot
    cdef double a1s

    @cython.locals(c=double, s=double, C=double)
    cdef void _rot(self, double x, double y, double z, double ang) noexcept

    @cython.locals(a=int, r0=double, r1=double, r2=double)
    cdef void _times_u(self) noexcept

    @cython.locals(a=int, b=int, i=int, d=double, start=int)
    cdef void _chain(self, int need) noexcept

    @cython.locals(a=int, d=double, t=double)
    cdef int _plane(self) noexcept

    @cython.locals(cx=double, cy=double, cz=double)
    cdef double _pitch(self) noexcept

    @cython.locals(opw=OPWCore, has_ref=int, i=int, k=int, n=int, out=list)
    cpdef list rows(self, const double[:, :] T, ref6)

    @cython.locals(opw=OPWCore, i=int, k=int, n=int)
    cpdef int fill(self, OPWCore core, int has_ref)

    @cython.locals(same=int, i=int, a=double, b=double)
    cdef int _same(self, OPWCore core, int has_ref) noexcept

    @cython.locals(opw=OPWCore, i=int, k=int, j=int, n=int, narms=int, nout=int, phi=double, arm=double,
                   v0=double, v1=double, v2=double)
    cdef int _found(self, int has_ref) noexcept

    @cython.locals(m=int, i=int, same=int)
    cdef int _known(self, int k, int narms) noexcept

    @cython.locals(i=int, a=int, b=int, cx=double, cy=double, cz=double, s=double, d=double, sin_t=double,
                   err=double, e=double)
    cdef int _wrist(self, int k) noexcept
