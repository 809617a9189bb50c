"""Hints for variables never read (DiagnosticSeverity.Hint, DiagnosticTag.Unnecessary), counted
by hand: main.src line 3 ``  DECL pose_t p`` (p at 14) is assigned (``p.x = ...``) and never
read; ``  DECL INT i, spare`` (spare at 14) is never used; the other names of the fixture are read."""

from __future__ import annotations

import pytest
from lsprotocol import types as L

from tests.lsp.conftest import PROGRAM, open_doc

pytestmark = pytest.mark.asyncio(loop_scope="module")

MAIN = PROGRAM / "main.src"


def hints(diags):
    return sorted((d.range.start.line, d.range.start.character, d.range.end.character, d.message, tuple(d.tags or ()))
                  for d in diags if d.severity == L.DiagnosticSeverity.Hint)


async def test_never_read_on_the_fixture(client, backup_copy):
    U = (L.DiagnosticTag.Unnecessary,)
    assert hints(await open_doc(client, MAIN, hints=True)) == [(3, 14, 15, "'p' is assigned but never read", U)]
    main = backup_copy / "R1" / "Program" / "main.src"
    text = MAIN.read_text().replace("  DECL INT i\n", "  DECL INT i, spare\n")
    assert hints(await open_doc(client, main, text, hints=True)) == [
        (2, 14, 19, "'spare' is declared but never used", U), (3, 14, 15, "'p' is assigned but never read", U)]
    # module data: local_count of main.dat is read in main.src (helper(local_count)); none there
    assert hints(await open_doc(client, PROGRAM / "main.dat", hints=True)) == []


async def test_never_read_on_a_real_backup(client, shared_corpus):
    """coge_25.dat of the palletizer: line 15 ``DECL INT SUCCESS`` and line 22 ``DECL
    BASIS_SUGG_T LAST_BASIS=...`` are named nowhere in coge_25.src (grep -i); its other
    variables are read there."""
    dat = shared_corpus / "ingeniado__KRC4-Robot-Palletizer" / "Program" / "SACO_25" / "coge_25.dat"
    got = hints(await open_doc(client, dat, hints=True))
    assert [h[:4] for h in got] == [(14, 9, 16, "'SUCCESS' is declared but never used"),
                                    (21, 18, 28, "'LAST_BASIS' is declared but never used")]
