"""A benchmark's child process that runs another checkout (``krl bench vm --baseline``, ``python -m
robot.bench --against``) imports only that checkout's files (krl/cbuild.py
``OTHER_CHECKOUT_PRELUDE``): this checkout's editable install maps each module to this checkout,
and a compiled extension the other checkout has not built came from here ("fastpath.Chooser size
changed" in ``krl bench vm --baseline 5c0322b``)."""

from __future__ import annotations

import os
import subprocess
import sys

from krl.cbuild import OTHER_CHECKOUT_PRELUDE

PROBE = ("import importlib.util, robot; "
         "print(robot.__path__[0]); print(importlib.util.find_spec('robot.bench'))")


def _child(checkout, prelude: str) -> list[str]:
    env = dict(os.environ, PYTHONPATH=str(checkout))
    out = subprocess.run([sys.executable, "-c", prelude + PROBE], cwd=checkout, env=env,
                         capture_output=True, text=True, check=True, timeout=120)
    return out.stdout.splitlines()


def test_a_module_the_other_checkout_lacks_is_not_taken_from_this_one(tmp_path):
    (tmp_path / "robot").mkdir()
    (tmp_path / "robot" / "__init__.py").write_text("", encoding="utf-8")
    package, spec = _child(tmp_path, OTHER_CHECKOUT_PRELUDE)
    assert package == str(tmp_path / "robot")
    assert spec == "None"


def test_the_editable_install_would_supply_it_without_the_prelude(tmp_path):
    """What the prelude guards against, on this machine's install: without it, the other
    checkout's package resolves a module it lacks to this checkout's file (an editable install,
    as ``make`` makes it; a wheel install has no such finder and the test says so)."""
    editable = [p for p in sys.path if "__editable__" in p] or \
        [f for f in sys.meta_path if "__editable__" in repr(f)]
    (tmp_path / "robot").mkdir()
    (tmp_path / "robot" / "__init__.py").write_text("", encoding="utf-8")
    package, spec = _child(tmp_path, "")
    assert package == str(tmp_path / "robot")
    if editable:
        assert "robot/bench.py" in spec
    else:
        assert spec == "None"
