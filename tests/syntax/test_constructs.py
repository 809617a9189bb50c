"""Every grammar construct's examples run in `make test` (not only in `make validate`).

grammar/constructs/<name>/: each ok_* example parses and builds to the statement kinds its
.expect file lists (written by hand from the reference, in KRL words); each bad_* near-miss is
rejected. Every construct has at least one of each, and every ok example has its .expect.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from krl.source import is_krl_file
from recovery.validate import CONSTRUCTS, check_example

EXAMPLES = sorted(p for d in CONSTRUCTS.iterdir() if d.is_dir() for p in d.iterdir()
                  if is_krl_file(p) and p.name.startswith(("ok_", "bad_")))


def test_every_construct_has_positive_and_negative_examples() -> None:
    dirs = sorted(d for d in CONSTRUCTS.iterdir() if d.is_dir())
    assert len(dirs) >= 31
    for d in dirs:
        names = [p.name for p in d.iterdir() if is_krl_file(p)]
        assert any(n.startswith("ok_") for n in names), f"{d.name}: no positive example"
        assert any(n.startswith("bad_") for n in names), f"{d.name}: no negative example"


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_example(path: Path) -> None:
    if path.name.startswith("ok_"):
        assert path.with_suffix(".expect").exists(), f"{path}: no .expect (statement kinds by hand)"
    result = check_example(path)
    assert result.passed, f"{result.path}: {result.detail}"
