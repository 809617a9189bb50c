"""Build the compiled hot path of the simulator (issue 39, "Simulator"; issue 47; issue 76 item 5),
Cython extensions, each beside its source (``*.so``; gitignored):

* ``robot.kinematics.fastpath``: robot/kinematics/fastpath.py itself, compiled with the C types of
  fastpath.pxd beside it (the kinematics' one source: the OPW form, its status and the choice
  among solutions; the file runs as Python without a compiler);
* :data:`PURE`: the other pure-Python-mode modules of the IPO cycle, each its .py compiled with
  the C types of the .pxd beside it, carrying the sha256 of the two (``built_from()``:
  robot/kinematics/compiled.py ``pure_module`` uses a build only when it is the current files');
  robot/ipocycle.py calls numpy's BLAS and MuJoCo through their C addresses where compiled (the
  function pointer types of robot/simcore/capi.pxd);
* :data:`SIMCORE`: the Cython modules of robot/simcore/, one job each, what needs C's access to
  numpy's BLAS functions (``CartPath``, ``plan_line``; they call fastpath's and lawtable's C
  functions). Each carries
  the sha256 of the sources it was built from (:func:`simcore_sha`, ``SOURCE_SHA``):
  robot/kinematics uses them only when every one is the current files' (no version number kept
  by hand).

One definition (:func:`extensions`), two ways in, as for the VM loop (interp/vm/build.py), both
through krl/cbuild.py:

* the package build: ``setup.py`` loads this file by path and gives :func:`extensions`, translated
  by Cython, to setuptools, so ``pip install``, ``pip install -e`` (which ``make`` runs) and the
  wheel carry them;
* ``python -m robot.build`` (``make vm-loop``): rebuilds them in place after a source changed.

Without Cython or a C compiler the build says so and succeeds; the pure-Python code runs then
(fastpath.py as it stands, robot/kinematics' numpy code for the rest). ``-ffp-contract=off``: no
fused multiply-add, so C gives the products and sums Python gives.
"""

from __future__ import annotations

import hashlib
import sys
import sysconfig
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
SIMCORE_DIR = HERE / "simcore"
#: the Cython modules of robot/simcore/: module name -> its .pyx (cartpath first: lineplan cimports it)
SIMCORE = {f"robot.simcore.{name}": SIMCORE_DIR / f"{name}.pyx"
           for name in ("cartpath", "lineplan")}
#: the C declarations they share
SIMCORE_CAPI = SIMCORE_DIR / "capi.pxd"
FASTPATH = HERE / "kinematics" / "fastpath.py"
FASTPATH_PXD = HERE / "kinematics" / "fastpath.pxd"
FASTPATH_MODULE = "robot.kinematics.fastpath"
#: the pure-Python-mode modules beside fastpath: module name -> its .py (the .pxd beside it);
#: one source each, compiled here and run as Python without a compiler
PURE = {"robot.steplimit": HERE / "steplimit.py", "robot.lawtable": HERE / "lawtable.py",
        "robot.kinematics.pal4rows": HERE / "kinematics" / "pal4rows.py", "robot.poseline": HERE / "poseline.py",
        "robot.ipocycle": HERE / "ipocycle.py"}
#: C flags: optimised, and no contraction of a * b + c into one rounding (bit-identical results);
#: no debug information (as interp/vm/build.py's CFLAGS: a fifth of the compile)
CFLAGS = ["-O2", "-g0", "-ffp-contract=off", "-fno-fast-math"]


def simcore_sources(pyx: Path) -> list[Path]:
    """The files a :data:`SIMCORE` module is built from: its .pyx, its .pxd where it has one, capi.pxd."""
    pxd = pyx.with_suffix(".pxd")
    return [pyx, *([pxd] if pxd.is_file() else []), SIMCORE_CAPI]


def simcore_sha(pyx: Path) -> str:
    """The sha256 of a :data:`SIMCORE` module's sources (:func:`simcore_sources`, in that order;
    the build embeds it as ``SOURCE_SHA``)."""
    return hashlib.sha256(b"".join(p.read_bytes() for p in simcore_sources(pyx))).hexdigest()


def pure_sha(py: Path) -> str:
    """The sha256 of a :data:`PURE` module's .py and .pxd (its build embeds it as ``PURE_SOURCE_SHA``)."""
    return hashlib.sha256(py.read_bytes() + py.with_suffix(".pxd").read_bytes()).hexdigest()


def pure_target(py: Path) -> Path:
    """The extension module's path of a :data:`PURE` module for this interpreter."""
    return py.with_name(py.stem + sysconfig.get_config_var("EXT_SUFFIX"))


def simcore_target(pyx: Path) -> Path:
    """The extension module's path of a :data:`SIMCORE` module for this interpreter."""
    return pyx.with_name(pyx.stem + sysconfig.get_config_var("EXT_SUFFIX"))


def fastpath_target() -> Path:
    """The fastpath extension module's path for this interpreter."""
    return FASTPATH.with_name("fastpath" + sysconfig.get_config_var("EXT_SUFFIX"))


def extensions(root: Path | None = None) -> list:
    """The setuptools ``Extension``s (``optional``: a failed compile leaves the pure-Python code
    in place), their sources absolute or relative to ``root``; fastpath first (the others cimport
    it), then :data:`PURE`, then :data:`SIMCORE`. Raises ImportError without setuptools."""
    from setuptools import Extension  # noqa: PLC0415  (setuptools loads only for a build)

    def rel(p: Path) -> str:
        return str(p) if root is None else p.relative_to(root).as_posix()

    return [Extension(FASTPATH_MODULE, [rel(FASTPATH)], extra_compile_args=CFLAGS, optional=True)] + [
        Extension(name, [rel(py)], extra_compile_args=CFLAGS, optional=True,
                  define_macros=[("PURE_SOURCE_SHA", f'"{pure_sha(py)}"')]) for name, py in PURE.items()] + [
        Extension(name, [rel(pyx)], extra_compile_args=CFLAGS, optional=True,
                  define_macros=[("SIMCORE_SOURCE_SHA", f'"{simcore_sha(pyx)}"')]) for name, pyx in SIMCORE.items()]


def build(force: bool = False) -> str:
    """Compile fastpath.py, the :data:`PURE` modules and the :data:`SIMCORE` modules in place; the outcome
    in words. Raises nothing for a missing Cython or compiler (the pure-Python code runs then)."""
    from krl.cbuild import build_in_place  # noqa: PLC0415  (loads only for a build; setup.py loads this file by path, where krl is not importable)

    fast, *rest = extensions()
    pure, sim = rest[:len(PURE)], rest[len(PURE):]
    out = [build_in_place(fast, fastpath_target(), (FASTPATH, FASTPATH_PXD), REPO,
                          "the kinematics run fastpath.py as Python", force)]
    for ext, py in zip(pure, PURE.values()):
        out.append(build_in_place(ext, pure_target(py), (py, py.with_suffix(".pxd"), FASTPATH_PXD, SIMCORE_CAPI), REPO,
                                  f"{py.name} runs as Python", force))
    pxds = (FASTPATH_PXD, *(py.with_suffix(".pxd") for py in PURE.values()), *SIMCORE_DIR.glob("*.pxd"))
    for ext, pyx in zip(sim, SIMCORE.values()):
        out.append(build_in_place(ext, simcore_target(pyx), (pyx, *pxds), REPO,
                                  "the simulator's pure-Python code runs", force))
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    print(build(force="--force" in argv))
    return 0


if __name__ == "__main__":
    sys.exit(main())
