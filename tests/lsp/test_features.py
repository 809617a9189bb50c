"""krl lsp driven over stdio by pytest-lsp: one test (at least) per feature. Every expected
position is counted by hand from the fixture backup (fixtures/backup), 0-based as LSP counts:
main.src line 11 is ``    p.x = gripper.mass`` (p at 4, x at 6, gripper at 10, mass at 18), and so on."""

from __future__ import annotations

import importlib.util
import json

import pytest
from lsprotocol import types as L

from app.check import run_check
from krl.fmt import format_text
from tests.lsp.conftest import (PROGRAM, change_doc, close_doc, open_doc, pos, summary,
                                wait_diagnostics, where)

pytestmark = pytest.mark.asyncio(loop_scope="module")

MAIN = PROGRAM / "main.src"
MAIN_TEXT = MAIN.read_text()


def td(path) -> L.TextDocumentIdentifier:
    return L.TextDocumentIdentifier(uri=path.as_uri())


async def definition(client, path, line, char):
    got = await client.text_document_definition_async(L.DefinitionParams(text_document=td(path), position=pos(line, char)))
    return [where(x) for x in (got or [])]


async def references(client, path, line, char, decl=True):
    got = await client.text_document_references_async(L.ReferenceParams(
        text_document=td(path), position=pos(line, char), context=L.ReferenceContext(include_declaration=decl)))
    return sorted(where(x) for x in (got or []))


def krl_check_json(folder) -> list[dict]:
    """The diagnostics of main.src as `krl check --format json FOLDER` prints them."""
    lines: list[str] = []
    run_check([str(folder)], fmt="json", echo=lines.append)
    return [d for ws in map(json.loads, lines) for d in ws["diagnostics"] if d["path"].endswith("main.src")]


async def test_diagnostics_resolve_config_and_globals(client):
    # main.src uses counter/gripper/run_mode ($config.dat), pose_t and helper (GLOBAL in tools.*),
    # local_count (main.dat): with the backup root found, nothing is undeclared.
    diags = await open_doc(client, MAIN)
    assert summary(diags) == []


async def test_diagnostics_unsaved_buffer_on_change_same_as_krl_check(client, backup_copy):
    path = backup_copy / "R1" / "Program" / "main.src"
    broken = MAIN_TEXT.replace("  counter = 0\n", "  countr = 0\n")
    diags = await open_doc(client, path, broken)          # the disk file is unchanged: the buffer wins
    assert summary(diags) == [("E101", 8, 2, "'countr' is not declared")]
    assert diags[0].range.end == pos(8, 8)                # the whole name
    assert diags[0].severity == L.DiagnosticSeverity.Error
    # the same text checked by `krl check`: same codes, places and messages
    path.write_text(broken)
    cli = krl_check_json(backup_copy)
    assert sorted((d["code"], d["line"] - 1, d["column"] - 1, d["message"]) for d in cli) == summary(diags)
    # on change: fixed, then a syntax error (IF without THEN on line 13)
    assert summary(await change_doc(client, path, MAIN_TEXT, 2)) == []
    no_then = MAIN_TEXT.replace("IF run_mode == #auto THEN", "IF run_mode == #auto")
    diags = await change_doc(client, path, no_then, 3)
    assert [(str(d.code), d.range.start.line) for d in diags] == [("E012", 13)]
    path.write_text(no_then)
    cli = krl_check_json(backup_copy)
    assert [(d["code"], d["line"] - 1, d["message"]) for d in cli] == [(str(d.code), d.range.start.line, d.message) for d in diags]
    close_doc(client, path)


async def test_definition_routine_across_files_global_and_ext(client):
    await open_doc(client, MAIN)
    # helper(local_count) on line 14 -> GLOBAL DEF helper in tools.src line 3, chars 11..17
    assert await definition(client, MAIN, 14, 5) == [("tools.src", 3, 11, 3, 17)]
    # the EXT declaration in main.dat (line 1, `  EXT helper(INT :IN)`) -> the same routine
    assert await definition(client, PROGRAM / "main.dat", 1, 7) == [("tools.src", 3, 11, 3, 17)]


async def test_definition_variables_local_module_config(client):
    await open_doc(client, MAIN)
    assert await definition(client, MAIN, 10, 24) == [("main.src", 2, 11, 2, 12)]          # i: local
    assert await definition(client, MAIN, 14, 12) == [("main.dat", 2, 11, 2, 22)]         # local_count: module .dat
    assert await definition(client, MAIN, 8, 2) == [("$config.dat", 1, 11, 1, 18)]        # counter: $config.dat


async def test_definition_types_components_enum(client):
    await open_doc(client, MAIN)
    assert await definition(client, MAIN, 3, 8) == [("tools.dat", 1, 15, 1, 21)]          # pose_t
    assert await definition(client, MAIN, 11, 6) == [("tools.dat", 1, 27, 1, 28)]         # p.x -> component x
    assert await definition(client, MAIN, 11, 19) == [("$config.dat", 2, 20, 2, 24)]      # gripper.mass
    assert await definition(client, MAIN, 13, 19) == [("$config.dat", 3, 14, 3, 18)]      # #auto of mode_t


async def test_definition_label_and_interrupt_handler(client):
    await open_doc(client, MAIN)
    assert await definition(client, MAIN, 16, 8) == [("main.src", 17, 2, 17, 6)]          # GOTO done
    assert await definition(client, MAIN, 5, 36) == [("main.src", 21, 4, 21, 11)]         # DO on_stop( )


async def test_references_variable_and_routine(client):
    await open_doc(client, MAIN)
    assert await references(client, MAIN, 8, 3) == sorted([
        ("$config.dat", 1, 11, 1, 18), ("main.src", 8, 2, 8, 9), ("main.src", 10, 4, 10, 11), ("main.src", 10, 14, 10, 21)])
    assert await references(client, MAIN, 8, 3, decl=False) == sorted([
        ("main.src", 8, 2, 8, 9), ("main.src", 10, 4, 10, 11), ("main.src", 10, 14, 10, 21)])
    assert await references(client, MAIN, 14, 4) == sorted([
        ("main.dat", 1, 6, 1, 12), ("main.src", 14, 4, 14, 10), ("tools.src", 3, 11, 3, 17)])
    # a component: x of pose_t, declared in tools.dat, used in main.src
    assert await references(client, MAIN, 11, 6) == sorted([("main.src", 11, 6, 11, 7), ("tools.dat", 1, 27, 1, 28)])


async def test_hover_variable_and_system_variable(client):
    await open_doc(client, MAIN)
    h = await client.text_document_hover_async(L.HoverParams(text_document=td(MAIN), position=pos(8, 4)))
    assert "DECL INT counter" in h.contents.value and "$config.dat" in h.contents.value
    # $OUT (line 18): BOOL[8192]; sysvars.yaml says writing it stops the advance run
    h = await client.text_document_hover_async(L.HoverParams(text_document=td(MAIN), position=pos(18, 3)))
    assert "BOOL" in h.contents.value and "8192" in h.contents.value
    assert "writing it stops the advance run" in h.contents.value
    assert "digital outputs (reference 7.1)" in h.contents.value          # sysvar_meanings.yaml
    # a component: its type and its structure
    h = await client.text_document_hover_async(L.HoverParams(text_document=td(MAIN), position=pos(11, 19)))
    assert "REAL mass" in h.contents.value and "tool_t" in h.contents.value


async def test_document_symbols_hierarchical(client):
    await open_doc(client, MAIN)
    syms = await client.text_document_document_symbol_async(L.DocumentSymbolParams(text_document=td(MAIN)))
    shape = [(s.name, s.kind, s.range.start.line, s.range.end.line,
              [(c.name, c.kind, c.range.start.line, c.range.end.line) for c in s.children or []]) for s in syms]
    assert shape == [
        ("main", L.SymbolKind.Function, 1, 19, [("i", L.SymbolKind.Variable, 2, 2), ("p", L.SymbolKind.Variable, 3, 3),
                                                ("INIT", L.SymbolKind.Namespace, 4, 7)]),
        ("on_stop", L.SymbolKind.Function, 21, 23, []),
    ]
    assert syms[0].selection_range.start == pos(1, 4)


async def test_workspace_symbols(client):
    await open_doc(client, MAIN)
    got = await client.workspace_symbol_async(L.WorkspaceSymbolParams(query="help"))
    assert sorted((s.name, where(s.location)) for s in got) == [
        ("helper", ("main.dat", 1, 6, 1, 12)), ("helper", ("tools.src", 3, 11, 3, 17))]


async def test_folding_ranges(client):
    await open_doc(client, MAIN)
    got = await client.text_document_folding_range_async(L.FoldingRangeParams(text_document=td(MAIN)))
    assert sorted((f.start_line, f.end_line, f.kind) for f in got) == sorted([
        (4, 7, L.FoldingRangeKind.Region),      # ;FOLD INIT .. ;ENDFOLD
        (1, 18, None),                          # DEF main .. (END on 19)
        (9, 11, None),                          # FOR .. (ENDFOR on 12)
        (13, 14, None),                         # IF .. (ENDIF on 15)
        (21, 22, None),                         # DEF on_stop .. (END on 23)
    ])


async def complete(client, path, line, char):
    got = await client.text_document_completion_async(L.CompletionParams(text_document=td(path), position=pos(line, char)))
    items = got.items if isinstance(got, L.CompletionList) else got or []
    return {i.label for i in items}


async def test_completion_components_after_dot(client):
    await open_doc(client, MAIN)
    assert await complete(client, MAIN, 11, 6) == {"x", "y"}            # after `p.` (pose_t)
    assert await complete(client, MAIN, 11, 18) == {"mass", "id"}       # after `gripper.` (tool_t)


async def test_completion_names_keywords_system_variables(client, backup_copy):
    path = backup_copy / "R1" / "Program" / "main.src"
    text = MAIN_TEXT.replace("  counter = 0\n", "  cou\n  ENDI\n  $POS_AC\n  run_mode = #ma\n")
    await open_doc(client, path, text)
    assert "counter" in await complete(client, path, 8, 5)               # global from $config.dat
    assert "ENDIF" in await complete(client, path, 9, 6)                 # keyword
    sysvars = await complete(client, path, 10, 9)
    assert "$POS_ACT" in sysvars and all(s.upper().startswith("$POS_AC") for s in sysvars)
    assert "i" in await complete(client, path, 8, 2)                     # local, empty prefix
    assert "MANUAL" in await complete(client, path, 11, 16)             # `#ma`: mode_t's value manual
    close_doc(client, path)


async def test_formatting_offered_exactly_when_krl_fmt_is_installed(client):
    has_fmt = importlib.util.find_spec("krl.fmt") is not None
    assert bool(client.init_result.capabilities.document_formatting_provider) == has_fmt
    await open_doc(client, MAIN)
    edits = await client.text_document_formatting_async(L.DocumentFormattingParams(
        text_document=td(MAIN), options=L.FormattingOptions(tab_size=2, insert_spaces=True))) if has_fmt else None
    if has_fmt:
        expected = format_text(MAIN_TEXT)
        assert (edits or []) == [] if expected == MAIN_TEXT else edits[0].new_text == expected
        # text that does not parse: no edit
        path = PROGRAM / "main.src"
        await change_doc(client, path, MAIN_TEXT.replace("IF run_mode == #auto THEN", "IF run_mode == #auto"), 50)
        assert not await client.text_document_formatting_async(L.DocumentFormattingParams(
            text_document=td(MAIN), options=L.FormattingOptions(tab_size=2, insert_spaces=True)))
        await change_doc(client, path, MAIN_TEXT, 51)


async def test_unsaved_buffer_of_another_file_is_seen(client, backup_copy):
    main = backup_copy / "R1" / "Program" / "main.src"
    tools = backup_copy / "R1" / "Program" / "tools.dat"
    assert summary(await open_doc(client, main)) == []
    # tools.dat edited in the editor, not saved: pose_t is gone -> main.src line 3 `  DECL pose_t p`
    client.diagnostics.pop(main.as_uri(), None)
    await open_doc(client, tools, "DEFDAT tools PUBLIC\n  DECL GLOBAL INT shared = 0\nENDDAT\n")
    assert summary(await wait_diagnostics(client, main.as_uri())) == [("E105", 3, 7, "unknown type 'pose_t'")]
    # closed without saving: the file on disk counts again
    client.diagnostics.pop(main.as_uri(), None)
    close_doc(client, tools)
    assert summary(await wait_diagnostics(client, main.as_uri())) == []
    close_doc(client, main)


async def test_untitled_buffer(client):
    uri = "untitled:Untitled-1"
    client.diagnostics.pop(uri, None)
    client.text_document_did_open(L.DidOpenTextDocumentParams(text_document=L.TextDocumentItem(
        uri=uri, language_id="krl", version=1, text="DEF x( )\n  DECL INT n\n  n = m\nEND\n")))
    assert summary(await wait_diagnostics(client, uri)) == [("E101", 2, 6, "'m' is not declared")]
    got = await client.text_document_definition_async(L.DefinitionParams(
        text_document=L.TextDocumentIdentifier(uri=uri), position=pos(2, 2)))
    assert [(x.uri, x.range.start.line, x.range.start.character) for x in got] == [(uri, 1, 11)]


async def test_krl_toml_of_the_backup_applies(client, backup_copy):
    (backup_copy / "krl.toml").write_text('[check]\nignore = ["E101"]\n[check.severity]\nE106 = "warning"\n')
    path = backup_copy / "R1" / "Program" / "main.src"
    text = MAIN_TEXT.replace("  counter = 0\n", "  countr = 0\n  nowhere( )\n")
    diags = await open_doc(client, path, text)
    # E101 (countr) ignored; E106 (nowhere) reported as a warning
    assert [(str(d.code), d.range.start.line, d.severity) for d in diags] == [("E106", 9, L.DiagnosticSeverity.Warning)]
    close_doc(client, path)


async def test_formatting_replaces_up_to_the_real_end_of_the_document(client, tmp_path):
    """The edit's end is the end of the last line in the client's position units (UTF-16 by
    default): '; Grüße 😀' is 10 units (the emoji is a surrogate pair), not 9 characters."""
    path = tmp_path / "fmt_end.src"
    text = "def t()\nend\n; Grüße 😀"
    await open_doc(client, path, text)
    edits = await client.text_document_formatting_async(L.DocumentFormattingParams(
        text_document=td(path), options=L.FormattingOptions(tab_size=2, insert_spaces=True)))
    assert len(edits) == 1 and edits[0].new_text.startswith("DEF t()\nEND\n")
    assert (edits[0].range.start.line, edits[0].range.start.character) == (0, 0)
    assert (edits[0].range.end.line, edits[0].range.end.character) == (2, 10)
    close_doc(client, path)


SHAPES = ("DEF shapes( )\n"                 # 0
          "  STRUC local_t INT a, b\n"       # 1  local_t at 8..15, a at 20, b at 23
          "  DECL local_t loc\n"             # 2  local_t at 7..14
          "  DECL pose_t p\n"                # 3  pose_t at 7..13: GLOBAL in tools.dat
          "  DECL tool_t t\n"                # 4  tool_t at 7..13: $config.dat
          "  loc.b = 1\n"                    # 5  b at 6
          "END\n")


async def hover(client, path, line, char) -> str:
    h = await client.text_document_hover_async(L.HoverParams(text_document=td(path), position=pos(line, char)))
    return h.contents.value if h is not None else ""


async def test_types_where_the_checker_declared_them(client, backup_copy):
    """A STRUC local to a routine, one GLOBAL in a .dat and one of $config.dat: go to definition
    and hover read the placement the checker's Declarer recorded (Scope.type_symbols)."""
    program, system = backup_copy / "R1" / "Program", backup_copy / "R1" / "System"
    shapes = program / "shapes.src"
    shapes.write_text(SHAPES)
    assert summary(await open_doc(client, shapes)) == []
    # uses -> declarations; tools.dat line 1 `  GLOBAL STRUC pose_t REAL x, y` (pose_t 15..21),
    # $config.dat line 2 `  STRUC tool_t REAL mass, INT id` (tool_t 8..14)
    assert await definition(client, shapes, 2, 9) == [("shapes.src", 1, 8, 1, 15)]
    assert await definition(client, shapes, 3, 8) == [("tools.dat", 1, 15, 1, 21)]
    assert await definition(client, shapes, 4, 10) == [("$config.dat", 2, 8, 2, 14)]
    assert await definition(client, shapes, 5, 6) == [("shapes.src", 1, 23, 1, 24)]     # loc.b -> component b
    # a declaration's own name is the type it entered
    assert await definition(client, shapes, 1, 12) == [("shapes.src", 1, 8, 1, 15)]
    assert await definition(client, program / "tools.dat", 1, 17) == [("tools.dat", 1, 15, 1, 21)]
    assert await definition(client, system / "$config.dat", 2, 8) == [("$config.dat", 2, 8, 2, 14)]
    # hover: the structure and where it is declared (1-based lines)
    assert await hover(client, shapes, 2, 9) == \
        "```krl\nSTRUC local_t INT a, INT b\n```\n\ndeclared in `R1/Program/shapes.src` line 2"
    assert await hover(client, shapes, 3, 8) == \
        "```krl\nSTRUC pose_t REAL x, REAL y\n```\n\ndeclared in `R1/Program/tools.dat` line 2"
    assert await hover(client, shapes, 4, 10) == \
        "```krl\nSTRUC tool_t REAL mass, INT id\n```\n\ndeclared in `R1/System/$config.dat` line 3"
    close_doc(client, shapes)
