"""Natives get an explicit context, not the runtime (issue 87 item 4;
interp/runtime/natives/context.py): a native implementation is called with its run's
``NativeContext``, the calls it may make, and writes no attribute through it.

Seen failing first: before the change every native took the runtime (``fn(rt, args)``: 26 of
its attributes read) and Set_KrlMsg/Set_KrlDlg wrote ``rt.msg_handle``; the scan below found
those two writes and EK's ``rt.sysvars.ek = ...``."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from interp.runtime.core import Runtime
from interp.runtime.natives import context as context_module
from interp.runtime.natives.context import NativeContext

from .helpers import run_krl

NATIVES = Path(context_module.__file__).resolve().parent


def writes_through_first_parameter(source: str) -> list[str]:
    """``function:line`` of each assignment in `source` whose target is an attribute reached
    from the function's first parameter (``ctx.x = v``, ``ctx.sysvars.ek = v``, ``ctx.x += v``; a
    method's own ``self`` aside)."""
    out = []
    for fn in ast.walk(ast.parse(source)):
        if not isinstance(fn, (ast.FunctionDef, ast.Lambda)) or not fn.args.args:
            continue
        first = fn.args.args[0].arg
        if first in ("self", "cls"):
            continue
        for node in ast.walk(fn):
            targets = node.targets if isinstance(node, ast.Assign) else \
                [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
            for t in targets:
                base = t
                while isinstance(base, ast.Attribute):
                    base = base.value
                if isinstance(t, ast.Attribute) and isinstance(base, ast.Name) and base.id == first:
                    out.append(f"{getattr(fn, 'name', 'lambda')}:{node.lineno}")
    return out


def test_the_scan_sees_a_native_that_writes_its_run():
    """The scan can fail: the shape of the old Set_KrlMsg and EK is found."""
    old = ("def _set_krlmsg(rt, a):\n    m = rt.messages.add('NOTIFY', 'x')\n    rt.msg_handle = m.handle\n"
           "def _ek(rt, a):\n    rt.sysvars.ek = (1, 2)\n    return rt.random.uniform(0, 1)\n")
    assert writes_through_first_parameter(old) == ["_set_krlmsg:3", "_ek:5"]


def test_no_native_writes_through_its_context():
    """No function of interp/runtime/natives/ assigns to an attribute of its first parameter,
    and none names the runtime (``rt``) any more."""
    found = []
    for path in sorted(NATIVES.glob("*.py")):
        if path.name == "context.py":
            continue
        text = path.read_text(encoding="utf-8")
        found += [f"{path.name}:{w}" for w in writes_through_first_parameter(text)]
        params = [f.args.args[0].arg for f in ast.walk(ast.parse(text))
                  if isinstance(f, ast.FunctionDef) and f.args.args]
        found += [f"{path.name}: parameter rt" for p in params if p == "rt"]
    assert found == []


def test_the_context_has_only_its_calls():
    """The context holds what its docstring lists and refuses any other attribute."""
    assert "rt" not in NativeContext.__slots__ and "random" not in NativeContext.__slots__
    ctx = NativeContext.__new__(NativeContext)
    with pytest.raises(AttributeError):
        ctx.msg_handle = 1


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_a_native_runs_on_its_runs_context(tmp_path, monkeypatch, interp):
    """A run calls each native with its NativeContext, not the runtime: Set_KrlMsg twice gives
    handles 1 and 2 (KUKA numbers a controller's messages from 1), the message window keeps
    the last (2) without the native writing the run; FRAND(1, 1) is 1.0."""
    seen = []
    real = Runtime.run_native

    def spy(self, fn, args):
        seen.append(type(self.natives).__name__)
        return real(self, fn, args)
    monkeypatch.setattr(Runtime, "run_native", spy)
    src = """
    DEF prog()
      DECL KRLMSG_T msg
      DECL KRLMSGPAR_T par[3]
      DECL KRLMSGOPT_T opt
      msg = {MODUL[] "prog", NR 1, MSG_TXT[] "first"}
      h1 = SET_KRLMSG(#NOTIFY, msg, par[], opt)
      msg.MSG_TXT[] = "second"
      h2 = SET_KRLMSG(#NOTIFY, msg, par[], opt)
      r = FRAND(1.0, 1.0)
    END
    """
    dat = """
    DEFDAT prog
      DECL INT h1=0
      DECL INT h2=0
      DECL REAL r=0.0
    ENDDAT
    """
    run = run_krl(tmp_path, src, dat, interp=interp, max_sim_time=2.0)
    assert run.result.reason == "completed", run.result.text
    assert (run.var("prog", "h1"), run.var("prog", "h2"), run.var("prog", "r")) == (1, 2, 1.0)
    assert run.rt.messages.last_handle == 2
    assert seen and set(seen) == {"NativeContext"}
    assert not hasattr(run.rt, "msg_handle")
