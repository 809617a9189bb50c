"""Shared fixtures of the front-end tests: hypothesis profiles and small helpers.

Profiles: "ci" (default, 50 examples per property) and "nightly" (more); choose with
HYPOTHESIS_PROFILE=nightly. They are registered here unless tests/conftest.py already did.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

# tests/conftest.py may register the same profiles for the whole suite: keep its definitions
for _name, _examples in (("ci", 50), ("nightly", 500)):
    try:
        settings.get_profile(_name)
    except Exception:  # noqa: BLE001 - hypothesis raises InvalidArgument for an unknown profile
        settings.register_profile(_name, max_examples=_examples, deadline=None,
                                  suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

CORPUS = Path(os.environ.get("KRL_CORPUS",
                             Path(__file__).resolve().parents[2].parent / "shared" / "krl-corpus"))


@pytest.fixture(scope="session")
def corpus() -> Path:
    if not CORPUS.is_dir():
        pytest.skip("../shared/krl-corpus is absent")
    return CORPUS
