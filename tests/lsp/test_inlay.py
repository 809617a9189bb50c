"""Inlay hints over LSP: I/O names and long texts from SIGNAL declarations, parameter names at
calls. Positions are 0-based and counted by hand: main.src line 5 is
``  INTERRUPT DECL 3 WHEN $IN[1] DO on_stop( )`` ($IN[1] ends at char 30), line 14
``    helper(local_count)`` (the argument at 11), line 18 ``  $OUT[2] = TRUE`` (``]`` at 8, end 9);
$config.dat declares ``SIGNAL stop_btn $IN[1] ;Stop button of the cell``, ``SIGNAL lamp $OUT[2]``
and the group ``SIGNAL code $OUT[3] TO $OUT[5]``."""

from __future__ import annotations

import pytest
from lsprotocol import types as L

from tests.lsp.conftest import PROGRAM, open_doc, pos

pytestmark = pytest.mark.asyncio(loop_scope="module")

MAIN = PROGRAM / "main.src"


async def hints(client, path, first=0, last=10_000):
    got = await client.text_document_inlay_hint_async(L.InlayHintParams(
        text_document=L.TextDocumentIdentifier(uri=path.as_uri()), range=L.Range(start=pos(first, 0), end=pos(last, 0))))
    return [(h.position.line, h.position.character, h.label, h.kind) for h in got or []]


async def test_io_names_and_parameter_names_on_the_fixture(client):
    await open_doc(client, MAIN)
    assert await hints(client, MAIN) == [
        (5, 30, "stop_btn: Stop button of the cell", L.InlayHintKind.Type),
        (14, 11, "n:", L.InlayHintKind.Parameter),      # helper's DEF names it n (the EXT does not)
        (18, 9, "lamp", L.InlayHintKind.Type),
    ]
    assert await hints(client, MAIN, 14, 15) == [(14, 11, "n:", L.InlayHintKind.Parameter)]


async def test_signal_group_bits_and_undeclared_io(client, backup_copy):
    main = backup_copy / "R1" / "Program" / "main.src"
    text = main.read_text().replace("  $OUT[2] = TRUE\n", "  $OUT[4] = $IN[7]\n")
    await open_doc(client, main, text)
    # `  $OUT[4] = $IN[7]`: $OUT[4] is bit 1 of code ($OUT[3] TO $OUT[5]); $IN[7] has no SIGNAL
    assert [h for h in await hints(client, main) if h[0] == 18] == [(18, 9, "code[bit 1]", L.InlayHintKind.Type)]


async def test_io_long_text_and_parameters_on_a_real_backup(client, shared_corpus):
    """rawpython__kukaKRLmagic: R1/System/$config.dat line 870 ``SIGNAL O_ALARM $OUT[1] ;Lampada
    Allarme``, line 840 ``SIGNAL I_AUTO $IN[2] ; Sistema in AUTOMATICO``. An unsaved buffer in
    its R1/Program (not written to disk) uses both, and calls PULSE (reference 5.12: PULSE(signal, level, duration))."""
    root = shared_corpus / "rawpython__kukaKRLmagic"
    probe = root / "R1" / "Program" / "hint_probe.src"
    assert not probe.exists()
    text = ("DEF hint_probe( )\n"
            "  WAIT FOR $IN[2]\n"             # line 1: ] at 16 -> hint at 17
            "  $OUT[1] = FALSE\n"             # line 2: ] at 8 -> 9
            "  PULSE($OUT[1], TRUE, 0.5)\n"   # line 3: args at 8, 17, 23
            "END\n")
    await open_doc(client, probe, text)
    got = await hints(client, probe)
    assert got[:3] == [(1, 17, "I_AUTO: Sistema in AUTOMATICO", L.InlayHintKind.Type),
                       (2, 9, "O_ALARM: Lampada Allarme", L.InlayHintKind.Type),
                       (3, 8, "SIGNAL:", L.InlayHintKind.Parameter)]
    assert (3, 15, "O_ALARM: Lampada Allarme", L.InlayHintKind.Type) in got
    assert [h[:3] for h in got if h[0] == 3 and h[3] == L.InlayHintKind.Parameter][1:] == [(3, 17, "LEVEL:"), (3, 23, "DURATION:")]
