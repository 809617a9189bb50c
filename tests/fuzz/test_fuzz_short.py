"""A short run of the fuzz targets (a few seconds each), so that the harness cannot rot: a target
starts under atheris, runs its seeds and some mutations, and finds nothing. make test runs one
target so (:data:`UNDER_ATHERIS`) and every target's function on its seeds in this process;
make nightly runs every target under atheris (here, marked slow, and at length: tests.fuzz.run)."""

from __future__ import annotations

import json

import pytest

from tests.fuzz.run import REPO, main, seed_files
from tests.fuzz.targets import TARGETS
from tests.test_json_schemas import validate


#: the targets make test starts under atheris: ``interp``, whose start takes every step of
#: atheris_main the others take (the project's modules instrumented as they import, the seeds,
#: libFuzzer's mutations, the summary) and one more, its subject instrumented apart (its own
#: ``instrument_imports``). Each start took 4.3-8.6 s in a fresh clone's run (2026-11-26;
#: mostly the atheris process); ``decode_parse``'s (7.2 s of CPU in the quiet run of
#: 2026-11-28) went to make nightly with the other five: it takes no step of the harness the
#: ``interp`` start does not, and its function, the first step of every other target, runs on
#: its seeds below in this process, uninstrumented, as every target's does.
UNDER_ATHERIS = ("interp",)


def _seeds_and_runs(target: str) -> tuple[int, int]:
    return (3, 6) if target == "interp" else (8, 40)


@pytest.mark.parametrize("target", [pytest.param(t, marks=() if t in UNDER_ATHERIS else pytest.mark.slow)
                                    for t in sorted(TARGETS)])
def test_short_fuzz_run(target, tmp_path):
    seeds, runs = _seeds_and_runs(target)
    # the runner's main in this process (`python -m tests.fuzz.run` is that main; it starts the
    # atheris process): not a process that imports the runner and the targets again (1.2 s of CPU, 2026-11-29)
    status = main([target, "--seconds", "3", "--seeds", str(seeds), "--runs", str(runs), "--out", str(tmp_path)])
    summary = json.loads((tmp_path / "summary.json").read_text())
    validate("fuzz-summary", summary)
    entry = summary["targets"][target]
    log = (tmp_path / target / "fuzz.log").read_text()
    assert status == 0, log[-3000:]
    assert entry["findings"] == 0
    assert entry["runs"] >= seeds, log[-3000:]     # every seed ran at least once
    assert "INITED" in log or "DONE" in log


def test_every_target_holds_on_its_seeds():
    """Every target's function on the seeds its short run starts from, in this process: the
    property holds for each (a target or a seed folder that rots fails here, fuzzed or not)."""
    failed = []
    for name, target in sorted(TARGETS.items()):
        for path in seed_files(name, _seeds_and_runs(name)[0]):
            try:
                target(path.read_bytes())
            except Exception as exc:  # noqa: BLE001 - each seed is reported by name
                failed.append(f"{name}: {path.name}: {type(exc).__name__}: {exc}")
    assert failed == []


def test_seeds_come_from_the_corpora():
    krl = seed_files("decode_parse", 50)
    assert 0 < len(krl) <= 50 + len(list((REPO / "tests" / "fuzz" / "crashes").rglob("*.bin")))
    assert all(p.suffix.lower() in (".src", ".dat", ".sub", ".bin") for p in krl)
    assert seed_files("stimuli", 10) and all(p.suffix in (".yaml", ".bin") for p in seed_files("stimuli", 10))
