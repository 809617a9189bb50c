"""Build the compiled dispatch loop: interp/vm/loop.py compiled by Cython, with the C types of
interp/vm/loop.pxd, into an extension module beside it (``loop.*.so``; gitignored). `make`
runs ``python -m interp.vm.build`` before the tests.

The pure-Python loop.py stays the tested fallback: without Cython or a C compiler this says
so and exits 0, and vm.py imports loop.py. vm.py runs the extension only when its
``VM_SOURCE`` is the sha256 of the current vm.py (a stale build is never run); the build is
skipped when the extension is newer than loop.py and loop.pxd.
"""

from __future__ import annotations

import os
import sys
import sysconfig
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
SOURCES = (HERE / "loop.py", HERE / "loop.pxd")


def target() -> Path:
    """The extension module's path for this interpreter."""
    return HERE / ("loop" + sysconfig.get_config_var("EXT_SUFFIX"))


def build(force: bool = False) -> str:
    """Compile loop.py; the outcome in words. Raises nothing for a missing Cython or
    compiler (the pure-Python loop runs then)."""
    out = target()
    if not force and out.exists() and all(out.stat().st_mtime >= s.stat().st_mtime for s in SOURCES):
        return f"{out.name} is up to date"
    try:
        from Cython.Build import cythonize  # noqa: PLC0415
        from setuptools import Distribution, Extension  # noqa: PLC0415
        from setuptools.command.build_ext import build_ext  # noqa: PLC0415
    except ImportError as e:
        return f"not compiled ({e.name} is not installed): the VM runs the pure-Python loop.py"
    tmp = REPO / "build" / "cython"
    ext = Extension("interp.vm.loop", [str(HERE / "loop.py")], extra_compile_args=["-O2"])
    try:
        exts = cythonize([ext], build_dir=str(tmp), quiet=True, force=True,
                         compiler_directives={"language_level": 3})
        dist = Distribution({"name": "krl-vm-loop", "ext_modules": exts})
        cmd = build_ext(dist)
        cmd.build_lib = str(tmp / "lib")
        cmd.build_temp = str(tmp / "temp")
        cmd.ensure_finalized()
        cmd.run()
    except Exception as e:  # noqa: BLE001  (no compiler, no Python headers: the fallback runs)
        return f"not compiled ({type(e).__name__}: {e}): the VM runs the pure-Python loop.py"
    # a rename, not a copy over the old file: a process that has the old one loaded keeps it
    os.replace(tmp / "lib" / "interp" / "vm" / out.name, out)
    return f"compiled {out.relative_to(REPO)}"


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    print(build(force="--force" in argv))
    return 0


if __name__ == "__main__":
    sys.exit(main())
