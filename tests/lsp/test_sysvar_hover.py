"""Every system variable the KRL reference names has a hover that gives its section.

The names and the sections that mention them are read here from the reference itself
(../shared/docs/krl-reference.md): every ``$NAME`` and the numbered heading it stands under.
The names that are no variable are the system data lists (``$config.dat`` ... named as
``$NAME.dat`` in 2.5) and ``$PARAM`` (a CHANNEL parameter, 2.5); every other one must be a
system variable of the tables, and its hover must cite a section that names it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from lsprotocol import types as L

from tests.lsp.conftest import open_doc, pos

pytestmark = pytest.mark.asyncio(loop_scope="module")

REFERENCE = Path(__file__).resolve().parents[2].parent / "shared" / "docs" / "krl-reference.md"


def reference_names() -> dict[str, set[str]]:
    """$NAME (upper case) -> the numbers of the sections whose text names it."""
    out: dict[str, set[str]] = {}
    section = ""
    for line in REFERENCE.read_text(encoding="utf-8").splitlines():
        m = re.match(r"#+ (\d+(?:\.\d+)*)", line)
        if m:
            section = m.group(1)
        for name in re.findall(r"\$[A-Za-z_][A-Za-z0-9_]*", line):
            out.setdefault(name.upper(), set()).add(section)
    return out


@pytest.mark.may_skip("the shared reference ../shared/docs/krl-reference.md is absent")
async def test_every_reference_system_variable_has_a_hover_with_its_section(client, tmp_path):
    if not REFERENCE.exists():
        pytest.skip("no reference")
    names = reference_names()
    text = REFERENCE.read_text(encoding="utf-8").lower()
    data_lists = {n for n in names if f"{n.lower()}.dat" in text}
    assert data_lists == {"$CONFIG", "$CUSTOM", "$MACHINE", "$OPERATE", "$OPERATE_R1", "$OPTION", "$ROBCOR"}
    variables = sorted(set(names) - data_lists - {"$PARAM"})
    assert len(variables) > 100
    path = tmp_path / "probe.src"
    lines = ["DEF probe( )"] + [f"  WAIT FOR {n} == {n}" for n in variables] + ["END"]
    await open_doc(client, path, "\n".join(lines) + "\n")
    missing = []
    for i, name in enumerate(variables, start=1):
        got = await client.text_document_hover_async(L.HoverParams(
            text_document=L.TextDocumentIdentifier(uri=path.as_uri()), position=pos(i, 12)))
        value = got.contents.value if got is not None else ""
        cited = re.findall(r"\(reference (\d+(?:\.\d+)*)\)", value)
        if not cited or cited[0] not in names[name]:
            missing.append((name, cited, sorted(names[name])))
    assert missing == []


async def test_hover_of_a_system_variable_on_a_real_backup(client, shared_corpus):
    """coge_25.src line 12 ``    GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )``
    ($STOPMESS at 33): reference 7.5 lists it (BOOL, RO)."""
    path = shared_corpus / "ingeniado__KRC4-Robot-Palletizer" / "Program" / "SACO_25" / "coge_25.src"
    await open_doc(client, path)
    got = await client.text_document_hover_async(L.HoverParams(
        text_document=L.TextDocumentIdentifier(uri=path.as_uri()), position=pos(11, 35)))
    assert "(reference 7.5)" in got.contents.value and "write-protected" in got.contents.value
