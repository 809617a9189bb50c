"""Build the compiled dispatch loop: interp/vm/loop.py compiled by Cython, with the C types of
interp/vm/loop.pxd, into an extension module beside it (``loop.*.so``; gitignored).

Two ways in, one definition (:func:`extension`), both through krl/cbuild.py:

* the package build: ``setup.py`` loads this file (by path: the build environment has none of
  the project's dependencies) and gives :func:`extension`, translated by Cython, to setuptools, so ``pip install``,
  ``pip install -e`` (which ``make`` runs) and the wheel all carry the compiled loop;
* ``python interp/vm/build.py`` (``make vm-loop``; ``python -m interp.vm.build`` too, which
  imports the package, the whole VM, first): rebuilds it in place after vm.py changed and loop.py
  was regenerated (interp/vm/gen_loop.py).

The pure-Python loop.py stays the tested fallback: without Cython or a C compiler the build
says so and succeeds, and vm.py imports loop.py. vm.py runs the extension only when its
``VM_SOURCE`` is the sha256 of the current vm.py (a stale build is never run); the in-place
build is skipped when the extension is newer than loop.py and loop.pxd.
"""

from __future__ import annotations

import sys
import sysconfig
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
SOURCES = (HERE / "loop.py", HERE / "loop.pxd")


def target() -> Path:
    """The extension module's path for this interpreter."""
    return HERE / ("loop" + sysconfig.get_config_var("EXT_SUFFIX"))


MODULE = "interp.vm.loop"


#: C flags: optimised; no debug information (Python's own flags ask for it with -g: a fifth of
#: the compile, 22.5 -> 18 s of CPU for loop.c, and 4.8 -> 0.7 MB of object code; gcc's code is
#: the same with or without it; 2026-11-25). -O2 stays although it is most of the set-up's gcc:
#: loop.c (Cython 3.3.1) takes 26.1 s of gcc CPU at -O2, 10.9 at -O1, 11.2 at -O1
#: -finline-small-functions, 19.0 at -O2 -fno-tree-pta -fno-tree-vrp, but each of those runs the
#: compute benchmark (interp/bench, four runs, valgrind's instruction count of the compiled
#: code, which the machine's load does not move) in 3.3 %, 3.2 % and 1.4 % more instructions
#: (517 M at -O2; 2026-11-29)
CFLAGS = ["-O2", "-g0"]


def extension(root: Path | None = None):
    """The setuptools ``Extension`` of the compiled loop, its source path absolute, or
    relative to ``root`` (a package build wants paths relative to the project). Cython compiles the .py
    source with the .pxd beside it; ``optional``: a failed compile leaves the pure-Python
    loop in place instead of failing the install. Raises ImportError without setuptools."""
    from setuptools import Extension  # noqa: PLC0415  (setuptools loads only for a build)

    src = HERE / "loop.py"
    src = str(src) if root is None else src.relative_to(root).as_posix()
    return Extension(MODULE, [src], extra_compile_args=CFLAGS, optional=True)


def build(force: bool = False) -> str:
    """Compile loop.py; the outcome in words. Raises nothing for a missing Cython or
    compiler (the pure-Python loop runs then)."""
    from krl.cbuild import build_in_place  # noqa: PLC0415  (loads only for a build; setup.py loads this file by path, where krl is not importable)

    return build_in_place(extension(), target(), SOURCES, REPO, "the VM runs the pure-Python loop.py", force)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    print(build(force="--force" in argv))
    return 0


if __name__ == "__main__":
    sys.exit(main())
