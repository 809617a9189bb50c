"""The recorded session of docs/editors.md is what `krl debug` does today on the corpus
program (interp/debug/transcript.py), and it shows what the issue asks: a breakpoint, a
motion stepped through, `$POS_ACT` and an output watched, steps back."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from interp.debug import transcript

DOC = Path(__file__).resolve().parents[2] / "docs" / "editors.md"

# the tests share the module's one recording (`recorded`): one xdist worker takes them (make test:
# --dist loadgroup; spread over two workers, each recorded it: 1.5 s of CPU each, 2026-11-27)
pytestmark = pytest.mark.xdist_group("debug-transcript")


@pytest.fixture(scope="module")
def recorded(shared_corpus):
    if not transcript.PROGRAM.is_file():
        pytest.fail(f"the corpus program {transcript.PROGRAM} is missing")
    return "\n".join(transcript.record())


def results(text: str, expr: str) -> list[str]:
    """The results of the watch `expr`, in order."""
    out = []
    lines = text.splitlines()
    for i, ln in enumerate(lines):
        if f'"expression": "{expr}"' in ln.replace("\\", ""):
            m = re.search(r'"result": "([^"]*)"', lines[i + 1])
            out.append(m.group(1))
    return out


def test_transcript_in_the_docs_is_current(recorded):
    doc = DOC.read_text(encoding="utf-8")
    m = re.search(r"<!-- transcript:begin -->\n(.*?)\n<!-- transcript:end -->", doc, re.S)
    assert m is not None and m.group(1).strip() == recorded.strip()


def test_transcript_shows_the_motion_and_the_step_back(recorded):
    pos = results(recorded, "$POS_ACT")
    out = results(recorded, "$OUT[5]")
    # at the breakpoint (l.27), after the PTP of l.28, after stepBack to l.28, after stepBack to l.27
    assert out == ["FALSE", "TRUE", "TRUE", "FALSE"]
    # l.28: PTP {X 281.36, Y 304.25, Z 459.51, A 0, B 90, C 0}: reached exactly in #MSTEP
    assert pos[1].startswith("{X 281.36, Y 304.25, Z 459.51, A 0.0, B 90.0, C 0.0")
    assert pos[0] == pos[2] == pos[3] != pos[1]          # stepBack restores the pose
