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

from krl.survey.mutants import EXPECTED, load_programs, mutants

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
        assert m.text.splitlines()[m.line - 1].strip() == m.inserted, (m.path, m.line)
        assert m.expected == EXPECTED[m.kind]


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
