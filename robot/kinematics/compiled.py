"""The switch between robot/kinematics/fastpath.py compiled and as Python, and the other
pure-Python-mode modules of the hot path (robot/build.py ``PURE``) compiled or as Python:
:func:`compiled_module` (robot/cartpath.py compiled, or None), :func:`fastpath_compiled`,
:func:`fastpath_module`, :func:`pure_module`, :func:`pure_python`, :data:`USE_COMPILED`. The family modules and the package read them here
(a module of its own, so that no family imports the package it belongs to)."""

from __future__ import annotations

import hashlib
import importlib.util
import math
import sysconfig
from pathlib import Path
from typing import Any

import numpy as np

from .. import cartpath, lawtable
from ..machine import load_machine

from . import fastpath as _fastpath  # the compiled extension when it is built, else the .py

#: The axis count of the compiled core's arm (robot/cartpath.py: six rotary axes, no external
#: axis): a segment of another model runs the Python code
COMPILED_AXES = 6
#: Use the compiled hot path (robot/kinematics/fastpath.py and robot/build.py ``PURE`` compiled) when it
#: is built; False: the Python code (the reference: the two agree bit for bit,
#: tests/robot/test_simcore.py)
USE_COMPILED = True
#: robot/kinematics/fastpath.py itself, loaded as Python (None until first needed)
_fastpath_py: Any = None
#: Whether the compiled fastpath answers as fastpath.py does (checked once: None until then)
_fastpath_agrees: bool | None = None
#: module name -> (the module compiled when current, or None; the module as Python), for
#: :func:`pure_module` (filled on first use)
_pure: dict[str, tuple[Any, Any]] = {}


def compiled_module() -> Any:
    """robot/cartpath.py compiled (``CartPath``, ``plan_line``, ``line_products``,
    ``superpose_products``) when its build is the current source's (:func:`pure_module`), the
    compiled fastpath and robot/lawtable.py (which it calls as C) are in use and
    :data:`USE_COMPILED` is on; else None (the callers run their Python code)."""
    if not USE_COMPILED or not fastpath_compiled() or pure_module(lawtable) is not lawtable:
        return None
    got = pure_module(cartpath)
    return got if got is cartpath else None


def fastpath_compiled() -> bool:
    """True when robot/kinematics/fastpath.py runs compiled: the extension is built, answers as
    the Python file does on a fixed set of poses (a stale build does not) and :data:`USE_COMPILED`
    is on."""
    global _fastpath_agrees
    if not USE_COMPILED or not getattr(_fastpath, "__file__", "").endswith(_EXT_SUFFIX):
        return False
    if _fastpath_agrees is None:
        _fastpath_agrees = _same_answers(_fastpath, _python_fastpath())
    return _fastpath_agrees


def fastpath_module() -> Any:
    """The fastpath module the kinematics use: compiled (:func:`fastpath_compiled`), else
    robot/kinematics/fastpath.py as Python."""
    return _fastpath if fastpath_compiled() else _python_fastpath()


def _python_fastpath() -> Any:
    """robot/kinematics/fastpath.py loaded as Python (the compiled module shadows it on import)."""
    global _fastpath_py
    if _fastpath_py is None:
        if not getattr(_fastpath, "__file__", "").endswith(_EXT_SUFFIX):
            _fastpath_py = _fastpath
        else:
            spec = importlib.util.spec_from_file_location(
                "robot.kinematics._fastpath_source", Path(__file__).with_name("fastpath.py"))
            _fastpath_py = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(_fastpath_py)
    return _fastpath_py


def pure_module(module: Any) -> Any:
    """The pure-Python-mode `module` (one of robot/build.py ``PURE``, imported: the compiled
    extension when it is built, else the .py) compiled when its build is the current source's (its
    ``built_from()``, the sha256 of the .py and .pxd robot/build.py embeds; a wheel ships no .pxd
    and is taken as built) and :data:`USE_COMPILED` is on; else the .py itself loaded as Python
    (the one source: the same code either way)."""
    name = module.__name__
    got = _pure.get(name)
    if got is None:
        got = _pure[name] = _pure_pair(module)
    return got[0] if USE_COMPILED and got[0] is not None else got[1]


def pure_python(module: Any) -> Any:
    """The pure-Python-mode `module`'s .py run as Python (the reference its build is compared with)."""
    pure_module(module)
    return _pure[module.__name__][1]


def rows_on(module: Any, solver: Any) -> tuple[Any, Any]:
    """``(module, core)``: the pure-Python-mode rows `module` (robot/kinematics/pal4rows.py,
    pal5rows.py) compiled on `solver`'s compiled OPW core where both are built and current, else
    the .py on the solver's OPW core as Python (robot/kinematics/opwsolver.py; the same rows)."""
    mod = pure_module(module)
    if mod is module and mod is not pure_python(module) and solver.compiled:
        return mod, solver.c
    return pure_python(module), solver.python_core()


def _pure_pair(module: Any) -> tuple[Any, Any]:
    """(`module` compiled when current else None, `module` as Python) for :func:`pure_module`."""
    if not getattr(module, "__file__", "").endswith(_EXT_SUFFIX):
        return None, module
    stem = Path(module.__file__).name[: -len(_EXT_SUFFIX)]
    py = Path(module.__file__).with_name(stem + ".py")
    pxd = py.with_suffix(".pxd")
    if not py.is_file():
        return module, module
    current = (not pxd.is_file()
               or module.built_from() == hashlib.sha256(py.read_bytes() + pxd.read_bytes()).hexdigest())
    spec = importlib.util.spec_from_file_location(module.__name__ + "_source", py)
    source = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(source)
    return (module if current else None), source


def _same_answers(compiled: Any, python: Any) -> bool:
    """True when the two fastpath modules give the same bytes on the KR 6 R900's OPW form for 32
    poses (every status, turns, a wrist singularity, a pose out of reach)."""
    o = load_machine().opw
    sgn = [float(v) for v in o.sign_corrections]
    offs = [math.radians(v) for v in o.offsets_deg]
    lo, hi = [-170.0, -190.0, -120.0, -185.0, -120.0, -350.0], [170.0, 45.0, 156.0, 185.0, 120.0, 350.0]
    ks = [-720.0, -360.0, 0.0, 360.0, 720.0]
    a, b = (m.OPWCore(o, 4.764, sgn, offs, lo, hi, ks, 0, 0) for m in (compiled, python))
    rng = np.random.default_rng(47)
    for i in range(32):
        T = np.eye(4)
        T[:3, :3] = np.linalg.qr(rng.normal(size=(3, 3)))[0] * (1.0 if i % 2 else -1.0)
        T[:3, 3] = rng.uniform(-700.0, 700.0, 3) * (2.0 if i == 5 else 1.0)
        ref = rng.uniform(-150.0, 150.0, 6)
        status, turn = (i % 8, None) if i % 3 else (None, i)
        x, y = a.inverse(T, status, turn, ref), b.inverse(T, status, turn, ref)
        if (x is None) != (y is None) or (x is not None and x.tobytes() != y.tobytes()):
            return False
        if a.rows_of(T, ref) != b.rows_of(T, ref):
            return False
    return True


_EXT_SUFFIX = sysconfig.get_config_var("EXT_SUFFIX")
