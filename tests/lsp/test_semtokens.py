"""Semantic tokens over LSP, decoded to absolute (line, start, length, type, modifiers). The
expected tokens are read by hand from the fixture lines (0-based):
main.src 0 ``&ACCESS RVP``, 3 ``  DECL pose_t p``, 11 ``    p.x = gripper.mass``,
13 ``  IF run_mode == #auto THEN``, 5 ``  INTERRUPT DECL 3 WHEN $IN[1] DO on_stop( )``;
tools.src 3 ``GLOBAL DEF helper(n:IN)``; $config.dat 2 ``  STRUC tool_t REAL mass, INT id``,
3 ``  ENUM mode_t auto, manual``, 6 ``  SIGNAL stop_btn $IN[1] ;Stop button of the cell``."""

from __future__ import annotations

import pytest
from lsprotocol import types as L

from tests.lsp.conftest import PROGRAM, SYSTEM, open_doc

pytestmark = pytest.mark.asyncio(loop_scope="module")


async def decoded(client, path) -> dict[int, list[tuple]]:
    caps = client.init_result.capabilities.semantic_tokens_provider
    types, mods = caps.legend.token_types, caps.legend.token_modifiers
    got = await client.text_document_semantic_tokens_full_async(
        L.SemanticTokensParams(text_document=L.TextDocumentIdentifier(uri=path.as_uri())))
    out: dict[int, list[tuple]] = {}
    line = col = 0
    d = got.data
    for i in range(0, len(d), 5):
        dl, ds, n, ty, md = d[i:i + 5]
        line += dl
        col = col + ds if dl == 0 else ds
        out.setdefault(line, []).append((col, n, types[ty], tuple(m for b, m in enumerate(mods) if md >> b & 1)))
    return out


async def test_semantic_tokens_of_the_fixture(client):
    await open_doc(client, PROGRAM / "main.src")
    main = await decoded(client, PROGRAM / "main.src")
    assert main[0] == [(0, 11, "macro", ())]
    assert main[3] == [(2, 4, "keyword", ()), (7, 6, "type", ()), (14, 1, "variable", ("declaration",))]
    assert main[11] == [(4, 1, "variable", ()), (6, 1, "property", ()), (10, 7, "variable", ()), (18, 4, "property", ())]
    assert main[13] == [(2, 2, "keyword", ()), (5, 8, "variable", ()), (17, 5, "enumMember", ()), (23, 4, "keyword", ())]
    assert main[5] == [(2, 9, "keyword", ()), (12, 4, "keyword", ()), (17, 1, "number", ()), (19, 4, "keyword", ()),
                       (24, 3, "variable", ("readonly", "defaultLibrary")), (28, 1, "number", ()),
                       (31, 2, "keyword", ()), (34, 7, "function", ())]
    assert main[4] == [(2, 10, "comment", ())]                  # ;FOLD INIT
    tools = await decoded(client, PROGRAM / "tools.src")
    assert tools[3] == [(0, 6, "keyword", ()), (7, 3, "keyword", ()), (11, 6, "function", ("declaration",)),
                        (18, 1, "parameter", ("declaration",)), (20, 2, "keyword", ())]
    config = await decoded(client, SYSTEM / "$config.dat")
    assert config[2] == [(2, 5, "keyword", ()), (8, 6, "type", ("declaration",)), (15, 4, "type", ("defaultLibrary",)),
                         (20, 4, "property", ("declaration",)), (26, 3, "type", ("defaultLibrary",)),
                         (30, 2, "property", ("declaration",))]
    assert config[3] == [(2, 4, "keyword", ()), (7, 6, "type", ("declaration",)),
                         (14, 4, "enumMember", ("declaration",)), (20, 6, "enumMember", ("declaration",))]
    assert config[6] == [(2, 6, "keyword", ()), (9, 8, "variable", ("declaration",)),
                         (18, 3, "variable", ("defaultLibrary",)), (22, 1, "number", ()), (25, 24, "comment", ())]


async def test_semantic_tokens_of_a_real_backup(client, shared_corpus):
    """coge_25.src of the palletizer backup: line 6 ``DECL E6POS POS_AUX1``, 13
    ``    BAS (#INITMOV,0 )``, 28 ``INC_Z1=350 ;Cota Inicial Seguridad 350``, 2
    ``&PARAM TEMPLATE = C:\\KRC\\Roboter\\Template\\vorgabe`` (a header)."""
    path = shared_corpus / "ingeniado__KRC4-Robot-Palletizer" / "Program" / "SACO_25" / "coge_25.src"
    await open_doc(client, path)
    got = await decoded(client, path)
    assert got[2] == [(0, 49, "macro", ())]
    assert got[6] == [(0, 4, "keyword", ()), (5, 5, "type", ("defaultLibrary",)), (11, 8, "variable", ("declaration",))]
    assert got[13] == [(4, 3, "function", ()), (9, 8, "enumMember", ()), (18, 1, "number", ())]
    assert got[28] == [(0, 6, "variable", ()), (7, 3, "number", ()), (11, 27, "comment", ())]
