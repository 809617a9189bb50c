"""Rename over LSP (prepareRename + rename). Positions are 0-based and counted by hand from the
fixture backup: main.src line 8 is ``  counter = 0`` (counter at 2..9), line 10
``    counter = counter + i`` (4..11, 14..21, i at 24), $config.dat line 1 ``  DECL INT counter``
(11..18), main.dat line 1 ``  EXT helper(INT :IN)`` (helper at 6), main.src line 14
``    helper(local_count)`` (4), tools.src line 3 ``GLOBAL DEF helper(n:IN)`` (helper at 11, n at 18)."""

from __future__ import annotations

from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest
from lsprotocol import types as L
from pygls.exceptions import JsonRpcException

from tests.lsp.conftest import PROGRAM, open_doc, pos

pytestmark = pytest.mark.asyncio(loop_scope="module")

MAIN = PROGRAM / "main.src"
PALLETIZER = "ingeniado__KRC4-Robot-Palletizer"


def td(path) -> L.TextDocumentIdentifier:
    return L.TextDocumentIdentifier(uri=path.as_uri())


def edits(got: L.WorkspaceEdit) -> dict[str, list[tuple[int, int, int, int, str]]]:
    out = {}
    for uri, es in (got.changes or {}).items():
        out[Path(unquote(urlparse(uri).path)).name] = sorted(
            (e.range.start.line, e.range.start.character, e.range.end.line, e.range.end.character, e.new_text) for e in es)
    return out


async def rename(client, path, line, char, new):
    return await client.text_document_rename_async(L.RenameParams(text_document=td(path), position=pos(line, char), new_name=new))


async def refused(client, path, line, char, new) -> str:
    with pytest.raises(JsonRpcException) as exc:
        await rename(client, path, line, char, new)
    return str(exc.value)


async def test_rename_config_variable_across_src_and_config_dat(client):
    await open_doc(client, MAIN)
    got = await rename(client, MAIN, 10, 16, "cycles")
    assert edits(got) == {
        "main.src": [(8, 2, 8, 9, "cycles"), (10, 4, 10, 11, "cycles"), (10, 14, 10, 21, "cycles")],
        "$config.dat": [(1, 11, 1, 18, "cycles")],
    }


async def test_rename_routine_from_a_call_renames_def_ext_and_calls(client):
    await open_doc(client, MAIN)
    got = await rename(client, MAIN, 14, 6, "assist")
    assert edits(got) == {
        "main.dat": [(1, 6, 1, 12, "assist")],
        "main.src": [(14, 4, 14, 10, "assist")],
        "tools.src": [(3, 11, 3, 17, "assist")],
    }


async def test_rename_local_and_parameter_stay_in_their_routine(client):
    await open_doc(client, MAIN)
    # i: DECL INT i (line 2, char 11), FOR i (9, 6), + i (10, 24)
    got = await rename(client, MAIN, 9, 6, "k")
    assert edits(got) == {"main.src": [(2, 11, 2, 12, "k"), (9, 6, 9, 7, "k"), (10, 24, 10, 25, "k")]}
    # the parameter n of helper: header (3, 18), DECL INT n (4, 11), shared = n (5, 11)
    got = await rename(client, PROGRAM / "tools.src", 5, 11, "count")
    assert edits(got) == {"tools.src": [(3, 18, 3, 19, "count"), (4, 11, 4, 12, "count"), (5, 11, 5, 12, "count")]}


async def test_rename_label(client):
    await open_doc(client, MAIN)
    got = await rename(client, MAIN, 17, 3, "finish")         # `  done:` line 17; GOTO done line 16 char 7
    assert edits(got) == {"main.src": [(16, 7, 16, 11, "finish"), (17, 2, 17, 6, "finish")]}


async def test_prepare_rename_range_and_refusals(client):
    await open_doc(client, MAIN)
    got = await client.text_document_prepare_rename_async(L.PrepareRenameParams(text_document=td(MAIN), position=pos(8, 5)))
    assert (got.range.start, got.range.end, got.placeholder) == (pos(8, 2), pos(8, 9), "counter")
    with pytest.raises(JsonRpcException) as exc:
        await client.text_document_prepare_rename_async(L.PrepareRenameParams(text_document=td(MAIN), position=pos(18, 3)))
    assert "'$OUT' is a system variable" in str(exc.value)
    with pytest.raises(JsonRpcException) as exc:        # `p.x`: x is a component
        await client.text_document_prepare_rename_async(L.PrepareRenameParams(text_document=td(MAIN), position=pos(11, 6)))
    assert "structure component" in str(exc.value)


async def test_rename_refused_for_clashes_and_bad_names(client):
    await open_doc(client, MAIN)
    assert "'p' already names a variable of routine main" in await refused(client, MAIN, 9, 6, "p")
    # a local i renamed to the global counter would hide it
    assert "'counter' would hide a variable of the global data" in await refused(client, MAIN, 9, 6, "counter")
    # the global shared renamed to n: helper's parameter n would hide it inside helper
    msg = await refused(client, PROGRAM / "tools.src", 5, 3, "n")
    assert "'n' is a parameter of routine helper, which would hide the renamed 'shared' there" in msg
    assert "'ENDIF' is a KRL keyword" in await refused(client, MAIN, 9, 6, "ENDIF")
    assert "system name" in await refused(client, MAIN, 9, 6, "$k")
    assert "at most 24" in await refused(client, MAIN, 9, 6, "a" * 25)
    assert "main routine" in await refused(client, MAIN, 1, 5, "start")


async def test_rename_refused_when_declared_twice_or_in_a_broken_file(client, backup_copy):
    program = backup_copy / "R1" / "Program"
    main = program / "main.src"
    # a second GLOBAL `shared` in main.dat: E102, which of the two is meant is ambiguous
    dat = (program / "main.dat").read_text().replace("ENDDAT", "  DECL GLOBAL INT shared = 1\nENDDAT")
    await open_doc(client, program / "main.dat", dat)
    await open_doc(client, main)
    assert "declared more than once" in await refused(client, program / "tools.src", 5, 3, "common")
    # a file with a syntax error that names the variable: its uses there are unknown
    (program / "main.dat").write_text((program / "main.dat").read_text())
    broken = main.read_text().replace("IF run_mode == #auto THEN", "IF run_mode == #auto")
    await open_doc(client, main, broken, version=2)
    assert "main.src, which has syntax errors" in await refused(client, backup_copy / "R1" / "System" / "$config.dat", 5, 16, "mode2")


async def test_rename_on_a_real_backup(client, shared_corpus):
    """SALIR (``DECL BOOL SALIR=FALSE``, $config.dat line 768, 0-based 767, char 10) is used in 21
    programs of the palletizer backup: 41 places by `grep -rniw SALIR` without comment lines."""
    root = shared_corpus / PALLETIZER
    coge = root / "Program" / "CAJA_G" / "coge_g.src"
    await open_doc(client, coge)
    got = edits(await rename(client, coge, 59, 5, "SALIDA"))      # line 60 `   SALIR = TRUE`
    assert got["coge_g.src"] == [(59, 3, 59, 8, "SALIDA"), (72, 3, 72, 8, "SALIDA")]
    assert got["$config.dat"] == [(767, 10, 767, 15, "SALIDA")]
    assert got["caja_g_m1.src"] == [(90, 3, 90, 8, "SALIDA"), (261, 0, 261, 5, "SALIDA")]
    assert sum(len(v) for v in got.values()) == 41
    assert len(got) == 22
