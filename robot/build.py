"""Build the compiled hot path of the simulator (issue 39, "Simulator"; issue 47; issue 76 item 5),
Cython extensions, each beside its source (``*.so``; gitignored):

* ``robot.kinematics.fastpath``: robot/kinematics/fastpath.py itself, compiled with the C types of
  fastpath.pxd beside it (the kinematics' one source: the OPW form, its status and the choice
  among solutions; the file runs as Python without a compiler);
* :data:`PURE`: the other pure-Python-mode modules of the hot path (the IPO cycle's kinematics,
  the CP paths and a single LIN's plan among them), each its .py compiled with the C types of the
  .pxd beside it, carrying the sha256 of the two (``built_from()``: robot/kinematics/compiled.py
  ``pure_module`` uses a build only when it is the current files'); robot/ipocycle.py and
  robot/cartpath.py call numpy's BLAS and MuJoCo through their C addresses where compiled (the
  function pointer types of robot/capi.pxd).

One definition (:func:`extensions`), two ways in, as for the VM loop (interp/vm/build.py), both
through krl/cbuild.py:

* the package build: ``setup.py`` loads this file by path and gives :func:`extensions`, translated
  by Cython, to setuptools, so ``pip install``, ``pip install -e`` (which ``make`` runs) and the
  wheel carry them;
* ``python -m robot.build`` (``make vm-loop``): rebuilds them in place after a source changed.

Without Cython or a C compiler the build says so and succeeds; the pure-Python code runs then
(fastpath.py and the PURE modules as they stand; where robot/kinematics/compiled.py
``compiled_module`` gives None, the callers' own Python code in place of robot/cartpath.py's).
``-ffp-contract=off``: no fused multiply-add, so C gives the products and sums Python gives.
"""

from __future__ import annotations

import hashlib
import sys
import sysconfig
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
#: the C declarations the PURE modules share (numpy's BLAS and MuJoCo as C function pointer types)
CAPI = HERE / "capi.pxd"
FASTPATH = HERE / "kinematics" / "fastpath.py"
FASTPATH_PXD = HERE / "kinematics" / "fastpath.pxd"
FASTPATH_MODULE = "robot.kinematics.fastpath"
#: the pure-Python-mode modules beside fastpath: module name -> its .py (the .pxd beside it);
#: one source each, compiled here and run as Python without a compiler
PURE = {"robot.steplimit": HERE / "steplimit.py", "robot.lawtable": HERE / "lawtable.py",
        "robot.kinematics.pal4rows": HERE / "kinematics" / "pal4rows.py",
        "robot.kinematics.pal5rows": HERE / "kinematics" / "pal5rows.py",
        "robot.kinematics.scararows": HERE / "kinematics" / "scararows.py", "robot.poseline": HERE / "poseline.py",
        "robot.ipocycle": HERE / "ipocycle.py", "robot.cartpath": HERE / "cartpath.py",
        "robot.cellproof": HERE / "cellproof.py"}
#: C flags: optimised, and no contraction of a * b + c into one rounding (bit-identical results);
#: no debug information (as interp/vm/build.py's CFLAGS: a fifth of the compile)
CFLAGS = ["-O2", "-g0", "-ffp-contract=off", "-fno-fast-math"]


def pure_sources(py: Path) -> tuple[Path, ...]:
    """The files a :data:`PURE` module's build reads: its .py and .pxd, fastpath.pxd, capi.pxd and
    the .pxd of each other PURE module its .pxd cimports (``from robot cimport lawtable``)."""
    pxd = py.with_suffix(".pxd")
    text = pxd.read_text(encoding="utf-8")
    others = tuple(p.with_suffix(".pxd") for n, p in PURE.items()
                   if p != py and (f"cimport {n.rsplit('.', 1)[1]}" in text or f"{n} cimport" in text))
    return (py, pxd, FASTPATH_PXD, CAPI, *others)


def pure_sha(py: Path) -> str:
    """The sha256 of a :data:`PURE` module's .py and .pxd (its build embeds it as ``PURE_SOURCE_SHA``)."""
    return hashlib.sha256(py.read_bytes() + py.with_suffix(".pxd").read_bytes()).hexdigest()


def pure_target(py: Path) -> Path:
    """The extension module's path of a :data:`PURE` module for this interpreter."""
    return py.with_name(py.stem + sysconfig.get_config_var("EXT_SUFFIX"))


def fastpath_target() -> Path:
    """The fastpath extension module's path for this interpreter."""
    return FASTPATH.with_name("fastpath" + sysconfig.get_config_var("EXT_SUFFIX"))


def extensions(root: Path | None = None) -> list:
    """The setuptools ``Extension``s (``optional``: a failed compile leaves the pure-Python code
    in place), their sources absolute or relative to ``root``; fastpath first (the others cimport
    it), then :data:`PURE`. Raises ImportError without setuptools."""
    from setuptools import Extension  # noqa: PLC0415  (setuptools loads only for a build)

    def rel(p: Path) -> str:
        return str(p) if root is None else p.relative_to(root).as_posix()

    return [Extension(FASTPATH_MODULE, [rel(FASTPATH)], extra_compile_args=CFLAGS, optional=True)] + [
        Extension(name, [rel(py)], extra_compile_args=CFLAGS, optional=True,
                  define_macros=[("PURE_SOURCE_SHA", f'"{pure_sha(py)}"')]) for name, py in PURE.items()]


def build(force: bool = False) -> str:
    """Compile fastpath.py and the :data:`PURE` modules in place; the outcome in words. Raises
    nothing for a missing Cython or compiler (the pure-Python code runs then)."""
    from krl.cbuild import build_in_place  # noqa: PLC0415  (loads only for a build; setup.py loads this file by path, where krl is not importable)

    fast, *pure = extensions()
    out = [build_in_place(fast, fastpath_target(), (FASTPATH, FASTPATH_PXD), REPO,
                          "the kinematics run fastpath.py as Python", force)]
    for ext, py in zip(pure, PURE.values()):
        out.append(build_in_place(ext, pure_target(py), pure_sources(py), REPO, f"{py.name} runs as Python", force))
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    print(build(force="--force" in argv))
    return 0


if __name__ == "__main__":
    sys.exit(main())
