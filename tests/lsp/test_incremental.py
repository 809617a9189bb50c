"""An edit that keeps a module's interface re-checks that module only (krl/lsp/incremental.py),
and gives exactly the diagnostics of a full check of the same texts; an edit of the interface
checks the whole workspace again."""

from __future__ import annotations

import shutil

from krl.lsp.analysis import build_analysis
from krl.lsp.project import Project
from tests.lsp.conftest import BACKUP


def rows(an):
    return [(d.path, d.code, d.line, d.column, d.message, d.help) for d in an.ws.diagnostics]


def full(p: Project, an):
    return build_analysis(an.root, [p.parsed(f) for f in an.files])


def edits_agree(p: Project, path: str, texts: list[tuple[str, bool]]) -> None:
    for text, incremental in texts:
        prev = p.latest(path)
        p.change(path, text)
        an = p.analyze(path)
        assert (an.ws is prev.ws) == incremental, text[:200]
        assert rows(an) == rows(full(p, an))


def test_body_edits_on_the_fixture(tmp_path):
    shutil.copytree(BACKUP, tmp_path / "KRC")
    main = str(tmp_path / "KRC" / "R1" / "Program" / "main.src")
    text = open(main).read()
    p = Project()
    p.open(main, text)
    p.analyze(main)
    edits_agree(p, main, [
        (text.replace("  counter = 0\n", "  countr = 0.5\n"), True),                 # E101
        (text.replace("  counter = 0\n", "  counter = 0.5\n  $IN[3] = TRUE\n  bar()\n"), True),   # W202, E501, E106
        (text, True),
        (text.replace("IF run_mode == #auto THEN", "IF run_mode == #auto"), True),   # a syntax error
        (text.replace("IF run_mode == #auto THEN", "IF run_mode == #auto").replace("counter = 0", "countr = 0"), True),
        (text, True),
        (text.replace("DEF on_stop( )", "GLOBAL DEF on_stop( )"), False),           # interface: GLOBAL
        (text, False),
        (text.replace("DEF on_stop( )", "DEF on_stop(x:IN)\n  DECL INT x"), False),  # interface: a parameter
        (text, False),
    ])
    an = p.latest(main)
    # go to definition from another file still reaches the new routine node
    assert an.ws.global_scope.routines["HELPER"].decl in an.files[str(tmp_path / "KRC" / "R1" / "Program" / "tools.src")].source.module.routines


def test_body_edits_on_a_real_backup(shared_corpus, tmp_path):
    """The palletizer backup: coge_g.src line 60 ``   SALIR = TRUE`` edited into an undeclared
    name, an unknown routine and a KUKA name the backup does not declare."""
    path = str(shared_corpus / "ingeniado__KRC4-Robot-Palletizer" / "Program" / "CAJA_G" / "coge_g.src")
    text = open(path, encoding="cp1252").read()
    p = Project()
    p.open(path, text)
    p.analyze(path)
    assert "   SALIR = TRUE\n" in text
    edits_agree(p, path, [
        (text.replace("   SALIR = TRUE\n", "   SALIRR = TRUE\n", 1), True),
        (text.replace("   SALIR = TRUE\n", "   no_such_routine()\n   SALIR = $NO_SUCH_SYSVAR\n", 1), True),
        (text.replace("   SALIR = TRUE\n", "   SALIR = TRUE +\n", 1), True),          # a syntax error
        (text, True),
    ])
