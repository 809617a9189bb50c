"""Call hierarchy over the program map (krl/lsp/calls.py, issue 26), driven by pytest-lsp.
Positions counted by hand from fixtures/backup, 0-based as LSP counts:

main.src  line 1  ``DEF main( )``                     main at 4..8; END on line 19
          line 5  ``  INTERRUPT DECL 3 WHEN $IN[1] DO on_stop( )``   on_stop at 34..41
          line 14 ``    helper(local_count)``         helper at 4..10
          line 21 ``DEF on_stop( )``                  on_stop at 4..11; END on line 23
tools.src line 3  ``GLOBAL DEF helper(n:IN)``         helper at 11..17; END on line 6
"""

from __future__ import annotations

from pathlib import Path

import pytest
from lsprotocol import types as L

from tests.lsp.conftest import PROGRAM, open_doc, pos

pytestmark = pytest.mark.asyncio(loop_scope="module")

MAIN = PROGRAM / "main.src"


def rng(r: L.Range) -> tuple[int, int, int, int]:
    return (r.start.line, r.start.character, r.end.line, r.end.character)


async def prepare(client, path, line, char):
    await open_doc(client, path)
    return await client.text_document_prepare_call_hierarchy_async(L.CallHierarchyPrepareParams(
        text_document=L.TextDocumentIdentifier(uri=path.as_uri()), position=pos(line, char))) or []


async def test_prepare_on_a_call_gives_the_called_routine(client):
    items = await prepare(client, MAIN, 14, 6)
    assert len(items) == 1
    it = items[0]
    assert (it.name, Path(it.uri).name, rng(it.selection_range), rng(it.range)) == (
        "helper", "tools.src", (3, 11, 3, 17), (3, 0, 6, 3))
    assert it.kind == L.SymbolKind.Function


async def test_prepare_on_a_def_line_and_nowhere_else(client):
    items = await prepare(client, MAIN, 1, 5)
    assert [(i.name, rng(i.selection_range), rng(i.range)) for i in items] == [("main", (1, 4, 1, 8), (1, 0, 19, 3))]
    assert await prepare(client, MAIN, 8, 3) == []          # `counter = 0`: a variable


async def test_outgoing_calls_include_the_interrupt_handler(client):
    (main,) = await prepare(client, MAIN, 1, 5)
    out = await client.call_hierarchy_outgoing_calls_async(L.CallHierarchyOutgoingCallsParams(item=main))
    got = sorted((c.to.name, Path(c.to.uri).name, [rng(r) for r in c.from_ranges]) for c in out)
    assert got == [("helper", "tools.src", [(14, 4, 14, 10)]),
                   ("on_stop", "main.src", [(5, 34, 5, 41)])]


async def test_incoming_calls(client):
    (helper,) = await prepare(client, MAIN, 14, 6)
    inc = await client.call_hierarchy_incoming_calls_async(L.CallHierarchyIncomingCallsParams(item=helper))
    assert [(c.from_.name, Path(c.from_.uri).name, [rng(r) for r in c.from_ranges]) for c in inc] == [
        ("main", "main.src", [(14, 4, 14, 10)])]
    (on_stop,) = await prepare(client, MAIN, 21, 5)
    inc = await client.call_hierarchy_incoming_calls_async(L.CallHierarchyIncomingCallsParams(item=on_stop))
    assert [(c.from_.name, [rng(r) for r in c.from_ranges]) for c in inc] == [("main", [(5, 34, 5, 41)])]
