"""The package build's one addition to pyproject.toml: the compiled VM loop and the simulator's
compiled inverse kinematics (Cython), so that ``pip install``, ``pip install -e`` and the wheel
all run them (issue 39). Their ``Extension``s live in interp/vm/build.py and robot/build.py, the
translation in krl/cbuild.py, all loaded here by path: the isolated build environment has
setuptools and Cython (pyproject.toml ``[build-system]``) but none of the project's own
dependencies. Without Cython or a C compiler
the extensions are skipped and the pure-Python code runs."""

import importlib.util
from pathlib import Path

from setuptools import setup

ROOT = Path(__file__).resolve().parent


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


_cbuild = _load("_krl_cbuild", ROOT / "krl" / "cbuild.py")
_vm = _load("_krl_vm_build", ROOT / "interp" / "vm" / "build.py")
_sim = _load("_krl_sim_build", ROOT / "robot" / "build.py")

# the extensions are translated and compiled side by side, one per core (a wheel's build, three:
# 50 -> 32 s wall on 2 cores, 2026-11-25)
setup(ext_modules=_cbuild.cythonized([_vm.extension(ROOT), *_sim.extensions(ROOT)], jobs=_cbuild.build_jobs()),
      options={"build_ext": {"parallel": _cbuild.build_jobs()}})
