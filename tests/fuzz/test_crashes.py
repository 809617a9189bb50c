"""Every input a fuzzer ever found (tests/fuzz/crashes/<target>/), minimized, run through its
target again: the property holds now (the fix stays fixed)."""

from __future__ import annotations

from pathlib import Path

from tests.fuzz.targets import TARGETS

CRASHES = Path(__file__).resolve().parent / "crashes"
FOUND = sorted(p for p in CRASHES.rglob("*.bin"))


def test_every_crash_folder_names_a_target():
    assert {p.parent.name for p in FOUND} <= set(TARGETS)


def test_every_finding_stays_fixed():
    failed = []
    for path in FOUND:
        try:
            TARGETS[path.parent.name](path.read_bytes())
        except Exception as exc:  # noqa: BLE001 - each finding is reported by name
            failed.append(f"{path.parent.name}/{path.name}: {type(exc).__name__}: {exc}")
    assert failed == []
