"""The compiled extensions' optimisation level (krl/cbuild.py ``optimisation_from_environment``):
the build files' ``-O2`` unless the environment's ``CFLAGS`` names a level, which then compiles
them (tests/test_wheel.py builds its wheel at ``-O0``). Checked on the compiler's command line
as setuptools really runs it: the environment's ``CFLAGS`` come before an extension's own flags,
so the last ``-O`` is the one gcc uses."""

from __future__ import annotations

import pytest
from setuptools import Distribution, Extension
from setuptools.command.build_ext import build_ext

from interp.vm import build as vm_build
from krl.cbuild import optimisation_from_environment
from robot import build as robot_build


def _compile_commands(tmp_path, monkeypatch, cflags: str | None) -> list[list[str]]:
    """The compile commands setuptools runs for a one-function C extension carrying the
    VM loop's own flags (interp/vm/build.py CFLAGS), with the environment's CFLAGS `cflags`."""
    if cflags is None:
        monkeypatch.delenv("CFLAGS", raising=False)
    else:
        monkeypatch.setenv("CFLAGS", cflags)
    (tmp_path / "probe.c").write_text("int probe(void) { return 1; }\n")
    ext = Extension("probe", [str(tmp_path / "probe.c")], extra_compile_args=vm_build.CFLAGS)
    optimisation_from_environment([ext])
    ran: list[list[str]] = []

    class Recording(build_ext):
        def build_extensions(self):
            # setuptools runs the compiler through Compiler.call (its own distutils, 80 on),
            # earlier through Compiler.spawn; the one it has is recorded
            name = "call" if hasattr(self.compiler, "call") else "spawn"
            real = getattr(self.compiler, name)

            def record(cmd, **kw):
                ran.append(list(cmd))
                return real(cmd, **kw)

            setattr(self.compiler, name, record)
            super().build_extensions()

    cmd = Recording(Distribution({"name": "probe", "ext_modules": [ext]}))
    cmd.build_lib = str(tmp_path / "lib")
    cmd.build_temp = str(tmp_path / "temp")
    cmd.ensure_finalized()
    cmd.run()
    return [c for c in ran if "-c" in c]


def _last_level(command: list[str]) -> str:
    return [a for a in command if a.startswith("-O")][-1]


@pytest.mark.parametrize("cflags, level", [(None, "-O2"), ("-pipe", "-O2"), ("-O0", "-O0"), ("-pipe -O3", "-O3")])
def test_the_environment_names_the_level_or_the_build_files_do(tmp_path, monkeypatch, cflags, level):
    (compile_cmd,) = _compile_commands(tmp_path, monkeypatch, cflags)
    assert _last_level(compile_cmd) == level
    assert "-g0" in compile_cmd


def test_the_other_flags_stay_and_the_build_files_lists_are_not_changed():
    exts = [vm_build.extension(), *robot_build.extensions()]
    optimisation_from_environment(exts, {"CFLAGS": "-O0"})
    robot_flags = ["-g0", "-ffp-contract=off", "-fno-fast-math"]
    # the VM loop, then the robot's: fastpath, each pure-Python-mode module (PURE)
    assert [e.extra_compile_args for e in exts] == [["-g0"]] + [robot_flags] * (1 + len(robot_build.PURE))
    assert vm_build.CFLAGS[0] == robot_build.CFLAGS[0] == "-O2"
    untouched = [vm_build.extension()]
    optimisation_from_environment(untouched, {"CFLAGS": "-march=native"})
    assert untouched[0].extra_compile_args == ["-O2", "-g0"]
