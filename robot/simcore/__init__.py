"""The simulator's compiled hot path that is not kinematics of its own (issue 39, "Simulator";
issue 47; issue 76 item 5): Cython modules built by robot/build.py (``SIMCORE``), one job each,
for what calls numpy's BLAS and MuJoCo through their C addresses. The kinematics' hot path is
robot/kinematics/fastpath.py and the other pure-Python-mode modules (robot/build.py ``PURE``),
compiled from their Python files; these modules call their C functions.

* robot/simcore/cartpath.pyx: :class:`CartPath` (a CP segment's poses, axes, planning walk,
  distance to the end, a Cartesian blend's setpoint);
* robot/simcore/lineplan.pyx: :func:`plan_line`, :func:`line_products` (a single LIN's plan);
* robot/simcore/capi.pxd: the C declarations they share.

Each gives the numbers of the Python code it stands for bit for bit; that code stays the fallback
and the reference (tests/robot/test_simcore.py). Importing this package raises ImportError when
a module is not built (robot/kinematics/compiled.py ``compiled_module`` then gives None and the
Python code runs). :data:`SOURCE_SHA`: module name -> the sha256 of the sources it was built from
(robot/build.py ``simcore_sha``): robot/kinematics/compiled.py uses the modules only when every
one is the current files'.
"""

from . import cartpath, lineplan
from .cartpath import CartPath
from .lineplan import line_products, plan_line

#: module name -> the sha256 of the sources it was built from (robot/build.py ``simcore_sha``)
SOURCE_SHA = {m.__name__: m.SOURCE_SHA for m in (cartpath, lineplan)}

__all__ = ["SOURCE_SHA", "CartPath", "line_products", "plan_line"]
