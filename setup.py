"""The package build's one addition to pyproject.toml: the compiled VM loop (Cython), so that
``pip install``, ``pip install -e`` and the wheel all run it (issue 39). Its definition lives
in interp/vm/build.py, loaded here by path: the isolated build environment has setuptools and
Cython (pyproject.toml ``[build-system]``) but none of the project's own dependencies. Without
Cython or a C compiler the extension is skipped and the pure-Python loop.py runs."""

import importlib.util
from pathlib import Path

from setuptools import setup

ROOT = Path(__file__).resolve().parent
_spec = importlib.util.spec_from_file_location("_krl_vm_build", ROOT / "interp" / "vm" / "build.py")
_build = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_build)

setup(ext_modules=_build.cythonized(ROOT))
