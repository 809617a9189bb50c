"""Fixtures of the pendant's tests: the module's Playwright driver (tests/chromium.py)."""

from tests.chromium import pw  # noqa: F401  (fixture)
