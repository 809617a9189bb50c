"""An edit that keeps a module's interface re-checks that module's changed routines (or a data
list's changed values) only (krl/workspace.py ``Workspace.replace``), and gives exactly the
diagnostics of a full check of the same texts, parsed afresh; an edit of the interface checks the
whole workspace again."""

from __future__ import annotations

import shutil

from krl.lsp.project import Project
from krl.workspace import LoadedFile, Workspace, load_text
from tests.lsp.conftest import BACKUP


def rows(diags):
    return [(d.path, d.code, d.line, d.column, d.message, d.help, d.end_line, d.end_column,
             [(n.path, n.line, n.column, n.message) for n in d.notes]) for d in diags]


class FullCheck:
    """Full checks of an analysis's texts by krl check's pipeline (krl/workspace.py
    ``check_texts``: each file parsed whole by ``load_text``, objects of its own, never the
    editor's). A file's parse is made again only when its text changed since this oracle's last
    check (the same text, parsed by the same code, is the same parse; as tests/lsp/test_edits.py
    ``Oracle``): each edit of the palletizer backup parsed its 53 files again until 2026-11-29."""

    def __init__(self) -> None:
        self.loaded: dict[str, tuple[str, LoadedFile]] = {}

    def __call__(self, an) -> Workspace:
        ws = Workspace(next(iter(an.files), ""))
        for path, fi in an.files.items():
            text = fi.parsed.text
            if path not in self.loaded or self.loaded[path][0] != text:
                self.loaded[path] = (text, load_text(text, path))
            ws.add_loaded(self.loaded[path][1], notify=False)
        ws.check(resolve=False)        # as krl check checks (app/check.py): no storage placed for a run
        return ws


def edits_agree(p: Project, path: str, texts: list[tuple[str, str]], fresh: FullCheck | None = None) -> None:
    fresh = fresh or FullCheck()
    for text, how in texts:
        p.change(path, text)
        an = p.analyze(path)
        assert an.how == how, text[:200]
        assert rows(an.ws.diagnostics) == rows(fresh(an).diagnostics)


def test_body_edits_on_the_fixture(tmp_path):
    shutil.copytree(BACKUP, tmp_path / "KRC")
    main = str(tmp_path / "KRC" / "R1" / "Program" / "main.src")
    text = open(main).read()
    p = Project()
    p.open(main, text)
    p.analyze(main)
    edits_agree(p, main, [
        (text.replace("  counter = 0\n", "  countr = 0.5\n"), "routines"),                  # E101
        (text.replace("  counter = 0\n", "  counter = 0.5\n  $IN[3] = TRUE\n  bar()\n"), "routines"),   # W202, E501, E106
        (text, "routines"),
        (text.replace("IF run_mode == #auto THEN", "IF run_mode == #auto"), "routines"),    # a syntax error
        (text.replace("IF run_mode == #auto THEN", "IF run_mode == #auto").replace("counter = 0", "countr = 0"),
         "routines"),
        (text, "routines"),
        (text.replace("DEF on_stop( )", "GLOBAL DEF on_stop( )"), "workspace"),           # interface: GLOBAL
        (text, "workspace"),
        (text.replace("DEF on_stop( )", "DEF on_stop(x:IN)\n  DECL INT x"), "workspace"),  # interface: a parameter
        (text, "workspace"),
    ])
    an = p.latest(main)
    # go to definition from another file still reaches the new routine node
    assert an.ws.global_scope.routines["HELPER"].decl in an.files[str(tmp_path / "KRC" / "R1" / "Program" / "tools.src")].source.module.routines


def test_data_list_edits_on_the_fixture(tmp_path):
    """A value of a data list changes: only that value is checked again; a declaration
    changes: the workspace."""
    shutil.copytree(BACKUP, tmp_path / "KRC")
    path = str(tmp_path / "KRC" / "R1" / "Program" / "main.dat")
    text = open(path).read()
    p = Project()
    p.open(path, text)
    p.analyze(path)
    value = "  DECL INT local_count = 0\n"
    assert value in text
    edits_agree(p, path, [
        (text.replace(value, "  DECL INT local_count = \"a string\"\n"), "values"),    # E201
        (text.replace(value, "  DECL INT local_count = #no_such\n"), "values"),
        (text.replace(value, "\n\n" + value), "values"),                               # lines inserted above
        (text, "values"),
        (text.replace(value, value.replace("DECL", "DECL GLOBAL", 1)), "workspace"),
        (text, "workspace"),
    ])


def test_body_edits_on_a_real_backup(shared_corpus, tmp_path):
    """The palletizer backup: coge_g.src line 60 ``   SALIR = TRUE`` edited into an unknown
    routine and a KUKA name the backup does not declare, then into a syntax error: each edit
    re-checks the routines alone and gives a full check's diagnostics (the first full check
    parses the backup's 53 files, the next coge_g.src alone: :class:`FullCheck`; the fixture's
    test above runs the other kinds of edit and the way back)."""
    path = str(shared_corpus / "ingeniado__KRC4-Robot-Palletizer" / "Program" / "CAJA_G" / "coge_g.src")
    text = open(path, encoding="cp1252").read()
    p = Project()
    p.open(path, text)
    p.analyze(path)
    assert "   SALIR = TRUE\n" in text
    edits_agree(p, path, [
        (text.replace("   SALIR = TRUE\n", "   no_such_routine()\n   SALIRR = $NO_SUCH_SYSVAR\n", 1), "routines"),
        (text.replace("   SALIR = TRUE\n", "   SALIR = TRUE +\n", 1), "routines"),          # a syntax error
    ])


def test_body_edits_that_change_the_unresolved_name_report(tmp_path):
    """The report of names the backup does not declare counts uses across the workspace: an
    edit that adds, repeats or removes such a use makes it again (Workspace.replace), one that
    leaves the uses as they were keeps it; either way exactly a full check's diagnostics."""
    shutil.copytree(BACKUP, tmp_path / "KRC")
    main = str(tmp_path / "KRC" / "R1" / "Program" / "main.src")
    text = open(main).read()
    p = Project()
    p.open(main, text)
    p.analyze(main)
    one = text.replace("  counter = 0\n", "  counter = 0\n  $NOT_A_KUKA_NAME = 1\n")
    two = text.replace("  counter = 0\n", "  counter = 0\n  $NOT_A_KUKA_NAME = 1\n  $NOT_A_KUKA_NAME = 2\n")
    edits_agree(p, main, [(one, "routines")])
    reported = [d.message for d in p.latest(main).ws.diagnostics if "NOT_A_KUKA_NAME" in d.message]
    assert reported
    edits_agree(p, main, [(two, "routines"), (two.replace("= 2", "= 3"), "routines"), (text, "routines")])
    assert not [d for d in p.latest(main).ws.diagnostics if "NOT_A_KUKA_NAME" in d.message]
