"""krl fmt over the real corpus (../shared/krl-corpus, read in place): every file that parses
formats to text that parses to the same AST (positions and keyword case aside) and formats to
itself. `make test` runs a deterministic sample (every 8th file by sorted path, ~70 files,
about 20 s on one core); the full sweep (every file) is marked slow and runs in `make nightly`."""

from __future__ import annotations

from pathlib import Path

import pytest

from krl.ast.build import build_module
from krl.ast.compare import first_difference, same_tree
from krl.fmt import format_text
from krl.fmt.core import FormatOptions, format_parsed
from krl.diagnostics import DiagnosticSink
from krl.syntax.parse import parse_source, parse_text
from krl.source import is_krl_file, read_source

STRIDE = 8


def corpus_files(corpus: Path) -> list[Path]:
    return sorted(p for p in corpus.rglob("*") if p.is_file() and is_krl_file(p))


def formatted(text: str, parsed) -> str:
    """``format_text(text)``, given `parsed`, the parse of `text` (tree kept): format_text parses
    the text it formats, so a text already parsed here is formatted from that parse
    (format_parsed), where format_text would parse the very same text (no BOM to set aside, a
    last line ended); else format_text. Halves the parses of this test (4 -> 2 per file)."""
    if parsed.tree is None or text.startswith("\ufeff") or not text.endswith(("\n", "\r")):
        return format_text(text)
    out = format_parsed(text, parsed, FormatOptions())
    return text if out == text else out


def check_file(path: Path) -> str:
    """'skip' (does not parse), 'same' or 'changed'; asserts the two properties."""
    src = read_source(path)
    before = parse_source(src)
    if not before.ok:
        return "skip"
    a = build_module(before, DiagnosticSink())
    out = formatted(src.text, before)
    after = parse_text(out, str(path))
    assert after.ok, (path, [f"{e.line}:{e.column} {e.message}" for e in after.errors][:3])
    b = build_module(after, DiagnosticSink())
    assert same_tree(a, b, fold_keywords=True), (path, first_difference(a, b, True))
    assert formatted(out, after) == out, f"{path}: not idempotent"
    return "same" if out == src.text else "changed"


def sweep(files: list[Path]) -> dict[str, int]:
    counts = {"skip": 0, "same": 0, "changed": 0}
    for p in files:
        counts[check_file(p)] += 1
    return counts


def test_corpus_sample_keeps_ast_and_is_idempotent(shared_corpus):
    files = corpus_files(shared_corpus)[::STRIDE]
    counts = sweep(files)
    # the sample must exercise the formatter on real files, not only skip them
    assert counts["same"] + counts["changed"] >= len(files) // 2, counts
    assert counts["changed"] > 0, counts


@pytest.mark.slow
def test_corpus_every_file_keeps_ast_and_is_idempotent(shared_corpus):
    files = corpus_files(shared_corpus)
    counts = sweep(files)
    assert counts["same"] + counts["changed"] >= len(files) // 2, counts
