"""The IPO cycle's axis step check (robot/monitor.py ``Monitor.check_speed``), written once in
Python and compiled by Cython from this very file (the C types in steplimit.pxd beside it;
robot/build.py ``PURE``): without a compiler it runs as it stands (robot/kinematics/compiled.py
``pure_module`` picks the one in use).

:func:`speed_ok`: True when no axis moves more than its limit in one cycle, ``abs(q[i] -
q_prev[i]) <= lim[i]`` over the shortest of the three lists (deg or mm per cycle); a NaN step
passes (a comparison with NaN is false), as in the monitor's error search. Comparisons of
differences of doubles: the same answer compiled and as Python.
"""

try:
    import cython
    COMPILED = cython.compiled
except ImportError:     # an install without Cython (a need of the build only): this file as Python
    COMPILED = False


def built_from() -> str:
    """The sha256 of steplimit.py and steplimit.pxd the compiled module was built from
    (robot/build.py embeds it); "" as Python."""
    if COMPILED:
        return pure_source_sha().decode("ascii")  # noqa: F821  (steplimit.pxd's C constant)
    return ""


def speed_ok(q, q_prev, lim):
    """True when ``abs(q[i] - q_prev[i]) <= lim[i]`` (floats) for every i below the shortest
    length of the three (module docstring)."""
    n = min(len(q), len(q_prev), len(lim))
    for i in range(n):
        a = q[i]
        b = q_prev[i]
        m = lim[i]
        if abs(a - b) > m:
            return False
    return True
