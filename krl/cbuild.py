"""The build of the compiled hot paths (issue 39): Cython extensions of the VM's dispatch loop
(interp/vm/build.py) and the simulator's core (robot/build.py), each compiled beside its
module. Each of those files defines its ``Extension``; this module holds what both builds do:

* :func:`cythonized`: the package build. ``setup.py`` loads this file and the two build files
  by path (the isolated build environment has setuptools and Cython, none of the project's
  dependencies, so this module imports nothing of the project) and gives setuptools the
  translated extensions: ``pip install``, ``pip install -e`` (which ``make`` runs) and the
  wheel all carry them;
* :func:`build_in_place`: ``make vm-loop`` (``python interp/vm/build.py``, ``python -m
  robot.build``) after a source changed;
* :data:`OTHER_CHECKOUT_PRELUDE`: what a benchmark's child process running another checkout
  (``krl bench vm --baseline``, ``python -m robot.bench --against``, the tools comparing two
  checkouts through :func:`other_checkout_command` and :func:`measured_in`) runs first.

Nothing here raises for missing build tools: without Cython, setuptools or a C compiler the
outcome says so and the pure-Python module stays the one that runs.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

#: Cython's options for every extension
DIRECTIVES = {"language_level": 3}

#: Python code a child process that runs another checkout of this repository (a baseline) runs
#: before its first import of the project, so that it imports only that checkout's files: this
#: checkout's editable install (``pip install -e``, which ``make`` runs) puts a finder on
#: ``sys.path`` that maps each module, the compiled extensions too, to this checkout, and an
#: extension the other checkout has not built would come from here (built against other
#: sources: "fastpath.Chooser size changed")
OTHER_CHECKOUT_PRELUDE = """
import sys
sys.meta_path[:] = [f for f in sys.meta_path if "__editable__" not in repr(f)]
sys.path_hooks[:] = [h for h in sys.path_hooks if "__editable__" not in repr(h)]
sys.path[:] = [p for p in sys.path if "__editable__" not in p]
sys.path_importer_cache.clear()
"""


def other_checkout_command(python: str, script: str, *args: str) -> list[str]:
    """The command line that runs `script` (a path) with `args` in a child process of `python`
    that imports only another checkout's files (:data:`OTHER_CHECKOUT_PRELUDE` first; the
    checkout itself goes in the child's ``PYTHONPATH``): ``tools/trace_identity.py``,
    ``tools/whole_run_bench.py``."""
    run = "import runpy, sys; sys.argv = sys.argv[1:]; runpy.run_path(sys.argv[0], run_name='__main__')"
    return [python, "-c", OTHER_CHECKOUT_PRELUDE + run, script, *args]


def measured_in(checkout, script: str, *args: str) -> dict:
    """The JSON object a benchmark `script` prints last on its standard output, run with `args`
    in another checkout (:func:`other_checkout_command`, this interpreter, in and with
    ``PYTHONPATH`` the checkout): the side of a tool that measures two checkouts one after the
    other (tools/basis_bench.py, tools/run_start_bench.py). Raises RuntimeError with the end of
    the child's standard error when it fails."""
    cmd = other_checkout_command(sys.executable, script, *args)
    r = subprocess.run(cmd, cwd=checkout, env=dict(os.environ, PYTHONPATH=str(checkout)),
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{checkout}: {r.stderr.strip()[-2000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def build_jobs() -> int:
    """How many extensions a package build translates and compiles at once: one per core this
    process may run on (krl.pool.default_jobs's rule, written again here: this module is loaded
    by path in the isolated build environment and imports nothing of the project)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def optimisation_from_environment(extensions: list, environ=os.environ) -> list:
    """``extensions`` (setuptools ``Extension``s), each without its own ``-O`` flags when the
    environment's ``CFLAGS`` names an optimisation level (``-O0``, ``-O3``, ``-Os``...): that
    level then compiles them. setuptools puts the environment's ``CFLAGS`` after Python's own
    flags but before an extension's ``extra_compile_args``, where the build files' ``-O2``
    (interp/vm/build.py, robot/build.py) would win; without an ``-O`` in ``CFLAGS`` (a plain
    ``pip install``) they keep it. tests/test_wheel.py builds its wheel at ``-O0``: it checks
    that the wheel carries and runs the extensions, not their speed (gcc 40 -> 4 s of CPU for
    the three, 2026-11-26). The other flags (``-g0``, robot/build.py's floating-point ones)
    stay. Returns the same list, changed in place."""
    if any(flag.startswith("-O") for flag in environ.get("CFLAGS", "").split()):
        for ext in extensions:
            ext.extra_compile_args = [a for a in ext.extra_compile_args if not a.startswith("-O")]
    return extensions


def cythonized(extensions: list, build_dir: str = "build/cython", force: bool = False, jobs: int = 1) -> list:
    """``extensions`` (setuptools ``Extension``s, ``optional``) translated to C by Cython
    (`jobs` at once), their optimisation level the environment's where it names one
    (:func:`optimisation_from_environment`), or ``[]`` without Cython: then nothing is
    compiled and the pure-Python modules run."""
    try:
        from Cython.Build import cythonize  # noqa: PLC0415  (optional; loads only for a build)
    except ImportError:
        return []
    optimisation_from_environment(extensions)
    return cythonize(extensions, build_dir=build_dir, quiet=True, force=force,
                     compiler_directives=DIRECTIVES, nthreads=jobs if len(extensions) > 1 else 0)


def build_in_place(extension, out: Path, sources, repo: Path, fallback: str, force: bool = False) -> str:
    """Compile ``extension`` (named ``pkg.sub.mod``) under ``repo/build/cython`` and move the
    module to ``out``, unless ``out`` is newer than every one of ``sources`` (``force``
    rebuilds); the outcome in words: ``NAME is up to date``, ``compiled PATH``, or
    ``not compiled (why): `` + ``fallback``."""
    if not force and out.exists() and all(out.stat().st_mtime >= Path(s).stat().st_mtime for s in sources):
        return f"{out.name} is up to date"
    try:
        # optional build tools, which load only for a build
        from Cython.Build import cythonize  # noqa: PLC0415, F401
        from setuptools import Distribution  # noqa: PLC0415
        from setuptools.command.build_ext import build_ext  # noqa: PLC0415
    except ImportError as e:
        return f"not compiled ({e.name} is not installed): {fallback}"
    tmp = repo / "build" / "cython"
    try:
        exts = cythonized([extension], build_dir=str(tmp), force=True)
        dist = Distribution({"name": extension.name.replace(".", "-"), "ext_modules": exts})
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
