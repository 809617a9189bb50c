"""The real-programs run over the KRC backups of ../shared/krl-corpus (skipped when absent)."""

from __future__ import annotations

from pathlib import Path

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
    assert text.startswith(f"{len(rows)} programs by cause:")
    assert all(r["cause"] in rp.CAUSES for r in rows)


@pytest.mark.slow
def test_all_backup_programs():
    rows = []
    for b in rp.find_backups(rp.DEFAULT_CORPUS):
        for p in rp.programs_of(b):
            rows.append(rp.run_one(p, 60.0, 300_000, rp.cell_of(p)))
    assert not [r for r in rows if r["reason"] == "internal"]
    print(rp.report(rows))


def test_every_stop_gets_one_cause():
    """interp/realprograms.py cause_of (issue 22, "Every stop explained")."""
    from interp.realprograms import cause_of

    assert cause_of({"reason": "completed"}) == "completed"
    assert cause_of({"reason": "halt", "file": "p.src", "line": 9}) == "intended end"
    assert cause_of({"reason": "error", "text": "unknown name t_vel"}) == "program error"
    assert cause_of({"reason": "error", "text": "workspace error: target not reachable"}) == "interpreter gap"
    assert cause_of({"reason": "internal", "text": "KeyError"}) == "interpreter gap"
    # a cycle loop stopped by the limit while its cell answers: answers until 58 s of 60 s
    assert cause_of({"reason": "max_sim_time", "sim_time": 60.0, "cell_answers": 29, "cell_last": 58.0}) \
        == "intended end"
    # the cell answered once at the start, then the program starved: a limit
    assert cause_of({"reason": "max_steps", "sim_time": 60.0, "cell_answers": 6, "cell_last": 2.0}) == "limit"
    assert cause_of({"reason": "max_sim_time", "sim_time": 60.0, "cell_answers": 0}) == "limit"


def test_committed_cell_files_load_and_are_found():
    """Every corpus/cells file is a valid cell file; cell_of prefers the program's own file."""
    from interp.realprograms import CELLS, cell_of
    from robot.stimuli import load_cell

    files = sorted(CELLS.rglob("*.yaml"))
    assert len(files) >= 4
    for f in files:
        cell = load_cell(f)
        assert cell.rules or cell.autoext or cell.pgno
    corpus = Path("/corpus")
    assert cell_of(corpus / "khrzysio__KRC4_test/R1/CELL.src", corpus) == CELLS / "khrzysio__KRC4_test/cell.yaml"
    assert cell_of(corpus / "khrzysio__KRC4_test/R1/Program/a.src", corpus) == CELLS / "khrzysio__KRC4_test.yaml"
    assert cell_of(corpus / "nobody/R1/a.src", corpus) is None
