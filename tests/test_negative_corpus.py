"""The negative corpus: every program in tests/negative/ is invalid KRL and must be rejected.

Each file is a small valid program with exactly one syntax mutation (see tests/negative/README.md
and tests/negative/generate.py). The grammar grows over time; it must keep rejecting all of them.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from krl.syntax.parse import parse_file

NEGATIVE_DIR = Path(__file__).resolve().parent / "negative"


def generator():
    """tests/negative/generate.py, loaded from its path (it is no module of a package)."""
    spec = importlib.util.spec_from_file_location("negative_generate", NEGATIVE_DIR / "generate.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module          # its dataclasses look their module up there
    spec.loader.exec_module(module)
    return module

NEGATIVE_FILES = sorted(p for p in NEGATIVE_DIR.iterdir()
                        if p.name.startswith("neg_") and p.suffix.lower() in (".src", ".dat", ".sub"))

def test_at_least_150_negative_programs():
    assert len(NEGATIVE_FILES) >= 150


def test_every_file_names_its_mutation():
    for path in NEGATIVE_FILES:
        first = path.read_text(encoding="utf-8").splitlines()[0]
        assert first.startswith("; NEGATIVE: ") and "(reference " in first, path.name


def test_generated_files_are_up_to_date():
    generate = generator()
    expected = generate.generate()
    assert sorted(expected) == [p.name for p in NEGATIVE_FILES]
    for name, text in expected.items():
        assert (NEGATIVE_DIR / name).read_text(encoding="utf-8") == text, name


@pytest.mark.parametrize("path", NEGATIVE_FILES, ids=[p.name for p in NEGATIVE_FILES])
def test_negative_program_is_rejected(path: Path):
    result = parse_file(path, keep_tree=False)
    assert result.ok is False, f"{path.name}: invalid program accepted by the grammar"
