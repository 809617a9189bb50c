"""One decision on KUKA's software (issue 46), on material nobody here wrote: every entry point
of every backup of ../shared/krl-corpus and of ../shared/krl-history (both sides of each pair)
runs as a new user runs it (``--inputs auto``, nothing hand-written) for a bounded simulated
time, and no run — robot program or submit program — may stop on a name the checker classifies
outside the backup (krl/semantics/outside.py ``Unresolved.classify``: W101/W105/W106/W107): the
run stands in for each (interp/runtime/kss.py). ``interp.realprograms.outside_stops`` reads the
run's errors against the checker's classification of the same workspace.

Cost: about 290 entry points of 18 backups (``make test`` runs the corpus and each history
repository's newest version, the ``new`` side of its newest pair, :func:`earlier_version`;
``make nightly`` all), one test per backup (its files are loaded and
checked once, interp/runtime/program.py; ``make test``'s two workers share the backups), each
entry point bounded to :data:`SIM_TIME_S` simulated seconds and :data:`STEPS` statements (the
idle fast-forward makes a program that starves cheap): 2.8 s CPU for kukaKRLmagic's 3 entry
points, 6.6 s for ChinaMilling's 25 (2026-11-25). Skipped only where ../shared is absent and
CI is not set (tests/conftest.py turns any other skip into a failure).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from interp import realprograms as rp
from tests.conftest import SHARED, SHARED_CORPUS, SHARED_HISTORY, earlier_pair

pytestmark = [pytest.mark.corpus,
              pytest.mark.skipif(not (SHARED_CORPUS / "MANIFEST.csv").exists(), reason="../shared/krl-corpus absent")]

#: the bound of each run: simulated seconds (a program that starves is fast-forwarded) and
#: statements of the robot program (the submit program's are added, realprograms.step_limit)
SIM_TIME_S = 20.0
STEPS = 100_000


def backups() -> list[Path]:
    """Every backup of the corpus, then of each side of each history pair."""
    roots = list(rp.find_backups(SHARED_CORPUS)) if SHARED_CORPUS.is_dir() else []
    if SHARED_HISTORY.is_dir():
        for side in ("old", "new"):
            for folder in sorted(SHARED_HISTORY.glob(f"*/*/{side}")):
                roots += rp.find_backups(folder)
    return roots


def earlier_version(root: Path) -> bool:
    """`root` is an earlier version of a history repository's backup than its newest: a side of
    a pair older than the repository's newest pair (the pairs ``NN-sha`` are numbered in commit
    order; earlier pairs hold earlier versions of the same backups: ChinaMilling's first three
    pairs, 6 sides, were 60 of the module's 71 s of CPU), or the ``old`` side of the newest pair
    (the version before its commit: ChinaMilling's 04 differs from its ``new`` side in sps.sub
    alone; rawpython's 03 ``old`` holds bas.src, Mada and operate.dat, which the corpus's
    rawpython backup holds too; 2.5 of the module's 30 s of CPU, 2026-11-28). ``make test`` runs
    the corpus and each repository's newest version (the ``new`` side of its newest pair);
    ``make nightly`` runs every side."""
    try:
        rel = root.relative_to(SHARED_HISTORY)
    except ValueError:
        return False
    return earlier_pair(f"{rel.parts[0]}/{rel.parts[1]}") or rel.parts[2] == "old"


def stops_of_backup(root: Path) -> list[tuple[str, str, list[str]]]:
    """(entry point, cause, its stops on a KUKA name) of each entry point of the backup `root`,
    on the VM, with --inputs auto and the bounds above."""
    out = []
    for entry in rp.entries_of(root):
        row = rp.run_one(entry, SIM_TIME_S, STEPS, auto=True, interp="vm", auto_sim_time=SIM_TIME_S)
        stops = row["outside_stops"] if row["reason"] != "internal" else [f"internal error: {row['text']}"]
        out.append((str(entry), row["cause"], stops))
    return out


ROOTS = backups()


def test_the_corpus_and_the_history_have_their_backups():
    assert len(ROOTS) >= 18 if (SHARED_HISTORY / "MANIFEST.csv").exists() else len(ROOTS) >= 4


@pytest.mark.parametrize("root", [pytest.param(r, marks=pytest.mark.slow) if earlier_version(r) else r
                                  for r in ROOTS], ids=[str(r.relative_to(SHARED)) for r in ROOTS])
def test_no_run_stops_on_a_name_the_checker_calls_kukas(root):
    rows = stops_of_backup(root)
    assert rows
    stopped = [(entry, stops) for entry, _cause, stops in rows if stops]
    assert not stopped, "\n".join(f"{e}: {s}" for e, stops in stopped for s in stops)
