"""The project's own KRL (the interpreters' BASIS, the conformance cases) checks without
false errors: the interpreters refuse to run a program with checker errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from krl.parsecache import through_store
from krl.source import is_krl_file
from krl.workspace import load_workspace

ROOT = Path(__file__).resolve().parents[2]
BASIS = ROOT / "interp" / "basis"
CASES = ROOT / "conformance" / "cases"


@pytest.mark.skipif(not BASIS.is_dir(), reason="interp/basis not present")
def test_basis_checks_clean():
    # BASIS's own files (interp/runtime/program.py: a folder run's System folder); kuka/p00.src is
    # KUKA's standard P00 that a backup lacking it gets, checked with the backup's $config.dat
    ws = load_workspace(sorted(p for p in BASIS.iterdir() if p.is_file() and is_krl_file(p)))
    assert not [str(d) for d in ws.check() if d.is_error]


def _cases():
    if not CASES.is_dir():
        return []
    return sorted(p for p in CASES.iterdir() if (p / "program.src").is_file())


@pytest.mark.skipif(not _cases(), reason="no conformance cases")
def test_conformance_cases_have_no_internal_or_unmapped_findings():
    """Cases may hold deliberate errors; internal errors and unmapped constructs never."""
    bad = []
    # each case's workspace holds BASIS too: its files' parses come from the store (krl/store.py,
    # as `krl check` reads them), parsed at the first case, not at each (7.8 -> 1.7 s of CPU,
    # the same diagnostics of every case, 2026-11-28)
    with through_store():
        for case in _cases()[::4]:   # a sample keeps the suite fast; all of them take ~10 s
            paths = [case] + ([BASIS] if BASIS.is_dir() else [])
            ws = load_workspace(paths, str(case))
            bad += [str(d) for d in ws.check() if d.code in ("E901", "W003")]
    assert not bad, bad[:10]
