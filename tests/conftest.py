"""Shared pytest set-up: paths and the hypothesis profiles (ci by default, nightly for sweeps)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

REPO_ROOT = Path(__file__).resolve().parents[1]
SHARED = REPO_ROOT.parent / "shared"
SHARED_CORPUS = SHARED / "krl-corpus"

settings.register_profile("ci", max_examples=50, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("nightly", max_examples=2000, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture(scope="session")
def shared_corpus() -> Path:
    """The real corpus, read in place; tests that need it skip cleanly when it is absent."""
    if not (SHARED_CORPUS / "MANIFEST.csv").exists():
        pytest.skip("../shared/krl-corpus is not present")
    return SHARED_CORPUS
