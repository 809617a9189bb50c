"""Quick fixes over LSP for the diagnostics that carry a help: declare an undeclared variable
(type from the checker), insert a missing block closer, split a glued keyword. Positions are
0-based, counted by hand from the edited fixture text (shown next to each case)."""

from __future__ import annotations

from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest
from lsprotocol import types as L

from tests.lsp.conftest import PROGRAM, change_doc, open_doc, pos

pytestmark = pytest.mark.asyncio(loop_scope="module")

MAIN_TEXT = (PROGRAM / "main.src").read_text()


async def actions(client, path, line):
    got = await client.text_document_code_action_async(L.CodeActionParams(
        text_document=L.TextDocumentIdentifier(uri=path.as_uri()), range=L.Range(start=pos(line, 0), end=pos(line, 0)),
        context=L.CodeActionContext(diagnostics=[])))
    out = []
    for a in got or []:
        for uri, edits in a.edit.changes.items():
            for e in edits:
                out.append((a.title, Path(unquote(urlparse(uri).path)).name, e.range.start.line, e.range.start.character,
                            e.range.end.line, e.range.end.character, e.new_text))
    return out


async def test_declare_undeclared_variable_with_the_checkers_type(client, backup_copy):
    main = backup_copy / "R1" / "Program" / "main.src"
    text = MAIN_TEXT.replace("  counter = 0\n", "  ready = counter > 2\n")      # line 8
    diags = await open_doc(client, main, text)
    assert [(d.code, d.range.start.line) for d in diags] == [("E101", 8)]
    # main.dat line 3 is ENDDAT; main's last declaration is line 3 `  DECL pose_t p`
    assert await actions(client, main, 8) == [
        ("Declare 'DECL BOOL ready' in main.dat", "main.dat", 3, 0, 3, 0, "  DECL BOOL ready\n"),
        ("Declare 'DECL BOOL ready' in main", "main.src", 4, 0, 4, 0, "  DECL BOOL ready\n"),
    ]
    # passed to helper(n:IN) with n INT: INT
    text = MAIN_TEXT.replace("helper(local_count)", "helper(amount)")             # line 14
    await open_doc(client, main, text, version=2)
    assert (await actions(client, main, 14))[0][0] == "Declare 'DECL INT amount' in main.dat"
    assert await actions(client, main, 9) == []                                  # no diagnostic there


async def test_insert_missing_endif_and_split_glued_keyword(client, backup_copy):
    main = backup_copy / "R1" / "Program" / "main.src"
    # ENDIF of line 15 removed: the IF of line 13 is closed by nothing before END (now line 18);
    # the parser's recovery passes over `DEF on_stop( )` (line 21), so the call of on_stop (line 5)
    # names a routine only a line not understood mentions: W106 (the rest is checked, issue 63)
    text = MAIN_TEXT.replace("    helper(local_count)\n  ENDIF\n", "    helper(local_count)\n")
    diags = await open_doc(client, main, text)
    assert [(d.code, d.range.start.line) for d in diags] == [("W106", 5), ("E010", 13)]
    assert await actions(client, main, 13) == [("Insert ENDIF", "main.src", 18, 0, 18, 0, "  ENDIF\n")]
    # `  INTERRUPT3 ON` (line 6): a space after INTERRUPT, at char 11
    text = MAIN_TEXT.replace("  INTERRUPT ON 3", "  INTERRUPT3 ON")
    diags = await change_doc(client, main, text, 2)
    assert [(d.code, d.range.start.line) for d in diags] == [("E002", 6)]
    assert await actions(client, main, 6) == [("Write 'INTERRUPT 3'", "main.src", 6, 11, 6, 11, " ")]


async def test_declare_on_a_real_backup(client, shared_corpus):
    """coge_25.src of the palletizer backup with its line 8 ``DECL REAL INC_Z1`` commented out:
    line 29 ``INC_Z1=350`` (0-based 28) assigns an INT; coge_25.dat's ENDDAT is its line 26
    (0-based 25); the routine's last declaration is line 7, its first statement (line 12) is
    indented by four spaces."""
    path = shared_corpus / "ingeniado__KRC4-Robot-Palletizer" / "Program" / "SACO_25" / "coge_25.src"
    text = path.read_text(encoding="cp1252").replace("DECL REAL INC_Z1", ";DECL REAL INC_Z1")
    diags = await open_doc(client, path, text)
    assert ("E101", 28, 0, "'INC_Z1' is not declared") in [(d.code, d.range.start.line, d.range.start.character, d.message) for d in diags]
    assert await actions(client, path, 28) == [
        ("Declare 'DECL INT INC_Z1' in coge_25.dat", "coge_25.dat", 25, 0, 25, 0, "  DECL INT INC_Z1\n"),
        ("Declare 'DECL INT INC_Z1' in coge_25", "coge_25.src", 7, 0, 7, 0, "    DECL INT INC_Z1\n"),
    ]
    # line 31 `POS_AUX1.Z=POS_AUX1.Z+INC_Z1`: the other operand is a REAL component
    assert (await actions(client, path, 30))[0][0] == "Declare 'DECL REAL INC_Z1' in coge_25.dat"
