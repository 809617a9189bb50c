"""The tolerances every kinematic family uses (robot/kinematics/; docs/robot.md "Boundaries and
singularities"): deg for angles, mm for lengths."""

#: Values closer than this to a status/turn switching point count as "on" it (deg, mm).
BOUNDARY_EPS = 1e-9
#: |A5| (deg) below which the wrist is treated as singular (A4 + A6 only defined).
WRIST_SINGULAR_DEG = 1e-6
#: Wrist point distance from the A1 axis (mm) below which A1 is undefined.
OVERHEAD_SINGULAR_MM = 1e-6
#: Tolerance of the reachability test on the cosine-law arguments.
ACOS_TOL = 1e-9
#: Tolerance of the soft-limit test (deg), absorbs floating-point noise.
LIMIT_EPS_DEG = 1e-9

__all__ = ["ACOS_TOL", "BOUNDARY_EPS", "LIMIT_EPS_DEG", "OVERHEAD_SINGULAR_MM", "WRIST_SINGULAR_DEG"]
