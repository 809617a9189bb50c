"""Where the Declarer enters each STRUC/ENUM (krl/semantics/checker.py ``declare_types``), as it
records it in ``Scope.type_symbols``; the language server reads this record. Expected scopes
from reference 2.7 (routine locals, the module's data list, GLOBAL names and $config.dat global)."""

from __future__ import annotations

from krl.workspace import check_texts

FILES = {
    "R1/System/$config.dat": "DEFDAT $CONFIG\n  STRUC tool_t REAL mass\nENDDAT\n",
    "R1/System/$machine.dat": "DEFDAT $MACHINE\n  STRUC tool_t REAL mass\nENDDAT\n",   # repeats: first wins, no E102
    "R1/Program/tools.dat": "DEFDAT tools PUBLIC\n  GLOBAL STRUC pose_t REAL x\n  ENUM mode_t a, b\nENDDAT\n",
    "R1/Program/tools.src": "DEF tools( )\n  STRUC local_t INT n\n  DECL local_t v\n  v.n = 1\nEND\n",
}


def test_each_type_is_recorded_once_in_the_scope_it_was_entered():
    ws = check_texts(FILES)
    assert [d.code for d in ws.diagnostics] == []
    glob = ws.global_scope
    unit = next(u for u in ws.units if u.name == "tools")
    (local,) = [s for s in ws.routine_scopes.values() if s.name == "tools"]

    def place(scope, name):
        sym = scope.type_symbols[name]
        assert sym.kind == "type" and sym.type is scope.types[name]
        return sym.scope, sym.path, sym.module, sym.decl.span.line

    assert sorted(glob.type_symbols) == ["POSE_T", "TOOL_T"]
    assert place(glob, "TOOL_T") == ("global", "R1/System/$config.dat", "$CONFIG", 2)
    assert place(glob, "POSE_T") == ("global", "R1/Program/tools.dat", "tools", 2)
    assert sorted(unit.scope.type_symbols) == ["MODE_T"]
    assert place(unit.scope, "MODE_T") == ("module", "R1/Program/tools.dat", "tools", 3)
    assert sorted(local.type_symbols) == ["LOCAL_T"]
    assert place(local, "LOCAL_T") == ("routine", "R1/Program/tools.src", "tools", 2)


def test_a_user_duplicate_is_e102_and_keeps_the_first_record():
    ws = check_texts({"a.src": "DEF a( )\n  STRUC s INT x\n  STRUC s REAL y\nEND\n"})
    assert [(d.code, d.line) for d in ws.diagnostics] == [("E102", 3)]
    (local,) = ws.routine_scopes.values()
    assert local.type_symbols["S"].decl.span.line == 2
