"""Shared fixtures of the front-end tests: hypothesis profiles and small helpers.

The hypothesis profiles are registered once, in tests/conftest.py.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

CORPUS = Path(os.environ.get("KRL_CORPUS",
                             Path(__file__).resolve().parents[2].parent / "shared" / "krl-corpus"))


@pytest.fixture(scope="session")
def corpus() -> Path:
    if not CORPUS.is_dir():
        pytest.skip("../shared/krl-corpus is absent")
    return CORPUS
