"""A short run of every fuzz target (a few seconds each), so that the harness cannot rot:
each target starts under atheris, runs its seeds and some mutations, and finds nothing."""

from __future__ import annotations

import json
import subprocess
import sys
import pytest

from tests.fuzz.run import REPO, seed_files
from tests.fuzz.targets import TARGETS
from tests.test_json_schemas import validate


@pytest.mark.parametrize("target", sorted(TARGETS))
def test_short_fuzz_run(target, tmp_path):
    seeds, runs = (3, 6) if target == "interp" else (8, 40)
    res = subprocess.run([sys.executable, "-m", "tests.fuzz.run", target, "--seconds", "3", "--seeds", str(seeds),
                          "--runs", str(runs), "--out", str(tmp_path)], cwd=REPO, capture_output=True, text=True,
                         timeout=600, check=False)
    summary = json.loads((tmp_path / "summary.json").read_text())
    validate("fuzz-summary", summary)
    entry = summary["targets"][target]
    log = (tmp_path / target / "fuzz.log").read_text()
    assert res.returncode == 0, res.stdout + res.stderr + log[-3000:]
    assert entry["findings"] == 0
    assert entry["runs"] >= seeds, log[-3000:]     # every seed ran at least once
    assert "INITED" in log or "DONE" in log


def test_seeds_come_from_the_corpora():
    krl = seed_files("decode_parse", 50)
    assert 0 < len(krl) <= 50 + len(list((REPO / "tests" / "fuzz" / "crashes").rglob("*.bin")))
    assert all(p.suffix.lower() in (".src", ".dat", ".sub", ".bin") for p in krl)
    assert seed_files("stimuli", 10) and all(p.suffix in (".yaml", ".bin") for p in seed_files("stimuli", 10))
