"""The checker's commands check without placing storage (krl/workspace.py ``Workspace.check``,
``resolve=False``): ``krl check``, the audit's check, the program map, the survey and the
seeded-error recall never run a program, and the resolver (krl/semantics/resolve.py) was two
thirds of their check. The resolver reports nothing, so the diagnostics are those of a full
check (tests/frontend/test_corpus.py compares them with its full checks of the corpus's
backups); a workspace checked so and then asked for a full check (a run) gets its places then.

Expected values: the full check of the same files (``resolve=True``), on a KRC backup of the
corpus (material nobody here wrote)."""

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


def smallest(backups, n):
    """The `n` backups of `backups` with the fewest files and folders."""
    return sorted(backups, key=lambda b: sum(1 for _ in b.rglob("*")))[:n]


def light_check(backup):
    """The workspace of `backup` (its files' parses from the one store, as krl check reads them)
    checked without placing storage."""
    ws = _loaded(backup)
    ws.check(resolve=False)
    return ws


@pytest.fixture(scope="module")
def backups(shared_corpus):
    found = find_backups(shared_corpus)
    assert len(found) >= 4
    return found


def _with_facts(ws) -> list:
    """The top-level statements of the workspace's routines that carry the resolver's advance-run
    facts (``ann.info``)."""
    return [n for u in ws.units if u.src is not None for r in u.src.module.routines
            for n in r.body if getattr(n, "ann", None) is not None and getattr(n.ann, "info", None) is not None]


def test_a_later_full_check_places_the_storage(backups):
    ws = light_check(smallest(backups, 1)[0])
    first = _diags(ws)
    assert ws.resolver is None and _with_facts(ws) == [], "the checker alone placed storage"
    ws.check()                      # a run's check: the places are made now, the findings stay
    assert ws.resolver is not None
    assert _diags(ws) == first
    assert _with_facts(ws), "no statement got its advance-run facts from the resolver"
