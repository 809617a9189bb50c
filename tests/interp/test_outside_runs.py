"""One decision on KUKA's software (issue 46), on material nobody here wrote: every entry point
of every backup of ../shared/krl-corpus and of ../shared/krl-history (both sides of each pair)
runs as a new user runs it (``--inputs auto``, nothing hand-written) for a bounded simulated
time, and no run — robot program or submit program — may stop on a name the checker classifies
outside the backup (krl/semantics/outside.py ``Unresolved.classify``: W101/W105/W106/W107): the
run stands in for each (interp/runtime/kss.py). ``interp.realprograms.outside_stops`` reads the
run's errors against the checker's classification of the same workspace.

Cost: about 290 entry points of 18 backups (``make test`` runs half of each corpus backup's
entry points, :func:`half_of`, and each history repository's newest version, the ``new`` side
of its newest pair, :func:`earlier_version`; ``make nightly`` all), one test per backup (per half) (its files are loaded and
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


def half_of(entries: list[Path], half: int | None) -> list[Path]:
    """The entry points of a half: None, all; 0 (``make test``), the submit programs and the
    robot programs at even positions (in entries_of's order); 1 (``make nightly``), the robot
    programs at odd positions. The two halves are every entry point once."""
    if half is None:
        return entries
    subs = [e for e in entries if e.suffix.lower() == ".sub"]
    robot = [e for e in entries if e.suffix.lower() != ".sub"]
    return (subs + robot[0::2]) if half == 0 else robot[1::2]


def stops_of_backup(root: Path, half: int | None = None) -> list[tuple[str, str, list[str]]]:
    """(entry point, cause, its stops on a KUKA name) of each entry point of the backup `root`
    (of the `half`: :func:`half_of`), on the VM, with --inputs auto and the bounds above."""
    out = []
    for entry in half_of(rp.entries_of(root), half):
        row = rp.run_one(entry, SIM_TIME_S, STEPS, auto=True, interp="vm", auto_sim_time=SIM_TIME_S)
        stops = row["outside_stops"] if row["reason"] != "internal" else [f"internal error: {row['text']}"]
        out.append((str(entry), row["cause"], stops))
    return out


ROOTS = backups()


def test_the_corpus_and_the_history_have_their_backups():
    assert len(ROOTS) >= 18 if (SHARED_HISTORY / "MANIFEST.csv").exists() else len(ROOTS) >= 4


def _params() -> list:
    """One test per half of each corpus backup (:func:`half_of`) and per history backup (whole);
    an earlier version, or a second half, is ``make nightly``'s (marked ``slow``). Listing the
    entry points is left to the test (it reads the backup: not at collection)."""
    out = []
    for r in ROOTS:
        rel = str(r.relative_to(SHARED))
        halves = (0, 1) if r.is_relative_to(SHARED_CORPUS) else (None,)
        for h in halves:
            slow = earlier_version(r) or h == 1
            out.append(pytest.param(r, h, marks=pytest.mark.slow if slow else (),
                                    id=rel if h is None else f"{rel}-half{h}"))
    return out


@pytest.mark.parametrize(("root", "half"), _params())
def test_no_run_stops_on_a_name_the_checker_calls_kukas(root, half):
    """``make test`` runs half of each corpus backup's entry points (its submit programs and
    every second robot program: ChinaMilling 13 of 25, the palletizer 12 of 23, khrzysio 20 of
    39, kukaKRLmagic 2 of 3; the same check on each entry point: the same bounds, the same
    verdict) and each history repository's newest version whole; ``make nightly`` the other
    halves and every earlier version."""
    rows = stops_of_backup(root, half)
    assert rows
    stopped = [(entry, stops) for entry, _cause, stops in rows if stops]
    assert not stopped, "\n".join(f"{e}: {s}" for e, stops in stopped for s in stops)
