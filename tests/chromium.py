"""The suite's headless Chromium (Debian's, driven by Playwright): one Playwright driver per
pytest process (:func:`pw`, a fixture of every test module through tests/conftest.py), one browser per driver,
launched at its first page with the flags `krl pendant` opens Chromium with (pendant/client.py
``CHROMIUM_FLAGS``) and ended with the session. Each page of a test gets a browser context of its
own (no cookie, storage or cache of another page, as with a fresh profile): a launch is about a
second of CPU (four launches on a fresh profile with the driver's start: 5.3 s, counted with a
cgroup, 2026-11-26), a context a fraction of it; an idle driver with its browser, none (a cgroup:
1.77 s for a start, a launch and a page, 1.72 s with 60 s of idling after them, 2026-11-28).
A test's wait for a condition of a page looks at it every :data:`POLL_MS`, not at each frame.

Why the driver is paused between tests (:class:`Driver`): Playwright's sync API runs its asyncio
loop in a greenlet and, after each call, marks that loop as the thread's running loop
(playwright/_impl/_greenlets.py ``wait_for_future``). While it is so marked, ``asyncio.run``,
pytest-asyncio's runner (the pytest-lsp tests) and a second ``sync_playwright()`` in the same
process refuse to start ("cannot be called from a running event loop", "It looks like you are
using Playwright Sync API inside the asyncio loop"). Between the tests that ask for ``pw`` the
mark is taken away and given back before the next one: the loop is idle then (no page is open),
so nothing of the driver runs."""

from __future__ import annotations

import asyncio

import playwright.sync_api as playwright
import pytest

from pendant.client import CHROMIUM_FLAGS
from tests.system_tools import require

#: how often a test's wait for a condition of a page evaluates it (ms; Playwright's
#: ``wait_for_function(..., polling=POLL_MS)``). Playwright's default evaluates it at each animation
#: frame: the page then makes 60 frames a second for as long as the test waits (the pendant's
#: waits last for whole program runs). A still page's 15 s wait cost 1.08 s of Chromium's CPU so,
#: 0.24 s at 100 ms (the medians of three, a cgroup, 2026-11-28); a condition that holds is
#: seen at most 100 ms later.
POLL_MS = 100


class Driver:
    """The process's one Playwright driver: started by the first test that asks for it, marked
    running only during the tests that ask for it (module docstring), stopped at the session's
    end (the teardown of :func:`pw`)."""

    manager = None       # playwright's PlaywrightContextManager of the running driver
    driver = None        # its sync Playwright object

    @classmethod
    def get(cls):
        if cls.driver is None:
            cls.manager = playwright.sync_playwright()
            cls.driver = cls.manager.start()
        return cls.driver

    @classmethod
    def resume(cls) -> None:
        """Mark the driver's loop running again (before a test that asks for ``pw``)."""
        if cls.manager is not None and not cls.manager._dispatcher_fiber.dead:
            asyncio.events._set_running_loop(cls.manager._loop)

    @classmethod
    def pause(cls) -> None:
        """Take the mark away (after such a test): other tests may run their own loops."""
        if cls.manager is not None and asyncio.events._get_running_loop() is cls.manager._loop:
            asyncio.events._set_running_loop(None)

    @classmethod
    def stop(cls) -> None:
        if cls.driver is not None:
            cls.resume()
            cls.driver.stop()
            cls.manager = cls.driver = None


class DriverPauses:
    """The pytest hooks of :class:`Driver` (registered by tests/conftest.py)."""

    @pytest.hookimpl(tryfirst=True)
    def pytest_runtest_setup(self, item: pytest.Item) -> None:
        if "pw" in getattr(item, "fixturenames", ()):
            Driver.resume()

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_teardown(self, item: pytest.Item, nextitem: pytest.Item | None):
        yield
        Driver.pause()


@pytest.fixture(scope="session")
def pw():
    """The process's Playwright driver (:class:`Driver`), a fixture of the session that
    tests/conftest.py imports (one definition: a module importing it made a driver of its own)."""
    try:
        yield Driver.get()
    finally:
        Driver.stop()


def shared_browser(pw, executable: str | None = None):
    """The headless Chromium of the Playwright driver ``pw`` (``executable``: default Debian's,
    :func:`tests.system_tools.require`), launched when ``pw`` has none connected (also after
    a crash of the browser)."""
    browser = getattr(pw, "krl_browser", None)
    if browser is None or not browser.is_connected():
        browser = pw.krl_browser = pw.chromium.launch(executable_path=executable or require("chromium"),
                                                      headless=True, args=CHROMIUM_FLAGS)
    return browser
