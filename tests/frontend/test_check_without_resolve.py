"""The checker's commands check without placing storage (krl/workspace.py ``Workspace.check``,
``resolve=False``): ``krl check``, the audit's check, the program map, the survey and the
seeded-error recall never run a program, and the resolver (krl/semantics/resolve.py) was two
thirds of their check. The resolver reports nothing, so the diagnostics are those of a full
check; a workspace checked so and then asked for a full check (a run) gets its places then.

Expected values: the full check of the same files (``resolve=True``), on two of the corpus's
KRC backups (material nobody here wrote)."""

from __future__ import annotations

import pytest

from krl.parsecache import through_store
from krl.project import find_backups
from krl.workspace import load_workspace


def _loaded(b):
    with through_store():           # each file's parse from the one store, as krl check reads it
        return load_workspace([b], str(b))


def _diags(ws) -> list[tuple]:
    return [(d.path, d.line, d.column, d.code, d.message) for d in ws.diagnostics]


@pytest.fixture(scope="module")
def backups(shared_corpus):
    found = find_backups(shared_corpus)
    assert len(found) >= 4
    return found


def _smallest(backups, n):
    return sorted(backups, key=lambda b: sum(1 for _ in b.rglob("*")))[:n]


def test_the_diagnostics_are_a_full_checks(backups):
    # two backups (12 s for all four; tests/frontend/test_corpus.py holds krl check's findings
    # on all four to the errors read in their files)
    for b in _smallest(backups, 2):
        full = _loaded(b)
        full.check()
        light = _loaded(b)
        light.check(resolve=False)
        assert full.resolver is not None and light.resolver is None, b
        assert _diags(light) == _diags(full), b
        assert _diags(light), f"{b}: no diagnostic at all (the comparison would be vacuous)"


def _with_facts(ws) -> list:
    """The top-level statements of the workspace's routines that carry the resolver's advance-run
    facts (``ann.info``)."""
    return [n for u in ws.units if u.src is not None for r in u.src.module.routines
            for n in r.body if getattr(n, "ann", None) is not None and getattr(n.ann, "info", None) is not None]


def test_a_later_full_check_places_the_storage(backups):
    ws = _loaded(_smallest(backups, 1)[0])
    ws.check(resolve=False)
    first = _diags(ws)
    assert ws.resolver is None and _with_facts(ws) == [], "the checker alone placed storage"
    ws.check()                      # a run's check: the places are made now, the findings stay
    assert ws.resolver is not None
    assert _diags(ws) == first
    assert _with_facts(ws), "no statement got its advance-run facts from the resolver"
