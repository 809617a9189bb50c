"""Signature help and document highlight over LSP. Positions are 0-based, counted by hand:
main.src line 14 ``    helper(local_count)`` (``(`` at 10, the argument at 11..22), line 8
``  counter = 0``, line 10 ``    counter = counter + i``; tools.src line 3
``GLOBAL DEF helper(n:IN)``."""

from __future__ import annotations

import pytest
from lsprotocol import types as L

from tests.lsp.conftest import PROGRAM, open_doc, pos

pytestmark = pytest.mark.asyncio(loop_scope="module")

MAIN = PROGRAM / "main.src"


async def signature(client, path, line, char):
    got = await client.text_document_signature_help_async(L.SignatureHelpParams(
        text_document=L.TextDocumentIdentifier(uri=path.as_uri()), position=pos(line, char)))
    if got is None:
        return None
    s = got.signatures[got.active_signature or 0]
    return s.label, [tuple(p.label) for p in s.parameters], got.active_parameter


async def highlights(client, path, line, char):
    got = await client.text_document_document_highlight_async(L.DocumentHighlightParams(
        text_document=L.TextDocumentIdentifier(uri=path.as_uri()), position=pos(line, char)))
    return sorted((h.range.start.line, h.range.start.character, h.range.end.character, h.kind) for h in got or [])


async def test_signature_help_on_the_fixture(client, backup_copy):
    await open_doc(client, MAIN)
    # the DEF of helper is `GLOBAL DEF helper(n:IN)` with `DECL INT n`
    assert await signature(client, MAIN, 14, 11) == ("DEF helper(INT n :IN)", [(11, 20)], 0)
    assert await signature(client, MAIN, 14, 4) is None          # on the name, not in the brackets
    # while typing a second argument (a parse error on the line): still helper; helper has one
    # parameter, so it stays the active one
    main = backup_copy / "R1" / "Program" / "main.src"
    await open_doc(client, main, MAIN.read_text().replace("helper(local_count)", "helper(local_count, "))
    assert await signature(client, main, 14, 24) == ("DEF helper(INT n :IN)", [(11, 20)], 0)


async def test_signature_help_on_a_real_backup(client, shared_corpus):
    """coge_25.src line 14 ``    BAS (#INITMOV,0 )``: System/bas.src ``DEF  BAS (COMMAND :IN,REAL_PAR :IN )``
    with ``DECL BAS_COMMAND COMMAND`` and ``REAL REAL_PAR``; line 60 ``   PULSE ( OK_LEIDO_SALIR_PROGRAMA, true, 0.5 )``
    (reference 5.12, functions.yaml: PULSE(BOOL SIGNAL :OUT, BOOL LEVEL :IN, REAL DURATION :IN))."""
    path = shared_corpus / "ingeniado__KRC4-Robot-Palletizer" / "Program" / "SACO_25" / "coge_25.src"
    await open_doc(client, path)
    label = "DEF BAS(BAS_COMMAND COMMAND :IN, REAL REAL_PAR :IN)"
    assert await signature(client, path, 13, 18) == (label, [(8, 31), (33, 50)], 1)
    assert await signature(client, path, 13, 10) == (label, [(8, 31), (33, 50)], 0)
    got = await signature(client, path, 59, 44)
    assert got[0] == "DEF PULSE(BOOL SIGNAL :OUT, BOOL LEVEL :IN, REAL DURATION :IN)" and got[2] == 2


async def test_document_highlight_read_write(client):
    await open_doc(client, MAIN)
    R, W, T = L.DocumentHighlightKind.Read, L.DocumentHighlightKind.Write, L.DocumentHighlightKind.Text
    # counter: written on lines 8 and 10 (4..11), read on line 10 (14..21); declared in $config.dat
    assert await highlights(client, MAIN, 10, 15) == [(8, 2, 9, W), (10, 4, 11, W), (10, 14, 21, R)]
    # i: declared (2, 11), FOR counter (9, 6) written, read (10, 24)
    assert await highlights(client, MAIN, 2, 11) == [(2, 11, 12, T), (9, 6, 7, W), (10, 24, 25, R)]
    # n in tools.src: header and DECL are declarations, `shared = n` reads it
    assert await highlights(client, PROGRAM / "tools.src", 5, 11) == [(3, 18, 19, T), (4, 11, 12, T), (5, 11, 12, R)]


async def test_document_highlight_on_a_real_backup(client, shared_corpus):
    """coge_g.src of the palletizer: SALIR written on lines 60 and 73 (``   SALIR = TRUE``)."""
    path = shared_corpus / "ingeniado__KRC4-Robot-Palletizer" / "Program" / "CAJA_G" / "coge_g.src"
    await open_doc(client, path)
    W = L.DocumentHighlightKind.Write
    assert await highlights(client, path, 59, 4) == [(59, 3, 8, W), (72, 3, 8, W)]
