"""Fixtures of the pendant's tests: the one Playwright driver of the session."""

from __future__ import annotations

import playwright.sync_api as playwright
import pytest


@pytest.fixture(scope="module")
def pw():
    """The Playwright driver of one test module (its sync API cannot be nested: module scope ends
    it before a test of another module, which may start its own, runs in the same worker)."""
    with playwright.sync_playwright() as p:
        yield p
