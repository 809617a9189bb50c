"""Build the compiled hot path of the simulator: robot/simcore.pyx compiled by Cython
into an extension module beside it (``simcore.*.so``; gitignored). Issue 39, "Simulator".

One definition (:func:`extension`), two ways in, as for the VM loop (interp/vm/build.py), both
through krl/cbuild.py:

* the package build: ``setup.py`` loads this file by path and gives :func:`extension`, translated
  by Cython, to setuptools, so ``pip install``, ``pip install -e`` (which ``make`` runs) and the
  wheel carry it;
* ``python -m robot.build`` (``make vm-loop``): rebuilds it in place after simcore.pyx changed.

Without Cython or a C compiler the build says so and succeeds; robot/kinematics.py then runs
its pure-Python OPW code, which the extension mirrors bit for bit (``-ffp-contract=off``: no
fused multiply-add, so C gives the products and sums Python gives).
"""

from __future__ import annotations

import sys
import sysconfig
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
SOURCE = HERE / "simcore.pyx"
MODULE = "robot.simcore"
#: C flags: optimised, and no contraction of a * b + c into one rounding (bit-identical results)
CFLAGS = ["-O2", "-ffp-contract=off", "-fno-fast-math"]


def target() -> Path:
    """The extension module's path for this interpreter."""
    return HERE / ("simcore" + sysconfig.get_config_var("EXT_SUFFIX"))


def extension(root: Path | None = None):
    """The setuptools ``Extension`` (``optional``: a failed compile leaves the pure-Python
    code in place), its source absolute or relative to ``root``. Raises ImportError without
    setuptools."""
    from setuptools import Extension  # noqa: PLC0415  (setuptools loads only for a build)

    src = str(SOURCE) if root is None else SOURCE.relative_to(root).as_posix()
    return Extension(MODULE, [src], extra_compile_args=CFLAGS, optional=True)


def build(force: bool = False) -> str:
    """Compile simcore.pyx in place; the outcome in words. Raises nothing for a missing Cython
    or compiler (the pure-Python inverse runs then)."""
    from krl.cbuild import build_in_place  # noqa: PLC0415  (loads only for a build; setup.py loads this file by path, where krl is not importable)

    return build_in_place(extension(), target(), (SOURCE,), REPO, "the pure-Python inverse kinematics runs", force)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    print(build(force="--force" in argv))
    return 0


if __name__ == "__main__":
    sys.exit(main())
