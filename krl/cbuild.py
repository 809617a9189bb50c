"""The in-place build of a compiled hot path (issue 39): one Cython extension compiled into
the source tree beside its module, for ``make vm-loop`` after a source changed. Used by
interp/vm/build.py (the VM's dispatch loop) and robot/build.py (the simulator's core); the
package build (setup.py) does not come here: it hands their ``Extension`` to setuptools.

Nothing here raises for missing build tools: without Cython, setuptools or a C compiler the
outcome says so and the pure-Python module stays the one that runs.
"""

from __future__ import annotations

import os
from pathlib import Path


def build_in_place(extension, out: Path, repo: Path, name: str, fallback: str) -> str:
    """Compile ``extension`` (a setuptools ``Extension`` named ``pkg.sub.mod``) with Cython
    (``language_level`` 3) under ``repo/build/cython`` and move the module to ``out``; the
    outcome in words: ``compiled PATH``, or ``not compiled (why): `` + ``fallback``.
    ``name`` is the throwaway distribution's name."""
    try:  # optional build tools, which load only for a build
        from Cython.Build import cythonize  # noqa: PLC0415
        from setuptools import Distribution  # noqa: PLC0415
        from setuptools.command.build_ext import build_ext  # noqa: PLC0415
    except ImportError as e:
        return f"not compiled ({e.name} is not installed): {fallback}"
    tmp = repo / "build" / "cython"
    try:
        exts = cythonize([extension], build_dir=str(tmp), quiet=True, force=True,
                         compiler_directives={"language_level": 3})
        dist = Distribution({"name": name, "ext_modules": exts})
        cmd = build_ext(dist)
        cmd.build_lib = str(tmp / "lib")
        cmd.build_temp = str(tmp / "temp")
        cmd.ensure_finalized()
        cmd.run()
    except Exception as e:  # noqa: BLE001  (no compiler, no Python headers: the fallback runs)
        return f"not compiled ({type(e).__name__}: {e}): {fallback}"
    built = tmp / "lib" / Path(*extension.name.split(".")[:-1]) / out.name
    if not built.is_file():                       # optional extension: the compile failed
        return f"not compiled (the C compiler failed): {fallback}"
    # a rename, not a copy over the old file: a process that has the old one loaded keeps it
    os.replace(built, out)
    return f"compiled {out.relative_to(repo)}"
