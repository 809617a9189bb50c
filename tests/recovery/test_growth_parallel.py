"""`krl growth` / `krl validate` scan grammar versions in parallel, with the fast engine when it
can run (recovery/growth.py scan_versions): the summaries equal a sequential scan with the
Python engine, version by version."""

from __future__ import annotations

import shutil
from pathlib import Path

from recovery.grammar_versions import committed_versions
from recovery.growth import scan_versions

REPO = Path(__file__).resolve().parents[2]


def test_parallel_versions_equal_sequential_python_scan(tmp_path, monkeypatch):
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    negatives = sorted((REPO / "tests" / "negative").glob("neg_*.src"))[:25]
    positives = sorted((REPO / "grammar" / "constructs").glob("*/ok_*.src"))[:25]
    for i, f in enumerate(negatives + positives):
        shutil.copyfile(f, corpus / f"{i:03d}_{f.name}")
    versions = committed_versions()
    # the first and the last grammar (a middle one too until 2026-11-27: 11.0 s of CPU for the three)
    texts = [versions[0].text, versions[-1].text]

    fast = scan_versions(corpus, texts, jobs=2, use_cache=False, progress=False)
    monkeypatch.setenv("KRL_ENGINE", "python")
    reference = scan_versions(corpus, texts, jobs=1, use_cache=False, progress=False)

    assert fast == reference
    assert [r["files"] for r in reference] == [50, 50]
    # the versions differ (the grammar grew), so the comparison is not of three equal scans
    assert reference[0]["files_ok"] < reference[-1]["files_ok"]
