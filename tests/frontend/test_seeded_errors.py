"""Recall of `krl check`: seeded semantic errors in valid programs of the corpus's backups.

krl/survey/mutants.py inserts one error line into a copy of a valid user program (17 kinds:
misspelled variable, wrong argument count, REAL into an ENUM, write to $IN, undeclared routine,
type mismatch in an aggregate, assignment to a CONST, non-BOOL IF/WAIT FOR condition, GOTO to
a missing label, duplicate declaration, EXIT outside a loop, RETURN value in a procedure,
operator types, function called as a statement, argument type, REAL FOR counter). The expected
code of each kind is fixed by the reference (2.3-2.7, 3.9, 5.x), not taken from the checker.
Every mutant must be reported as an error with that code at the inserted line.
"""

from __future__ import annotations

import pytest

from krl.diagnostics.render import split_lines
from krl.source import read_source
from krl.survey.mutants import EXPECTED, load_programs, mutants

#: the kinds that insert two lines (the statement and its closer)
TWO_LINE_KINDS = ("if_condition_not_bool", "for_counter_not_int")

# the tests share the module's mutants, each checked in its backup (30 s of CPU): one xdist worker
# takes them (make test: --dist loadgroup)
pytestmark = [pytest.mark.xdist_group("seeded-errors")]


@pytest.fixture(scope="module")
def programs(shared_corpus):
    progs = load_programs(shared_corpus)
    assert len(progs) >= 20, "too few valid user programs in the corpus's backups"
    return progs


@pytest.fixture(scope="module")
def seeded(shared_corpus, programs):
    return mutants(shared_corpus, programs=programs)


def test_enough_mutants_of_enough_kinds(seeded):
    assert len(seeded) >= 60
    kinds = {m.kind for m in seeded}
    assert len(kinds) >= 8, kinds
    assert all(sum(m.kind == k for m in seeded) >= 3 for k in kinds)


def test_each_mutant_is_one_inserted_line_at_its_line(seeded):
    """The line a mutant names is the line it inserted, and the file gained only that text."""
    for m in seeded:
        lines = split_lines(m.text)
        assert lines[m.line - 1].strip() == m.inserted, (m.path, m.line)
        assert m.expected == EXPECTED[m.kind]
        inserted = 2 if m.kind in TWO_LINE_KINDS else 1
        assert lines[:m.line - 1] + lines[m.line - 1 + inserted:] == split_lines(read_source(m.path).text), \
            (m.kind, m.path)


def test_every_mutant_is_an_error_at_its_line(seeded):
    missed = [f"{m.kind}: {m.path}:{m.line}: {m.inserted!r} -> {m.reported}" for m in seeded if not m.found]
    recall = (len(seeded) - len(missed)) / len(seeded)
    print(f"checker recall: {len(seeded) - len(missed)}/{len(seeded)} = {recall:.1%}")
    assert not missed, "\n".join(missed)


def test_mutants_are_deterministic(shared_corpus, programs, seeded):
    again = mutants(shared_corpus, programs=programs, check=False)
    assert [(m.kind, m.path, m.line, m.inserted) for m in again] == \
        [(m.kind, m.path, m.line, m.inserted) for m in seeded]
    other = mutants(shared_corpus, programs=programs, seed=15, check=False)
    assert [(m.path, m.line) for m in other] != [(m.path, m.line) for m in seeded]


def test_a_line_break_only_python_sees_is_kept(tmp_path):
    """A form feed inside a comment is no line end for the KRL lexer (LF only): the mutant keeps
    it, inserts its line before the statement the lexer's line number names, and the file
    gains only that line. (str.splitlines cut the comment in two: its tail became a statement
    line, an error the mutant did not seed, and every later line moved by one.)"""
    (tmp_path / "KRC" / "R1" / "System").mkdir(parents=True)
    (tmp_path / "KRC" / "R1" / "System" / "$config.dat").write_text("DEFDAT $CONFIG\nENDDAT\n")
    prog = tmp_path / "KRC" / "R1" / "Program"
    prog.mkdir(parents=True)
    text = ("DEF feed()\n  DECL INT count\n  ; first page\x0csecond page of the comment\n"
            "  count = 1\n  count = count + 1\nEND\n")
    (prog / "feed.src").write_text(text)
    programs = load_programs(tmp_path)
    assert [p.src.path.endswith("feed.src") for p in programs] == [True]
    seeded = mutants(tmp_path, per_kind=1, programs=programs, check=True)
    assert any(m.kind == "misspelled_variable" for m in seeded)
    for m in seeded:
        lines = split_lines(m.text)
        assert lines[m.line - 1].strip() == m.inserted, (m.kind, lines)
        inserted = 2 if m.kind in TWO_LINE_KINDS else 1
        assert lines[:m.line - 1] + lines[m.line - 1 + inserted:] == split_lines(text), m.kind
        assert m.found, (m.kind, m.reported)
