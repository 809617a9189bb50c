"""Shared fixtures of the front-end tests: hypothesis profiles and small helpers.

Profiles: "ci" (default, 50 examples per property) and "nightly" (500); choose with
HYPOTHESIS_PROFILE=nightly.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("ci", max_examples=50, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("nightly", max_examples=500, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

CORPUS = Path(os.environ.get("KRL_CORPUS",
                             Path(__file__).resolve().parents[2].parent / "shared" / "krl-corpus"))


@pytest.fixture(scope="session")
def corpus() -> Path:
    if not CORPUS.is_dir():
        pytest.skip("../shared/krl-corpus is absent")
    return CORPUS
