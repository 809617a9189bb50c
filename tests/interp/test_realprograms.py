"""The real-programs run over the KRC backups of ../shared/krl-corpus (skipped when absent)."""

from __future__ import annotations

import pytest

from interp import realprograms as rp

pytestmark = [pytest.mark.corpus,
              pytest.mark.skipif(not rp.DEFAULT_CORPUS.is_dir(), reason="../shared/krl-corpus absent")]


def test_backups_found_and_a_few_programs_run():
    backups = rp.find_backups(rp.DEFAULT_CORPUS)
    assert backups
    progs = [p for b in backups for p in rp.programs_of(b)][:4]
    rows = [rp.run_one(p, max_sim_time=5.0, max_steps=20_000) for p in progs]
    assert all(r["reason"] != "internal" for r in rows), rows
    text = rp.report(rows)
    assert text.startswith(f"{len(rows)} programs:")


@pytest.mark.slow
def test_all_backup_programs():
    rows = []
    for b in rp.find_backups(rp.DEFAULT_CORPUS):
        for p in rp.programs_of(b):
            rows.append(rp.run_one(p, 60.0, 300_000))
    assert not [r for r in rows if r["reason"] == "internal"]
    print(rp.report(rows))
