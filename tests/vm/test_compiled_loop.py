"""The compiled dispatch loop (interp/vm/build.py: Cython compiles the generated loop.py with
the C types of loop.pxd; `make` builds it before the tests):

* where Cython and a C compiler are installed, the extension is built from the current
  loop.py and is the loop the VM runs (``vm.COMPILED``);
* it gives the same traces as the same loop run as plain Python and as the tree interpreter;
* an extension built from another loop.py is never run, and the build falls back cleanly
  without Cython.
"""

from __future__ import annotations

import importlib.util
import inspect
import shutil
import sys
import sysconfig
import types

import pytest

from interp.run import make_runtime, run_spec
from interp.vm import build, vm as V

from .test_generated_loop import PROGRAMS, _trace


def _can_compile() -> bool:
    # without Cython (a dev dependency) nothing is compiled and loop.py/the Python core run
    if importlib.util.find_spec("Cython") is None:
        return False
    return shutil.which(sysconfig.get_config_var("CC").split()[0]) is not None


def test_the_compiled_loop_is_built_and_runs():
    if not _can_compile():
        pytest.skip("no Cython or no C compiler: the pure-Python loop runs (make vm-loop says so)")
    assert build.target().exists(), "the compiled loop is missing: run make vm-loop"
    assert V.COMPILED, "the compiled loop is stale (built from another loop.py): run make vm-loop"
    assert not V._loop.__file__.endswith(".py")
    rt, vm = make_runtime(run_spec(PROGRAMS[-1], mujoco=False, interp="vm"))
    assert vm.loop is V._loop.run and not inspect.isfunction(vm.loop)     # compiled, not bytecode


# the benchmark program (36 s of CPU on both loops) runs in `make nightly`; the others here
@pytest.mark.parametrize("program", [pytest.param(p, marks=pytest.mark.slow) if p.stem == "bench" else p
                                     for p in PROGRAMS[1::2]], ids=lambda p: p.stem)
def test_compiled_and_python_loops_give_identical_traces(program):
    compiled = _trace(program, "vm")
    python = _trace(program, "vm", loop="python")
    assert compiled == python
    assert _trace(program, "tree")[0] == compiled[0]


def test_an_extension_of_another_vm_py_is_not_run():
    assert not V._current(types.SimpleNamespace(SOURCE="0" * 64))
    assert V._current(V._python_loop())       # the extension of this very loop.py


def test_the_build_falls_back_without_cython(monkeypatch):
    monkeypatch.setitem(sys.modules, "Cython.Build", None)
    out = build.build(force=True)
    assert out.startswith("not compiled (Cython.Build is not installed)"), out
    assert "pure-Python loop.py" in out
