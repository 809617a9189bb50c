"""The suite's headless Chromium (Debian's, driven by Playwright): one browser per Playwright
driver, launched at its first page with the flags `krl pendant` opens Chromium with
(pendant/client.py ``CHROMIUM_FLAGS``) and ended with the driver. Each page of a test gets a
browser context of its own (no cookie, storage or cache of another page, as with a fresh
profile): a launch is about a second of CPU (four launches on a fresh profile with the driver's
start: 5.3 s, counted with a cgroup, 2026-11-26), a context a fraction of it."""

from __future__ import annotations

from pendant.client import CHROMIUM_FLAGS
from tests.system_tools import require


def shared_browser(pw, executable: str | None = None):
    """The headless Chromium of the Playwright driver ``pw`` (``executable``: default Debian's,
    :func:`tests.system_tools.require`), launched when ``pw`` has none connected."""
    browser = getattr(pw, "krl_browser", None)
    if browser is None or not browser.is_connected():
        browser = pw.krl_browser = pw.chromium.launch(executable_path=executable or require("chromium"),
                                                      headless=True, args=CHROMIUM_FLAGS)
    return browser
