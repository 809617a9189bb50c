"""tests/chromium.py: the process's one Playwright driver and its browser serve the page tests of
every module, while the asyncio loops of other tests (``asyncio.run``, pytest-asyncio's, as the
pytest-lsp tests use, another ``sync_playwright()``) run between them. The tests run in order in
one worker (one xdist group); each later one reads what the first kept (run alone, it keeps
the same itself)."""

from __future__ import annotations

import asyncio

import playwright.sync_api as playwright
import pytest

from tests.chromium import shared_browser

pytestmark = pytest.mark.xdist_group("chromium-driver")

FIRST: dict = {}


def _text_of_a_page(browser, text: str) -> str:
    ctx = browser.new_context()
    try:
        page = ctx.new_page()
        page.set_content(f"<p>{text}</p>")
        return page.inner_text("p")
    finally:
        ctx.close()


def test_a_page_in_the_driver(pw):
    FIRST.update(driver=pw, browser=shared_browser(pw))
    assert _text_of_a_page(FIRST["browser"], "one") == "one"


def test_asyncio_run_after_it():
    assert asyncio.run(asyncio.sleep(0, result=7)) == 7


@pytest.mark.asyncio
async def test_pytest_asyncio_after_it():
    assert await asyncio.sleep(0, result=8) == 8


def test_another_sync_playwright_after_it():
    with playwright.sync_playwright() as other:
        assert other is not FIRST.get("driver")
        assert other.chromium.name == "chromium"


def test_the_next_page_has_the_same_driver_and_browser(pw):
    # run alone (not after the first), it keeps what the first would have
    FIRST.setdefault("driver", pw)
    FIRST.setdefault("browser", shared_browser(pw))
    assert pw is FIRST["driver"] and shared_browser(pw) is FIRST["browser"]
    assert _text_of_a_page(shared_browser(pw), "two") == "two"


def test_a_browser_that_went_away_is_launched_again(pw):
    FIRST.setdefault("browser", shared_browser(pw))
    FIRST["browser"].close()
    browser = shared_browser(pw)
    assert browser is not FIRST["browser"] and browser.is_connected()
    assert _text_of_a_page(browser, "three") == "three"
