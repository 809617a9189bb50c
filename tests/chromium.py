"""The suite's headless Chromium (Debian's, driven by Playwright): one Playwright driver per test
module (:func:`pw`, a fixture a module imports), one browser per driver, launched at its first
page with the flags `krl pendant` opens Chromium with (pendant/client.py ``CHROMIUM_FLAGS``) and
ended with the driver. Each page of a test gets a browser context of its own (no cookie,
storage or cache of another page, as with a fresh profile): a launch is about a second of CPU
(four launches on a fresh profile with the driver's start: 5.3 s, counted with a cgroup,
2026-11-26), a context a fraction of it."""

from __future__ import annotations

import playwright.sync_api as playwright
import pytest

from pendant.client import CHROMIUM_FLAGS
from tests.system_tools import require


@pytest.fixture(scope="module")
def pw():
    """The Playwright driver of one test module (its sync API cannot be nested: module scope ends
    it before a test of another module, which may start its own, runs in the same worker). A
    driver's start is 0.6-0.7 s of CPU; with it, its browser (:func:`shared_browser`) serves every
    page of the module."""
    with playwright.sync_playwright() as p:
        yield p


def shared_browser(pw, executable: str | None = None):
    """The headless Chromium of the Playwright driver ``pw`` (``executable``: default Debian's,
    :func:`tests.system_tools.require`), launched when ``pw`` has none connected."""
    browser = getattr(pw, "krl_browser", None)
    if browser is None or not browser.is_connected():
        browser = pw.krl_browser = pw.chromium.launch(executable_path=executable or require("chromium"),
                                                      headless=True, args=CHROMIUM_FLAGS)
    return browser
