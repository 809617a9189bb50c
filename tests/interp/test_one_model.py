"""One program model (issue 23): krl check, krl run and krl lsp see the same files
(krl/project.py) and the same resolution (krl/semantics/resolve.py).

The fixture is a program whose old run-time rules and the checker disagreed: outside a
backup the runtime indexed only the top level of the program's folder, so a GLOBAL routine
in a subfolder was accepted by the checker and never found by the run. Expected values by
hand: Helper (sub/lib.src line 1) sets $OUT[5]; the program ends completed with $OUT[5] TRUE.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from krl.ast import nodes as N
from krl.lsp.navigate import definition, resolve
from krl.lsp.project import Project
from krl.semantics.resolve import GLOBAL, LOCAL, MODULE, SYSTEM, UNRESOLVED
from krl.workspace import workspaces_for
from robot.trace import TraceWriter

PROG = "DEF prog()\n  DECL INT n\n  n = 2\n  Helper()\n  $OUT[n] = done\nEND\n"
DAT = "DEFDAT prog\n  DECL BOOL done = TRUE\nENDDAT\n"
LIB = "GLOBAL DEF Helper()\n  $OUT[5] = TRUE\nEND\n"


def _folder(tmp_path: Path) -> Path:
    (tmp_path / "sub").mkdir()
    (tmp_path / "prog.src").write_text(PROG)
    (tmp_path / "prog.dat").write_text(DAT)
    (tmp_path / "sub" / "lib.src").write_text(LIB)
    return tmp_path / "prog.src"


def test_global_routine_in_a_subfolder_is_the_same_for_check_run_and_lsp(tmp_path):
    prog = _folder(tmp_path)
    lib = tmp_path / "sub" / "lib.src"
    # krl check FILE: the program's files are its folder's; Helper is declared, no error
    [ws] = workspaces_for(prog)
    assert ws.check() == []
    call = ws.modules["PROG"].routines[0].body[1].call
    assert N.symbol_of(call).decl is ws.modules["LIB"].routines[0]
    # krl run: the same routine runs (tree and VM)
    for interp in ("tree", "vm"):
        tw = TraceWriter(keep=True)
        rt, _ = make_runtime(run_spec(prog, mujoco=False, interp=interp), RunSinks(trace=tw))
        res = rt.run()
        assert res.reason == "completed", (interp, res)
        calls = [e["name"] for e in tw.events if e["kind"] == "call"]
        assert calls == ["prog", "Helper"], (interp, calls)
        assert rt.controller.io.get_out(5) and rt.controller.io.get_out(2), interp
    # krl lsp: go to definition on the call (line 4, column 3) lands on lib.src line 1
    project = Project()
    project.open(str(prog), PROG)
    an = project.analyze(str(prog))
    target = resolve(an, str(prog), 4, 3)
    place = definition(an, target)
    assert Path(place.path) == lib and place.line == 1


def test_every_use_has_its_storage_class_and_slot(tmp_path):
    prog = _folder(tmp_path)
    [ws] = workspaces_for(prog)
    ws.check()
    r = ws.modules["PROG"].routines[0]
    assert [s.name for s in r.ann.layout.slots] == ["n"]
    names = {(n.name, n.ann.place.kind, n.ann.place.slot) for n in r.walk() if isinstance(n, N.Name)}
    assert ("n", LOCAL, 0) in names and ("$OUT", SYSTEM, 0) in names
    done = next(n for n in r.walk() if isinstance(n, N.Name) and n.name == "done").ann.place
    prog_unit = next(i for i, u in enumerate(ws.units) if u.name.upper() == "PROG")
    assert (done.kind, done.owner, done.slot) == (MODULE, prog_unit, 0)
    assert GLOBAL != MODULE and UNRESOLVED not in {k for _, k, _ in names}


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_an_undeclared_name_is_refused_and_a_run_time_error_with_no_check(tmp_path, interp):
    """The checker rejects the program (E101): it does not start; without the check the name
    is the run-time error "unknown name" at its line, identically in both interpreters."""
    p = tmp_path / "bad.src"
    p.write_text("DEF bad()\n  $OUT[1] = TRUE\n  $OUT[2] = nothere\nEND\n")
    rt, _ = make_runtime(run_spec(p, mujoco=False, interp=interp))
    res = rt.run()
    assert res.reason == "error" and "cannot start" in res.text and "E101" in res.text and res.line == 3
    rt, _ = make_runtime(run_spec(p, mujoco=False, interp=interp, check=False))
    res = rt.run()
    # issue 85: with what the checker said before the run (E101 at line 3, column 13)
    assert (res.reason, res.text, res.line) == (
        "error", "unknown name nothere: the backup declares no nothere (krl check: E101 at bad.src:3:13); KUKA's "
                 "controller does not link bad.src with that error, so no program that is or calls bad.src can be "
                 "selected", 3)
    assert rt.controller.io.get_out(1) and not rt.controller.io.get_out(2)


EXT_PROG = """DEF caller()
  EXT callee(INT :IN)
  callee(7)
END
"""
EXT_CALLEE = """DEF callee(n :IN)
  DECL INT n
  $OUT[n] = TRUE
END
"""


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_an_ext_declaration_links_to_the_module_it_names(tmp_path, interp):
    """``EXT callee(...)`` in a module declares the main routine of module callee.src
    (reference 2.6): the call runs it, as the controller's linker binds it (issue 22: the
    backups' ``EXT BAS (...)`` lines had made every BAS call a stub)."""
    (tmp_path / "caller.src").write_text(EXT_PROG)
    (tmp_path / "callee.src").write_text(EXT_CALLEE)
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(tmp_path / "caller.src", mujoco=False, interp=interp), RunSinks(trace=tw))
    res = rt.run()
    assert res.reason == "completed", res
    assert [e["name"] for e in tw.events if e["kind"] == "call"] == ["caller", "callee"]
    assert rt.controller.io.get_out(7)
