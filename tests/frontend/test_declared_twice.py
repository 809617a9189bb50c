"""The semantic model's facts of names declared twice (krl/semantics/checker.py DeclaredTwice,
``Workspace.declared_twice``): what the language server's rename and the backup diff read
instead of E102's words. The places below are counted by hand from the texts.
"""

from __future__ import annotations

from krl.diagnostics.codes import E102
from krl.workspace import Workspace, check_texts, load_text

SRC = """DEF prog()
  INT i
  REAL i
  i = 1
END

DEF helper()
END

DEF helper()
END
"""
DAT = """DEFDAT prog PUBLIC
  DECL GLOBAL INT g
  DECL INT g
  STRUC pair INT a, REAL a
  STRUC pair INT x
ENDDAT
"""


def _facts(ws):
    return [(f.name, f.kind, f.span.file, f.span.line, (f.first.file, f.first.line) if f.first else None, f.struc)
            for f in ws.declared_twice()]


def test_each_kind_of_second_declaration_is_a_fact_with_both_places():
    ws = check_texts({"/p/prog.src": SRC, "/p/prog.dat": DAT})
    assert sorted(_facts(ws)) == sorted([
        ("i", "value", "/p/prog.src", 3, ("/p/prog.src", 2), ""),
        ("helper", "routine", "/p/prog.src", 10, ("/p/prog.src", 7), ""),
        ("g", "value", "/p/prog.dat", 3, ("/p/prog.dat", 2), ""),      # GLOBAL and not in one data list
        ("pair", "type", "/p/prog.dat", 5, ("/p/prog.dat", 4), ""),
        ("a", "component", "/p/prog.dat", 4, ("/p/prog.dat", 4), "pair"),
    ])
    # every fact is one E102 finding, worded by the same template
    e102 = sorted((d.path, d.line, d.message) for d in ws.diagnostics if d.code == E102)
    assert e102 == sorted((f.span.file, f.span.line, f.worded()[1]) for f in ws.declared_twice())
    assert ("/p/prog.src", 3, "'i' is declared more than once (first declared at /p/prog.src:2:3)") in e102   # the declaration INT i
    assert ("/p/prog.dat", 4, "component 'a' appears twice in pair") in e102


def test_a_re_check_after_an_edit_keeps_the_facts_of_a_full_check():
    ws = check_texts({"/p/prog.src": SRC, "/p/prog.dat": DAT})
    fixed = SRC.replace("  REAL i\n", "  REAL j\n")
    ws.replace(load_text(fixed, "/p/prog.src"))
    full = check_texts({"/p/prog.src": fixed, "/p/prog.dat": DAT})
    assert sorted(_facts(ws)) == sorted(_facts(full))
    assert "i" not in {f.name for f in ws.declared_twice()}
    assert {f.name for f in ws.declared_twice()} == {"helper", "g", "pair", "a"}


def test_no_facts_before_a_check():
    assert Workspace("/p").declared_twice() == []
