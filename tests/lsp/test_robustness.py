"""krl lsp on awkward input: files outside any backup, non-UTF-8 files, syntax errors (partial
trees), files changed on disk, input past the limits of krl/limits.py, odd requests; and a
handler that raises is answered, not fatal. Expected values are counted by hand."""

from __future__ import annotations

import pytest
from lsprotocol import types as L

from krl.limits import MAX_FILE_BYTES, MAX_NESTING
from tests.lsp.conftest import PROGRAM, change_doc, close_doc, open_doc, pos, summary, wait_diagnostics, where

pytestmark = pytest.mark.asyncio(loop_scope="module")

MAIN_TEXT = (PROGRAM / "main.src").read_text()


def td(path) -> L.TextDocumentIdentifier:
    return L.TextDocumentIdentifier(uri=path.as_uri())


async def test_file_outside_any_backup_with_a_cp1252_data_list(client, tmp_path):
    folder = tmp_path / "loose"
    folder.mkdir()
    # prog.dat is cp1252 (0xF6 0xDF = "öß" in a comment): decoded by the project's read_source
    (folder / "prog.dat").write_bytes(b"DEFDAT prog\r\n; Gr\xf6\xdfe\r\n  DECL INT y\r\nENDDAT\r\n")
    src = folder / "prog.src"
    src.write_text("DEF prog( )\n  y = 1\n  x = 2\nEND\n")
    diags = await open_doc(client, src)
    assert summary(diags) == [("E101", 2, 2, "'x' is not declared")]       # y comes from prog.dat
    got = await client.text_document_definition_async(L.DefinitionParams(text_document=td(src), position=pos(1, 2)))
    assert [where(x) for x in got] == [("prog.dat", 2, 11, 2, 12)]
    close_doc(client, src)


async def test_syntax_error_keeps_navigation_on_the_partial_tree(client, backup_copy):
    path = backup_copy / "R1" / "Program" / "main.src"
    no_then = MAIN_TEXT.replace("IF run_mode == #auto THEN", "IF run_mode == #auto")
    diags = await open_doc(client, path, no_then)
    assert [(str(d.code), d.range.start.line) for d in diags] == [("E012", 13)]
    # names still resolve in the file that does not parse
    got = await client.text_document_definition_async(L.DefinitionParams(text_document=td(path), position=pos(8, 3)))
    assert [where(x) for x in got] == [("$config.dat", 1, 11, 1, 18)]
    got = await client.text_document_definition_async(L.DefinitionParams(text_document=td(path), position=pos(10, 24)))
    assert [where(x) for x in got] == [("main.src", 2, 11, 2, 12)]
    close_doc(client, path)


async def test_file_changed_on_disk(client, backup_copy):
    path = backup_copy / "R1" / "Program" / "main.src"
    assert summary(await open_doc(client, path)) == []
    # another program removes the STRUC pose_t from tools.dat
    tools = backup_copy / "R1" / "Program" / "tools.dat"
    tools.write_text("DEFDAT tools PUBLIC\n  DECL GLOBAL INT shared = 0\nENDDAT\n")
    client.diagnostics.pop(path.as_uri(), None)
    client.workspace_did_change_watched_files(L.DidChangeWatchedFilesParams(
        changes=[L.FileEvent(uri=tools.as_uri(), type=L.FileChangeType.Changed)]))
    diags = await wait_diagnostics(client, path.as_uri())
    assert summary(diags) == [("E105", 3, 7, "unknown type 'pose_t'")]
    close_doc(client, path)


async def test_input_past_the_limits(client, tmp_path):
    deep = tmp_path / "deep.src"
    levels = MAX_NESTING + 20
    text = "DEF deep( )\n" + "IF TRUE THEN\n" * levels + "ENDIF\n" * levels + "END\n"
    diags = await open_doc(client, deep, text)
    # the first IF past the budget: line 1 + MAX_NESTING (0-based), column 0
    assert [(str(d.code), d.range.start.line, d.range.start.character) for d in diags] == [("E018", 1 + MAX_NESTING, 0)]
    # a buffer over MAX_FILE_BYTES is not parsed: E001 naming its size
    huge = "; comment\n" * (MAX_FILE_BYTES // 10 + 1)
    diags = await change_doc(client, deep, huge, 2)
    assert summary(diags) == [("E001", 0, 0, f"file not checked: too_large ({len(huge)} bytes > {MAX_FILE_BYTES})")]
    # NUL bytes: binary
    diags = await change_doc(client, deep, "DEF deep( )\n\x00\nEND\n", 3)
    assert summary(diags) == [("E001", 0, 0, "file not checked: binary (NUL bytes)")]
    # the server still answers
    syms = await client.text_document_document_symbol_async(L.DocumentSymbolParams(text_document=td(deep)))
    assert syms == []
    close_doc(client, deep)


async def test_odd_requests_get_empty_answers(client):
    main = PROGRAM / "main.src"
    await open_doc(client, main)
    far = await client.text_document_hover_async(L.HoverParams(text_document=td(main), position=pos(10_000, 500)))
    assert far is None
    # a document the server never saw, and that does not exist
    ghost = L.TextDocumentIdentifier(uri="file:///nonexistent-krl-folder/ghost.src")
    assert await client.text_document_definition_async(L.DefinitionParams(text_document=ghost, position=pos(0, 0))) is None
    got = await client.text_document_definition_async(L.DefinitionParams(text_document=td(main), position=pos(14, 5)))
    assert [where(x) for x in got] == [("tools.src", 3, 11, 3, 17)]
