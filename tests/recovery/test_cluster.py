"""Clustering: one missing construct is one cluster, however many files and lines show it."""

from __future__ import annotations

from pathlib import Path

import pytest

from recovery.cluster import cluster_results
from recovery.grammar_versions import committed_versions, parser_dir_for, python_target
from recovery.scan import scan
from krl.syntax.engines import java

# Clustering is tested against the first, restrictive grammar, where spline blocks and
# `INTERRUPT ... DO BRAKE` are missing constructs, so the test does not move as the grammar grows.


@pytest.fixture(scope="module")
def first_grammar() -> tuple[str, str]:
    first = committed_versions()[0]
    # Build the version's Java parser here, once: built on first use inside a scan worker,
    # javac ran within the per-file timeout, which a loaded machine exceeded (the file then
    # became an "internal | parser failure" row).
    # Its Python parser (the scan's parse of a file the Java engine leaves to it) in the same JVM
    # (KrlBuild, as `krl growth` builds versions): one start and JIT warm-up for the ANTLR tool's
    # two runs and javac (5.5-6.1 -> 3.7-4.0 s of CPU, 2026-11-29).
    if java.unavailable_reason() is None:
        java.build_many([("java", first.text, java.java_target(first.text)),
                         ("python", first.text, python_target(first.text))])
        java.grammar_classes(first.text)
    return first.sha, str(parser_dir_for(first.text))


def write(tmp: Path, name: str, text: str) -> None:
    (tmp / name).write_bytes(text.encode("utf-8"))


SPLINE_BLOCK = ("SPLINE WITH $VEL = {CP 0.2}\n  SPL P1\n  SPL P2 WITH $VEL = {CP 0.1}\n"
                "  SLIN P3\nENDSPLINE C_SPL\n")


def run(tmp: Path, grammar: tuple[str, str]):
    gsha, parser_dir = grammar
    # These tests are about clustering, not about the per-file timeout (tests/recovery/
    # test_bad_input.py): a generous one keeps a worker's JVM start on a loaded machine in.
    return cluster_results(scan(tmp, gsha, parser_dir=parser_dir, jobs=1, use_cache=False, progress=False,
                                timeout=600))


def test_same_construct_in_two_files_shares_one_cluster(tmp_path: Path, first_grammar) -> None:
    # An unknown block (a spline block in the starting grammar's terms) in two files,
    # with different names and numbers: one cluster, two files, and the inner lines of
    # the block are follow-on errors, not clusters of their own.
    write(tmp_path, "a.src", "DEF a()\n  x = 1\n" + SPLINE_BLOCK + "  x = 2\nEND\n")
    write(tmp_path, "b.src", "DEF b()\n" + SPLINE_BLOCK.replace("P1", "XP7").replace("0.2", "2") + "END\n")
    clusters = run(tmp_path, first_grammar)
    assert len(clusters) == 1
    assert clusters[0].files == 2
    assert clusters[0].leading_keyword == "SPLINE"


def test_different_constructs_get_different_clusters(tmp_path: Path, first_grammar) -> None:
    write(tmp_path, "a.src", "DEF a()\n" + SPLINE_BLOCK + "END\n")
    write(tmp_path, "b.src", "DEF b()\n  INTERRUPT DECL 3 WHEN $IN[1] DO BRAKE\nEND\n")
    write(tmp_path, "c.src", "DEF c()\n  INTERRUPT DECL 4 WHEN $IN[2] DO BRAKE\n  x = 1\n"
                             "  INTERRUPT DECL 5 WHEN $IN[3] DO BRAKE\nEND\n")
    clusters = run(tmp_path, first_grammar)
    by_kw = {c.leading_keyword: c for c in clusters}
    assert set(by_kw) == {"SPLINE", "INTERRUPT"}
    assert by_kw["INTERRUPT"].files == 2
    assert by_kw["INTERRUPT"].occurrences == 3
    # Ranked by files, then occurrences.
    assert clusters[0].leading_keyword == "INTERRUPT"


def test_file_with_two_constructs_counts_in_both(tmp_path: Path, first_grammar) -> None:
    write(tmp_path, "a.src", "DEF a()\n" + SPLINE_BLOCK + "  x = 1\n"
                             "  INTERRUPT DECL 3 WHEN $IN[1] DO BRAKE\nEND\n")
    clusters = run(tmp_path, first_grammar)
    assert sorted(c.leading_keyword for c in clusters) == ["INTERRUPT", "SPLINE"]
    assert all(c.files == 1 for c in clusters)


def test_failed_block_opener_does_not_cascade(tmp_path: Path, first_grammar) -> None:
    # `IF a = 1 THEN` fails on its opener line; its ENDIF must not become a second cluster.
    write(tmp_path, "a.src", "DEF a()\n  IF a = 1 THEN\n    x = 1\n  ENDIF\nEND\n")
    clusters = run(tmp_path, first_grammar)
    assert len(clusters) == 1
    assert clusters[0].leading_keyword == "IF"


def test_lexer_errors_form_their_own_cluster(tmp_path: Path, first_grammar) -> None:
    write(tmp_path, "a.src", "DEF a()\n  x = 1 ? 2\nEND\n")
    write(tmp_path, "b.src", "DEF b()\n  y = ?\nEND\n")
    clusters = run(tmp_path, first_grammar)
    lexer = [c for c in clusters if c.signature.startswith("lexer")]
    assert len(lexer) == 1 and lexer[0].files == 2
